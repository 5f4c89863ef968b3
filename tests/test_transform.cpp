// Transformed text (docs/transforms.md) on lavapipe with validation on: each texel channel of a
// rotated, scaled, sheared, mirrored or projected glyph against the exact area of its transformed
// outline (support/transform_reference).
//
// lavapipe is slow: glyphs are small and few, most cases take 64 samples (bounds measured with
// margin, printed as "[ transform ]" lines) and a few converge to 512, held to the targets of
// issue 25 (mean 0.001, worst texel 1/128).
#include "headless_context.hpp"
#include "plane_support.hpp"
#include "shape_support.hpp"
#include "test_support.hpp"
#include "transform_reference.hpp"

#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <set>

namespace crisp {
namespace {

HeadlessContext* context() {
    static test::GpuFixture fixture = test::make_gpu_fixture({}, false, "");
    return fixture.context.get();
}

#define REQUIRE_GPU() \
    if (!context()) GTEST_FAIL() << "no Vulkan device (lavapipe is installed by scripts/setup.sh)"

// The targets of issue 25 for converged text.
constexpr double kConvergedMean = 0.001;
constexpr double kConvergedMax = 1.0 / 128.0;

struct Error {
    double mean = 0.0;
    double max = 0.0;
    uint64_t channels = 0;
    uint32_t drawn = 0;
    bool in_range = true;      // every coverage within [0, 1]
    uint32_t transformed = 0;  // drawn glyphs whose key carries a linear part
    uint32_t projective = 0;   // and a perspective
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

constexpr uint32_t kAtlas = 512;

// A renderer for the tests: `samples` per glyph, an unbounded frame budget.
std::unique_ptr<Renderer> make_renderer(const Font& font, uint32_t samples, const SubpixelLayout& layout) {
    RendererCreateInfo info = renderer_create_info(*context());
    info.atlas.width = info.atlas.height = kAtlas;
    info.atlas.max_samples = samples;
    info.atlas.frame_budget = uint64_t{1} << 40;
    info.layout = layout;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << renderer.error().message;
    if (!renderer) return nullptr;
    EXPECT_TRUE(renderer->add_font(font));
    return std::make_unique<Renderer>(std::move(*renderer));
}

// A GPU texel channel's coverage.
double coverage_of(const test::Texel& t, size_t channel) {
    const uint16_t sums[3] = {t.r, t.g, t.b};
    return static_cast<double>(sums[channel]) / (kCoverageOne * std::max<uint32_t>(t.count, 1));
}

// Each drawn glyph's texel channels against the exact transformed area of its own key.
Error measure(const Font& font, const Renderer& renderer, const std::vector<test::Texel>& texels, uint32_t samples,
              const SubpixelLayout& layout) {
    Error result;
    double sum = 0.0;
    for (const DrawnGlyph& d : renderer.drawn()) {
        ++result.drawn;
        const GlyphKey& key = d.instance.key;
        if (is_transformed(key)) ++result.transformed;
        if (key.perspective[0] != 0 || key.perspective[1] != 0) ++result.projective;
        const GlyphRecord& glyph = font.asset().glyphs[d.instance.key.glyph];
        const TransformedCoverage exact(font.asset(), glyph, d.instance.key);
        for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                const test::Texel& t = texels[size_t{d.atlas_y + ty} * kAtlas + d.atlas_x + tx];
                EXPECT_EQ(t.count, samples);
                const std::array<double, 3> truth = exact.texel(layout, tx + d.part_x, ty + d.part_y);
                for (size_t c = 0; c < 3; ++c) {
                    const double got = coverage_of(t, c);
                    if (!(got >= 0.0 && got <= 1.0)) result.in_range = false;
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
    return result;
}

void expect_no_validation_messages() {
    const ValidationMessages messages = context()->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
}

// Draws `glyphs` with `options` until every glyph holds `samples`, then measures each drawn
// glyph's texel channels against the exact transformed area.
Error render_and_measure(const Font& font, std::span<const GlyphInstance> glyphs, const DrawOptions& options,
                         uint32_t samples, const SubpixelLayout& layout = *subpixel_preset("rgb")) {
    HeadlessContext& ctx = *context();
    std::unique_ptr<Renderer> renderer = make_renderer(font, samples, layout);
    if (!renderer) return {};
    const Result<uint32_t> frames =
        test::render_until_converged(ctx, *renderer, 2000, [&] { renderer->draw(glyphs, options); });
    EXPECT_TRUE(frames) << frames.error().message;
    Result<std::vector<test::Texel>> read = test::read_atlas(ctx, *renderer);
    EXPECT_TRUE(read) << read.error().message;
    if (!read) return {};
    const Error result = measure(font, *renderer, *read, samples, layout);
    expect_no_validation_messages();
    return result;
}

// At 64 samples, a rotated glyph's error is its first frames' (rows in y): these bounds are
// those measured on lavapipe with margin.
// Measured: mean at most 0.0011, worst texel 0.0088 (Ag at 180 degrees).
constexpr double kMean64 = 0.002;
constexpr double kMax64 = 0.02;

void report(const std::string& what, uint32_t samples, const Error& e) {
    std::printf("[ transform ] %s, %u samples: mean %.5f, max %.5f over %llu channels\n", what.c_str(), samples, e.mean,
                e.max, static_cast<unsigned long long>(e.channels));
}

// Reports `e` and holds it to the bounds of its sample count: the targets at 512 samples, the
// measured bounds at 64. Overlapping contours never sum above 1.
void expect_within_bounds(const std::string& what, uint32_t samples, const Error& e) {
    report(what, samples, e);
    const bool converged = samples >= 512;
    EXPECT_TRUE(e.in_range) << what;
    EXPECT_LE(e.mean, converged ? kConvergedMean : kMean64) << what;
    EXPECT_LE(e.max, converged ? kConvergedMax : kMax64) << what;
}

// render_and_measure(), then expect_within_bounds() at its sample count, with every glyph drawn.
Error measure_within_bounds(const std::string& what, const Font& font, std::span<const GlyphInstance> glyphs,
                            const DrawOptions& options, uint32_t samples,
                            const SubpixelLayout& layout = *subpixel_preset("rgb")) {
    const Error e = render_and_measure(font, glyphs, options, samples, layout);
    expect_within_bounds(what, samples, e);
    EXPECT_EQ(e.drawn, glyphs.size()) << what;
    return e;
}

TextTransform rotation(double degrees, double scale, float pivot_x, float pivot_y) {
    const double t = degrees * std::numbers::pi / 180.0;
    const auto c = static_cast<float>(std::cos(t) * scale), s = static_cast<float>(std::sin(t) * scale);
    return {c, -s, s, c, pivot_x, pivot_y};
}

DrawOptions transformed(const TextTransform& transform) {
    DrawOptions options;
    options.transform = transform;
    return options;
}

TEST(Transform, RotatedTextConvergesToTheExactTransformedArea) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Ag");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Ag", 14.0f, 20.0f, 30.0f);
    for (double degrees : {0.0, 90.0, 37.0, 180.0, 271.3, 13.7, -151.2, 0.4}) {
        DrawOptions options;
        options.transform = rotation(degrees, 1.0, 20.0f, 30.0f);
        const Error e = render_and_measure(*font, glyphs, options, 64);
        char what[64];
        std::snprintf(what, sizeof what, "Ag 14 px rgb, %.1f degrees", degrees);
        expect_within_bounds(what, 64, e);
        EXPECT_EQ(e.drawn, glyphs.size());
        EXPECT_LE(e.mean, 0.002);
    }
}

TEST(Transform, ConvergedRotationsMeetTheTargets) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("g");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "g", 14.0f, 20.3f, 30.6f);
    for (double degrees : {37.0, 271.3}) {
        measure_within_bounds("g 14 px rgb, " + std::to_string(degrees) + " degrees", *font, glyphs,
                              transformed(rotation(degrees, 1.0, 20.0f, 30.0f)), 512);
    }
}

TEST(Transform, MirroredAndShearedText) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Rg");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Rg", 14.0f, 20.0f, 30.0f);
    const struct {
        const char* what;
        TextTransform t;
    } cases[] = {
        {"mirrored x (-1, 0, 0, 1)", {-1.0f, 0.0f, 0.0f, 1.0f, 20.0f, 30.0f}},
        {"mirrored y (1, 0, 0, -1)", {1.0f, 0.0f, 0.0f, -1.0f, 20.0f, 30.0f}},
        {"shear x 0.5", {1.0f, 0.5f, 0.0f, 1.0f, 20.0f, 30.0f}},
        {"shear x -0.5", {1.0f, -0.5f, 0.0f, 1.0f, 20.0f, 30.0f}},
        {"shear y 0.5", {1.0f, 0.0f, 0.5f, 1.0f, 20.0f, 30.0f}},
        {"shear y -0.5, mirrored", {-1.0f, 0.0f, -0.5f, 1.0f, 20.0f, 30.0f}},
    };
    for (const auto& c : cases) {
        ASSERT_TRUE(valid_transform(c.t)) << c.what;
        measure_within_bounds(std::string("Rg 14 px rgb, ") + c.what, *font, glyphs, transformed(c.t), 64);
    }
    // Converged: the shear at its limit.
    const std::vector<GlyphInstance> one = lay_out(*font, "R", 14.0f, 20.0f, 30.0f);
    measure_within_bounds("R 14 px rgb, shear x 0.5", *font, one, transformed({1.0f, 0.5f, 0.0f, 1.0f, 20.0f, 30.0f}),
                          512);
}

