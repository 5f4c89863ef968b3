#include "text/stroke.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace crisp {

namespace {

// A piece turns by at most this much, so that its offsets are close to quadratics and its sweep,
// where it does not fold, is a simple region.
constexpr double kMaxPieceTurn = 40.0 * std::numbers::pi / 180.0;
// Halvings of a curve's parameter interval, at most: 2^-24 of a curve is far below any tolerance.
constexpr int kMaxSplitDepth = 24;
// A piece whose smallest radius of curvature rho is at most r / kFoldRatio is treated as folding on
// its concave side: the offset's radius there, rho - r, would be at most a tenth of rho, next to
// the cusp where the sweep folds over.
constexpr double kFoldRatio = 0.9;
// Arcs of a round join span at most 45 degrees (control point at r / cos(22.5 deg)), more where
// the tolerance asks.
constexpr double kMaxArc = 45.0 * std::numbers::pi / 180.0;
// Consecutive curves whose tangents differ by less than this are joined without a join: the wedge
// left between their sweeps is at most r * 1e-9 wide.
constexpr double kStraightTurn = 1e-9;

Vec2 left_normal(Vec2 d) {
    return {-d.y, d.x};
}
Vec2 unit(Vec2 d) {
    const double l = length(d);
    return l > 0.0 ? (1.0 / l) * d : Vec2{};
}
// The angle that turns direction a into direction b, in (-pi, pi].
double turn(Vec2 a, Vec2 b) {
    return std::atan2(cross(a, b), dot(a, b));
}

Vec2 derivative(const Quad& q, double t) {
    return 2.0 * ((1.0 - t) * (q.p1 - q.p0) + t * (q.p2 - q.p1));
}
// The unit tangent; where the derivative vanishes (a control point on an end point) the chord's.
Vec2 direction(const Quad& q, double t) {
    const Vec2 d = derivative(q, t);
    const double scale = length(q.p2 - q.p0) + length(q.p1 - q.p0);
    if (length(d) > 1e-12 * scale) return unit(d);
    return unit(q.p2 - q.p0);
}
Vec2 offset_point(const Quad& q, double t, double s) {
    return evaluate(q, t) + s * left_normal(direction(q, t));
}
// The curve over [t0, t1] as a quadratic of its own (the blossom gives the control point).
Quad subquad(const Quad& q, double t0, double t1) {
    const Vec2 control = (1.0 - t0) * (1.0 - t1) * q.p0 + ((1.0 - t0) * t1 + t0 * (1.0 - t1)) * q.p1 + t0 * t1 * q.p2;
    return {evaluate(q, t0), control, evaluate(q, t1)};
}
Quad translated(const Quad& q, Vec2 by) {
    return {q.p0 + by, q.p1 + by, q.p2 + by};
}
Quad reversed(const Quad& q) {
    return {q.p2, q.p1, q.p0};
}

// Radius of curvature at t: |c'|^3 / |c' x c''| = 2 |B + t A|^3 / |B x A| with c'/2 = B + t A.
double curvature_radius(const Quad& q, double t) {
    const double bend = std::abs(cross(q.p1 - q.p0, q.p0 - 2.0 * q.p1 + q.p2));
    if (bend == 0.0) return HUGE_VAL;
    const double speed = 0.5 * length(derivative(q, t));
    return 2.0 * speed * speed * speed / bend;
}

// The quadratic through the offsets at t0 and t1 whose control point is where their tangents (the
// curve's) meet; `ok` false, and the chord in its place, when they meet behind an end.
struct OffsetFit {
    Quad quad;
    bool ok = false;
};
OffsetFit fit_offset(const Quad& q, double t0, double t1, double s) {
    const Vec2 a = offset_point(q, t0, s), b = offset_point(q, t1, s);
    const Vec2 da = direction(q, t0), db = direction(q, t1);
    const double chord = length(b - a);
    const double denominator = cross(da, db);
    if (std::abs(denominator) <= 1e-9) return {{a, 0.5 * (a + b), b}, dot(b - a, da) >= 0.0};
    const double u = cross(b - a, db) / denominator;
    const double v = cross(da, b - a) / denominator;
    if (!(u >= 0.0 && v >= 0.0 && u <= 2.0 * chord + 1e-12 && v <= 2.0 * chord + 1e-12))
        return {line_to_quad(a, b), false};
    return {{a, a + u * da, b}, true};
}

// Distance from p to the quadratic, by Newton's method from parameter u (the fit's parameters
// track the curve's closely where the fit is good, so a start at the same parameter converges).
double distance_near(const Quad& q, Vec2 p, double u) {
    const Vec2 second = 2.0 * (q.p0 - 2.0 * q.p1 + q.p2);
    for (int i = 0; i < 6; ++i) {
        const Vec2 d = derivative(q, u), e = evaluate(q, u) - p;
        const double f = dot(e, d), df = dot(d, d) + dot(e, second);
        if (!(df > 0.0)) break;
        u = std::clamp(u - f / df, 0.0, 1.0);
    }
    return std::min({length(evaluate(q, u) - p), length(q.p0 - p), length(q.p2 - p)});
}

// The fit's largest distance from the true offset over seven inner samples, or infinity.
double fit_error(const Quad& q, double t0, double t1, double s, const OffsetFit& fit) {
    if (!fit.ok) return HUGE_VAL;
    double worst = 0.0;
    for (int k = 1; k < 8; ++k) {
        const double f = k / 8.0;
        worst = std::max(worst, distance_near(fit.quad, offset_point(q, t0 + f * (t1 - t0), s), f));
    }
    return worst;
}

struct Piece {
    double t0 = 0.0, t1 = 1.0;
    bool folds = false;  // the concave side is covered by sheared strips, not by the offset
    Quad left, right;    // the fitted offsets +r and -r (only the convex one when folding)
};

// Appends the pieces of curves and joins to `out`, every contour wound clockwise.
class Stroker {
public:
    Stroker(const StrokeStyle& style, std::vector<Contour>& out) : style_(style), out_(out) {}

