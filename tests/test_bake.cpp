#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H
#include <hb.h>

#include <cmath>
#include <limits>
#include <random>

namespace crisp {
namespace {

BakeOptions subset(std::string_view text) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = decode_utf8(text);
    return options;
}

uint32_t glyph_of(const std::string& path, uint32_t face_index, uint32_t codepoint) {
    FT_Library library = nullptr;
    FT_Init_FreeType(&library);
    FT_Face face = nullptr;
    FT_New_Face(library, path.c_str(), face_index, &face);
    const uint32_t glyph = FT_Get_Char_Index(face, codepoint);
    FT_Done_Face(face);
    FT_Done_FreeType(library);
    return glyph;
}

TEST(Bake, TrueTypeBakesEveryGlyphAndRoundTrips) {
    auto baked = bake_font_file(test::kDejaVuSans, BakeOptions{});
    ASSERT_TRUE(baked) << baked.error().message;
    const BakeReport& report = baked->report;
    EXPECT_EQ(report.glyph_count, baked->asset.glyphs.size());
    EXPECT_EQ(report.baked_glyphs, report.glyph_count);
    EXPECT_EQ(report.failed_glyphs, 0u);
    EXPECT_EQ(report.cubic_count, 0u);  // TrueType is quadratic
    EXPECT_EQ(baked->asset.info.flags & kFontCubic, 0u);
    EXPECT_EQ(baked->asset.info.units_per_em, 2048u);
    EXPECT_EQ(baked->asset.info.family, "DejaVu Sans");
    EXPECT_GT(report.curve_count, 100000u);
    EXPECT_EQ(report.curve_count, report.line_count + report.quadratic_count + report.cubic_pieces + report.y_splits -
                                      report.dropped_zero_length);

    auto loaded = load_asset(serialize_asset(baked->asset));
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_TRUE(*loaded == baked->asset);  // the same curves, bands and metrics
}

TEST(Bake, MetricsMatchTheFont) {
    auto baked = bake_font_file(test::kDejaVuSans, subset("H"));
    ASSERT_TRUE(baked);
    FT_Library library = nullptr;
    FT_Init_FreeType(&library);
    FT_Face face = nullptr;
    ASSERT_EQ(FT_New_Face(library, test::kDejaVuSans.c_str(), 0, &face), 0);
    const uint32_t glyph = FT_Get_Char_Index(face, 'H');
    ASSERT_EQ(FT_Load_Glyph(face, glyph, FT_LOAD_NO_SCALE), 0);
    const double upem = face->units_per_EM;
    const GlyphRecord& record = baked->asset.glyphs[glyph];
    EXPECT_EQ(record.flags, kGlyphBaked);
    EXPECT_FLOAT_EQ(record.advance, static_cast<float>(static_cast<double>(face->glyph->metrics.horiAdvance) / upem));
    EXPECT_FLOAT_EQ(record.bearing_x,
                    static_cast<float>(static_cast<double>(face->glyph->metrics.horiBearingX) / upem));
    EXPECT_FLOAT_EQ(record.bearing_y,
                    static_cast<float>(static_cast<double>(face->glyph->metrics.horiBearingY) / upem));
    // 'H' is made of lines: its bbox is its outline's.
    FT_BBox box;
    FT_Outline_Get_CBox(&face->glyph->outline, &box);
    EXPECT_FLOAT_EQ(record.bbox_min_x, static_cast<float>(static_cast<double>(box.xMin) / upem));
    EXPECT_FLOAT_EQ(record.bbox_max_y, static_cast<float>(static_cast<double>(box.yMax) / upem));
    EXPECT_EQ(baked->asset.info.ascender, face->ascender);
    EXPECT_EQ(baked->asset.info.descender, face->descender);
    FT_Done_Face(face);
    FT_Done_FreeType(library);
    // Glyphs not asked for are present as empty records.
    EXPECT_EQ(baked->asset.glyphs[glyph_of(test::kDejaVuSans, 0, 'x')].flags, 0u);
}

TEST(Bake, CffCubicsAreLoweredWithinTolerance) {
    BakeOptions options;
    auto baked = bake_font_file(test::kInterCff, options);
    ASSERT_TRUE(baked) << baked.error().message;
    const BakeReport& report = baked->report;
    EXPECT_GT(report.cubic_count, 10000u);
    EXPECT_GE(report.cubic_pieces, report.cubic_count);
    EXPECT_LE(report.max_deviation_em, static_cast<double>(options.tolerance_em));
    EXPECT_GT(report.seed_max_deviation_em, report.max_deviation_em);
    EXPECT_NE(baked->asset.info.flags & kFontCubic, 0u);
    EXPECT_FLOAT_EQ(baked->asset.info.max_deviation_em, static_cast<float>(report.max_deviation_em));
    EXPECT_EQ(report.failed_glyphs, 0u);
}

TEST(Bake, SubsetIncludesLigaturesShapingProduces) {
    auto baked = bake_font_file(test::kDejaVuSans, subset("office"));
    ASSERT_TRUE(baked);
    const auto bytes = test::read_file(test::kDejaVuSans);
    hb_blob_t* blob = hb_blob_create(reinterpret_cast<const char*>(bytes.data()), static_cast<unsigned>(bytes.size()),
                                     HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    hb_face_t* face = hb_face_create(blob, 0);
    hb_font_t* font = hb_font_create(face);
    hb_buffer_t* buffer = hb_buffer_create();
    hb_buffer_add_utf8(buffer, "office", -1, 0, -1);
    hb_buffer_guess_segment_properties(buffer);
    hb_shape(font, buffer, nullptr, 0);
    unsigned count = 0;
    const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &count);
    EXPECT_LT(count, 6u);  // DejaVu Sans has an "ffi" or "fi" ligature
    for (unsigned i = 0; i < count; ++i) {
        EXPECT_NE(baked->asset.glyphs[infos[i].codepoint].flags & kGlyphBaked, 0u) << "glyph " << infos[i].codepoint;
    }
    hb_buffer_destroy(buffer);
    hb_font_destroy(font);
    hb_face_destroy(face);
    hb_blob_destroy(blob);
    EXPECT_NE(baked->asset.glyphs[0].flags & kGlyphBaked, 0u);  // .notdef
    EXPECT_LT(baked->report.baked_glyphs, 40u);
}

TEST(Bake, FacePicksTheFaceOfACollection) {
    BakeOptions first = subset("骨");
    BakeOptions second = first;
    second.face_index = 2;
    auto a = bake_font_file(test::kNotoCjk, first);
    auto b = bake_font_file(test::kNotoCjk, second);
    ASSERT_TRUE(a) << a.error().message;
    ASSERT_TRUE(b) << b.error().message;
    FT_Library library = nullptr;
    FT_Init_FreeType(&library);
    for (uint32_t index : {0u, 2u}) {
        FT_Face face = nullptr;
        ASSERT_EQ(FT_New_Face(library, test::kNotoCjk.c_str(), index, &face), 0);
        EXPECT_EQ((index ? b : a)->asset.info.family, face->family_name);
        EXPECT_EQ((index ? b : a)->asset.info.face_index, index);
        FT_Done_Face(face);
    }
    FT_Done_FreeType(library);
    EXPECT_NE(a->asset.info.family, b->asset.info.family);
    // The faces (Japanese and Simplified Chinese) map 骨 to their own regional forms; each
    // subset holds its face's form.
    const uint32_t japanese = glyph_of(test::kNotoCjk, 0, U'骨'), chinese = glyph_of(test::kNotoCjk, 2, U'骨');
    EXPECT_NE(japanese, chinese);
    EXPECT_NE(a->asset.glyphs[japanese].flags & kGlyphBaked, 0u);
    EXPECT_NE(b->asset.glyphs[chinese].flags & kGlyphBaked, 0u);

    BakeOptions missing;
    missing.face_index = 99;
    auto none = bake_font_file(test::kNotoCjk, missing);
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().code, ErrorCode::font_unreadable);
    EXPECT_NE(none.error().message.find("face 99"), std::string::npos);
}

