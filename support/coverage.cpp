#include "coverage.hpp"

#include "shared.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>

// The float instantiation must round exactly where the shader rounds: no fused multiply-adds.
// GCC does not contract in ISO mode (-std=c++20, as the build sets); clang contracts within an
// expression unless told not to.
#if defined(__clang__)
#pragma clang fp contract(off)
#endif

namespace crisp {

static_assert(kRowCrossings == gpu::kRasterRowCrossings);
static_assert(static_cast<float>(kRowOffset) == gpu::kRasterRowOffset);
static_assert(kRowOffset == 1.0 / 16 + 1.0 / 128 + 1.0 / 1024);
static_assert(static_cast<float>(kR2StepX) == gpu::kRasterR2StepX);
static_assert(static_cast<float>(kR2StepY) == gpu::kRasterR2StepY);

// -------------------------------------------------------------------------------------------------
// 1. The sample function.
//
// With y1, y2, y3 the control points' heights relative to the ray, the curve is
// y(t) = a t^2 - 2 b t + c with a = y1 - 2 y2 + y3, b = y1 - y2, c = y1, whose roots are
// t1 = (b - d) / a and t2 = (b + d) / a, d = sqrt(b^2 - a c). The slope there is
// y'(t1) = 2 (a t1 - b) = -2 d <= 0 and y'(t2) = +2 d >= 0 whatever the sign of a: root 1 is where
// the curve runs downwards through the ray and root 2 where it runs upwards. The +x ray from a
// point inside a clockwise (y-up) contour meets the contour's right side running downwards, so
// "+1 at root 1, -1 at root 2" makes clockwise +1 and counter-clockwise -1.
//
// Which roots lie on the curve (t in [0, 1]) follows from the signs alone. Call a control point
// "below" when its relative height is negative (the sign bit, so -0.0 is below), "above" otherwise;
// shift = below(y1) | below(y2) << 1 | below(y3) << 2 and the two bits of (0x2E74 >> shift) & 0x0101
// say whether root 1 (bit 0) and root 2 (bit 8) count:
//
//   shift  y1 y2 y3   curve                                             root 1  root 2
//     0    +  +  +    never reaches below the ray                         -       -
//     1    -  +  +    starts below, ends above: one upward crossing       -       x
//     2    +  -  +    starts and ends above: dips below twice, or not     x       x
//     3    -  -  +    starts below, ends above: one upward crossing       -       x
//     4    +  +  -    starts above, ends below: one downward crossing     x       -
//     5    -  +  -    starts and ends below: rises above twice, or not    x       x
//     6    +  -  -    starts above, ends below: one downward crossing     x       -
//     7    -  -  -    never reaches above the ray                         -       -
//
// (0x2E74 has bits 2, 4, 5, 6 set for root 1 and bits 9, 10, 11, 13 for root 2, which is this
// table.) In rows 2 and 5 a curve that does not reach the ray has b^2 - a c < 0, so d is clamped to
// 0, t1 == t2, both roots give the same x and cancel. Treating 0 as "above" is the same as moving
// the ray an infinitesimal distance down: an end point on the ray is counted once, by the curve
// that arrives from below or leaves downwards, and a curve touching the ray from above or below
// adds 0. A curve flat in y has three equal signs (row 0 or 7) and never counts.
//
// Slug's linear case solves the tangent at t = 0 rather than the curve: its crossing is off by up
// to |a| < kLinearEpsilon in y, and a curve that starts flat (b == 0) divides by zero and loses
// its crossing. RootSolver::stable avoids both; docs/coverage.md measures the difference.
namespace {

// The root code of the curve whose control heights relative to the ray are y1, y2, y3, and its two
// roots t1 (running down) and t2 (running up) when the code is not 0.
template <class Real>
unsigned classified_roots(Real y1, Real y2, Real y3, RootSolver solver, Real& t1, Real& t2) {
    const unsigned shift = (std::signbit(y1) ? 1u : 0u) | (std::signbit(y2) ? 2u : 0u) | (std::signbit(y3) ? 4u : 0u);
    const unsigned code = (0x2E74u >> shift) & 0x0101u;
    if (code == 0u) return 0u;

    const Real two = 2;
    const Real zero = 0;
    const Real a = y1 - y2 * two + y3;
    const Real b = y1 - y2;
    const Real c = y1;
    if (solver == RootSolver::slug) {
        if (std::abs(a) < static_cast<Real>(kLinearEpsilon)) {
            t1 = t2 = c / (b * two);
        } else {
            const Real d = std::sqrt(std::max(b * b - a * c, zero));
            t1 = (b - d) / a;
            t2 = (b + d) / a;
        }
    } else {
        const Real discriminant = b * b - a * c;
        if (!(discriminant > zero)) {
            // A double root, or none: both roots at the vertex so that rows 2 and 5 cancel. Here
            // a != 0, or else b == 0 too and all three heights are equal (code 0).
            t1 = t2 = b / a;
        } else {
            // (b - d) / a == c / (b + d) and (b + d) / a == c / (b - d): take for each root the
            // form whose sum does not cancel. A near-linear curve's eligible root is c / (b +- d),
            // which tends to c / (2 b) as a vanishes, so no epsilon is needed.
            const Real d = std::sqrt(discriminant);
            t1 = b >= zero ? c / (b + d) : (b - d) / a;
            t2 = b <= zero ? c / (b - d) : (b + d) / a;
        }
    }
    return code;
}

}  // namespace

template <class Real>
int curve_winding(Real x1, Real y1, Real x2, Real y2, Real x3, Real y3, RootSolver solver) {
    Real t1 = 0, t2 = 0;
    const unsigned code = classified_roots(y1, y2, y3, solver, t1, t2);
    if (code == 0u) return 0;
    const Real two = 2;
    const Real zero = 0;
    const Real ax = x1 - x2 * two + x3;
    const Real bx = x1 - x2;
    const Real cx = x1;
    int winding = 0;
    if ((code & 1u) != 0u && (ax * t1 - bx * two) * t1 + cx > zero) ++winding;
    if (code > 1u && (ax * t2 - bx * two) * t2 + cx > zero) --winding;
    return winding;
}

template int curve_winding<float>(float, float, float, float, float, float, RootSolver);
template int curve_winding<double>(double, double, double, double, double, double, RootSolver);

int curve_winding(const Quad& curve, Vec2 sample, RootSolver solver) {
    return curve_winding<double>(curve.p0.x - sample.x, curve.p0.y - sample.y, curve.p1.x - sample.x,
                                 curve.p1.y - sample.y, curve.p2.x - sample.x, curve.p2.y - sample.y, solver);
}

int winding_number(std::span<const Quad> curves, Vec2 sample, RootSolver solver) {
    int winding = 0;
    for (const Quad& curve : curves) winding += curve_winding(curve, sample, solver);
    return winding;
}

namespace {

template <class Real>
int slot_winding(const Point* p, Real x, Real y, RootSolver solver) {
    return curve_winding<Real>(static_cast<Real>(p[0].x) - x, static_cast<Real>(p[0].y) - y,
                               static_cast<Real>(p[1].x) - x, static_cast<Real>(p[1].y) - y,
                               static_cast<Real>(p[2].x) - x, static_cast<Real>(p[2].y) - y, solver);
}

}  // namespace

int winding_number(std::span<const Point> glyph_points, std::span<const uint8_t> is_curve, Vec2 sample,
                   RootSolver solver) {
    assert(glyph_points.size() == 2 * is_curve.size() + 1 || is_curve.empty());
    int winding = 0;
    for (size_t slot = 0; slot < is_curve.size(); ++slot) {
        if (is_curve[slot]) winding += slot_winding<double>(&glyph_points[2 * slot], sample.x, sample.y, solver);
    }
    return winding;
}

// Why the band's curves are enough. A curve adds a nonzero amount at height y only if its control
// heights straddle y (rows 1 to 6). In rows 1, 3, 4 and 6 its end points straddle y, so the curve
// reaches y. In rows 2 and 5 it adds nonzero only if b^2 - a c rounds above 0, and the vertex
// c - b^2 / a lies on the ray's far side exactly when b^2 - a c >= 0; rounding can only misjudge a
// vertex within a few ulps of the curve's size of the ray (there |b| <= |a|). So a contributing
// curve comes within rounding of y. The baker lists a curve in every band its exact y-extent, rounded
// outwards to float, touches once the band is widened by kBandOverlap = 1/256 of its height on
// both sides, and band_of(float(y)) misplaces y across a band edge only when y is within a few
// float ulps of that edge, far inside the 1/256 overlap. So every curve that can add to the
// winding at y is in the band of y. Curves listed nowhere add nothing: flat curves are rows 0 and
// 7 at every height, and pads are not curves of any contour (testing them would be wrong, not
// merely slower). A sample above or below the bbox is clamped into the top or bottom band, where
// no curve straddles its height. tests/test_coverage.cpp checks banded == all-real-curves on
// grids over real glyphs.
template <class Real>
int winding_number_banded(const FontAsset& asset, const GlyphRecord& glyph, Real x_em, Real y_em, RootSolver solver) {
    if (glyph.band_count == 0 || glyph.band_words == 0) return 0;
    const uint32_t band = FontAsset::band_of(glyph, static_cast<float>(y_em));
    const uint32_t* words = &asset.band_words[glyph.band_offset + size_t{band} * glyph.band_words];
    const Point* points = &asset.points[glyph.point_offset];
    int winding = 0;
    for (uint32_t word = 0; word < glyph.band_words; ++word) {
        uint32_t bits = words[word];
        while (bits != 0u) {
            const auto bit = static_cast<uint32_t>(std::countr_zero(bits));
            bits &= bits - 1u;
            const uint32_t slot = word * 32u + bit;
            winding += slot_winding<Real>(points + 2 * size_t{slot}, x_em, y_em, solver);
        }
    }
    return winding;
}

template int winding_number_banded<float>(const FontAsset&, const GlyphRecord&, float, float, RootSolver);
template int winding_number_banded<double>(const FontAsset&, const GlyphRecord&, double, double, RootSolver);

std::vector<uint32_t> listed_curves(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<uint32_t> merged(glyph.band_words, 0u);
    for (uint32_t band = 0; band < glyph.band_count; ++band) {
        for (uint32_t word = 0; word < glyph.band_words; ++word) {
            merged[word] |= asset.band_words[glyph.band_offset + size_t{band} * glyph.band_words + word];
        }
    }
    std::vector<uint32_t> slots;
    for (uint32_t word = 0; word < glyph.band_words; ++word) {
        for (uint32_t bits = merged[word]; bits != 0u; bits &= bits - 1u) {
            slots.push_back(word * 32u + static_cast<uint32_t>(std::countr_zero(bits)));
        }
    }
    return slots;
}

std::vector<Quad> listed_quads(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<Quad> quads;
    auto to_vec = [](const Point& p) { return Vec2{static_cast<double>(p.x), static_cast<double>(p.y)}; };
    for (uint32_t slot : listed_curves(asset, glyph)) {
        const Point* p = &asset.points[glyph.point_offset + 2 * size_t{slot}];
        quads.push_back({to_vec(p[0]), to_vec(p[1]), to_vec(p[2])});
    }
    return quads;
}

Vec2 r2_offset(uint32_t n) {
    const double u = 0.5 + static_cast<double>(n) * kR2StepX;
    const double v = 0.5 + static_cast<double>(n) * kR2StepY;
    return {u - std::floor(u), v - std::floor(v)};
}

double coverage_points(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1,
                       uint32_t sample_count, uint32_t first_sample) {
    if (sample_count == 0) return 0.0;
    uint32_t hits = 0;
    for (uint32_t i = 0; i < sample_count; ++i) {
        const Vec2 offset = r2_offset(first_sample + i);
        const double x = x0 + offset.x * (x1 - x0);
        const double y = y0 + offset.y * (y1 - y0);
        if (winding_number_banded<double>(asset, glyph, x, y) != 0) ++hits;
    }
    return static_cast<double>(hits) / static_cast<double>(sample_count);
}

// Row samples: shaders/raster/raster.comp's row_crossing(), row_curve() and row_walk(), operation for
// operation (Real = float).

double radical_inverse_2(uint32_t n) {
    uint32_t reversed = 0;
    for (int bit = 0; bit < 32; ++bit) reversed |= ((n >> bit) & 1u) << (31 - bit);
    return static_cast<double>(reversed) * 0x1p-32;
}

double row_height(uint32_t n) {
    const double v = radical_inverse_2(n) + kRowOffset;
    return v - std::floor(v);
}

float row_dither(uint32_t n) {
    const float u = 0.5f + static_cast<float>(n) * gpu::kRasterR2StepX;
    return u - std::floor(u);
}

namespace {

// The row segment being walked (the union of the segments of the channels on the row): the
// shader's RowList.
template <class Real>
struct RowSpan {
    Real start = 0, end = 0;
    int winding = 0;  // just right of start
    uint32_t count = 0;
    bool more = false;
    std::array<Real, kRowCrossings> x{};
    std::array<int, kRowCrossings> direction{};

