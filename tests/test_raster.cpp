// The GPU rasterizer held to the CPU reference, texel by texel, on lavapipe with validation on.
#include "coverage.hpp"
#include "headless_context.hpp"
#include "shared.h"
#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/device_features.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <cstring>
#include <memory>
#include <tuple>
#include <type_traits>
#include <set>
#include <string>
#include <string_view>

namespace crisp {
namespace {

using Fixture = test::GpuFixture;

Fixture& fixture() {
    static Fixture f = test::make_gpu_fixture({}, false, "Hg@&1");
    return f;
}

using test::Texel;

// Reads the whole atlas back.
std::vector<Texel> read_atlas(const Renderer& renderer) {
    Result<std::vector<Texel>> texels = test::read_atlas(*fixture().context, renderer);
    EXPECT_TRUE(texels) << texels.error().message;
    return texels ? std::move(*texels) : std::vector<Texel>{};
}

// Renders frames of `draw` (which calls the renderer's draw()) until the text converges, at
// most `max_frames`, calling `check` after each frame; returns the atlas texels.
template <typename Draw, typename Check>
std::vector<Texel> render(Renderer& renderer, uint32_t& frames, uint32_t max_frames, Draw&& draw, Check&& check) {
    Result<uint32_t> rendered = test::render_until_converged(*fixture().context, renderer, max_frames, draw, check);
    EXPECT_TRUE(rendered) << rendered.error().message;
    frames = rendered ? *rendered : 0;
    return read_atlas(renderer);
}

// Renders `layout` until it converges and returns the atlas texels.
std::vector<Texel> render(Renderer& renderer, const TextLayout& layout, uint32_t& frames) {
    return render(
        renderer, frames, 1000, [&] { renderer.draw(layout.glyphs); }, [] {});
}

// The float positions the shader computes for sample n of texel (tx, ty), channel c.
void gpu_sample(const TexelToEm& map, const SampleRect& rect, uint32_t tx, uint32_t ty, uint32_t n, float& x,
                float& y) {
    float u = 0.5f + static_cast<float>(n) * gpu::kRasterR2StepX;
    float v = 0.5f + static_cast<float>(n) * gpu::kRasterR2StepY;
    u -= std::floor(u);
    v -= std::floor(v);
    const float px = static_cast<float>(tx) + (rect.x0 + (rect.x1 - rect.x0) * u);
    const float py = static_cast<float>(ty) + (rect.y0 + (rect.y1 - rect.y0) * v);
    x = map.offset_x + map.scale_x * px;
    y = map.offset_y + map.scale_y * py;
}

struct Comparison {
    uint64_t texels = 0;
    uint64_t mismatched = 0;   // sums differ
    uint64_t unexplained = 0;  // ... and no sample of the texel lies near an edge (points) or
                               // rounds differently in double (rows)
    uint64_t covered = 0;      // texel channels with any coverage
    uint64_t row_passes = 0;   // rows: passes over the curves beyond one per sample
};

// A point-sample channel's expected hits: double-precision banded winding at the shader's float
// sample positions. `near_edge` is set when a sample lies within kEdge em of the outline (the
// winding changes within that distance).
uint32_t point_hits(const FontAsset& asset, const GlyphRecord& glyph, const TexelToEm& map, const SampleRect& rect,
                    uint32_t tx, uint32_t ty, uint32_t samples, bool& near_edge) {
    constexpr double kEdge = 2e-5;  // em: 1/50 px at 1000 px per em
    uint32_t hits = 0;
    for (uint32_t n = 0; n < samples; ++n) {
        float x = 0, y = 0;
        gpu_sample(map, rect, tx, ty, n, x, y);
        const double xd = x, yd = y;
        const bool hit = winding_number_banded<double>(asset, glyph, xd, yd) != 0;
        hits += hit;
        for (const auto& [dx, dy] : {std::pair{kEdge, 0.0}, {-kEdge, 0.0}, {0.0, kEdge}, {0.0, -kEdge}}) {
            if ((winding_number_banded<double>(asset, glyph, xd + dx, yd + dy) != 0) != hit) near_edge = true;
        }
    }
    return hits * kCoverageOne;
}

// A row-sample texel's expected sums: the CPU reference in float, the shader's arithmetic.
// `ambiguous` is set when a sample's units in a channel differ in double precision (the GPU may
// round a last bit differently, e.g. by fusing a multiply-add).
std::array<uint32_t, 3> row_sums(const FontAsset& asset, const GlyphRecord& glyph, const TexelToEm& map,
                                 const SubpixelLayout& layout, uint32_t tx, uint32_t ty, uint32_t samples,
                                 bool& ambiguous, uint64_t& extra_passes) {
    const uint32_t rows = shares_sample_rows(layout) ? 1 : 3;
    std::array<uint32_t, 3> sums{};
    for (uint32_t n = 0; n < samples; ++n) {
        uint32_t passes = rows;
        const std::array<uint32_t, 3> units = row_sample_units(asset, glyph, map, layout, tx, ty, n, &passes);
        extra_passes += passes - rows;
        for (size_t c = 0; c < 3; ++c) {
            sums[c] += units[c];
            const SampleRect& rect = layout.channels[c];
            const double v = row_height(n), px = tx, py = ty;
            const double ry0 = rect.y0, ry1 = rect.y1, rx0 = rect.x0, rx1 = rect.x1;
            const double ox = map.offset_x, oy = map.offset_y, sx = map.scale_x, sy = map.scale_y;
            const double y = oy + sy * (py + (ry0 + (ry1 - ry0) * v));
            const double x0 = ox + sx * (px + rx0);
            const double x1 = ox + sx * (px + rx1);
            const double covered = row_covered_length_banded<double>(asset, glyph, y, x0, x1);
            if (row_units<double>(covered, x1 - x0, row_dither(n), kCoverageOne) != units[c]) ambiguous = true;
        }
    }
    return sums;
}

// Compares every texel of every drawn glyph with the CPU reference of the renderer's sample kind.
Comparison compare(const Renderer& renderer, const std::vector<Texel>& texels, uint32_t samples,
                   const Font* font = nullptr) {
    const FontAsset& asset = (font ? font : fixture().font.get())->asset();
    const uint32_t width = renderer.atlas().config().width;
    const bool rows = renderer.sample_kind() == SampleKind::rows;
    Comparison result;
    for (const DrawnGlyph& d : renderer.drawn()) {
        const GlyphRecord& glyph = asset.glyphs[d.instance.key.glyph];
        const TexelToEm map = texel_to_em(glyph_rect(glyph, d.instance.key), d.instance.key);
        EXPECT_EQ(d.samples, samples);
        for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                const Texel& t = texels[(d.atlas_y + ty) * width + d.atlas_x + tx];
                EXPECT_EQ(t.count, samples);
                const uint16_t got[3] = {t.r, t.g, t.b};
                bool mismatch = false, explained = false;
                const SubpixelLayout& layout = renderer.subpixel_layout();
                std::array<uint32_t, 3> row_expected{};
                if (rows) {
                    row_expected = row_sums(asset, glyph, map, layout, tx + d.part_x, ty + d.part_y, samples, explained,
                                            result.row_passes);
                }
                for (size_t c = 0; c < 3; ++c) {
                    const SampleRect& rect = layout.channels[c];
                    const uint32_t expected =
                        rows ? row_expected[c]
                             : point_hits(asset, glyph, map, rect, tx + d.part_x, ty + d.part_y, samples, explained);
                    if (got[c] != expected) mismatch = true;
                    if (got[c] > 0) ++result.covered;
                }
                ++result.texels;
                if (mismatch) {
                    ++result.mismatched;
                    if (!explained) ++result.unexplained;
                }
            }
        }
    }
    return result;
}

