// crisp: the glyph atlas, CPU side. docs/atlas.md explains how it works.
//
// The atlas decides where each glyph's accumulators live in the atlas image and how many samples
// the rasterizer adds to each glyph in each frame. It owns no GPU object and never calls the
// renderer: per frame it takes the glyphs to draw and returns a list of raster work.
//
// Space. The atlas is cut into cells of kAtlasCellSize x kAtlasCellSize texels. A glyph's rect is
// rounded up to a power-of-two number of cells per axis and takes a block that is square or twice
// as tall as wide (a 10x30 texel rect takes 1x2 cells, 16x32 texels): an aligned run of 1, 2, 4,
// ... bits in a bitset of free cells whose index runs along a transposed Z-order curve (N-order).
//
// Residency. Glyphs are found by GlyphKey. A glyph acquired in the current frame is pinned: it is
// never evicted before the next begin_frame(). Glyphs not used this frame stay resident while the
// space allows and are evicted least-recently-used when a new glyph needs room.
//
// Samples. Every resident glyph counts the samples accumulated in its rect. A glyph drawn this
// frame and short of AtlasConfig::max_samples gets more: the ramp (8, 4, 2 by default) in its
// first frames, then `steady` (1) per frame, within a per-frame budget of curve tests.
//
// A frame:
//
//     atlas.begin_frame();
//     for (each glyph instance to draw) {
//         AtlasLookup lookup = atlas.acquire(key, rect.width, rect.height, curve_tests_per_sample);
//         if (lookup.status == AtlasStatus::placed) remember lookup.entry for the quad;
//         else skip the glyph (empty: nothing to draw; atlas_full, too_large: report it)
//     }
//     std::span<const RasterWork> work = atlas.schedule();  // record the rasterizer dispatch
//     draw the quads whose entry holds samples > 0
//
// Not thread-safe: one thread drives an atlas. An atlas is a plain value (copyable and movable);
// it holds no global state, so a program may keep several.
#pragma once

#include <crisp/export.hpp>

#include <crisp/glyph.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace crisp {

inline constexpr uint32_t kAtlasCellSize = 16;    // texels per cell side
inline constexpr uint32_t kAtlasMinSize = 16;     // one cell
inline constexpr uint32_t kAtlasMaxSize = 16384;  // Vulkan's common maxImageDimension2D
// The rasterizer places sample n at frac(0.5 + n * alpha) in float; past 2^16 the product loses
// the bits that separate neighbouring samples.
inline constexpr uint32_t kAtlasMaxSamples = 65536;

inline constexpr uint32_t kNoAtlasEntry = 0xFFFFFFFFu;

// A glyph acquired with a visible part holds that part grown by this many texels per side
// (within its rect), so that text scrolled by a little keeps its entry and its samples.
inline constexpr uint32_t kAtlasPartMargin = kAtlasCellSize;

struct AtlasConfig {
    // Atlas image size in texels: each a power of two from kAtlasMinSize to kAtlasMaxSize.
    // Width and height may differ; blocks are never wider than tall, so in a wide atlas the
    // largest glyph is limited by the height (see AtlasStatus::too_large).
    uint32_t width = 2048;
    uint32_t height = 2048;
    // Samples a glyph gets in its first frames on screen (index 0: the first frame), then
    // `steady` per frame until it holds `max_samples`. A glyph cut short by the budget catches
    // up: in its k-th served frame it is brought to ramp[0] + ... + ramp[k] samples.
    // Each entry in [1, max_samples]; the ramp may be empty.
    std::vector<uint32_t> ramp = {8, 4, 2};
    uint32_t steady = 1;         // in [1, max_samples]
    uint32_t max_samples = 512;  // in [1, kAtlasMaxSamples]
    // Curve tests the rasterizer may spend per frame (one sample of a glyph costs its
    // curve_tests_per_sample). On an H200 a curve test of row samples costs about 7 ps of raster
    // time (a new 4K screen of 16 px text: 7.6e7 tests in 0.53 ms), so 2^26 is about 0.48 ms
    // there; slower GPUs should lower it (set_frame_budget, from their own timings). New text
    // that does not fit takes fewer samples in its first frame (see schedule()). At least 1.
    uint64_t frame_budget = uint64_t{1} << 26;
};

