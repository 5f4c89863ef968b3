// Stroke geometry for text effects (docs/effects.md, "Stroke geometry"): a glyph's outline grown
// into S(r), the region within half-width r of it (round joins; miter and bevel joins replace the
// round corners), as closed contours of quadratics ("pieces") whose nonzero union is S(r) within a
// tolerance; and the packing of an effect layer, pieces (set A) then the glyph's own curves (set
// B), into a glyph the rasterizer draws with a boolean of the two sets' windings.
#pragma once

#include "asset/curves.hpp"
#include "core/limits.hpp"

#include <crisp/asset.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <vector>

namespace crisp {

enum class StrokeJoin : uint8_t { round, miter, bevel };

// What an effect layer covers, from the windings of set A (the pieces, S(w) or S(w / 2)) and set
// B (the glyph G): a centred outline is a, an outside one a_not_b, an inside one a_and_b, weight
// +w a_or_b, weight -w b_not_a.
enum class StrokeOp : uint8_t { a, a_not_b, a_and_b, a_or_b, b_not_a };

constexpr bool stroke_op_covers(StrokeOp op, bool in_a, bool in_b) {
    switch (op) {
        case StrokeOp::a:
            return in_a;
        case StrokeOp::a_not_b:
            return in_a && !in_b;
        case StrokeOp::a_and_b:
            return in_a && in_b;
        case StrokeOp::a_or_b:
            return in_a || in_b;
        case StrokeOp::b_not_a:
            return in_b && !in_a;
    }
    return false;
}

struct StrokeStyle {
    double half_width = 0.0;  // r, em: S(r) reaches r either side of the outline
    StrokeJoin join = StrokeJoin::round;
    // Miter joins: a corner whose miter ratio 1 / sin(alpha / 2) (alpha the angle between its two
    // segments, SVG's rule) passes this is bevelled. At least 1.
    double miter_limit = 4.0;
    double tolerance = 1.0 / 16384.0;  // em: the pieces' boundary lies within this of S(r)'s
};

// The glyph's closed contours as the asset stores them: every real curve in slot order (flat ones
// included, pads left out), a new contour after each pad. Expects a valid asset (load_asset or
// validate_asset passed it).
std::vector<Contour> glyph_contours(const FontAsset& asset, const GlyphRecord& glyph);

// The boundary of the contours' nonzero fill as closed contours, clockwise in y-up where the fill
// is inside: each curve cut where another crosses it, the pieces with the fill on one side only
// kept (the parts of overlapping contours inside the fill, which stroking would outline, go), and
// chained. Contours that neither overlap nor cross come back as they are; where the pieces cannot be
// chained (coincident stretches the cuts miss) the contours come back too.
std::vector<Contour> boundary_contours(const std::vector<Contour>& contours);
// The same for the union of several nonzero fills (a colour glyph's layers: its silhouette), the
// contours of each fill wound either way: every piece turned to have the union on its right.
// Where the pieces cannot be chained, all fills' contours come back as they are (whose windings
// may cancel where fills of opposite directions overlap).
std::vector<Contour> union_boundary(const std::vector<std::vector<Contour>>& fills);

// Appends to `pieces` closed contours of quadratics, all wound clockwise in y-up (+1 by the
// rasterizer's rule), whose nonzero union is S(style.half_width) of `contours` within
// style.tolerance: each curve's perpendicular sweep (split where it turns by more than 40 degrees
// and where its offsets leave the tolerance; cut into short sheared strips on a side where its
// radius of curvature falls below r), and a join at each corner. Contours whose last point is not
// their first are stroked open, without a join there.
// Errors (ErrorCode::invalid_argument, naming the parameter): a half-width that is negative, not
// finite or past limits::kMaxStrokeHalfWidthEm, a tolerance that is not positive and finite, a miter limit below 1 or
// not finite, a contour point that is not finite, or pieces past limits::kMaxStrokeCurves curves; `pieces` is then left
// as it was.
Status stroke_pieces(const std::vector<Contour>& contours, const StrokeStyle& style, std::vector<Contour>& pieces);

// An effect layer's glyph, ready to upload: `record`'s point_offset and band_offset are 0 (the
// caller places `points` and `band_words`), its advance, bearings and flags the source glyph's.
struct DerivedGlyph {
    GlyphRecord record;
    std::vector<Point> points;         // 2 * record.curve_count + 1
    std::vector<uint32_t> band_words;  // record.band_count * record.band_words
    uint32_t set_b_first = 0;          // first curve slot of set B (the glyph's own curves)
};

// Packs `pieces` as set A (contours joined by pad slots), a pad, then the glyph's own slots
// (pads included) copied point for point as set B, with the bands the baker would give a glyph of
// that many curves over the bbox of all points. With no pieces set B starts at slot 0. Errors
// (ErrorCode::invalid_argument) when the slots would pass limits::kMaxStrokeCurves plus the glyph's.
Result<DerivedGlyph> pack_derived_glyph(const std::vector<Contour>& pieces, const FontAsset& asset,
                                        const GlyphRecord& glyph);
// The same with set B the closed contours `set_b` (a colour glyph's silhouette), the advance,
// bearings and flags `base`'s. Errors as above, and when set B passes limits::kMaxStrokeCurves.
Result<DerivedGlyph> pack_derived_glyph(const std::vector<Contour>& pieces, const std::vector<Contour>& set_b,
                                        const GlyphRecord& base);

}  // namespace crisp
