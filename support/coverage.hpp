// The two CPU references the GPU rasterizer is held to (docs/coverage.md):
//
// 1. Sample coverage: the nonzero winding number of a ray cast from a point sample towards +x,
//    with Eric Lengyel's root classification (the "Slug" method), exactly as the compute shader
//    evaluates it; and the mean of such point hits over R2-placed samples. Row samples: the
//    covered length of a horizontal segment under the nonzero rule, from the same roots sorted
//    along the row, and its mean over van der Corput rows. Float instantiations repeat the
//    shader's operations in the shader's order.
// 2. Exact coverage: the area fraction of a rectangle covered by a glyph under the nonzero rule,
//    from sorted crossings integrated over y. It shares no code with (1) and is what (1) converges
//    to as samples grow.
//
// Windings follow Slug's sign: a crossing where the curve runs downwards (y falling as t grows)
// adds +1, upwards -1. An outline that runs clockwise in y-up (TrueType outer contours) winds +1,
// counter-clockwise (CFF outer contours) -1; the nonzero rule fills both.
//
// Functions taking a FontAsset expect a valid one (load_asset or validate_asset passed it): they
// index its points and band words without further checks.
#pragma once

#include "asset/curves.hpp"

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp {

// Below this |a| (the t^2 coefficient of y(t), em) the curve is solved as a line, as in Slug.
inline constexpr double kLinearEpsilon = 1.0 / 65536.0;

// The R2 sequence: sample n of a rectangle sits at frac(0.5 + n * (kR2StepX, kR2StepY)) of it
// (the shader's gpu::kRasterR2StepX and kRasterR2StepY, in double).
inline constexpr double kR2StepX = 0.7548776662466927;  // 1 / g, g the plastic number 1.3247...
inline constexpr double kR2StepY = 0.5698402909980532;  // 1 / g^2

// How a root of y(t) = 0 is computed once the classification has said which roots count.
enum class RootSolver {
    // The contract the shader implements: t = (b -+ d) / a, and t = c / (2 b) when |a| is below
    // kLinearEpsilon.
    slug,
    // A proposal, measured in docs/coverage.md: the eligible root from the form without
    // cancellation, c / (b +- d) or (b -+ d) / a, which also covers the linear case without an
    // epsilon. Not what the shader does unless it is changed to match.
    stable,
};

// The winding contribution of one quadratic to a +x ray from the sample, given the control
// points relative to the sample (x1 = p0.x - s.x, ...): -1, 0 or +1. Real is float (the shader's
// arithmetic, operation for operation; see docs/coverage.md for the sequence) or double.
template <class Real>
int curve_winding(Real x1, Real y1, Real x2, Real y2, Real x3, Real y3, RootSolver solver = RootSolver::slug);

// The same for a double-precision curve and sample.
int curve_winding(const Quad& curve, Vec2 sample, RootSolver solver = RootSolver::slug);

// Winding number at `sample` over the given curves (each one curve of a closed outline).
int winding_number(std::span<const Quad> curves, Vec2 sample, RootSolver solver = RootSolver::slug);

// Winding number at `sample` over the slots of a packed glyph (2 * is_curve.size() + 1 points)
// whose is_curve entry is set: every real curve, flat ones included, pads excluded. An asset does
// not say which slots are pads; the baker's PackedGlyph does.
int winding_number(std::span<const Point> glyph_points, std::span<const uint8_t> is_curve, Vec2 sample,
                   RootSolver solver = RootSolver::slug);

// The GPU's form: the winding number over the curves listed in the band FontAsset::band_of(glyph,
// float(y_em)). Exact: see the comment in coverage.cpp. Real = float mirrors the shader (the
// relative coordinates are p - s in float); Real = double is the reference.
template <class Real>
int winding_number_banded(const FontAsset& asset, const GlyphRecord& glyph, Real x_em, Real y_em,
                          RootSolver solver = RootSolver::slug);

// The slots listed in any band of the glyph, ascending: its real curves less the flat ones.
std::vector<uint32_t> listed_curves(const FontAsset& asset, const GlyphRecord& glyph);

// The curves listed in any band, as double-precision quadratics.
std::vector<Quad> listed_quads(const FontAsset& asset, const GlyphRecord& glyph);

// Offset of R2 sample n within a unit square, in [0, 1)^2, computed in double.
Vec2 r2_offset(uint32_t n);

// ---- Row samples (shaders/raster/raster.comp's row_samples(); docs/coverage.md, "Row samples").

// Crossings inside one segment kept at once (gpu::kRasterRowCrossings): a segment with more is
// finished by further passes over the curves, each from the last crossing kept. Exact either way.
inline constexpr uint32_t kRowCrossings = 8;
// Row sample n sits at height frac(radical_inverse_2(n) + kRowOffset) of the rect
// (gpu::kRasterRowOffset): 1/16 + 1/128 + 1/1024, 73/1024.
inline constexpr double kRowOffset = 0.0712890625;

// The base-2 radical inverse of n (van der Corput): n's bits mirrored about the binary point.
double radical_inverse_2(uint32_t n);
// Height of row sample n within a rect, in [0, 1): exact in float as in double for n < 2^23.
double row_height(uint32_t n);
// The quantization dither of row sample n, frac(0.5 + n * kR2StepX), computed in float as the
// shader does.
float row_dither(uint32_t n);

// The covered length under the nonzero rule of the segment [x0, x1] at height y over the given
// curves: the winding at x0 from the roots right of it, then the roots inside (x0, x1) sorted
// and walked, kRowCrossings at a time. Real = float mirrors the shader (curves rounded to float);
// double is the reference. `passes`, when given, receives how many passes over the curves the
// segment took (1 unless more than kRowCrossings crossings lie inside it).
template <class Real>
Real row_covered_length(std::span<const Quad> curves, Real y, Real x0, Real x1, uint32_t* passes = nullptr);

// The same over the curves listed in the band FontAsset::band_of(glyph, float(y)), as the shader.
template <class Real>
Real row_covered_length_banded(const FontAsset& asset, const GlyphRecord& glyph, Real y, Real x0, Real x1,
                               uint32_t* passes = nullptr);

// What a row sample adds to its channel's accumulator: the covered fraction covered / length in
// `one` units, floor(fraction * one + dither), clamped to [0, one]; 0 for a segment of no length.
// Real = float is the shader's arithmetic.
template <class Real>
uint32_t row_units(Real covered, Real length, Real dither, uint32_t one);

// What row sample n of texel (tx, ty) of a glyph rect (mapped to em by `map`) adds to each channel
// of `layout`, in float as shaders/raster/raster.comp computes it with shared row roots (the renderer's
// default): channels that share their rows (shares_sample_rows) walk one row across the union of
// their segments, each covered stretch clipped to each channel's segment; otherwise each channel
// walks its own row. Each channel then adds row_units(..., row_dither(n), 64). `passes`, when
// given, receives the passes over the curves all rows took together.
std::array<uint32_t, 3> row_sample_units(const FontAsset& asset, const GlyphRecord& glyph, const TexelToEm& map,
                                         const SubpixelLayout& layout, uint32_t tx, uint32_t ty, uint32_t n,
                                         uint32_t* passes = nullptr);

// Mean over the row samples first_sample .. first_sample + sample_count - 1 of the covered fraction
// of the segment [x0, x1] at height y0 + row_height(n) (y1 - y0), in double. `quantized`: each
// sample's fraction as the atlas holds it, row_units(..., double(row_dither(n)), 64) / 64;
// otherwise exact. 0 when sample_count is 0.
double coverage_rows(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1,
                     uint32_t sample_count, uint32_t first_sample = 0, bool quantized = true);

// Fraction of the samples first_sample .. first_sample + sample_count - 1, placed by R2 in the em
// rectangle [x0, x1] x [y0, y1] (offset (u, v) maps to (x0 + u (x1 - x0), y0 + v (y1 - y0))), whose
// banded double winding number is nonzero. 0 when sample_count is 0.
double coverage_points(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1,
                       uint32_t sample_count, uint32_t first_sample = 0);

// A glyph prepared for exact area coverage: its curves cut into pieces monotonic in y.
class ExactCoverage {
public:
    // The curves listed in any band of the glyph (pads and flat curves, which bound no area, are
    // listed in none).
    ExactCoverage(const FontAsset& asset, const GlyphRecord& glyph);
    // Any closed outlines given as their curves.
    explicit ExactCoverage(std::span<const Quad> curves);

    // Area (em^2) of [x0, x1] x [y0, y1] where the nonzero winding number is nonzero. 0 for an
    // empty or inverted rectangle. Accurate to about 1e-12 of the rectangle's area.
    double area(double x0, double y0, double x1, double y1) const;

    // area() divided by the rectangle's area, in [0, 1]; 0 for an empty rectangle.
    double coverage(double x0, double y0, double x1, double y1) const;

    // The winding number at (x, y) from the sorted-crossing walk (no root classification): a piece
    // monotonic in y crosses the ray when y is in (its lowest y, its highest y], and counts when
    // its crossing lies strictly right of x. A reference for the sample function.
    int winding(double x, double y) const;

private:
    struct Piece {
        Quad curve;
        double t0 = 0.0, t1 = 1.0;  // parameter interval over which y is monotonic
        double y_lo = 0.0, y_hi = 0.0;
        double x_lo = 0.0, x_hi = 0.0;  // x-extent of the piece
        int direction = 0;              // +1 when y falls along t (Slug's root 1), -1 when it rises
    };
    void add_curve(const Quad& curve);
    double crossing_x(const Piece& piece, double y) const;
    double covered_length(std::span<const Piece* const> active, double y, double x0, double x1) const;
    double integrate(std::span<const Piece* const> active, double ya, double yb, double x0, double x1,
                     double allowed_error) const;

    std::vector<Piece> pieces_;
};

// ExactCoverage(asset, glyph).coverage(x0, y0, x1, y1). For many rectangles, prepare once.
double exact_coverage(const FontAsset& asset, const GlyphRecord& glyph, double x0, double y0, double x1, double y1);

}  // namespace crisp
