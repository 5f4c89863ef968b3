// Private: the blur of a blurred shadow or glow (docs/effects.md, "Blur"), shared by the CPU code
// and mirrored operation for operation in shaders/raster/raster.comp.
//
// A blur of radius R px is, per axis, k = B * B * B: three boxes of width w = 2 R / 3, so that its
// support 3 w reaches R either side and sigma = w / 2 = R / 3. A texel channel's filter along an
// axis is its sample interval's box [x0, x1] convolved with k; blur_cdf() is that filter's CDF,
// built from H, the integral of the unit B3 kernel's CDF, without sampling.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace crisp {

// GlyphKey::blur's unit: 1/64 px of radius.
inline constexpr double kBlurUnit = 1.0 / 64.0;

// The widths of the three boxes of a blur of radius `radius` px: w = 2 R / 3.
template <class Real>
Real blur_box_width(Real radius) {
    return radius * Real(2) / Real(3);
}

// The CDF of the unit B3 kernel (three unit boxes, support [-3/2, 3/2]) at z.
template <class Real>
Real blur_b3_cdf(Real z) {
    const Real a = std::abs(z);
    Real upper;  // the CDF at -a
    if (a >= Real(1.5)) {
        upper = Real(0);
    } else if (a >= Real(0.5)) {
        const Real s = Real(1.5) - a;
        upper = s * s * s / Real(6);
    } else {
        upper = Real(0.5) - a * (Real(0.75) - a * a / Real(3));
    }
    return z < Real(0) ? upper : Real(1) - upper;
}

// H(z), the integral of blur_b3_cdf from -infinity to z: 0 up to -3/2, (z + 3/2)^4 / 24 on
// [-3/2, -1/2], on [-1/2, 0] 1/24 + (z + 1/2) / 6 + 3/8 (z + 1/2)^2 - (z^4 / 4 + z / 8 + 3/64) / 3,
// and z + H(-z) for z > 0 (the CDF's symmetry), so that H(z) = z from 3/2 on.
template <class Real>
Real blur_h(Real z) {
    const Real n = -std::abs(z);  // H at n = -|z|, then the symmetry
    Real h;
    if (n <= Real(-1.5)) {
        h = Real(0);
    } else if (n <= Real(-0.5)) {
        const Real s = n + Real(1.5);
        const Real s2 = s * s;
        h = s2 * s2 / Real(24);
    } else {
        const Real s = n + Real(0.5);
        const Real n2 = n * n;
        h = Real(1) / Real(24) + s / Real(6) + Real(0.375) * s * s -
            (n2 * n2 / Real(4) + n / Real(8) + Real(3) / Real(64)) / Real(3);
    }
    return z > Real(0) ? z + h : h;
}

// The CDF at t of the box [x0, x1] convolved with the blur of box width w:
//     F(t) = (w / b) (H((t - x0) / w) - H((t - x1) / w)),  b = x1 - x0;
// without blur (w = 0) the box's own clamp((t - x0) / b, 0, 1), and for a box of no width the
// blur's own CDF.
template <class Real>
Real blur_cdf(Real t, Real x0, Real x1, Real w) {
    const Real b = x1 - x0;
    if (!(w > Real(0))) {
        if (!(b > Real(0))) return t < x0 ? Real(0) : Real(1);
        return std::clamp((t - x0) / b, Real(0), Real(1));
    }
    if (!(b > Real(0))) return blur_b3_cdf((t - x0) / w);
    return (w / b) * (blur_h((t - x0) / w) - blur_h((t - x1) / w));
}

// The density of that filter at t (blur_cdf's derivative), for w > 0.
template <class Real>
Real blur_density(Real t, Real x0, Real x1, Real w) {
    const Real b = x1 - x0;
    if (!(b > Real(0))) return Real(0);
    return (blur_b3_cdf((t - x0) / w) - blur_b3_cdf((t - x1) / w)) / b;
}

// How many safeguarded Newton steps blur_inverse_cdf() takes (raster.comp writes them out).
inline constexpr uint32_t kBlurInverseSteps = 12;

// Where the unit B3 kernel's CDF is about v: exact on its outer pieces (cubics), one Newton step
// from the line through its centre on the inner one. blur_inverse_cdf()'s first guess.
template <class Real>
Real blur_b3_inverse_guess(Real v) {
    if (v < Real(1) / Real(6)) return std::cbrt(Real(6) * v) - Real(1.5);
    if (v > Real(5) / Real(6)) return Real(1.5) - std::cbrt(Real(6) * (Real(1) - v));
    Real z = (v - Real(0.5)) / Real(0.75);
    z -= (Real(0.5) + z * (Real(0.75) - z * z / Real(3)) - v) / (Real(0.75) - z * z);
    return z;
}

// The t in [x0 - 3w/2, x1 + 3w/2] where blur_cdf(t, x0, x1, w) = v (v in [0, 1]), w > 0 and
// x1 > x0: from the point where a B3 kernel of the filter's variance (box width
// sqrt(w^2 + b^2 / 3)) about the box's centre reaches v, kBlurInverseSteps Newton steps, each kept
// inside the bracket the previous ones found (a step that would leave it bisects instead).
template <class Real>
Real blur_inverse_cdf(Real v, Real x0, Real x1, Real w) {
    Real lo = x0 - Real(1.5) * w, hi = x1 + Real(1.5) * w;
    const Real b = x1 - x0;
    const Real spread = std::sqrt(w * w + b * b / Real(3));
    Real t = std::clamp(Real(0.5) * (x0 + x1) + spread * blur_b3_inverse_guess(v), lo, hi);
    for (uint32_t i = 0; i < kBlurInverseSteps; ++i) {
        const Real f = blur_cdf(t, x0, x1, w) - v;
        if (f < Real(0)) lo = t;
        if (f > Real(0)) hi = t;
        const Real d = blur_density(t, x0, x1, w);
        const Real next = d > Real(0) ? t - f / d : lo - Real(1);
        t = next >= lo && next <= hi ? next : Real(0.5) * (lo + hi);
    }
    return t;
}

}  // namespace crisp
