// The atlas's placement and residency: N-order blocks in bitsets of cells, LRU eviction, growth.
// The sample schedule is in schedule.cpp.
#include <crisp/atlas.hpp>

#include "atlas/morton.hpp"
#include "atlas/state.hpp"

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

    auto state = std::make_unique<State>();
    state->config = config;
    state->cells_x = config.width / kAtlasCellSize;
    state->cells_y = config.height / kAtlasCellSize;
    state->usable_cells = state->cells_x * state->cells_y;
    state->find_outside_cells();
    state->used_words = state->permanent_words;
    state->pinned_words = state->permanent_words;
    state->skip_full_words();

    uint64_t total = 0;
    for (uint32_t samples : config.ramp) state->ramp_totals.push_back(total += samples);
    return GlyphAtlas(std::move(state));
}

GlyphAtlas::GlyphAtlas(std::unique_ptr<State> state) : state_(std::move(state)) {}
GlyphAtlas::GlyphAtlas(const GlyphAtlas& other) : state_(std::make_unique<State>(*other.state_)) {}
GlyphAtlas& GlyphAtlas::operator=(const GlyphAtlas& other) {
    if (this != &other) state_ = std::make_unique<State>(*other.state_);
    return *this;
}
GlyphAtlas::GlyphAtlas(GlyphAtlas&& other) noexcept = default;
GlyphAtlas& GlyphAtlas::operator=(GlyphAtlas&& other) noexcept = default;
GlyphAtlas::~GlyphAtlas() = default;

// The index space is the square of the longer side; in a non-square atlas the indices that
// decode outside it, and the pad bits of a last word shorter than 64 cells, are never free.
void GlyphAtlas::State::find_outside_cells() {
    const uint32_t side = std::max(cells_x, cells_y);
    const uint32_t index_count = side * side;
    permanent_words.assign((index_count + 63) / 64, 0);
    if (cells_x != cells_y) {
        for (uint32_t i = 0; i < index_count; ++i) {
            const CellCoord cell = n_order_decode(i);
            if (cell.x >= cells_x || cell.y >= cells_y) permanent_words[i / 64] |= uint64_t{1} << (i % 64);
        }
    }
    if (index_count % 64 != 0) permanent_words.back() |= kFullWord << (index_count % 64);
}

void GlyphAtlas::State::skip_full_words() {
    const auto word_count = static_cast<uint32_t>(used_words.size());
    while (first_free_word < word_count && used_words[first_free_word] == kFullWord) ++first_free_word;
}

bool GlyphAtlas::State::grow() {
    if (config.width * 2 > kAtlasMaxSize || config.height * 2 > kAtlasMaxSize) return false;
    const std::vector<uint64_t> old_permanent = permanent_words;
    std::vector<uint64_t> old_used = used_words, old_pinned = pinned_words;
    config.width *= 2;
    config.height *= 2;
    cells_x *= 2;
    cells_y *= 2;
    usable_cells = cells_x * cells_y;
    // The new index space's cells outside the atlas (non-square or tiny atlases), as create() finds them.
    find_outside_cells();
    // The old cells keep their state: what entries own or pin, without the old outside bits.
    used_words = permanent_words;
    pinned_words = permanent_words;
    for (size_t w = 0; w < old_permanent.size(); ++w) {
        used_words[w] |= old_used[w] & ~old_permanent[w];
        pinned_words[w] |= old_pinned[w] & ~old_permanent[w];
    }
    first_free_word = 0;
    skip_full_words();
    block_used.clear();
    return true;
}

void GlyphAtlas::State::begin_frame() {
    ++frame;
    pinned_words = permanent_words;
    pinned_ids.clear();
    work_list.clear();
    scheduled = false;
    frame_counters = {};
}

void GlyphAtlas::State::lru_unlink(uint32_t id) {
    Slot& slot = slots[id];
    if (slot.lru_prev != kNoAtlasEntry)
        slots[slot.lru_prev].lru_next = slot.lru_next;
    else
        lru_head = slot.lru_next;
    if (slot.lru_next != kNoAtlasEntry)
        slots[slot.lru_next].lru_prev = slot.lru_prev;
    else
        lru_tail = slot.lru_prev;
    slot.lru_prev = slot.lru_next = kNoAtlasEntry;
}

void GlyphAtlas::State::lru_push_front(uint32_t id) {
    Slot& slot = slots[id];
    slot.lru_prev = kNoAtlasEntry;
    slot.lru_next = lru_head;
    if (lru_head != kNoAtlasEntry)
        slots[lru_head].lru_prev = id;
    else
        lru_tail = id;
    lru_head = id;
}

