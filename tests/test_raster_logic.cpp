// The renderer's CPU-only parts, without a device: draw requests (pen offsets, clipped parts,
// motion), the subpixel-step controller, and the rasterizer's work items.
#include "raster/coarsening.hpp"
#include "raster/held_fonts.hpp"
#include "raster/paints.hpp"
#include "raster/raster.hpp"
#include "raster/requests.hpp"
#include "test_support.hpp"

#include <crisp/atlas.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

namespace crisp {
namespace {

constexpr FontId kFontId = 3;

// The fonts a test holds, as the renderer's FontStore would hold them on the GPU.
class TestFonts final : public raster::HeldFonts {
public:
    const raster::HeldFont* find(FontId id) const override {
        const auto it = fonts.find(id);
        return it == fonts.end() ? nullptr : &it->second;
    }
    std::unordered_map<FontId, raster::HeldFont> fonts;
};

const Font& test_font() {
    static const std::unique_ptr<Font> font = test::bake_test_font("Hg", kFontId);
    EXPECT_TRUE(font);
    return *font;
}

// The first glyph of `text` laid out at `size` px with its pen at (x, y).
GlyphInstance glyph_at(float size, float x, float y, const char* text = "H") {
    const Font* fonts[] = {&test_font()};
    LayoutOptions options;
    options.origin_x = x;
    options.origin_y = y;
    Result<TextLayout> layout = layout_text(fonts, text, {.size = size}, options);
    EXPECT_TRUE(layout) << layout.error().message;
    EXPECT_FALSE(layout->glyphs.empty());
    return layout->glyphs.front();
}

const GlyphRecord& record_of(const GlyphInstance& glyph) {
    return test_font().asset().glyphs[glyph.key.glyph];
}

// Where an instance's pen is, in 1/256 px: its whole pixel (x less the rect's offset) and its key's step.
int64_t pen_steps(const GlyphInstance& glyph, int axis) {
    const GlyphRect rect = glyph_rect(record_of(glyph), glyph.key);
    const int64_t whole = axis == 0 ? glyph.x - rect.x : glyph.y - rect.y;
    return whole * kSubpixelSteps + (axis == 0 ? glyph.key.subpixel_x : glyph.key.subpixel_y);
}

GlyphAtlas make_atlas(uint32_t side) {
    AtlasConfig config;
    config.width = config.height = side;
    Result<GlyphAtlas> atlas = GlyphAtlas::create(config);
    EXPECT_TRUE(atlas) << atlas.error().message;
    return std::move(*atlas);
}

// A renderer's CPU parts over one atlas and the test font.
struct Frame {
    explicit Frame(uint32_t atlas_side) : atlas(make_atlas(atlas_side)), requests(atlas, fonts, coarsening, stats) {
        fonts.fonts[kFontId] = {&test_font().asset(), 0, 0, 0, {}};
    }
    void begin() {
        atlas.begin_frame();
        requests.begin_frame();
        stats = {};
    }
    // settle, schedule and collect, as record() does.
    void end(const raster::AtlasLimits& limits = {}) {
        requests.settle(limits);
        atlas.schedule();
        requests.collect_drawn();
    }
    TestFonts fonts;
    GlyphAtlas atlas;
    RendererStats stats;
    raster::Coarsening coarsening;
    raster::FrameRequests requests;
};

TEST(RasterCoarsening, PensMoveAtMostHalfAStepAndKeysRectsAndPositionsFollow) {
    const GlyphInstance base = glyph_at(20.0f, 30.0f, 40.0f);
    const FontAsset* asset = &test_font().asset();
    for (const uint32_t steps : {4u, 1u}) {
        const int64_t grid = kSubpixelSteps / steps;
        for (uint32_t sub = 0; sub < kSubpixelSteps; ++sub) {
            GlyphInstance glyph = base;
            ASSERT_TRUE(raster::moved(asset, glyph, sub / 256.0, (255 - sub) / 256.0));
            const GlyphInstance out = raster::coarsened(asset, glyph, steps);
            for (int axis = 0; axis < 2; ++axis) {
                const uint8_t offset = axis == 0 ? out.key.subpixel_x : out.key.subpixel_y;
                EXPECT_EQ(offset % grid, 0) << steps << " steps, " << sub;
                EXPECT_LE(std::abs(pen_steps(out, axis) - pen_steps(glyph, axis)), grid / 2) << steps << ", " << sub;
            }
            const GlyphRect rect = glyph_rect(record_of(out), out.key);
            EXPECT_EQ(out.width, rect.width);
            EXPECT_EQ(out.height, rect.height);
            EXPECT_EQ(out.pen_x, glyph.pen_x);  // the pen a layout asked for stays
        }
    }
    // 250/256 px rounds up to the next pixel's step 0: the carry moves x by a whole pixel.
    GlyphInstance glyph = base;
    const double pen = static_cast<double>(base.pen_x);
    ASSERT_TRUE(raster::moved(asset, glyph, std::floor(pen) + 250 / 256.0 - pen, 0.0));
    ASSERT_EQ(glyph.key.subpixel_x, 250);
    const GlyphInstance carried = raster::coarsened(asset, glyph, 4);
    EXPECT_EQ(carried.key.subpixel_x, 0);
    EXPECT_EQ(pen_steps(carried, 0), pen_steps(glyph, 0) + 6);
    // The finest steps, and a font not held, leave the instance as it is.
    EXPECT_EQ(raster::coarsened(asset, glyph, kSubpixelSteps).key, glyph.key);
    EXPECT_EQ(raster::coarsened(nullptr, glyph, 1).key, glyph.key);
}

TEST(RasterRequests, MovedFollowsThePenAndRefusesBadOnes) {
    const FontAsset* asset = &test_font().asset();
    const GlyphInstance base = glyph_at(16.0f, 10.0f, 20.0f);
    GlyphInstance glyph = base;
    ASSERT_TRUE(raster::moved(asset, glyph, 100.375, -3.5));
    EXPECT_FLOAT_EQ(glyph.pen_x, base.pen_x + 100.375f);
    EXPECT_FLOAT_EQ(glyph.pen_y, base.pen_y - 3.5f);
    const double pen_x = static_cast<double>(base.pen_x) + 100.375, pen_y = static_cast<double>(base.pen_y) - 3.5;
    EXPECT_EQ(pen_steps(glyph, 0), std::llround(pen_x * kSubpixelSteps));
    EXPECT_EQ(pen_steps(glyph, 1), std::llround(pen_y * kSubpixelSteps));
    EXPECT_EQ(glyph.width, glyph_rect(record_of(glyph), glyph.key).width);

    // A zero offset keeps the layout's key, even a snapped one.
    glyph = base;
    glyph.key.subpixel_x = 17;
    ASSERT_TRUE(raster::moved(asset, glyph, 0.0, 0.0));
    EXPECT_EQ(glyph.key.subpixel_x, 17);

    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    for (const auto& [dx, dy] :
         {std::pair{nan, 0.0}, {0.0, nan}, {inf, 0.0}, {0.0, -inf}, {16777300.0, 0.0}, {0.0, -16777300.0}}) {
        glyph = base;
        EXPECT_FALSE(raster::moved(asset, glyph, dx, dy)) << dx << ", " << dy;
    }
    glyph = base;
    EXPECT_TRUE(raster::moved(asset, glyph, 16777000.0 - static_cast<double>(base.pen_x), 0.0));
    glyph = base;
    EXPECT_TRUE(raster::moved(nullptr, glyph, 5.0, 5.0));  // admit() counts it as an unknown font
    EXPECT_EQ(glyph.x, base.x);

    // draw() with such an offset draws nothing, counted as skipped, also when the frame starts over.
    Frame frame(64);
    frame.begin();
    const GlyphInstance glyphs[] = {base, base};
    raster::MotionTracker motion;
    DrawOptions away;
    away.offset_x = std::numeric_limits<float>::infinity();
    frame.requests.add(glyphs, away, motion);
    frame.end();
    EXPECT_EQ(frame.stats.skipped_glyphs, 2u);
    EXPECT_TRUE(frame.requests.drawn().empty());
}

TEST(RasterRequests, AGlyphDrawnInPartsIsAcquiredOnceForTheirBoundingBox) {
    const GlyphInstance glyph = glyph_at(200.0f, 20.0f, 200.0f);
    ASSERT_GT(glyph.width, 100u);
    const uint32_t part = 20, gap = 40;
    const VkRect2D left{{glyph.x, glyph.y}, {part, glyph.height}};
    const VkRect2D right{{glyph.x + static_cast<int32_t>(part + gap), glyph.y}, {part, glyph.height}};

    Frame both(1024);
    both.begin();
    both.requests.add(glyph, &left, kSubpixelSteps);
    both.requests.add(glyph, &right, kSubpixelSteps);
    both.end();
    EXPECT_EQ(both.stats.clipped_glyphs, 2u);
    EXPECT_EQ(both.atlas.stats().resident_glyphs, 1u);
    const AtlasEntry* entry = both.atlas.entry(both.atlas.find(glyph.key));
    ASSERT_NE(entry, nullptr);
    // The box from the left part's first texel to the right part's last, and the margin.
    EXPECT_EQ(entry->part.x, 0u);
    EXPECT_EQ(entry->part.width, part + gap + part + kAtlasPartMargin);
    EXPECT_EQ(entry->part.height, glyph.height);
    // Each shows only its own part.
    ASSERT_EQ(both.requests.drawn().size(), 2u);
    for (const DrawnGlyph& drawn : both.requests.drawn()) EXPECT_EQ(drawn.instance.width, part);
    EXPECT_EQ(both.requests.drawn()[0].part_x, 0u);
    EXPECT_EQ(both.requests.drawn()[1].part_x, part + gap);
    EXPECT_EQ(both.requests.drawn()[1].instance.x, right.offset.x);

    // One part alone takes that part and its margin.
    Frame one(1024);
    one.begin();
    one.requests.add(glyph, &left, kSubpixelSteps);
    one.end();
    const AtlasEntry* alone = one.atlas.entry(one.atlas.find(glyph.key));
    ASSERT_NE(alone, nullptr);
    EXPECT_EQ(alone->part.width, part + kAtlasPartMargin);

    // Outside the visible rect: culled, nothing acquired.
    const VkRect2D away{{glyph.x + static_cast<int32_t>(glyph.width), glyph.y}, {10, 10}};
    one.begin();
    one.requests.add(glyph, &away, kSubpixelSteps);
    one.end();
    EXPECT_EQ(one.stats.culled_glyphs, 1u);
    EXPECT_TRUE(one.requests.drawn().empty());
}

TEST(RasterRequests, NamedDrawsMoveUntilTheyRestAndAreForgotten) {
    raster::MotionTracker motion;
    motion.begin_frame();
    EXPECT_FALSE(motion.moving(7, 10.0, 20.0));  // first seen
    motion.begin_frame();
    EXPECT_FALSE(motion.moving(7, 10.0, 20.0));
    motion.begin_frame();
    EXPECT_TRUE(motion.moving(7, 10.5, 20.0));  // its pen changed
    for (uint32_t frame = 1; frame < kMotionSettleFrames; ++frame) {
        motion.begin_frame();
        EXPECT_TRUE(motion.moving(7, 10.5, 20.0)) << frame;
    }
    motion.begin_frame();
    EXPECT_FALSE(motion.moving(7, 10.5, 20.0));  // settled

    // An abandoned frame's motion is taken back.
    motion.begin_frame();
    EXPECT_TRUE(motion.moving(7, 11.0, 20.0));
    motion.abandon_frame();
    motion.begin_frame();
    EXPECT_FALSE(motion.moving(7, 10.5, 20.0));

    // Not drawn for kForgetMotionFrames frames: forgotten at the next multiple of them.
    for (const bool wait_to_forget : {false, true}) {
        raster::MotionTracker named;
        named.begin_frame();  // frame 1
        EXPECT_FALSE(named.moving(9, 0.0, 0.0));
        const uint64_t last = 2 * raster::MotionTracker::kForgetMotionFrames - (wait_to_forget ? 0 : 1);
        for (uint64_t frame = 2; frame <= last; ++frame) named.begin_frame();
        EXPECT_EQ(named.moving(9, 5.0, 0.0), !wait_to_forget) << wait_to_forget;
    }

    // Through draw(): the glyphs of a moving draw take kMovingSubpixelSteps and are counted.
    Frame frame(256);
    raster::MotionTracker tracker;
    const GlyphInstance glyphs[] = {glyph_at(16.0f, 3.3f, 20.0f), glyph_at(16.0f, 13.7f, 20.0f)};
    for (const float offset : {0.0f, 0.1f}) {
        tracker.begin_frame();
        frame.begin();
        DrawOptions named;
        named.offset_x = offset;
        named.id = 5;
        frame.requests.add(glyphs, named, tracker);
        frame.end();
    }
    EXPECT_EQ(frame.stats.moving_glyphs, 2u);
    ASSERT_EQ(frame.requests.drawn().size(), 2u);
    for (const DrawnGlyph& drawn : frame.requests.drawn()) {
        EXPECT_EQ(drawn.instance.key.subpixel_x % (kSubpixelSteps / kMovingSubpixelSteps), 0);
    }
}

// Counts calm frames until the steps get finer.
uint32_t calm_frames_to_refine(raster::Coarsening& coarsening) {
    const uint32_t steps = coarsening.steps();
    uint32_t frames = 0;
    while (coarsening.steps() == steps && frames < 100000) {
        coarsening.end_frame(true);
        ++frames;
    }
    return frames;
}

TEST(RasterCoarsening, LevelsGoCoarserWhenFullAndFinerAfterCalmFrames) {
    raster::Coarsening coarsening;
    EXPECT_EQ(coarsening.steps(), kSubpixelSteps);
    coarsening.end_frame(true);  // at the finest, calm frames change nothing
    EXPECT_EQ(coarsening.steps(), kSubpixelSteps);
    ASSERT_TRUE(coarsening.coarsen());
    EXPECT_EQ(coarsening.steps(), 4u);
    ASSERT_TRUE(coarsening.coarsen());
    EXPECT_EQ(coarsening.steps(), 1u);
    EXPECT_FALSE(coarsening.coarsen());
    EXPECT_EQ(coarsening.steps(), 1u);
    for (int frame = 0; frame < 1000; ++frame) coarsening.end_frame(false);  // never calm: stays
    EXPECT_EQ(coarsening.steps(), 1u);
    EXPECT_EQ(calm_frames_to_refine(coarsening), raster::kCalmFrames);
    EXPECT_EQ(coarsening.steps(), 4u);
    EXPECT_EQ(calm_frames_to_refine(coarsening), raster::kCalmFrames);
    EXPECT_EQ(coarsening.steps(), kSubpixelSteps);

    // Finer steps that do not fit the very next frame double the wait, up to kMaxCalmFrames.
    uint32_t wait = raster::kCalmFrames;
    for (int round = 0; round < 8; ++round) {
        wait = std::min(wait * 2, raster::kMaxCalmFrames);
        ASSERT_TRUE(coarsening.coarsen());
        EXPECT_EQ(calm_frames_to_refine(coarsening), wait) << round;
    }
    EXPECT_EQ(wait, raster::kMaxCalmFrames);

    // A frame that fits at the finer steps keeps the wait as it was.
    raster::Coarsening fits;
    ASSERT_TRUE(fits.coarsen());
    EXPECT_EQ(calm_frames_to_refine(fits), raster::kCalmFrames);
    fits.end_frame(false);
    ASSERT_TRUE(fits.coarsen());
    EXPECT_EQ(calm_frames_to_refine(fits), raster::kCalmFrames);
}

TEST(RasterCoarsening, AFullAtlasGrowsOrTakesCoarserStepsInsteadOfDroppingGlyphs) {
    // 20 keys of one glyph at 20 subpixel positions; a 64 x 64 atlas has 16 cells of one each.
    std::vector<GlyphInstance> glyphs;
    for (int i = 0; i < 20; ++i) glyphs.push_back(glyph_at(12.0f, 10.0f + static_cast<float>(i) / 20.0f, 20.0f));
    std::set<uint8_t> offsets;
    for (const GlyphInstance& glyph : glyphs) offsets.insert(glyph.key.subpixel_x);
    ASSERT_EQ(offsets.size(), 20u);

    Frame frame(64);
    frame.begin();
    for (const GlyphInstance& glyph : glyphs) frame.requests.add(glyph, nullptr, kSubpixelSteps);
    EXPECT_GT(frame.stats.failed_glyphs, 0u);  // before the frame settles
    frame.end();
    EXPECT_EQ(frame.stats.subpixel_steps, 4u);
    EXPECT_EQ(frame.stats.failed_glyphs, 0u);
    EXPECT_GT(frame.stats.coarsened_glyphs, 0u);
    EXPECT_EQ(frame.requests.drawn().size(), 20u);
    EXPECT_EQ(frame.coarsening.steps(), 4u);  // the next frames too

    // Where the atlas may grow, it doubles instead.
    const raster::AtlasLimits limits{16384, 128 * 128 * 8};
    EXPECT_TRUE(limits.can_grow(make_atlas(64).config()));
    EXPECT_FALSE(limits.can_grow(make_atlas(128).config()));
    EXPECT_FALSE((raster::AtlasLimits{64, 1u << 30}.can_grow(make_atlas(64).config())));
    Frame grows(64);
    grows.begin();
    for (const GlyphInstance& glyph : glyphs) grows.requests.add(glyph, nullptr, kSubpixelSteps);
    grows.end(limits);
    EXPECT_EQ(grows.stats.atlas_grown, 1u);
    EXPECT_EQ(grows.stats.atlas_width, 128u);
    EXPECT_EQ(grows.stats.subpixel_steps, kSubpixelSteps);
    EXPECT_EQ(grows.stats.coarsened_glyphs, 0u);
    EXPECT_EQ(grows.requests.drawn().size(), 20u);
}

TEST(RasterWorkItems, ItemsAddressTheirFontsRangesAndTileTheWorkgroups) {
    const GlyphInstance h = glyph_at(24.0f, 0.25f, 30.0f);
    const GlyphInstance g = glyph_at(24.0f, 0.5f, 30.0f, "g");
    TestFonts fonts;
    const uint64_t points_at = 1000 * sizeof(Point), bands_at = 64 * sizeof(uint32_t);
    fonts.fonts[kFontId] = {&test_font().asset(), 5, points_at, bands_at, {}};
    RasterWork first{};
    first.key = h.key;
    first.x = 32;
    first.y = 48;
    first.width = h.width;
    first.height = h.height;
    first.part_x = 2;
    first.part_y = 3;
    first.first_texel = 7;
    first.texel_count = 130;  // 3 workgroups of 64
    first.first_sample = 4;
    first.sample_count = 2;
    RasterWork none = first;
    none.sample_count = 0;
    RasterWork unknown = first;
    unknown.key.font = kFontId + 1;
    RasterWork second = first;
    second.key = g.key;
    second.texel_count = gpu::kRasterWorkgroupSize;  // exactly one
    const RasterWork work[] = {first, none, unknown, second};

    std::vector<gpu::RasterItem> items = {gpu::RasterItem{}};  // stale: replaced
    std::vector<uint32_t> table = {9};
    std::vector<gpu::RasterTransform> transforms = {gpu::RasterTransform{}};  // stale: replaced
    std::array<uint32_t, raster::kRasterItemKinds> kinds{};
    EXPECT_EQ(raster::build_work_items(work, fonts, items, transforms, table, kinds), 4u);
    EXPECT_EQ(kinds, (std::array<uint32_t, raster::kRasterItemKinds>{4, 0, 0}));
    EXPECT_TRUE(transforms.empty());
    ASSERT_EQ(items.size(), 2u);
    EXPECT_EQ(table, (std::vector<uint32_t>{0, 0, 0, 1}));
    const GlyphRecord& record = record_of(h);
    const TexelToEm map = texel_to_em(glyph_rect(record, h.key), h.key);
    const gpu::RasterItem& item = items[0];
    EXPECT_EQ(item.atlas_x, 32u);
    EXPECT_EQ(item.atlas_y, 48u);
    EXPECT_EQ(item.width, h.width);
    EXPECT_EQ(item.height, h.height);
    EXPECT_EQ(item.offset_x, map.offset_x);
    EXPECT_EQ(item.offset_y, map.offset_y);
    EXPECT_EQ(item.scale_x, map.scale_x);
    EXPECT_EQ(item.scale_y, map.scale_y);
    EXPECT_EQ(item.bbox_min_y, record.bbox_min_y);
    EXPECT_EQ(item.bbox_max_y, record.bbox_max_y);
    EXPECT_EQ(item.point_offset, 1000 + record.point_offset);
    EXPECT_EQ(item.band_offset, 64 + record.band_offset);
    EXPECT_EQ(item.band_count, record.band_count);
    EXPECT_EQ(item.band_words, record.band_words);
    EXPECT_EQ(item.font, 5u);
    EXPECT_EQ(item.first_sample, 4u);
    EXPECT_EQ(item.sample_count, 2u);
    EXPECT_EQ(item.part_x, 2u);
    EXPECT_EQ(item.part_y, 3u);
    EXPECT_EQ(item.first_texel, 7u);
    EXPECT_EQ(item.texel_count, 130u);
    EXPECT_EQ(item.first_workgroup, 0u);
    EXPECT_EQ(items[1].first_workgroup, 3u);
    EXPECT_EQ(item.transform, gpu::kRasterNoTransform);
    EXPECT_EQ(items[1].point_offset, 1000 + record_of(g).point_offset);
    EXPECT_NE(items[1].point_offset, item.point_offset);
    EXPECT_EQ(raster::build_work_items({}, fonts, items, transforms, table, kinds), 0u);
    EXPECT_EQ(kinds, (std::array<uint32_t, raster::kRasterItemKinds>{0, 0, 0}));
    EXPECT_TRUE(items.empty());
    EXPECT_TRUE(table.empty());
}

// A key's linear part at `degrees` of rotation, 24 px per em (y down: em y runs up the screen).
GlyphKey rotated_key(GlyphKey key, double degrees) {
    const double a = degrees * 3.14159265358979323846 / 180.0, s = 24.0 * 256.0;
    key.linear[0] = static_cast<int32_t>(std::lround(s * std::cos(a)));
    key.linear[1] = static_cast<int32_t>(std::lround(s * std::sin(a)));
    key.linear[2] = static_cast<int32_t>(std::lround(s * std::sin(a)));
    key.linear[3] = static_cast<int32_t>(std::lround(-s * std::cos(a)));
    return key;
}

TEST(RasterWorkItems, TransformedItemsFollowByKindAndNearVerticalOnesWalkTwoLines) {
    const GlyphInstance h = glyph_at(24.0f, 0.25f, 30.0f);
    EXPECT_EQ(raster::item_kind(h.key), 0u);
    // Within 15 degrees of vertical (either way, mirrored too) the stems run along the rows.
    for (const double degrees : {90.0, 76.0, -80.0, 270.0, 104.0}) {
        EXPECT_EQ(raster::item_kind(rotated_key(h.key, degrees)), gpu::kRasterTwoLineItems) << degrees;
    }
    for (const double degrees : {0.0, 37.0, 74.0, 180.0, 106.0, -45.0}) {
        EXPECT_EQ(raster::item_kind(rotated_key(h.key, degrees)), 1u) << degrees;
    }

    TestFonts fonts;
    fonts.fonts[kFontId] = {&test_font().asset(), 0, 0, 0, {}};
    RasterWork plain{};
    plain.key = h.key;
    plain.width = h.width;
    plain.height = h.height;
    plain.texel_count = 2 * gpu::kRasterWorkgroupSize;
    plain.sample_count = 1;
    RasterWork vertical = plain, oblique = plain;
    vertical.key = rotated_key(h.key, 88.0);
    vertical.texel_count = 1;
    oblique.key = rotated_key(h.key, 37.0);
    oblique.texel_count = 3 * gpu::kRasterWorkgroupSize + 1;
    const RasterWork work[] = {vertical, plain, oblique, plain};
    std::vector<gpu::RasterItem> items;
    std::vector<gpu::RasterTransform> transforms;
    std::vector<uint32_t> table;
    std::array<uint32_t, raster::kRasterItemKinds> kinds{};
    EXPECT_EQ(raster::build_work_items(work, fonts, items, transforms, table, kinds), 2u + 2u + 4u + 1u);
    EXPECT_EQ(kinds, (std::array<uint32_t, raster::kRasterItemKinds>{4, 4, 1}));
    ASSERT_EQ(items.size(), 4u);
    ASSERT_EQ(transforms.size(), 2u);
    EXPECT_EQ(items[0].transform, gpu::kRasterNoTransform);
    EXPECT_EQ(items[1].transform, gpu::kRasterNoTransform);
    EXPECT_EQ(items[2].transform, 0u);  // the oblique glyph, then the vertical one
    EXPECT_EQ(items[3].transform, 1u);
    EXPECT_EQ(items[2].first_workgroup, 4u);
    EXPECT_EQ(items[3].first_workgroup, 8u);
    EXPECT_EQ(table, (std::vector<uint32_t>{0, 0, 1, 1, 2, 2, 2, 2, 3}));
}

// ---- Colour layers' fills (raster/paints)

// The test font's asset with a palette and one paint of each kind the resolver treats apart.
FontAsset painted_asset() {
    FontAsset asset = test_font().asset();
    asset.palette_size = 2;
    asset.palette_colours = {0x80FF0000u, 0xFF00FF00u, 0xFFFFFFFFu, 0xFF000000u};  // 0: blue at alpha 0.5
    asset.stops = {{0.0f, 0, 1.0f}, {0.0f, 1, 1.0f}, {1.0f, kForegroundPaletteIndex, 0.5f}};
    Paint solid;
    solid.stop_count = 1;
    Paint linear{PaintKind::linear, PaintExtend::repeat, 1, 2, 0, {2.0f, 0.0f, 0.0f, 3.0f, 0.5f, -0.25f},
                 {0, 0, 1, 0, 0, 0}};
    Paint image{PaintKind::image, PaintExtend::pad, 0, 0, 0, {}, {}};
    asset.paints = {solid, linear, image};
    asset.colour_glyphs = {{0, 0, 1, kColourClipped, -0.5f, -0.25f, 1.0f, 0.75f}};
    return asset;
}

TEST(FramePaints, SolidFillsBecomeColoursAndGradientsMapPixelsToTheirSpace) {
    const FontAsset asset = painted_asset();
    TestFonts fonts;
    fonts.fonts[kFontId] = {&asset, 0, 0, 0, {}};
    const GlyphInstance base = glyph_at(32.0f, 10.3f, 40.6f);
    auto layer = [&](uint32_t paint, uint32_t palette, uint32_t colour_glyph) {
        DrawnGlyph drawn;
        drawn.instance = base;
        drawn.instance.paint = paint;
        drawn.instance.palette = palette;
        drawn.instance.colour_glyph = colour_glyph;
        drawn.instance.color[0] = 0.5f;  // linear grey text at alpha 0.8
        drawn.instance.color[1] = 0.5f;
        drawn.instance.color[2] = 0.5f;
        drawn.instance.color[3] = 0.8f;
        return drawn;
    };
    std::vector<DrawnGlyph> drawn = {layer(0, 0, kNoColourGlyph), layer(0, 1, 0),
                                     layer(1, 7, kNoColourGlyph), layer(2, 0, kNoColourGlyph),
                                     layer(9, 0, kNoColourGlyph), layer(kNoPaint, 0, 0)};
    raster::FramePaints paints;
    RendererStats stats;
    paints.resolve(drawn, fonts, nullptr, stats);

    // Palette 0's entry 0, blue at alpha 0.5, times the text's 0.8: a colour, no fill.
    EXPECT_EQ(drawn[0].paint, kNoPaint);
    EXPECT_FLOAT_EQ(drawn[0].instance.color[2], 1.0f);
    EXPECT_FLOAT_EQ(drawn[0].instance.color[0], 0.0f);
    EXPECT_NEAR(drawn[0].instance.color[3], 128.0f / 255.0f * 0.8f, 1e-6f);
    // Palette 1 (white) with the colour glyph's clip box: a solid fill whose clip is in pixels.
    ASSERT_EQ(drawn[1].paint, 0u);
    const FramePaint& clipped = paints.paints()[0];
    EXPECT_EQ(clipped.kind, PaintKind::solid);
    EXPECT_FLOAT_EQ(drawn[1].instance.color[0], 1.0f);
    const GlyphRect rect = glyph_rect(record_of(base), base.key);
    const double pen_x = base.x - rect.x + base.key.subpixel_x / 256.0,
                 pen_y = base.y - rect.y + base.key.subpixel_y / 256.0;
    EXPECT_NEAR(clipped.clip[0], pen_x - 0.5 * 32.0, 1e-4);
    EXPECT_NEAR(clipped.clip[1], pen_y - 0.75 * 32.0, 1e-4);
    EXPECT_NEAR(clipped.clip[2], pen_x + 1.0 * 32.0, 1e-4);
    EXPECT_NEAR(clipped.clip[3], pen_y + 0.25 * 32.0, 1e-4);
    // The gradient (palette 7 is past the two: palette 0): its stops premultiplied and sRGB-encoded,
    // the foreground stop the text's colour at alpha 1 times the stop's 0.5; pixels mapped through em.
    ASSERT_EQ(drawn[2].paint, 1u);
    const FramePaint& linear = paints.paints()[1];
    ASSERT_EQ(linear.stop_count, 2u);
    const FrameStop& green = paints.stops()[linear.first_stop];
    EXPECT_FLOAT_EQ(green.colour[1], 1.0f);
    EXPECT_FLOAT_EQ(green.colour[3], 1.0f);
    const FrameStop& text = paints.stops()[linear.first_stop + 1];
    EXPECT_NEAR(text.colour[0], 0.5 * (1.055 * std::pow(0.5, 1 / 2.4) - 0.055), 1e-5);
    EXPECT_FLOAT_EQ(text.colour[3], 0.5f);
    EXPECT_FLOAT_EQ(text.offset, 1.0f);
    EXPECT_FLOAT_EQ(linear.opacity, 0.8f);
    // The pixel point at em (0.25, 0.5) lands at to_paint(0.25, 0.5) = (2 * 0.25 + 0.5, 3 * 0.5 - 0.25).
    const double px = pen_x + 0.25 * 32.0, py = pen_y - 0.5 * 32.0;
    auto mapped = [&](int row) {
        const float* m = linear.to_paint + 3 * row;
        return static_cast<double>(m[0]) * px + static_cast<double>(m[1]) * py + static_cast<double>(m[2]);
    };
    EXPECT_NEAR(mapped(0), 1.0, 1e-4);
    EXPECT_NEAR(mapped(1), 1.25, 1e-4);
    // An image without a place draws nothing; an unknown paint keeps its colour; plain text is untouched.
    EXPECT_EQ(drawn[3].paint, kNoPaint);
    EXPECT_EQ(drawn[3].instance.color[3], 0.0f);
    EXPECT_EQ(drawn[4].paint, kNoPaint);
    EXPECT_EQ(drawn[4].instance.color[3], 0.8f);
    EXPECT_EQ(drawn[5].paint, kNoPaint);
    EXPECT_EQ(drawn[5].instance.color[0], 0.5f);
    EXPECT_EQ(stats.colour_layers, 4u);
    EXPECT_EQ(stats.frame_paints, 2u);
    EXPECT_EQ(stats.bitmap_misses, 1u);
}

}  // namespace
}  // namespace crisp
