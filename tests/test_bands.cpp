#include "asset/bands.hpp"
#include "bake/outline.hpp"
#include "test_support.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H

#include <cmath>

namespace crisp {
namespace {

bool band_has(const GlyphBands& bands, uint32_t band, uint32_t slot) {
    return (bands.words[size_t{band} * bands.band_words + slot / 32] >> (slot % 32)) & 1u;
}

GlyphRecord record_for(const PackedGlyph& glyph, const GlyphBands& bands) {
    GlyphRecord record;
    record.bbox_min_y = glyph.min_y;
    record.bbox_max_y = glyph.max_y;
    record.band_count = bands.band_count;
    return record;
}

// Every point of every real, non-flat curve lies in a band whose bitset lists the curve, where
// the band is found by the same rule the rasterizer uses.
void check_every_curve_is_in_its_bands(const PackedGlyph& glyph, const GlyphBands& bands, uint32_t glyph_index) {
    const GlyphRecord record = record_for(glyph, bands);
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        if (!glyph.is_curve[slot]) continue;
        const Point* p = &glyph.points[2 * slot];
        if (p[0].y == p[1].y && p[1].y == p[2].y) continue;
        for (int k = 0; k <= 64; ++k) {
            const double t = k / 64.0, s = 1.0 - t;
            const double y0 = p[0].y, y1 = p[1].y, y2 = p[2].y;
            const auto y = static_cast<float>(s * s * y0 + 2 * s * t * y1 + t * t * y2);
            const uint32_t band = FontAsset::band_of(record, y);
            if (!band_has(bands, band, slot)) {
                ADD_FAILURE() << "glyph " << glyph_index << " curve " << slot << " at y=" << y << " missing from band "
                              << band << " of " << bands.band_count;
                return;
            }
        }
    }
}

struct FontBandStats {
    uint32_t glyphs = 0;
    uint32_t max_bands = 0;
};

FontBandStats check_font(const std::string& path, long face_index, uint32_t stride) {
    FT_Library library = nullptr;
    EXPECT_EQ(FT_Init_FreeType(&library), 0);
    FT_Face face = nullptr;
    EXPECT_EQ(FT_New_Face(library, path.c_str(), face_index, &face), 0) << path;
    FontBandStats stats;
    if (!face) return stats;
    for (FT_Long glyph = 0; glyph < face->num_glyphs; glyph += stride) {
        EXPECT_EQ(FT_Load_Glyph(face, static_cast<FT_UInt>(glyph), FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING), 0);
        OutlineOptions options;
        options.scale = 1.0 / face->units_per_EM;
        options.measure_seed = false;
        OutlineCounters counters;
        OutlineBuilder builder(options, counters);
        std::string error;
        EXPECT_TRUE(decompose_outline(face->glyph->outline, builder, error)) << error;
        const PackedGlyph packed = pack_contours(builder.finish());
        const GlyphBands bands = build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap);
        check_every_curve_is_in_its_bands(packed, bands, static_cast<uint32_t>(glyph));
        ++stats.glyphs;
        stats.max_bands = std::max<uint32_t>(stats.max_bands, bands.band_count);
        if (::testing::Test::HasFailure()) break;
    }
    FT_Done_Face(face);
    FT_Done_FreeType(library);
    return stats;
}

TEST(Bands, NoCurveIsMissingFromABandItTouchesDejaVu) {
    EXPECT_GT(check_font(test::kDejaVuSans, 0, 1).glyphs, 6000u);
}

TEST(Bands, NoCurveIsMissingFromABandItTouchesInterCff) {
    EXPECT_GT(check_font(test::kInterCff, 0, 1).glyphs, 2000u);
}

TEST(Bands, NoCurveIsMissingFromABandItTouchesInterVariable) {
    EXPECT_GT(check_font(test::kInterVariable, 0, 1).glyphs, 2000u);
}

TEST(Bands, NoCurveIsMissingFromABandItTouchesCantarell) {
    EXPECT_GT(check_font(test::kCantarell, 0, 1).glyphs, 300u);
}

