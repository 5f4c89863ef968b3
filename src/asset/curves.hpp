// Quadratic and cubic Bezier curves in double precision, and the conversions the baker needs:
// lines to quadratics, cubics to quadratics within a tolerance, and splits at y-extrema. Part of
// crisp (the run time) since effect layers' stroke geometry uses them too.
#pragma once

#include <cstddef>
#include <vector>

namespace crisp {

struct Vec2 {
    double x = 0.0;
    double y = 0.0;
    friend bool operator==(const Vec2&, const Vec2&) = default;
};

inline Vec2 operator+(Vec2 a, Vec2 b) {
    return {a.x + b.x, a.y + b.y};
}
inline Vec2 operator-(Vec2 a, Vec2 b) {
    return {a.x - b.x, a.y - b.y};
}
inline Vec2 operator*(double s, Vec2 a) {
    return {s * a.x, s * a.y};
}
double length(Vec2 a);
inline double dot(Vec2 a, Vec2 b) {
    return a.x * b.x + a.y * b.y;
}
inline double cross(Vec2 a, Vec2 b) {
    return a.x * b.y - a.y * b.x;
}
inline Vec2 lerp(Vec2 a, Vec2 b, double t) {
    return a + t * (b - a);
}

struct Quad {
    Vec2 p0, p1, p2;
    friend bool operator==(const Quad&, const Quad&) = default;
};

// A closed contour: each curve's p2 is the next one's p0, the last one's the first one's p0.
using Contour = std::vector<Quad>;

struct Cubic {
    Vec2 p0, p1, p2, p3;
};

Vec2 evaluate(const Quad& q, double t);
Vec2 evaluate(const Cubic& c, double t);

// The cubic's piece over [t0, t1], as a cubic of its own (parameter rescaled to [0, 1]).
Cubic subcubic(const Cubic& c, double t0, double t1);

// A line as a quadratic with its control point at the midpoint: the same point set, traversed at
// the same speed, so evaluate(line_to_quad(a, b), t) == lerp(a, b, t).
Quad line_to_quad(Vec2 a, Vec2 b);

// The quadratic closest to a cubic in the parametric sense: control point (3 (p1 + p2) - (p0 + p3)) / 4.
// Its largest distance to the cubic at equal parameters is exactly midpoint_error(c).
Quad midpoint_quad(const Cubic& c);

// sqrt(3) / 36 * |p3 - 3 p2 + 3 p1 - p0|: the largest of |c(t) - midpoint_quad(c)(t)| over t.
// The third derivative of a cubic is constant, so splitting a cubic into n equal pieces divides
// this error by n^3 in every piece alike.
double midpoint_error(const Cubic& c);

// Lowers a cubic into the fewest equal-parameter pieces whose midpoint quadratics stay within
// `tolerance` of the cubic (at equal parameters, which bounds the distance between the curves);
// appends them to `out` and returns the largest deviation of any piece (<= tolerance).
// `max_pieces` bounds the work on absurd input; beyond it the deviation returned exceeds the
// tolerance and the caller decides.
double lower_cubic(const Cubic& c, double tolerance, std::vector<Quad>& out, int max_pieces = 256);

// The seed's fixed split of a cubic into two quadratics, for comparison.
void seed_split_cubic(const Cubic& c, Quad out[2]);

// Largest |c(t) - q(s)| over `samples` + 1 evenly spaced parameters, where the piece q stands for
// the cubic over [t0, t1] and s = (t - t0) / (t1 - t0). A measurement, not a bound.
double sampled_deviation(const Cubic& c, double t0, double t1, const Quad& q, int samples);

// The parameters that cut a quadratic into pieces monotonic in y: 0, its y-extremum's parameter
// where that lies strictly inside (0, 1), and 1. Returns how many (2 or 3); cuts past them are 1.
int y_monotonic_cuts(const Quad& q, double cuts[3]);

// Splits a quadratic at the parameter of its y-extremum when that lies strictly inside (0, 1),
// so every piece is monotonic in y. Returns the number of pieces written (1 or 2).
int split_at_y_extremum(const Quad& q, Quad out[2]);

// True when all three points coincide: the curve has no length and is dropped.
bool is_zero_length(const Quad& q);

}  // namespace crisp
