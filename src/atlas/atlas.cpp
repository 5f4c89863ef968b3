#include <crisp/atlas.hpp>

#include "atlas/morton.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
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

AtlasBlock atlas_block(uint32_t width, uint32_t height) {
    // Cells per axis, rounded up to powers of two (bit_ceil(0) is 1: a zero side takes a cell);
    // then square or 1:2 tall, the shapes an aligned run of the transposed Z-order can take.
    const auto cells = [](uint32_t texels) {
        return std::bit_ceil(static_cast<uint32_t>((uint64_t{texels} + kAtlasCellSize - 1) / kAtlasCellSize));
    };
    const uint32_t need_x = cells(width), need_y = cells(height);
    const uint32_t block_y = std::max(need_x, need_y);
    return AtlasBlock{std::max(need_x, block_y / 2), block_y};
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

bool GlyphAtlas::grow() {
    if (config_.width * 2 > kAtlasMaxSize || config_.height * 2 > kAtlasMaxSize) return false;
    const std::vector<uint64_t> old_permanent = permanent_words_;
    std::vector<uint64_t> old_used = used_words_, old_pinned = pinned_words_;
    config_.width *= 2;
    config_.height *= 2;
    cells_x_ *= 2;
    cells_y_ *= 2;
    usable_cells_ = cells_x_ * cells_y_;
    // The new index space's cells outside the atlas (non-square or tiny atlases), as create() finds them.
    const uint32_t side = std::max(cells_x_, cells_y_);
    const uint32_t index_count = side * side;
    const uint32_t word_count = (index_count + 63) / 64;
    permanent_words_.assign(word_count, 0);
    if (cells_x_ != cells_y_) {
        for (uint32_t i = 0; i < index_count; ++i) {
            const CellCoord cell = n_order_decode(i);
            if (cell.x >= cells_x_ || cell.y >= cells_y_) permanent_words_[i / 64] |= uint64_t{1} << (i % 64);
        }
    }
    if (index_count % 64 != 0) permanent_words_.back() |= kFullWord << (index_count % 64);
    // The old cells keep their state: what entries own or pin, without the old outside bits.
    used_words_ = permanent_words_;
    pinned_words_ = permanent_words_;
    for (size_t w = 0; w < old_permanent.size(); ++w) {
        used_words_[w] |= old_used[w] & ~old_permanent[w];
        pinned_words_[w] |= old_pinned[w] & ~old_permanent[w];
    }
    first_free_word_ = 0;
    while (first_free_word_ < word_count && used_words_[first_free_word_] == kFullWord) ++first_free_word_;
    block_used_.clear();
    return true;
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

void GlyphAtlas::evict_font(FontId font) {
    for (uint32_t id = 0; id < slots_.size(); ++id) {
        if (slots_[id].resident && slots_[id].entry.key.font == font && !pinned(slots_[id])) evict(id);
    }
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
    return acquire(key, width, height, curve_tests_per_sample, TexelRect{0, 0, width, height});
}

AtlasLookup GlyphAtlas::acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                                const TexelRect& visible) {
    const uint32_t x0 = std::min(visible.x, width), y0 = std::min(visible.y, height);
    const uint32_t x1 = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{visible.x} + visible.width, width));
    const uint32_t y1 = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{visible.y} + visible.height, height));
    if (x0 >= x1 || y0 >= y1) return {};

    if (const auto found = ids_by_key_.find(key); found != ids_by_key_.end()) {
        const uint32_t id = found->second;
        Slot& slot = slots_[id];
        assert(slot.entry.width == width && slot.entry.height == height && "equal keys need equal rects");
        const TexelRect& held = slot.entry.part;
        const bool holds = x0 >= held.x && y0 >= held.y && x1 <= held.x + held.width && y1 <= held.y + held.height;
        if (holds || pinned(slot)) {
            pin(id);
            ++frame_counters_.hits;
            ++total_counters_.hits;
            return lookup_of(id);
        }
        evict(id);
        ++frame_counters_.parts_replaced;
        ++total_counters_.parts_replaced;
    }
    // The part held: the visible texels and a margin, unless that is the whole rect anyway.
    TexelRect part;
    part.x = x0 > kAtlasPartMargin ? x0 - kAtlasPartMargin : 0;
    part.y = y0 > kAtlasPartMargin ? y0 - kAtlasPartMargin : 0;
    part.width = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{x1} + kAtlasPartMargin, width) - part.x);
    part.height = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{y1} + kAtlasPartMargin, height) - part.y);
    return place(key, width, height, curve_tests_per_sample, part);
}

AtlasLookup GlyphAtlas::lookup_of(uint32_t id) const {
    const AtlasEntry& entry = slots_[id].entry;
    AtlasLookup lookup;
    lookup.status = AtlasStatus::placed;
    lookup.entry = id;
    lookup.x = entry.x;
    lookup.y = entry.y;
    lookup.width = entry.width;
    lookup.height = entry.height;
    lookup.part = entry.part;
    return lookup;
}