enum class AtlasStatus : uint8_t {
    placed,      // the glyph has an entry; entry, x, y, width and height are valid
    empty,       // the rect has no area (a space): nothing to draw, nothing allocated
    atlas_full,  // glyphs pinned this frame leave no block of the needed size; nothing was evicted
    too_large,   // the glyph's block is larger than the atlas; it can never be placed
};

// Short stable name of a status ("atlas_full"), for logs and JSON.
CRISP_API const char* atlas_status_name(AtlasStatus status);

// The block of cells a rect of width x height texels takes in the atlas: cells per axis rounded up
// to powers of two, then square or twice as tall as wide. For sizing an atlas before the glyphs
// arrive. Any sizes are accepted; a zero side takes one cell on that axis.
struct AtlasBlock {
    uint32_t cells_x = 0;
    uint32_t cells_y = 0;
};
CRISP_API AtlasBlock atlas_block(uint32_t width, uint32_t height);

// A rectangle of texels within a glyph's rect: (0, 0) is the rect's top-left texel.
struct TexelRect {
    uint32_t x = 0;
    uint32_t y = 0;
    uint32_t width = 0;
    uint32_t height = 0;
};

struct AtlasLookup {
    AtlasStatus status = AtlasStatus::empty;
    uint32_t entry = kNoAtlasEntry;  // id of the entry while it stays resident; kNoAtlasEntry unless placed
    uint32_t x = 0;                  // texel of the part's top-left corner in the atlas
    uint32_t y = 0;
    uint32_t width = 0;  // the glyph rect, texels
    uint32_t height = 0;
    TexelRect part;  // the part of the glyph rect the entry holds (the whole rect unless clipped)
};

// A resident glyph, read-only.
struct AtlasEntry {
    GlyphKey key;
    uint32_t x = 0;  // texel of the block's (and the part's) top-left corner
    uint32_t y = 0;
    uint32_t width = 0;  // the glyph rect, texels
    uint32_t height = 0;
    // The part of the rect the entry holds: the whole rect, or for a glyph acquired with a
    // visible part, that part grown by up to kAtlasPartMargin texels per side.
    TexelRect part;
    uint32_t block_width = 0;   // the cells the entry owns, texels: the part rounded up to
    uint32_t block_height = 0;  // powers of two of cells, height = width or 2 * width
    // One sample over the part: the acquire()d cost of the whole rect scaled by the part's share
    // of its texels (rounded up).
    uint64_t curve_tests_per_sample = 0;
    // Samples every texel of the part holds, counting those of this frame's schedule() once it
    // ran. Texels of a split sample already done hold one more (see RasterWork).
    uint32_t samples = 0;
    uint32_t split_texels_done = 0;  // texels of the part that hold the split sample in progress
    uint64_t last_used_frame = 0;    // frame() when last acquired
};

// Samples the rasterizer adds to one entry this frame: sample indices first_sample to
// first_sample + sample_count - 1 of texels first_texel to first_texel + texel_count - 1 (row
// major) of the entry's part, width x height texels at (x, y) in the atlas and at (part_x, part_y)
// in the glyph rect. Usually the work covers the whole part; a glyph whose one sample costs more
// than the whole frame budget gets its sample in pieces of texels over several frames (a split
// sample), and its entry counts the sample once the last piece is scheduled.
// first_sample == 0 means the accumulators hold nothing of this glyph (a new entry, reused cells,
// or invalidate_samples()): the rasterizer must clear each texel before adding.
struct RasterWork {
    uint32_t entry = 0;
    GlyphKey key;
    uint32_t x = 0;
    uint32_t y = 0;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t part_x = 0;
    uint32_t part_y = 0;
    uint32_t first_texel = 0;
    uint32_t texel_count = 0;
    uint32_t first_sample = 0;
    uint32_t sample_count = 0;
    uint64_t curve_tests = 0;  // the atlas's estimate of this work's cost, counted in the budget
};

