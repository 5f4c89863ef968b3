// Placing glyphs under a transform (docs/transforms.md): quantized keys, 2D transforms about a
// pivot, and text on a world-space plane with its local affine maps and their error.
#include <crisp/transform.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>

namespace crisp {

namespace {

bool finite(std::initializer_list<double> values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// `value` in `one` units per 1, rounded to a multiple of `step` units; false past `limit` units.
bool quantize(double value, double one, uint32_t step, double limit, int32_t& out) {
    const double units = std::round(value * one / step) * step;
    if (!(std::abs(units) <= limit)) return false;
    out = static_cast<int32_t>(units);
    return true;
}

// The pen on one axis split into its whole pixel and its subpixel offset at `steps` per pixel.
void split_pen(double pen, uint32_t steps, int32_t& whole, uint8_t& subpixel) {
    double base = std::floor(pen);
    const double step = std::round((pen - base) * steps);
    double offset = step * static_cast<double>(kSubpixelSteps / steps);
    if (offset >= kSubpixelSteps) {
        base += 1.0;
        offset = 0.0;
    }
    whole = static_cast<int32_t>(base);
    subpixel = static_cast<uint8_t>(offset);
}

double length3(const std::array<float, 3>& v) {
    return std::hypot(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]));
}

}  // namespace

bool place_glyph(const GlyphRecord& record, const GlyphPlacement& place, const TransformSteps& steps,
                 GlyphInstance& glyph) {
    const double* l = place.linear;
    if (!finite({place.pen_x, place.pen_y, l[0], l[1], l[2], l[3], place.perspective[0], place.perspective[1]}))
        return false;
    constexpr double kMaxPen = 16777216.0;  // 2^24 px
    if (!(std::abs(place.pen_x) <= kMaxPen && std::abs(place.pen_y) <= kMaxPen)) return false;
    const uint32_t subpixel = std::clamp(std::bit_floor(std::max(steps.subpixel, 1u)), 1u, kSubpixelSteps);
    GlyphKey key = glyph.key;
    constexpr double kMaxLinear = 4194304.0 * kLinearOne;         // 2^22 px per em
    constexpr double kMaxPerspective = 1024.0 * kPerspectiveOne;  // 2^10 per em
    for (int i = 0; i < 4; ++i) {
        if (!quantize(l[i], kLinearOne, std::max(steps.linear, 1u), kMaxLinear, key.linear[i])) return false;
    }
    for (int i = 0; i < 2; ++i) {
        if (!quantize(place.perspective[i], kPerspectiveOne, std::max(steps.perspective, 1u), kMaxPerspective,
                      key.perspective[i]))
            return false;
    }
    const auto q = [&](int i) { return static_cast<double>(key.linear[i]) / kLinearOne; };
    if (!(std::abs(q(0) * q(3) - q(1) * q(2)) >= 1.0 / 65536.0)) return false;
    if (key.linear[1] == 0 && key.linear[2] == 0 && key.linear[0] > 0 && key.linear[3] < 0 && key.perspective[0] == 0 &&
        key.perspective[1] == 0) {
        // Axis-aligned after all: the layout's own key, shared with untransformed text.
        key.size_x = static_cast<uint32_t>(key.linear[0]);
        key.size_y = static_cast<uint32_t>(-key.linear[3]);
        std::fill(std::begin(key.linear), std::end(key.linear), 0);
    } else {
        key.size_x = std::max(1u, static_cast<uint32_t>(std::lround(std::hypot(q(0), q(2)) * kSizeOne)));
        key.size_y = std::max(1u, static_cast<uint32_t>(std::lround(std::hypot(q(1), q(3)) * kSizeOne)));
    }
    int32_t whole_x = 0, whole_y = 0;
    split_pen(place.pen_x, subpixel, whole_x, key.subpixel_x);
    split_pen(place.pen_y, subpixel, whole_y, key.subpixel_y);
    const GlyphRect rect = glyph_rect(record, key);
    glyph.key = key;
    glyph.x = whole_x + rect.x;
    glyph.y = whole_y + rect.y;
    glyph.width = rect.width;
    glyph.height = rect.height;
    glyph.pen_x = static_cast<float>(place.pen_x);
    glyph.pen_y = static_cast<float>(place.pen_y);
    return true;
}

