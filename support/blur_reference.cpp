#include "blur_reference.hpp"

#include "text/blur_kernel.hpp"

#include <algorithm>
#include <cmath>

namespace crisp {

namespace {

double bezier(double a, double b, double c, double t) {
    const double s = 1.0 - t;
    return s * s * a + 2.0 * s * t * b + t * t * c;
}

// The t in [t0, t1] where the y of `q` (monotonic over [t0, t1]) is y.
double solve_y(const Quad& q, double t0, double t1, double y) {
    const double a = q.p0.y - 2.0 * q.p1.y + q.p2.y;
    const double b = 2.0 * (q.p1.y - q.p0.y);
    const double c = q.p0.y - y;
    double t = 0.5 * (t0 + t1);
    const double scale = std::abs(q.p0.y) + std::abs(q.p1.y) + std::abs(q.p2.y) + 1.0;
    if (std::abs(a) <= 1e-14 * scale) {
        if (b != 0.0) t = -c / b;
    } else {
        const double disc = std::max(b * b - 4.0 * a * c, 0.0);
        const double qq = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        const double r1 = qq / a, r2 = qq != 0.0 ? c / qq : r1;
        const double mid = 0.5 * (t0 + t1);
        const auto distance = [&](double r) { return r < t0 ? t0 - r : r > t1 ? r - t1 : 0.0; };
        t = distance(r1) < distance(r2) || (distance(r1) == distance(r2) && std::abs(r1 - mid) < std::abs(r2 - mid))
                ? r1
                : r2;
    }
    t = std::clamp(t, t0, t1);
    // Two Newton steps polish what cancellation left.
    for (int i = 0; i < 2; ++i) {
        const double f = bezier(q.p0.y, q.p1.y, q.p2.y, t) - y;
        const double d = 2.0 * ((1.0 - t) * (q.p1.y - q.p0.y) + t * (q.p2.y - q.p1.y));
        if (d == 0.0) break;
        t = std::clamp(t - f / d, t0, t1);
    }
    return t;
}

Quad to_texels(const Quad& q, const Projective& to_texel) {
    const double* m = to_texel.m;
    const auto point = [&](Vec2 p) { return Vec2{m[0] * p.x + m[1] * p.y + m[2], m[3] * p.x + m[4] * p.y + m[5]}; };
    return {point(q.p0), point(q.p1), point(q.p2)};
}

// The curves of a packed glyph, as quads, split at slot `split` into two sets: the slots some band
// lists, and the curves flat in em y, which no band lists but which cross a transformed glyph's
// rows (a slot whose three points share y and whose control point is not its start: a pad slot
// repeats its start).
void curves_of(const GlyphRecord& record, std::span<const Point> points, std::span<const uint32_t> band_words,
               uint32_t split, std::vector<Quad>& a, std::vector<Quad>& b) {
    for (uint32_t slot = 0; slot < record.curve_count; ++slot) {
        const uint32_t word = slot / 32, bit = slot % 32;
        uint32_t bits = 0;
        for (uint32_t band = 0; band < record.band_count; ++band) {
            bits |= band_words[size_t{record.band_offset} + size_t{band} * record.band_words + word];
        }
        const Point* p = &points[size_t{record.point_offset} + 2 * size_t{slot}];
        const bool flat = p[0].y == p[1].y && p[1].y == p[2].y && !(p[1].x == p[0].x && p[1].y == p[0].y);
        if (((bits >> bit) & 1u) == 0 && !flat) continue;
        const auto v = [](const Point& point) {
            return Vec2{static_cast<double>(point.x), static_cast<double>(point.y)};
        };
        const Quad q{v(p[0]), v(p[1]), v(p[2])};
        (slot >= split ? b : a).push_back(q);
    }
}

}  // namespace

BlurReference::BlurReference(std::span<const Quad> set_a, std::span<const Quad> set_b, StrokeOp op)
    : a_(set_a.begin(), set_a.end()), b_(set_b.begin(), set_b.end()), op_(op) {}

BlurReference BlurReference::of_glyph(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<Quad> a, b;
    curves_of(glyph, asset.points, asset.band_words, UINT32_MAX, a, b);
    return BlurReference(a);
}

BlurReference BlurReference::of_derived(const DerivedGlyph& derived, StrokeOp op) {
    std::vector<Quad> a, b;
    GlyphRecord record = derived.record;
    curves_of(record, derived.points, derived.band_words, derived.set_b_first, a, b);
    return BlurReference(a, b, op);
}

void BlurReference::add_pieces(const Quad& q, bool in_b, std::vector<Piece>& out) const {
    double cuts[3];
    const int n = y_monotonic_cuts(q, cuts);
    for (int i = 0; i + 1 < n; ++i) {
        Piece p;
        p.curve = q;
        p.t0 = cuts[i];
        p.t1 = cuts[i + 1];
        const double ya = bezier(q.p0.y, q.p1.y, q.p2.y, p.t0), yb = bezier(q.p0.y, q.p1.y, q.p2.y, p.t1);
        if (ya == yb) continue;  // flat: crosses no row
        p.y_lo = std::min(ya, yb);
        p.y_hi = std::max(ya, yb);
        p.in_b = in_b;
        out.push_back(p);
    }
}

// The sum over the covered stretches of the row at y of the x filter's CDF across each.
double BlurReference::row(const std::vector<Piece>& pieces, double y, double x0, double x1, double w,
                          std::vector<Row>& rows) const {
    rows.clear();
    for (const Piece& p : pieces) {
        if (!(y > p.y_lo && y <= p.y_hi)) continue;
        const double t = solve_y(p.curve, p.t0, p.t1, y);
        const double ya = bezier(p.curve.p0.y, p.curve.p1.y, p.curve.p2.y, p.t0);
        const double yb = bezier(p.curve.p0.y, p.curve.p1.y, p.curve.p2.y, p.t1);
        rows.push_back({bezier(p.curve.p0.x, p.curve.p1.x, p.curve.p2.x, t), yb > ya ? 1 : -1, p.in_b});
    }
    std::sort(rows.begin(), rows.end(), [](const Row& l, const Row& r) { return l.x < r.x; });
    int wa = 0, wb = 0;
    double sum = 0.0, at = 0.0;  // the CDF at the last crossing
    const bool two_sets = !b_.empty();
    for (const Row& r : rows) {
        const double here = blur_cdf(r.x, x0, x1, w);
        const bool covered = two_sets ? stroke_op_covers(op_, wa != 0, wb != 0) : wa != 0;
        if (covered) sum += here - at;
        at = here;
        (r.in_b ? wb : wa) += r.direction;
    }
    return sum;
}

std::array<double, 3> BlurReference::texel(const TexelToEm& map, const SubpixelLayout& layout, uint32_t tx, uint32_t ty,
                                           double w, double tolerance) const {
    // em = offset + scale * texel, inverted.
    const double sx = static_cast<double>(map.scale_x), sy = static_cast<double>(map.scale_y);
    const Projective to_texel{{1.0 / sx, 0.0, -static_cast<double>(map.offset_x) / sx, 0.0, 1.0 / sy,
                               -static_cast<double>(map.offset_y) / sy, 0.0, 0.0, 1.0}};
    return texel(to_texel, layout, tx, ty, w, tolerance);
}

std::array<double, 3> BlurReference::texel(const Projective& map, const SubpixelLayout& layout, uint32_t tx,
                                           uint32_t ty, double w, double tolerance) const {
    std::vector<Piece> pieces;
    for (const Quad& q : a_) add_pieces(to_texels(q, map), false, pieces);
    for (const Quad& q : b_) add_pieces(to_texels(q, map), true, pieces);
    std::vector<Row> scratch;
    std::array<double, 3> out{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& rect = layout.channels[c];
        // Channels that share a rect (a gray layout's three) share its coverage.
        if (c > 0 && rect == layout.channels[c - 1]) {
            out[c] = out[c - 1];
            continue;
        }
        const double x0 = tx + static_cast<double>(rect.x0), x1 = tx + static_cast<double>(rect.x1);
        const double y0 = ty + static_cast<double>(rect.y0), y1 = ty + static_cast<double>(rect.y1);
        const double lo = y0 - 1.5 * w, hi = y1 + 1.5 * w;
        // The pieces the filter's rows reach, and where the integrand may kink.
        std::vector<Piece> near;
        std::vector<double> knots = {lo, hi};
        for (const Piece& p : pieces) {
            if (p.y_hi <= lo || p.y_lo >= hi) continue;
            near.push_back(p);
            for (const double k : {p.y_lo, p.y_hi}) {
                if (k > lo && k < hi) knots.push_back(k);
            }
        }
        if (near.empty()) continue;
        if (w > 0.0) {
            for (const double base : {y0, y1}) {
                for (const double k : {-1.5, -0.5, 0.5, 1.5}) knots.push_back(base + k * w);
            }
        }
        std::sort(knots.begin(), knots.end());
        knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
        const auto f = [&](double y) {
            const double density = w > 0.0 ? blur_density(y, y0, y1, w) : 1.0 / (y1 - y0);
            if (density == 0.0) return 0.0;
            return density * row(near, y, x0, x1, w, scratch);
        };
        double total = 0.0, error = 0.0;
        const double span = hi - lo;
        for (size_t k = 0; k + 1 < knots.size(); ++k) {
            const double a = knots[k], b = knots[k + 1];
            if (!(b > a)) continue;
            // Adaptive Simpson, at least three levels deep.
            struct Frame {
                double a, b, fa, fm, fb, whole, eps;
                int depth;
            };
            const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
            std::vector<Frame> stack = {
                {a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), tolerance * (b - a) / span, 0}};
            while (!stack.empty()) {
                const Frame s = stack.back();
                stack.pop_back();
                const double m = 0.5 * (s.a + s.b);
                const double lm = f(0.5 * (s.a + m)), rm = f(0.5 * (m + s.b));
                const double left = (m - s.a) / 6.0 * (s.fa + 4.0 * lm + s.fm);
                const double right = (s.b - m) / 6.0 * (s.fm + 4.0 * rm + s.fb);
                const double diff = left + right - s.whole;
                if (s.depth >= 3 && (std::abs(diff) <= 15.0 * s.eps || s.depth >= 40)) {
                    total += left + right + diff / 15.0;
                    error += std::abs(diff) / 15.0;
                    continue;
                }
                stack.push_back({s.a, m, s.fa, lm, s.fm, left, 0.5 * s.eps, s.depth + 1});
                stack.push_back({m, s.b, s.fm, rm, s.fb, right, 0.5 * s.eps, s.depth + 1});
            }
        }
        out[c] = total;
        error_ = std::max(error_, error);
    }
    return out;
}

}  // namespace crisp
