// The CPU reference of stroke geometry (docs/effects.md, "Stroke geometry"): the exact area of
// (S(r) op G) inside a rectangle, where G is a glyph (nonzero fill) and S(r) the union of every
// curve's perpendicular sweep {c(t) + s n(t) : t in [0, 1], |s| <= r} and the joins at its corners
// (round: the disc of radius r at every contour vertex; bevel: the triangle of the corner and the
// two offset points on the outer side; miter: the miter polygon while 1 / sin(alpha / 2) is within
// the limit, else the bevel). It shares no code with the stroker (src/text/stroke.cpp): a point is
// in S(r) when a stationary point of its distance to a curve (a root of a cubic) is within r, or a
// join holds it; the area is a quadtree over the rectangle whose cells no boundary element's box
// touches are settled by their centre, and whose leaves integrate the covered length of rows
// between the exact crossings of the boundary elements (offset curves, end normals, join edges and
// circles, glyph curves) by adaptive Simpson over y.
#pragma once

#include "coverage.hpp"

#include "asset/curves.hpp"
#include "text/stroke.hpp"

#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace crisp {

struct StrokeArea {
    double area = 0.0;   // em^2
    double error = 0.0;  // the integration's own estimate of its error, em^2 (Simpson's |S2 - S1| / 15)
};

class StrokeReference {
public:
    // `glyph`: closed contours (em, y up), G by the nonzero rule and the outline S(r) strokes.
    StrokeReference(const std::vector<Contour>& glyph, StrokeJoin join, double half_width, double miter_limit,
                    StrokeOp op);
    // A colour glyph's silhouette: G the union of the fills (each by the nonzero rule, wound either
    // way), S(r) the sweeps of every curve of every fill. A sweep of a curve inside G adds nothing
    // outside G, so this is the silhouette's exact (S(r) op G) for the ops that keep S only
    // outside G (a_not_b, a_or_b); for the others, S(r) of the silhouette's boundary is not this.
    StrokeReference(const std::vector<std::vector<Contour>>& fills, StrokeJoin join, double half_width,
                    double miter_limit, StrokeOp op);
    ~StrokeReference();
    StrokeReference(StrokeReference&&) = default;

    bool in_stroke(Vec2 p) const;
    bool in_glyph(Vec2 p) const;
    bool covers(Vec2 p) const { return stroke_op_covers(op_, in_stroke(p), in_glyph(p)); }

    // Area of [x0, x1] x [y0, y1] (em) that op covers; 0 for an empty or inverted rectangle. The
    // integration aims at 1e-7 of the rectangle's area.
    StrokeArea area(double x0, double y0, double x1, double y1) const;
    double coverage(double x0, double y0, double x1, double y1) const;

    // Each channel's covered fraction of texel (tx, ty) of a glyph rect mapped to em by `map`.
    std::array<double, 3> texel(const TexelToEm& map, const SubpixelLayout& layout, uint32_t tx, uint32_t ty) const;

    // A conservative box of everything op can cover.
    void bounds(double& x0, double& y0, double& x1, double& y1) const;

private:
    struct Element {
        Quad curve;
        double x0, y0, x1, y1;  // the control polygon's box grown by r
    };
    struct Join {
        Vec2 corner;
        std::vector<Vec2> polygon;  // convex, counter-clockwise; empty for a round join's disc
    };
    // A piece of a boundary element over which its y is monotonic: an offset c(t) + s n(t) over
    // [t0, t1] (s = 0 for a glyph curve or a line), or a circle's half (circle true).
    struct Boundary {
        Quad curve;
        double s = 0.0, t0 = 0.0, t1 = 1.0;
        bool circle = false;
        double y_lo = 0.0, y_hi = 0.0, x_lo = 0.0, x_hi = 0.0;
    };

    void add_offset(const Quad& curve, double s);
    void add_segment(Vec2 a, Vec2 b);
    double covered_length(const std::vector<uint32_t>& boundary, double y, double x0, double x1) const;
    void cell(const std::vector<uint32_t>& boundary, double x0, double y0, double x1, double y1, int depth,
              double tolerance, StrokeArea& out) const;
    double integrate(const std::vector<uint32_t>& boundary, double x0, double x1, double ya, double yb, double fa,
                     double fm, double fb, double whole, double tolerance, int depth, double& error) const;

    StrokeJoin join_;
    double r_;
    double miter_limit_;
    StrokeOp op_;
    std::vector<std::vector<Quad>> fill_curves_;
    std::vector<std::unique_ptr<ExactCoverage>> fills_;  // each fill's winding: G is where any is nonzero
    std::vector<Element> elements_;
    std::vector<Join> joins_;
    std::vector<Boundary> boundary_;
};

}  // namespace crisp