struct AtlasCounters {
    uint64_t hits = 0;              // acquire() found the glyph resident
    uint64_t allocations = 0;       // acquire() placed a new entry
    uint64_t evictions = 0;         // unpinned entries evicted to make room
    uint64_t failed_full = 0;       // acquire() calls answered atlas_full
    uint64_t failed_too_large = 0;  // acquire() calls answered too_large
    uint64_t samples = 0;           // samples scheduled
    uint64_t curve_tests = 0;       // curve tests scheduled (samples times each entry's cost)
    uint64_t budget_overruns = 0;   // frames whose single forced texel sample exceeded the budget
    uint64_t split_pieces = 0;      // work items that hold part of a split sample
    uint64_t parts_replaced = 0;    // entries placed anew because the visible part left the held one
};

struct AtlasStats {
    uint32_t usable_cells = 0;  // cells inside the atlas
    uint32_t used_cells = 0;    // cells owned by resident entries
    uint32_t pinned_cells = 0;  // cells owned by entries acquired this frame
    float occupancy = 0.0f;     // used_cells / usable_cells
    uint32_t resident_glyphs = 0;
    uint32_t pinned_glyphs = 0;    // acquired this frame
    uint32_t refining_glyphs = 0;  // pinned and short of max_samples
    AtlasCounters frame;           // since the last begin_frame()
    AtlasCounters total;           // since create()
};

class CRISP_API GlyphAtlas {
public:
    // Makes an empty atlas in frame 0. A size that is not a power of two in [kAtlasMinSize,
    // kAtlasMaxSize], a ramp or steady value outside [1, max_samples], max_samples outside
    // [1, kAtlasMaxSamples] or a frame_budget of 0 returns ErrorCode::invalid_argument naming it.
    static Result<GlyphAtlas> create(const AtlasConfig& config = {});

    // An atlas is a value: a copy is a deep copy, independent of the original. A moved-from atlas
    // may only be assigned to or destroyed.
    GlyphAtlas(const GlyphAtlas& other);
    GlyphAtlas& operator=(const GlyphAtlas& other);
    GlyphAtlas(GlyphAtlas&& other) noexcept;
    GlyphAtlas& operator=(GlyphAtlas&& other) noexcept;
    ~GlyphAtlas();

    // Ends the current frame and starts the next: unpins every entry, clears the work list and
    // the per-frame counters.
    void begin_frame();