TEST(Transform, TinyAndLargeScales) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("ag");
    ASSERT_TRUE(font);
    // 0.25x of 16 px: 4 px glyphs, converged.
    const std::vector<GlyphInstance> small = lay_out(*font, "ag", 16.0f, 20.0f, 30.0f);
    measure_within_bounds("ag 16 px x 0.25 rgb, 23 degrees", *font, small,
                          transformed(rotation(23.0, 0.25, 20.0f, 30.0f)), 512);
    // 8x of 12 px: a 96 px glyph, about 100 x 100 texels.
    const std::vector<GlyphInstance> large = lay_out(*font, "a", 12.0f, 20.0f, 30.0f);
    const Error big = measure_within_bounds("a 12 px x 8 rgb, -31 degrees", *font, large,
                                            transformed(rotation(-31.0, 8.0, 20.0f, 30.0f)), 64);
    EXPECT_GT(big.channels, 3000u);
}

TEST(Transform, ALargeRotatedGlyphSeenInPartIsExactThere) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("a");
    ASSERT_TRUE(font);
    // 12 px x 40: a 480 px glyph, rotated; only a 40 x 40 window of the target can be seen, so
    // the atlas holds that part with its margin, at texel offsets part_x, part_y of the rect.
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "a", 12.0f, 100.0f, 300.0f);
    DrawOptions options = transformed(rotation(30.0, 40.0, 100.0f, 300.0f));
    options.visible = VkRect2D{{270, 220}, {40, 40}};  // about the glyph's centre
    const Error e = measure_within_bounds("a 12 px x 40 rgb, 30 degrees, a 40 x 40 part", *font, glyphs, options, 64);
    EXPECT_GT(e.channels, 1000u);
    EXPECT_LT(e.channels, 3u * 40 * 40 + 1);  // only the visible texels are reported
}

