// Transformed text (docs/transforms.md) on lavapipe with validation on: each texel channel of a
// rotated, scaled, sheared, mirrored or projected glyph against the exact area of its transformed
// outline (support/transform_reference).
#include "headless_context.hpp"
#include "test_support.hpp"
#include "transform_reference.hpp"

#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

namespace crisp {
namespace {

HeadlessContext* context() {
    static test::GpuFixture fixture = test::make_gpu_fixture({}, false, "");
    return fixture.context.get();
}

#define REQUIRE_GPU() \
    if (!context()) GTEST_FAIL() << "no Vulkan device (lavapipe is installed by scripts/setup.sh)"

struct Error {
    double mean = 0.0;
    double max = 0.0;
    uint64_t channels = 0;
    uint32_t drawn = 0;
};

std::vector<GlyphInstance> lay_out(const Font& font, std::string_view text, float size, float x, float y) {
    const Font* fonts[] = {&font};
    TextStyle style;
    style.size = size;
    LayoutOptions options;
    options.origin_x = x;
    options.origin_y = y;
    auto layout = layout_text(fonts, text, style, options);
    EXPECT_TRUE(layout);
    return layout ? layout->glyphs : std::vector<GlyphInstance>{};
}

// Draws `glyphs` with `options` until every glyph holds `samples`, then measures each drawn
// glyph's texel channels against the exact transformed area.
Error render_and_measure(const Font& font, std::span<const GlyphInstance> glyphs, const DrawOptions& options,
                         uint32_t samples, const SubpixelLayout& layout = *subpixel_preset("rgb")) {
    HeadlessContext& ctx = *context();
    RendererCreateInfo info = renderer_create_info(ctx);
    constexpr uint32_t kAtlas = 512;
    info.atlas.width = info.atlas.height = kAtlas;
    info.atlas.max_samples = samples;
    info.atlas.frame_budget = uint64_t{1} << 40;
    info.layout = layout;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << renderer.error().message;
    if (!renderer) return {};
    EXPECT_TRUE(renderer->add_font(font));
    const Result<uint32_t> frames =
        test::render_until_converged(ctx, *renderer, 2000, [&] { renderer->draw(glyphs, options); });
    EXPECT_TRUE(frames) << frames.error().message;
    Result<std::vector<test::Texel>> read = test::read_atlas(ctx, *renderer);
    EXPECT_TRUE(read) << read.error().message;
    if (!read) return {};
    Error result;
    double sum = 0.0;
    for (const DrawnGlyph& d : renderer->drawn()) {
        ++result.drawn;
        const GlyphRecord& glyph = font.asset().glyphs[d.instance.key.glyph];
        const TransformedCoverage exact(font.asset(), glyph, d.instance.key);
        for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                const test::Texel& t = (*read)[size_t{d.atlas_y + ty} * kAtlas + d.atlas_x + tx];
                EXPECT_EQ(t.count, samples);
                const uint16_t sums[3] = {t.r, t.g, t.b};
                const std::array<double, 3> truth = exact.texel(layout, tx + d.part_x, ty + d.part_y);
                for (size_t c = 0; c < 3; ++c) {
                    const double got = static_cast<double>(sums[c]) / (kCoverageOne * std::max<uint32_t>(t.count, 1));
                    if (truth[c] == 0.0 && got == 0.0) continue;
                    const double e = std::fabs(got - truth[c]);
                    sum += e;
                    result.max = std::max(result.max, e);
                    ++result.channels;
                }
            }
        }
    }
    if (result.channels > 0) result.mean = sum / static_cast<double>(result.channels);
    const ValidationMessages messages = ctx.validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    return result;
}

TextTransform rotation(double degrees, double scale, float pivot_x, float pivot_y) {
    const double t = degrees * std::numbers::pi / 180.0;
    const auto c = static_cast<float>(std::cos(t) * scale), s = static_cast<float>(std::sin(t) * scale);
    return {c, -s, s, c, pivot_x, pivot_y};
}

TEST(Transform, RotatedTextConvergesToTheExactTransformedArea) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Ag");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Ag", 14.0f, 20.0f, 30.0f);
    for (double degrees : {0.0, 90.0, 37.0}) {
        DrawOptions options;
        options.transform = rotation(degrees, 1.0, 20.0f, 30.0f);
        const Error e = render_and_measure(*font, glyphs, options, 64);
        std::printf("[ transform ] %.0f degrees: mean %.5f, max %.5f over %llu channels\n", degrees, e.mean, e.max,
                    static_cast<unsigned long long>(e.channels));
        EXPECT_EQ(e.drawn, glyphs.size());
        EXPECT_LE(e.mean, 0.002);
    }
}

}  // namespace
}  // namespace crisp
