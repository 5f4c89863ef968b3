// The little linear algebra the example's scene needs. Matrices are column-major (element
// [column * 4 + row]), as GLSL and crisp::depth_from_view_projection() read them.
#pragma once

#include <array>
#include <cmath>

namespace engine {

struct Vec3 {
    float x = 0.0f, y = 0.0f, z = 0.0f;
};
inline Vec3 operator+(Vec3 a, Vec3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(Vec3 a, Vec3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator*(Vec3 a, float s) {
    return {a.x * s, a.y * s, a.z * s};
}
inline float dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 normalize(Vec3 a) {
    return a * (1.0f / std::sqrt(dot(a, a)));
}

struct Mat4 {
    std::array<float, 16> m{};
    float& at(int column, int row) { return m[static_cast<size_t>(column * 4 + row)]; }
    float at(int column, int row) const { return m[static_cast<size_t>(column * 4 + row)]; }
    static Mat4 identity() {
        Mat4 out;
        for (int i = 0; i < 4; ++i) out.at(i, i) = 1.0f;
        return out;
    }
};

inline Mat4 operator*(const Mat4& a, const Mat4& b) {
    Mat4 out;
    for (int column = 0; column < 4; ++column) {
        for (int row = 0; row < 4; ++row) {
            float sum = 0.0f;
            for (int k = 0; k < 4; ++k) sum += a.at(k, row) * b.at(column, k);
            out.at(column, row) = sum;
        }
    }
    return out;
}

// (x, y, z, w) of the point `p` under `matrix`.
inline std::array<float, 4> transform_point(const Mat4& matrix, Vec3 p) {
    std::array<float, 4> out{};
    for (int row = 0; row < 4; ++row) {
        out[static_cast<size_t>(row)] =
            matrix.at(0, row) * p.x + matrix.at(1, row) * p.y + matrix.at(2, row) * p.z + matrix.at(3, row);
    }
    return out;
}

// The direction `v` under `matrix` (w = 0: no translation).
inline Vec3 transform_direction(const Mat4& matrix, Vec3 v) {
    return {matrix.at(0, 0) * v.x + matrix.at(1, 0) * v.y + matrix.at(2, 0) * v.z,
            matrix.at(0, 1) * v.x + matrix.at(1, 1) * v.y + matrix.at(2, 1) * v.z,
            matrix.at(0, 2) * v.x + matrix.at(1, 2) * v.y + matrix.at(2, 2) * v.z};
}

inline Mat4 translation(Vec3 t) {
    Mat4 out = Mat4::identity();
    out.at(3, 0) = t.x;
    out.at(3, 1) = t.y;
    out.at(3, 2) = t.z;
    return out;
}

inline Mat4 rotation_y(float radians) {
    Mat4 out = Mat4::identity();
    const float c = std::cos(radians), s = std::sin(radians);
    out.at(0, 0) = c;
    out.at(0, 2) = -s;
    out.at(2, 0) = s;
    out.at(2, 2) = c;
    return out;
}

// Right-handed view: the eye looks from `eye` at `target`, y up.
inline Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
    const Vec3 forward = normalize(target - eye);
    const Vec3 right = normalize(cross(forward, up));
    const Vec3 true_up = cross(right, forward);
    Mat4 out = Mat4::identity();
    out.at(0, 0) = right.x;
    out.at(1, 0) = right.y;
    out.at(2, 0) = right.z;
    out.at(0, 1) = true_up.x;
    out.at(1, 1) = true_up.y;
    out.at(2, 1) = true_up.z;
    out.at(0, 2) = -forward.x;
    out.at(1, 2) = -forward.y;
    out.at(2, 2) = -forward.z;
    out.at(3, 0) = -dot(right, eye);
    out.at(3, 1) = -dot(true_up, eye);
    out.at(3, 2) = dot(forward, eye);
    return out;
}

// Vulkan's clip space: y down, depth 0 at `near` and 1 at `far` (glm::perspectiveRH_ZO with y
// flipped). `shift_x` moves the image right by that many half-widths (a lens shift), so the scene
// can be centred beside a HUD without turning the camera.
inline Mat4 perspective(float fov_y, float aspect, float near, float far, float shift_x) {
    const float f = 1.0f / std::tan(fov_y / 2.0f);
    Mat4 out;
    out.at(0, 0) = f / aspect;
    out.at(1, 1) = -f;
    out.at(2, 0) = -shift_x;  // times w = -z_view: x_ndc moves by shift_x
    out.at(2, 2) = far / (near - far);
    out.at(2, 3) = -1.0f;
    out.at(3, 2) = near * far / (near - far);
    return out;
}

}  // namespace engine