    void cross(Real at, int dir) {
        if (!(at > start)) return;
        winding += dir;
        if (!(at < end)) return;
        uint32_t n = count;
        if (n == kRowCrossings) {
            more = true;
            if (!(at < x[n - 1])) return;
            --n;  // every crossing dropped lies at or right of every one kept
        }
        count = n + 1;
        while (n > 0 && x[n - 1] > at) {
            x[n] = x[n - 1];
            direction[n] = direction[n - 1];
            --n;
        }
        x[n] = at;
        direction[n] = dir;
    }

    // Adds the covered stretch [from, to], clipped to each channel's segment [lo, hi], to `part`.
    static void cover(std::span<Real, 3> part, Real from, Real to, std::span<const Real, 3> lo,
                      std::span<const Real, 3> hi) {
        for (size_t c = 0; c < 3; ++c) part[c] += std::max(std::min(to, hi[c]) - std::max(from, lo[c]), Real(0));
    }

    // The covered length of each channel's segment within the part of the row this pass saw
    // (shaders/raster/raster.comp's row_walk()).
    std::array<Real, 3> walk(std::span<const Real, 3> lo, std::span<const Real, 3> hi) {
        std::array<Real, 3> part{};
        int w = winding;
        Real at = start;
        for (uint32_t i = 0; i < count; ++i) {
            if (w != 0) cover(part, at, x[i], lo, hi);
            w -= direction[i];
            at = x[i];
        }
        if (more) {
            start = at;
        } else if (w != 0) {
            cover(part, at, end, lo, hi);
        }
        return part;
    }
};

// The crossings of one curve (absolute em) with the row at height y.
template <class Real>
void row_curve(RowSpan<Real>& span, Real p0x, Real p0y, Real p1x, Real p1y, Real p2x, Real p2y, Real y) {
    Real t1 = 0, t2 = 0;
    const unsigned code = classified_roots<Real>(p0y - y, p1y - y, p2y - y, RootSolver::slug, t1, t2);
    if (code == 0u) return;
    const Real two = 2;
    const Real ax = p0x - p1x * two + p2x;
    const Real bx = p0x - p1x;
    const Real x1 = (ax * t1 - bx * two) * t1 + p0x;
    const Real x2 = (ax * t2 - bx * two) * t2 + p0x;
    // Two roots that meet (a tangent, or a curve that misses the row) cancel exactly: skipping them
    // keeps the walk the same whichever band range the curves come from.
    if (code == 0x0101u && x1 == x2) return;
    if ((code & 1u) != 0u) span.cross(x1, +1);
    if (code > 1u) span.cross(x2, -1);
}

// Passes of `for_each_curve(visit)` (visit takes the six coordinates) until the row at height y is
// walked over [start, end]; adds the covered length within each channel's segment [lo, hi] to
// covered[c] where mine[c] is 1 (0 adds nothing), as the shader does.
template <class Real, class ForEachCurve>
void row_lengths(ForEachCurve&& for_each_curve, Real y, Real start, Real end, std::span<const Real, 3> lo,
                 std::span<const Real, 3> hi, std::span<const Real, 3> mine, std::span<Real, 3> covered,
                 uint32_t* passes) {
    RowSpan<Real> span;
    span.start = start;
    span.end = end;
    uint32_t pass_count = 0;
    do {
        span.winding = 0;
        span.count = 0;
        span.more = false;
        for_each_curve([&](Real p0x, Real p0y, Real p1x, Real p1y, Real p2x, Real p2y) {
            row_curve(span, p0x, p0y, p1x, p1y, p2x, p2y, y);
        });
        const std::array<Real, 3> part = span.walk(lo, hi);
        for (size_t c = 0; c < 3; ++c) covered[c] += part[c] * mine[c];
        ++pass_count;
    } while (span.more);
    if (passes) *passes = pass_count;
}

template <class Real, class ForEachCurve>
Real row_length(ForEachCurve&& for_each_curve, Real y, Real x0, Real x1, uint32_t* passes) {
    const std::array<Real, 3> lo{x0, x0, x0}, hi{x1, x1, x1}, mine{1, 0, 0};
    std::array<Real, 3> covered{};
    row_lengths<Real>(for_each_curve, y, x0, x1, std::span<const Real, 3>(lo), std::span<const Real, 3>(hi),
                      std::span<const Real, 3>(mine), std::span<Real, 3>(covered), passes);
    return covered[0];
}

// Calls visit(p0x, p0y, p1x, p1y, p2x, p2y) for each curve listed in the band of the glyph that
// holds y (none for a glyph without bands).
template <class Real>
auto banded_curves(const FontAsset& asset, const GlyphRecord& glyph, Real y) {
    return [&asset, &glyph, y](auto&& visit) {
        if (glyph.band_count == 0 || glyph.band_words == 0) return;
        const uint32_t band = FontAsset::band_of(glyph, static_cast<float>(y));
        const uint32_t* words = &asset.band_words[glyph.band_offset + size_t{band} * glyph.band_words];
        const Point* points = &asset.points[glyph.point_offset];
        for (uint32_t word = 0; word < glyph.band_words; ++word) {
            for (uint32_t bits = words[word]; bits != 0u; bits &= bits - 1u) {
                const Point* p = points + 2 * size_t{word * 32u + static_cast<uint32_t>(std::countr_zero(bits))};
                visit(static_cast<Real>(p[0].x), static_cast<Real>(p[0].y), static_cast<Real>(p[1].x),
                      static_cast<Real>(p[1].y), static_cast<Real>(p[2].x), static_cast<Real>(p[2].y));
            }
        }
    };
}

}  // namespace

template <class Real>
Real row_covered_length(std::span<const Quad> curves, Real y, Real x0, Real x1, uint32_t* passes) {
    auto each = [&](auto&& visit) {
        for (const Quad& q : curves) {
            visit(static_cast<Real>(q.p0.x), static_cast<Real>(q.p0.y), static_cast<Real>(q.p1.x),
                  static_cast<Real>(q.p1.y), static_cast<Real>(q.p2.x), static_cast<Real>(q.p2.y));
        }
    };
    return row_length<Real>(each, y, x0, x1, passes);
}

template <class Real>
Real row_covered_length_banded(const FontAsset& asset, const GlyphRecord& glyph, Real y, Real x0, Real x1,
                               uint32_t* passes) {
    return row_length<Real>(banded_curves<Real>(asset, glyph, y), y, x0, x1, passes);
}

template <class Real>
uint32_t row_units(Real covered, Real length, Real dither, uint32_t one) {
    if (!(length > Real(0))) return 0;
    const Real units = std::floor((covered / length) * static_cast<Real>(one) + dither);
    return static_cast<uint32_t>(std::clamp(units, Real(0), static_cast<Real>(one)));
}

template float row_covered_length<float>(std::span<const Quad>, float, float, float, uint32_t*);
template double row_covered_length<double>(std::span<const Quad>, double, double, double, uint32_t*);
template float row_covered_length_banded<float>(const FontAsset&, const GlyphRecord&, float, float, float, uint32_t*);
template double row_covered_length_banded<double>(const FontAsset&, const GlyphRecord&, double, double, double,
                                                  uint32_t*);
template uint32_t row_units<float>(float, float, float, uint32_t);
template uint32_t row_units<double>(double, double, double, uint32_t);

std::array<uint32_t, 3> row_sample_units(const FontAsset& asset, const GlyphRecord& glyph, const TexelToEm& map,
                                         const SubpixelLayout& layout, uint32_t tx, uint32_t ty, uint32_t n,
                                         uint32_t* passes) {
    const auto v = static_cast<float>(row_height(n));
    std::array<float, 3> lo{}, hi{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& rect = layout.channels[c];
        lo[c] = map.offset_x + map.scale_x * (static_cast<float>(tx) + rect.x0);
        hi[c] = map.offset_x + map.scale_x * (static_cast<float>(tx) + rect.x1);
    }
    // One row for channels that share their rows, else a row per channel (the shader's `rows`).
    const size_t rows = shares_sample_rows(layout) ? 1 : 3;
    std::array<float, 3> covered{};
    uint32_t pass_count = 0;
    for (size_t row = 0; row < rows; ++row) {
        const SampleRect& rect = layout.channels[row];
        const float y = map.offset_y + map.scale_y * (static_cast<float>(ty) + (rect.y0 + (rect.y1 - rect.y0) * v));
        // Shared rows walk the union of the segments; a row of its own, its channel's segment.
        std::array<float, 3> mine{1, 1, 1};
        float start = std::min(lo[0], std::min(lo[1], lo[2]));
        float end = std::max(hi[0], std::max(hi[1], hi[2]));
        if (rows > 1) {
            mine = {0, 0, 0};
            mine[row] = 1;
            start = lo[row];
            end = hi[row];
        }
        uint32_t row_passes = 0;
        row_lengths<float>(banded_curves<float>(asset, glyph, y), y, start, end, std::span<const float, 3>(lo),
                           std::span<const float, 3>(hi), std::span<const float, 3>(mine), std::span<float, 3>(covered),
                           &row_passes);
        pass_count += row_passes;
    }
    if (passes) *passes = pass_count;
    const float dither = row_dither(n);
    return {row_units<float>(covered[0], hi[0] - lo[0], dither, 64),
            row_units<float>(covered[1], hi[1] - lo[1], dither, 64),
            row_units<float>(covered[2], hi[2] - lo[2], dither, 64)};
}

double coverage_rows(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1,
                     uint32_t sample_count, uint32_t first_sample, bool quantized) {
    if (sample_count == 0 || !(x1 > x0)) return 0.0;
    double sum = 0.0;
    for (uint32_t i = 0; i < sample_count; ++i) {
        const uint32_t n = first_sample + i;
        const double y = y0 + row_height(n) * (y1 - y0);
        const double covered = row_covered_length_banded<double>(asset, glyph, y, x0, x1);
        sum += quantized ? row_units<double>(covered, x1 - x0, static_cast<double>(row_dither(n)), 64) / 64.0
                         : covered / (x1 - x0);
    }
    return sum / static_cast<double>(sample_count);
}

// -------------------------------------------------------------------------------------------------
// 2. Exact area coverage.
//
// Cut every curve at its y-extremum into pieces monotonic in y. At a height y each piece whose
// y-range (y_lo, y_hi] holds y crosses the horizontal line once, running down (+1) or up (-1);
// sorted by x, the crossings give the winding number along the whole line, and the length of
// [x0, x1] where it is nonzero. That length L(y) is integrated over [y0, y1] after cutting it at
// every "event": piece ends (curve end points and extrema), and heights where a piece crosses
// x = x0 or x = x1. Between two events the crossings are a fixed set and L is smooth, except for
// a square-root behaviour next to an extremum (x(y) ~ x_e +- k sqrt(y - y_e)) and kinks where two
// curves cross (self-intersections, overlapping contours). The substitution
// y = ya + (yb - ya) s^2 (3 - 2 s) turns sqrt(y - ya) and sqrt(yb - y) into smooth functions of s,
// and adaptive Gauss-Legendre on s takes care of the kinks.

namespace {

constexpr int kGaussOrder = 10;

struct GaussLegendre {
    std::array<double, kGaussOrder> node{};
    std::array<double, kGaussOrder> weight{};
};

// Nodes and weights on [-1, 1] by Newton's method on the Legendre polynomial.
GaussLegendre make_gauss_legendre() {
    GaussLegendre rule;
    const int n = kGaussOrder;
    for (int i = 0; i < n; ++i) {
        double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
        double derivative = 1.0;
        for (int iteration = 0; iteration < 100; ++iteration) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            derivative = n * (x * p1 - p0) / (x * x - 1.0);
            const double step = p1 / derivative;
            x -= step;
            if (std::fabs(step) < 1e-17) break;
        }
        rule.node[static_cast<size_t>(i)] = x;
        rule.weight[static_cast<size_t>(i)] = 2.0 / ((1.0 - x * x) * derivative * derivative);
    }
    return rule;
}

const GaussLegendre& gauss_legendre() {
    static const GaussLegendre rule = make_gauss_legendre();
    return rule;
}

// Accuracy asked of an area, relative to the rectangle's, and how far the adaptive rule may
// subdivide one interval between events.
constexpr double kRelativeTolerance = 1e-13;
constexpr int kMaxDepth = 40;
constexpr int kMaxSubdivisions = 2000;

// Roots of A t^2 + B t + C = 0 without cancellation; returns how many (0 to 2).
int solve_quadratic(double A, double B, double C, double roots[2]) {
    if (A == 0.0) {
        if (B == 0.0) return 0;
        roots[0] = -C / B;
        return 1;
    }
    // Callers know a root exists (or lose nothing by a spurious one): a negative discriminant is a
    // tangent within rounding, kept as the double root.
    const double discriminant = std::max(B * B - 4.0 * A * C, 0.0);
    const double q = -0.5 * (B + std::copysign(std::sqrt(discriminant), B));
    if (q == 0.0) {
        roots[0] = 0.0;  // B == 0 and C == 0
        return 1;
    }
    roots[0] = q / A;
    roots[1] = C / q;
    return 2;
}

double x_at(const Quad& q, double t) {
    const double s = 1.0 - t;
    return s * s * q.p0.x + 2.0 * s * t * q.p1.x + t * t * q.p2.x;
}

double y_at(const Quad& q, double t) {
    const double s = 1.0 - t;
    return s * s * q.p0.y + 2.0 * s * t * q.p1.y + t * t * q.p2.y;
}

struct Crossing {
    double x;
    int direction;
};

}  // namespace

