// The GPU compositor on lavapipe with validation on: each mode against the CPU references of
// oit_reference.hpp (built from the same atlas texels), order independence,
// bound, coplanar paint order, per-channel subpixel compositing and opaque text.
#include "composite_fixture.hpp"
#include "headless_context.hpp"
#include "oit_reference.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace crisp {
namespace {

using namespace compositing_test;

TEST(Compositor, RejectsBadCreateInfo) {
    CompositorCreateInfo info = compositor_info();
    info.width = 0;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info();
    info.exact_nodes_per_pixel = 65;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info();
    info.frames_in_flight = 9;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info();
    info.device = VK_NULL_HANDLE;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    // An instance older than Vulkan 1.2, or one whose version is not given, cannot run crisp's SPIR-V.
    for (const uint32_t version : {0u, VK_API_VERSION_1_0, VK_API_VERSION_1_1}) {
        info = compositor_info();
        info.instance_api_version = version;
        auto old = Compositor::create(info);
        ASSERT_FALSE(old);
        EXPECT_EQ(old.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(old.error().message.find("compositor: instance_api_version is "), std::string::npos)
            << old.error().message;
    }
    // Without the reference modes the size is not looked at, and no per-pixel memory is made.
    info = compositor_info();
    info.reference_modes = false;
    info.width = 0;
    auto tiles_only = Compositor::create(info);
    ASSERT_TRUE(tiles_only);
    EXPECT_EQ(tiles_only->target_image(), VK_NULL_HANDLE);
    EXPECT_EQ(parse_composite_mode("wboit"), CompositeMode::wboit);
    EXPECT_EQ(parse_composite_mode("tiled"), CompositeMode::tiled);
    EXPECT_FALSE(parse_composite_mode("layered"));  // the first compositor's mode is gone
    EXPECT_FALSE(parse_composite_mode("sorted"));
}

TEST(Compositor, ExactMatchesTheCpuReference) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor) << compositor.error().message;
    const std::vector<float> image = composite(*compositor, scene, CompositeMode::exact);
    double worst = 0.0;
    for (size_t p = 0; p < scene.pixels.size(); ++p) {
        const oit::LinearRgb want = oit::composite_exact(scene.pixels[p], background_rgb());
        for (size_t c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double{image[p * 4 + c]} - double{want[c]}));
        EXPECT_FLOAT_EQ(image[p * 4 + 3], 1.0f);
    }
    EXPECT_LT(worst, 2e-5);
    EXPECT_GE(max_overlap(scene), 4u);  // the scene does overlap
    expect_no_validation_messages();
}

TEST(Compositor, UnsortedAndWboitMatchTheCpuReferences) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    const std::vector<float> unsorted = composite(*compositor, scene, CompositeMode::unsorted);
    const std::vector<float> wboit = composite(*compositor, scene, CompositeMode::wboit);
    double worst_unsorted = 0.0, worst_wboit = 0.0;
    for (size_t p = 0; p < scene.pixels.size(); ++p) {
        // drawn() is in draw order, so the pixel lists are in submission order too.
        const oit::LinearRgb want_unsorted = oit::composite_unsorted(scene.pixels[p], background_rgb());
        const oit::LinearRgb want_wboit = oit::composite_wboit(scene.pixels[p], background_rgb());
        for (size_t c = 0; c < 3; ++c) {
            worst_unsorted = std::max(worst_unsorted, std::abs(double{unsorted[p * 4 + c]} - double{want_unsorted[c]}));
            worst_wboit = std::max(worst_wboit, std::abs(double{wboit[p * 4 + c]} - double{want_wboit[c]}));
        }
    }
    EXPECT_LT(worst_unsorted, 2e-5);
    // Fixed-point sums (2^-24 per term, 2^-16 per absorbance) against float sums.
    EXPECT_LT(worst_wboit, 2e-4);
    expect_no_validation_messages();
}

