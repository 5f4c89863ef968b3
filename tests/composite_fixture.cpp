// The compositor tests' shared fixture (composite_fixture.hpp).
#include "composite_fixture.hpp"

#include "test_support.hpp"

#include <crisp/layout.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace crisp::compositing_test {

// A context with what the renderer and every compositor path need.
Fixture& fixture() {
    // Synchronization validation: the compositor's barriers are what is tested too.
    static Fixture f = test::make_gpu_fixture({.draw_path = true, .reference_modes = true}, true, "Hamburgefonstiv@&1");
    return f;
}

Scene render_scene(const std::vector<TextRun>& runs, const char* layout_name, float size) {
    Fixture& f = fixture();
    HeadlessContext& context = *f.context;
    Scene scene;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = kSamples;
    info.layout = *subpixel_preset(layout_name);
    // The CPU references these scenes are held to blend coverage as it is; the contrast model is
    // held to its own reference (test_contrast.cpp).
    info.contrast.mode = ContrastMode::linear;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << (renderer ? "" : renderer.error().message);
    scene.renderer = std::make_unique<Renderer>(std::move(*renderer));
    EXPECT_TRUE(scene.renderer->add_font(*f.font));

    std::vector<GlyphInstance> glyphs;
    uint32_t paint_order = 0;
    const Font* fonts[] = {f.font.get()};
    for (const TextRun& run : runs) {
        TextStyle style;
        style.size = size;
        std::copy(run.color, run.color + 4, style.color);
        style.depth = run.depth;
        LayoutOptions options;
        options.origin_x = run.x;
        options.origin_y = run.y;
        options.first_paint_order = paint_order;
        auto laid = layout_text(fonts, run.text, style, options);
        EXPECT_TRUE(laid);
        glyphs.insert(glyphs.end(), laid->glyphs.begin(), laid->glyphs.end());
        paint_order = laid->next_paint_order;
    }
    Renderer& r = *scene.renderer;
    const Result<uint32_t> frames = test::render_until_converged(context, r, 200, [&] {
        r.draw(glyphs, VkRect2D{{0, 0}, {kWidth, kHeight}});
    });
    EXPECT_TRUE(frames) << frames.error().message;
    EXPECT_TRUE(r.converged());
    scene.drawn.assign(r.drawn().begin(), r.drawn().end());

    const uint32_t atlas_width = r.atlas().config().width;
    Result<std::vector<Texel>> read = test::read_atlas(context, r);
    EXPECT_TRUE(read) << read.error().message;
    std::vector<Texel> texels =
        read ? std::move(*read) : std::vector<Texel>(size_t{atlas_width} * r.atlas().config().height);

    scene.pixels.resize(size_t{kWidth} * kHeight);
    for (const DrawnGlyph& d : scene.drawn) {
        const GlyphInstance& g = d.instance;
        for (uint32_t ty = 0; ty < g.height; ++ty) {
            for (uint32_t tx = 0; tx < g.width; ++tx) {
                const int64_t x = int64_t{g.x} + tx, y = int64_t{g.y} + ty;
                if (x < 0 || y < 0 || x >= kWidth || y >= kHeight) continue;
                const Texel& t = texels[size_t{d.atlas_y + ty} * atlas_width + d.atlas_x + tx];
                if (t.count == 0) continue;
                oit::Fragment fragment;
                fragment.depth = g.depth;
                fragment.paint_order = g.paint_order;
                const uint16_t sums[3] = {t.r, t.g, t.b};
                bool visible = false;
                for (int c = 0; c < 3; ++c) {
                    const float coverage =
                        std::min(static_cast<float>(sums[c]) / (64.0f * static_cast<float>(t.count)), 1.0f);
                    const float opacity = g.color[3] * coverage;
                    fragment.transmittance[c] = 1.0f - opacity;
                    fragment.light[c] = g.color[c] * opacity;
                    visible = visible || opacity > 0.0f;
                }
                if (visible) scene.pixels[static_cast<size_t>(y) * kWidth + static_cast<size_t>(x)].push_back(fragment);
            }
        }
    }
    return scene;
}

CompositorCreateInfo compositor_info() {
    Fixture& f = fixture();
    CompositorCreateInfo info = compositor_create_info(*f.context);
    info.width = kWidth;
    info.height = kHeight;
    info.reference_modes = true;
    return info;
}

// Composites the scene's glyphs (in the given order) and returns linear premultiplied RGBA.
std::vector<float> composite(Compositor& compositor, const Scene& scene, std::span<const DrawnGlyph> glyphs,
                             CompositeMode mode, QuadPath path) {
    HeadlessContext& context = *fixture().context;
    const VkDeviceSize bytes = VkDeviceSize{kWidth} * kHeight * 4 * sizeof(float);
    auto readback = context.create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    EXPECT_TRUE(readback);
    CompositeParams params;
    params.mode = mode;
    params.path = path;
    std::copy(kBackground, kBackground + 4, params.background);
    EXPECT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) {
        EXPECT_TRUE(compositor.record_reference(cb, scene.renderer->drawn_frame().with_glyphs(glyphs), params));
        compositor.record_target_readback(cb, readback->handle());
    }));
    std::vector<float> image(size_t{kWidth} * kHeight * 4);
    std::memcpy(image.data(), readback->mapped().data(), bytes);
    return image;
}

std::vector<float> composite(Compositor& compositor, const Scene& scene, CompositeMode mode) {
    return composite(compositor, scene, scene.drawn, mode, QuadPath::raster);
}

oit::LinearRgb background_rgb() {
    return {kBackground[0], kBackground[1], kBackground[2]};
}

void expect_no_validation_messages() {
    const ValidationMessages messages = fixture().context->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    for (const std::string& text : messages.recent) ADD_FAILURE() << text;
}

// Overlapping runs at distinct depths whose paint order is not their depth order.
std::vector<TextRun> overlapping_runs(float alpha) {
    return {
        {"Hamburg", 1.25f, 20.0f, {0.9f, 0.1f, 0.1f, alpha}, 0.6f},
        {"efonts", 3.6f, 22.3f, {0.1f, 0.6f, 0.2f, alpha}, 0.2f},
        {"Hamburg", 2.4f, 24.7f, {0.1f, 0.2f, 0.9f, alpha}, 0.4f},
        {"stiv@&1", 0.7f, 34.1f, {0.2f, 0.2f, 0.2f, alpha}, 0.3f},
    };
}

size_t max_overlap(const Scene& scene) {
    size_t most = 0;
    for (const auto& list : scene.pixels) most = std::max(most, list.size());
    return most;
}
}  // namespace crisp::compositing_test