Result<Renderer> make_renderer(const SubpixelLayout& layout, uint32_t samples, SampleKind kind = SampleKind::rows) {
    const HeadlessContext& context = *fixture().context;
    RendererCreateInfo info = renderer_create_info(context);
    info.sample_kind = kind;
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = samples;
    info.layout = layout;
    return Renderer::create(info);
}

// Six lines of 11 px "Hg@&1Hg", each at its own subpixel offset: more keys than a 64 x 64
// atlas's 16 cells hold.
std::vector<GlyphInstance> six_lines_of_small_text() {
    const Font* fonts[] = {fixture().font.get()};
    std::vector<GlyphInstance> glyphs;
    for (int line = 0; line < 6; ++line) {
        TextStyle style;
        style.size = 11.0f;
        LayoutOptions options;
        options.origin_x = 1.0f + 0.137f * static_cast<float>(line);
        options.origin_y = 12.0f + 13.29f * static_cast<float>(line);
        auto layout = layout_text(fonts, "Hg@&1Hg", style, options);
        EXPECT_TRUE(layout);
        if (layout) glyphs.insert(glyphs.end(), layout->glyphs.begin(), layout->glyphs.end());
    }
    return glyphs;
}

// `text` in the fixture's font at `size` px, its first pen at (x, y); empty where layout fails
// (the caller's checks then fail).
TextLayout fixture_layout(std::string_view text, float size, float x, float y) {
    const Font* fonts[] = {fixture().font.get()};
    TextStyle style;
    style.size = size;
    auto layout = layout_text(fonts, text, style, LayoutOptions{.origin_x = x, .origin_y = y});
    EXPECT_TRUE(layout);
    return layout ? std::move(*layout) : TextLayout{};
}

// Every drawn glyph's texels equal the reference (but where a sample lies on the outline), and
// some texel holds ink. Returns the comparison for further checks.
Comparison expect_matches_reference(const Renderer& renderer, const std::vector<Texel>& texels, uint32_t samples,
                                    const Font* font = nullptr) {
    const Comparison result = compare(renderer, texels, samples, font);
    EXPECT_GT(result.covered, 0u);
    EXPECT_EQ(result.unexplained, 0u) << result.mismatched << " of " << result.texels << " texels differ";
    return result;
}

void expect_no_validation_messages() {
    const ValidationMessages messages = fixture().context->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    for (const std::string& text : messages.recent) ADD_FAILURE() << text;
}

class RasterMatchesReference : public ::testing::TestWithParam<std::tuple<const char*, float, float, SampleKind>> {};

TEST_P(RasterMatchesReference, TexelByTexel) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context) << "no Vulkan device";
    ASSERT_TRUE(f.font);
    const auto [layout_name, size, offset, kind] = GetParam();
    constexpr uint32_t kSamples = 24;
    auto renderer = make_renderer(*subpixel_preset(layout_name), kSamples, kind);
    ASSERT_TRUE(renderer) << renderer.error().message;
    ASSERT_TRUE(renderer->add_font(*f.font));
    const Font* fonts[] = {f.font.get()};
    LayoutOptions options;
    options.origin_x = 3.0f + offset;
    options.origin_y = 2.0f + size + offset * 0.5f;
    TextStyle style;
    style.size = size;
    auto layout = layout_text(fonts, "Hg@&1", style, options);
    ASSERT_TRUE(layout);
    uint32_t frames = 0;
    const std::vector<Texel> texels = render(*renderer, *layout, frames);
    EXPECT_TRUE(renderer->converged());
    EXPECT_GE(frames, 4u);  // 8 + 4 + 2 + 1 + ... to 24
    const Comparison result = expect_matches_reference(*renderer, texels, kSamples);
    std::printf("%s %s: %llu of %llu texels differ, %llu extra row passes\n", layout_name,
                kind == SampleKind::rows ? "rows" : "points", static_cast<unsigned long long>(result.mismatched),
                static_cast<unsigned long long>(result.texels), static_cast<unsigned long long>(result.row_passes));
    EXPECT_LT(static_cast<double>(result.mismatched), 0.02 * static_cast<double>(result.texels));
    expect_no_validation_messages();
}

// Every preset layout with rows (stripes share rows; vrgb, qd-oled, woled and pentile do not),
// and points on four of them.
INSTANTIATE_TEST_SUITE_P(Sizes, RasterMatchesReference,
                         ::testing::Values(std::tuple{"gray", 11.0f, 0.0f, SampleKind::rows},
                                           std::tuple{"rgb", 16.0f, 0.37f, SampleKind::rows},
                                           std::tuple{"bgr", 9.0f, 0.5f, SampleKind::rows},
                                           std::tuple{"vrgb", 23.5f, 0.71f, SampleKind::rows},
                                           std::tuple{"vbgr", 7.0f, 0.2f, SampleKind::rows},
                                           std::tuple{"qd-oled", 40.0f, 0.125f, SampleKind::rows},
                                           std::tuple{"woled", 13.0f, 0.3f, SampleKind::rows},
                                           std::tuple{"pentile", 12.0f, 0.6f, SampleKind::rows},
                                           std::tuple{"gray", 11.0f, 0.0f, SampleKind::points},
                                           std::tuple{"rgb", 16.0f, 0.37f, SampleKind::points},
                                           std::tuple{"vrgb", 23.5f, 0.71f, SampleKind::points},
                                           std::tuple{"qd-oled", 40.0f, 0.125f, SampleKind::points}));

TEST(Raster, StaticTextConvergesAndThenSchedulesNoWork) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto renderer = make_renderer(*subpixel_preset("rgb"), 16);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const Font* fonts[] = {f.font.get()};
    auto layout = layout_text(fonts, "Hg", TextStyle{}, LayoutOptions{.origin_x = 2.5f, .origin_y = 20.0f});
    ASSERT_TRUE(layout);
    uint32_t frames = 0;
    render(*renderer, *layout, frames);
    ASSERT_TRUE(renderer->converged());
    for (int i = 0; i < 3; ++i) {
        renderer->begin_frame();
        renderer->draw(layout->glyphs);
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
        EXPECT_EQ(renderer->stats().work_items, 0u);
        EXPECT_EQ(renderer->stats().samples, 0u);
        EXPECT_EQ(renderer->stats().drawn_glyphs, 2u);
    }
    // A layout change invalidates the samples: work resumes.
    ASSERT_TRUE(renderer->set_subpixel_layout(*subpixel_preset("bgr")));
    renderer->begin_frame();
    renderer->draw(layout->glyphs);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    EXPECT_EQ(renderer->stats().work_items, 2u);
    expect_no_validation_messages();
}

