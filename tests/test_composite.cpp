// The GPU compositor on lavapipe with validation on: each mode against the CPU references of
// oit_reference.hpp (built from the same atlas texels), order independence, the layered error
// bound, coplanar paint order, per-channel subpixel compositing and opaque text.
#include "composite_fixture.hpp"
#include "oit_reference.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>
#include <crisp/vulkan_context.hpp>

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
    info.max_layers = 9;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info();
    info.exact_nodes_per_pixel = 65;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info(KeyFormat::rgb);
    info.int64_atomics = false;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = compositor_info();
    info.int64_atomics = false;
    auto fallback = Compositor::create(info);
    ASSERT_TRUE(fallback);
    ASSERT_EQ(fallback->warnings().size(), 1u);  // mono keys, said so
    EXPECT_NE(fallback->warnings()[0].find("mono"), std::string::npos);
    EXPECT_EQ(parse_composite_mode("wboit"), CompositeMode::wboit);
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

TEST(Compositor, LayeredMatchesTheCpuReferenceForEveryK) {
    const Scene scene = render_scene(overlapping_runs(0.5f));
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    for (uint32_t layers : {1u, 2u, 4u, 8u}) {
        const std::vector<float> image = composite(*compositor, scene, CompositeMode::layered, layers);
        EXPECT_EQ(compositor->stats().layers, layers);
        EXPECT_FALSE(compositor->stats().mono_keys);
        double worst = 0.0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const oit::LinearRgb want = oit::composite_layered(scene.pixels[p], background_rgb(), layers);
            for (size_t c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double{image[p * 4 + c]} - double{want[c]}));
        }
        // The same keys and the same estimate; the GPU's tail transmittance is exp(-A) of fixed-point
        // absorbance where the CPU multiplies codes, and its light sums are fixed point.
        EXPECT_LT(worst, 1e-3) << "K = " << layers;
    }
    expect_no_validation_messages();
}

// Where a pixel's fragments all fit in the K layers, layered is exact up to the rounding of each
// transmittance to 8 bits. The rounding bound is max(1, n / 2) / 255 for n fragments (docs/oit.md);
// the issue asks for 1/255, and these scenes (up to 6 fragments a pixel) keep to it. Past K the error
// falls as K grows.
TEST(Compositor, LayeredIsExactWhereTheOverlapFitsAndDegradesSmoothlyPastIt) {
    const Scene scene = render_scene(overlapping_runs(0.6f));
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    const std::vector<float> exact = composite(*compositor, scene, CompositeMode::exact);
    double previous_rmse = 1e9;
    for (uint32_t layers : {1u, 2u, 4u, 8u}) {
        const std::vector<float> image = composite(*compositor, scene, CompositeMode::layered, layers);
        double sum = 0.0;
        size_t fitting = 0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const size_t n = scene.pixels[p].size();
            for (size_t c = 0; c < 3; ++c) {
                const double error = std::abs(double{image[p * 4 + c]} - double{exact[p * 4 + c]});
                sum += error * error;
                if (n <= layers) {
                    EXPECT_LE(error, 1.0 / 255.0 + 1e-6)
                        << "pixel " << p << ", " << n << " fragments, K = " << layers;
                }
            }
            fitting += n <= layers;
        }
        EXPECT_GT(fitting, 0u);
        const double rmse = std::sqrt(sum / (static_cast<double>(scene.pixels.size()) * 3.0));
        EXPECT_LE(rmse, previous_rmse + 1e-6) << "K = " << layers;
        previous_rmse = rmse;
    }
    EXPECT_LT(previous_rmse, 1.0 / 255.0);  // at K = 8 every pixel of this scene fits
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
        for (CompositeMode mode : {CompositeMode::layered, CompositeMode::wboit, CompositeMode::exact}) {
            for (uint32_t layers : {2u, 8u}) {
                if (mode != CompositeMode::layered && layers != 8u) continue;
                const std::vector<float> a = composite(*compositor, scene, scene.drawn, mode, layers, path);
                const std::vector<float> b = composite(*compositor, shuffled, reversed, mode, layers, path);
                EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
                    << composite_mode_name(mode) << " K = " << layers << ", " << quad_path_name(path);
            }
        }
    }
    // Unsorted is order-dependent, and shows it: the same fragments give another image.
    const std::vector<float> a = composite(*compositor, scene, CompositeMode::unsorted);
    const std::vector<float> b = composite(*compositor, shuffled, reversed, CompositeMode::unsorted);
    EXPECT_NE(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
    expect_no_validation_messages();
}