TEST(Transform, TransformsAtTheirLimitsAreRefusedOrDrawnNeverACrash) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Ag");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Ag", 14.0f, 20.0f, 30.0f);
    std::unique_ptr<Renderer> renderer = make_renderer(*font, 8, *subpixel_preset("rgb"));
    ASSERT_TRUE(renderer);
    // 65536 x 14 px: glyphs about a million pixels wide, larger than any atlas.
    for (const TextTransform& t :
         {rotation(33.0, 65536.0, 20.0f, 30.0f), TextTransform{65536.0f, 0.0f, 0.0f, 65536.0f, 0.0f, 0.0f}}) {
        ASSERT_TRUE(valid_transform(t));
        ASSERT_TRUE(
            test::render_until_converged(*context(), *renderer, 1, [&] { renderer->draw(glyphs, transformed(t)); }));
        const RendererStats& stats = renderer->stats();
        EXPECT_TRUE(renderer->drawn().empty());
        EXPECT_EQ(stats.failed_glyphs + stats.culled_glyphs, 2u);
    }
    // The smallest determinant valid_transform() takes: glyphs smaller than a texel, drawn.
    ASSERT_TRUE(test::render_until_converged(*context(), *renderer, 1, [&] {
        renderer->draw(glyphs, transformed({1.0f / 256, 0.0f, 0.0f, 1.0f / 256, 20.0f, 30.0f}));
    }));
    EXPECT_EQ(renderer->stats().drawn_glyphs, 2u);
    expect_no_validation_messages();
}

TEST(Transform, GrayRgbAndVerticalLayouts) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("g");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "g", 14.0f, 20.0f, 30.0f);
    for (const char* name : {"gray", "rgb", "vrgb"}) {
        const SubpixelLayout& layout = *subpixel_preset(name);
        measure_within_bounds(std::string("g 14 px ") + name + ", 37 degrees", *font, glyphs,
                              transformed(rotation(37.0, 1.0, 20.0f, 30.0f)), 64, layout);
    }
    measure_within_bounds("g 14 px vrgb, 123 degrees", *font, glyphs, transformed(rotation(123.0, 1.0, 20.0f, 30.0f)),
                          512, *subpixel_preset("vrgb"));
}

// A hand-made shape at 20 px, rotated by 37 degrees about its pen, on gray and vrgb, at 64 samples.
void expect_rotated_shape_accurate(const char* what, const std::vector<Contour>& contours) {
    uint32_t glyph = 0;
    auto font = test::with_shape(contours, glyph);
    ASSERT_TRUE(font) << what;
    const GlyphInstance instance = test::place(*font, glyph, 20.0f, 20.25f, 30.0f);
    for (const char* layout : {"gray", "vrgb"}) {
        const Error e = measure_within_bounds(std::string(what) + ", 20 px " + layout + ", 37 degrees", *font,
                                              std::span(&instance, 1), transformed(rotation(37.0, 1.0, 20.0f, 30.0f)),
                                              64, *subpixel_preset(layout));
        EXPECT_EQ(e.drawn, 1u) << what;  // overlapping contours never above 1
    }
}