TEST(Raster, BadConfigurationsAreRefused) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto too_many = make_renderer(*subpixel_preset("rgb"), 2000);
    ASSERT_FALSE(too_many);
    EXPECT_EQ(too_many.error().code, ErrorCode::invalid_argument);
    RendererCreateInfo unknown_kind = renderer_create_info(*f.context);
    unknown_kind.sample_kind = static_cast<SampleKind>(7);
    auto refused = Renderer::create(unknown_kind);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument);
    // An instance created for Vulkan 1.1 (or of a version not given) cannot run crisp's SPIR-V,
    // whatever the device offers.
    for (const uint32_t version : {0u, VK_API_VERSION_1_1}) {
        RendererCreateInfo old = renderer_create_info(*f.context);
        old.instance_api_version = version;
        auto made = Renderer::create(old);
        ASSERT_FALSE(made);
        EXPECT_EQ(made.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(made.error().message.find(version == 0 ? "not given" : "Vulkan 1.1"), std::string::npos)
            << made.error().message;
    }
    SubpixelLayout bad = *subpixel_preset("rgb");
    bad.channels[0].x1 = 5.0f;
    EXPECT_FALSE(make_renderer(bad, 16));
    auto renderer = make_renderer(*subpixel_preset("rgb"), 16);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    auto again = renderer->add_font(*f.font);
    ASSERT_FALSE(again);
    EXPECT_NE(again.error().message.find("added already"), std::string::npos);
    EXPECT_FALSE(renderer->set_subpixel_layout(bad));
    EXPECT_EQ(renderer->subpixel_layout().name, "rgb");
    // Instances of a font never added are counted and skipped.
    GlyphInstance stray;
    stray.key.font = 99;
    stray.width = stray.height = 4;
    renderer->begin_frame();
    renderer->draw(std::span(&stray, 1));
    EXPECT_EQ(renderer->stats().unknown_fonts, 1u);
}

}  // namespace
}  // namespace crisp

namespace crisp {
namespace {

TEST(Raster, TwoRenderersOnTwoContextsWorkSideBySide) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto second = test::create_renderer_context();
    ASSERT_TRUE(second) << second.error().message;
    RendererCreateInfo info = renderer_create_info(*second);
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = 8;
    auto other = Renderer::create(info);
    ASSERT_TRUE(other) << other.error().message;
    auto mine = make_renderer(*subpixel_preset("rgb"), 8);
    ASSERT_TRUE(mine);
    ASSERT_TRUE(mine->add_font(*f.font));
    ASSERT_TRUE(other->add_font(*f.font));
    const Font* fonts[] = {f.font.get()};
    auto layout = layout_text(fonts, "Hg", TextStyle{}, LayoutOptions{.origin_x = 2.5f, .origin_y = 20.0f});
    ASSERT_TRUE(layout);
    // Interleaved frames: each renderer's state and each context's queue stay its own.
    for (int frame = 0; frame < 2; ++frame) {
        for (auto [renderer, context] : {std::pair{&*mine, f.context.get()}, std::pair{&*other, &*second}}) {
            renderer->begin_frame();
            renderer->draw(layout->glyphs);
            ASSERT_TRUE(context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
        }
    }
    EXPECT_TRUE(mine->converged());
    EXPECT_TRUE(other->converged());
    EXPECT_EQ(mine->drawn().size(), other->drawn().size());
    const ValidationMessages messages = second->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    expect_no_validation_messages();
}

// Issue 13: one glyph whose single sample costs several frame budgets is rasterized in pieces of
// texels, each frame within the budget, and converges on the reference like any other.
TEST(Raster, AGlyphDearerThanTheBudgetIsSplitAcrossFrames) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    BakeOptions bake;
    bake.all_glyphs = false;
    bake.codepoints = decode_utf8("H");
    auto baked = bake_font_file(CRISP_MANY_CURVES_FONT, bake);
    ASSERT_TRUE(baked) << baked.error().message;
    auto font = Font::create(std::move(baked->asset), 2);
    ASSERT_TRUE(font);
    const Font* fonts[] = {&*font};
    TextStyle style;
    style.size = 24.0f;
    auto layout = layout_text(fonts, "H", style, LayoutOptions{.origin_x = 1.25f, .origin_y = 24.0f});
    ASSERT_TRUE(layout);
    ASSERT_EQ(layout->glyphs.size(), 1u);
    const GlyphInstance& glyph = layout->glyphs[0];
    const uint64_t cost = curve_tests_per_sample(font->asset(), font->asset().glyphs[glyph.key.glyph], glyph.key);

    constexpr uint32_t kSamples = 4;
    const HeadlessContext& context = *f.context;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = kSamples;
    info.atlas.ramp = {};
    info.atlas.frame_budget = cost / 6;  // one sample takes at least six frames
    auto renderer = Renderer::create(info);
    ASSERT_TRUE(renderer) << renderer.error().message;
    ASSERT_TRUE(renderer->add_font(*font));
    uint32_t frames = 0;
    uint64_t pieces = 0;
    const std::vector<Texel> texels = render(
        *renderer, frames, 100, [&] { renderer->draw(layout->glyphs); },
        [&] {
            const AtlasStats stats = renderer->atlas().stats();
            EXPECT_LE(renderer->stats().curve_tests, info.atlas.frame_budget);
            EXPECT_EQ(stats.frame.budget_overruns, 0u);
            pieces += stats.frame.split_pieces;
        });
    ASSERT_TRUE(renderer->converged()) << "not converged after " << frames << " frames";
    // Four samples of six budgets or more each, and no more frames than the pieces need.
    EXPECT_GE(frames, 4u * 6u);
    EXPECT_LE(frames, 4u * 7u);
    EXPECT_GE(pieces, frames);  // a piece or two every frame
    expect_matches_reference(*renderer, texels, kSamples, &*font);
    expect_no_validation_messages();
}

// Issue 13: a 2000 px glyph on a 200 x 200 target gets work only for what can be seen, fits an
// atlas too small for the whole of it, and its visible texels match the reference.
TEST(Raster, OnlyTheVisiblePartOfAHugeGlyphIsRasterized) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    const Font* fonts[] = {f.font.get()};
    TextStyle style;
    style.size = 2000.0f;
    // The pen far left: the target sees texels (900, 460) to (1100, 660) of the 1114 x 1461
    // rect, the left edge of the H's right stem and the paper beside it.
    auto layout = layout_text(fonts, "H", style, LayoutOptions{.origin_x = -1095.0f, .origin_y = 1000.0f});
    ASSERT_TRUE(layout);
    ASSERT_EQ(layout->glyphs.size(), 1u);
    ASSERT_GT(layout->glyphs[0].width, 1000u);

    constexpr uint32_t kSamples = 16;
    RendererCreateInfo info = renderer_create_info(*f.context);
    info.atlas.width = info.atlas.height = 512;  // the whole rect would need 2048 x 2048
    info.atlas.max_samples = kSamples;
    auto renderer = Renderer::create(info);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const VkRect2D visible{{0, 0}, {200, 200}};

    // Drawn whole, it does not fit.
    renderer->begin_frame();
    renderer->draw(layout->glyphs);
    EXPECT_EQ(renderer->stats().failed_glyphs, 1u);

    uint32_t frames = 0;
    const std::vector<Texel> texels = render(
        *renderer, frames, 20, [&] { renderer->draw(layout->glyphs, visible); },
        [&] {
            EXPECT_EQ(renderer->stats().failed_glyphs, 0u);
            EXPECT_EQ(renderer->stats().clipped_glyphs, 1u);
            // Work for the visible 200 x 200 texels and the margin around them, no more.
            const uint32_t side = 200 + 2 * kAtlasPartMargin;
            EXPECT_LE(renderer->stats().workgroups, (side * side + 63) / 64);
        });
    ASSERT_TRUE(renderer->converged());
    EXPECT_EQ(frames, 5u);  // 8 + 4 + 2 + 1 + 1 samples
    ASSERT_EQ(renderer->drawn().size(), 1u);
    const DrawnGlyph& drawn = renderer->drawn()[0];
    // The drawn part covers the target and lies within the margin of it.
    EXPECT_LE(drawn.instance.x, 0);
    EXPECT_LE(drawn.instance.y, 0);
    EXPECT_GE(drawn.instance.x + static_cast<int32_t>(drawn.instance.width), 200);
    EXPECT_GE(drawn.instance.y + static_cast<int32_t>(drawn.instance.height), 200);
    EXPECT_LE(drawn.instance.width, 200 + 2 * kAtlasPartMargin);
    EXPECT_EQ(drawn.instance.x, layout->glyphs[0].x + static_cast<int32_t>(drawn.part_x));
    const Comparison result = compare(*renderer, texels, kSamples);
    EXPECT_GT(result.covered, 1000u);                      // ink is visible...
    EXPECT_LT(result.covered, 3 * result.texels - 1000u);  // ...and so is paper
    EXPECT_EQ(result.unexplained, 0u) << result.mismatched << " of " << result.texels << " texels differ";

