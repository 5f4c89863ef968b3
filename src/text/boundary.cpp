// The boundary of a glyph's nonzero fill as closed contours (docs/effects.md, "Overlapping
// contours"): every curve cut where another crosses it, the pieces that have the fill on one side
// only kept, and chained back into contours.
#include "text/stroke.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace crisp {

namespace {

struct Box {
    double x0, y0, x1, y1;
};

Box box_of(const Quad& q) {
    return {std::min({q.p0.x, q.p1.x, q.p2.x}), std::min({q.p0.y, q.p1.y, q.p2.y}), std::max({q.p0.x, q.p1.x, q.p2.x}),
            std::max({q.p0.y, q.p1.y, q.p2.y})};
}

bool overlap(const Box& a, const Box& b) {
    return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1;
}

// The piece of q over [t0, t1] as a quadratic of its own.
Quad sub_quad(const Quad& q, double t0, double t1) {
    const Vec2 a = evaluate(q, t0), b = evaluate(q, t1);
    // The control point: where the tangents at t0 and t1 meet, c(t0) + (t1 - t0) / 2 c'(t0).
    const Vec2 d0 = 2.0 * ((1.0 - t0) * (q.p1 - q.p0) + t0 * (q.p2 - q.p1));
    return {a, a + (0.5 * (t1 - t0)) * d0, b};
}

// Nonzero winding of the curves about p: signed crossings of the ray to +x.
int winding(const std::vector<Quad>& curves, Vec2 p) {
    int w = 0;
    for (const Quad& q : curves) {
        const double a = q.p0.y - 2.0 * q.p1.y + q.p2.y, b = 2.0 * (q.p1.y - q.p0.y), c = q.p0.y - p.y;
        double roots[2];
        int n = 0;
        if (std::abs(a) < 1e-14) {
            if (b != 0.0) roots[n++] = -c / b;
        } else {
            const double disc = b * b - 4.0 * a * c;
            if (disc >= 0.0) {
                const double s = std::sqrt(disc);
                roots[n++] = (-b - s) / (2.0 * a);
                roots[n++] = (-b + s) / (2.0 * a);
            }
        }
        for (int i = 0; i < n; ++i) {
            const double t = roots[i];
            // Half-open in t so that a crossing at a shared end point counts once.
            if (!(t >= 0.0 && t < 1.0)) continue;
            const double dy = 2.0 * a * t + b;
            if (dy == 0.0) continue;
            if (evaluate(q, t).x > p.x) w += dy > 0.0 ? 1 : -1;
        }
    }
    return w;
}

// Parameters where curves a and b cross, by subdividing both while their boxes meet. Coincident
// stretches (more hits than two curves can cross) give none: the midpoint tests settle them.
void crossings(const Quad& a, const Quad& b, std::vector<std::pair<double, double>>& hits) {
    struct Span {
        double a0, a1, b0, b1;
        int depth;
    };
    constexpr int kMaxDepth = 40;
    constexpr size_t kMaxHits = 16;
    std::vector<Span> stack{{0.0, 1.0, 0.0, 1.0, 0}};
    std::vector<std::pair<double, double>> found;
    // Curves that run along each other meet in every span: past this many spans they count as
    // coincident.
    constexpr int kMaxSpans = 1 << 14;
    int spans = 0;
    while (!stack.empty() && found.size() <= kMaxHits) {
        if (++spans > kMaxSpans) return;
        const Span s = stack.back();
        stack.pop_back();
        const Quad qa = sub_quad(a, s.a0, s.a1), qb = sub_quad(b, s.b0, s.b1);
        const Box ba = box_of(qa), bb = box_of(qb);
        if (!overlap(ba, bb)) continue;
        const double size = std::max({ba.x1 - ba.x0, ba.y1 - ba.y0, bb.x1 - bb.x0, bb.y1 - bb.y0});
        if (s.depth >= kMaxDepth || size < 1e-12) {
            const double ta = 0.5 * (s.a0 + s.a1), tb = 0.5 * (s.b0 + s.b1);
            const bool near = std::any_of(found.begin(), found.end(), [&](const auto& f) {
                return std::abs(f.first - ta) < 1e-9 && std::abs(f.second - tb) < 1e-9;
            });
            if (!near) found.push_back({ta, tb});
            continue;
        }
        const double am = 0.5 * (s.a0 + s.a1), bm = 0.5 * (s.b0 + s.b1);
        stack.push_back({s.a0, am, s.b0, bm, s.depth + 1});
        stack.push_back({s.a0, am, bm, s.b1, s.depth + 1});
        stack.push_back({am, s.a1, s.b0, bm, s.depth + 1});
        stack.push_back({am, s.a1, bm, s.b1, s.depth + 1});
    }
    if (found.size() > 4) return;  // two quadratics cross at most four times
    hits.insert(hits.end(), found.begin(), found.end());
}

double distance(Vec2 a, Vec2 b) {
    return length(a - b);
}

}  // namespace