TEST(TransformHardCase, OverlappingHolesSelfIntersectingAndHairlinesRotated) {
    REQUIRE_GPU();
    using test::circle;
    using test::polygon;
    expect_rotated_shape_accurate("overlapping squares", {polygon({{0, 0}, {0.6, 0}, {0.6, 0.6}, {0, 0.6}}),
                                                          polygon({{0.3, 0.3}, {0.9, 0.3}, {0.9, 0.9}, {0.3, 0.9}})});
    expect_rotated_shape_accurate("ring", {circle(0.5, 0.5, 0.45, false), circle(0.5, 0.5, 0.25, true)});
    expect_rotated_shape_accurate("pentagram",
                                  {polygon({{0.5, 0.95}, {0.79, 0.05}, {0.02, 0.61}, {0.98, 0.61}, {0.21, 0.05}})});
    expect_rotated_shape_accurate("hairlines", {polygon({{0.1, 0}, {0.105, 0}, {0.105, 0.9}, {0.1, 0.9}}),
                                                polygon({{0, 0.4}, {0.8, 0.4}, {0.8, 0.405}, {0, 0.405}})});
}

TEST(TransformHardCase, RowsWithMoreCrossingsThanTheRegistersHoldRotated) {
    REQUIRE_GPU();
    // The comb of test_accuracy.cpp: rotated by 37 degrees, a texel row crosses its teeth
    // obliquely, still about 20 edges a row.
    std::vector<Contour> comb;
    for (int i = 0; i < 24; ++i) {
        const double x = 0.3 + 0.004 * i;
        comb.push_back(test::polygon({{x, 0.1}, {x + 0.002, 0.1}, {x + 0.002, 0.8}, {x, 0.8}}));
        comb.push_back(test::polygon({{x + 0.001, 0.3}, {x + 0.003, 0.3}, {x + 0.003, 0.9}, {x + 0.001, 0.9}}));
    }
    expect_rotated_shape_accurate("comb", comb);
    // many-curves.ttf's 'H': 1,000 squares 0.3 px wide at 24 px, 64 crossings a row, 4,000 curves.
    auto font = test::bake_subset(CRISP_MANY_CURVES_FONT, "H");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "H", 24.0f, 20.0f, 30.0f);
    ASSERT_EQ(glyphs.size(), 1u);
    EXPECT_GE(font->asset().glyphs[glyphs[0].key.glyph].curve_count, 4000u);
    measure_within_bounds("many-curves.ttf H (4,000 curves) 24 px gray, 37 degrees", *font, glyphs,
                          transformed(rotation(37.0, 1.0, 20.0f, 30.0f)), 64, *subpixel_preset("gray"));
}

TEST(TransformHardCase, CjkGlyphAndFourPixelsRotated) {
    REQUIRE_GPU();
    auto e = test::bake_test_font("e");
    ASSERT_TRUE(e);
    const std::vector<GlyphInstance> tiny = lay_out(*e, "e", 4.0f, 20.6f, 30.3f);
    measure_within_bounds("e 4 px rgb, 57 degrees", *e, tiny, transformed(rotation(57.0, 1.0, 20.0f, 30.0f)), 512);
    if (!std::filesystem::exists(test::kNotoCjk)) GTEST_SKIP() << test::kNotoCjk << " is missing";
    auto cjk = test::bake_subset(test::kNotoCjk, "龘");
    ASSERT_TRUE(cjk);
    const std::vector<GlyphInstance> glyphs = lay_out(*cjk, "龘", 16.0f, 20.0f, 30.0f);
    ASSERT_EQ(glyphs.size(), 1u);
    EXPECT_GT(cjk->asset().glyphs[glyphs[0].key.glyph].curve_count, 200u);
    measure_within_bounds("Noto Sans CJK 龘 16 px gray, -21 degrees", *cjk, glyphs,
                          transformed(rotation(-21.0, 1.0, 20.0f, 30.0f)), 64, *subpixel_preset("gray"));
}

// Text "Ag" at 14 px laid out at layout pixels (0, 0) on a plane seen through a camera.
struct PlaneScene {
    std::unique_ptr<Font> font = test::bake_test_font("Ag");
    std::vector<GlyphInstance> glyphs = font ? lay_out(*font, "Ag", 14.0f, 0.0f, 0.0f) : std::vector<GlyphInstance>{};
};

DrawOptions on_plane(const TextPlane& plane) {
    DrawOptions options;
    options.plane = plane;
    return options;
}

