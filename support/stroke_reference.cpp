#include "stroke_reference.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace crisp {

namespace {

// The unit tangent of q at t; at an end whose control point sits on it, the chord's direction
// (the limit of the tangent there).
Vec2 tangent_at(const Quad& q, double t) {
    const Vec2 d = 2.0 * ((1.0 - t) * (q.p1 - q.p0) + t * (q.p2 - q.p1));
    const double l2 = dot(d, d);
    if (l2 > 1e-26 * (dot(q.p1 - q.p0, q.p1 - q.p0) + dot(q.p2 - q.p1, q.p2 - q.p1))) return (1.0 / std::sqrt(l2)) * d;
    const Vec2 chord = q.p2 - q.p0;
    return (1.0 / std::sqrt(dot(chord, chord))) * chord;
}
Vec2 normal_at(const Quad& q, double t) {
    const Vec2 d = tangent_at(q, t);
    return {-d.y, d.x};
}
Vec2 offset_at(const Quad& q, double t, double s) {
    return evaluate(q, t) + s * normal_at(q, t);
}

// The real roots in [0, 1] of c3 t^3 + c2 t^2 + c1 t + c0, by bisection between the polynomial's
// turning points (so each bracket holds at most one root).
void unit_roots(double c3, double c2, double c1, double c0, std::vector<double>& roots) {
    roots.clear();
    const auto f = [&](double t) { return ((c3 * t + c2) * t + c1) * t + c0; };
    double cuts[4] = {0.0, 1.0, 1.0, 1.0};
    int count = 1;
    // Turning points: roots of 3 c3 t^2 + 2 c2 t + c1.
    const double a = 3.0 * c3, b = 2.0 * c2;
    if (a != 0.0) {
        const double disc = b * b - 4.0 * a * c1;
        if (disc >= 0.0) {
            const double sq = std::sqrt(disc);
            const double q = -0.5 * (b + std::copysign(sq, b));
            double t1 = q / a, t2 = q != 0.0 ? c1 / q : t1;
            if (t1 > t2) std::swap(t1, t2);
            if (t1 > 0.0 && t1 < 1.0) cuts[count++] = t1;
            if (t2 > 0.0 && t2 < 1.0 && t2 != t1) cuts[count++] = t2;
        }
    } else if (b != 0.0) {
        const double t = -c1 / b;
        if (t > 0.0 && t < 1.0) cuts[count++] = t;
    }
    cuts[count++] = 1.0;
    std::sort(cuts, cuts + count);
    for (int i = 0; i + 1 < count; ++i) {
        double lo = cuts[i], hi = cuts[i + 1];
        double flo = f(lo), fhi = f(hi);
        if (flo == 0.0) {
            roots.push_back(lo);
            continue;
        }
        if (i + 2 == count && fhi == 0.0) roots.push_back(hi);
        if ((flo < 0.0) == (fhi < 0.0) || fhi == 0.0) continue;
        for (int k = 0; k < 80 && hi - lo > 1e-17; ++k) {
            const double mid = 0.5 * (lo + hi);
            const double fm = f(mid);
            if ((fm < 0.0) == (flo < 0.0)) {
                lo = mid;
                flo = fm;
            } else {
                hi = mid;
            }
        }
        roots.push_back(0.5 * (lo + hi));
    }
}

// True when p lies on a normal of q within r of its foot: some stationary point of |p - q(t)|
// (a root of (q(t) - p) . q'(t), a cubic) is within r.
bool in_sweep(const Quad& q, Vec2 p, double r, std::vector<double>& roots) {
    const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = q.p1 - q.p0, d = q.p0 - p;
    unit_roots(dot(a, a), 3.0 * dot(a, b), 2.0 * dot(b, b) + dot(d, a), dot(d, b), roots);
    for (double t : roots) {
        const Vec2 e = evaluate(q, t) - p;
        if (dot(e, e) <= r * r) return true;
    }
    return false;
}

bool in_convex(const std::vector<Vec2>& polygon, Vec2 p) {
    for (size_t i = 0; i < polygon.size(); ++i) {
        if (cross(polygon[(i + 1) % polygon.size()] - polygon[i], p - polygon[i]) < 0.0) return false;
    }
    return true;
}

// Contours as the reference strokes them: zero-length curves dropped; a curve with collinear
// points traced as its one or two lines (two when it runs back on itself).
std::vector<Quad> elements_of(const Contour& contour) {
    std::vector<Quad> out;
    for (const Quad& q : contour) {
        if (q.p0 == q.p1 && q.p1 == q.p2) continue;
        const double area = cross(q.p1 - q.p0, q.p2 - q.p0);
        const double scale = dot(q.p1 - q.p0, q.p1 - q.p0) + dot(q.p2 - q.p0, q.p2 - q.p0);
        if (std::abs(area) > 1e-12 * scale) {
            out.push_back(q);
            continue;
        }
        const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = q.p1 - q.p0;
        const double t = dot(a, a) > 0.0 ? -dot(b, a) / dot(a, a) : 0.0;
        const Vec2 back = evaluate(q, t);
        if (t > 0.0 && t < 1.0) {
            if (!(back == q.p0)) out.push_back(line_to_quad(q.p0, back));
            if (!(back == q.p2)) out.push_back(line_to_quad(back, q.p2));
        } else if (!(q.p0 == q.p2)) {
            out.push_back(line_to_quad(q.p0, q.p2));
        }
    }
    return out;
}

}  // namespace

