// Shared by the compositor tests (lavapipe, validation and synchronization validation on): a
// context with every feature the compositor's paths use, scenes of text runs rendered to
// convergence with the per-pixel fragments the shaders see, and the reference modes' read-back.
#pragma once

#include "headless_context.hpp"
#include "oit_reference.hpp"
#include "test_support.hpp"

#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/renderer.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace crisp::compositing_test {

constexpr uint32_t kWidth = 72;
constexpr uint32_t kHeight = 40;
constexpr uint32_t kSamples = 16;  // enough for coverage ramps; quick to converge on lavapipe

constexpr float kBackground[4] = {0.9f, 0.85f, 0.7f, 1.0f};  // linear

using Fixture = test::GpuFixture;

// The shared context (created once) and font.
Fixture& fixture();

struct TextRun {
    const char* text;
    float x, y;
    float color[4];  // sRGB, straight alpha
    float depth;
};

using test::Texel;

// A scene rendered to convergence: its glyphs, the atlas texels, and the fragments of every pixel
// (in draw order) as the compositor's shaders compute them.
struct Scene {
    std::unique_ptr<Renderer> renderer;
    std::vector<DrawnGlyph> drawn;
    std::vector<std::vector<oit::Fragment>> pixels;  // kWidth * kHeight lists
};

Scene render_scene(const std::vector<TextRun>& runs, const char* layout_name = "rgb", float size = 20.0f);

// The reference modes at kWidth x kHeight, for the fixture's device.
CompositorCreateInfo compositor_info();

// Composites the scene's glyphs (in the given order) with a reference mode and returns linear
// premultiplied RGBA.
std::vector<float> composite(Compositor& compositor, const Scene& scene, std::span<const DrawnGlyph> glyphs,
                             CompositeMode mode, QuadPath path = QuadPath::raster);
std::vector<float> composite(Compositor& compositor, const Scene& scene, CompositeMode mode);

oit::LinearRgb background_rgb();
void expect_no_validation_messages();
// Overlapping runs at distinct depths whose paint order is not their depth order.
std::vector<TextRun> overlapping_runs(float alpha);
size_t max_overlap(const Scene& scene);

}  // namespace crisp::compositing_test