bool valid_transform(const TextTransform& t) {
    const double a = static_cast<double>(t.a), b = static_cast<double>(t.b), c = static_cast<double>(t.c),
                 d = static_cast<double>(t.d);
    if (!finite({a, b, c, d, static_cast<double>(t.pivot_x), static_cast<double>(t.pivot_y)})) return false;
    constexpr double kMaxEntry = 65536.0;
    if (std::max({std::abs(a), std::abs(b), std::abs(c), std::abs(d)}) > kMaxEntry) return false;
    return std::abs(a * d - b * c) >= 1.0 / 65536.0;
}

bool valid_plane(const TextPlane& plane) {
    for (const auto* v : {&plane.origin, &plane.axis_x, &plane.axis_y}) {
        for (float f : *v) {
            if (!std::isfinite(f)) return false;
        }
    }
    for (float f : plane.view_projection) {
        if (!std::isfinite(f)) return false;
    }
    for (float f : plane.viewport) {
        if (!std::isfinite(f)) return false;
    }
    const auto& x = plane.axis_x;
    const auto& y = plane.axis_y;
    const std::array<float, 3> cross = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                                        x[0] * y[1] - x[1] * y[0]};
    const double lx = length3(x), ly = length3(y);
    if (!(lx > 0.0 && ly > 0.0)) return false;
    if (!(length3(cross) > 1e-6 * lx * ly)) return false;
    return plane.viewport[2] > 0.0f && plane.viewport[3] > 0.0f;
}

GlyphPlacement place_transformed(const TextTransform& t, double pen_x, double pen_y, double size_x, double size_y,
                                 double dx, double dy) {
    const double a = static_cast<double>(t.a), b = static_cast<double>(t.b), c = static_cast<double>(t.c),
                 d = static_cast<double>(t.d);
    const double px = pen_x - static_cast<double>(t.pivot_x), py = pen_y - static_cast<double>(t.pivot_y);
    GlyphPlacement place;
    place.pen_x = static_cast<double>(t.pivot_x) + a * px + b * py + dx;
    place.pen_y = static_cast<double>(t.pivot_y) + c * px + d * py + dy;
    // L times em-to-layout-pixels, diag(size_x, -size_y).
    place.linear[0] = a * size_x;
    place.linear[1] = -b * size_y;
    place.linear[2] = c * size_x;
    place.linear[3] = -d * size_y;
    return place;
}

namespace {

// The plane's projection of layout pixels as homogeneous target pixels and clip z:
// (X, Y, W, Z) = col0 x + col1 y + col2, the pixel (X / W, Y / W), NDC z = Z / W.
struct PlaneMap {
    double col[3][4] = {};

    explicit PlaneMap(const TextPlane& plane) {
        const auto& m = plane.view_projection;
        const auto clip = [&](const std::array<float, 3>& v, double w, double out[4]) {
            for (int r = 0; r < 4; ++r) {
                out[r] = static_cast<double>(m[static_cast<size_t>(r)]) * static_cast<double>(v[0]) +
                         static_cast<double>(m[static_cast<size_t>(4 + r)]) * static_cast<double>(v[1]) +
                         static_cast<double>(m[static_cast<size_t>(8 + r)]) * static_cast<double>(v[2]) +
                         static_cast<double>(m[static_cast<size_t>(12 + r)]) * w;
            }
        };
        double c[3][4];
        clip(plane.axis_x, 0.0, c[0]);
        clip(plane.axis_y, 0.0, c[1]);
        clip(plane.origin, 1.0, c[2]);
        const double vx = static_cast<double>(plane.viewport[0]), vy = static_cast<double>(plane.viewport[1]);
        const double hw = 0.5 * static_cast<double>(plane.viewport[2]),
                     hh = 0.5 * static_cast<double>(plane.viewport[3]);
        for (int k = 0; k < 3; ++k) {
            col[k][0] = (vx + hw) * c[k][3] + hw * c[k][0];
            col[k][1] = (vy + hh) * c[k][3] + hh * c[k][1];
            col[k][2] = c[k][3];
            col[k][3] = c[k][2];
        }
    }
    void at(double x, double y, double out[4]) const {
        for (int r = 0; r < 4; ++r) out[r] = col[0][r] * x + col[1][r] * y + col[2][r];
    }
};

}  // namespace

