#include <crisp/glyph.hpp>

#include <bit>
#include <cmath>

namespace crisp {

namespace {

uint64_t mix(uint64_t x) {
    // splitmix64's finalizer: every input bit reaches every output bit.
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

}  // namespace

size_t GlyphKeyHash::operator()(const GlyphKey& key) const {
    const uint64_t a = (uint64_t{key.font} << 32) | key.glyph;
    const uint64_t b =
        (uint64_t{key.size_x} << 40) ^ (uint64_t{key.size_y} << 16) ^ (uint64_t{key.subpixel_x} << 8) ^ key.subpixel_y;
    return static_cast<size_t>(mix(a ^ mix(b)));
}

GlyphRect glyph_rect(const GlyphRecord& glyph, const GlyphKey& key) {
    if (glyph.curve_count == 0) return {};
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    const double left = std::floor(sub_x + static_cast<double>(glyph.bbox_min_x) * size_x) - kGlyphPadding;
    const double right = std::ceil(sub_x + static_cast<double>(glyph.bbox_max_x) * size_x) + kGlyphPadding;
    const double top = std::floor(sub_y - static_cast<double>(glyph.bbox_max_y) * size_y) - kGlyphPadding;
    const double bottom = std::ceil(sub_y - static_cast<double>(glyph.bbox_min_y) * size_y) + kGlyphPadding;
    return {static_cast<int32_t>(left), static_cast<int32_t>(top), static_cast<uint32_t>(right - left),
            static_cast<uint32_t>(bottom - top)};
}

TexelToEm texel_to_em(const GlyphRect& rect, const GlyphKey& key) {
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    TexelToEm mapping;
    mapping.scale_x = static_cast<float>(1.0 / size_x);
    mapping.scale_y = static_cast<float>(-1.0 / size_y);
    mapping.offset_x = static_cast<float>((rect.x - sub_x) / size_x);
    mapping.offset_y = static_cast<float>((sub_y - rect.y) / size_y);
    return mapping;
}

uint64_t curve_tests_per_sample(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key) {
    if (glyph.curve_count == 0 || glyph.band_count == 0) return 0;
    const GlyphRect rect = glyph_rect(glyph, key);
    const TexelToEm map = texel_to_em(rect, key);
    uint64_t tests = 0;
    uint32_t cached_band = UINT32_MAX;
    uint64_t cached_count = 0;
    for (uint32_t row = 0; row < rect.height; ++row) {
        const float y = map.offset_y + map.scale_y * (static_cast<float>(row) + 0.5f);
        const uint32_t band = FontAsset::band_of(glyph, y);
        if (band != cached_band) {
            cached_band = band;
            cached_count = 0;
            const size_t first = size_t{glyph.band_offset} + size_t{band} * glyph.band_words;
            for (size_t w = 0; w < glyph.band_words; ++w)
                cached_count += static_cast<uint64_t>(std::popcount(asset.band_words[first + w]));
        }
        tests += cached_count * rect.width;
    }
    return tests;
}

}  // namespace crisp
