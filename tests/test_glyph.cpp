#include <crisp/glyph.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <unordered_set>

namespace crisp {
namespace {

GlyphRecord box(float x0, float y0, float x1, float y1) {
    GlyphRecord g;
    g.bbox_min_x = x0;
    g.bbox_min_y = y0;
    g.bbox_max_x = x1;
    g.bbox_max_y = y1;
    g.curve_count = 4;
    g.band_count = 1;
    g.band_words = 1;
    g.flags = kGlyphBaked;
    return g;
}

GlyphKey key_at(float size, float subpixel_x, float subpixel_y) {
    GlyphKey key;
    key.size_x = key.size_y = static_cast<uint32_t>(std::lround(size * kSizeOne));
    key.subpixel_x = static_cast<uint8_t>(std::lround(subpixel_x * kSubpixelSteps));
    key.subpixel_y = static_cast<uint8_t>(std::lround(subpixel_y * kSubpixelSteps));
    return key;
}

TEST(Glyph, RectCoversTheOutlineWithPadding) {
    // An outline from (0.1, -0.21) to (0.6, 0.71) em at 20 px and a pen 0.25 px right of its
    // pixel: x from 2.25 to 12.25 px, y (down) from -14.2 to 4.2 px.
    const GlyphRect rect = glyph_rect(box(0.1f, -0.21f, 0.6f, 0.71f), key_at(20.0f, 0.25f, 0.0f));
    EXPECT_EQ(rect.x, 2 - kGlyphPadding);
    EXPECT_EQ(rect.x + static_cast<int32_t>(rect.width), 13 + kGlyphPadding);
    EXPECT_EQ(rect.y, -15 - kGlyphPadding);
    EXPECT_EQ(rect.y + static_cast<int32_t>(rect.height), 5 + kGlyphPadding);
    EXPECT_EQ(glyph_rect(GlyphRecord{}, key_at(20.0f, 0, 0)).width, 0u);  // no outline, no rect
}

TEST(Glyph, TexelToEmMapsTheRectOntoTheOutline) {
    const GlyphRecord glyph = box(0.1f, -0.2f, 0.6f, 0.7f);
    for (const float sub : {0.0f, 0.5f, 0.99609375f}) {
        const GlyphKey key = key_at(37.5f, sub, sub);
        const GlyphRect rect = glyph_rect(glyph, key);
        const TexelToEm map = texel_to_em(rect, key);
        // The rect's corners map outside the outline by at most padding + one texel, and inside
        // it by none: the outline fits the rect.
        const float left = map.offset_x, top = map.offset_y;
        const float right = map.offset_x + map.scale_x * static_cast<float>(rect.width);
        const float bottom = map.offset_y + map.scale_y * static_cast<float>(rect.height);
        EXPECT_LE(left, glyph.bbox_min_x - kGlyphPadding / 37.5f + 1e-6f);
        EXPECT_GE(right, glyph.bbox_max_x + kGlyphPadding / 37.5f - 1e-6f);
        EXPECT_GE(top, glyph.bbox_max_y + kGlyphPadding / 37.5f - 1e-6f);
        EXPECT_LE(bottom, glyph.bbox_min_y - kGlyphPadding / 37.5f + 1e-6f);
        EXPECT_GT(left, glyph.bbox_min_x - (kGlyphPadding + 1) / 37.5f);
    }
}

TEST(Glyph, CurveTestsPerSampleCountsEachRowsBand) {
    FontAsset asset;
    GlyphRecord glyph = box(0.0f, 0.0f, 1.0f, 1.0f);
    glyph.curve_count = 40;  // two words per band
    glyph.band_count = 2;
    glyph.band_words = 2;
    asset.band_words = {0x0000000Fu, 0x1u, 0xFFFFFFFFu, 0x0u};  // band 0: 5 curves, band 1: 32
    const GlyphKey key = key_at(10.0f, 0.0f, 0.0f);
    const GlyphRect rect = glyph_rect(glyph, key);  // 12 x 12 with padding: rows above y=0.5 in band 1
    uint64_t expected = 0;
    for (uint32_t row = 0; row < rect.height; ++row) {
        const float y = texel_to_em(rect, key).offset_y - (static_cast<float>(row) + 0.5f) / 10.0f;
        expected += (y >= 0.5f ? 32u : 5u) * rect.width;
    }
    EXPECT_EQ(curve_tests_per_sample(asset, glyph, key), expected);
    EXPECT_EQ(curve_tests_per_sample(asset, GlyphRecord{}, key), 0u);
}

TEST(Glyph, KeysHashAndCompareByEveryField) {
    std::unordered_set<GlyphKey, GlyphKeyHash> keys;
    GlyphKey key = key_at(16.0f, 0.5f, 0.0f);
    keys.insert(key);
    for (int field = 0; field < 6; ++field) {
        GlyphKey other = key;
        switch (field) {
            case 0:
                other.font = 1;
                break;
            case 1:
                other.glyph = 7;
                break;
            case 2:
                other.size_x += 1;
                break;
            case 3:
                other.size_y += 1;
                break;
            case 4:
                other.subpixel_x += 1;
                break;
            case 5:
                other.subpixel_y += 1;
                break;
        }
        EXPECT_FALSE(other == key);
        EXPECT_TRUE(keys.insert(other).second);
    }
    EXPECT_FALSE(keys.insert(key).second);
}

}  // namespace
}  // namespace crisp