// Each drawn glyph's depth is the NDC z of its bbox centre's world point on `plane`.
void expect_depths_of_centres(const Font& font, std::span<const GlyphInstance> glyphs, const Renderer& renderer,
                              const TextPlane& plane) {
    ASSERT_EQ(renderer.drawn().size(), glyphs.size());
    for (size_t i = 0; i < glyphs.size(); ++i) {
        const GlyphInstance& laid = glyphs[i];
        const GlyphRecord& g = font.asset().glyphs[laid.key.glyph];
        const double size = laid.key.size_x / static_cast<double>(kSizeOne);
        const std::array<double, 4> box = test::bbox_of(g);
        const double cx = 0.5 * (box[0] + box[2]), cy = 0.5 * (box[1] + box[3]);
        const test::Vec3 c = test::plane_point(plane, static_cast<double>(laid.pen_x) + size * cx,
                                               static_cast<double>(laid.pen_y) - size * cy);
        const float world[3] = {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
        const std::optional<float> depth = depth_from_view_projection(plane.view_projection.data(), world);
        ASSERT_TRUE(depth) << i;
        EXPECT_NEAR(renderer.drawn()[i].instance.depth, *depth, 1e-6) << i;
    }
}

// A plane a little tilted, seen from 6 world units: each glyph's local affine is within
// kMaxLocalAffineError of the projection.
TextPlane tilted_plane() {
    return test::plane_seen_from({0.42, 0.1, 6.0}, {0.36, 0.15, 0.0}, 0.04f, 200.0f, 150.0f);
}
// The same plane seen at a grazing angle from nearby: no glyph's local affine is close enough.
TextPlane grazing_plane() {
    return test::plane_seen_from({0.36, -1.5, 0.6}, {0.36, 0.15, 0.0}, 0.04f, 200.0f, 150.0f);
}

TEST(TransformPlane, LocalAffineGlyphsAgainstTheirKeyAndTheExactProjection) {
    REQUIRE_GPU();
    const PlaneScene scene;
    ASSERT_TRUE(scene.font);
    const Font& font = *scene.font;
    const TextPlane plane = tilted_plane();
    const SubpixelLayout& layout = *subpixel_preset("gray");
    std::unique_ptr<Renderer> renderer = make_renderer(font, 64, layout);
    ASSERT_TRUE(renderer);
    const DrawOptions options = on_plane(plane);
    ASSERT_TRUE(
        test::render_until_converged(*context(), *renderer, 2000, [&] { renderer->draw(scene.glyphs, options); }));
    Result<std::vector<test::Texel>> texels = test::read_atlas(*context(), *renderer);
    ASSERT_TRUE(texels);
    const Error own = measure(font, *renderer, *texels, 64, layout);
    expect_within_bounds("Ag 14 px gray on a tilted plane, local affine, against its key", 64, own);
    EXPECT_EQ(own.drawn, 2u);
    EXPECT_EQ(own.transformed, 2u);
    EXPECT_EQ(own.projective, 0u);
    expect_depths_of_centres(font, scene.glyphs, *renderer, plane);

    // Against the exact projective coverage of the plane: a perspective key made by hand from
    // the exact placement. The local affine moves the outline by at most kMaxLocalAffineError;
    // a texel's channel crossed by at most 4 px of outline changes by at most 4 times that.
    const double allowed = 4.0 * kMaxLocalAffineError;
    double worst_reference = 0.0, worst_gpu = 0.0, sum_gpu = 0.0;
    uint64_t channels = 0;
    for (size_t i = 0; i < scene.glyphs.size(); ++i) {
        const DrawnGlyph& d = renderer->drawn()[i];
        const GlyphInstance& laid = scene.glyphs[i];
        const GlyphRecord& g = font.asset().glyphs[laid.key.glyph];
        const double size = laid.key.size_x / static_cast<double>(kSizeOne);
        const PlanePlacement affine = place_on_plane(plane, g, laid.pen_x, laid.pen_y, size, size);
        ASSERT_FALSE(affine.projective);
        std::printf("[ transform ] glyph %zu: local-affine error %.5f px\n", i, affine.affine_error);
        GlyphInstance exact = laid;
        exact.key.subpixel_x = exact.key.subpixel_y = 0;
        ASSERT_TRUE(place_glyph(g, test::exact_placement(plane, laid.pen_x, laid.pen_y, size, size),
                                kStillTransformSteps, exact));
        ASSERT_NE(exact.key.perspective[0] | exact.key.perspective[1], 0);
        const TransformedCoverage projective(font.asset(), g, exact.key);
        const TransformedCoverage local(font.asset(), g, d.instance.key);
        for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                const test::Texel& t = (*texels)[size_t{d.atlas_y + ty} * kAtlas + d.atlas_x + tx];
                const double ex = d.instance.x + static_cast<int32_t>(tx) - exact.x;
                const double ey = d.instance.y + static_cast<int32_t>(ty) - exact.y;
                const std::array<double, 3> mine = local.texel(layout, tx, ty);
                for (size_t c = 0; c < 3; ++c) {
                    const SampleRect& r = layout.channels[c];
                    const double truth =
                        projective.coverage(ex + static_cast<double>(r.x0), ey + static_cast<double>(r.y0),
                                            ex + static_cast<double>(r.x1), ey + static_cast<double>(r.y1));
                    const double got = coverage_of(t, c);
                    if (truth == 0.0 && got == 0.0) continue;
                    worst_reference = std::max(worst_reference, std::fabs(mine[c] - truth));
                    worst_gpu = std::max(worst_gpu, std::fabs(got - truth));
                    sum_gpu += std::fabs(got - truth);
                    ++channels;
                }
            }
        }
    }
    std::printf(
        "[ transform ] local affine against the exact projection: references differ by at most %.5f "
        "(allowed %.5f); GPU mean %.5f, max %.5f over %llu channels\n",
        worst_reference, allowed, sum_gpu / static_cast<double>(std::max<uint64_t>(channels, 1)), worst_gpu,
        static_cast<unsigned long long>(channels));
    EXPECT_GT(channels, 100u);
    EXPECT_LE(worst_reference, allowed);
    EXPECT_LE(worst_gpu, own.max + allowed);
    EXPECT_LE(sum_gpu / static_cast<double>(std::max<uint64_t>(channels, 1)), own.mean + kMaxLocalAffineError);
    expect_no_validation_messages();
}

