// Shared by the transform tests: a camera built by hand (a perspective times a look-at, Vulkan's
// clip conventions, column-major) and the exact projection of a TextPlane's layout pixels, written
// independently of src/text/transform.cpp so that its placements can be checked against it.
#pragma once

#include <crisp/asset.hpp>
#include <crisp/transform.hpp>

#include <array>
#include <cmath>

namespace crisp::test {

using Vec3 = std::array<double, 3>;

// A glyph's bbox in em: min x, min y, max x, max y.
inline std::array<double, 4> bbox_of(const GlyphRecord& g) {
    return {static_cast<double>(g.bbox_min_x), static_cast<double>(g.bbox_min_y), static_cast<double>(g.bbox_max_x),
            static_cast<double>(g.bbox_max_y)};
}

inline Vec3 sub3(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double dot3(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross3(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3 normalized(const Vec3& v) {
    const double l = std::sqrt(dot3(v, v));
    return {v[0] / l, v[1] / l, v[2] / l};
}

// perspective(fov_y, aspect, near, far) * look_at(eye, centre, up), column-major: right-handed view
// space looking down -z, clip y negated (Vulkan's NDC y points down), depth 0 at near and 1 at far.
inline std::array<float, 16> view_projection(const Vec3& eye, const Vec3& centre, const Vec3& up, double fov_y,
                                             double aspect, double near, double far) {
    const Vec3 f = normalized(sub3(centre, eye));
    const Vec3 s = normalized(cross3(f, up));
    const Vec3 u = cross3(s, f);
    // Row-major view matrix.
    const double view[4][4] = {{s[0], s[1], s[2], -dot3(s, eye)},
                               {u[0], u[1], u[2], -dot3(u, eye)},
                               {-f[0], -f[1], -f[2], dot3(f, eye)},
                               {0.0, 0.0, 0.0, 1.0}};
    const double t = 1.0 / std::tan(fov_y / 2.0);
    const double projection[4][4] = {{t / aspect, 0.0, 0.0, 0.0},
                                     {0.0, -t, 0.0, 0.0},
                                     {0.0, 0.0, far / (near - far), near * far / (near - far)},
                                     {0.0, 0.0, -1.0, 0.0}};
    std::array<float, 16> out{};
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
            double v = 0.0;
            for (int k = 0; k < 4; ++k) v += projection[r][k] * view[k][c];
            out[static_cast<size_t>(c * 4 + r)] = static_cast<float>(v);
        }
    }
    return out;
}

// A plane of text whose layout pixel (x, y) lies at world (x, -y, 0) times `scale`, seen from
// `eye` looking at `centre` on a viewport of width x height pixels.
inline TextPlane plane_seen_from(const Vec3& eye, const Vec3& centre, float scale, float width, float height) {
    TextPlane plane;
    plane.origin = {0.0f, 0.0f, 0.0f};
    plane.axis_x = {scale, 0.0f, 0.0f};
    plane.axis_y = {0.0f, -scale, 0.0f};
    plane.view_projection = view_projection(eye, centre, {0.0, 1.0, 0.0}, 0.9, width / height, 0.1, 1000.0);
    plane.viewport = {0.0f, 0.0f, width, height};
    return plane;
}

// The world point of layout pixel (x, y) on `plane`.
inline Vec3 plane_point(const TextPlane& plane, double x, double y) {
    Vec3 p{};
    for (size_t i = 0; i < 3; ++i) {
        p[i] = static_cast<double>(plane.origin[i]) + x * static_cast<double>(plane.axis_x[i]) +
               y * static_cast<double>(plane.axis_y[i]);
    }
    return p;
}

// The clip coordinates of world point `p` under the plane's view-projection.
inline std::array<double, 4> clip_of(const TextPlane& plane, const Vec3& p) {
    const auto& m = plane.view_projection;
    std::array<double, 4> clip{};
    for (size_t r = 0; r < 4; ++r) {
        clip[r] = static_cast<double>(m[r]) * p[0] + static_cast<double>(m[4 + r]) * p[1] +
                  static_cast<double>(m[8 + r]) * p[2] + static_cast<double>(m[12 + r]);
    }
    return clip;
}

// Target pixel (x, y) and clip w of world point `p` seen through the plane's camera.
inline std::array<double, 3> project(const TextPlane& plane, const Vec3& p) {
    const std::array<double, 4> clip = clip_of(plane, p);
    const auto& v = plane.viewport;
    return {static_cast<double>(v[0]) + (clip[0] / clip[3] + 1.0) / 2.0 * static_cast<double>(v[2]),
            static_cast<double>(v[1]) + (clip[1] / clip[3] + 1.0) / 2.0 * static_cast<double>(v[3]), clip[3]};
}

// Where em point (ex, ey) of a glyph at pen (pen_x, pen_y), size px per em, lands under
// `place`: pen + (L e) / (1 + p . e).
inline std::array<double, 2> placed_point(const GlyphPlacement& place, double ex, double ey) {
    const double w = 1.0 + place.perspective[0] * ex + place.perspective[1] * ey;
    return {place.pen_x + (place.linear[0] * ex + place.linear[1] * ey) / w,
            place.pen_y + (place.linear[2] * ex + place.linear[3] * ey) / w};
}

// The exact projective placement of a glyph at layout pen (pen_x, pen_y), (size_x, size_y) px per
// em, on `plane`: its pen at the projected em origin, and L and p from the projection's
// homogeneous pixels X(e) = X0 + Xe e, W(e) = W0 + We e as pixel = pen + ((Xe - pen We) e) / W0 /
// (1 + (We / W0) e).
inline GlyphPlacement exact_placement(const TextPlane& plane, double pen_x, double pen_y, double size_x,
                                      double size_y) {
    const auto homogeneous = [&](double ex, double ey) {
        const std::array<double, 4> clip = clip_of(plane, plane_point(plane, pen_x + size_x * ex, pen_y - size_y * ey));
        const auto& v = plane.viewport;
        const double hw = static_cast<double>(v[2]) / 2.0, hh = static_cast<double>(v[3]) / 2.0;
        return std::array<double, 3>{(static_cast<double>(v[0]) + hw) * clip[3] + hw * clip[0],
                                     (static_cast<double>(v[1]) + hh) * clip[3] + hh * clip[1], clip[3]};
    };
    const std::array<double, 3> o = homogeneous(0.0, 0.0), ux = homogeneous(1.0, 0.0), uy = homogeneous(0.0, 1.0);
    GlyphPlacement place;
    place.pen_x = o[0] / o[2];
    place.pen_y = o[1] / o[2];
    const std::array<double, 3> d[2] = {{ux[0] - o[0], ux[1] - o[1], ux[2] - o[2]},
                                        {uy[0] - o[0], uy[1] - o[1], uy[2] - o[2]}};
    for (int col = 0; col < 2; ++col) {
        place.linear[col] = (d[col][0] - place.pen_x * d[col][2]) / o[2];
        place.linear[2 + col] = (d[col][1] - place.pen_y * d[col][2]) / o[2];
        place.perspective[col] = d[col][2] / o[2];
    }
    return place;
}

}  // namespace crisp::test