TEST(Bake, VariationChangesTheOutlines) {
    BakeOptions thin = subset("H");
    thin.variations = {{make_tag("wght"), 100.0f}};
    BakeOptions black = subset("H");
    black.variations = {{make_tag("wght"), 900.0f}};
    auto a = bake_font_file(test::kInterVariable, thin);
    auto b = bake_font_file(test::kInterVariable, black);
    ASSERT_TRUE(a) << a.error().message;
    ASSERT_TRUE(b) << b.error().message;
    const uint32_t glyph = glyph_of(test::kInterVariable, 0, 'H');
    const GlyphRecord& h_thin = a->asset.glyphs[glyph];
    const GlyphRecord& h_black = b->asset.glyphs[glyph];
    EXPECT_GT(h_black.advance, h_thin.advance);
    EXPECT_GT(h_black.bbox_max_x - h_black.bbox_min_x, h_thin.bbox_max_x - h_thin.bbox_min_x);
    EXPECT_NE(a->asset.points, b->asset.points);
    EXPECT_NE(a->asset.info.flags & kFontVariable, 0u);
    bool found = false;
    for (const AxisValue& axis : b->asset.info.axes) {
        if (axis.tag == make_tag("wght")) {
            EXPECT_EQ(axis.value, 900.0f);
            found = true;
        }
    }
    EXPECT_TRUE(found);
}