// Pinned entries gather at the front of the LRU list, so the tail is the least recently used
// unpinned entry whenever there is one.
void GlyphAtlas::State::pin(uint32_t id) {
    Slot& slot = slots[id];
    if (pinned(slot)) return;
    slot.entry.last_used_frame = frame;
    set_range(pinned_words, slot.first_bit, slot.bit_count, true);
    pinned_ids.push_back(id);
    lru_unlink(id);
    lru_push_front(id);
}

void GlyphAtlas::State::mark_cells(uint32_t first_bit, uint32_t bit_count, bool used) {
    set_range(used_words, first_bit, bit_count, used);
    if (used) {
        used_cells += bit_count;
        skip_full_words();
    } else {
        used_cells -= bit_count;
        first_free_word = std::min(first_free_word, first_bit / 64);
    }
}

uint32_t GlyphAtlas::State::find_block(uint32_t bit_count) const {
    // Words below first_free_word are full, so no run can start there.
    return find_clear_run(used_words, bit_count, first_free_word);
}

void GlyphAtlas::State::evict(uint32_t id) {
    Slot& slot = slots[id];
    assert(slot.resident && !pinned(slot));
    mark_cells(slot.first_bit, slot.bit_count, false);
    ids_by_key.erase(slot.entry.key);
    lru_unlink(id);
    slot.resident = false;
    free_ids.push_back(id);
    ++frame_counters.evictions;
    ++total_counters.evictions;
}

void GlyphAtlas::State::evict_font(FontId font) {
    for (uint32_t id = 0; id < slots.size(); ++id) {
        if (slots[id].resident && slots[id].entry.key.font == font && !pinned(slots[id])) evict(id);
    }
}

// Called when no free block of bit_count cells exists. Returns the block freed by evicting
// unpinned entries least recently used first, or kNotFound having evicted nothing.
uint32_t GlyphAtlas::State::make_room(uint32_t bit_count) {
    if (lru_tail == kNoAtlasEntry || pinned(slots[lru_tail])) return kNotFound;
    // Evicting every unpinned entry would leave only the pinned cells taken. If they leave no
    // block, eviction cannot help: fail now and keep the unpinned glyphs for later frames.
    if (find_clear_run(pinned_words, bit_count, 0) == kNotFound) return kNotFound;
    // Blocks of 64 cells or more keep a count of their used cells, taken the first time an
    // eviction touches them, so that evicting thousands of small glyphs for one large block
    // costs O(cells / 64) in all rather than that much per eviction.
    const bool count_blocks = bit_count >= 64;
    if (count_blocks) block_used.assign(used_words.size() * 64 / bit_count, kNotFound);
    for (;;) {
        const uint32_t victim = lru_tail;
        // The pinned-cells check above guarantees a block appears before the unpinned run out.
        assert(victim != kNoAtlasEntry && !pinned(slots[victim]));
        if (victim == kNoAtlasEntry || pinned(slots[victim])) return kNotFound;
        const uint32_t freed_first = slots[victim].first_bit;
        const uint32_t freed_count = slots[victim].bit_count;
        evict(victim);
        // No block was free before this eviction, so a block can only have appeared where the
        // freed cells are: the freed block itself if it is big enough, else the aligned block
        // of bit_count cells around it (blocks are aligned powers of two, so they nest).
        if (freed_count >= bit_count) return freed_first;
        const uint32_t candidate = freed_first & ~(bit_count - 1);
        if (!count_blocks) {
            if (range_clear(used_words, candidate, bit_count)) return candidate;
            continue;
        }
        uint32_t& used = block_used[candidate / bit_count];
        if (used == kNotFound) {
            used = 0;
            for (uint32_t w = candidate / 64; w < (candidate + bit_count) / 64; ++w)
                used += static_cast<uint32_t>(std::popcount(used_words[w]));
        } else {
            used -= freed_count;
        }
        if (used == 0) return candidate;
    }
}

AtlasLookup GlyphAtlas::State::acquire(const GlyphKey& key, uint32_t width, uint32_t height,
                                       uint64_t curve_tests_per_sample, const TexelRect& visible) {
    const uint32_t x0 = std::min(visible.x, width), y0 = std::min(visible.y, height);
    const uint32_t x1 = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{visible.x} + visible.width, width));
    const uint32_t y1 = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{visible.y} + visible.height, height));
    if (x0 >= x1 || y0 >= y1) return {};

    if (const auto found = ids_by_key.find(key); found != ids_by_key.end()) {
        const uint32_t id = found->second;
        Slot& slot = slots[id];
        assert(slot.entry.width == width && slot.entry.height == height && "equal keys need equal rects");
        const TexelRect& held = slot.entry.part;
        const bool holds = x0 >= held.x && y0 >= held.y && x1 <= held.x + held.width && y1 <= held.y + held.height;
        if (holds || pinned(slot)) {
            pin(id);
            ++frame_counters.hits;
            ++total_counters.hits;
            return lookup_of(id);
        }
        evict(id);
        ++frame_counters.parts_replaced;
        ++total_counters.parts_replaced;
    }
    // The part held: the visible texels and a margin, unless that is the whole rect anyway.
    TexelRect part;
    part.x = x0 > kAtlasPartMargin ? x0 - kAtlasPartMargin : 0;
    part.y = y0 > kAtlasPartMargin ? y0 - kAtlasPartMargin : 0;
    part.width = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{x1} + kAtlasPartMargin, width) - part.x);
    part.height = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{y1} + kAtlasPartMargin, height) - part.y);
    return place(key, width, height, curve_tests_per_sample, part);
}

