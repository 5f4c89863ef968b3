// The GPU rasterizer held to the CPU reference, texel by texel, on lavapipe with validation on.
#include "coverage.hpp"
#include "test_support.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/vulkan_context.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

namespace crisp {
namespace {

struct Fixture {
    std::unique_ptr<HeadlessContext> context;
    std::unique_ptr<Font> font;
};

Fixture& fixture() {
    static Fixture f = [] {
        Fixture made;
        HeadlessContextOptions options;
        options.validation = true;
        auto context = HeadlessContext::create(options);
        if (context) made.context = std::make_unique<HeadlessContext>(std::move(*context));
        made.font = test::bake_test_font("Hg@&1");
        return made;
    }();
    return f;
}

using test::Texel;

// Renders `text` until it converges and returns the atlas texels.
std::vector<Texel> render(Renderer& renderer, const TextLayout& layout, uint32_t& frames) {
    HeadlessContext& context = *fixture().context;
    frames = 0;
    do {
        renderer.begin_frame();
        renderer.draw(layout.glyphs);
        EXPECT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer.record(cb)); }));
        ++frames;
    } while (!renderer.converged() && frames < 1000);
    const AtlasConfig& config = renderer.atlas().config();
    const VkDeviceSize bytes = VkDeviceSize{config.width} * config.height * sizeof(Texel);
    auto readback = context.create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    EXPECT_TRUE(readback);
    EXPECT_TRUE(
        context.submit_and_wait([&](VkCommandBuffer cb) { renderer.record_atlas_readback(cb, readback->handle()); }));
    auto data = context.read_buffer(*readback, 0, bytes);
    EXPECT_TRUE(data);
    std::vector<Texel> texels(config.width * config.height);
    std::memcpy(texels.data(), data->data(), bytes);
    return texels;
}

// The float positions the shader computes for sample n of texel (tx, ty), channel c.
void gpu_sample(const TexelToEm& map, const SampleRect& rect, uint32_t tx, uint32_t ty, uint32_t n, float& x,
                float& y) {
    float u = 0.5f + static_cast<float>(n) * 0.7548776662466927f;
    float v = 0.5f + static_cast<float>(n) * 0.5698402909980532f;
    u -= std::floor(u);
    v -= std::floor(v);
    const float px = static_cast<float>(tx) + (rect.x0 + (rect.x1 - rect.x0) * u);
    const float py = static_cast<float>(ty) + (rect.y0 + (rect.y1 - rect.y0) * v);
    x = map.offset_x + map.scale_x * px;
    y = map.offset_y + map.scale_y * py;
}

struct Comparison {
    uint64_t texels = 0;
    uint64_t mismatched = 0;   // hit counts differ
    uint64_t unexplained = 0;  // ... and no sample of the texel lies near an edge
    uint64_t covered = 0;      // texels with any hit
};

// Compares every texel of every drawn glyph with the CPU reference: double-precision banded
// winding at the shader's float sample positions. A differing texel is explained when one of
// its samples lies within kEdge em of the outline (the winding changes within that distance).
Comparison compare(const Renderer& renderer, const std::vector<Texel>& texels, uint32_t samples) {
    constexpr double kEdge = 2e-5;  // em: 1/50 px at 1000 px per em
    const FontAsset& asset = fixture().font->asset();
    const uint32_t width = renderer.atlas().config().width;
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
                bool mismatch = false, near_edge = false;
                for (int c = 0; c < 3; ++c) {
                    uint32_t hits = 0;
                    for (uint32_t n = 0; n < samples; ++n) {
                        float x = 0, y = 0;
                        gpu_sample(map, renderer.subpixel_layout().channels[static_cast<size_t>(c)], tx, ty, n, x, y);
                        const double xd = x, yd = y;
                        const bool hit = winding_number_banded<double>(asset, glyph, xd, yd) != 0;
                        hits += hit;
                        for (const auto& [dx, dy] :
                             {std::pair{kEdge, 0.0}, {-kEdge, 0.0}, {0.0, kEdge}, {0.0, -kEdge}}) {
                            if ((winding_number_banded<double>(asset, glyph, xd + dx, yd + dy) != 0) != hit)
                                near_edge = true;
                        }
                    }
                    if (got[c] != hits * kCoverageOne) mismatch = true;
                    if (got[c] > 0) ++result.covered;
                }
                ++result.texels;
                if (mismatch) {
                    ++result.mismatched;
                    if (!near_edge) ++result.unexplained;
                }
            }
        }
    }
    return result;
}

Result<Renderer> make_renderer(const SubpixelLayout& layout, uint32_t samples) {
    const HeadlessContext& context = *fixture().context;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = samples;
    info.layout = layout;
    return Renderer::create(info);
}

void expect_no_validation_messages() {
    const ValidationMessages messages = fixture().context->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    for (const std::string& text : messages.recent) ADD_FAILURE() << text;
}

class RasterMatchesReference : public ::testing::TestWithParam<std::tuple<const char*, float, float>> {};

TEST_P(RasterMatchesReference, TexelByTexel) {
    Fixture& f = fixture();
    ASSERT_TRUE(f.context) << "no Vulkan device";
    ASSERT_TRUE(f.font);
    const auto [layout_name, size, offset] = GetParam();
    constexpr uint32_t kSamples = 24;
    auto renderer = make_renderer(*subpixel_preset(layout_name), kSamples);
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
    const Comparison result = compare(*renderer, texels, kSamples);
    EXPECT_GT(result.covered, 0u);
    EXPECT_EQ(result.unexplained, 0u) << result.mismatched << " of " << result.texels << " texels differ";
    EXPECT_LT(static_cast<double>(result.mismatched), 0.02 * static_cast<double>(result.texels));
    expect_no_validation_messages();
}

INSTANTIATE_TEST_SUITE_P(Sizes, RasterMatchesReference,
                         ::testing::Values(std::tuple{"gray", 11.0f, 0.0f}, std::tuple{"rgb", 16.0f, 0.37f},
                                           std::tuple{"vrgb", 23.5f, 0.71f}, std::tuple{"qd-oled", 40.0f, 0.125f}));

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
    HeadlessContextOptions options;
    options.validation = true;
    auto second = HeadlessContext::create(options);
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

}  // namespace
}  // namespace crisp