    // Wholly off the target: culled, no work.
    renderer->begin_frame();
    renderer->draw(layout->glyphs, VkRect2D{{-5000, 0}, {100, 100}});
    EXPECT_EQ(renderer->stats().culled_glyphs, 1u);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    EXPECT_EQ(renderer->stats().work_items, 0u);
    EXPECT_TRUE(renderer->drawn().empty());
    expect_no_validation_messages();
}

// Issue 9: crisp checks what the device was created with, not what the GPU offers. lavapipe
// offers every feature crisp uses; a device created without them must be refused, clearly.
TEST(Raster, FeaturesAreCheckedAgainstTheDeviceAsCreated) {
    HeadlessContextOptions options;
    options.validation = true;
    options.api_version = VK_API_VERSION_1_3;
    auto bare = HeadlessContext::create(options);  // no features enabled at all
    ASSERT_TRUE(bare) << bare.error().message;
    RendererCreateInfo info = renderer_create_info(*bare);
    auto refused = Renderer::create(info);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::vulkan);
    EXPECT_NE(refused.error().message.find("created without shaderStorageBufferArrayDynamicIndexing"),
              std::string::npos)
        << refused.error().message;
    info.enabled_features = nullptr;
    EXPECT_EQ(Renderer::create(info).error().code, ErrorCode::invalid_argument);

    CompositorCreateInfo compositor = compositor_create_info(*bare);
    EXPECT_TRUE(Compositor::create(compositor));  // the tile path needs nothing more
    compositor.draw_format = VK_FORMAT_R8G8B8A8_UNORM;
    auto no_draw = Compositor::create(compositor);
    ASSERT_FALSE(no_draw);
    EXPECT_NE(no_draw.error().message.find("dynamicRendering"), std::string::npos) << no_draw.error().message;
    compositor.draw_format = VK_FORMAT_UNDEFINED;
    compositor.reference_modes = true;
    compositor.width = compositor.height = 8;
    auto no_reference = Compositor::create(compositor);
    ASSERT_FALSE(no_reference);
    EXPECT_NE(no_reference.error().message.find("fragmentStoresAndAtomics"), std::string::npos);
    compositor.enabled_features = nullptr;
    EXPECT_EQ(Compositor::create(compositor).error().code, ErrorCode::invalid_argument);

    // add_crisp_features fills in a chain; a device made from it is accepted by every part.
    VkPhysicalDeviceVulkan13Features vulkan13{};
    vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    const Status no_room = add_crisp_features(bare->instance(), bare->physical_device(), features, {.draw_path = true});
    ASSERT_FALSE(no_room);  // no structure to hold dynamicRendering
    EXPECT_EQ(no_room.error().code, ErrorCode::invalid_argument);
    EXPECT_FALSE(features.features.shaderStorageBufferArrayDynamicIndexing);  // unchanged
    features.pNext = &vulkan13;
    ASSERT_TRUE(add_crisp_features(bare->instance(), bare->physical_device(), features,
                                   {.draw_path = true, .reference_modes = true, .storage_without_format = false}));
    EXPECT_TRUE(features.features.shaderStorageBufferArrayDynamicIndexing);
    EXPECT_TRUE(features.features.dualSrcBlend);
    EXPECT_TRUE(features.features.fragmentStoresAndAtomics);
    EXPECT_TRUE(vulkan13.dynamicRendering);
    EXPECT_FALSE(features.features.shaderStorageImageWriteWithoutFormat);
    options.required_features = &features;
    auto full = HeadlessContext::create(options);
    ASSERT_TRUE(full) << full.error().message;
    EXPECT_TRUE(Renderer::create(renderer_create_info(*full)));
    compositor = compositor_create_info(*full);
    compositor.draw_format = VK_FORMAT_R8G8B8A8_UNORM;
    compositor.reference_modes = true;
    compositor.width = compositor.height = 8;
    auto made = Compositor::create(compositor);
    EXPECT_TRUE(made) << made.error().message;
    for (HeadlessContext* context : {&*bare, &*full}) {
        const ValidationMessages messages = context->validation_messages();
        EXPECT_EQ(messages.errors + messages.warnings, 0u);
    }
}

// Issue 9: a full atlas must not make visible text vanish. Lines of the same letters at many
// subpixel offsets want far more entries than a 16-cell atlas holds; the glyphs that find no room
// are drawn at quarter-pixel, then whole-pixel, positions whose entries they share.
TEST(Raster, AFullAtlasDrawsGlyphsCoarserRatherThanDroppingThem) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    RendererCreateInfo info = renderer_create_info(*f.context);
    info.atlas.width = info.atlas.height = 64;  // 16 cells of 16 x 16 texels
    info.atlas.max_samples = 8;
    auto renderer = Renderer::create(info);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const std::vector<GlyphInstance> glyphs = six_lines_of_small_text();
    ASSERT_EQ(glyphs.size(), 42u);
    std::set<GlyphKey, bool (*)(const GlyphKey&, const GlyphKey&)> keys([](const GlyphKey& a, const GlyphKey& b) {
        return std::tie(a.glyph, a.subpixel_x, a.subpixel_y) < std::tie(b.glyph, b.subpixel_x, b.subpixel_y);
    });
    for (const GlyphInstance& g : glyphs) keys.insert(g.key);
    ASSERT_GT(keys.size(), 16u);  // more glyphs than cells

    renderer->begin_frame();
    renderer->draw(glyphs);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    const RendererStats& stats = renderer->stats();
    EXPECT_EQ(stats.failed_glyphs, 0u);
    EXPECT_GT(stats.coarsened_glyphs, 0u);
    EXPECT_GT(renderer->atlas().stats().total.failed_full, 0u);  // the atlas did refuse them
    EXPECT_LT(stats.subpixel_steps, kSubpixelSteps);
    ASSERT_EQ(renderer->drawn().size(), glyphs.size());  // every one drawn, none skipped
    // Each drawn glyph is the one asked for, at its own key or at a coarser one within half a
    // quarter pixel of it.
    for (size_t i = 0; i < glyphs.size(); ++i) {
        const GlyphInstance& asked = glyphs[i];
        const GlyphInstance& drawn = renderer->drawn()[i].instance;
        EXPECT_EQ(drawn.key.glyph, asked.key.glyph);
        if (drawn.key == asked.key) continue;
        EXPECT_EQ(drawn.key.subpixel_x % 64, 0);
        const GlyphRect asked_rect = glyph_rect(f.font->asset().glyphs[asked.key.glyph], asked.key);
        const GlyphRect drawn_rect = glyph_rect(f.font->asset().glyphs[drawn.key.glyph], drawn.key);
        const double asked_pen = asked.x - asked_rect.x + asked.key.subpixel_x / 256.0;
        const double drawn_pen = drawn.x - drawn_rect.x + drawn.key.subpixel_x / 256.0;
        EXPECT_LE(std::abs(drawn_pen - asked_pen), 0.5 + 1e-9);  // whole pixel at worst
    }
    // The next frame keeps the coarse steps: nothing is refused, nothing restarts.
    const uint64_t refused = renderer->atlas().stats().total.failed_full;
    renderer->begin_frame();
    renderer->draw(glyphs);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    EXPECT_EQ(renderer->atlas().stats().total.failed_full, refused);
    EXPECT_EQ(renderer->drawn().size(), glyphs.size());
    // Once the atlas has stayed nearly empty (one glyph on screen), the steps get fine again.
    const std::span<const GlyphInstance> one(glyphs.data(), 1);
    for (int frame = 0; frame < 241 && renderer->stats().subpixel_steps != kSubpixelSteps; ++frame) {
        renderer->begin_frame();
        renderer->draw(one);
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    }
    renderer->begin_frame();
    renderer->draw(one);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    EXPECT_EQ(renderer->stats().subpixel_steps, kSubpixelSteps);
    EXPECT_EQ(renderer->drawn()[0].instance.key, glyphs[0].key);
    expect_no_validation_messages();
}