StrokeReference::StrokeReference(const std::vector<Contour>& glyph, StrokeJoin join, double half_width,
                                 double miter_limit, StrokeOp op)
    : StrokeReference(std::vector<std::vector<Contour>>{glyph}, join, half_width, miter_limit, op) {}

StrokeReference::StrokeReference(const std::vector<std::vector<Contour>>& fills, StrokeJoin join, double half_width,
                                 double miter_limit, StrokeOp op)
    : join_(join), r_(half_width), miter_limit_(miter_limit), op_(op) {
    for (const std::vector<Contour>& fill : fills) {
        std::vector<Quad>& curves = fill_curves_.emplace_back();
        for (const Contour& contour : fill) curves.insert(curves.end(), contour.begin(), contour.end());
    }
    for (const std::vector<Quad>& curves : fill_curves_) {
        fills_.push_back(std::make_unique<ExactCoverage>(curves));
        for (const Quad& q : curves) add_offset(q, 0.0);
    }
    for (const std::vector<Contour>& fill : fills) {
        for (const Contour& contour : fill) {
            const std::vector<Quad> elements = elements_of(contour);
            if (elements.empty()) continue;
            for (const Quad& q : elements) {
                Element e{q, std::min({q.p0.x, q.p1.x, q.p2.x}) - r_, std::min({q.p0.y, q.p1.y, q.p2.y}) - r_,
                          std::max({q.p0.x, q.p1.x, q.p2.x}) + r_, std::max({q.p0.y, q.p1.y, q.p2.y}) + r_};
                elements_.push_back(e);
                add_offset(q, r_);
                add_offset(q, -r_);
                add_segment(offset_at(q, 0.0, -r_), offset_at(q, 0.0, r_));
                add_segment(offset_at(q, 1.0, -r_), offset_at(q, 1.0, r_));
            }
            const bool closed = elements.back().p2 == elements.front().p0;
            for (size_t i = 0; i < elements.size(); ++i) {
                if (i + 1 == elements.size() && !closed) break;
                const Quad& in = elements[i];
                const Quad& out = elements[(i + 1) % elements.size()];
                const Vec2 corner = in.p2, d_in = tangent_at(in, 1.0), d_out = tangent_at(out, 0.0);
                double angle = std::atan2(cross(d_in, d_out), dot(d_in, d_out));
                if (join_ == StrokeJoin::round) {
                    joins_.push_back({corner, {}});
                    Boundary top{{corner, corner, corner},
                                 r_,
                                 0.0,
                                 1.0,
                                 true,
                                 corner.y,
                                 corner.y + r_,
                                 corner.x - r_,
                                 corner.x + r_};
                    Boundary bottom = top;
                    bottom.y_lo = corner.y - r_;
                    bottom.y_hi = corner.y;
                    boundary_.push_back(top);
                    boundary_.push_back(bottom);
                    continue;
                }
                if (std::abs(angle) <= 1e-9) continue;
                if (std::abs(cross(d_in, d_out)) <= 1e-15 && dot(d_in, d_out) < 0.0) angle = std::numbers::pi;
                const double outer = angle > 0.0 ? -1.0 : 1.0;
                const Vec2 n_in = outer * Vec2{-d_in.y, d_in.x}, n_out = outer * Vec2{-d_out.y, d_out.x};
                const Vec2 a = corner + r_ * n_in, b = corner + r_ * n_out;
                std::vector<Vec2> polygon{corner, a};
                // The miter ratio 1 / sin(alpha / 2), alpha = pi - |angle| the angle between the segments.
                const double ratio = 1.0 / std::sin(0.5 * (std::numbers::pi - std::abs(angle)));
                if (join_ == StrokeJoin::miter && std::abs(angle) < std::numbers::pi && ratio <= miter_limit_) {
                    const Vec2 mid = n_in + n_out;
                    polygon.push_back(corner + (r_ * ratio / length(mid)) * mid);
                }
                polygon.push_back(b);
                double area = 0.0;
                for (size_t k = 0; k < polygon.size(); ++k)
                    area += cross(polygon[k], polygon[(k + 1) % polygon.size()]);
                if (!(std::abs(area) > 0.0)) continue;
                if (area < 0.0) std::reverse(polygon.begin(), polygon.end());
                for (size_t k = 0; k < polygon.size(); ++k) add_segment(polygon[k], polygon[(k + 1) % polygon.size()]);
                joins_.push_back({corner, std::move(polygon)});
            }
        }
    }
}

