#include <crisp/atlas.hpp>

#include "morton.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <string>

namespace crisp {

namespace {

constexpr uint32_t kNotFound = 0xFFFFFFFFu;
constexpr uint64_t kFullWord = ~uint64_t{0};

// Bit k set: an aligned run of 2^i cells (index i) may start at bit k of a word.
constexpr uint64_t kRunStarts[6] = {
    0xFFFFFFFFFFFFFFFFull, 0x5555555555555555ull, 0x1111111111111111ull,
    0x0101010101010101ull, 0x0001000100010001ull, 0x0000000100000001ull,
};

// Bit k of the result is set when bits k to k + run - 1 of `free_bits` are all set and k is a
// multiple of `run` (a power of two below 64). Runs never straddle words because they are aligned.
uint64_t free_runs(uint64_t free_bits, uint32_t run) {
    for (uint32_t shift = 1; shift < run; shift <<= 1) free_bits &= free_bits >> shift;
    return free_bits & kRunStarts[std::countr_zero(run)];
}

// The first run of `bit_count` clear bits aligned to `bit_count` (a power of two), starting the
// search at word `start_word`; kNotFound if there is none.
uint32_t find_clear_run(const std::vector<uint64_t>& words, uint32_t bit_count, uint32_t start_word) {
    const auto word_count = static_cast<uint32_t>(words.size());
    if (bit_count < 64) {
        for (uint32_t w = start_word; w < word_count; ++w) {
            if (words[w] == kFullWord) continue;
            const uint64_t runs = free_runs(~words[w], bit_count);
            if (runs != 0) return w * 64 + static_cast<uint32_t>(std::countr_zero(runs));
        }
        return kNotFound;
    }
    const uint32_t run_words = bit_count / 64;
    for (uint32_t w = start_word & ~(run_words - 1); w + run_words <= word_count; w += run_words) {
        bool clear = true;
        for (uint32_t k = 0; k < run_words && clear; ++k) clear = words[w + k] == 0;
        if (clear) return w * 64;
    }
    return kNotFound;
}

// Mask of the bits of an aligned run of fewer than 64 bits, within its word.
uint64_t run_mask(uint32_t first_bit, uint32_t bit_count) {
    return ((uint64_t{1} << bit_count) - 1) << (first_bit % 64);
}

bool range_clear(const std::vector<uint64_t>& words, uint32_t first_bit, uint32_t bit_count) {
    if (bit_count < 64) return (words[first_bit / 64] & run_mask(first_bit, bit_count)) == 0;
    for (uint32_t w = first_bit / 64; w < (first_bit + bit_count) / 64; ++w)
        if (words[w] != 0) return false;
    return true;
}

void set_range(std::vector<uint64_t>& words, uint32_t first_bit, uint32_t bit_count, bool set) {
    if (bit_count < 64) {
        const uint64_t mask = run_mask(first_bit, bit_count);
        uint64_t& word = words[first_bit / 64];
        word = set ? (word | mask) : (word & ~mask);
        return;
    }
    std::fill(words.begin() + first_bit / 64, words.begin() + (first_bit + bit_count) / 64, set ? kFullWord : 0);
}

// Counters are fed caller-supplied costs; a saturated total is more useful than a wrapped one.
uint64_t add_saturating(uint64_t a, uint64_t b) {
    return a > kFullWord - b ? kFullWord : a + b;
}

bool valid_size(uint32_t size) {
    return size >= kAtlasMinSize && size <= kAtlasMaxSize && std::has_single_bit(size);
}

Error invalid(std::string message) {
    return Error{ErrorCode::invalid_argument, std::move(message)};
}

}  // namespace

const char* atlas_status_name(AtlasStatus status) {
    switch (status) {
        case AtlasStatus::placed:
            return "placed";
        case AtlasStatus::empty:
            return "empty";
        case AtlasStatus::atlas_full:
            return "atlas_full";
        case AtlasStatus::too_large:
            return "too_large";
    }
    return "unknown";
}

Result<GlyphAtlas> GlyphAtlas::create(const AtlasConfig& config) {
    if (!valid_size(config.width) || !valid_size(config.height))
        return invalid("atlas size " + std::to_string(config.width) + "x" + std::to_string(config.height) +
                       " is not a power of two from " + std::to_string(kAtlasMinSize) + " to " +
                       std::to_string(kAtlasMaxSize) + " on each axis");
    if (config.max_samples == 0 || config.max_samples > kAtlasMaxSamples)
        return invalid("max_samples " + std::to_string(config.max_samples) + " is not in [1, " +
                       std::to_string(kAtlasMaxSamples) + "]");
    if (config.steady == 0 || config.steady > config.max_samples)
        return invalid("steady " + std::to_string(config.steady) + " is not in [1, max_samples]");
    for (size_t i = 0; i < config.ramp.size(); ++i)
        if (config.ramp[i] == 0 || config.ramp[i] > config.max_samples)
            return invalid("ramp[" + std::to_string(i) + "] = " + std::to_string(config.ramp[i]) +
                           " is not in [1, max_samples]");
    if (config.frame_budget == 0) return invalid("frame_budget is 0; it must allow at least one curve test");

    GlyphAtlas atlas;
    atlas.config_ = config;
    atlas.cells_x_ = config.width / kAtlasCellSize;
    atlas.cells_y_ = config.height / kAtlasCellSize;
    atlas.usable_cells_ = atlas.cells_x_ * atlas.cells_y_;

    // The index space is the square of the longer side; in a non-square atlas the indices that
    // decode outside it, and the pad bits of a last word shorter than 64 cells, are never free.
    const uint32_t side = std::max(atlas.cells_x_, atlas.cells_y_);
    const uint32_t index_count = side * side;
    const uint32_t word_count = (index_count + 63) / 64;
    std::vector<uint64_t>& permanent = atlas.permanent_words_;
    permanent.assign(word_count, 0);
    if (atlas.cells_x_ != atlas.cells_y_) {
        for (uint32_t i = 0; i < index_count; ++i) {
            const CellCoord cell = n_order_decode(i);
            if (cell.x >= atlas.cells_x_ || cell.y >= atlas.cells_y_) permanent[i / 64] |= uint64_t{1} << (i % 64);
        }
    }
    if (index_count % 64 != 0) permanent.back() |= kFullWord << (index_count % 64);
    atlas.used_words_ = permanent;
    atlas.pinned_words_ = permanent;
    while (atlas.first_free_word_ < word_count && atlas.used_words_[atlas.first_free_word_] == kFullWord)
        ++atlas.first_free_word_;

    uint64_t total = 0;
    for (uint32_t samples : config.ramp) atlas.ramp_totals_.push_back(total += samples);
    return atlas;
}

void GlyphAtlas::begin_frame() {
    ++frame_;
    pinned_words_ = permanent_words_;
    pinned_ids_.clear();
    work_.clear();
    scheduled_ = false;
    frame_counters_ = {};
}

void GlyphAtlas::lru_unlink(uint32_t id) {
    Slot& slot = slots_[id];
    if (slot.lru_prev != kNoAtlasEntry)
        slots_[slot.lru_prev].lru_next = slot.lru_next;
    else
        lru_head_ = slot.lru_next;
    if (slot.lru_next != kNoAtlasEntry)
        slots_[slot.lru_next].lru_prev = slot.lru_prev;
    else
        lru_tail_ = slot.lru_prev;
    slot.lru_prev = slot.lru_next = kNoAtlasEntry;
}

void GlyphAtlas::lru_push_front(uint32_t id) {
    Slot& slot = slots_[id];
    slot.lru_prev = kNoAtlasEntry;
    slot.lru_next = lru_head_;
    if (lru_head_ != kNoAtlasEntry)
        slots_[lru_head_].lru_prev = id;
    else
        lru_tail_ = id;
    lru_head_ = id;
}

// Pinned entries gather at the front of the LRU list, so the tail is the least recently used
// unpinned entry whenever there is one.
void GlyphAtlas::pin(uint32_t id) {
    Slot& slot = slots_[id];
    if (pinned(slot)) return;
    slot.entry.last_used_frame = frame_;
    set_range(pinned_words_, slot.first_bit, slot.bit_count, true);
    pinned_ids_.push_back(id);
    lru_unlink(id);
    lru_push_front(id);
}

void GlyphAtlas::mark_cells(uint32_t first_bit, uint32_t bit_count, bool used) {
    set_range(used_words_, first_bit, bit_count, used);
    const auto word_count = static_cast<uint32_t>(used_words_.size());
    if (used) {
        used_cells_ += bit_count;
        while (first_free_word_ < word_count && used_words_[first_free_word_] == kFullWord) ++first_free_word_;
    } else {
        used_cells_ -= bit_count;
        first_free_word_ = std::min(first_free_word_, first_bit / 64);
    }
}

uint32_t GlyphAtlas::find_block(uint32_t bit_count) const {
    // Words below first_free_word_ are full, so no run can start there.
    return find_clear_run(used_words_, bit_count, first_free_word_);
}

void GlyphAtlas::evict(uint32_t id) {
    Slot& slot = slots_[id];
    assert(slot.resident && !pinned(slot));
    mark_cells(slot.first_bit, slot.bit_count, false);
    ids_by_key_.erase(slot.entry.key);
    lru_unlink(id);
    slot.resident = false;
    free_ids_.push_back(id);
    ++frame_counters_.evictions;
    ++total_counters_.evictions;
}

// Called when no free block of bit_count cells exists. Returns the block freed by evicting
// unpinned entries least recently used first, or kNotFound having evicted nothing.
uint32_t GlyphAtlas::make_room(uint32_t bit_count) {
    if (lru_tail_ == kNoAtlasEntry || pinned(slots_[lru_tail_])) return kNotFound;
    // Evicting every unpinned entry would leave only the pinned cells taken. If they leave no
    // block, eviction cannot help: fail now and keep the unpinned glyphs for later frames.
    if (find_clear_run(pinned_words_, bit_count, 0) == kNotFound) return kNotFound;
    // Blocks of 64 cells or more keep a count of their used cells, taken the first time an
    // eviction touches them, so that evicting thousands of small glyphs for one large block
    // costs O(cells / 64) in all rather than that much per eviction.
    const bool count_blocks = bit_count >= 64;
    if (count_blocks) block_used_.assign(used_words_.size() * 64 / bit_count, kNotFound);
    for (;;) {
        const uint32_t victim = lru_tail_;
        // The pinned-cells check above guarantees a block appears before the unpinned run out.
        assert(victim != kNoAtlasEntry && !pinned(slots_[victim]));
        if (victim == kNoAtlasEntry || pinned(slots_[victim])) return kNotFound;
        const uint32_t freed_first = slots_[victim].first_bit;
        const uint32_t freed_count = slots_[victim].bit_count;
        evict(victim);
        // No block was free before this eviction, so a block can only have appeared where the
        // freed cells are: the freed block itself if it is big enough, else the aligned block
        // of bit_count cells around it (blocks are aligned powers of two, so they nest).
        if (freed_count >= bit_count) return freed_first;
        const uint32_t candidate = freed_first & ~(bit_count - 1);
        if (!count_blocks) {
            if (range_clear(used_words_, candidate, bit_count)) return candidate;
            continue;
        }
        uint32_t& used = block_used_[candidate / bit_count];
        if (used == kNotFound) {
            used = 0;
            for (uint32_t w = candidate / 64; w < (candidate + bit_count) / 64; ++w)
                used += static_cast<uint32_t>(std::popcount(used_words_[w]));
        } else {
            used -= freed_count;
        }
        if (used == 0) return candidate;
    }
}

AtlasLookup GlyphAtlas::acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample) {
    AtlasLookup lookup;
    if (width == 0 || height == 0) return lookup;

    uint32_t id = kNoAtlasEntry;
    if (const auto found = ids_by_key_.find(key); found != ids_by_key_.end()) {
        id = found->second;
        assert(slots_[id].entry.width == width && slots_[id].entry.height == height && "equal keys need equal rects");
        pin(id);
        ++frame_counters_.hits;
        ++total_counters_.hits;
    } else {
        // Cells per axis, rounded up to powers of two; then the block is made square or 1:2 tall
        // (the shapes an aligned run of the transposed Z-order can take).
        const uint64_t need_x = std::bit_ceil((uint64_t{width} + kAtlasCellSize - 1) / kAtlasCellSize);
        const uint64_t need_y = std::bit_ceil((uint64_t{height} + kAtlasCellSize - 1) / kAtlasCellSize);
        const uint64_t block_y = std::max(need_x, need_y);
        const uint64_t block_x = std::max(need_x, block_y / 2);
        if (block_x > cells_x_ || block_y > cells_y_) {
            lookup.status = AtlasStatus::too_large;
            ++frame_counters_.failed_too_large;
            ++total_counters_.failed_too_large;
            return lookup;
        }
        const auto bit_count = static_cast<uint32_t>(block_x * block_y);
        uint32_t first_bit = find_block(bit_count);
        if (first_bit == kNotFound) first_bit = make_room(bit_count);
        if (first_bit == kNotFound) {
            lookup.status = AtlasStatus::atlas_full;
            ++frame_counters_.failed_full;
            ++total_counters_.failed_full;
            return lookup;
        }

        if (!free_ids_.empty()) {
            id = free_ids_.back();
            free_ids_.pop_back();
        } else {
            id = static_cast<uint32_t>(slots_.size());
            slots_.emplace_back();
        }
        Slot& slot = slots_[id];
        slot = Slot{};
        // The lowest index of an aligned run has the run's low bits clear: its top-left cell.
        const CellCoord cell = n_order_decode(first_bit);
        slot.entry.key = key;
        slot.entry.x = cell.x * kAtlasCellSize;
        slot.entry.y = cell.y * kAtlasCellSize;
        slot.entry.width = width;
        slot.entry.height = height;
        slot.entry.block_width = static_cast<uint32_t>(block_x) * kAtlasCellSize;
        slot.entry.block_height = static_cast<uint32_t>(block_y) * kAtlasCellSize;
        slot.entry.curve_tests_per_sample = curve_tests_per_sample;
        slot.entry.last_used_frame = frame_;
        slot.first_bit = first_bit;
        slot.bit_count = bit_count;
        slot.resident = true;
        mark_cells(first_bit, bit_count, true);
        set_range(pinned_words_, first_bit, bit_count, true);
        pinned_ids_.push_back(id);
        lru_push_front(id);
        ids_by_key_.emplace(key, id);
        ++frame_counters_.allocations;
        ++total_counters_.allocations;
    }

    const AtlasEntry& entry = slots_[id].entry;
    lookup.status = AtlasStatus::placed;
    lookup.entry = id;
    lookup.x = entry.x;
    lookup.y = entry.y;
    lookup.width = entry.width;
    lookup.height = entry.height;
    return lookup;
}

