// The atlas's sample schedule: which resident glyphs get samples this frame, within the budget,
// and the undo of a frame whose work never ran. Placement and residency are in atlas.cpp.
#include <crisp/atlas.hpp>

#include "atlas/state.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <limits>

namespace crisp {

namespace {

// Counters are fed caller-supplied costs; a saturated total is more useful than a wrapped one.
uint64_t add_saturating(uint64_t a, uint64_t b) {
    constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
    return a > kMax - b ? kMax : a + b;
}

}  // namespace

// The samples an entry wants this frame: enough to reach its ramp's running total (so a glyph
// cut short by the budget catches up), or `steady` past the ramp; never past max_samples.
uint32_t GlyphAtlas::State::share(const Slot& slot) const {
    const uint32_t samples = slot.entry.samples;
    uint64_t want = config.steady;
    if (slot.served_frames < ramp_totals.size() && ramp_totals[slot.served_frames] > samples)
        want = ramp_totals[slot.served_frames] - samples;
    return static_cast<uint32_t>(std::min<uint64_t>(want, config.max_samples - samples));
}

// Counts a work item: its samples once they cover the whole part, its cost at once.
void GlyphAtlas::State::count_work(const RasterWork& work) {
    if (std::none_of(undo.begin(), undo.end(), [&](const Undo& u) { return u.id == work.entry; })) {
        // The entry's state before this item: the item's first sample, and the texels done
        // before it (for a piece that finished its sample the entry has moved on since).
        const Slot& slot = slots[work.entry];
        const bool finished = slot.entry.samples != work.first_sample;
        undo.push_back(
            {work.entry, work.first_sample, work.first_texel, finished ? slot.served_frames - 1 : slot.served_frames});
    }
    const bool finishes = work.first_texel + work.texel_count == work.width * work.height;
    if (finishes) {
        frame_counters.samples += work.sample_count;
        total_counters.samples += work.sample_count;
    }
    if (work.texel_count < work.width * work.height) {
        ++frame_counters.split_pieces;
        ++total_counters.split_pieces;
    }
    frame_counters.curve_tests = add_saturating(frame_counters.curve_tests, work.curve_tests);
    total_counters.curve_tests = add_saturating(total_counters.curve_tests, work.curve_tests);
}

// One sample of an entry that no frame's budget pays for, in pieces of texels: the texels that
// `allowance` pays for (at the cost per texel rounded up), continuing where the last piece stopped.
// When not even one texel fits, the entry gets one texel anyway if `force` (a budget overrun),
// else nothing. Returns the curve tests spent.
uint64_t GlyphAtlas::State::schedule_split(uint32_t id, uint64_t allowance, bool force) {
    Slot& slot = slots[id];
    AtlasEntry& entry = slot.entry;
    const uint64_t texels = uint64_t{entry.part.width} * entry.part.height;
    const uint64_t per_texel = std::max<uint64_t>((entry.curve_tests_per_sample + texels - 1) / texels, 1);
    uint64_t count = std::min(texels - entry.split_texels_done, allowance / per_texel);
    const bool overrun = count == 0 && force;
    if (count == 0 && !overrun) return 0;
    if (overrun) count = 1;
    RasterWork& work = work_list.emplace_back();
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
        ++frame_counters.budget_overruns;
        ++total_counters.budget_overruns;
    }
    return work.curve_tests;
}

GlyphAtlas::State::FirstFrame GlyphAtlas::State::fit_first_frame(size_t new_count) const {
    FirstFrame fit;
    uint64_t cost_sum = 0;  // of one sample of every new entry that is not split
    uint32_t step = 0;
    for (size_t i = 0; i < new_count; ++i) {
        const Slot& slot = slots[waiting_ids[i]];
        const uint64_t cost = slot.entry.curve_tests_per_sample;
        if (cost > config.frame_budget || slot.entry.split_texels_done > 0) continue;  // split: its own turns
        cost_sum += cost;
        step = std::max(step, share(slot));
    }
    fit.samples = step;
    if (cost_sum == 0) return fit;
    const uint64_t budget = config.frame_budget;
    if (cost_sum > budget / std::max<uint32_t>(step, 1)) {
        // The largest power of two that fits for all; 1 when even one each does not (strict turns).
        const uint64_t affordable = std::max<uint64_t>(budget / cost_sum, 1);
        fit.samples = std::bit_floor(static_cast<uint32_t>(std::min<uint64_t>(affordable, step)));
        fit.spare = budget - std::min(budget, cost_sum * fit.samples);
    }
    return fit;
}