    void stroke_curve(const Quad& q);
    void join(Vec2 corner, Vec2 in, Vec2 out);
    uint64_t curves() const { return curves_; }

private:
    void split(const Quad& q, double t0, double t1, int depth, std::vector<Piece>& pieces) const;
    void emit_sweep(std::span<const Piece> run);
    void emit_convex_half(const Quad& q, std::span<const Piece> run, double concave);
    void emit_strips(const Quad& q, double t0, double t1, double concave);
    void emit(Contour contour);
    void emit_polygon(std::span<const Vec2> corners);

    StrokeStyle style_;
    std::vector<Contour>& out_;
    uint64_t curves_ = 0;
};

void Stroker::split(const Quad& q, double t0, double t1, int depth, std::vector<Piece>& pieces) const {
    if (pieces.size() > limits::kMaxStrokeCurves) return;  // the caller refuses the stroke
    const double r = style_.half_width;
    const auto halve = [&] {
        const double mid = 0.5 * (t0 + t1);
        split(q, t0, mid, depth + 1, pieces);
        split(q, mid, t1, depth + 1, pieces);
    };
    const bool can_split = depth < kMaxSplitDepth;
    if (can_split && std::abs(turn(direction(q, t0), direction(q, t1))) > kMaxPieceTurn) return halve();
    Piece piece{t0, t1, false, {}, {}};
    const double rho = std::min(curvature_radius(q, t0), curvature_radius(q, t1));
    piece.folds = r >= kFoldRatio * rho;
    const double concave = cross(q.p1 - q.p0, q.p0 - 2.0 * q.p1 + q.p2) > 0.0 ? 1.0 : -1.0;
    double error = 0.0;
    for (double side : {1.0, -1.0}) {
        if (piece.folds && side == concave) continue;
        const OffsetFit fit = fit_offset(q, t0, t1, side * r);
        error = std::max(error, fit_error(q, t0, t1, side * r, fit));
        (side > 0.0 ? piece.left : piece.right) = fit.quad;
    }
    if (can_split && error > style_.tolerance) return halve();
    pieces.push_back(piece);
}

void Stroker::emit(Contour contour) {
    std::erase_if(contour, [](const Quad& c) { return is_zero_length(c); });
    if (contour.empty()) return;
    curves_ += contour.size();
    out_.push_back(std::move(contour));
}

// A convex polygon as lines, wound clockwise whichever way its corners come.
void Stroker::emit_polygon(std::span<const Vec2> corners) {
    std::vector<Vec2> ring(corners.begin(), corners.end());
    double area = 0.0;
    for (size_t i = 0; i < ring.size(); ++i) area += cross(ring[i], ring[(i + 1) % ring.size()]);
    if (!(std::abs(area) > 1e-24)) return;  // a hairpin's bevel: no area
    if (area > 0.0) std::reverse(ring.begin(), ring.end());
    Contour contour;
    for (size_t i = 0; i < ring.size(); ++i) contour.push_back(line_to_quad(ring[i], ring[(i + 1) % ring.size()]));
    emit(std::move(contour));
}

// The sweep {c(t) + s n(t) : |s| <= r} of a run of pieces none of which folds: +r forward, -r
// back. Its boundary winds once around every point it covers (the map (t, s) keeps its
// orientation where r is below the radius of curvature), clockwise: the left offset runs forward.
void Stroker::emit_sweep(std::span<const Piece> run) {
    Contour contour;
    for (const Piece& p : run) contour.push_back(p.left);
    contour.push_back(line_to_quad(run.back().left.p2, run.back().right.p2));
    for (size_t i = run.size(); i-- > 0;) contour.push_back(reversed(run[i].right));
    contour.push_back(line_to_quad(run.front().right.p0, run.front().left.p0));
    emit(std::move(contour));
}

// The convex half {c(t) + s n(t)} of a run of folding pieces, s from 0 to r on the side away from
// the centre of curvature (concave = +1: the centre is on the left).
void Stroker::emit_convex_half(const Quad& q, std::span<const Piece> run, double concave) {
    Contour contour;
    const Quad curve = subquad(q, run.front().t0, run.back().t1);
    if (concave > 0.0) {
        contour.push_back(curve);
        contour.push_back(line_to_quad(curve.p2, run.back().right.p2));
        for (size_t i = run.size(); i-- > 0;) contour.push_back(reversed(run[i].right));
        contour.push_back(line_to_quad(run.front().right.p0, curve.p0));
    } else {
        for (const Piece& p : run) contour.push_back(p.left);
        contour.push_back(line_to_quad(run.back().left.p2, curve.p2));
        contour.push_back(reversed(curve));
        contour.push_back(line_to_quad(curve.p0, run.front().left.p0));
    }
    emit(std::move(contour));
}

// Where the curve's radius of curvature falls below r its concave offset folds back: that side is
// instead the union of short strips {c(u) + s m : u in [u0, u1], 0 <= s <= r}, m the chord's unit
// normal towards the centre. Every strip point lies within r of the curve; the strips turn by at
// most delta, which leaves gaps of r (1 - cos(delta / 2)) <= tolerance at their joints.
void Stroker::emit_strips(const Quad& q, double t0, double t1, double concave) {
    const double r = style_.half_width;
    const double delta = std::min(kMaxPieceTurn, std::sqrt(8.0 * style_.tolerance / r));
    const double total = std::abs(turn(direction(q, t0), direction(q, t1)));
    // The tangent angle of a quadratic is monotonic: cut at equal angles (found by bisection).
    const double wanted = std::ceil(total / delta);
    if (!(wanted <= limits::kMaxStrokeCurves)) {
        curves_ = uint64_t{limits::kMaxStrokeCurves} + 1;  // refused by the caller
        return;
    }
    const int count = std::max(1, static_cast<int>(wanted));
    const double start_angle = std::atan2(direction(q, t0).y, direction(q, t0).x);
    double u0 = t0;
    for (int k = 1; k <= count; ++k) {
        double u1 = t1;
        if (k < count) {
            const double target = total * k / count;
            double lo = u0, hi = t1;
            for (int i = 0; i < 50; ++i) {
                const double mid = 0.5 * (lo + hi);
                const Vec2 d = direction(q, mid);
                const double angle = std::abs(turn({std::cos(start_angle), std::sin(start_angle)}, d));
                (angle < target ? lo : hi) = mid;
            }
            u1 = hi;
        }
        const Quad piece = subquad(q, u0, u1);
        const Vec2 m = concave * left_normal(unit(piece.p2 - piece.p0));
        const Quad far = translated(piece, r * m);
        Contour contour;
        if (concave > 0.0) {
            contour = {far, line_to_quad(far.p2, piece.p2), reversed(piece), line_to_quad(piece.p0, far.p0)};
        } else {
            contour = {piece, line_to_quad(piece.p2, far.p2), reversed(far), line_to_quad(far.p0, piece.p0)};
        }
        emit(std::move(contour));
        u0 = u1;
    }
}

void Stroker::stroke_curve(const Quad& q) {
    std::vector<Piece> pieces;
    // Cut at the point of highest curvature (where |c'| is least): each side then has its
    // smallest radius of curvature at one of its ends.
    const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = q.p1 - q.p0;
    const double aa = dot(a, a);
    const double t_sharp = aa > 0.0 ? -dot(b, a) / aa : 0.0;
    if (t_sharp > 1e-9 && t_sharp < 1.0 - 1e-9) {
        split(q, 0.0, t_sharp, 0, pieces);
        split(q, t_sharp, 1.0, 0, pieces);
    } else {
        split(q, 0.0, 1.0, 0, pieces);
    }
    const double concave = cross(b, a) > 0.0 ? 1.0 : -1.0;
    for (size_t first = 0; first < pieces.size();) {
        size_t last = first + 1;
        while (last < pieces.size() && pieces[last].folds == pieces[first].folds) ++last;
        const std::span<const Piece> run(pieces.data() + first, last - first);
        if (run.front().folds) {
            emit_convex_half(q, run, concave);
            emit_strips(q, run.front().t0, run.back().t1, concave);
        } else {
            emit_sweep(run);
        }
        first = last;
    }
}

// The join at a corner where a direction `in` turns into `out`, on the outer side (inside, the two
// sweeps overlap). However small the turn, the wedge between the two sweeps' end normals reaches
// from the offsets down to the corner, so only a turn below kStraightTurn goes without one.
void Stroker::join(Vec2 corner, Vec2 in, Vec2 out) {
    const double r = style_.half_width;
    double angle = turn(in, out);
    if (std::abs(cross(in, out)) <= 1e-12 && dot(in, out) < 0.0) angle = std::numbers::pi;  // a hairpin
    if (std::abs(angle) <= kStraightTurn) return;
    // Outer side: the right for a left turn.
    const double outer = angle > 0.0 ? -1.0 : 1.0;
    const Vec2 n_in = outer * left_normal(in), n_out = outer * left_normal(out);
    const Vec2 a = corner + r * n_in, b = corner + r * n_out;
    const double miter_ratio = 1.0 / std::cos(0.5 * angle);
    if (style_.join == StrokeJoin::round) {
        int arcs = std::max(1, static_cast<int>(std::ceil(std::abs(angle) / kMaxArc)));
        const auto arc_error = [&](int n) {
            const double h = 0.5 * std::abs(angle) / n;
            return r * (0.5 * (std::cos(h) + 1.0 / std::cos(h)) - 1.0);
        };
        while (arc_error(arcs) > style_.tolerance && arcs < 4096) ++arcs;
        const double start = std::atan2(n_in.y, n_in.x);
        Contour contour{line_to_quad(corner, a)};
        Vec2 from = a;
        for (int k = 1; k <= arcs; ++k) {
            const double mid = start + angle * (k - 0.5) / arcs, end = start + angle * k / arcs;
            const double reach = r / std::cos(0.5 * angle / arcs);
            const Vec2 to = k == arcs ? b : corner + r * Vec2{std::cos(end), std::sin(end)};
            contour.push_back({from, corner + reach * Vec2{std::cos(mid), std::sin(mid)}, to});
            from = to;
        }
        contour.push_back(line_to_quad(b, corner));
        // A left turn sweeps the arc counter-clockwise: reverse it to wind clockwise.
        if (angle > 0.0) {
            std::reverse(contour.begin(), contour.end());
            for (Quad& c : contour) c = reversed(c);
        }
        emit(std::move(contour));
    } else if (style_.join == StrokeJoin::miter && std::abs(angle) < std::numbers::pi &&
               miter_ratio <= style_.miter_limit) {
        const Vec2 tip = corner + (r * miter_ratio) * unit(n_in + n_out);
        const Vec2 corners[] = {corner, a, tip, b};
        emit_polygon(corners);
    } else {
        const Vec2 corners[] = {corner, a, b};
        emit_polygon(corners);
    }
}

Error invalid(std::string message) {
    return Error{ErrorCode::invalid_argument, std::move(message)};
}

bool finite(Vec2 p) {
    return std::isfinite(p.x) && std::isfinite(p.y);
}

// A contour's curves as the stroker walks them: zero-length curves dropped, and a curve whose
// points are collinear as the one or two lines it traces (a control point beyond an end turns it
// back on itself: a hairpin, joined like a corner).
std::vector<Quad> stroke_elements(const Contour& contour) {
    std::vector<Quad> elements;
    for (const Quad& q : contour) {
        if (is_zero_length(q)) continue;
        const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = q.p1 - q.p0;
        const double scale = dot(q.p2 - q.p0, q.p2 - q.p0) + dot(b, b);
        if (std::abs(cross(q.p1 - q.p0, q.p2 - q.p0)) > 1e-12 * scale) {
            elements.push_back(q);
            continue;
        }
        const double aa = dot(a, a);
        const double t = aa > 0.0 ? -dot(b, a) / aa : 0.0;
        if (t > 0.0 && t < 1.0) {
            const Vec2 back = evaluate(q, t);
            if (!(back == q.p0)) elements.push_back(line_to_quad(q.p0, back));
            if (!(back == q.p2)) elements.push_back(line_to_quad(back, q.p2));
        } else if (!(q.p0 == q.p2)) {
            elements.push_back(line_to_quad(q.p0, q.p2));
        }
    }
    return elements;
}

}  // namespace