// The samples an entry wants this frame: enough to reach its ramp's running total (so a glyph
// cut short by the budget catches up), or `steady` past the ramp; never past max_samples.
uint32_t GlyphAtlas::share(const Slot& slot) const {
    const uint32_t samples = slot.entry.samples;
    uint64_t want = config_.steady;
    if (slot.served_frames < ramp_totals_.size() && ramp_totals_[slot.served_frames] > samples)
        want = ramp_totals_[slot.served_frames] - samples;
    return static_cast<uint32_t>(std::min<uint64_t>(want, config_.max_samples - samples));
}

std::span<const RasterWork> GlyphAtlas::schedule() {
    if (scheduled_) return work_;
    scheduled_ = true;

    // New entries first, in acquire order: they have nothing to show yet.
    waiting_ids_.clear();
    for (uint32_t id : pinned_ids_)
        if (slots_[id].entry.samples == 0) waiting_ids_.push_back(id);
    const size_t new_count = waiting_ids_.size();
    // Then the rest by id, starting at the cursor and wrapping around.
    for (uint32_t id : pinned_ids_) {
        const uint32_t samples = slots_[id].entry.samples;
        if (samples > 0 && samples < config_.max_samples) waiting_ids_.push_back(id);
    }
    const auto old_begin = waiting_ids_.begin() + static_cast<std::ptrdiff_t>(new_count);
    std::sort(old_begin, waiting_ids_.end());
    std::rotate(old_begin, std::lower_bound(old_begin, waiting_ids_.end(), cursor_), waiting_ids_.end());

    uint64_t budget_left = config_.frame_budget;
    bool cursor_moved = false;
    for (size_t i = 0; i < waiting_ids_.size(); ++i) {
        const uint32_t id = waiting_ids_[i];
        Slot& slot = slots_[id];
        const bool is_old = i >= new_count;
        const uint32_t wanted = share(slot);
        const uint64_t cost = slot.entry.curve_tests_per_sample;
        uint64_t count = cost == 0 ? wanted : std::min<uint64_t>(wanted, budget_left / cost);
        bool overrun = false;
        if (count == 0) {
            if (!work_.empty()) {
                // Strict turns: an entry that cannot be served ends the frame rather than let
                // cheaper ones behind it go first, and the next frame's round starts with it.
                if (is_old && !cursor_moved) cursor_ = id;
                break;
            }
            // Even one sample exceeds the whole budget: take it anyway, alone, or this glyph
            // could never be drawn.
            count = 1;
            overrun = true;
        }

        RasterWork& work = work_.emplace_back();
        work.entry = id;
        work.key = slot.entry.key;
        work.x = slot.entry.x;
        work.y = slot.entry.y;
        work.width = slot.entry.width;
        work.height = slot.entry.height;
        work.first_sample = slot.entry.samples;
        work.sample_count = static_cast<uint32_t>(count);
        slot.entry.samples += work.sample_count;
        ++slot.served_frames;

        const uint64_t tests = count * cost;  // <= budget_left, or one sample when overrunning
        budget_left = overrun ? 0 : budget_left - tests;
        frame_counters_.samples += count;
        total_counters_.samples += count;
        frame_counters_.curve_tests = add_saturating(frame_counters_.curve_tests, tests);
        total_counters_.curve_tests = add_saturating(total_counters_.curve_tests, tests);
        if (overrun) {
            ++frame_counters_.budget_overruns;
            ++total_counters_.budget_overruns;
            // Move on, or an entry no budget can afford would take every frame until it is done.
            if (is_old && !cursor_moved) cursor_ = id + 1;
            break;
        }
        if (is_old && count < wanted && !cursor_moved) {
            cursor_ = id;
            cursor_moved = true;
        }
    }
    return work_;
}