TEST(Raster, DrawOptionsMoveRecolourAndSetDepthWithoutALayout) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto renderer = make_renderer(*subpixel_preset("rgb"), 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const TextLayout layout = fixture_layout("Hg@&1", 13.0f, 5.0f, 20.0f);
    // The same text laid out where the offset puts it (offsets exact in binary).
    const TextLayout moved = fixture_layout("Hg@&1", 13.0f, 5.0f + 3.25f, 20.0f + 0.5f);
    ASSERT_FALSE(moved.glyphs.empty());

    DrawOptions options;
    options.offset_x = 3.25f;
    options.offset_y = 0.5f;
    options.color = std::array<float, 4>{1.0f, 0.5f, std::nanf(""), 2.0f};
    options.depth = 0.25f;
    renderer->begin_frame();
    renderer->draw(layout.glyphs, options);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    ASSERT_EQ(renderer->drawn().size(), moved.glyphs.size());
    for (size_t i = 0; i < moved.glyphs.size(); ++i) {
        const GlyphInstance& want = moved.glyphs[i];
        const GlyphInstance& got = renderer->drawn()[i].instance;
        EXPECT_EQ(got.key, want.key) << i;
        EXPECT_EQ(got.x, want.x) << i;
        EXPECT_EQ(got.y, want.y) << i;
        EXPECT_EQ(got.width, want.width) << i;
        EXPECT_EQ(got.height, want.height) << i;
        EXPECT_EQ(got.color[0], 1.0f);
        EXPECT_EQ(got.color[1], srgb_to_linear(0.5f));
        EXPECT_EQ(got.color[2], 0.0f);  // NaN reads as 0
        EXPECT_EQ(got.color[3], 1.0f);  // clamped
        EXPECT_EQ(got.depth, 0.25f);
        EXPECT_EQ(got.paint_order, want.paint_order);
    }
    // A zero offset keeps the layout's glyphs as they are; a non-finite one draws nothing.
    renderer->begin_frame();
    renderer->draw(layout.glyphs, DrawOptions{});
    DrawOptions broken;
    broken.offset_x = std::numeric_limits<float>::infinity();
    renderer->draw(layout.glyphs, broken);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    ASSERT_EQ(renderer->drawn().size(), layout.glyphs.size());
    for (size_t i = 0; i < layout.glyphs.size(); ++i) {
        EXPECT_EQ(renderer->drawn()[i].instance.key, layout.glyphs[i].key);
        EXPECT_EQ(renderer->drawn()[i].instance.x, layout.glyphs[i].x);
        EXPECT_EQ(renderer->drawn()[i].instance.depth, layout.glyphs[i].depth);
    }
    EXPECT_EQ(renderer->stats().skipped_glyphs, layout.glyphs.size());
    expect_no_validation_messages();
}

// A label gliding 0.37 px a frame: with a name it takes quarter-pixel steps and keeps gathering
// samples in a few entries; without one, each frame needs new entries that never get past their
// first samples. At rest it returns to the fine steps.
TEST(Raster, MovingTextTakesCoarserStepsAndKeepsConverging) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    const TextLayout label = fixture_layout("Hg", 13.0f, 4.0f, 16.0f);
    ASSERT_EQ(label.glyphs.size(), 2u);
    constexpr int kFrames = 40;
    struct Run {
        std::set<GlyphKey, bool (*)(const GlyphKey&, const GlyphKey&)> keys{[](const GlyphKey& a, const GlyphKey& b) {
            return std::tie(a.glyph, a.subpixel_x, a.subpixel_y) < std::tie(b.glyph, b.subpixel_x, b.subpixel_y);
        }};
        uint32_t last_samples = 0;
        uint32_t moving = 0;
    };
    const auto run = [&](uint64_t id, Renderer& renderer, int frames, float speed, float start) {
        Run result;
        for (int frame = 0; frame < frames; ++frame) {
            DrawOptions options;
            options.offset_x = start + speed * static_cast<float>(frame);
            options.id = id;
            renderer.begin_frame();
            renderer.draw(label.glyphs, options);
            EXPECT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer.record(cb)); }));
            for (const DrawnGlyph& d : renderer.drawn()) result.keys.insert(d.instance.key);
            result.last_samples = renderer.drawn().empty() ? 0 : renderer.drawn()[0].samples;
            result.moving += renderer.stats().moving_glyphs;
        }
        return result;
    };
    auto named = make_renderer(*subpixel_preset("rgb"), 256);
    auto anonymous = make_renderer(*subpixel_preset("rgb"), 256);
    ASSERT_TRUE(named && anonymous);
    ASSERT_TRUE(named->add_font(*f.font));
    ASSERT_TRUE(anonymous->add_font(*f.font));
    const Run with_id = run(7, *named, kFrames, 0.37f, 0.0f);
    const Run without = run(0, *anonymous, kFrames, 0.37f, 0.0f);
    EXPECT_LE(with_id.keys.size(), 2u * (kMovingSubpixelSteps + 1));  // + its first, static frame
    EXPECT_GE(without.keys.size(), 2u * (kFrames - 1));
    EXPECT_EQ(with_id.moving, 2u * (kFrames - 1));  // all but the first frame, when it was first seen
    EXPECT_EQ(without.moving, 0u);
    EXPECT_GT(with_id.last_samples, 2 * without.last_samples);
    // At rest for kMotionSettleFrames frames, the label is static again: its layout's fine steps.
    const float rest = 0.37f * kFrames;
    const Run resting = run(7, *named, kMotionSettleFrames + 1, 0.0f, rest);
    const Run still = run(0, *anonymous, 1, 0.0f, rest);
    ASSERT_EQ(named->drawn().size(), 2u);
    ASSERT_EQ(anonymous->drawn().size(), 2u);
    for (size_t i = 0; i < 2; ++i) EXPECT_EQ(named->drawn()[i].instance.key, anonymous->drawn()[i].instance.key);
    EXPECT_EQ(still.moving, 0u);
    EXPECT_EQ(named->stats().moving_glyphs, 0u);
    EXPECT_GT(resting.moving, 0u);  // the first rest frames still count as moving
    expect_no_validation_messages();
}