StrokeReference::~StrokeReference() = default;

void StrokeReference::add_segment(Vec2 a, Vec2 b) {
    if (a == b) return;
    add_offset(line_to_quad(a, b), 0.0);
}

// Cuts c(t) + s n(t) where its y turns: where c's does (c'_y = 0) and at the cusps of an offset
// past the radius of curvature (s kappa = 1, where the offset runs backwards).
void StrokeReference::add_offset(const Quad& q, double s) {
    const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = q.p1 - q.p0;
    std::vector<double> cuts{0.0, 1.0};
    if (a.y != 0.0) cuts.push_back(-b.y / a.y);
    // kappa(t) = (b x a) / (2 |b + t a|^3) with the left normal; s kappa = 1 where
    // |b + t a|^2 = (s (b x a) / 2)^(2/3).
    const double bend = cross(b, a);
    if (s * bend > 0.0) {
        const double k = std::cbrt(0.5 * s * bend);
        const double qa = dot(a, a), qb = 2.0 * dot(a, b), qc = dot(b, b) - k * k;
        const double disc = qb * qb - 4.0 * qa * qc;
        if (qa > 0.0 && disc >= 0.0) {
            cuts.push_back((-qb - std::sqrt(disc)) / (2.0 * qa));
            cuts.push_back((-qb + std::sqrt(disc)) / (2.0 * qa));
        }
    }
    std::erase_if(cuts, [](double t) { return !(t >= 0.0 && t <= 1.0); });
    std::sort(cuts.begin(), cuts.end());
    const double x_lo = std::min({q.p0.x, q.p1.x, q.p2.x}) - std::abs(s);
    const double x_hi = std::max({q.p0.x, q.p1.x, q.p2.x}) + std::abs(s);
    for (size_t i = 0; i + 1 < cuts.size(); ++i) {
        if (!(cuts[i + 1] > cuts[i])) continue;
        const double ya = offset_at(q, cuts[i], s).y, yb = offset_at(q, cuts[i + 1], s).y;
        boundary_.push_back({q, s, cuts[i], cuts[i + 1], false, std::min(ya, yb), std::max(ya, yb), x_lo, x_hi});
    }
}

bool StrokeReference::in_glyph(Vec2 p) const {
    return std::any_of(fills_.begin(), fills_.end(), [&](const auto& fill) { return fill->winding(p.x, p.y) != 0; });
}

bool StrokeReference::in_stroke(Vec2 p) const {
    if (!(r_ > 0.0)) return false;
    thread_local std::vector<double> roots;
    for (const Join& j : joins_) {
        if (j.polygon.empty() ? dot(p - j.corner, p - j.corner) <= r_ * r_ : in_convex(j.polygon, p)) return true;
    }
    for (const Element& e : elements_) {
        if (p.x < e.x0 || p.x > e.x1 || p.y < e.y0 || p.y > e.y1) continue;
        if (in_sweep(e.curve, p, r_, roots)) return true;
    }
    return false;
}