void GlyphAtlas::invalidate_samples() {
    for (Slot& slot : slots_) {
        slot.entry.samples = 0;
        slot.served_frames = 0;
    }
}

void GlyphAtlas::set_frame_budget(uint64_t curve_tests) {
    assert(curve_tests > 0);
    config_.frame_budget = std::max<uint64_t>(curve_tests, 1);
}

uint32_t GlyphAtlas::find(const GlyphKey& key) const {
    const auto found = ids_by_key_.find(key);
    return found == ids_by_key_.end() ? kNoAtlasEntry : found->second;
}

const AtlasEntry* GlyphAtlas::entry(uint32_t id) const {
    if (id >= slots_.size() || !slots_[id].resident) return nullptr;
    return &slots_[id].entry;
}

AtlasStats GlyphAtlas::stats() const {
    AtlasStats stats;
    stats.usable_cells = usable_cells_;
    stats.used_cells = used_cells_;
    stats.occupancy = static_cast<float>(used_cells_) / static_cast<float>(usable_cells_);
    stats.resident_glyphs = static_cast<uint32_t>(ids_by_key_.size());
    stats.pinned_glyphs = static_cast<uint32_t>(pinned_ids_.size());
    for (uint32_t id : pinned_ids_)
        if (slots_[id].entry.samples < config_.max_samples) ++stats.refining_glyphs;
    stats.frame = frame_counters_;
    stats.total = total_counters_;
    return stats;
}

}  // namespace crisp