// The compute path runs the same per-fragment code over tiles instead of rasterized quads: with
// fixed-point sums and sorted lists the images are the same to the bit, for 64-bit and mono keys.
TEST(Compositor, ComputeQuadPathMatchesTheRasterPathBitForBit) {
    std::vector<TextRun> runs = overlapping_runs(0.6f);
    runs.push_back({"efonts", -9.3f, 8.0f, {0.5f, 0.5f, 0.1f, 0.8f}, 0.25f});  // off the left and top edges
    const Scene scene = render_scene(runs);
    for (KeyFormat keys : {KeyFormat::rgb, KeyFormat::mono}) {
        auto compositor = Compositor::create(compositor_info(keys));
        ASSERT_TRUE(compositor);
        for (CompositeMode mode : {CompositeMode::layered, CompositeMode::wboit, CompositeMode::exact}) {
            for (uint32_t layers : {1u, 3u, 8u}) {
                if (mode != CompositeMode::layered && layers != 8u) continue;
                const std::vector<float> raster =
                    composite(*compositor, scene, scene.drawn, mode, layers, QuadPath::raster);
                const std::vector<float> computed =
                    composite(*compositor, scene, scene.drawn, mode, layers, QuadPath::compute);
                EXPECT_EQ(compositor->stats().path, QuadPath::compute);
                EXPECT_GT(compositor->stats().tiles, 0u);
                EXPECT_EQ(std::memcmp(raster.data(), computed.data(), raster.size() * sizeof(float)), 0)
                    << composite_mode_name(mode) << " K = " << layers;
            }
        }
        // Unsorted needs the blend unit's order: it stays rasterized.
        composite(*compositor, scene, scene.drawn, CompositeMode::unsorted, kAutoLayers, QuadPath::compute);
        EXPECT_EQ(compositor->stats().path, QuadPath::raster);
    }
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
        const std::vector<float> a = composite(*compositor, scene, broken, CompositeMode::exact, kAutoLayers, path);
        const std::vector<float> b = composite(*compositor, scene, kept, CompositeMode::exact, kAutoLayers, path);
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
    auto compositor = Compositor::create(compositor_info(KeyFormat::automatic, true));
    ASSERT_TRUE(compositor);
    for (uint32_t layers : {1u, 4u}) {
        const std::vector<float> first = composite(*compositor, scene, CompositeMode::layered, layers);
        const std::vector<float> second = composite(*compositor, scene, CompositeMode::layered, layers);
        EXPECT_TRUE(compositor->stats().mono_keys);  // a gray layout
        EXPECT_EQ(std::memcmp(first.data(), second.data(), first.size() * sizeof(float)), 0);
        size_t both_opaque = 0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const auto& list = scene.pixels[p];
            if (list.size() < 2) continue;
            // Both glyphs fully cover the pixel: only the blue (later) one may show.
            bool all_opaque = true;
            for (const oit::Fragment& f : list) all_opaque = all_opaque && f.transmittance[0] == 0.0f;
            if (!all_opaque) continue;
            ++both_opaque;
            EXPECT_NEAR(first[p * 4 + 0], 0.0f, 1e-6) << "pixel " << p << " K = " << layers;
            EXPECT_NEAR(first[p * 4 + 2], 1.0f, 1e-6) << "pixel " << p << " K = " << layers;
        }
        EXPECT_GT(both_opaque, 0u);
        // And the whole image is exact's, within the 8-bit transmittance bound.
        const std::vector<float> exact = composite(*compositor, scene, CompositeMode::exact);
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const size_t n = scene.pixels[p].size();
            if (n > layers) continue;
            for (size_t c = 0; c < 3; ++c) {
                EXPECT_NEAR(first[p * 4 + c], exact[p * 4 + c], 1.0 / 255.0 + 1e-6);
            }
        }
    }
    expect_no_validation_messages();
}