ExactCoverage::ExactCoverage(const FontAsset& asset, const GlyphRecord& glyph) {
    for (const Quad& curve : listed_quads(asset, glyph)) add_curve(curve);
}

ExactCoverage::ExactCoverage(std::span<const Quad> curves) {
    for (const Quad& curve : curves) add_curve(curve);
}

void ExactCoverage::add_curve(const Quad& curve) {
    double cuts[3];
    const int cut_count = y_monotonic_cuts(curve, cuts);
    for (int i = 0; i + 1 < cut_count; ++i) {
        Piece piece;
        piece.curve = curve;
        piece.t0 = cuts[i];
        piece.t1 = cuts[i + 1];
        const double ya = piece.t0 == 0.0 ? curve.p0.y : y_at(curve, piece.t0);
        const double yb = piece.t1 == 1.0 ? curve.p2.y : y_at(curve, piece.t1);
        if (ya == yb) continue;  // flat: never crossed
        piece.y_lo = std::min(ya, yb);
        piece.y_hi = std::max(ya, yb);
        piece.direction = yb < ya ? +1 : -1;
        const double xa = x_at(curve, piece.t0), xb = x_at(curve, piece.t1);
        piece.x_lo = std::min(xa, xb);
        piece.x_hi = std::max(xa, xb);
        const double x_denominator = curve.p0.x - 2.0 * curve.p1.x + curve.p2.x;
        if (x_denominator != 0.0) {
            const double t = (curve.p0.x - curve.p1.x) / x_denominator;
            if (t > piece.t0 && t < piece.t1) {
                piece.x_lo = std::min(piece.x_lo, x_at(curve, t));
                piece.x_hi = std::max(piece.x_hi, x_at(curve, t));
            }
        }
        pieces_.push_back(piece);
    }
}