    // Finds or places the glyph `key` whose rect is width x height texels and costs
    // curve_tests_per_sample curve tests per sample (over the whole rect), and pins it for this
    // frame. Returns:
    // - placed: a resident entry (a hit, O(1)), or a new one with 0 samples. To make room it
    //   evicts unpinned entries, least recently used first, one at a time until the block fits.
    // - empty: width or height is 0; no entry.
    // - atlas_full: entries pinned this frame leave no free aligned block of the needed size.
    //   Nothing is evicted and nothing else changes: every glyph already placed keeps its
    //   entry, and the same request can succeed next frame.
    // - too_large: the block (rect rounded up to cells, powers of two, at least half as wide as
    //   tall) is wider or taller than the atlas. Such a glyph never fits; skip it.
    // Failures are counted in stats(). Equal keys must come with equal width and height (the
    // key determines the rect); a mismatch is a programmer error and asserts, and release builds
    // keep the first size. curve_tests_per_sample is read when the glyph is placed and ignored for a
    // resident one (the key determines the cost too), so callers may compute it only on a miss
    // (find() first). May be called after
    // schedule(): the glyph is pinned but gets samples from the next frame on.
    AtlasLookup acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample);

    // The same for a glyph of which only `visible` (texels of its rect; clipped to the rect) can
    // reach the target: the entry holds that part grown by kAtlasPartMargin per side, and only
    // its texels get samples. A resident entry whose part contains `visible` is a hit; one whose
    // part does not is evicted and placed anew with the new part (its samples are lost, and so is
    // the entry when the new part does not fit: counted in parts_replaced) unless it is pinned
    // this frame: a pinned entry never moves, and the lookup returns it as it is (lookup.part says
    // what it holds). Callers that draw one glyph several times in a frame should acquire it once
    // with the bounding box of the visible parts. `visible` empty after clipping: status empty,
    // nothing changes.
    AtlasLookup acquire(const GlyphKey& key, uint32_t width, uint32_t height, uint64_t curve_tests_per_sample,
                        const TexelRect& visible);

    // Decides this frame's samples and returns the work list; call once per frame after every
    // acquire(). Only entries pinned this frame and short of max_samples get samples: first the
    // new ones (0 samples) in acquire order, then the rest in turn from a cursor that rotates
    // over entry ids across frames, so with a steady set of glyphs none starves. When the new
    // entries' first ramp step does not fit the budget together, each gets the largest power of
    // two of samples (at most that step) that lets all of them fit, and those in acquire order
    // whose full step still fits the rest get it: new text shows whole in its first frame, its
    // samples a stratified prefix (a power of two of rows is stratified; 6 rows cost 1.5x 4 and
    // err about as much). Only where one sample each does not fit do some wait. An entry whose
    // share does not fit the rest of the budget gets the samples that fit; the first entry that
    // gets none ends the frame's list. An entry whose single sample costs more than the whole
    // budget is split: it gets the texels of one sample that its allowance pays for (at the cost
    // per texel rounded up), continued from where it stopped in later frames. Split entries share
    // at most half the budget while other entries wait, and whatever the others leave, so a
    // pathological glyph neither stalls the rest nor starves. The budget is never exceeded,
    // except when nothing else is scheduled and the first split entry cannot afford one sample of
    // a single texel: it gets that texel anyway (counted as a budget overrun), so every glyph
    // can be drawn.
    // The entries' sample counts include the returned work at once. A glyph still at 0 samples
    // after schedule() has nothing in its part (possibly another glyph's old accumulators): do
    // not draw it this frame. Calling schedule() again in the same frame returns the same list.
    // The span stays valid until the next begin_frame().
    std::span<const RasterWork> schedule();

    // Takes back this frame's schedule() when its work will never run (the renderer's frame was
    // dropped): every entry it gave work gets back its sample count, its split-sample progress and
    // its place in the ramp, the turn cursor goes back, and the work list empties; the counters
    // forget the frame's samples and curve tests. Entries placed or evicted by acquire() stay as
    // they are (a placed entry keeps 0 samples and is cleared by its next work). Without a
    // schedule() this frame it does nothing.
    void abandon_frame();

    // Doubles the atlas on both axes, keeping every entry where it is: entries are placed in
    // N-order over the cell grid, so the old grid is the first quarter of the new one's index
    // space and the new cells are free. The caller copies the old image into the top-left of an
    // image of the new config().width x height. False (nothing changes) when a side would pass
    // kAtlasMaxSize. May be called at any time; entries pinned and work scheduled stay valid.
    bool grow();

    // Evicts every resident entry of `font` (a font the caller no longer draws); call after
    // begin_frame() and before this frame's acquire()s. A font without entries changes nothing.
    void evict_font(FontId font);

    // Forgets every resident entry's samples (after a subpixel layout change, for example): each
    // restarts its ramp at sample 0, and its next work item clears the rect. Entries stay resident.
    // Work already returned by schedule() this frame stays valid to execute.
    void invalidate_samples();

    // Replaces AtlasConfig::frame_budget from the next schedule() on. 0 is a programmer error
    // (asserts; release builds use 1).
    void set_frame_budget(uint64_t curve_tests);

    // The resident entry with `key`, or kNoAtlasEntry. Neither pins nor touches the entry.
    uint32_t find(const GlyphKey& key) const;

    // The entry with id `id`, or nullptr when no resident entry has that id (ids of evicted
    // entries are reused by later ones). The pointer stays valid until the next acquire().
    const AtlasEntry* entry(uint32_t id) const;

    // Every resident entry's id is below this.
    uint32_t entry_capacity() const;

    AtlasStats stats() const;
    const AtlasConfig& config() const;
    uint64_t frame() const;

private:
    struct State;
    explicit GlyphAtlas(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

}  // namespace crisp