Status stroke_pieces(const std::vector<Contour>& contours, const StrokeStyle& style, std::vector<Contour>& pieces) {
    if (!std::isfinite(style.half_width) || style.half_width < 0.0)
        return invalid("stroke half_width " + std::to_string(style.half_width) + " em: not a finite width >= 0");
    if (style.half_width > limits::kMaxStrokeHalfWidthEm) {
        return invalid("stroke half_width " + std::to_string(style.half_width) + " em: more than " +
                       std::to_string(limits::kMaxStrokeHalfWidthEm) + " em (limits::kMaxStrokeHalfWidthEm)");
    }
    if (!std::isfinite(style.tolerance) || !(style.tolerance > 0.0))
        return invalid("stroke tolerance " + std::to_string(style.tolerance) + " em: not a finite length > 0");
    if (!std::isfinite(style.miter_limit) || !(style.miter_limit >= 1.0))
        return invalid("stroke miter_limit " + std::to_string(style.miter_limit) + ": not a finite ratio >= 1");
    for (const Contour& contour : contours) {
        for (const Quad& q : contour) {
            if (!finite(q.p0) || !finite(q.p1) || !finite(q.p2))
                return invalid("stroke contour: a point is not finite");
        }
    }
    if (style.half_width == 0.0) return {};
    std::vector<Contour> made;
    Stroker stroker(style, made);
    for (const Contour& contour : contours) {
        const std::vector<Quad> elements = stroke_elements(contour);
        if (elements.empty()) continue;
        const bool closed = elements.back().p2 == elements.front().p0;
        for (size_t i = 0; i < elements.size(); ++i) {
            stroker.stroke_curve(elements[i]);
            const bool last = i + 1 == elements.size();
            if (!last || closed) {
                const Quad& next = elements[last ? 0 : i + 1];
                stroker.join(elements[i].p2, direction(elements[i], 1.0), direction(next, 0.0));
            }
            if (stroker.curves() > limits::kMaxStrokeCurves) {
                return invalid("stroke half_width " + std::to_string(style.half_width) + " em at tolerance " +
                               std::to_string(style.tolerance) + " em: more than " +
                               std::to_string(limits::kMaxStrokeCurves) + " curves (limits::kMaxStrokeCurves)");
            }
        }
    }
    pieces.insert(pieces.end(), std::make_move_iterator(made.begin()), std::make_move_iterator(made.end()));
    return {};
}

}  // namespace crisp