// A draw's visible rect clips its glyphs to the pixel: drawn() reports only texels inside it (the
// atlas holds a margin around them, which the compositor must not show).
TEST(Raster, DrawnGlyphsStayInsideTheVisibleRect) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto renderer = make_renderer(*subpixel_preset("rgb"), 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const TextLayout layout = fixture_layout("Hg@&1", 24.0f, 3.0f, 30.0f);
    ASSERT_FALSE(layout.glyphs.empty());
    // A box through the middle of the line: every glyph is cut above and below.
    const VkRect2D box{{10, 18}, {60, 7}};
    DrawOptions options;
    options.visible = box;
    renderer->begin_frame();
    renderer->draw(layout.glyphs, options);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    ASSERT_FALSE(renderer->drawn().empty());
    uint64_t shown = 0;
    for (const DrawnGlyph& d : renderer->drawn()) {
        const GlyphInstance& g = d.instance;
        EXPECT_GE(g.x, box.offset.x);
        EXPECT_GE(g.y, box.offset.y);
        EXPECT_LE(g.x + static_cast<int32_t>(g.width), box.offset.x + static_cast<int32_t>(box.extent.width));
        EXPECT_LE(g.y + static_cast<int32_t>(g.height), box.offset.y + static_cast<int32_t>(box.extent.height));
        shown += uint64_t{g.width} * g.height;
    }
    // ... and nothing inside it is lost: the shown texels are the glyphs' rects within the box.
    uint64_t expected = 0;
    for (const GlyphInstance& g : layout.glyphs) {
        const int64_t w = std::min<int64_t>(int64_t{g.x} + g.width, 70) - std::max<int64_t>(g.x, 10);
        const int64_t h = std::min<int64_t>(int64_t{g.y} + g.height, 25) - std::max<int64_t>(g.y, 18);
        if (w > 0 && h > 0) expected += static_cast<uint64_t>(w * h);
    }
    EXPECT_EQ(shown, expected);
    expect_no_validation_messages();
}

// Dropped frames do not advance the motion clock: a label that comes to rest while frames are
// dropped is moving or static at the same submitted frames as in the run that dropped none.
TEST(Raster, DroppedFramesDoNotCountTowardsALabelsRest) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    HeadlessContext& context = *f.context;
    const TextLayout label = fixture_layout("Hg", 13.0f, 4.0f, 16.0f);
    ASSERT_FALSE(label.glyphs.empty());
    test::UnsubmittedCommandBuffer dropped(context);
    ASSERT_TRUE(dropped.ok());

    // Moves for 4 submitted frames, then rests; returns moving_glyphs of each submitted frame.
    const auto run = [&](bool drop) {
        auto renderer = make_renderer(*subpixel_preset("rgb"), 64);
        EXPECT_TRUE(renderer && renderer->add_font(*f.font));
        std::vector<uint32_t> moving;
        for (uint32_t frame = 0; frame < 4 + kMotionSettleFrames + 2; ++frame) {
            DrawOptions options;
            options.offset_x = 0.37f * static_cast<float>(std::min(frame, 4u));
            options.id = 3;
            if (drop) {  // each frame is first recorded once and dropped
                renderer->begin_frame();
                renderer->draw(label.glyphs, options);
                EXPECT_TRUE(dropped.record_and_drop([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer->record(cb)); }));
                EXPECT_TRUE(renderer->abandon_frame(renderer->frame()));
            }
            renderer->begin_frame();
            renderer->draw(label.glyphs, options);
            EXPECT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer->record(cb)); }));
            moving.push_back(renderer->stats().moving_glyphs);
        }
        return moving;
    };
    const std::vector<uint32_t> kept = run(false);
    const std::vector<uint32_t> with_drops = run(true);
    EXPECT_EQ(kept, with_drops);
    EXPECT_GT(kept[4], 0u);      // still moving just after it stopped
    EXPECT_EQ(kept.back(), 0u);  // at rest in the end
    expect_no_validation_messages();
}

// Fonts share the font pages: more fonts than the shader has buffer slots draw, each texel
// equal to the reference; a removed font's instances are unknown from the next frame on, and a
// font added in its place (its ranges reused once the GPU is done with them) draws correctly.
TEST(Raster, ManyFontsShareThePagesAndRemovedFontsLeave) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    constexpr uint32_t kSamples = 8;
    auto renderer = make_renderer(*subpixel_preset("rgb"), kSamples);
    ASSERT_TRUE(renderer);
    constexpr FontId kFonts = 2 * kRendererFontPages + 3;
    std::vector<std::unique_ptr<Font>> fonts;
    for (FontId id = 1; id <= kFonts; ++id) {
        fonts.push_back(test::bake_test_font("Hg@&1", id));  // the fixture's glyphs, under many ids
        ASSERT_TRUE(fonts.back());
        ASSERT_TRUE(renderer->add_font(*fonts.back()));
    }
    // One glyph of each font, side by side.
    const auto glyphs_of = [&](const std::vector<std::unique_ptr<Font>>& held) {
        std::vector<GlyphInstance> glyphs;
        for (size_t i = 0; i < held.size(); ++i) {
            const Font* one[] = {held[i].get()};
            TextStyle style;
            style.size = 11.0f + static_cast<float>(i % 5);
            const char* text[] = {"H", "g", "@", "&", "1"};
            auto laid = layout_text(one, text[i % 5], style,
                                    LayoutOptions{.origin_x = 2.0f + 14.0f * static_cast<float>(i % 12),
                                                  .origin_y = 20.0f + 24.0f * static_cast<float>(i / 12)});
            EXPECT_TRUE(laid);
            if (laid) glyphs.insert(glyphs.end(), laid->glyphs.begin(), laid->glyphs.end());
        }
        return glyphs;
    };
    const auto check = [&](const std::vector<GlyphInstance>& glyphs) {
        uint32_t frames = 0;
        const std::vector<Texel> texels = render(
            *renderer, frames, 100, [&] { renderer->draw(glyphs); }, [] {});
        ASSERT_EQ(renderer->drawn().size(), glyphs.size());
        expect_matches_reference(*renderer, texels, kSamples);
    };
    check(glyphs_of(fonts));

    // Remove font 3: this frame still has it, the next one does not.
    const std::vector<GlyphInstance> all = glyphs_of(fonts);
    ASSERT_TRUE(renderer->remove_font(3));
    EXPECT_FALSE(renderer->remove_font(3));       // already on its way out
    EXPECT_FALSE(renderer->add_font(*fonts[2]));  // not gone yet
    renderer->begin_frame();
    renderer->draw(all);
    EXPECT_EQ(renderer->stats().unknown_fonts, 1u);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    EXPECT_FALSE(renderer->remove_font(3));
    // A different font under the same id takes its place: "g" is the only glyph it has.
    fonts[2] = test::bake_test_font("g", 3);
    ASSERT_TRUE(fonts[2]);
    ASSERT_TRUE(renderer->add_font(*fonts[2]));
    for (int cycle = 0; cycle < 3; ++cycle) {  // cycles of removal reuse the freed ranges
        ASSERT_TRUE(renderer->remove_font(5));
        renderer->begin_frame();
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
        fonts[4] = test::bake_test_font("Hg@&1", 5);
        ASSERT_TRUE(renderer->add_font(*fonts[4]));
    }
    std::vector<std::unique_ptr<Font>> without_third;
    for (size_t i = 0; i < fonts.size(); ++i) {
        if (i != 2) without_third.push_back(std::move(fonts[i]));
    }
    check(glyphs_of(without_third));
    const Font* replaced[] = {fonts[2].get()};
    auto g = layout_text(replaced, "g", TextStyle{}, LayoutOptions{.origin_x = 3.0f, .origin_y = 90.0f});
    ASSERT_TRUE(g);
    ASSERT_EQ(g->glyphs.size(), 1u);
    uint32_t frames = 0;
    const std::vector<Texel> texels = render(
        *renderer, frames, 100, [&] { renderer->draw(g->glyphs); }, [] {});
    expect_matches_reference(*renderer, texels, kSamples, fonts[2].get());
    expect_no_validation_messages();
}