TEST(TransformPlane, GrazingGlyphsAreProjectiveAndMatchTheExactProjection) {
    REQUIRE_GPU();
    const PlaneScene scene;
    ASSERT_TRUE(scene.font);
    const TextPlane plane = grazing_plane();
    std::unique_ptr<Renderer> renderer = make_renderer(*scene.font, 64, *subpixel_preset("rgb"));
    ASSERT_TRUE(renderer);
    const DrawOptions options = on_plane(plane);
    ASSERT_TRUE(
        test::render_until_converged(*context(), *renderer, 2000, [&] { renderer->draw(scene.glyphs, options); }));
    Result<std::vector<test::Texel>> texels = test::read_atlas(*context(), *renderer);
    ASSERT_TRUE(texels);
    const Error e = measure(*scene.font, *renderer, *texels, 64, *subpixel_preset("rgb"));
    expect_within_bounds("Ag 14 px rgb on a plane at a grazing angle, projective", 64, e);
    EXPECT_EQ(e.drawn, 2u);
    EXPECT_EQ(e.projective, 2u);
    expect_depths_of_centres(*scene.font, scene.glyphs, *renderer, plane);
    expect_no_validation_messages();
    // Converged, under perspective: the targets of still text.
    const Error converged = measure_within_bounds("Ag 14 px rgb on a plane at a grazing angle, projective", *scene.font,
                                                  scene.glyphs, options, 512);
    EXPECT_EQ(converged.projective, 2u);
}

TEST(TransformPlane, GlyphsBehindTheEyeAreCulled) {
    REQUIRE_GPU();
    const PlaneScene scene;
    ASSERT_TRUE(scene.font);
    std::unique_ptr<Renderer> renderer = make_renderer(*scene.font, 8, *subpixel_preset("rgb"));
    ASSERT_TRUE(renderer);
    // Looking away from the text.
    const DrawOptions away = on_plane(test::plane_seen_from({0.4, 0.2, 6.0}, {0.4, 0.2, 12.0}, 0.04f, 200.0f, 150.0f));
    ASSERT_TRUE(test::render_until_converged(*context(), *renderer, 1, [&] { renderer->draw(scene.glyphs, away); }));
    EXPECT_EQ(renderer->stats().culled_glyphs, 2u);
    EXPECT_EQ(renderer->stats().skipped_glyphs, 0u);
    EXPECT_TRUE(renderer->drawn().empty());
    // The eye just above the text at the middle of 'A', looking along the line: 'A' reaches behind
    // it, 'g' lies ahead.
    std::vector<GlyphInstance> line = scene.glyphs;
    const double gap = 0.5 * static_cast<double>(line[0].pen_x + line[1].pen_x) * 0.04;
    const DrawOptions along =
        on_plane(test::plane_seen_from({gap, 0.2, 0.5}, {gap + 10.0, 0.2, 0.0}, 0.04f, 200.0f, 150.0f));
    ASSERT_TRUE(test::render_until_converged(*context(), *renderer, 1, [&] { renderer->draw(line, along); }));
    EXPECT_EQ(renderer->stats().culled_glyphs, 1u);
    ASSERT_EQ(renderer->drawn().size(), 1u);
    EXPECT_EQ(renderer->drawn()[0].instance.key.glyph, line[1].key.glyph);
    expect_no_validation_messages();
}