TEST(Compositor, ShuffledRunsGiveBitIdenticalImages) {
    std::vector<TextRun> runs = overlapping_runs(0.6f);
    const Scene scene = render_scene(runs);
    std::mt19937 random(7);
    std::shuffle(runs.begin(), runs.end(), random);
    const Scene shuffled = render_scene(runs);
    // Submission order within the draw too.
    std::vector<DrawnGlyph> reversed(shuffled.drawn.rbegin(), shuffled.drawn.rend());
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    for (QuadPath path : {QuadPath::raster, QuadPath::compute}) {
        for (CompositeMode mode : {CompositeMode::wboit, CompositeMode::exact}) {
            const std::vector<float> a = composite(*compositor, scene, scene.drawn, mode, path);
            const std::vector<float> b = composite(*compositor, shuffled, reversed, mode, path);
            EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
                << composite_mode_name(mode) << ", " << quad_path_name(path);
        }
    }
    // Unsorted is order-dependent, and shows it: the same fragments give another image.
    const std::vector<float> a = composite(*compositor, scene, CompositeMode::unsorted);
    const std::vector<float> b = composite(*compositor, shuffled, reversed, CompositeMode::unsorted);
    EXPECT_NE(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
    expect_no_validation_messages();
}

// The compute path runs the same per-fragment code over tiles instead of rasterized quads: with
// fixed-point sums and sorted lists the images are the same to the bit.
TEST(Compositor, ComputeQuadPathMatchesTheRasterPathBitForBit) {
    std::vector<TextRun> runs = overlapping_runs(0.6f);
    runs.push_back({"efonts", -9.3f, 8.0f, {0.5f, 0.5f, 0.1f, 0.8f}, 0.25f});  // off the left and top edges
    const Scene scene = render_scene(runs);
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    for (CompositeMode mode : {CompositeMode::wboit, CompositeMode::exact}) {
        const std::vector<float> raster = composite(*compositor, scene, scene.drawn, mode, QuadPath::raster);
        const std::vector<float> computed = composite(*compositor, scene, scene.drawn, mode, QuadPath::compute);
        EXPECT_EQ(compositor->stats().path, QuadPath::compute);
        EXPECT_GT(compositor->stats().tiles, 0u);
        EXPECT_EQ(std::memcmp(raster.data(), computed.data(), raster.size() * sizeof(float)), 0)
            << composite_mode_name(mode);
    }
    // Unsorted needs the blend unit's order: it stays rasterized.
    composite(*compositor, scene, scene.drawn, CompositeMode::unsorted, QuadPath::compute);
    EXPECT_EQ(compositor->stats().path, QuadPath::raster);
    EXPECT_EQ(parse_quad_path("compute"), QuadPath::compute);
    EXPECT_FALSE(parse_quad_path("mesh"));
    expect_no_validation_messages();
}

// Glyphs whose rect is not in the atlas (a caller's mistake) draw nothing where they miss it; the
// rest of the frame is untouched and nothing reads outside the image.
TEST(Compositor, RectsOutsideTheAtlasDrawNothing) {
    const Scene scene = render_scene(overlapping_runs(0.6f));
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    std::vector<DrawnGlyph> broken = scene.drawn;
    std::vector<DrawnGlyph> kept(scene.drawn.begin() + 1, scene.drawn.end());
    broken[0].atlas_x = 1u << 20;
    for (QuadPath path : {QuadPath::raster, QuadPath::compute}) {
        const std::vector<float> a = composite(*compositor, scene, broken, CompositeMode::exact, path);
        const std::vector<float> b = composite(*compositor, scene, kept, CompositeMode::exact, path);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << quad_path_name(path);
    }
    expect_no_validation_messages();
}

// Two opaque runs at one depth: the later-drawn is in front wherever they overlap, in every frame.
TEST(Compositor, CoplanarGlyphsResolveByPaintOrder) {
    const std::vector<TextRun> runs = {
        {"HHH", 1.0f, 28.0f, {1.0f, 0.0f, 0.0f, 1.0f}, 0.5f},
        {"mmm", 4.5f, 30.0f, {0.0f, 0.0f, 1.0f, 1.0f}, 0.5f},
    };
    const Scene scene = render_scene(runs, "gray", 24.0f);
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    for (CompositeMode mode : {CompositeMode::exact, CompositeMode::wboit}) {
        const std::vector<float> first = composite(*compositor, scene, mode);
        const std::vector<float> second = composite(*compositor, scene, mode);
        EXPECT_EQ(std::memcmp(first.data(), second.data(), first.size() * sizeof(float)), 0);
        if (mode != CompositeMode::exact) continue;
        size_t both_opaque = 0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const auto& list = scene.pixels[p];
            if (list.size() < 2) continue;
            // Both glyphs fully cover the pixel: only the blue (later) one may show.
            bool all_opaque = true;
            for (const oit::Fragment& f : list) all_opaque = all_opaque && f.transmittance[0] == 0.0f;
            if (!all_opaque) continue;
            ++both_opaque;
            EXPECT_NEAR(first[p * 4 + 0], 0.0f, 1e-6) << "pixel " << p;
            EXPECT_NEAR(first[p * 4 + 2], 1.0f, 1e-6) << "pixel " << p;
        }
        EXPECT_GT(both_opaque, 0u);
    }
    expect_no_validation_messages();
}