void StrokeReference::bounds(double& x0, double& y0, double& x1, double& y1) const {
    x0 = y0 = HUGE_VAL;
    x1 = y1 = -HUGE_VAL;
    for (const Boundary& b : boundary_) {
        x0 = std::min(x0, b.x_lo);
        x1 = std::max(x1, b.x_hi);
        y0 = std::min(y0, b.y_lo);
        y1 = std::max(y1, b.y_hi);
    }
}

// Between two consecutive crossings of the boundary elements on a row, op's cover is constant
// (every edge of S(r) and of G is among them): one point test per stretch.
double StrokeReference::covered_length(const std::vector<uint32_t>& boundary, double y, double x0, double x1) const {
    thread_local std::vector<double> xs;
    xs.clear();
    xs.push_back(x0);
    for (uint32_t index : boundary) {
        const Boundary& b = boundary_[index];
        if (y < b.y_lo || y > b.y_hi) continue;
        if (b.circle) {
            const Vec2 c = b.curve.p0;
            const double h = b.s * b.s - (y - c.y) * (y - c.y);
            if (h < 0.0) continue;
            // Each half circle adds both of its crossings; the two halves together give them twice
            // on the middle row only, which changes no stretch's cover.
            const double w = std::sqrt(h);
            for (double x : {c.x - w, c.x + w}) {
                if (x > x0 && x < x1) xs.push_back(x);
            }
            continue;
        }
        // y is monotonic over the piece: the Illinois variant of regula falsi, which keeps the
        // root bracketed and converges superlinearly.
        double lo = b.t0, hi = b.t1;
        double flo = offset_at(b.curve, lo, b.s).y - y, fhi = offset_at(b.curve, hi, b.s).y - y;
        if ((flo < 0.0) == (fhi < 0.0) && flo != 0.0 && fhi != 0.0) continue;
        double t = lo;
        int side = 0;
        for (int k = 0; k < 100 && hi - lo > 1e-15; ++k) {
            t = flo == fhi ? 0.5 * (lo + hi) : std::clamp((lo * fhi - hi * flo) / (fhi - flo), lo, hi);
            const double ft = offset_at(b.curve, t, b.s).y - y;
            if (ft == 0.0) break;
            if ((ft < 0.0) == (flo < 0.0)) {
                lo = t;
                flo = ft;
                if (side == -1) fhi *= 0.5;
                side = -1;
            } else {
                hi = t;
                fhi = ft;
                if (side == 1) flo *= 0.5;
                side = 1;
            }
            if (std::abs(ft) < 1e-16) break;
        }
        const double x = offset_at(b.curve, t, b.s).x;
        if (x > x0 && x < x1) xs.push_back(x);
    }
    xs.push_back(x1);
    std::sort(xs.begin(), xs.end());
    double covered = 0.0;
    for (size_t i = 0; i + 1 < xs.size(); ++i) {
        if (!(xs[i + 1] > xs[i])) continue;
        if (covers({0.5 * (xs[i] + xs[i + 1]), y})) covered += xs[i + 1] - xs[i];
    }
    return covered;
}

double StrokeReference::integrate(const std::vector<uint32_t>& boundary, double x0, double x1, double ya, double yb,
                                  double fa, double fm, double fb, double whole, double tolerance, int depth,
                                  double& error) const {
    const double m = 0.5 * (ya + yb);
    const double fl = covered_length(boundary, 0.5 * (ya + m), x0, x1);
    const double fr = covered_length(boundary, 0.5 * (m + yb), x0, x1);
    const double left = (m - ya) / 6.0 * (fa + 4.0 * fl + fm), right = (yb - m) / 6.0 * (fm + 4.0 * fr + fb);
    const double difference = left + right - whole;
    if (depth >= 40 || std::abs(difference) <= 15.0 * tolerance) {
        error += std::abs(difference) / 15.0;
        return left + right + difference / 15.0;
    }
    return integrate(boundary, x0, x1, ya, m, fa, fl, fm, left, 0.5 * tolerance, depth + 1, error) +
           integrate(boundary, x0, x1, m, yb, fm, fr, fb, right, 0.5 * tolerance, depth + 1, error);
}