// The same glyphs drawn twice (a caller emboldening text, say): identical keys. The seed drops the
// second of two equal keys; crisp keeps both, so layered still matches exact.
TEST(Compositor, EqualKeysAreNotLost) {
    const Scene scene = render_scene({{"Hamburg", 1.3f, 24.0f, {0.8f, 0.1f, 0.3f, 0.5f}, 0.5f}});
    std::vector<DrawnGlyph> twice = scene.drawn;
    twice.insert(twice.end(), scene.drawn.begin(), scene.drawn.end());
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    const std::vector<float> exact = composite(*compositor, scene, twice, CompositeMode::exact);
    const std::vector<float> once = composite(*compositor, scene, scene.drawn, CompositeMode::exact);
    for (uint32_t layers : {1u, 2u, 8u}) {
        const std::vector<float> layered = composite(*compositor, scene, twice, CompositeMode::layered, layers);
        double worst = 0.0, darker = 0.0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            for (size_t c = 0; c < 3; ++c) {
                worst = std::max(worst, std::abs(double{layered[p * 4 + c]} - double{exact[p * 4 + c]}));
                darker = std::max(darker, std::abs(double{once[p * 4 + c]} - double{exact[p * 4 + c]}));
            }
        }
        EXPECT_GT(darker, 0.05);  // the second copy matters
        // Two fragments per pixel at most (glyphs of one run barely overlap): within one code at
        // K >= 2; at K = 1 the copy goes to the tail, whose estimate is exact for one fragment.
        EXPECT_LT(worst, 1.0 / 255.0) << "K = " << layers;
    }
    expect_no_validation_messages();
}

// Subpixel coverage differs per channel; two coloured runs over each other must composite each
// channel with its own transmittance (64-bit keys), which mono keys cannot.
TEST(Compositor, ColouredSubpixelTextCompositesPerChannel) {
    const std::vector<TextRun> runs = {
        {"Hamburg", 1.3f, 22.0f, {1.0f, 0.8f, 0.0f, 0.9f}, 0.7f},
        {"Hamburg", 1.6f, 23.0f, {0.0f, 0.3f, 1.0f, 0.9f}, 0.3f},
    };
    const Scene scene = render_scene(runs, "rgb");
    auto rgb = Compositor::create(compositor_info(KeyFormat::rgb));
    auto mono = Compositor::create(compositor_info(KeyFormat::mono));
    ASSERT_TRUE(rgb);
    ASSERT_TRUE(mono);
    const std::vector<float> exact = composite(*rgb, scene, CompositeMode::exact);
    const std::vector<float> layered = composite(*rgb, scene, CompositeMode::layered, 4);
    const std::vector<float> layered_mono = composite(*mono, scene, CompositeMode::layered, 4);
    double worst_rgb = 0.0, worst_mono = 0.0;
    size_t channels_differ = 0;
    for (size_t p = 0; p < scene.pixels.size(); ++p) {
        const auto& list = scene.pixels[p];
        if (list.size() > 4) continue;
        for (const oit::Fragment& f : list) {
            channels_differ += f.transmittance[0] != f.transmittance[2];
        }
        for (size_t c = 0; c < 3; ++c) {
            worst_rgb = std::max(worst_rgb, std::abs(double{layered[p * 4 + c]} - double{exact[p * 4 + c]}));
            worst_mono = std::max(worst_mono, std::abs(double{layered_mono[p * 4 + c]} - double{exact[p * 4 + c]}));
        }
    }
    EXPECT_GT(channels_differ, 0u);        // the text really is subpixel
    EXPECT_LE(worst_rgb, 1.0 / 255.0);     // two fragments: within one code
    EXPECT_GT(worst_mono, 4.0 / 255.0);    // one transmittance for three channels is visibly wrong
    expect_no_validation_messages();
}