AtlasLookup GlyphAtlas::State::lookup_of(uint32_t id) const {
    const AtlasEntry& entry = slots[id].entry;
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

AtlasLookup GlyphAtlas::State::place(const GlyphKey& key, uint32_t width, uint32_t height,
                                     uint64_t curve_tests_per_sample, const TexelRect& part) {
    AtlasLookup lookup;
    const AtlasBlock block = atlas_block(part.width, part.height);
    const uint64_t block_x = block.cells_x, block_y = block.cells_y;
    if (block_x > cells_x || block_y > cells_y) {
        lookup.status = AtlasStatus::too_large;
        ++frame_counters.failed_too_large;
        ++total_counters.failed_too_large;
        return lookup;
    }
    const auto bit_count = static_cast<uint32_t>(block_x * block_y);
    uint32_t first_bit = find_block(bit_count);
    if (first_bit == kNotFound) first_bit = make_room(bit_count);
    if (first_bit == kNotFound) {
        lookup.status = AtlasStatus::atlas_full;
        ++frame_counters.failed_full;
        ++total_counters.failed_full;
        return lookup;
    }

    uint32_t id = kNoAtlasEntry;
    if (!free_ids.empty()) {
        id = free_ids.back();
        free_ids.pop_back();
    } else {
        id = static_cast<uint32_t>(slots.size());
        slots.emplace_back();
    }
    Slot& slot = slots[id];
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
    slot.entry.last_used_frame = frame;
    slot.first_bit = first_bit;
    slot.bit_count = bit_count;
    slot.resident = true;
    mark_cells(first_bit, bit_count, true);
    set_range(pinned_words, first_bit, bit_count, true);
    pinned_ids.push_back(id);
    lru_push_front(id);
    ids_by_key.emplace(key, id);
    ++frame_counters.allocations;
    ++total_counters.allocations;
    return lookup_of(id);
}

// ---- The public face: each call on the state, with no work of its own.

void GlyphAtlas::begin_frame() {
    state_->begin_frame();
}

AtlasLookup GlyphAtlas::acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample) {
    return state_->acquire(key, width, height, curve_tests_per_sample, TexelRect{0, 0, width, height});
}

AtlasLookup GlyphAtlas::acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                                const TexelRect& visible) {
    return state_->acquire(key, width, height, curve_tests_per_sample, visible);
}

bool GlyphAtlas::grow() {
    return state_->grow();
}

void GlyphAtlas::evict_font(FontId font) {
    state_->evict_font(font);
}

uint32_t GlyphAtlas::find(const GlyphKey& key) const {
    const auto found = state_->ids_by_key.find(key);
    return found == state_->ids_by_key.end() ? kNoAtlasEntry : found->second;
}

const AtlasEntry* GlyphAtlas::entry(uint32_t id) const {
    const std::vector<State::Slot>& slots = state_->slots;
    if (id >= slots.size() || !slots[id].resident) return nullptr;
    return &slots[id].entry;
}

uint32_t GlyphAtlas::entry_capacity() const {
    return static_cast<uint32_t>(state_->slots.size());
}

const AtlasConfig& GlyphAtlas::config() const {
    return state_->config;
}

uint64_t GlyphAtlas::frame() const {
    return state_->frame;
}

AtlasStats GlyphAtlas::stats() const {
    const State& s = *state_;
    AtlasStats stats;
    stats.usable_cells = s.usable_cells;
    stats.used_cells = s.used_cells;
    for (size_t w = 0; w < s.pinned_words.size(); ++w)
        stats.pinned_cells += static_cast<uint32_t>(std::popcount(s.pinned_words[w] & ~s.permanent_words[w]));
    stats.occupancy = static_cast<float>(s.used_cells) / static_cast<float>(s.usable_cells);
    stats.resident_glyphs = static_cast<uint32_t>(s.ids_by_key.size());
    stats.pinned_glyphs = static_cast<uint32_t>(s.pinned_ids.size());
    for (uint32_t id : s.pinned_ids)
        if (s.slots[id].entry.samples < s.config.max_samples) ++stats.refining_glyphs;
    stats.frame = s.frame_counters;
    stats.total = s.total_counters;
    return stats;
}

}  // namespace crisp
