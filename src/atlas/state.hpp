// GlyphAtlas's state and the algorithms over it, private to src/atlas/: placement and residency
// in atlas.cpp, the sample schedule in schedule.cpp.
#pragma once

#include <crisp/atlas.hpp>

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace crisp {

struct CRISP_HIDDEN GlyphAtlas::State {
    struct Slot {
        AtlasEntry entry;
        uint32_t first_bit = 0;             // N-order index of the block's first cell
        uint32_t bit_count = 0;             // cells in the block
        uint32_t served_frames = 0;         // frames that scheduled samples since the last reset
        uint32_t lru_prev = kNoAtlasEntry;  // towards more recently used
        uint32_t lru_next = kNoAtlasEntry;  // towards less recently used
        bool resident = false;
    };

    // Placement and residency (atlas.cpp).
    void begin_frame();
    AtlasLookup acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                        const TexelRect& visible);
    bool grow();
    void find_outside_cells();  // permanent_words from cells_x and cells_y
    void skip_full_words();     // first_free_word past the full words of used_words
    void evict_font(FontId font);
    bool pinned(const Slot& slot) const { return slot.entry.last_used_frame == frame; }
    void pin(uint32_t id);
    void lru_unlink(uint32_t id);
    void lru_push_front(uint32_t id);
    void mark_cells(uint32_t first_bit, uint32_t bit_count, bool used);
    uint32_t find_block(uint32_t bit_count) const;
    uint32_t make_room(uint32_t bit_count);
    void evict(uint32_t id);
    AtlasLookup lookup_of(uint32_t id) const;
    AtlasLookup place(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                      const TexelRect& part);

    // The sample schedule (schedule.cpp).
    std::span<const RasterWork> schedule();
    void abandon_frame();
    uint32_t share(const Slot& slot) const;
    // The new entries' first frame (waiting_ids[0, new_count)): `samples` each (the first ramp
    // step, or the power of two below it that fits the budget for all), and `spare` curve tests
    // that can bring some of them, in order, to their whole step.
    struct FirstFrame {
        uint32_t samples = 0;
        uint64_t spare = 0;
    };
    FirstFrame fit_first_frame(size_t new_count) const;
    uint64_t schedule_split(uint32_t id, uint64_t allowance, bool force);
    void count_work(const RasterWork& work);

    AtlasConfig config;
    uint32_t cells_x = 0;
    uint32_t cells_y = 0;
    uint32_t usable_cells = 0;
    uint32_t used_cells = 0;
    std::vector<uint64_t> used_words;       // bit i set: N-order cell i is taken or outside the atlas
    std::vector<uint64_t> pinned_words;     // bit i set: cell i is pinned this frame or outside
    std::vector<uint64_t> permanent_words;  // bit i set: cell i is outside the atlas
    uint32_t first_free_word = 0;           // every used_words word below it is full
    std::vector<uint64_t> ramp_totals;      // ramp_totals[k] = ramp[0] + ... + ramp[k]
    std::vector<uint32_t> block_used;       // scratch for make_room(): used cells per block

    std::vector<Slot> slots;
    std::vector<uint32_t> free_ids;
    std::unordered_map<GlyphKey, uint32_t, GlyphKeyHash> ids_by_key;
    uint32_t lru_head = kNoAtlasEntry;  // most recently used
    uint32_t lru_tail = kNoAtlasEntry;  // least recently used

    uint64_t frame = 0;
    std::vector<uint32_t> pinned_ids;   // pinned this frame, in acquire order
    std::vector<uint32_t> waiting_ids;  // scratch for schedule()
    std::vector<uint32_t> split_ids;    // scratch for schedule(): split entries short of their piece
    uint32_t cursor = 0;                // entry id the next frame's round starts at
    bool scheduled = false;
    std::vector<RasterWork> work_list;
    struct Undo {
        uint32_t id = 0;
        uint32_t samples = 0;
        uint32_t split_texels_done = 0;
        uint32_t served_frames = 0;
    };
    std::vector<Undo> undo;  // the entries' state before this frame's schedule()
    uint32_t undo_cursor = 0;
    AtlasCounters frame_counters;
    AtlasCounters total_counters;
};

}  // namespace crisp