// Keys of the glyphs drawn this frame.
std::vector<GlyphKey> drawn_keys(const Renderer& renderer) {
    std::vector<GlyphKey> keys;
    for (const DrawnGlyph& d : renderer.drawn()) keys.push_back(d.instance.key);
    return keys;
}

TEST(TransformKeys, StillTextReusesItsEntriesAndMovingTextTakesCoarseKeys) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Ag");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Ag", 14.0f, 20.3f, 30.6f);
    std::unique_ptr<Renderer> renderer = make_renderer(*font, 64, *subpixel_preset("rgb"));
    ASSERT_TRUE(renderer);
    HeadlessContext& ctx = *context();

    // Still: the same transform every frame converges in two entries.
    DrawOptions still = transformed(rotation(37.0, 1.0, 20.0f, 30.0f));
    still.id = 7;
    const Result<uint32_t> frames =
        test::render_until_converged(ctx, *renderer, 200, [&] { renderer->draw(glyphs, still); });
    ASSERT_TRUE(frames);
    EXPECT_TRUE(renderer->converged());
    EXPECT_GT(*frames, 4u);
    const AtlasCounters settled = renderer->atlas().stats().total;
    std::printf("[ transform ] still rotated text: %u frames, %llu allocations, %llu hits\n", *frames,
                static_cast<unsigned long long>(settled.allocations), static_cast<unsigned long long>(settled.hits));
    EXPECT_EQ(settled.allocations, 2u);
    EXPECT_GE(settled.hits, 2u * (*frames - 1));
    for (const DrawnGlyph& d : renderer->drawn()) EXPECT_EQ(d.samples, 64u);
    EXPECT_EQ(renderer->stats().moving_glyphs, 0u);
    const std::vector<GlyphKey> fine = drawn_keys(*renderer);
    ASSERT_EQ(fine.size(), 2u);

    // Moving: a new rotation every frame, 0.05 degrees apart.
    constexpr uint32_t kSweep = 40;
    DrawOptions moving = still;
    for (uint32_t frame = 1; frame <= kSweep; ++frame) {
        moving.transform = rotation(37.0 + 0.05 * frame, 1.0, 20.0f, 30.0f);
        ASSERT_TRUE(test::render_until_converged(ctx, *renderer, 1, [&] { renderer->draw(glyphs, moving); }));
        EXPECT_EQ(renderer->stats().moving_glyphs, 2u) << frame;
        for (const GlyphKey& key : drawn_keys(*renderer)) {
            ASSERT_TRUE(is_transformed(key));
            for (int i = 0; i < 4; ++i) EXPECT_EQ(key.linear[i] % 64, 0) << frame;
            EXPECT_EQ(key.subpixel_x % (kSubpixelSteps / kMovingSubpixelSteps), 0);
            EXPECT_EQ(key.subpixel_y % (kSubpixelSteps / kMovingSubpixelSteps), 0);
        }
    }
    const uint64_t swept = renderer->atlas().stats().total.allocations - settled.allocations;
    std::printf("[ transform ] %u frames of moving rotated text (2 glyphs): %llu allocations\n", kSweep,
                static_cast<unsigned long long>(swept));
    EXPECT_LE(swept, kSweep * 2 / 4);

    // The same sweep drawn without an id takes fine keys: nearly a new entry per glyph and frame.
    std::unique_ptr<Renderer> unnamed = make_renderer(*font, 64, *subpixel_preset("rgb"));
    ASSERT_TRUE(unnamed);
    DrawOptions anonymous = still;
    anonymous.id = 0;
    for (uint32_t frame = 1; frame <= kSweep; ++frame) {
        anonymous.transform = rotation(37.0 + 0.05 * frame, 1.0, 20.0f, 30.0f);
        ASSERT_TRUE(test::render_until_converged(ctx, *unnamed, 1, [&] { unnamed->draw(glyphs, anonymous); }));
        EXPECT_EQ(unnamed->stats().moving_glyphs, 0u);
    }
    const uint64_t fine_sweep = unnamed->atlas().stats().total.allocations;
    std::printf("[ transform ] the same sweep with fine keys: %llu allocations\n",
                static_cast<unsigned long long>(fine_sweep));
    EXPECT_GE(fine_sweep, 4 * swept);

    // At rest: fine keys again once kMotionSettleFrames frames have passed.
    uint32_t rested = 0;
    while (renderer->stats().moving_glyphs != 0 && rested <= kMotionSettleFrames + 1) {
        ASSERT_TRUE(test::render_until_converged(ctx, *renderer, 1, [&] { renderer->draw(glyphs, moving); }));
        ++rested;
    }
    EXPECT_EQ(rested, kMotionSettleFrames);
    EXPECT_EQ(renderer->stats().moving_glyphs, 0u);
    // The fine keys of the last rotation: those a still draw of it takes.
    std::unique_ptr<Renderer> other = make_renderer(*font, 64, *subpixel_preset("rgb"));
    ASSERT_TRUE(other);
    DrawOptions last = moving;
    last.id = 0;
    ASSERT_TRUE(test::render_until_converged(ctx, *other, 1, [&] { other->draw(glyphs, last); }));
    EXPECT_EQ(drawn_keys(*renderer), drawn_keys(*other));
    bool some_fine = false;
    for (const GlyphKey& key : drawn_keys(*renderer)) {
        for (int i = 0; i < 4; ++i) some_fine = some_fine || key.linear[i] % 64 != 0;
    }
    EXPECT_TRUE(some_fine);
    expect_no_validation_messages();
}

