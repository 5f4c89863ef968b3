// crisp: text drawn at a transform: rotated, scaled, sheared or mirrored in the target's plane,
// or on a plane in world space seen through the caller's view-projection (docs/transforms.md).
//
// A transformed glyph stays an axis-aligned rect of the target's pixels: its key carries the
// transform's linear part (and perspective, where one affine map is not enough), quantized, and
// the rasterizer integrates each texel's channel rectangles over the transformed outline, so the
// compositor draws it like any glyph and its texels converge like any glyph's.
#pragma once

#include <crisp/export.hpp>

#include <crisp/glyph.hpp>
#include <crisp/layout.hpp>

#include <array>
#include <cstdint>

namespace crisp {

// A 2D transform of a draw's glyphs in the target's pixels (x right, y down): a pen p lands at
//     pivot + L (p - pivot),   L = {a, b; c, d}: x' = a x + b y, y' = c x + d y,
// and each glyph's outline is mapped by L too. DrawOptions::offset moves the result. A rotation
// by t clockwise on screen (y down) is {cos t, -sin t, sin t, cos t}.
struct TextTransform {
    float a = 1.0f, b = 0.0f, c = 0.0f, d = 1.0f;
    float pivot_x = 0.0f;  // target pixels, y down
    float pivot_y = 0.0f;
};

// Text on a plane in world space: layout pixel (x, y) (y down, as the layout placed it) lies at
// world point origin + x axis_x + y axis_y, which the caller's view-projection takes to clip
// space (Vulkan's: NDC y down, depth 0..1) and the viewport to target pixels:
//     pixel = (viewport[0] + (ndc.x + 1) / 2 viewport[2], viewport[1] + (ndc.y + 1) / 2 viewport[3]).
// Each glyph's depth is its centre's NDC z (as depth_from_view_projection() gives), for the draw
// path's depth test and the compositor's order.
struct TextPlane {
    std::array<float, 3> origin{};
    std::array<float, 3> axis_x{1.0f, 0.0f, 0.0f};   // world units per layout pixel along the text
    std::array<float, 3> axis_y{0.0f, -1.0f, 0.0f};  // world units per layout pixel down the text
    std::array<float, 16> view_projection{1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f,
                                          0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};  // column-major
    std::array<float, 4> viewport{};  // x, y, width, height: target pixels
};

// Where a glyph is drawn when it is not axis-aligned: em (y up) to target pixels (y down),
//     pixel = pen + (L e) / (1 + p . e),  L = {linear[0], linear[1]; linear[2], linear[3]}.
struct GlyphPlacement {
    double pen_x = 0.0;  // target pixels, y down: where the em origin lands
    double pen_y = 0.0;
    double linear[4] = {};       // pixels per em
    double perspective[2] = {};  // per em
};

// Quantization of a transformed key (transformed_key()): the linear part's and perspective's steps
// in their key units, and the pen's subpixel steps per pixel.
struct TransformSteps {
    uint32_t linear = 1;                 // 1: 1/256 px per em (still text); 64: 1/4 px per em (moving text)
    uint32_t perspective = 1;            // 1: 2^-20 per em; 1024: 2^-10
    uint32_t subpixel = kSubpixelSteps;  // 1, 2, 4, ..., 256
};
// Steps of text that stays, and of text whose transform changes every few frames.
inline constexpr TransformSteps kStillTransformSteps{1, 1, kSubpixelSteps};
inline constexpr TransformSteps kMovingTransformSteps{64, 1024, 4};

// `glyph` with its key, rect and pen made for `place`: the linear part and perspective quantized
// at `steps` (an axis-aligned linear part with positive diagonal and no perspective gives the
// untransformed key), the pen split into its whole pixel and subpixel offset. False, leaving
// `glyph` unchanged, when any value is not finite, the linear part is singular (|det| below
// 2^-16 px^2 per em^2) or beyond 2^22 px per em, the perspective is beyond 2^10 per em, or the pen
// lies beyond 2^24 px. A key that passes may still have an empty rect (glyph_rect()).
CRISP_API bool place_glyph(const GlyphRecord& record, const GlyphPlacement& place, const TransformSteps& steps,
                           GlyphInstance& glyph);

// Whether a TextTransform can be drawn: finite, |det| at least 2^-16 and no entry beyond 2^16.
CRISP_API bool valid_transform(const TextTransform& transform);
// Whether a TextPlane can be drawn: finite, axes neither zero nor parallel, a viewport of positive
// size.
CRISP_API bool valid_plane(const TextPlane& plane);

// The placement of a glyph laid out at pen (pen_x, pen_y) with pixels per em (size_x, size_y)
// under `transform`, then moved by (dx, dy).
CRISP_API GlyphPlacement place_transformed(const TextTransform& transform, double pen_x, double pen_y, double size_x,
                                           double size_y, double dx, double dy);

// The largest distance (pixels) between a perspective placement and the local affine one at which
// the local affine is used: past it the glyph's key keeps its perspective (exact projective
// coverage). The bound holds at the corners of the glyph's bbox, where the difference is largest.
inline constexpr double kMaxLocalAffineError = 1.0 / 128.0;

// A glyph on a plane: its placement (the local affine map at its bbox centre, the Jacobian of the
// projection there, or the exact projective one where that is more than kMaxLocalAffineError
// off), the local affine's error, and its depth.
struct PlanePlacement {
    GlyphPlacement place;
    double affine_error = 0.0;  // pixels: the local affine's largest distance from the projection
    bool projective = false;    // the placement keeps its perspective
    float depth = 0.0f;         // NDC z of the bbox centre
    bool visible = false;       // false: some bbox corner is behind the eye or out of range
};
// The placement of glyph `record` laid out at pen (pen_x, pen_y) with (size_x, size_y) pixels per
// em on `plane` (valid_plane()).
CRISP_API PlanePlacement place_on_plane(const TextPlane& plane, const GlyphRecord& record, double pen_x, double pen_y,
                                        double size_x, double size_y);

}  // namespace crisp