TEST(Bake, BadVariationsAreRefused) {
    BakeOptions unknown = subset("H");
    unknown.variations = {{make_tag("wdth"), 100.0f}};
    auto a = bake_font_file(test::kInterVariable, unknown);
    ASSERT_FALSE(a);
    EXPECT_EQ(a.error().code, ErrorCode::font_unsupported);
    EXPECT_NE(a.error().message.find("wdth"), std::string::npos);

    BakeOptions outside = subset("H");
    outside.variations = {{make_tag("wght"), 5000.0f}};
    auto b = bake_font_file(test::kInterVariable, outside);
    ASSERT_FALSE(b);
    EXPECT_EQ(b.error().code, ErrorCode::invalid_argument);

    BakeOptions static_font = subset("H");
    static_font.variations = {{make_tag("wght"), 700.0f}};
    auto c = bake_font_file(test::kDejaVuSans, static_font);
    ASSERT_FALSE(c);
    EXPECT_EQ(c.error().code, ErrorCode::font_unsupported);
}

TEST(Bake, FailedGlyphsAreReportedOrBakedEmpty) {
    BakeOptions strict = subset("Hello");
    strict.max_curves_per_glyph = 3;
    auto a = bake_font_file(test::kDejaVuSans, strict);
    ASSERT_FALSE(a);
    EXPECT_EQ(a.error().code, ErrorCode::glyph_failed);
    EXPECT_NE(a.error().message.find("more than the limit of 3"), std::string::npos);

    strict.allow_failed = true;
    auto b = bake_font_file(test::kDejaVuSans, strict);
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_GT(b->report.failed_glyphs, 0u);
    const GlyphRecord& h = b->asset.glyphs[glyph_of(test::kDejaVuSans, 0, 'H')];
    EXPECT_EQ(h.flags, kGlyphBaked | kGlyphFailed);
    EXPECT_EQ(h.curve_count, 0u);
    EXPECT_TRUE(validate_asset(b->asset));
}

TEST(Bake, BadFontsAreErrorsNotCrashes) {
    std::vector<std::byte> noise(4096);
    std::mt19937 random(7);
    for (std::byte& b : noise) b = static_cast<std::byte>(random() & 0xFF);
    auto a = bake_font(noise, BakeOptions{});
    ASSERT_FALSE(a);
    EXPECT_EQ(a.error().code, ErrorCode::font_unreadable);

    auto b = bake_font({}, BakeOptions{});
    ASSERT_FALSE(b);

    auto c = bake_font_file("/nonexistent/font.ttf", BakeOptions{});
    ASSERT_FALSE(c);
    EXPECT_EQ(c.error().code, ErrorCode::io);

    // Truncated fonts either fail cleanly or bake what they hold.
    const auto bytes = test::read_file(test::kInterCff);
    for (const size_t size : {size_t{12}, size_t{100}, size_t{1000}, bytes.size() / 2, bytes.size() - 1}) {
        auto truncated = bake_font(std::span(bytes).first(size), subset("Hamburgefonstiv"));
        if (truncated) {
            EXPECT_TRUE(validate_asset(truncated->asset));
        }
    }

    BakeOptions bad_tolerance;
    bad_tolerance.tolerance_em = 0.0f;
    auto d = bake_font_file(test::kDejaVuSans, bad_tolerance);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().code, ErrorCode::invalid_argument);
}