double ExactCoverage::crossing_x(const Piece& piece, double y) const {
    const Quad& q = piece.curve;
    const double A = q.p0.y - 2.0 * q.p1.y + q.p2.y;
    const double B = 2.0 * (q.p1.y - q.p0.y);
    const double C = q.p0.y - y;
    double roots[2];
    const int count = solve_quadratic(A, B, C, roots);
    // y is monotonic on [t0, t1], so one root lies there (up to rounding): take the nearest.
    double best = 0.5 * (piece.t0 + piece.t1), best_distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < count; ++i) {
        const double clamped = std::clamp(roots[i], piece.t0, piece.t1);
        const double distance = std::fabs(clamped - roots[i]);
        if (distance < best_distance) {
            best_distance = distance;
            best = clamped;
        }
    }
    return x_at(q, best);
}

int ExactCoverage::winding(double x, double y) const {
    int winding = 0;
    for (const Piece& piece : pieces_) {
        if (piece.y_lo < y && y <= piece.y_hi && crossing_x(piece, y) > x) winding += piece.direction;
    }
    return winding;
}

double ExactCoverage::covered_length(std::span<const Piece* const> active, double y, double x0, double x1) const {
    // w(x) = sum of the directions of the crossings right of x: walk from x1 leftwards.
    int winding = 0;
    std::array<Crossing, 64> local;
    std::vector<Crossing> spill;
    size_t count = 0;
    auto push = [&](Crossing crossing) {
        if (count < local.size()) {
            local[count++] = crossing;
        } else {
            if (spill.empty()) spill.assign(local.begin(), local.end());
            spill.push_back(crossing);
            ++count;
        }
    };
    for (const Piece* piece : active) {
        if (piece->x_lo >= x1) {
            winding += piece->direction;
            continue;
        }
        const double x = crossing_x(*piece, y);
        if (x <= x0) continue;
        if (x >= x1) {
            winding += piece->direction;
            continue;
        }
        push({x, piece->direction});
    }
    std::span<Crossing> crossings =
        count <= local.size() ? std::span<Crossing>(local.data(), count) : std::span<Crossing>(spill);
    std::sort(crossings.begin(), crossings.end(), [](const Crossing& a, const Crossing& b) { return a.x > b.x; });
    double length = 0.0, right = x1;
    for (const Crossing& crossing : crossings) {
        if (winding != 0) length += right - crossing.x;
        winding += crossing.direction;
        right = crossing.x;
    }
    if (winding != 0) length += right - x0;
    return length;
}

