// crisp: glyph keys and glyph placement, shared by layout, the atlas and the rasterizer.
//
// A glyph drawn at a fractional pen position is split into a whole-pixel position and a subpixel
// offset. Glyphs with equal keys (font, glyph, size or transform, subpixel offset) rasterize to
// identical texels, so they share one atlas entry wherever they are drawn.
//
// A transformed glyph (rotated, scaled, sheared, mirrored, or in perspective: docs/transforms.md)
// is still an axis-aligned rect of the target's pixels; its key carries the transform's linear
// part and perspective, quantized, and its texels hold the coverage of the transformed outline.
#pragma once

#include <crisp/export.hpp>

#include <crisp/asset.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

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

// Units of GlyphKey::linear (pixels per em) and GlyphKey::perspective (per em).
inline constexpr double kLinearOne = 256.0;           // 1/256 px per em
inline constexpr double kPerspectiveOne = 1048576.0;  // 2^-20 per em

struct GlyphKey {
    FontId font = 0;
    uint32_t glyph = 0;      // glyph index in the font
    uint32_t size_x = 0;     // pixels per em, u24.8 (a transformed key: its linear part's column lengths)
    uint32_t size_y = 0;     // pixels per em, u24.8
    uint8_t subpixel_x = 0;  // pen offset right of the whole pixel, u0.8
    uint8_t subpixel_y = 0;  // pen offset below the whole pixel (y down), u0.8
    // A blurred layer (a blurred shadow, a glow: include/crisp/effects.hpp): the blur's radius in
    // 1/64 px; 0 none. Its rect grows by the blur's reach, ceil(R + 1) texels a side.
    uint16_t blur = 0;
    // A transformed glyph: a point e of its em space (y up) lands at
    //     pen + (L e) / (1 + p . e)   target pixels (y down),
    // L = {linear[0], linear[1]; linear[2], linear[3]} in 1/kLinearOne px per em and p =
    // perspective in 1/kPerspectiveOne per em. All zero (an axis-aligned key): L = diag(size_x,
    // -size_y), p = 0. transformed_key() makes these; an identity-like transform gives the
    // axis-aligned key, so it shares entries with untransformed text.
    int32_t linear[4] = {};
    int32_t perspective[2] = {};
    // 0: the glyph's own outline. Otherwise an effect layer's outline derived from it (an outline,
    // a weight: include/crisp/effects.hpp, docs/effects.md), its shape coded by the renderer:
    // keys of the same glyph, size and offset with equal codes share their atlas entry. With
    // kSilhouetteGlyph in `glyph`, derived from a colour glyph's silhouette instead.
    uint32_t effect = 0;
    friend bool operator==(const GlyphKey&, const GlyphKey&) = default;
};

// GlyphKey::glyph of an effect layer of a colour glyph (an outline, shadow or glow around it; its
// `effect` is never 0): this bit and the face glyph the colour glyph colours. The layer's outline
// is derived from the union of that colour glyph's layers' outlines, its silhouette.
inline constexpr uint32_t kSilhouetteGlyph = 1u << 31;

// Whether `key` carries a transform (its linear part is not all zero).
inline bool is_transformed(const GlyphKey& key) {
    return key.linear[0] != 0 || key.linear[1] != 0 || key.linear[2] != 0 || key.linear[3] != 0;
}

// A total order of keys, field by field: negative when a comes first, 0 when they are equal.
CRISP_API int compare_keys(const GlyphKey& a, const GlyphKey& b);

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
// subpixel offset, plus kGlyphPadding on each side (and a blurred key's reach, blur_reach()). Empty (0 x 0) for a glyph
// without curves, and for a transformed key under which some corner of the bbox is not in front of the eye (1 + p . e
// below kMinPerspectiveW) or lands more than kMaxTransformedExtent pixels away.
CRISP_API GlyphRect glyph_rect(const GlyphRecord& glyph, const GlyphKey& key);

// The texels a blurred key's rect grows by on each side: ceil(R + 1) for a radius of R px
// (GlyphKey::blur / 64), 0 without blur.
CRISP_API int32_t blur_reach(const GlyphKey& key);

// How far in front of the eye a transformed glyph's every bbox corner must be: 1 + p . e at least
// this (a glyph nearer to crossing the eye plane is not drawn).
inline constexpr double kMinPerspectiveW = 1.0 / 64.0;
// The farthest a transformed glyph's bbox corner may land from its pen, in pixels.
inline constexpr double kMaxTransformedExtent = 1048576.0;

// Maps a point of a glyph's rect (texel units from the rect's top-left corner, y down) to em
// (y up). This is the texel-to-em mapping the rasterizer and its CPU reference use, for keys that
// are not transformed (em_to_texel() serves every key).
struct TexelToEm {
    float scale_x = 0.0f;   // em per texel: 1 / size_x
    float scale_y = 0.0f;   // em per texel, negated: -1 / size_y
    float offset_x = 0.0f;  // em of the rect's top-left corner
    float offset_y = 0.0f;
};
CRISP_API TexelToEm texel_to_em(const GlyphRect& rect, const GlyphKey& key);

// A projective map of the plane as a row-major 3x3 matrix: (X, Y, W) = m (x, y, 1), the point
// (X / W, Y / W).
struct Projective {
    double m[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
};

// The map from a glyph's em space (y up) to its rect's texels (y down, from the rect's top-left
// corner) at `key`, for any key: W is 1 unless the key has perspective. Its inverse (em from
// texels) is inverse(em_to_texel(...)).
CRISP_API Projective em_to_texel(const GlyphRect& rect, const GlyphKey& key);
// The inverse of a projective map; the identity for a singular one.
CRISP_API Projective inverse(const Projective& map);

// The glyph's curves that are flat in y (horizontal lines in em), as bits over its curve slots
// (glyph.band_words words; empty when it has none). No band lists them, since a horizontal ray
// never crosses one, but the oblique rows of a transformed glyph do. A slot counts when its three
// points share y and its control point is not its start (a pad slot between contours repeats its
// start; a line's control point is its midpoint). `asset` must be valid (load_asset()).
CRISP_API std::vector<uint32_t> flat_curve_words(const FontAsset& asset, const GlyphRecord& glyph);

// What one sample of every texel of the glyph's rect costs the rasterizer, in curve tests: the
// sum over the rect's rows of its width times the curves listed in the band of the row's centre;
// for a blurred key, each texel's term times the passes its wider row takes (one per 8 crossings
// of the row within the blur's reach of the texel, at least one). The atlas budgets its samples
// in these units. 0 for a glyph without curves.
CRISP_API uint64_t curve_tests_per_sample(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key);

inline float size_to_float(uint32_t fixed) {
    return static_cast<float>(fixed) / static_cast<float>(kSizeOne);
}
inline float subpixel_to_float(uint8_t fixed) {
    return static_cast<float>(fixed) / static_cast<float>(kSubpixelSteps);
}

}  // namespace crisp