std::vector<Contour> boundary_contours(const std::vector<Contour>& contours) {
    std::vector<Quad> curves;
    for (const Contour& c : contours) curves.insert(curves.end(), c.begin(), c.end());
    if (curves.empty()) return contours;
    Box all = box_of(curves.front());
    for (const Quad& q : curves) {
        const Box b = box_of(q);
        all = {std::min(all.x0, b.x0), std::min(all.y0, b.y0), std::max(all.x1, b.x1), std::max(all.y1, b.y1)};
    }
    const double scale = std::max({all.x1 - all.x0, all.y1 - all.y0, 1e-6});
    const double end_eps = 1e-7;       // parameters this near an end are the end
    const double side = 1e-6 * scale;  // how far beside a piece its two sides are tested
    const double snap = 1e-7 * scale;  // end points this near are one vertex

    // Each curve's cuts: parameters, and the point both curves of a crossing take there.
    struct Cut {
        double t;
        Vec2 point;
    };
    std::vector<std::vector<Cut>> cuts(curves.size());
    std::vector<Box> boxes(curves.size());
    for (size_t i = 0; i < curves.size(); ++i) boxes[i] = box_of(curves[i]);
    std::vector<std::pair<double, double>> hits;
    for (size_t i = 0; i < curves.size(); ++i) {
        for (size_t j = i + 1; j < curves.size(); ++j) {
            if (!overlap(boxes[i], boxes[j])) continue;
            hits.clear();
            crossings(curves[i], curves[j], hits);
            for (const auto& [ti, tj] : hits) {
                const bool inner_i = ti > end_eps && ti < 1.0 - end_eps;
                const bool inner_j = tj > end_eps && tj < 1.0 - end_eps;
                if (!inner_i && !inner_j) continue;  // a shared vertex
                // A curve crossed at its end (a T-junction) gives its end point exactly.
                const auto point = [&](const Quad& q, double t, bool inner) {
                    return inner ? evaluate(q, t) : t < 0.5 ? q.p0 : q.p2;
                };
                const Vec2 pi = point(curves[i], ti, inner_i), pj = point(curves[j], tj, inner_j);
                const Vec2 at = 0.5 * (pi + pj);
                if (inner_i) cuts[i].push_back({ti, inner_j ? at : pj});
                if (inner_j) cuts[j].push_back({tj, inner_i ? at : pi});
            }
        }
    }

    // The pieces with the fill on exactly one side, each turned to have it on its right (clockwise
    // in y-up, TrueType's outer direction).
    std::vector<Quad> kept;
    bool dropped = false;
    for (size_t i = 0; i < curves.size(); ++i) {
        std::vector<Cut>& c = cuts[i];
        std::sort(c.begin(), c.end(), [](const Cut& a, const Cut& b) { return a.t < b.t; });
        double t0 = 0.0;
        Vec2 from = curves[i].p0;
        for (size_t k = 0; k <= c.size(); ++k) {
            const double t1 = k < c.size() ? c[k].t : 1.0;
            const Vec2 to = k < c.size() ? c[k].point : curves[i].p2;
            if (t1 - t0 <= end_eps) continue;
            Quad piece = sub_quad(curves[i], t0, t1);
            piece.p0 = from;
            piece.p2 = to;
            t0 = t1;
            from = to;
            // Tested at a parameter no vertex or horizontal edge of a font is likely to share a
            // height with (the midpoint of a stem often is the height of a bar).
            const double tm = 0.41421356237;
            const Vec2 m = evaluate(piece, tm);
            Vec2 d = (1.0 - tm) * (piece.p1 - piece.p0) + tm * (piece.p2 - piece.p1);
            if (length(d) == 0.0) d = piece.p2 - piece.p0;
            const double len = length(d);
            if (len == 0.0) continue;
            const Vec2 left{-d.y / len, d.x / len};
            const bool in_left = winding(curves, m + side * left) != 0;
            const bool in_right = winding(curves, m - side * left) != 0;
            if (in_left == in_right) {
                dropped = true;
                continue;
            }
            if (in_left) piece = {piece.p2, piece.p1, piece.p0};
            kept.push_back(piece);
        }
    }
    // Nothing overlapped and nothing was cut: the glyph's own contours are its boundary.
    const bool cut = std::any_of(cuts.begin(), cuts.end(), [](const std::vector<Cut>& c) { return !c.empty(); });
    if (!dropped && !cut) return contours;

    // Chained back into closed contours: each piece followed by the unused piece that starts
    // where it ends. A chain that does not close (a fault of the cuts) leaves the glyph's own
    // contours, which overlap but never lose a curve of the boundary.
    std::vector<uint8_t> used(kept.size(), 0);
    std::vector<Contour> out;
    for (size_t first = 0; first < kept.size(); ++first) {
        if (used[first]) continue;
        Contour contour{kept[first]};
        used[first] = 1;
        for (;;) {
            const Vec2 end = contour.back().p2;
            if (distance(end, contour.front().p0) <= snap && contour.size() > 1) break;
            size_t next = SIZE_MAX;
            double best = snap;
            for (size_t k = 0; k < kept.size(); ++k) {
                if (used[k]) continue;
                const double d = distance(kept[k].p0, end);
                if (d <= best) {
                    best = d;
                    next = k;
                }
            }
            if (next == SIZE_MAX) {
                if (distance(end, contour.front().p0) <= snap) break;  // a one-piece loop
                return contours;
            }
            used[next] = 1;
            Quad q = kept[next];
            q.p0 = end;
            contour.push_back(q);
        }
        contour.back().p2 = contour.front().p0;
        out.push_back(std::move(contour));
    }
    return out;
}

}  // namespace crisp