TEST(Bands, NoCurveIsMissingFromABandItTouchesNotoCjkEvery16thGlyph) {
    const FontBandStats stats = check_font(test::kNotoCjk, 0, 16);
    EXPECT_GT(stats.glyphs, 4000u);
    EXPECT_EQ(stats.max_bands, kMaxBands);  // complex CJK glyphs use every band they may
}

Contour square(double x0, double y0, double x1, double y1) {
    return {line_to_quad({x0, y0}, {x1, y0}), line_to_quad({x1, y0}, {x1, y1}), line_to_quad({x1, y1}, {x0, y1}),
            line_to_quad({x0, y1}, {x0, y0})};
}

TEST(Bands, PackingSharesEndPointsAndPadsBetweenContours) {
    const PackedGlyph glyph = pack_contours({square(0, 0, 1, 1), square(0.25, 0.25, 0.75, 0.75)});
    ASSERT_EQ(glyph.curve_count, 9u);  // 4 + pad + 4
    EXPECT_EQ(glyph.real_curves, 8u);
    ASSERT_EQ(glyph.points.size(), 19u);
    EXPECT_EQ(glyph.is_curve[4], 0);
    EXPECT_EQ(glyph.points[8], (Point{0, 0}));           // the first contour closes
    EXPECT_EQ(glyph.points[10], (Point{0.25f, 0.25f}));  // the second starts on an even index
    EXPECT_EQ(glyph.points[18], (Point{0.25f, 0.25f}));  // and closes
    EXPECT_EQ(glyph.min_x, 0.0f);
    EXPECT_EQ(glyph.max_y, 1.0f);
}

TEST(Bands, FlatCurvesAreListedNowhere) {
    const PackedGlyph glyph = pack_contours({square(0, 0, 1, 1)});
    const GlyphBands bands = build_bands(glyph, kTargetCurvesPerBand, kMaxBands, kBandOverlap);
    for (uint32_t band = 0; band < bands.band_count; ++band) {
        EXPECT_FALSE(band_has(bands, band, 0));  // the bottom edge
        EXPECT_FALSE(band_has(bands, band, 2));  // the top edge
        EXPECT_TRUE(band_has(bands, band, 1));
        EXPECT_TRUE(band_has(bands, band, 3));
    }
}

TEST(Bands, BandCountIsTheFewestThatMeetsTheTarget) {
    // 24 short vertical strokes stacked in y: one band holds all of them, and bands split them.
    Contour strokes;
    std::vector<Contour> contours;
    for (int i = 0; i < 24; ++i) contours.push_back(square(0, i, 0.1, i + 0.9));
    const PackedGlyph glyph = pack_contours(contours);
    const GlyphBands bands = build_bands(glyph, 8, kMaxBands, kBandOverlap);
    EXPECT_LE(bands.max_curves_in_band, 8u);
    // One band fewer would not meet the target.
    const GlyphBands fewer = build_bands(glyph, 8, bands.band_count - 1u, kBandOverlap);
    EXPECT_GT(fewer.max_curves_in_band, 8u);
    // A curve spanning the whole glyph sits in every band, so the target can be out of reach:
    // then the band count that reaches the lowest worst case wins.
    contours.push_back(square(2, 0, 2.1, 24));
    const GlyphBands tall = build_bands(pack_contours(contours), 1, 16, kBandOverlap);
    EXPECT_LE(tall.band_count, 16u);
    EXPECT_GE(tall.max_curves_in_band, 3u);
}

TEST(Bands, BandOfFollowsTheBandHeights) {
    GlyphRecord record;
    record.bbox_min_y = -0.25f;
    record.bbox_max_y = 0.75f;
    record.band_count = 4;
    EXPECT_EQ(FontAsset::band_of(record, -0.25f), 0u);
    EXPECT_EQ(FontAsset::band_of(record, 0.0f), 1u);
    EXPECT_EQ(FontAsset::band_of(record, 0.49f), 2u);
    EXPECT_EQ(FontAsset::band_of(record, 0.75f), 3u);  // the top edge stays in the last band
    EXPECT_EQ(FontAsset::band_of(record, 9.0f), 3u);
    EXPECT_EQ(FontAsset::band_of(record, -9.0f), 0u);
    EXPECT_EQ(FontAsset::band_of(record, std::nanf("")), 0u);
}

}  // namespace
}  // namespace crisp