// Issue 31: the tolerance follows the largest size the asset is drawn at, and the report gives
// the deviation in pixels at that size.
TEST(Bake, MaxSizeSetsTheToleranceInPixels) {
    BakeOptions options = subset("Sag");
    auto at16 = bake_font_file(test::kInterCff, options);
    ASSERT_TRUE(at16) << at16.error().message;
    EXPECT_EQ(at16->report.tolerance_em, static_cast<double>(kPixelTolerance / kDefaultMaxSizePx));
    EXPECT_EQ(at16->report.report_size_px, static_cast<double>(kDefaultMaxSizePx));
    EXPECT_GT(at16->report.max_deviation_px, 0.0);
    EXPECT_LE(at16->report.max_deviation_px, static_cast<double>(kPixelTolerance));

    options.max_size_px = 64.0f;
    options.tolerance_em = 0.01f;  // not read once a size is given
    auto at64 = bake_font_file(test::kInterCff, options);
    ASSERT_TRUE(at64) << at64.error().message;
    EXPECT_EQ(at64->report.tolerance_em, static_cast<double>(kPixelTolerance / 64.0f));
    EXPECT_FLOAT_EQ(at64->asset.info.tolerance_em, kPixelTolerance / 64.0f);
    EXPECT_EQ(at64->report.report_size_px, 64.0);
    EXPECT_LE(at64->report.max_deviation_px, static_cast<double>(kPixelTolerance));
    EXPECT_NEAR(at64->report.max_deviation_px, at64->report.max_deviation_em * 64.0, 1e-12);
    // A quarter of the tolerance costs more pieces (about 4^(1/3) as many).
    EXPECT_GT(at64->report.cubic_pieces, at16->report.cubic_pieces * 5 / 4);

    for (const float bad : {0.5f, -1.0f, kMaxBakeSizePx * 2.0f, std::numeric_limits<float>::quiet_NaN()}) {
        options.max_size_px = bad;
        auto refused = bake_font_file(test::kInterCff, options);
        ASSERT_FALSE(refused) << bad;
        EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument) << bad;
        EXPECT_NE(refused.error().message.find("largest size"), std::string::npos) << refused.error().message;
    }
}

TEST(Bake, SplittingAtYExtremaAddsCurvesAndKeepsTheAssetValid) {
    BakeOptions plain = subset("aeiou");
    BakeOptions split = plain;
    split.split_y_extrema = true;
    auto a = bake_font_file(test::kInterCff, plain);
    auto b = bake_font_file(test::kInterCff, split);
    ASSERT_TRUE(a);
    ASSERT_TRUE(b);
    EXPECT_GT(b->report.y_splits, 0u);
    EXPECT_EQ(b->report.curve_count, a->report.curve_count + b->report.y_splits);
}

TEST(Bake, ThousandUnitsPerEmCff) {
    auto baked = bake_font_file(test::kCantarell, BakeOptions{});
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_EQ(baked->asset.info.units_per_em, 1000u);
    EXPECT_EQ(baked->report.failed_glyphs, 0u);
}

}  // namespace
}  // namespace crisp

namespace crisp {
namespace {

TEST(Bake, CjkFaceBakesCompletely) {
    auto baked = bake_font_file(test::kNotoCjk, BakeOptions{});
    ASSERT_TRUE(baked) << baked.error().message;
    const BakeReport& report = baked->report;
    EXPECT_EQ(report.glyph_count, 65535u);
    EXPECT_EQ(report.baked_glyphs, report.glyph_count);
    EXPECT_EQ(report.failed_glyphs, 0u);
    EXPECT_GT(report.max_curves_per_glyph, 300u);  // glyphs with hundreds of curves
    EXPECT_LE(report.max_deviation_em, static_cast<double>(kDefaultToleranceEm));
    EXPECT_TRUE(validate_asset(baked->asset));
}

}  // namespace
}  // namespace crisp
