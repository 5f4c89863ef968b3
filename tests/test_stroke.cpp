// Stroke geometry (docs/effects.md): the pieces' nonzero union held per texel to the exact
// reference (support/stroke_reference.hpp) for every join and op, their orientation, the
// refusals, the derived glyph's packing, and FreeType's stroker as an outside check.
#include "coverage.hpp"
#include "shape_support.hpp"
#include "stroke_reference.hpp"
#include "test_support.hpp"

#include "text/stroke.hpp"

#include <crisp/font.hpp>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_GLYPH_H
#include FT_OUTLINE_H
#include FT_STROKER_H

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace crisp {
namespace {

const Font& font() {
    static const std::unique_ptr<Font> made = test::bake_test_font("MW4o@");
    EXPECT_TRUE(made);
    return *made;
}

std::vector<Contour> glyph_of(char32_t c) {
    const Font& f = font();
    return glyph_contours(f.asset(), *f.glyph_record(f.nominal_glyph(c)));
}

std::vector<Quad> flattened(const std::vector<Contour>& contours) {
    std::vector<Quad> out;
    for (const Contour& c : contours) out.insert(out.end(), c.begin(), c.end());
    return out;
}

double signed_area(const Contour& contour) {
    double twice = 0.0;
    const auto cross = [](Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; };
    for (const Quad& q : contour)
        twice += (2.0 * cross(q.p0, q.p1) + 2.0 * cross(q.p1, q.p2) + cross(q.p0, q.p2)) / 3.0;
    return 0.5 * twice;
}

// The pieces' cover under `op` by areas: A, B and A + B under the nonzero rule (all clockwise).
struct PieceCoverage {
    ExactCoverage a, b, both;
    StrokeOp op;
    PieceCoverage(const std::vector<Contour>& pieces, const std::vector<Contour>& glyph, StrokeOp o)
        : a(flattened(pieces)), b(flattened(glyph)), both(joined(pieces, glyph)), op(o) {}
    static std::vector<Quad> joined(const std::vector<Contour>& pieces, const std::vector<Contour>& glyph) {
        std::vector<Quad> all = flattened(pieces);
        const std::vector<Quad> g = flattened(glyph);
        all.insert(all.end(), g.begin(), g.end());
        return all;
    }
    double coverage(double x0, double y0, double x1, double y1) const {
        const double ca = a.coverage(x0, y0, x1, y1), cb = b.coverage(x0, y0, x1, y1);
        const double cu = both.coverage(x0, y0, x1, y1);
        switch (op) {
            case StrokeOp::a:
                return ca;
            case StrokeOp::a_not_b:
                return cu - cb;
            case StrokeOp::a_and_b:
                return ca + cb - cu;
            case StrokeOp::a_or_b:
                return cu;
            case StrokeOp::b_not_a:
                return cu - ca;
        }
        return 0.0;
    }
};

struct Case {
    const char* name;
    std::vector<Contour> glyph;
    StrokeJoin join;
    double miter_limit;
    double half_width;
    StrokeOp op;
};

struct Measured {
    double worst = 0.0;
    double reference_error = 0.0;  // the reference's own largest error estimate, per texel
    size_t pieces = 0, curves = 0;
};

// Every texel of the case's bounds at `pixels` per em.
Measured measure(const Case& c, double pixels) {
    Measured m;
    StrokeStyle style;
    style.half_width = c.half_width;
    style.join = c.join;
    style.miter_limit = c.miter_limit;
    style.tolerance = 1.0 / (1024.0 * pixels);  // a quarter of 1/256 px
    std::vector<Contour> pieces;
    const Status made = stroke_pieces(c.glyph, style, pieces);
    EXPECT_TRUE(made) << c.name << ": " << (made ? "" : made.error().message);
    m.pieces = pieces.size();
    for (const Contour& p : pieces) m.curves += p.size();
    const StrokeReference reference(c.glyph, c.join, c.half_width, c.miter_limit, c.op);
    const PieceCoverage covered(pieces, c.glyph, c.op);
    double bx0, by0, bx1, by1;
    reference.bounds(bx0, by0, bx1, by1);
    const double texel = 1.0 / pixels;
    const auto tx0 = static_cast<int>(std::floor(bx0 * pixels)), tx1 = static_cast<int>(std::ceil(bx1 * pixels));
    const auto ty0 = static_cast<int>(std::floor(by0 * pixels)), ty1 = static_cast<int>(std::ceil(by1 * pixels));
    for (int ty = ty0; ty < ty1; ++ty) {
        for (int tx = tx0; tx < tx1; ++tx) {
            const double x0 = tx * texel, y0 = ty * texel;
            const StrokeArea exact = reference.area(x0, y0, x0 + texel, y0 + texel);
            const double want = exact.area / (texel * texel);
            const double got = covered.coverage(x0, y0, x0 + texel, y0 + texel);
            m.worst = std::max(m.worst, std::abs(got - want));
            m.reference_error = std::max(m.reference_error, exact.error / (texel * texel));
        }
    }
    return m;
}

const char* join_name(StrokeJoin join) {
    return join == StrokeJoin::round ? "round" : join == StrokeJoin::miter ? "miter" : "bevel";
}

void expect_case(const Case& c, double pixels) {
    const Measured m = measure(c, pixels);
    std::printf(
        "%-5s %-5s limit %4.1f r %.4f em op %d at %3.0f px: %5zu pieces %6zu curves, worst texel %.2e "
        "(reference %.1e)\n",
        c.name, join_name(c.join), c.miter_limit, c.half_width, static_cast<int>(c.op), pixels, m.pieces, m.curves,
        m.worst, m.reference_error);
    EXPECT_LE(m.worst, 1.0 / 256.0) << c.name << " " << join_name(c.join) << " r " << c.half_width << " at " << pixels
                                    << " px";
    EXPECT_LE(m.reference_error, 1e-5);
}

struct JoinCase {
    StrokeJoin join;
    double limit;
};
constexpr JoinCase kJoins[] = {
    {StrokeJoin::round, 4.0},  {StrokeJoin::miter, 1.0}, {StrokeJoin::miter, 4.0},
    {StrokeJoin::miter, 10.0}, {StrokeJoin::bevel, 4.0},
};

TEST(Stroke, CentredStrokeMatchesReferenceAtSmallSizes) {
    const std::pair<const char*, std::vector<Contour>> shapes[] = {
        {"star", test::star()}, {"M", glyph_of('M')}, {"W", glyph_of('W')}, {"4", glyph_of('4')}, {"o", glyph_of('o')}};
    for (const auto& [name, glyph] : shapes) {
        for (const JoinCase& j : kJoins) {
            for (double r : {0.002, 0.03, 0.125}) {
                for (double pixels : {8.0, 16.0}) expect_case({name, glyph, j.join, j.limit, r, StrokeOp::a}, pixels);
            }
        }
    }
}

TEST(Stroke, CentredStrokeMatchesReferenceAt48Pixels) {
    const std::pair<const char*, std::vector<Contour>> shapes[] = {
        {"star", test::star()}, {"M", glyph_of('M')}, {"W", glyph_of('W')}, {"4", glyph_of('4')}, {"o", glyph_of('o')}};
    for (const auto& [name, glyph] : shapes) {
        for (const JoinCase& j : kJoins) {
            for (double r : {0.002, 0.125}) expect_case({name, glyph, j.join, j.limit, r, StrokeOp::a}, 48.0);
        }
    }
}

TEST(Stroke, CentredStrokeMatchesReferenceAt200Pixels) {
    expect_case({"star", test::star(), StrokeJoin::miter, 4.0, 0.03, StrokeOp::a}, 200.0);
    expect_case({"M", glyph_of('M'), StrokeJoin::round, 4.0, 0.03, StrokeOp::a}, 200.0);
    expect_case({"4", glyph_of('4'), StrokeJoin::bevel, 4.0, 0.01, StrokeOp::a}, 200.0);
    expect_case({"o", glyph_of('o'), StrokeJoin::round, 4.0, 0.125, StrokeOp::a}, 200.0);
}

// Where r passes a curve's radius of curvature its concave side is strips, which reach about
// r delta / 2 past a curve's end normal: beside a miter or bevel corner that may round a tight bend.
// '@' has such bends next to corners.
TEST(Stroke, FoldingBendsBesideCornersMatchReference) {
    for (StrokeJoin join : {StrokeJoin::miter, StrokeJoin::bevel, StrokeJoin::round}) {
        for (double r : {0.05, 0.2}) expect_case({"@", glyph_of('@'), join, 4.0, r, StrokeOp::a}, 16.0);
    }
    expect_case({"@", glyph_of('@'), StrokeJoin::miter, 10.0, 0.2, StrokeOp::a}, 48.0);
}

TEST(Stroke, EveryOpMatchesReference) {
    for (StrokeOp op : {StrokeOp::a_not_b, StrokeOp::a_and_b, StrokeOp::a_or_b, StrokeOp::b_not_a}) {
        for (double pixels : {16.0, 48.0}) {
            // Thinning by 0.05 em would leave nothing of the 'o' (its stems are 0.09 em wide).
            expect_case({"o", glyph_of('o'), StrokeJoin::round, 4.0, op == StrokeOp::b_not_a ? 0.015 : 0.05, op},
                        pixels);
            expect_case({"M", glyph_of('M'), StrokeJoin::miter, 4.0, 0.03, op}, pixels);
            expect_case({"star", test::star(), StrokeJoin::bevel, 4.0, 0.06, op}, pixels);
        }
    }
}

TEST(Stroke, PiecesWindClockwiseAndNeverCancel) {
    for (const auto& glyph : {test::star(), glyph_of('M'), glyph_of('o'), glyph_of('@')}) {
        for (StrokeJoin join : {StrokeJoin::round, StrokeJoin::miter, StrokeJoin::bevel}) {
            for (double r : {0.005, 0.05, 0.25}) {
                StrokeStyle style{r, join, 4.0, 1e-4};
                std::vector<Contour> pieces;
                ASSERT_TRUE(stroke_pieces(glyph, style, pieces));
                ASSERT_FALSE(pieces.empty());
                const ExactCoverage exact(flattened(pieces));
                for (const Contour& p : pieces) {
                    EXPECT_LT(signed_area(p), 0.0);
                    EXPECT_EQ(p.front().p0, p.back().p2);
                    for (size_t i = 0; i + 1 < p.size(); ++i) EXPECT_EQ(p[i].p2, p[i + 1].p0);
                }
                // No point winds negatively: a piece wound the other way would cancel an overlap.
                const StrokeReference reference(glyph, join, r, 4.0, StrokeOp::a);
                double x0, y0, x1, y1;
                reference.bounds(x0, y0, x1, y1);
                int holes = 0;
                for (int i = 0; i < 64; ++i) {
                    for (int k = 0; k < 64; ++k) {
                        const Vec2 p{x0 + (x1 - x0) * (i + 0.5) / 64, y0 + (y1 - y0) * (k + 0.5) / 64};
                        const int w = exact.winding(p.x, p.y);
                        EXPECT_GE(w, 0);
                        // A point well inside S(r) (its whole tolerance disc) is covered.
                        bool deep = true;
                        for (int a = 0; a < 8 && deep; ++a) {
                            const double t = a * std::numbers::pi / 4;
                            deep = reference.in_stroke({p.x + 2e-4 * std::cos(t), p.y + 2e-4 * std::sin(t)});
                        }
                        if (deep && reference.in_stroke(p) && w == 0) ++holes;
                    }
                }
                EXPECT_EQ(holes, 0);
            }
        }
    }
}

TEST(Stroke, PieceCounts) {
    for (char32_t c : {U'o', U'M', U'W', U'4', U'@'}) {
        const std::vector<Contour> glyph = glyph_of(c);
        for (double r : {0.01, 0.05, 0.2}) {
            for (StrokeJoin join : {StrokeJoin::round, StrokeJoin::miter}) {
                std::vector<Contour> pieces;
                const Status made = stroke_pieces(glyph, {r, join, 4.0, 1e-4}, pieces);
                ASSERT_TRUE(made) << made.error().message;
                size_t curves = 0;
                for (const Contour& p : pieces) curves += p.size();
                std::printf("'%c' (%zu curves) r %.2f em %s, tolerance 1e-4 em: %zu pieces, %zu curves\n",
                            static_cast<char>(c), flattened(glyph).size(), r, join_name(join), pieces.size(), curves);
                EXPECT_LT(curves, 40 * flattened(glyph).size() + 400);
            }
        }
    }
}

TEST(Stroke, RefusesBadParameters) {
    const std::vector<Contour> glyph = glyph_of('o');
    const auto refused = [&](StrokeStyle style, const char* names) {
        std::vector<Contour> pieces{test::star()[0]};
        const Status status = stroke_pieces(glyph, style, pieces);
        EXPECT_FALSE(status);
        if (!status) {
            EXPECT_EQ(status.error().code, ErrorCode::invalid_argument);
            EXPECT_NE(status.error().message.find(names), std::string::npos) << status.error().message;
        }
        EXPECT_EQ(pieces.size(), 1u);
    };
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    refused({nan, StrokeJoin::round, 4.0, 1e-4}, "half_width");
    refused({inf, StrokeJoin::round, 4.0, 1e-4}, "half_width");
    refused({-0.01, StrokeJoin::round, 4.0, 1e-4}, "half_width");
    refused({0.01, StrokeJoin::round, 4.0, 0.0}, "tolerance");
    refused({0.01, StrokeJoin::round, 4.0, -1e-4}, "tolerance");
    refused({0.01, StrokeJoin::round, 4.0, nan}, "tolerance");
    refused({0.01, StrokeJoin::miter, 0.5, 1e-4}, "miter_limit");
    refused({0.01, StrokeJoin::miter, nan, 1e-4}, "miter_limit");
    refused({4.5, StrokeJoin::round, 4.0, 1e-4}, "kMaxStrokeHalfWidthEm");
    // Past the curve bound: a quarter em at a tolerance of 1e-14 em.
    refused({0.25, StrokeJoin::round, 4.0, 1e-14}, "kMaxStrokeCurves");
    std::vector<Contour> bad = glyph;
    bad[0][0].p1.x = nan;
    std::vector<Contour> pieces;
    EXPECT_FALSE(stroke_pieces(bad, {0.01, StrokeJoin::round, 4.0, 1e-4}, pieces));
    EXPECT_TRUE(pieces.empty());
    // A zero width is S(0): the outline itself, no area.
    EXPECT_TRUE(stroke_pieces(glyph, {0.0, StrokeJoin::round, 4.0, 1e-4}, pieces));
    EXPECT_TRUE(pieces.empty());
}

TEST(Stroke, GlyphContoursAreTheGlyph) {
    const Font& f = font();
    const GlyphRecord& o = *f.glyph_record(f.nominal_glyph('o'));
    const std::vector<Contour> contours = glyph_contours(f.asset(), o);
    ASSERT_EQ(contours.size(), 2u);
    for (const Contour& c : contours) EXPECT_EQ(c.front().p0, c.back().p2);
    for (char32_t ch : {U'M', U'4', U'@'}) {
        const GlyphRecord& g = *f.glyph_record(f.nominal_glyph(ch));
        const ExactCoverage from_asset(f.asset(), g), from_contours(flattened(glyph_contours(f.asset(), g)));
        const double a = from_asset.area(-1, -1, 2, 2), b = from_contours.area(-1, -1, 2, 2);
        EXPECT_GT(a, 0.01);
        EXPECT_NEAR(a, b, 1e-12);
    }
}

// Every texel of a 64 px grid over the contours: the boundary's nonzero fill is the contours'.
double worst_fill_difference(const std::vector<Contour>& contours, const std::vector<Contour>& boundary) {
    const ExactCoverage a(flattened(contours)), b(flattened(boundary));
    double worst = 0.0;
    for (int ty = -16; ty < 80; ++ty) {
        for (int tx = -16; tx < 80; ++tx) {
            const double x0 = tx / 64.0, y0 = ty / 64.0;
            worst = std::max(worst, std::abs(a.coverage(x0, y0, x0 + 1 / 64.0, y0 + 1 / 64.0) -
                                             b.coverage(x0, y0, x0 + 1 / 64.0, y0 + 1 / 64.0)));
        }
    }
    return worst;
}

// Every boundary curve has the fill on its right (clockwise in y-up) and not on its left.
void expect_fill_on_the_right(const std::vector<Contour>& boundary) {
    const ExactCoverage fill(flattened(boundary));
    for (const Contour& c : boundary) {
        EXPECT_EQ(c.front().p0, c.back().p2);
        for (const Quad& q : c) {
            const Vec2 m = evaluate(q, 0.5), d = q.p2 - q.p0;
            const double len = length(d), e = 2e-6;
            if (len < 1e-6) continue;
            const Vec2 left{-d.y / len * e, d.x / len * e};
            const auto covered = [&](Vec2 p) { return fill.coverage(p.x - 5e-7, p.y - 5e-7, p.x + 5e-7, p.y + 5e-7); };
            EXPECT_LT(covered(m + left), 0.5) << m.x << ", " << m.y;
            EXPECT_GT(covered(m - left), 0.5) << m.x << ", " << m.y;
        }
    }
}

TEST(Stroke, BoundaryOfOverlappingContoursIsTheFillsEdge) {
    // A plus of two overlapping bars, both clockwise: one contour of twelve lines.
    const std::vector<Contour> plus = {test::polygon({{0.1, 0.3}, {0.1, 0.5}, {0.7, 0.5}, {0.7, 0.3}}),
                                       test::polygon({{0.3, 0.1}, {0.3, 0.7}, {0.5, 0.7}, {0.5, 0.1}})};
    const std::vector<Contour> b = boundary_contours(plus);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_EQ(b[0].size(), 12u);
    EXPECT_LT(worst_fill_difference(plus, b), 1e-9);
    expect_fill_on_the_right(b);
    // A square inside another of the same direction is no edge of the fill; a hole (the other
    // direction) is.
    const Contour outer = test::polygon({{0.0, 0.0}, {0.0, 0.8}, {0.8, 0.8}, {0.8, 0.0}});
    const Contour inner = test::polygon({{0.2, 0.2}, {0.2, 0.6}, {0.6, 0.6}, {0.6, 0.2}});
    const Contour hole = test::polygon({{0.2, 0.2}, {0.6, 0.2}, {0.6, 0.6}, {0.2, 0.6}});
    EXPECT_EQ(boundary_contours({outer, inner}).size(), 1u);
    EXPECT_EQ(boundary_contours({outer, hole}).size(), 2u);
    // Curves: two overlapping discs, both clockwise: one contour around their union.
    const std::vector<Contour> discs = {test::circle(0.3, 0.4, 0.25, true), test::circle(0.5, 0.4, 0.25, true)};
    const std::vector<Contour> lens = boundary_contours(discs);
    ASSERT_EQ(lens.size(), 1u);
    EXPECT_LT(worst_fill_difference(discs, lens), 1e-9);
    expect_fill_on_the_right(lens);
    // A glyph without overlaps is its own boundary, curve for curve.
    for (char32_t ch : {U'o', U'M', U'@'}) {
        const std::vector<Contour> g = glyph_of(ch);
        EXPECT_EQ(boundary_contours(g), g);
    }
}

TEST(Stroke, UnionOfFillsWoundEitherWay) {
    // A ring and a bar across it, its hole and beyond its sides, the bar wound the other way (a
    // CFF layer among TrueType ones): their windings added would cancel where they overlap.
    const std::vector<Contour> ring = {test::circle(0.5, 0.4, 0.4, true), test::circle(0.5, 0.4, 0.2, false)};
    const Contour bar_cw = test::polygon({{0.1, 0.3}, {0.1, 0.5}, {0.9, 0.5}, {0.9, 0.3}});
    const Contour bar_ccw = test::polygon({{0.1, 0.3}, {0.9, 0.3}, {0.9, 0.5}, {0.1, 0.5}});
    std::vector<Contour> same_way = ring;
    same_way.push_back(bar_cw);
    const std::vector<Contour> u = union_boundary({ring, {bar_ccw}});
    EXPECT_LT(worst_fill_difference(same_way, u), 1e-9);
    expect_fill_on_the_right(u);
    // Fills that share edges and touch: a square, the bar on its sides, a disc touching them.
    const Contour square = test::polygon({{0.1, 0.0}, {0.1, 0.8}, {0.9, 0.8}, {0.9, 0.0}});
    const std::vector<Contour> s = union_boundary({{square}, {bar_ccw}, {test::circle(0.5, 0.4, 0.4, false)}});
    ASSERT_EQ(s.size(), 1u);
    EXPECT_LT(worst_fill_difference({square}, s), 1e-9);
    expect_fill_on_the_right(s);
    // One fill: boundary_contours().
    EXPECT_EQ(union_boundary({ring}), boundary_contours(ring));
}

TEST(Stroke, BoundaryOfAVariableFontsOverlappingGlyphs) {
    // Inter's variable masters draw 'A', 'Q' and others with overlapping contours.
    auto inter = test::bake_subset(test::kInterVariable, "AQR8&");
    ASSERT_TRUE(inter);
    uint32_t overlapping = 0;
    for (char32_t ch : {U'A', U'Q', U'R', U'8', U'&'}) {
        const std::vector<Contour> g = glyph_contours(inter->asset(), *inter->glyph_record(inter->nominal_glyph(ch)));
        const std::vector<Contour> b = boundary_contours(g);
        overlapping += b != g;
        EXPECT_LT(worst_fill_difference(g, b), 1e-7) << static_cast<char>(ch);
        expect_fill_on_the_right(b);
    }
    EXPECT_GT(overlapping, 0u);
}

TEST(Stroke, DerivedGlyphPacksPiecesThenTheGlyph) {
    const Font& f = font();
    const FontAsset& asset = f.asset();
    const GlyphRecord& glyph = *f.glyph_record(f.nominal_glyph('4'));
    std::vector<Contour> pieces;
    ASSERT_TRUE(stroke_pieces(glyph_contours(asset, glyph), {0.04, StrokeJoin::miter, 4.0, 1e-4}, pieces));
    const Result<DerivedGlyph> derived = pack_derived_glyph(pieces, asset, glyph);
    ASSERT_TRUE(derived);
    const DerivedGlyph& d = derived.value();
    size_t piece_curves = 0;
    for (const Contour& p : pieces) piece_curves += p.size();
    EXPECT_EQ(d.set_b_first, piece_curves + pieces.size());  // a pad after each piece
    EXPECT_EQ(d.record.curve_count, d.set_b_first + glyph.curve_count);
    ASSERT_EQ(d.points.size(), 2 * size_t{d.record.curve_count} + 1);
    for (uint32_t i = 0; i <= 2 * glyph.curve_count; ++i)
        EXPECT_EQ(d.points[2 * size_t{d.set_b_first} + i], asset.points[glyph.point_offset + i]);
    EXPECT_EQ(d.band_words.size(), size_t{d.record.band_count} * d.record.band_words);
    EXPECT_EQ(d.record.band_words, (d.record.curve_count + 31) / 32);
    EXPECT_GT(d.record.band_count, 1u);
    for (const Point& p : d.points) {
        EXPECT_GE(p.x, d.record.bbox_min_x);
        EXPECT_LE(p.x, d.record.bbox_max_x);
        EXPECT_GE(p.y, d.record.bbox_min_y);
        EXPECT_LE(p.y, d.record.bbox_max_y);
    }
    // Through the bands it is the union of the pieces and the glyph.
    FontAsset alone;
    alone.points = d.points;
    alone.band_words = d.band_words;
    alone.glyphs = {d.record};
    const ExactCoverage banded(alone, alone.glyphs[0]);
    const ExactCoverage direct(PieceCoverage::joined(pieces, glyph_contours(asset, glyph)));
    const std::vector<uint32_t> listed = listed_curves(alone, alone.glyphs[0]);
    EXPECT_TRUE(std::any_of(listed.begin(), listed.end(), [&](uint32_t s) { return s >= d.set_b_first; }));
    for (double y = -0.1; y < 0.8; y += 0.05) {
        EXPECT_NEAR(banded.area(-0.1, y, 0.8, y + 0.05), direct.area(-0.1, y, 0.8, y + 0.05), 1e-6);
        for (double x = -0.05; x < 0.75; x += 0.0371) {
            EXPECT_EQ(winding_number_banded<double>(alone, alone.glyphs[0], x, y + 0.013) != 0,
                      direct.winding(x, y + 0.013) != 0);
        }
    }
    // No pieces: set B alone, from slot 0.
    const Result<DerivedGlyph> bare = pack_derived_glyph({}, asset, glyph);
    ASSERT_TRUE(bare);
    EXPECT_EQ(bare.value().set_b_first, 0u);
    EXPECT_EQ(bare.value().record.curve_count, glyph.curve_count);
}

// The per-texel form the GPU tests compare with: a glyph rect's texels (y down) mapped to em by
// texel_to_em(), each channel's rectangle of the layout.
TEST(Stroke, ReferenceTexelsAreTheChannelsRectangles) {
    const Font& f = font();
    const uint32_t index = f.nominal_glyph('o');
    const GlyphRecord& o = *f.glyph_record(index);
    const StrokeReference reference(glyph_contours(f.asset(), o), StrokeJoin::round, 0.05, 4.0, StrokeOp::a_not_b);
    const GlyphKey key = test::key_at(index, 16, 0, 0);
    const GlyphRect rect = glyph_rect(o, key);
    const TexelToEm map = texel_to_em(rect, key);
    const SubpixelLayout rgb = *subpixel_preset("rgb");
    int partial = 0;
    for (uint32_t ty = 0; ty < rect.height; ++ty) {
        for (uint32_t tx = 0; tx < rect.width; ++tx) {
            const std::array<double, 3> got = reference.texel(map, rgb, tx, ty);
            for (size_t c = 0; c < 3; ++c) {
                const SampleRect& r = rgb.channels[c];
                const auto em_x = [&](double x) {
                    return static_cast<double>(map.offset_x) + static_cast<double>(map.scale_x) * x;
                };
                const auto em_y = [&](double y) {
                    return static_cast<double>(map.offset_y) + static_cast<double>(map.scale_y) * y;
                };
                const double want =
                    reference.coverage(em_x(tx + static_cast<double>(r.x0)), em_y(ty + static_cast<double>(r.y1)),
                                       em_x(tx + static_cast<double>(r.x1)), em_y(ty + static_cast<double>(r.y0)));
                EXPECT_NEAR(got[c], want, 1e-12);
                if (want > 0.01 && want < 0.99) ++partial;
            }
        }
    }
    EXPECT_GT(partial, 50);
}

// FreeType's stroker (round caps and joins) on 'o', 'M' and '4' at 48 px beside the reference's
// centred round stroke, per texel. Its curves approximate the offsets differently (and it strokes
// the outline FreeType loads, at 26.6 precision), so the check is loose; the figures are reported.
TEST(Stroke, FreeTypeStrokerAgreesLoosely) {
    FT_Library library = nullptr;
    ASSERT_EQ(FT_Init_FreeType(&library), 0);
    FT_Face face = nullptr;
    ASSERT_EQ(FT_New_Face(library, test::kDejaVuSans.c_str(), 0, &face), 0);
    const double pixels = 48.0;
    ASSERT_EQ(FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixels)), 0);
    FT_Stroker stroker = nullptr;
    ASSERT_EQ(FT_Stroker_New(library, &stroker), 0);
    for (char32_t c : {U'o', U'M', U'4'}) {
        for (double r : {0.01, 0.05}) {
            ASSERT_EQ(FT_Load_Char(face, c, FT_LOAD_NO_BITMAP | FT_LOAD_NO_HINTING), 0);
            FT_Glyph ft_glyph = nullptr;
            ASSERT_EQ(FT_Get_Glyph(face->glyph, &ft_glyph), 0);
            // FreeType's radius is in 26.6 pixels: the reference strokes at the width it rounds to.
            const long radius = std::lround(r * pixels * 64.0);
            const double ft_r = static_cast<double>(radius) / (pixels * 64.0);
            FT_Stroker_Set(stroker, radius, FT_STROKER_LINECAP_ROUND, FT_STROKER_LINEJOIN_ROUND, 0);
            ASSERT_EQ(FT_Glyph_Stroke(&ft_glyph, stroker, 1), 0);
            const FT_Outline& outline = reinterpret_cast<FT_OutlineGlyph>(ft_glyph)->outline;
            // The stroked outline in em (26.6 pixels / pixels), cubics lowered as the baker does.
            struct Walk {
                std::vector<Quad> quads;
                Vec2 at;
                double scale;
            } walk{{}, {}, 1.0 / (64.0 * pixels)};
            FT_Outline_Funcs funcs{};
            funcs.move_to = [](const FT_Vector* to, void* user) {
                auto* w = static_cast<Walk*>(user);
                w->at = {static_cast<double>(to->x) * w->scale, static_cast<double>(to->y) * w->scale};
                return 0;
            };
            funcs.line_to = [](const FT_Vector* to, void* user) {
                auto* w = static_cast<Walk*>(user);
                const Vec2 p{static_cast<double>(to->x) * w->scale, static_cast<double>(to->y) * w->scale};
                w->quads.push_back(line_to_quad(w->at, p));
                w->at = p;
                return 0;
            };
            funcs.conic_to = [](const FT_Vector* control, const FT_Vector* to, void* user) {
                auto* w = static_cast<Walk*>(user);
                const Vec2 k{static_cast<double>(control->x) * w->scale, static_cast<double>(control->y) * w->scale};
                const Vec2 p{static_cast<double>(to->x) * w->scale, static_cast<double>(to->y) * w->scale};
                w->quads.push_back({w->at, k, p});
                w->at = p;
                return 0;
            };
            funcs.cubic_to = [](const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
                auto* w = static_cast<Walk*>(user);
                const Cubic cubic{w->at,
                                  {static_cast<double>(c1->x) * w->scale, static_cast<double>(c1->y) * w->scale},
                                  {static_cast<double>(c2->x) * w->scale, static_cast<double>(c2->y) * w->scale},
                                  {static_cast<double>(to->x) * w->scale, static_cast<double>(to->y) * w->scale}};
                lower_cubic(cubic, 1e-6, w->quads);
                w->at = cubic.p3;
                return 0;
            };
            FT_Outline_Decompose(const_cast<FT_Outline*>(&outline), &funcs, &walk);
            FT_Done_Glyph(ft_glyph);
            const ExactCoverage peer(walk.quads);
            const StrokeReference reference(glyph_of(c), StrokeJoin::round, ft_r, 4.0, StrokeOp::a);
            double x0, y0, x1, y1;
            reference.bounds(x0, y0, x1, y1);
            const double texel = 1.0 / pixels;
            double worst = 0.0, sum = 0.0, area_ref = 0.0, area_peer = 0.0;
            int count = 0;
            for (double y = std::floor(y0 * pixels) * texel; y < y1; y += texel) {
                for (double x = std::floor(x0 * pixels) * texel; x < x1; x += texel) {
                    const double want = reference.coverage(x, y, x + texel, y + texel);
                    const double got = peer.coverage(x, y, x + texel, y + texel);
                    worst = std::max(worst, std::abs(got - want));
                    sum += std::abs(got - want);
                    area_ref += want;
                    area_peer += got;
                    ++count;
                }
            }
            std::printf("FT_Stroker '%c' r %.2f em at 48 px: worst texel %.4f, mean %.5f, area %.2f vs %.2f texels\n",
                        static_cast<char>(c), r, worst, sum / count, area_peer, area_ref);
            EXPECT_LT(worst, 0.1);
            EXPECT_NEAR(area_peer, area_ref, 0.01 * area_ref);
        }
    }
    FT_Stroker_Done(stroker);
    FT_Done_Face(face);
    FT_Done_FreeType(library);
}

}  // namespace
}  // namespace crisp