// record() without begin_frame() before it, or twice in a frame, is refused and changes nothing:
// the frames after it are those of a renderer never misused.
TEST(Raster, RecordWithoutBeginFrameOrTwiceInAFrameIsRefused) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto renderer = make_renderer(*subpixel_preset("rgb"), 16);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const Font* fonts[] = {f.font.get()};
    auto laid = layout_text(fonts, "Hg", TextStyle{}, LayoutOptions{.origin_x = 2.0f, .origin_y = 20.0f});
    ASSERT_TRUE(laid);
    const auto record_refused = [&](const char* why) {
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) {
            const Status s = renderer->record(cb);
            ASSERT_FALSE(s);
            EXPECT_EQ(s.error().code, ErrorCode::invalid_argument);
            EXPECT_NE(s.error().message.find(why), std::string::npos) << s.error().message;
        }));
    };
    record_refused("without begin_frame()");
    for (int frame = 0; frame < 3; ++frame) {
        renderer->begin_frame();
        renderer->draw(laid->glyphs);
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
        EXPECT_EQ(renderer->stats().samples, frame == 0 ? 16u : frame == 1 ? 8u : 4u);  // the ramp goes on
        record_refused("twice in one frame");
    }
    // An abandoned frame must begin again. (Its command buffer is submitted all the same, since
    // the context has no other way: the texels it adds are not looked at.)
    renderer->begin_frame();
    renderer->draw(laid->glyphs);
    ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) {
        ASSERT_TRUE(renderer->record(cb));
        EXPECT_TRUE(renderer->abandon_frame(renderer->frame()));
    }));
    record_refused("without begin_frame()");
    expect_no_validation_messages();
}

// A font's page, once no font uses it, gives its buffers back, and a memory block made for them
// goes back to the driver: the memory held returns to what it was before the font came.
TEST(Raster, RemovingTheLastFontOfAPageGivesItsMemoryBack) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    auto renderer = make_renderer(*subpixel_preset("rgb"), 16);
    ASSERT_TRUE(renderer);
    const auto frame = [&](const std::vector<GlyphInstance>& glyphs) {
        renderer->begin_frame();
        renderer->draw(glyphs);
        ASSERT_TRUE(f.context->submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    };
    frame({});
    const DeviceMemoryUse before = renderer->device_memory();
    for (int cycle = 0; cycle < 2; ++cycle) {
        const std::unique_ptr<Font> font = test::bake_test_font("Hg", 9);
        ASSERT_TRUE(font);
        ASSERT_TRUE(renderer->add_font(*font));
        const Font* fonts[] = {font.get()};
        auto laid = layout_text(fonts, "Hg", TextStyle{}, LayoutOptions{.origin_x = 2.0f, .origin_y = 20.0f});
        ASSERT_TRUE(laid);
        frame(laid->glyphs);
        const DeviceMemoryUse held = renderer->device_memory();
        std::printf("[ memory ] before the font %u allocations, %llu bytes; with it %u, %llu\n", before.allocations,
                    static_cast<unsigned long long>(before.bytes), held.allocations,
                    static_cast<unsigned long long>(held.bytes));
        EXPECT_GT(held.bytes, before.bytes);
        ASSERT_TRUE(renderer->remove_font(9));
        for (int i = 0; i < 4; ++i) frame({});  // past the frames that may read its ranges
        const DeviceMemoryUse after = renderer->device_memory();
        EXPECT_EQ(after.allocations, before.allocations);
        EXPECT_EQ(after.bytes, before.bytes);
    }
    expect_no_validation_messages();
}

// With a memory budget, an atlas too small for the frame's glyphs grows (its image copied into a
// larger one) rather than coarsening them; glyphs that had converged before keep their samples
// through the copy, and a dropped growth frame is grown again by the next one.
// An engine's own entry point (as volk's would be): it counts what crisp asks for, the dispatches,
// memory allocations and buffers crisp makes through it, and withholds one function on request.
namespace engine_loader {
PFN_vkGetInstanceProcAddr loader = nullptr;  // the real one behind it
PFN_vkGetDeviceProcAddr device_loader = nullptr;
PFN_vkCmdDispatch dispatch = nullptr;
PFN_vkAllocateMemory allocate_memory = nullptr;
PFN_vkCreateBuffer create_buffer = nullptr;
std::set<std::string> asked;
uint32_t dispatches = 0;
uint32_t allocations = 0;
uint32_t buffers = 0;
std::string withheld;

void reset(PFN_vkGetInstanceProcAddr real) {
    loader = real;
    asked.clear();
    dispatches = allocations = buffers = 0;
    withheld.clear();
}

VKAPI_ATTR void VKAPI_CALL counting_dispatch(VkCommandBuffer cb, uint32_t x, uint32_t y, uint32_t z) {
    ++dispatches;
    dispatch(cb, x, y, z);
}
VKAPI_ATTR VkResult VKAPI_CALL counting_allocate_memory(VkDevice device, const VkMemoryAllocateInfo* info,
                                                        const VkAllocationCallbacks* allocator, VkDeviceMemory* out) {
    ++allocations;
    return allocate_memory(device, info, allocator, out);
}
VKAPI_ATTR VkResult VKAPI_CALL counting_create_buffer(VkDevice device, const VkBufferCreateInfo* info,
                                                      const VkAllocationCallbacks* allocator, VkBuffer* out) {
    ++buffers;
    return create_buffer(device, info, allocator, out);
}

// The wrapper in place of `real` for the functions counted, else `real` itself.
PFN_vkVoidFunction hooked(std::string_view name, PFN_vkVoidFunction real) {
    const auto wrap = [&](auto& keep, auto wrapper) {
        keep = reinterpret_cast<std::remove_reference_t<decltype(keep)>>(real);
        return reinterpret_cast<PFN_vkVoidFunction>(wrapper);
    };
    if (name == "vkCmdDispatch") return wrap(dispatch, counting_dispatch);
    if (name == "vkAllocateMemory") return wrap(allocate_memory, counting_allocate_memory);
    if (name == "vkCreateBuffer") return wrap(create_buffer, counting_create_buffer);
    return real;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL device_proc_addr(VkDevice device, const char* name) {
    asked.insert(name);
    return name == withheld ? nullptr : hooked(name, device_loader(device, name));
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL instance_proc_addr(VkInstance instance, const char* name) {
    asked.insert(name);
    if (name == withheld) return nullptr;
    const PFN_vkVoidFunction real = loader(instance, name);
    if (std::string_view(name) != "vkGetDeviceProcAddr") return hooked(name, real);
    device_loader = reinterpret_cast<PFN_vkGetDeviceProcAddr>(real);
    return reinterpret_cast<PFN_vkVoidFunction>(device_proc_addr);
}
}  // namespace engine_loader

// crisp calls Vulkan only through the entry point the caller hands it (and references no Vulkan
// symbol of its own: the crisp_references_no_vulkan_symbol test), so that an engine that loads
// Vulkan itself gets crisp's calls through its own dispatch, and the text comes out right.
TEST(Raster, VulkanIsCalledThroughTheCallersEntryPoint) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    HeadlessContext& context = *f.context;
    engine_loader::reset(context.get_instance_proc_addr());
    const TextLayout layout = fixture_layout("Hg@", 14.0f, 2.0f, 16.0f);
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 128;
    info.atlas.max_samples = 16;
    {
        auto renderer = Renderer::create(info);
        ASSERT_TRUE(renderer);
        ASSERT_TRUE(renderer->add_font(*f.font));
        uint32_t frames = 0;
        render(*renderer, layout, frames);
    }
    EXPECT_TRUE(engine_loader::asked.empty());
    EXPECT_EQ(engine_loader::dispatches, 0u);

    info.get_instance_proc_addr = engine_loader::instance_proc_addr;
    {
        auto renderer = Renderer::create(info);
        ASSERT_TRUE(renderer) << renderer.error().message;
        ASSERT_TRUE(renderer->add_font(*f.font));
        uint32_t frames = 0;
        const std::vector<Texel> through_engine = render(*renderer, layout, frames);
        EXPECT_EQ(engine_loader::dispatches, frames);  // one rasterizer dispatch a frame with work
        expect_matches_reference(*renderer, through_engine, 16);
    }
    for (const char* name : {"vkGetPhysicalDeviceProperties", "vkCreateComputePipelines", "vkCmdPipelineBarrier"}) {
        EXPECT_EQ(engine_loader::asked.count(name), 1u) << name;
    }

    // A function the engine's loader does not give is named, and nothing is made.
    engine_loader::withheld = "vkCmdDispatchIndirect";
    auto refused = Renderer::create(info);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::vulkan);
    EXPECT_NE(refused.error().message.find("vkCmdDispatchIndirect"), std::string::npos) << refused.error().message;
    CompositorCreateInfo compositor_info = compositor_create_info(context);
    compositor_info.get_instance_proc_addr = engine_loader::instance_proc_addr;
    auto no_compositor = Compositor::create(compositor_info);
    ASSERT_FALSE(no_compositor);
    EXPECT_NE(no_compositor.error().message.find("vkCmdDispatchIndirect"), std::string::npos);
    engine_loader::withheld.clear();
    EXPECT_TRUE(Compositor::create(compositor_info));
    expect_no_validation_messages();
}

