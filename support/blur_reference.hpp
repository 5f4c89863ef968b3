// The CPU reference of blurred layers (docs/effects.md, "Blur"): the exact blurred coverage of a
// texel channel, the integral over y of the y filter's density times, over the covered stretches
// of the row at y, the x filter's CDF across each (src/text/blur_kernel.hpp). The stretches come
// from the exact crossings of the row with the curves (cut where their y turns, each crossing
// solved in double), under the nonzero rule, of one set of curves or, for a derived glyph, of two
// sets combined by its op. The y integral is adaptive Simpson between the filter's knots and the
// heights where a curve starts, ends or turns. It shares no code with the rasterizer's path but
// blur_kernel.hpp.
#pragma once

#include "asset/curves.hpp"
#include "text/stroke.hpp"

#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp {

class BlurReference {
public:
    // The glyph `set_a` (em, y up; closed contours) under the nonzero rule, or with `set_b`, the
    // region where `op` holds of (inside A, inside B).
    explicit BlurReference(std::span<const Quad> set_a, std::span<const Quad> set_b = {}, StrokeOp op = StrokeOp::a);

    // A glyph of an asset, and a derived glyph with its op (its slots some band lists, and those
    // flat in em y, which cross a transformed glyph's rows; split at set_b_first).
    static BlurReference of_glyph(const FontAsset& asset, const GlyphRecord& glyph);
    static BlurReference of_derived(const DerivedGlyph& derived, StrokeOp op);

    // Each channel's blurred coverage of texel (tx, ty) of a glyph rect mapped to em by `map`, for
    // a blur of box width `w` texels (w = 2 R / 3; 0: no blur, the channel's exact area).
    // The integration aims at `tolerance` per channel; error() then holds the largest estimate
    // (Simpson's |S2 - S1| / 15) of any call so far.
    std::array<double, 3> texel(const TexelToEm& map, const SubpixelLayout& layout, uint32_t tx, uint32_t ty, double w,
                                double tolerance = 1e-6) const;
    // The same for any key's rect, `to_texel` its em_to_texel() (affine: W must be 1).
    std::array<double, 3> texel(const Projective& to_texel, const SubpixelLayout& layout, uint32_t tx, uint32_t ty,
                                double w, double tolerance = 1e-6) const;
    double error() const { return error_; }

private:
    struct Piece {
        Quad curve;  // texel units (x right, y down) after texel() maps it
        double t0 = 0.0, t1 = 1.0;
        double y_lo = 0.0, y_hi = 0.0;
        bool in_b = false;
    };
    struct Row {
        double x;
        int direction;
        bool in_b;
    };
    void add_pieces(const Quad& curve, bool in_b, std::vector<Piece>& out) const;
    double row(const std::vector<Piece>& pieces, double y, double x0, double x1, double w,
               std::vector<Row>& scratch) const;

    std::vector<Quad> a_, b_;
    StrokeOp op_;
    mutable double error_ = 0.0;
};

}  // namespace crisp
