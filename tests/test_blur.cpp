// The blur's kernel (src/text/blur_kernel.hpp) against numeric integration, its inverse CDF, and
// the blurred reference (support/blur_reference.hpp) against the exact area without blur and the
// glyph's area in texels (a blur keeps the mass) with it.
#include "blur_reference.hpp"
#include "coverage.hpp"
#include "test_support.hpp"

#include "text/blur_kernel.hpp"

#include <crisp/font.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace crisp {
namespace {

// The unit B3 kernel's CDF by numeric integration: P(U1 + U2 + U3 - 3/2 <= z) for uniform U's,
// the inner integral exact (the third box's own CDF), the outer two by the midpoint rule.
double numeric_b3_cdf(double z) {
    constexpr int kSteps = 600;
    double sum = 0.0;
    for (int i = 0; i < kSteps; ++i) {
        for (int j = 0; j < kSteps; ++j) {
            const double u = (i + 0.5) / kSteps, v = (j + 0.5) / kSteps;
            sum += std::clamp(z + 1.5 - u - v, 0.0, 1.0);
        }
    }
    return sum / (kSteps * kSteps);
}

// Simpson's rule of `f` over [a, b] in `n` (even) steps.
template <class F>
double simpson(F&& f, double a, double b, int n) {
    const double h = (b - a) / n;
    double sum = f(a) + f(b);
    for (int i = 1; i < n; ++i) sum += f(a + i * h) * (i % 2 == 1 ? 4.0 : 2.0);
    return sum * h / 3.0;
}

TEST(BlurKernel, TheB3CdfIsThreeBoxesConvolved) {
    for (double z = -2.0; z <= 2.0; z += 0.0625) {
        EXPECT_NEAR(blur_b3_cdf(z), numeric_b3_cdf(z), 2e-6) << z;
    }
    EXPECT_DOUBLE_EQ(blur_b3_cdf(0.0), 0.5);
    EXPECT_DOUBLE_EQ(blur_b3_cdf(-1.5), 0.0);
    EXPECT_DOUBLE_EQ(blur_b3_cdf(1.5), 1.0);
}

TEST(BlurKernel, HIsTheIntegralOfTheCdf) {
    EXPECT_DOUBLE_EQ(blur_h(0.0), 0.203125);
    EXPECT_DOUBLE_EQ(blur_h(-1.5), 0.0);
    EXPECT_DOUBLE_EQ(blur_h(-7.0), 0.0);
    EXPECT_DOUBLE_EQ(blur_h(1.5), 1.5);
    EXPECT_DOUBLE_EQ(blur_h(9.25), 9.25);
    double worst = 0.0;
    for (double z = -2.0; z <= 2.0; z += 1.0 / 32.0) {
        // The CDF's pieces meet at -1/2, 1/2 (C2 there): split the integral at them.
        double numeric = 0.0, from = -1.5;
        for (const double to : {-0.5, 0.5, 1.5, 2.0}) {
            const double end = std::min(to, z);
            if (end > from) numeric += simpson([](double s) { return blur_b3_cdf(s); }, from, end, 64);
            from = to;
        }
        worst = std::max(worst, std::abs(blur_h(z) - numeric));
        EXPECT_NEAR(blur_h(z), numeric, 1e-12) << z;
        // The derivative is the CDF.
        const double h = 1e-5;
        EXPECT_NEAR((blur_h(z + h) - blur_h(z - h)) / (2 * h), blur_b3_cdf(z), 1e-8) << z;
    }
    std::printf("[ blur ] H against Simpson: max %.2e\n", worst);
}

TEST(BlurKernel, TheChannelFilterCdfIsTheBoxConvolvedWithTheBlur) {
    // F(t) = (1 / b) integral over the box of the blur's CDF at t - u.
    double worst = 0.0;
    for (const double w : {0.25, 1.0, 4.0}) {
        for (const auto& [x0, x1] : {std::pair{0.0, 1.0}, std::pair{-0.333, 0.0}, std::pair{0.2, 1.533}}) {
            for (double t = x0 - 1.6 * w; t <= x1 + 1.6 * w; t += w / 16.0) {
                double numeric = 0.0;
                // Split at the kernel's knots t - u = {-1.5, -0.5, 0.5, 1.5} w.
                std::vector<double> cuts = {x0, x1};
                for (const double k : {-1.5, -0.5, 0.5, 1.5}) {
                    const double u = t - k * w;
                    if (u > x0 && u < x1) cuts.push_back(u);
                }
                std::sort(cuts.begin(), cuts.end());
                for (size_t i = 0; i + 1 < cuts.size(); ++i) {
                    numeric += simpson([&](double u) { return blur_b3_cdf((t - u) / w); }, cuts[i], cuts[i + 1], 64);
                }
                numeric /= x1 - x0;
                worst = std::max(worst, std::abs(blur_cdf(t, x0, x1, w) - numeric));
                EXPECT_NEAR(blur_cdf(t, x0, x1, w), numeric, 1e-12) << w << " " << x0 << " " << t;
                const double h = 1e-6;
                EXPECT_NEAR((blur_cdf(t + h, x0, x1, w) - blur_cdf(t - h, x0, x1, w)) / (2 * h),
                            blur_density(t, x0, x1, w), 1e-6);
            }
            EXPECT_NEAR(blur_cdf(x0 - 1.5 * w, x0, x1, w), 0.0, 1e-15);
            EXPECT_NEAR(blur_cdf(x1 + 1.5 * w, x0, x1, w), 1.0, 1e-15);
        }
    }
    std::printf("[ blur ] F against Simpson: max %.2e\n", worst);
    // Without blur, the box's own CDF.
    EXPECT_DOUBLE_EQ(blur_cdf(0.25, 0.0, 0.5, 0.0), 0.5);
    EXPECT_DOUBLE_EQ(blur_cdf(-1.0, 0.0, 0.5, 0.0), 0.0);
    EXPECT_DOUBLE_EQ(blur_cdf(3.0, 0.0, 0.5, 0.0), 1.0);
}

TEST(BlurKernel, TheInverseCdfConvergesInItsStepsInDoubleAndFloat) {
    double worst_double = 0.0, worst_float = 0.0;
    for (const double w : {1.0 / 96.0, 1.0, 4.0, 85.0}) {
        for (const auto& [x0, x1] : {std::pair{0.0, 1.0}, std::pair{0.333, 0.667}, std::pair{-0.25, 1.25}}) {
            for (int i = 0; i <= 256; ++i) {
                const double v = i / 256.0;
                const double t = blur_inverse_cdf(v, x0, x1, w);
                EXPECT_GE(t, x0 - 1.5 * w);
                EXPECT_LE(t, x1 + 1.5 * w);
                worst_double = std::max(worst_double, std::abs(blur_cdf(t, x0, x1, w) - v));
                const float tf = blur_inverse_cdf(static_cast<float>(v), static_cast<float>(x0), static_cast<float>(x1),
                                                  static_cast<float>(w));
                worst_float = std::max(worst_float, std::abs(blur_cdf(static_cast<double>(tf), x0, x1, w) - v));
            }
        }
    }
    std::printf("[ blur ] inverse CDF: |F(F^-1(v)) - v| max %.2e in double, %.2e in float\n", worst_double,
                worst_float);
    // In double the deep tails (quartic in t) keep Newton linear: 6e-8 at v = 0 or 1. In float F
    // cancels: (w / b) (H(z0) - H(z1)) loses w / b ulps, 3e-5 at w = 85 (R = 128 px) over b = 1/3.
    EXPECT_LE(worst_double, 1e-7);
    EXPECT_LE(worst_float, 5e-5);
}

TEST(BlurReference, WithoutBlurItIsTheExactAreaAndWithItTheMassIsKept) {
    const std::unique_ptr<Font> font = test::bake_test_font("M@");
    ASSERT_TRUE(font);
    const SubpixelLayout gray = *subpixel_preset("gray");
    const SubpixelLayout rgb = *subpixel_preset("rgb");
    for (const char32_t c : {U'M', U'@'}) {
        const GlyphRecord& glyph = *font->glyph_record(font->nominal_glyph(c));
        const BlurReference reference = BlurReference::of_glyph(font->asset(), glyph);
        const ExactCoverage exact(font->asset(), glyph);
        GlyphKey key = test::key_at(font->nominal_glyph(c), 16, 77, 201);
        const GlyphRect rect = glyph_rect(glyph, key);
        const TexelToEm map = texel_to_em(rect, key);
        const double ox = static_cast<double>(map.offset_x), sx = static_cast<double>(map.scale_x);
        const double oy = static_cast<double>(map.offset_y), sy = static_cast<double>(map.scale_y);
        double worst = 0.0;
        for (uint32_t ty = 0; ty < rect.height; ++ty) {
            for (uint32_t tx = 0; tx < rect.width; ++tx) {
                const std::array<double, 3> got = reference.texel(map, rgb, tx, ty, 0.0, 1e-9);
                for (size_t ch = 0; ch < 3; ++ch) {
                    const SampleRect& r = rgb.channels[ch];
                    const double ex0 = ox + sx * (tx + static_cast<double>(r.x0));
                    const double ex1 = ox + sx * (tx + static_cast<double>(r.x1));
                    const double ey0 = oy + sy * (ty + static_cast<double>(r.y1));
                    const double ey1 = oy + sy * (ty + static_cast<double>(r.y0));
                    worst = std::max(worst, std::abs(got[ch] - exact.coverage(ex0, ey0, ex1, ey1)));
                }
            }
        }
        std::printf("[ blur ] reference without blur vs ExactCoverage, %c 16 px rgb: max %.2e\n", static_cast<char>(c),
                    worst);
        EXPECT_LE(worst, 1e-6);
        // Blurred by R = 3 px (w = 2): the sum over the grown rect is the glyph's area in texels.
        const double area_texels =
            exact.area(glyph.bbox_min_x, glyph.bbox_min_y, glyph.bbox_max_x, glyph.bbox_max_y) / (sx * -sy);
        key.blur = 3 * 64;
        const GlyphRect grown = glyph_rect(glyph, key);
        EXPECT_EQ(grown.width, rect.width + 2 * 4);
        EXPECT_EQ(grown.height, rect.height + 2 * 4);
        const TexelToEm grown_map = texel_to_em(grown, key);
        double sum = 0.0;
        for (uint32_t ty = 0; ty < grown.height; ++ty) {
            for (uint32_t tx = 0; tx < grown.width; ++tx) sum += reference.texel(grown_map, gray, tx, ty, 2.0)[0];
        }
        std::printf("[ blur ] blurred mass %.6f vs area %.6f texels, integration error %.1e\n", sum, area_texels,
                    reference.error());
        EXPECT_NEAR(sum, area_texels, 1e-4 * area_texels);
        EXPECT_LE(reference.error(), 1e-6);
    }
}

TEST(BlurKey, TheBlurIsPartOfTheKey) {
    GlyphKey a = test::key_at(3, 16, 0, 0), b = a;
    b.blur = 96;
    EXPECT_NE(a, b);
    EXPECT_NE(compare_keys(a, b), 0);
    EXPECT_EQ(compare_keys(a, b), -compare_keys(b, a));
    EXPECT_NE(GlyphKeyHash{}(a), GlyphKeyHash{}(b));
    EXPECT_EQ(blur_reach(a), 0);
    EXPECT_EQ(blur_reach(b), 3);  // ceil(1.5 + 1)
}

}  // namespace
}  // namespace crisp
