// Small inputs that used to take minutes or gigabytes (docs/limits.md): TrueType composites that
// expand a thousandfold a level, and fonts whose glyphs fill an asset past what a renderer holds.
// The fonts are made at build time by make_hostile_fonts.py.
#include "test_support.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace crisp {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// 30 glyphs of 1000 x 1000 x 1000 empty parts (200 KB) took 76 s and 2.1 GB: FreeType expands a
// composite part by part. The parts are counted in glyf first, and each such glyph fails, naming
// the limit, without being loaded.
TEST(InputBounds, CompositesAreBoundedBeforeTheyAreExpanded) {
    const auto start = std::chrono::steady_clock::now();
    auto refused = bake_font_file(CRISP_HOSTILE_COMPOSITES_FONT, BakeOptions{});
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::glyph_failed);
    EXPECT_NE(refused.error().message.find("33 of 44 glyphs failed; first: glyph 3: a composite of 1001000 parts, "
                                           "more than the limit of " +
                                           std::to_string(kMaxCompositeParts)),
              std::string::npos)
        << refused.error().message;

    BakeOptions options;
    options.allow_failed = true;
    auto baked = bake_font_file(CRISP_HOSTILE_COMPOSITES_FONT, options);
    ASSERT_TRUE(baked) << baked.error().message;
    // The 30 glyphs, the 1000 x 1000 part they share, the one nested too deep and the cycle.
    EXPECT_EQ(baked->report.failed_glyphs, 33u);
    EXPECT_EQ(baked->report.baked_glyphs, 11u);  // .notdef, the leaf, its 1000-part composite, 8 nested
    std::printf("30 composites of 10^9 parts refused in %.3f s\n", seconds_since(start));  // not asserted
}

// A composite that contains itself, or nests past kMaxCompositeDepth, fails the same way.
TEST(InputBounds, CompositeCyclesAndDepthAreRefused) {
    const auto bake = [](char32_t c) {
        BakeOptions options;
        options.all_glyphs = false;
        options.codepoints = {c};
        return bake_font_file(CRISP_HOSTILE_COMPOSITES_FONT, options);
    };
    auto deepest = bake(U'a' + kMaxCompositeDepth - 1);  // a part nested kMaxCompositeDepth deep
    ASSERT_TRUE(deepest) << deepest.error().message;
    EXPECT_EQ(deepest->report.failed_glyphs, 0u);
    auto deeper = bake(U'a' + kMaxCompositeDepth);
    ASSERT_FALSE(deeper);
    EXPECT_NE(deeper.error().message.find("composite components nested 9 deep, more than the limit of 8"),
              std::string::npos)
        << deeper.error().message;
    auto cyclic = bake(U'z');
    ASSERT_FALSE(cyclic);
    EXPECT_NE(cyclic.error().message.find("a composite glyph that contains itself"), std::string::npos)
        << cyclic.error().message;
}

// Composites of one 4096-curve glyph, each 6 bytes of the font: 11,000 of them wrote a 1.13 GB
// asset that --check refused, 65,535 ended in std::bad_alloc. The bake stops at the glyph that
// would pass the curve points one storage buffer of every Vulkan device holds.
TEST(InputBounds, AnAssetPastWhatARendererHoldsIsRefusedEarly) {
    const auto start = std::chrono::steady_clock::now();
    auto refused = bake_font_file(CRISP_HOSTILE_CURVES_FONT, BakeOptions{});
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::font_unsupported);
    EXPECT_NE(refused.error().message.find("glyph 1639: the asset's curve points would reach 134253768 bytes, more "
                                           "than the limit of " +
                                           std::to_string(kMaxAssetPointBytes)),
              std::string::npos)
        << refused.error().message;
    std::printf("65,535 glyphs of 4096 curves refused in %.3f s\n", seconds_since(start));  // not asserted

    // The glyphs a text needs bake.
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = {'A', 'B'};
    auto baked = bake_font_file(CRISP_HOSTILE_CURVES_FONT, options);
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_EQ(baked->report.max_curves_per_glyph, kMaxCurvesPerGlyph);
}

}  // namespace
}  // namespace crisp