// Opaque text through the layered path: it hides what is behind it completely, and composited
// back to front it looks as opaque rendering (unsorted "over" in depth order) does.
TEST(Compositor, OpaqueTextHidesWhatIsBehind) {
    const std::vector<TextRun> runs = {
        {"HHH", 1.0f, 28.0f, {0.0f, 1.0f, 0.0f, 1.0f}, 0.8f},  // behind, drawn first
        {"mmm", 4.5f, 30.0f, {0.2f, 0.1f, 0.6f, 1.0f}, 0.2f},  // in front, drawn last
    };
    const Scene scene = render_scene(runs, "rgb", 24.0f);
    auto compositor = Compositor::create(compositor_info());
    ASSERT_TRUE(compositor);
    const std::vector<float> layered = composite(*compositor, scene, CompositeMode::layered, 8);
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
        // (Up to the 2^-24 steps of the fixed-point light sums.)
        EXPECT_NEAR(layered[p * 4 + 0], srgb_to_linear(0.2f), 1e-7);
        EXPECT_NEAR(layered[p * 4 + 1], srgb_to_linear(0.1f), 1e-7);
        EXPECT_NEAR(layered[p * 4 + 2], srgb_to_linear(0.6f), 1e-7);
    }
    EXPECT_GT(hidden, 0u);
    expect_no_validation_messages();
}

TEST(Compositor, AutoLayersFollowTheMeasuredOverlap) {
    const Scene scene = render_scene(overlapping_runs(0.5f));
    CompositorCreateInfo info = compositor_info();
    info.frames_in_flight = 1;
    auto compositor = Compositor::create(info);
    ASSERT_TRUE(compositor);
    EXPECT_TRUE(compositor->prepare_layered(QuadPath::raster));  // no pipeline built mid-frame below
    composite(*compositor, scene, CompositeMode::layered, kAutoLayers);
    EXPECT_EQ(compositor->stats().layers, kMaxCompositeLayers);  // nothing measured yet
    EXPECT_FALSE(compositor->stats().measured);
    composite(*compositor, scene, CompositeMode::layered, kAutoLayers);
    ASSERT_TRUE(compositor->stats().measured);
    const size_t overlap = max_overlap(scene);
    EXPECT_EQ(compositor->stats().max_overlap, overlap);
    EXPECT_EQ(compositor->stats().layers, std::min<size_t>(overlap, kMaxCompositeLayers));
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

// Layer buffers split where one would pass the range: the image does not change.
TEST(Compositor, LayerBuffersSplitPastTheBufferRange) {
    const Scene scene = render_scene(overlapping_runs(0.5f));
    auto whole = Compositor::create(compositor_info());
    CompositorCreateInfo info = compositor_info();
    info.max_layer_buffer_bytes = VkDeviceSize{kWidth} * kHeight * 8 * 3;  // three layers of 64-bit keys
    info.exact_nodes_per_pixel = 1;
    auto split = Compositor::create(info);
    ASSERT_TRUE(whole);
    ASSERT_TRUE(split) << split.error().message;
    for (uint32_t layers : {3u, 4u, 8u}) {
        const std::vector<float> a = composite(*whole, scene, CompositeMode::layered, layers);
        const std::vector<float> b = composite(*split, scene, CompositeMode::layered, layers);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << "K = " << layers;
    }
    // Below one layer of keys nothing fits: an error that names the range.
    info.max_layer_buffer_bytes = VkDeviceSize{kWidth} * kHeight * 8 - 1;
    auto too_small = Compositor::create(info);
    ASSERT_FALSE(too_small);
    EXPECT_EQ(too_small.error().code, ErrorCode::vulkan);
    EXPECT_NE(too_small.error().message.find("maxStorageBufferRange"), std::string::npos);
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