AtlasLookup GlyphAtlas::place(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                              const TexelRect& part) {
    AtlasLookup lookup;
    const AtlasBlock block = atlas_block(part.width, part.height);
    const uint64_t block_x = block.cells_x, block_y = block.cells_y;
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

    uint32_t id = kNoAtlasEntry;
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
    slot.entry.part = part;
    slot.entry.block_width = static_cast<uint32_t>(block_x) * kAtlasCellSize;
    slot.entry.block_height = static_cast<uint32_t>(block_y) * kAtlasCellSize;
    slot.entry.curve_tests_per_sample = curve_tests_per_sample;
    const uint64_t rect_texels = uint64_t{width} * height, part_texels = uint64_t{part.width} * part.height;
    if (part_texels < rect_texels) {
        const double scaled = std::ceil(static_cast<double>(curve_tests_per_sample) * static_cast<double>(part_texels) /
                                        static_cast<double>(rect_texels));
        slot.entry.curve_tests_per_sample = std::min(curve_tests_per_sample, static_cast<uint64_t>(scaled));
    }
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
    return lookup_of(id);
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

// Counts a work item: its samples once they cover the whole part, its cost at once.
void GlyphAtlas::count_work(const RasterWork& work) {
    if (std::none_of(undo_.begin(), undo_.end(), [&](const Undo& u) { return u.id == work.entry; })) {
        // The entry's state before this item: the item's first sample, and the texels done
        // before it (for a piece that finished its sample the entry has moved on since).
        const Slot& slot = slots_[work.entry];
        const bool finished = slot.entry.samples != work.first_sample;
        undo_.push_back({work.entry, work.first_sample, work.first_texel,
                         finished ? slot.served_frames - 1 : slot.served_frames});
    }
    const bool finishes = work.first_texel + work.texel_count == work.width * work.height;
    if (finishes) {
        frame_counters_.samples += work.sample_count;
        total_counters_.samples += work.sample_count;
    }
    if (work.texel_count < work.width * work.height) {
        ++frame_counters_.split_pieces;
        ++total_counters_.split_pieces;
    }
    frame_counters_.curve_tests = add_saturating(frame_counters_.curve_tests, work.curve_tests);
    total_counters_.curve_tests = add_saturating(total_counters_.curve_tests, work.curve_tests);
}

// One sample of an entry that no frame's budget pays for, in pieces of texels: the texels that
// `allowance` pays for (at the cost per texel rounded up), continuing where the last piece stopped.
// When not even one texel fits, the entry gets one texel anyway if `force` (a budget overrun),
// else nothing. Returns the curve tests spent.
uint64_t GlyphAtlas::schedule_split(uint32_t id, uint64_t allowance, bool force) {
    Slot& slot = slots_[id];
    AtlasEntry& entry = slot.entry;
    const uint64_t texels = uint64_t{entry.part.width} * entry.part.height;
    const uint64_t per_texel = std::max<uint64_t>((entry.curve_tests_per_sample + texels - 1) / texels, 1);
    uint64_t count = std::min(texels - entry.split_texels_done, allowance / per_texel);
    const bool overrun = count == 0 && force;
    if (count == 0 && !overrun) return 0;
    if (overrun) count = 1;
    RasterWork& work = work_.emplace_back();
    work.entry = id;
    work.key = entry.key;
    work.x = entry.x;
    work.y = entry.y;
    work.width = entry.part.width;
    work.height = entry.part.height;
    work.part_x = entry.part.x;
    work.part_y = entry.part.y;
    work.first_texel = entry.split_texels_done;
    work.texel_count = static_cast<uint32_t>(count);
    work.first_sample = entry.samples;
    work.sample_count = 1;
    work.curve_tests = count * per_texel;
    entry.split_texels_done += work.texel_count;
    if (entry.split_texels_done == texels) {  // the last piece: the sample is whole
        entry.split_texels_done = 0;
        entry.samples += 1;
        ++slot.served_frames;
    }
    count_work(work);
    if (overrun) {
        ++frame_counters_.budget_overruns;
        ++total_counters_.budget_overruns;
    }
    return work.curve_tests;
}

GlyphAtlas::FirstFrame GlyphAtlas::fit_first_frame(size_t new_count) const {
    FirstFrame fit;
    uint64_t cost_sum = 0;  // of one sample of every new entry that is not split
    uint32_t step = 0;
    for (size_t i = 0; i < new_count; ++i) {
        const Slot& slot = slots_[waiting_ids_[i]];
        const uint64_t cost = slot.entry.curve_tests_per_sample;
        if (cost > config_.frame_budget || slot.entry.split_texels_done > 0) continue;  // split: its own turns
        cost_sum += cost;
        step = std::max(step, share(slot));
    }
    fit.samples = step;
    if (cost_sum == 0) return fit;
    const uint64_t budget = config_.frame_budget;
    if (cost_sum > budget / std::max<uint32_t>(step, 1)) {
        // The largest power of two that fits for all; 1 when even one each does not (strict turns).
        const uint64_t affordable = std::max<uint64_t>(budget / cost_sum, 1);
        fit.samples = std::bit_floor(static_cast<uint32_t>(std::min<uint64_t>(affordable, step)));
        fit.spare = budget - std::min(budget, cost_sum * fit.samples);
    }
    return fit;
}

std::span<const RasterWork> GlyphAtlas::schedule() {
    if (scheduled_) return work_;
    scheduled_ = true;
    undo_.clear();
    undo_cursor_ = cursor_;

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
    // Split entries share at most half the budget while others wait, and the rest of it after.
    uint64_t split_left = std::max<uint64_t>(config_.frame_budget / 2, 1);
    FirstFrame first = fit_first_frame(new_count);
    split_ids_.clear();
    bool cursor_moved = false;
    for (size_t i = 0; i < waiting_ids_.size(); ++i) {
        const uint32_t id = waiting_ids_[i];
        Slot& slot = slots_[id];
        const bool is_old = i >= new_count;
        const uint64_t cost = slot.entry.curve_tests_per_sample;
        if (cost > config_.frame_budget || slot.entry.split_texels_done > 0) {
            const uint64_t spent = schedule_split(id, std::min(budget_left, split_left), false);
            budget_left -= spent;
            split_left -= std::min(split_left, spent);
            if (slot.entry.split_texels_done > 0 || spent == 0) {
                split_ids_.push_back(id);
                if (is_old && !cursor_moved) {
                    cursor_ = id;
                    cursor_moved = true;
                }
            }
            continue;
        }
        uint32_t wanted = share(slot);
        if (!is_old && wanted > first.samples) {
            // Cut to the fitted power of two unless the whole step fits what the fit left over.
            const uint64_t extra = cost * (wanted - first.samples);
            if (extra <= first.spare) {
                first.spare -= extra;
            } else {
                wanted = first.samples;
            }
        }
        uint64_t count = cost == 0 ? wanted : std::min<uint64_t>(wanted, budget_left / cost);
        if (count == 0) {
            // Strict turns: an entry that cannot be served ends the frame rather than let
            // cheaper ones behind it go first, and the next frame's round starts with it.
            if (is_old && !cursor_moved) cursor_ = id;
            break;
        }

        RasterWork& work = work_.emplace_back();
        work.entry = id;
        work.key = slot.entry.key;
        work.x = slot.entry.x;
        work.y = slot.entry.y;
        work.width = slot.entry.part.width;
        work.height = slot.entry.part.height;
        work.part_x = slot.entry.part.x;
        work.part_y = slot.entry.part.y;
        work.texel_count = work.width * work.height;
        work.first_sample = slot.entry.samples;
        work.sample_count = static_cast<uint32_t>(count);
        work.curve_tests = count * cost;  // <= budget_left
        slot.entry.samples += work.sample_count;
        ++slot.served_frames;
        budget_left -= work.curve_tests;
        count_work(work);
        if (is_old && count < wanted && !cursor_moved) {
            cursor_ = id;
            cursor_moved = true;
        }
    }
    // What the others left goes to the split entries, in the same order. Each of them got no
    // piece yet or is inside a sample, so a piece never overlaps one given this frame. An entry
    // that no budget pays one texel for gets one texel alone, as an overrun.
    for (uint32_t id : split_ids_) budget_left -= schedule_split(id, budget_left, work_.empty());
    return work_;
}

void GlyphAtlas::abandon_frame() {
    if (!scheduled_) return;
    for (const Undo& u : undo_) {
        Slot& slot = slots_[u.id];
        if (!slot.resident) continue;
        slot.entry.samples = u.samples;
        slot.entry.split_texels_done = u.split_texels_done;
        slot.served_frames = u.served_frames;
    }
    undo_.clear();
    cursor_ = undo_cursor_;
    work_.clear();
    total_counters_.samples -= frame_counters_.samples;
    total_counters_.curve_tests -= std::min(total_counters_.curve_tests, frame_counters_.curve_tests);
    total_counters_.split_pieces -= frame_counters_.split_pieces;
    total_counters_.budget_overruns -= frame_counters_.budget_overruns;
    frame_counters_.samples = frame_counters_.curve_tests = 0;
    frame_counters_.split_pieces = frame_counters_.budget_overruns = 0;
}

void GlyphAtlas::invalidate_samples() {
    for (Slot& slot : slots_) {
        slot.entry.samples = 0;
        slot.entry.split_texels_done = 0;
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
    for (size_t w = 0; w < pinned_words_.size(); ++w)
        stats.pinned_cells += static_cast<uint32_t>(std::popcount(pinned_words_[w] & ~permanent_words_[w]));
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
