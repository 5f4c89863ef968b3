// The boundary of a glyph's nonzero fill, or of the union of several fills (a colour glyph's
// layers), as closed contours (docs/effects.md, "Overlapping contours"): every curve cut where
// another crosses it, the pieces that have the fill on one side only kept, and chained back into
// contours.
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

// Nonzero winding of curves [first, last) about p: signed crossings of the ray to +x.
int winding(const std::vector<Quad>& curves, size_t first, size_t last, Vec2 p) {
    int w = 0;
    for (size_t at = first; at < last; ++at) {
        const Quad& q = curves[at];
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
// stretches (more hits than two curves can cross) give none and return true: the caller cuts each
// curve where the other ends on it, and the midpoint tests settle the pieces.
bool crossings(const Quad& a, const Quad& b, std::vector<std::pair<double, double>>& hits) {
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
        if (++spans > kMaxSpans) return true;
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
    if (found.size() > 4) return true;  // two quadratics cross at most four times
    hits.insert(hits.end(), found.begin(), found.end());
    return false;
}

// The parameter of q nearest p: the best of a few samples, refined by Newton's method on
// (q(t) - p) . q'(t).
double nearest_parameter(const Quad& q, Vec2 p) {
    constexpr int kSamples = 32;
    double best = 0.0, best_d = length(q.p0 - p);
    for (int i = 1; i <= kSamples; ++i) {
        const double t = static_cast<double>(i) / kSamples;
        const double d = length(evaluate(q, t) - p);
        if (d < best_d) {
            best = t;
            best_d = d;
        }
    }
    const Vec2 a = q.p0 - 2.0 * q.p1 + q.p2, b = 2.0 * (q.p1 - q.p0);
    double t = best;
    for (int k = 0; k < 8; ++k) {
        const Vec2 off = evaluate(q, t) - p, d1 = 2.0 * t * a + b, d2 = 2.0 * a;
        const double f = dot(off, d1), df = dot(d1, d1) + dot(off, d2);
        if (df <= 0.0) break;
        t = std::clamp(t - f / df, 0.0, 1.0);
    }
    return length(evaluate(q, t) - p) < best_d ? t : best;
}

// Whether two kept pieces are one stretch of the boundary twice (coincident edges of two fills):
// the same ends, and the same control point or both straight.
bool same_piece(const Quad& a, const Quad& b, double snap) {
    if (length(a.p0 - b.p0) > snap || length(a.p2 - b.p2) > snap) return false;
    if (length(a.p1 - b.p1) <= snap) return true;
    const auto straight = [snap](const Quad& q) {
        const Vec2 chord = q.p2 - q.p0;
        const double len = length(chord);
        return len > 0.0 && std::abs(chord.x * (q.p1.y - q.p0.y) - chord.y * (q.p1.x - q.p0.x)) / len <= snap;
    };
    return straight(a) && straight(b);
}

double distance(Vec2 a, Vec2 b) {
    return length(a - b);
}

// Whether p is inside any fill: fill k is curves [ends[k - 1], ends[k]) (ends[-1] = 0).
bool inside(const std::vector<Quad>& curves, const std::vector<size_t>& ends, Vec2 p) {
    size_t first = 0;
    for (const size_t last : ends) {
        if (winding(curves, first, last, p) != 0) return true;
        first = last;
    }
    return false;
}

std::vector<Contour> concatenated(const std::vector<std::vector<Contour>>& fills) {
    std::vector<Contour> all;
    for (const std::vector<Contour>& fill : fills) all.insert(all.end(), fill.begin(), fill.end());
    return all;
}

}  // namespace

std::vector<Contour> boundary_contours(const std::vector<Contour>& contours) {
    return union_boundary({contours});
}

std::vector<Contour> union_boundary(const std::vector<std::vector<Contour>>& fills) {
    std::vector<Quad> curves;
    std::vector<size_t> ends;
    for (const std::vector<Contour>& fill : fills) {
        for (const Contour& c : fill) curves.insert(curves.end(), c.begin(), c.end());
        ends.push_back(curves.size());
    }
    if (curves.empty()) return concatenated(fills);
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
            if (crossings(curves[i], curves[j], hits)) {
                // Coincident: each curve cut where the other ends inside it.
                const auto cut_at_ends = [&](size_t on, size_t of) {
                    for (const Vec2 end : {curves[of].p0, curves[of].p2}) {
                        const double t = nearest_parameter(curves[on], end);
                        if (t > end_eps && t < 1.0 - end_eps && length(evaluate(curves[on], t) - end) <= snap) {
                            cuts[on].push_back({t, end});
                        }
                    }
                };
                cut_at_ends(i, j);
                cut_at_ends(j, i);
                continue;
            }
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
    bool dropped = false, turned = false;
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
            const bool in_left = inside(curves, ends, m + side * left);
            const bool in_right = inside(curves, ends, m - side * left);
            if (in_left == in_right) {
                dropped = true;
                continue;
            }
            if (in_left) {
                piece = {piece.p2, piece.p1, piece.p0};
                turned = true;
            }
            if (std::any_of(kept.begin(), kept.end(),
                            [&](const Quad& other) { return same_piece(other, piece, snap); })) {
                dropped = true;
                continue;
            }
            kept.push_back(piece);
        }
    }
    // Nothing overlapped and nothing was cut: the glyph's own contours are its boundary (several
    // fills' contours only where none was turned, since their windings add).
    const bool cut = std::any_of(cuts.begin(), cuts.end(), [](const std::vector<Cut>& c) { return !c.empty(); });
    if (!dropped && !cut && (fills.size() == 1 || !turned)) return concatenated(fills);

    // Chained back into closed contours: each piece followed by the unused piece that starts
    // where it ends. Where two curves touch (a layer's edge tangent to another's curve), the cuts
    // about the touching point leave the stretch between them twice, once in a sliver that
    // closes no contour: an open chain that short is dropped. Any other chain that does not close
    // (a fault of the cuts) leaves the fills' own contours, which overlap but never lose a curve
    // of the boundary.
    const double sliver = 1e-3 * scale;
    std::vector<uint8_t> used(kept.size(), 0);
    std::vector<Contour> out;
    for (size_t first = 0; first < kept.size(); ++first) {
        if (used[first]) continue;
        Contour contour{kept[first]};
        used[first] = 1;
        bool open = false;
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
                double length_of = 0.0;
                for (const Quad& q : contour) length_of += distance(q.p0, q.p1) + distance(q.p1, q.p2);
                if (length_of > sliver) return concatenated(fills);
                open = true;
                break;
            }
            used[next] = 1;
            Quad q = kept[next];
            q.p0 = end;
            contour.push_back(q);
        }
        if (open) continue;
        contour.back().p2 = contour.front().p0;
        out.push_back(std::move(contour));
    }
    return out;
}

}  // namespace crisp
