// crisp: text effects drawn from the same coverage as the text (docs/effects.md): an outline,
// a drop shadow (hard or blurred), a glow and a weight (emboldening or thinning), per draw
// (DrawOptions::effects).
//
// Each effect is a layer of the glyph: an outline of its own (the glyph stroked, curves offset into
// quadratics on the CPU, cached per glyph and width in em) rasterized and converged in the atlas
// like any glyph, exact and sharp at every size, at the glyph's depth and ordered under or over it
// (DrawnGlyph::stack), so the compositor blends them exactly.
#pragma once

#include <crisp/export.hpp>

#include <crisp/result.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace crisp {

// Where an outline of width w lies about the glyph's edge.
enum class OutlinePlacement : uint8_t {
    outside,  // the band between the edge and the edge grown by w, drawn under the glyph
    inside,   // the band between the edge and the edge shrunk by w, drawn over the glyph
    centred,  // w / 2 either side of the edge, drawn over the glyph
};

// How an outline turns a corner: a round join keeps every point within w of the edge (the
// outline is then exactly the points that near); a miter extends the two edges' offsets to their
// meeting point while the miter ratio 1 / sin(alpha / 2) (alpha the corner's angle, SVG's rule) is
// within the limit, else bevels; a bevel cuts the corner straight.
enum class LineJoin : uint8_t { round, miter, bevel };

struct TextOutline {
    float width = 1.0f;  // target pixels at the glyph's size (sqrt(size_x size_y) px per em)
    OutlinePlacement placement = OutlinePlacement::outside;
    LineJoin join = LineJoin::round;
    // Miter joins: at least 1; kept to a 2^(1/16) step (4.4 %), and at most kMaxMiterLimit.
    float miter_limit = 4.0f;
    std::array<float, 4> color{0.0f, 0.0f, 0.0f, 1.0f};  // sRGB, straight alpha, as DrawOptions::color
    friend bool operator==(const TextOutline&, const TextOutline&) = default;
};

// A drop shadow: the glyph (with its outline, where it has one) in `color`, moved by the offset,
// blurred by `blur` and drawn under everything else of the draw. The blur of radius R is exact
// (not sampled from a texture): per axis three boxes of width 2R/3 (reaching R, sigma R/3)
// convolved with each texel channel's own sample interval, converged in the atlas like the text.
// A transformed glyph's layer is blurred in the target's pixels, after the transform.
struct TextShadow {
    float offset_x = 2.0f;  // target pixels, y down
    float offset_y = 2.0f;
    std::array<float, 4> color{0.0f, 0.0f, 0.0f, 0.5f};  // sRGB, straight alpha
    float blur = 0.0f;  // radius, target pixels, 0 to kMaxEffectBlur; 0: a hard shadow; kept to 1/64 px
    friend bool operator==(const TextShadow&, const TextShadow&) = default;
};

// A glow: the glyph (with its outline, where it has one) blurred by `radius` in `color`, unmoved,
// drawn over the shadow and under the outline and the face (kStackGlow), at the draw's first
// paint order.
struct TextGlow {
    float radius = 4.0f;  // target pixels, more than 0 up to kMaxEffectBlur; kept to 1/64 px
    std::array<float, 4> color{1.0f, 1.0f, 1.0f, 0.75f};  // sRGB, straight alpha
    friend bool operator==(const TextGlow&, const TextGlow&) = default;
};

struct TextEffects {
    // Pixels the face grows by (positive: bolder, miter joins) or shrinks by (negative: thinner),
    // on every side of every stem; 0 draws the glyph's own outline.
    float weight = 0.0f;
    // An outside outline reaches `width` past the face as weighted (a positive weight); inside and
    // centred ones, and any with a negative weight, lie about the glyph's own edge.
    std::optional<TextOutline> outline;
    std::optional<TextShadow> shadow;
    std::optional<TextGlow> glow;
    friend bool operator==(const TextEffects&, const TextEffects&) = default;
};

// The farthest a shadow may be moved, in pixels, on each axis.
inline constexpr float kMaxShadowOffset = 4096.0f;
// The largest outline width and |weight|, in pixels: far past any use (and past the glyph's own
// size limit in em, which DrawOptions checks per glyph: kMaxEffectReachEm).
inline constexpr float kMaxEffectWidth = 4096.0f;
// How far an effect may reach past a glyph's edge, in em of its size: an outline of width w
// reaches w (centred: w / 2) plus the weight; past this the glyph's layer is not drawn
// (RendererStats::failed_effects).
inline constexpr float kMaxEffectReachEm = 4.0f;
inline constexpr float kMaxMiterLimit = 128.0f;
// The largest blur radius of a shadow or glow, in pixels.
inline constexpr float kMaxEffectBlur = 128.0f;

// Names as files and command lines write them: "outside", "inside", "centred"; "round", "miter",
// "bevel" ("unknown" for a value outside the enum). The parsers return nullopt for any other name.
CRISP_API const char* outline_placement_name(OutlinePlacement placement);
CRISP_API const char* line_join_name(LineJoin join);
CRISP_API std::optional<OutlinePlacement> parse_outline_placement(std::string_view name);
CRISP_API std::optional<LineJoin> parse_line_join(std::string_view name);

// Success when every field is finite and in its range; otherwise invalid_argument naming the
// field and its value ("effects: outline width -1 is negative"). With `size` (pixels per em,
// positive), also refuses effects that reach past kMaxEffectReachEm at that size.
CRISP_API Status validate_text_effects(const TextEffects& effects);
CRISP_API Status validate_text_effects(const TextEffects& effects, float size);

}  // namespace crisp