// Buffers take their memory from a few shared blocks, not one allocation each, and once a scene
// has been drawn a few frames, recording it again makes no buffer and allocates nothing, in the
// renderer or in the compositor.
TEST(Raster, BuffersShareAFewBlocksAndWarmFramesAllocateNothing) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    HeadlessContext& context = *f.context;
    engine_loader::reset(context.get_instance_proc_addr());
    RendererCreateInfo info = renderer_create_info(context);
    info.get_instance_proc_addr = engine_loader::instance_proc_addr;
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = 64;
    auto renderer = Renderer::create(info);
    ASSERT_TRUE(renderer) << renderer.error().message;
    ASSERT_TRUE(renderer->add_font(*f.font));
    CompositorCreateInfo compositor_info = compositor_create_info(context);
    compositor_info.get_instance_proc_addr = engine_loader::instance_proc_addr;
    auto compositor = Compositor::create(compositor_info);
    ASSERT_TRUE(compositor) << compositor.error().message;

    constexpr uint32_t kWidth = 96, kHeight = 96;
    auto target = context.create_image({VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT});
    ASSERT_TRUE(target);
    ASSERT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) {
        VkImageMemoryBarrier barrier{};
        barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
        barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.image = target->handle();
        barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr,
                             0, nullptr, 1, &barrier);
    }));
    const CompositeTarget composite_target{
        target->view(), VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_UNDEFINED, {kWidth, kHeight}, {}};
    const std::vector<GlyphInstance> glyphs = six_lines_of_small_text();
    const auto frame = [&](uint32_t i) {
        renderer->begin_frame();
        // Each frame moves the text by a pixel or two, so that the compositor bins anew.
        DrawOptions options;
        options.offset_x = static_cast<float>(i % 3);
        renderer->draw(glyphs, options);
        EXPECT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) {
            VkMemoryBarrier barrier{};
            barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
            barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
            vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                                 &barrier, 0, nullptr, 0, nullptr);
            EXPECT_TRUE(renderer->record(cb));
            EXPECT_TRUE(compositor->record(cb, renderer->drawn_frame(), composite_target));
        }));
    };
    for (uint32_t i = 0; i < 3; ++i) frame(i);  // warm-up: fonts uploaded, slots sized
    const uint32_t allocations = engine_loader::allocations, buffers = engine_loader::buffers;
    for (uint32_t i = 3; i < 12; ++i) frame(i);
    EXPECT_EQ(engine_loader::allocations, allocations);
    EXPECT_EQ(engine_loader::buffers, buffers);

    // The renderer's buffers (items, a font page's points and bands, the font's staging, the empty
    // slot) in a device-local and a host-visible block, the atlas image and the bitmap images' blank
    // layer; the compositor's slots' quads, tiles, bins, headers and paints in two blocks likewise.
    const DeviceMemoryUse renderer_memory = renderer->device_memory();
    const DeviceMemoryUse compositor_memory = compositor->device_memory();
    EXPECT_LE(renderer_memory.allocations, 4u);
    EXPECT_LE(compositor_memory.allocations, 2u);
    EXPECT_EQ(renderer_memory.allocations + compositor_memory.allocations, allocations);
    EXPECT_GE(renderer_memory.bytes, VkDeviceSize{256} * 256 * 8);
    expect_no_validation_messages();
}

TEST(Raster, AnAtlasWithABudgetGrowsInsteadOfCoarsening) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context);
    HeadlessContext& context = *f.context;
    constexpr uint32_t kSamples = 8;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 64;  // 16 cells
    info.atlas.max_samples = kSamples;
    info.atlas_memory_budget = 128 * 128 * 8;  // one doubling
    auto renderer = Renderer::create(info);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*f.font));
    const std::vector<GlyphInstance> glyphs = six_lines_of_small_text();
    ASSERT_EQ(glyphs.size(), 42u);
    // The first line fits the small atlas and converges there.
    const std::span<const GlyphInstance> first_line(glyphs.data(), 7);
    uint32_t frames = 0;
    render(
        *renderer, frames, 100, [&] { renderer->draw(first_line); }, [] {});
    ASSERT_TRUE(renderer->converged());
    EXPECT_EQ(renderer->stats().atlas_width, 64u);

    // All six lines: the frame that grows the atlas is dropped once, then submitted.
    test::UnsubmittedCommandBuffer dropped(context);
    ASSERT_TRUE(dropped.ok());
    renderer->begin_frame();
    renderer->draw(glyphs);
    EXPECT_TRUE(dropped.record_and_drop([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer->record(cb)); }));
    EXPECT_EQ(renderer->stats().atlas_grown, 1u);
    EXPECT_TRUE(renderer->abandon_frame(renderer->frame()));
    renderer->begin_frame();
    renderer->draw(glyphs);
    ASSERT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) { ASSERT_TRUE(renderer->record(cb)); }));
    const RendererStats& grown = renderer->stats();
    EXPECT_EQ(grown.atlas_grown, 0u);  // the atlas grew in the dropped frame; this one made the image
    EXPECT_EQ(grown.atlas_width, 128u);
    EXPECT_EQ(grown.atlas_height, 128u);
    EXPECT_EQ(grown.subpixel_steps, kSubpixelSteps);
    EXPECT_EQ(grown.coarsened_glyphs, 0u);
    EXPECT_EQ(grown.failed_glyphs, 0u);
    EXPECT_EQ(renderer->drawn().size(), glyphs.size());
    const std::vector<Texel> texels = render(
        *renderer, frames, 100, [&] { renderer->draw(glyphs); }, [] {});
    ASSERT_TRUE(renderer->converged());
    EXPECT_EQ(renderer->atlas().config().width, 128u);
    expect_matches_reference(*renderer, texels, kSamples);
    expect_no_validation_messages();
}

}  // namespace
}  // namespace crisp