TEST(Transform, RefusedTransformsAndPlanesDrawNothing) {
    REQUIRE_GPU();
    auto font = test::bake_test_font("Ag");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "Ag", 14.0f, 20.0f, 30.0f);
    std::unique_ptr<Renderer> renderer = make_renderer(*font, 8, *subpixel_preset("rgb"));
    ASSERT_TRUE(renderer);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::vector<std::pair<const char*, DrawOptions>> refused;
    for (const auto& [what, t] : std::initializer_list<std::pair<const char*, TextTransform>>{
             {"zero", {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f}},
             {"rank 1", {1.0f, 2.0f, 2.0f, 4.0f, 0.0f, 0.0f}},
             {"NaN entry", {nan, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}},
             {"infinite entry", {1.0f, inf, 0.0f, 1.0f, 0.0f, 0.0f}},
             {"infinite pivot", {1.0f, 0.0f, 0.0f, 1.0f, -inf, 0.0f}}})
        refused.emplace_back(what, transformed(t));
    const TextPlane good = tilted_plane();
    TextPlane parallel = good;
    parallel.axis_y = {0.08f, 0.0f, 0.0f};
    TextPlane no_viewport = good;
    no_viewport.viewport[3] = 0.0f;
    TextPlane nan_camera = good;
    nan_camera.view_projection[10] = nan;
    refused.emplace_back("parallel axes", on_plane(parallel));
    refused.emplace_back("zero viewport", on_plane(no_viewport));
    refused.emplace_back("NaN view-projection", on_plane(nan_camera));
    DrawOptions both = on_plane(good);
    both.transform = rotation(10.0, 1.0, 0.0f, 0.0f);
    refused.emplace_back("transform and plane", both);
    // Untransformed text beside each refused draw still draws.
    ASSERT_TRUE(test::render_until_converged(*context(), *renderer, 100, [&] { renderer->draw(glyphs); }));
    for (const auto& [what, options] : refused) {
        ASSERT_TRUE(test::render_until_converged(*context(), *renderer, 1, [&] {
            renderer->draw(glyphs);
            renderer->draw(glyphs, options);
        }));
        EXPECT_EQ(renderer->stats().skipped_glyphs, 2u) << what;
        EXPECT_EQ(renderer->stats().drawn_glyphs, 2u) << what;
        for (const GlyphKey& key : drawn_keys(*renderer)) EXPECT_FALSE(is_transformed(key)) << what;
    }
    expect_no_validation_messages();
}

TEST(Transform, ColourGlyphsDrawRotated) {
    REQUIRE_GPU();
    Result<BakeResult> baked = bake_font_file(CRISP_SOURCE_DIR "/tests/fonts/colour/colrv0.ttf", BakeOptions{});
    ASSERT_TRUE(baked) << baked.error().message;
    Result<Font> font = Font::create(std::move(baked->asset), 1);
    ASSERT_TRUE(font) << font.error().message;
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "\xee\x80\x80\xee\x80\x81", 16.0f, 20.0f, 30.0f);
    ASSERT_GT(glyphs.size(), 2u);  // each colour glyph is two or more layers
    for (const GlyphInstance& g : glyphs) EXPECT_NE(g.colour_glyph, kNoColourGlyph);
    const Error e = measure_within_bounds("colrv0.ttf U+E000 U+E001 16 px rgb, layers, 30 degrees", *font, glyphs,
                                          transformed(rotation(30.0, 1.0, 20.0f, 30.0f)), 64);
    EXPECT_EQ(e.drawn, glyphs.size());
    EXPECT_EQ(e.transformed, glyphs.size());
}

}  // namespace
}  // namespace crisp
