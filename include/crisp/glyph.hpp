// crisp: glyph keys and glyph placement, shared by layout, the atlas and the rasterizer.
//
// A glyph drawn at a fractional pen position is split into a whole-pixel position and a subpixel
// offset. Glyphs with equal keys (font, glyph, size, subpixel offset) rasterize to identical
// texels, so they share one atlas entry wherever they are drawn.
#pragma once

#include <crisp/export.hpp>

#include <crisp/asset.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>

namespace crisp {

// Identifies a font among those one renderer or layout uses; chosen by whoever loads the fonts.
using FontId = uint32_t;

// Fixed-point units of GlyphKey: sizes are u24.8 pixels, subpixel offsets u0.8 pixels.
inline constexpr uint32_t kSizeFractionBits = 8;
inline constexpr uint32_t kSizeOne = 1u << kSizeFractionBits;  // 1.0 px in u24.8
inline constexpr uint32_t kSubpixelSteps = 256;                // u0.8: 1/256 px

// Texels of padding around a glyph's outline bbox in its atlas rect, so samples of channels whose
// rectangles reach up to this far past their pixel still land in the rect. Subpixel layouts keep
// every rectangle within [-kGlyphPadding, 1 + kGlyphPadding] of the pixel.
inline constexpr int32_t kGlyphPadding = 1;

struct GlyphKey {
    FontId font = 0;
    uint32_t glyph = 0;      // glyph index in the font
    uint32_t size_x = 0;     // pixels per em, u24.8
    uint32_t size_y = 0;     // pixels per em, u24.8
    uint8_t subpixel_x = 0;  // pen offset right of the whole pixel, u0.8
    uint8_t subpixel_y = 0;  // pen offset below the whole pixel (y down), u0.8
    friend bool operator==(const GlyphKey&, const GlyphKey&) = default;
};

struct CRISP_API GlyphKeyHash {
    size_t operator()(const GlyphKey& key) const;
};

// Where a glyph's atlas rect lands, relative to the whole pixel its pen is in (x right, y down),
// and its size in texels. Texel (i, j) of the rect is target pixel (pen_x + x + i, pen_y + y + j).
struct GlyphRect {
    int32_t x = 0;
    int32_t y = 0;
    uint32_t width = 0;  // 0 for a glyph without an outline
    uint32_t height = 0;
};

// The rect of `glyph` at `key`: the pixels its outline bbox touches at the key's size and
// subpixel offset, plus kGlyphPadding on each side. Empty (0 x 0) for a glyph without curves.
CRISP_API GlyphRect glyph_rect(const GlyphRecord& glyph, const GlyphKey& key);

// Maps a point of a glyph's rect (texel units from the rect's top-left corner, y down) to em
// (y up). This is the texel-to-em mapping the rasterizer and its CPU reference use.
struct TexelToEm {
    float scale_x = 0.0f;   // em per texel: 1 / size_x
    float scale_y = 0.0f;   // em per texel, negated: -1 / size_y
    float offset_x = 0.0f;  // em of the rect's top-left corner
    float offset_y = 0.0f;
};
CRISP_API TexelToEm texel_to_em(const GlyphRect& rect, const GlyphKey& key);

// What one sample of every texel of the glyph's rect costs the rasterizer, in curve tests: the
// sum over the rect's rows of its width times the curves listed in the band of the row's centre.
// The atlas budgets its samples in these units. 0 for a glyph without curves.
CRISP_API uint64_t curve_tests_per_sample(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key);

inline float size_to_float(uint32_t fixed) {
    return static_cast<float>(fixed) / static_cast<float>(kSizeOne);
}
inline float subpixel_to_float(uint8_t fixed) {
    return static_cast<float>(fixed) / static_cast<float>(kSubpixelSteps);
}

}  // namespace crisp
