#include "asset/curves.hpp"

#include <algorithm>
#include <cmath>

namespace crisp {

double length(Vec2 a) {
    return std::hypot(a.x, a.y);
}

Vec2 evaluate(const Quad& q, double t) {
    const double s = 1.0 - t;
    return s * s * q.p0 + 2.0 * s * t * q.p1 + t * t * q.p2;
}

Vec2 evaluate(const Cubic& c, double t) {
    const double s = 1.0 - t;
    return s * s * s * c.p0 + 3.0 * s * s * t * c.p1 + 3.0 * s * t * t * c.p2 + t * t * t * c.p3;
}

Cubic subcubic(const Cubic& c, double t0, double t1) {
    // Blossoming: the piece's control points are the polar forms f(t0,t0,t0), f(t0,t0,t1), ...
    auto blossom = [&](double a, double b, double d) {
        const Vec2 ab0 = lerp(c.p0, c.p1, a), ab1 = lerp(c.p1, c.p2, a), ab2 = lerp(c.p2, c.p3, a);
        const Vec2 bc0 = lerp(ab0, ab1, b), bc1 = lerp(ab1, ab2, b);
        return lerp(bc0, bc1, d);
    };
    return {blossom(t0, t0, t0), blossom(t0, t0, t1), blossom(t0, t1, t1), blossom(t1, t1, t1)};
}

Quad line_to_quad(Vec2 a, Vec2 b) {
    return {a, 0.5 * (a + b), b};
}

Quad midpoint_quad(const Cubic& c) {
    return {c.p0, 0.25 * (3.0 * (c.p1 + c.p2) - (c.p0 + c.p3)), c.p3};
}

double midpoint_error(const Cubic& c) {
    const Vec2 d3 = c.p3 - 3.0 * c.p2 + 3.0 * c.p1 - c.p0;
    return std::sqrt(3.0) / 36.0 * length(d3);
}

double lower_cubic(const Cubic& c, double tolerance, std::vector<Quad>& out, int max_pieces) {
    const double whole = midpoint_error(c);
    int pieces = 1;
    if (whole > tolerance) {
        const double needed = std::ceil(std::cbrt(whole / tolerance) - 1e-9);
        pieces = needed >= max_pieces ? max_pieces : std::max(1, static_cast<int>(needed));
    }
    double worst = 0.0;
    for (int i = 0; i < pieces; ++i) {
        const double t0 = static_cast<double>(i) / pieces;
        const double t1 = static_cast<double>(i + 1) / pieces;
        Cubic piece = subcubic(c, t0, t1);
        // Pin the joints to the exact shared points so contours stay closed bit for bit.
        if (i == 0) piece.p0 = c.p0;
        if (i == pieces - 1) piece.p3 = c.p3;
        if (i > 0) piece.p0 = out.back().p2;
        out.push_back(midpoint_quad(piece));
        worst = std::max(worst, midpoint_error(piece));
    }
    return worst;
}

void seed_split_cubic(const Cubic& c, Quad out[2]) {
    const Vec2 c0 = lerp(c.p0, c.p1, 0.75);
    const Vec2 c1 = lerp(c.p3, c.p2, 0.75);
    const Vec2 m = lerp(c0, c1, 0.5);
    out[0] = {c.p0, c0, m};
    out[1] = {m, c1, c.p3};
}

double sampled_deviation(const Cubic& c, double t0, double t1, const Quad& q, int samples) {
    double worst = 0.0;
    for (int i = 0; i <= samples; ++i) {
        const double s = static_cast<double>(i) / samples;
        worst = std::max(worst, length(evaluate(c, t0 + s * (t1 - t0)) - evaluate(q, s)));
    }
    return worst;
}

int y_monotonic_cuts(const Quad& q, double cuts[3]) {
    cuts[0] = 0.0;
    cuts[1] = cuts[2] = 1.0;
    // dy/dt = 2 ((1 - t)(p1 - p0) + t (p2 - p1)) vanishes at t = (p0 - p1) / (p0 - 2 p1 + p2).
    const double denominator = q.p0.y - 2.0 * q.p1.y + q.p2.y;
    if (denominator == 0.0) return 2;
    const double t = (q.p0.y - q.p1.y) / denominator;
    if (!(t > 0.0 && t < 1.0)) return 2;
    cuts[1] = t;
    return 3;
}

int split_at_y_extremum(const Quad& q, Quad out[2]) {
    double cuts[3];
    if (y_monotonic_cuts(q, cuts) == 2) {
        out[0] = q;
        return 1;
    }
    const double t = cuts[1];
    const Vec2 a = lerp(q.p0, q.p1, t);
    const Vec2 b = lerp(q.p1, q.p2, t);
    Vec2 m = lerp(a, b, t);
    m.y = evaluate(q, t).y;
    // Both halves are flat at the extremum: their control points share its height.
    out[0] = {q.p0, {a.x, m.y}, m};
    out[1] = {m, {b.x, m.y}, q.p2};
    return 2;
}

bool is_zero_length(const Quad& q) {
    return q.p0 == q.p1 && q.p1 == q.p2;
}

}  // namespace crisp