PlanePlacement place_on_plane(const TextPlane& plane, const GlyphRecord& record, double pen_x, double pen_y,
                              double size_x, double size_y) {
    PlanePlacement out;
    const PlaneMap map(plane);
    // Homogeneous pixels of em point e: n0 + K e, with n0 the pen's and K the columns times
    // diag(size_x, -size_y).
    double n0[4];
    map.at(pen_x, pen_y, n0);
    double k[2][4];
    for (int r = 0; r < 4; ++r) {
        k[0][r] = map.col[0][r] * size_x;
        k[1][r] = -map.col[1][r] * size_y;
    }
    const auto project = [&](double ex, double ey, double h[4]) {
        for (int r = 0; r < 4; ++r) h[r] = n0[r] + k[0][r] * ex + k[1][r] * ey;
    };
    // Every bbox corner in front of the eye and within the depth range.
    const double box[4] = {static_cast<double>(record.bbox_min_x), static_cast<double>(record.bbox_min_y),
                           static_cast<double>(record.bbox_max_x), static_cast<double>(record.bbox_max_y)};
    if (!(n0[2] > 0.0)) return out;
    for (int corner = 0; corner < 4; ++corner) {
        double h[4];
        project(box[(corner & 1) != 0 ? 2 : 0], box[(corner & 2) != 0 ? 3 : 1], h);
        if (!(h[2] >= kMinPerspectiveW * n0[2])) return out;
        const double z = h[3] / h[2];
        if (!(z >= 0.0 && z <= 1.0)) return out;
    }
    const double cx = 0.5 * (box[0] + box[2]), cy = 0.5 * (box[1] + box[3]);
    double hc[4];
    project(cx, cy, hc);
    const double sx = hc[0] / hc[2], sy = hc[1] / hc[2];
    out.depth = static_cast<float>(hc[3] / hc[2]);
    // The Jacobian at the centre: (K_xy - s K_w) / W.
    double j[4];
    for (int col = 0; col < 2; ++col) {
        j[col] = (k[col][0] - sx * k[col][2]) / hc[2];
        j[2 + col] = (k[col][1] - sy * k[col][2]) / hc[2];
    }
    double error = 0.0;
    for (int corner = 0; corner < 4; ++corner) {
        const double ex = box[(corner & 1) != 0 ? 2 : 0], ey = box[(corner & 2) != 0 ? 3 : 1];
        double h[4];
        project(ex, ey, h);
        const double ax = sx + j[0] * (ex - cx) + j[1] * (ey - cy), ay = sy + j[2] * (ex - cx) + j[3] * (ey - cy);
        error = std::max(error, std::hypot(h[0] / h[2] - ax, h[1] / h[2] - ay));
    }
    out.affine_error = error;
    out.visible = true;
    if (error <= kMaxLocalAffineError) {
        out.place.pen_x = sx - j[0] * cx - j[1] * cy;
        out.place.pen_y = sy - j[2] * cx - j[3] * cy;
        std::copy(std::begin(j), std::end(j), std::begin(out.place.linear));
        return out;
    }
    // Exact: pen at the projected em origin, L = (K_xy - pen K_w) / n0_w, p = K_w / n0_w.
    out.projective = true;
    const double px = n0[0] / n0[2], py = n0[1] / n0[2];
    out.place.pen_x = px;
    out.place.pen_y = py;
    for (int col = 0; col < 2; ++col) {
        out.place.linear[col] = (k[col][0] - px * k[col][2]) / n0[2];
        out.place.linear[2 + col] = (k[col][1] - py * k[col][2]) / n0[2];
        out.place.perspective[col] = k[col][2] / n0[2];
    }
    return out;
}

}  // namespace crisp