void StrokeReference::cell(const std::vector<uint32_t>& boundary, double x0, double y0, double x1, double y1, int depth,
                           double tolerance, StrokeArea& out) const {
    std::vector<uint32_t> inside;
    for (uint32_t index : boundary) {
        const Boundary& b = boundary_[index];
        if (b.y_hi < y0 || b.y_lo > y1 || b.x_hi < x0 || b.x_lo > x1) continue;
        inside.push_back(index);
    }
    const double cell_area = (x1 - x0) * (y1 - y0);
    if (inside.empty()) {
        // No boundary element reaches the cell: its cover is its centre's.
        if (covers({0.5 * (x0 + x1), 0.5 * (y0 + y1)})) out.area += cell_area;
        return;
    }
    if (depth < 2) {
        const double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
        cell(inside, x0, y0, mx, my, depth + 1, 0.25 * tolerance, out);
        cell(inside, mx, y0, x1, my, depth + 1, 0.25 * tolerance, out);
        cell(inside, x0, my, mx, y1, depth + 1, 0.25 * tolerance, out);
        cell(inside, mx, my, x1, y1, depth + 1, 0.25 * tolerance, out);
        return;
    }
    // A leaf: integrate rows between the heights where an element starts, ends or turns in y.
    std::vector<double> ys{y0, y1};
    for (uint32_t index : inside) {
        const Boundary& b = boundary_[index];
        for (double y : {b.y_lo, b.y_hi, b.circle ? b.curve.p0.y : b.y_lo}) {
            if (y > y0 && y < y1) ys.push_back(y);
        }
    }
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    for (size_t i = 0; i + 1 < ys.size(); ++i) {
        const double ya = ys[i], yb = ys[i + 1];
        if (!(yb > ya)) continue;
        const double share = tolerance * (yb - ya) / (y1 - y0);
        // Rows just inside each end: a crossing through an end point is then never on the row.
        const double eps = 1e-12 * (yb - ya);
        const double fa = covered_length(inside, ya + eps, x0, x1), fb = covered_length(inside, yb - eps, x0, x1);
        const double fm = covered_length(inside, 0.5 * (ya + yb), x0, x1);
        const double whole = (yb - ya) / 6.0 * (fa + 4.0 * fm + fb);
        out.area += integrate(inside, x0, x1, ya, yb, fa, fm, fb, whole, share, 0, out.error);
    }
}

StrokeArea StrokeReference::area(double x0, double y0, double x1, double y1) const {
    StrokeArea out;
    if (!(x1 > x0) || !(y1 > y0)) return out;
    std::vector<uint32_t> all(boundary_.size());
    for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    cell(all, x0, y0, x1, y1, 0, 1e-7 * (x1 - x0) * (y1 - y0), out);
    return out;
}

double StrokeReference::coverage(double x0, double y0, double x1, double y1) const {
    if (!(x1 > x0) || !(y1 > y0)) return 0.0;
    return std::clamp(area(x0, y0, x1, y1).area / ((x1 - x0) * (y1 - y0)), 0.0, 1.0);
}

std::array<double, 3> StrokeReference::texel(const TexelToEm& map, const SubpixelLayout& layout, uint32_t tx,
                                             uint32_t ty) const {
    std::array<double, 3> out{};
    const auto sx = static_cast<double>(map.scale_x), sy = static_cast<double>(map.scale_y);
    const auto ox = static_cast<double>(map.offset_x), oy = static_cast<double>(map.offset_y);
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        // Channels that share a rect (a gray layout's three) share its area.
        if (c > 0 && r == layout.channels[c - 1]) {
            out[c] = out[c - 1];
            continue;
        }
        const double ax = ox + sx * (tx + static_cast<double>(r.x0)), bx = ox + sx * (tx + static_cast<double>(r.x1));
        const double ay = oy + sy * (ty + static_cast<double>(r.y0)), by = oy + sy * (ty + static_cast<double>(r.y1));
        out[c] = coverage(std::min(ax, bx), std::min(ay, by), std::max(ax, bx), std::max(ay, by));
    }
    return out;
}

}  // namespace crisp