std::span<const RasterWork> GlyphAtlas::State::schedule() {
    if (scheduled) return work_list;
    scheduled = true;
    undo.clear();
    undo_cursor = cursor;

    // New entries first, in acquire order: they have nothing to show yet.
    waiting_ids.clear();
    for (uint32_t id : pinned_ids)
        if (slots[id].entry.samples == 0) waiting_ids.push_back(id);
    const size_t new_count = waiting_ids.size();
    // Then the rest by id, starting at the cursor and wrapping around.
    for (uint32_t id : pinned_ids) {
        const uint32_t samples = slots[id].entry.samples;
        if (samples > 0 && samples < config.max_samples) waiting_ids.push_back(id);
    }
    const auto old_begin = waiting_ids.begin() + static_cast<std::ptrdiff_t>(new_count);
    std::sort(old_begin, waiting_ids.end());
    std::rotate(old_begin, std::lower_bound(old_begin, waiting_ids.end(), cursor), waiting_ids.end());

    uint64_t budget_left = config.frame_budget;
    // Split entries share at most half the budget while others wait, and the rest of it after.
    uint64_t split_left = std::max<uint64_t>(config.frame_budget / 2, 1);
    FirstFrame first = fit_first_frame(new_count);
    split_ids.clear();
    bool cursor_moved = false;
    for (size_t i = 0; i < waiting_ids.size(); ++i) {
        const uint32_t id = waiting_ids[i];
        Slot& slot = slots[id];
        const bool is_old = i >= new_count;
        const uint64_t cost = slot.entry.curve_tests_per_sample;
        if (cost > config.frame_budget || slot.entry.split_texels_done > 0) {
            const uint64_t spent = schedule_split(id, std::min(budget_left, split_left), false);
            budget_left -= spent;
            split_left -= std::min(split_left, spent);
            if (slot.entry.split_texels_done > 0 || spent == 0) {
                split_ids.push_back(id);
                if (is_old && !cursor_moved) {
                    cursor = id;
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
            if (is_old && !cursor_moved) cursor = id;
            break;
        }

        RasterWork& work = work_list.emplace_back();
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
            cursor = id;
            cursor_moved = true;
        }
    }
    // What the others left goes to the split entries, in the same order. Each of them got no
    // piece yet or is inside a sample, so a piece never overlaps one given this frame. An entry
    // that no budget pays one texel for gets one texel alone, as an overrun.
    for (uint32_t id : split_ids) budget_left -= schedule_split(id, budget_left, work_list.empty());
    return work_list;
}

void GlyphAtlas::State::abandon_frame() {
    if (!scheduled) return;
    for (const Undo& u : undo) {
        Slot& slot = slots[u.id];
        if (!slot.resident) continue;
        slot.entry.samples = u.samples;
        slot.entry.split_texels_done = u.split_texels_done;
        slot.served_frames = u.served_frames;
    }
    undo.clear();
    cursor = undo_cursor;
    work_list.clear();
    total_counters.samples -= frame_counters.samples;
    total_counters.curve_tests -= std::min(total_counters.curve_tests, frame_counters.curve_tests);
    total_counters.split_pieces -= frame_counters.split_pieces;
    total_counters.budget_overruns -= frame_counters.budget_overruns;
    frame_counters.samples = frame_counters.curve_tests = 0;
    frame_counters.split_pieces = frame_counters.budget_overruns = 0;
}

std::span<const RasterWork> GlyphAtlas::schedule() {
    return state_->schedule();
}

void GlyphAtlas::abandon_frame() {
    state_->abandon_frame();
}

void GlyphAtlas::invalidate_samples() {
    for (State::Slot& slot : state_->slots) {
        slot.entry.samples = 0;
        slot.entry.split_texels_done = 0;
        slot.served_frames = 0;
    }
}

void GlyphAtlas::set_frame_budget(uint64_t curve_tests) {
    assert(curve_tests > 0);
    state_->config.frame_budget = std::max<uint64_t>(curve_tests, 1);
}

}  // namespace crisp