double ExactCoverage::integrate(std::span<const Piece* const> active, double ya, double yb, double x0, double x1,
                                double allowed_error) const {
    const double height = yb - ya;
    const GaussLegendre& rule = gauss_legendre();
    // y = ya + height g(s), g(s) = s^2 (3 - 2 s), dy = height 6 s (1 - s) ds.
    auto integrand = [&](double s) {
        const double y = ya + height * (s * s * (3.0 - 2.0 * s));
        return covered_length(active, y, x0, x1) * height * 6.0 * s * (1.0 - s);
    };
    auto gauss = [&](double a, double b) {
        const double half = 0.5 * (b - a), middle = 0.5 * (a + b);
        double sum = 0.0;
        for (int i = 0; i < kGaussOrder; ++i) {
            sum += rule.weight[static_cast<size_t>(i)] * integrand(middle + half * rule.node[static_cast<size_t>(i)]);
        }
        return sum * half;
    };
    // Each part of [0, 1] may err in proportion to its width. The budget bounds the work where the
    // integrand is noisier than the allowance (a curve so flat that its x jumps between adjacent
    // doubles of y); what is left there is below the allowance anyway.
    int budget = kMaxSubdivisions;
    auto adapt = [&](auto&& self, double a, double b, double whole, int depth) -> double {
        const double middle = 0.5 * (a + b);
        const double left = gauss(a, middle), right = gauss(middle, b);
        if (std::fabs(left + right - whole) <= allowed_error * (b - a) || depth >= kMaxDepth || --budget < 0) {
            return left + right;
        }
        return self(self, a, middle, left, depth + 1) + self(self, middle, b, right, depth + 1);
    };
    return adapt(adapt, 0.0, 1.0, gauss(0.0, 1.0), 0);
}