// Opaque text through the exact mode: it hides what is behind it completely, and composited
// back to front it looks as opaque rendering (unsorted "over" in depth order) does.
TEST(Compositor, OpaqueTextHidesWhatIsBehind) {
    const std::vector<TextRun> runs = {
        {"HHH", 1.0f, 28.0f, {0.0f, 1.0f, 0.0f, 1.0f}, 0.8f},  // behind, drawn first
        {"mmm", 4.5f, 30.0f, {0.2f, 0.1f, 0.6f, 1.0f}, 0.2f},  // in front, drawn last
    };
    const Scene scene = render_scene(runs, "rgb", 24.0f);
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    const std::vector<float> layered = composite(*compositor, scene, CompositeMode::exact);
    const std::vector<float> opaque = composite(*compositor, scene, CompositeMode::unsorted);
    size_t hidden = 0;
    for (size_t p = 0; p < scene.pixels.size(); ++p) {
        const auto& list = scene.pixels[p];
        for (size_t c = 0; c < 3; ++c) {
            EXPECT_NEAR(layered[p * 4 + c], opaque[p * 4 + c], 1.0 / 255.0);
        }
        // The front glyph covers the pixel fully: exactly its colour, no green from behind.
        const bool front_opaque = !list.empty() && list.back().depth == 0.2f && list.back().transmittance[0] == 0.0f &&
                                  list.back().transmittance[1] == 0.0f && list.back().transmittance[2] == 0.0f;
        if (!front_opaque || list.size() < 2) continue;
        ++hidden;
        EXPECT_NEAR(layered[p * 4 + 0], srgb_to_linear(0.2f), 1e-7);
        EXPECT_NEAR(layered[p * 4 + 1], srgb_to_linear(0.1f), 1e-7);
        EXPECT_NEAR(layered[p * 4 + 2], srgb_to_linear(0.6f), 1e-7);
    }
    EXPECT_GT(hidden, 0u);
    expect_no_validation_messages();
}

TEST(Compositor, ExactCountsWhatItsPoolCannotHold) {
    // Three copies of the overlapping runs: more fragments than pixels.
    std::vector<TextRun> runs;
    for (float shift : {0.0f, 5.3f, 10.6f}) {
        for (TextRun run : overlapping_runs(0.5f)) {
            run.y = run.y - 8.0f + shift;
            runs.push_back(run);
        }
    }
    const Scene scene = render_scene(runs);
    CompositorCreateInfo info = compositor_info();
    info.frames_in_flight = 1;
    info.exact_nodes_per_pixel = 1;  // too few for this scene
    auto compositor = Compositor::create(info);
    ASSERT_TRUE(compositor);
    size_t fragments = 0;
    for (const auto& list : scene.pixels) fragments += list.size();
    ASSERT_GT(fragments, size_t{kWidth} * kHeight);
    composite(*compositor, scene, CompositeMode::exact);
    composite(*compositor, scene, CompositeMode::exact);  // reads the first frame's counters
    ASSERT_TRUE(compositor->stats().measured);
    EXPECT_EQ(compositor->stats().exact_lost_nodes, fragments - size_t{kWidth} * kHeight);
    expect_no_validation_messages();
}

TEST(Compositor, DepthFromViewProjection) {
    // A Vulkan perspective (depth 0 at near = 1, 1 at far = 100), looking down -z, column-major.
    const float near = 1.0f, far = 100.0f;
    float m[16] = {};
    m[0] = 1.0f;
    m[5] = 1.0f;
    m[10] = far / (near - far);
    m[11] = -1.0f;
    m[14] = far * near / (near - far);
    const float at_near[3] = {0.0f, 0.0f, -1.0f};
    const float at_far[3] = {0.3f, 0.1f, -100.0f};
    const float between[3] = {0.0f, 0.0f, -10.0f};
    const float behind[3] = {0.0f, 0.0f, 5.0f};
    const float nan[3] = {0.0f, std::nanf(""), -10.0f};
    EXPECT_NEAR(*depth_from_view_projection(m, at_near), 0.0f, 1e-6f);
    EXPECT_NEAR(*depth_from_view_projection(m, at_far), 1.0f, 1e-6f);
    const float d = *depth_from_view_projection(m, between);
    EXPECT_GT(d, 0.9f);  // perspective depth crowds towards 1
    EXPECT_LT(d, 1.0f);
    EXPECT_FALSE(depth_from_view_projection(m, behind));
    EXPECT_FALSE(depth_from_view_projection(m, nan));
}

}  // namespace
}  // namespace crisp