double ExactCoverage::area(double x0, double y0, double x1, double y1) const {
    if (!(x1 > x0) || !(y1 > y0)) return 0.0;
    // Pieces that can matter: their y-range meets the rectangle's and some of them lies right of
    // x0 (a crossing left of x0 changes nothing inside the rectangle).
    std::vector<const Piece*> relevant;
    std::vector<double> events{y0, y1};
    for (const Piece& piece : pieces_) {
        if (piece.y_hi <= y0 || piece.y_lo >= y1 || piece.x_hi <= x0) continue;
        relevant.push_back(&piece);
        events.push_back(piece.y_lo);
        events.push_back(piece.y_hi);
        const Quad& q = piece.curve;
        for (const double side : {x0, x1}) {
            if (!(piece.x_lo <= side && side <= piece.x_hi)) continue;
            double roots[2];
            const int count =
                solve_quadratic(q.p0.x - 2.0 * q.p1.x + q.p2.x, 2.0 * (q.p1.x - q.p0.x), q.p0.x - side, roots);
            for (int i = 0; i < count; ++i) {
                if (roots[i] >= piece.t0 && roots[i] <= piece.t1) events.push_back(y_at(q, roots[i]));
            }
        }
    }
    if (relevant.empty()) return 0.0;
    std::sort(events.begin(), events.end());
    events.erase(std::unique(events.begin(), events.end()), events.end());

    // The error allowed in the whole area, shared by the intervals in proportion to their heights,
    // but never less than an equal share each, so that a sliver between two close events is not
    // held to an absolute accuracy that double precision cannot give it.
    const double allowed = kRelativeTolerance * (x1 - x0) * (y1 - y0);
    const double floor_share = allowed / (4.0 * static_cast<double>(events.size()));
    double area = 0.0;
    std::vector<const Piece*> active;
    for (size_t i = 0; i + 1 < events.size(); ++i) {
        const double ya = events[i], yb = events[i + 1];
        if (ya < y0 || yb > y1) continue;
        const double middle = 0.5 * (ya + yb);
        active.clear();
        for (const Piece* piece : relevant) {
            if (piece->y_lo < middle && middle < piece->y_hi) active.push_back(piece);
        }
        if (active.empty()) continue;
        area += integrate(active, ya, yb, x0, x1, std::max(allowed * (yb - ya) / (y1 - y0), floor_share));
    }
    return area;
}

double ExactCoverage::coverage(double x0, double y0, double x1, double y1) const {
    if (!(x1 > x0) || !(y1 > y0)) return 0.0;
    return std::clamp(area(x0, y0, x1, y1) / ((x1 - x0) * (y1 - y0)), 0.0, 1.0);
}

double exact_coverage(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1) {
    return ExactCoverage(asset, glyph).coverage(x0, y0, x1, y1);
}

}  // namespace crisp
