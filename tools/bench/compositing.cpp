// crisp-bench --suite compositing (formerly crisp-bench-composite): what each compositing mode
// costs and how far it is from exact, for scenes of N overlapping layers of text at high and low
// alpha. Per mode (the tile path into RGBA32F and RGBA8 images, the whole frame of converged text
// with it, the draw path, and the reference modes: exact, unsorted, wboit): the GPU time of its
// record call on converged static text (Vulkan timestamp queries), the error of its image against
// the exact CPU reference (support/oit_reference) in 8-bit sRGB codes, and its bytes per pixel.
// docs/benchmarks-compositing.md.
#include "bench.hpp"
#include "gpu_tools.hpp"
#include "vk/barriers.hpp"
#include "vk/resources.hpp"
#include "image_io.hpp"
#include "json_writer.hpp"
#include "oit_reference.hpp"
#include "headless_context.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace {

constexpr uint32_t kFramesInFlight = 2;
// Frames each mode runs before the timed ones (pipelines, caches and the auto K settle), at least
// frames_in_flight: with one timed frame or more, the stats the last frame reports as measured
// (and the auto K) then come from a frame of the same mode.
constexpr uint32_t kDefaultWarmupFrames = 2;
static_assert(kDefaultWarmupFrames >= kFramesInFlight);
// ... and for at least this long (wall clock): a GPU that idled (while the CPU checked the last
// scene) runs its first frames at low clocks: on an H200 the first modes of a scene measured up
// to 5x slower with 2 warm-up frames alone.
constexpr double kDefaultWarmupMs = 500.0;
// Untimed clears of a 3840x2160 RGBA32F image recorded before each frame's timed commands. Between
// two frames the GPU idles while the CPU works (the compositor sorts the quads, the bench checks),
// and with short frames an H200's clock governor then held the SM clock at 345-900 MHz, lower the
// longer the run: the tile path's 4-layer time rose from 0.66 to 1.13 ms within 100 frames and
// depended on the modes that ran before. With 8 clears at 3840x2160 the clock stayed at 1980 MHz
// (2 were too few); docs/results/h200-composite-tiles-clocks.md. The load image has that size
// whatever the canvas: 8 clears of a 1920x1080 target did not hold the clock (32 layers: 1.43 ms
// against 0.556 with 32 clears; docs/results/h200-composite-tiles-staged-bins.md). A CPU device
// has no clock governor, and there the clears would only slow the sweep: none by default.
constexpr uint32_t kDefaultClockLoad = 8;
constexpr uint32_t kClockLoadWidth = 3840, kClockLoadHeight = 2160;
// Layer i is shifted by (i * kShiftStepX mod kShiftRangeX, i * kShiftStepY mod kShiftRangeY)
// pixels: fractional steps, so that the layers' glyphs overlap partially and at many phases.
constexpr float kShiftStepX = 1.37f, kShiftRangeX = 5.0f;
constexpr float kShiftStepY = 0.61f, kShiftRangeY = 3.0f;
constexpr float kMargin = 4.0f;
// Mid grey (sRGB 0.5) behind the text: errors show in both directions.
constexpr float kBackgroundSrgb = 0.5f;
constexpr uint32_t kExactNodeBytes = 36;       // CompositorCreateInfo::exact_nodes_per_pixel
constexpr uint32_t kTargetBytesPerPixel = 16;  // RGBA32F
constexpr uint32_t kMaxConvergeFrames = 4096;

struct Args {
    std::string font = crisp::bench::data_file("fonts/DejaVuSans.ttf");
    std::string layout = "rgb";
    float size = 18.0f;
    uint32_t width = 512, height = 256;
    std::vector<uint32_t> layers = {1, 2, 4, 8, 16, 32};
    std::vector<float> alphas = {0.9f, 0.3f};
    uint32_t frames = 10;
    uint32_t warmup = kDefaultWarmupFrames;
    double warmup_ms = kDefaultWarmupMs;
    uint32_t clock_load = kDefaultClockLoad;
    uint32_t samples = 512;
    uint32_t subpixel_steps = 4;
    crisp::QuadPath path = crisp::QuadPath::raster;
    crisp::ContrastMode contrast = crisp::ContrastMode::linear;
    std::vector<std::string> modes = {"tiled", "tiled-rebin", "tiled-rgba8", "frame",
                                      "draw",  "exact",       "unsorted",    "wboit"};
    bool cpu_check = true;
};

[[noreturn]] void fail(const std::string& message) {
    crisp::bench::fail("compositing", message);
}

// ---- Scenes

// A fixed-seed mt19937: its raw outputs are the same with every standard library (its
// distributions are not).
double unit(std::mt19937& rng) {
    return static_cast<double>(rng()) / 4294967296.0;
}

struct Scene {
    std::vector<crisp::GlyphInstance> glyphs;  // layer after layer: the submission order
    uint64_t rect_texels = 0;                  // sum of the rects' areas: no more fragments than this
    VkRect2D visible{};                        // the target: what the renderer rasterizes
};

// N copies of a screen of prose, one per layer, each shifted by a fractional offset, with its own
// colour and depth. Depths are evenly spaced in (0, 1) and shuffled, so depth order is not paint
// order; each layer is one depth plane and numbers its paint orders from 0.
Scene make_scene(const Args& args, const crisp::Font& font, const std::string& text, uint32_t layers, float alpha) {
    Scene scene;
    scene.visible = VkRect2D{{0, 0}, {args.width, args.height}};
    std::mt19937 rng(1000u + layers);
    std::vector<uint32_t> depth_rank(layers);
    for (uint32_t i = 0; i < layers; ++i) depth_rank[i] = i;
    for (uint32_t i = layers; i > 1; --i) std::swap(depth_rank[i - 1], depth_rank[rng() % i]);

    const crisp::Font* fonts[] = {&font};
    crisp::Layouter layouter;
    crisp::TextLayout laid;
    for (uint32_t i = 0; i < layers; ++i) {
        crisp::TextStyle style;
        style.size = args.size;
        for (int c = 0; c < 3; ++c) style.color[c] = static_cast<float>(0.05 + 0.9 * unit(rng));
        style.color[3] = alpha;
        style.depth = static_cast<float>(depth_rank[i] + 1) / static_cast<float>(layers + 1);
        crisp::LayoutOptions options;
        options.origin_x = kMargin + std::fmod(static_cast<float>(i) * kShiftStepX, kShiftRangeX);
        options.origin_y = kMargin + args.size + std::fmod(static_cast<float>(i) * kShiftStepY, kShiftRangeY);
        options.wrap_width = static_cast<float>(args.width) - 2.0f * kMargin - kShiftRangeX;
        options.subpixel_steps = args.subpixel_steps;
        if (crisp::Status s = layouter.layout(fonts, text, style, options, laid); !s) fail(s.error().message);
        for (const crisp::GlyphInstance& g : laid.glyphs) {
            if (g.x < 0 || g.y < 0 || g.x + static_cast<int64_t>(g.width) > args.width ||
                g.y + static_cast<int64_t>(g.height) > args.height) {
                continue;
            }
            scene.glyphs.push_back(g);
            scene.rect_texels += uint64_t{g.width} * g.height;
        }
    }
    return scene;
}

// Draws the scene until every glyph holds its samples; returns the frames it took.
uint32_t converge(crisp::HeadlessContext& context, crisp::Renderer& renderer, const Scene& scene) {
    crisp::Result<uint32_t> frames = crisp::harness::render_until_converged(
        context, renderer, kMaxConvergeFrames, [&] { renderer.draw(scene.glyphs, scene.visible); });
    if (!frames) fail(frames.error().message);
    return *frames;
}

// ---- Images and errors

// 8-bit sRGB codes of the target's RGB (premultiplied over an opaque background: alpha is 1).
std::vector<uint8_t> srgb_codes(std::span<const float> rgba, float& worst_alpha_error) {
    std::vector<uint8_t> codes(rgba.size() / 4 * 3);
    worst_alpha_error = 0.0f;
    for (size_t p = 0; p < rgba.size() / 4; ++p) {
        for (size_t c = 0; c < 3; ++c) codes[3 * p + c] = crisp::linear_to_srgb8(rgba[4 * p + c]);
        worst_alpha_error = std::max(worst_alpha_error, std::abs(rgba[4 * p + 3] - 1.0f));
    }
    return codes;
}

struct ImageError {
    double rmse = 0.0;
    int max = 0;
};

ImageError compare(const std::vector<uint8_t>& got, const std::vector<uint8_t>& want) {
    ImageError error;
    double sum_squares = 0.0;
    for (size_t i = 0; i < got.size(); ++i) {
        const int d = std::abs(int{got[i]} - int{want[i]});
        sum_squares += static_cast<double>(d * d);
        error.max = std::max(error.max, d);
    }
    error.rmse = got.empty() ? 0.0 : std::sqrt(sum_squares / static_cast<double>(got.size()));
    return error;
}

// Calls visit(pixel, fragment) for every fragment the GPU quads produce, in submission order:
// pixel (x + i, y + j) of a glyph reads atlas texel (atlas_x + i, atlas_y + j), coverage
// min(sum / (kCoverageOne * count), 1); skipped where the texel has no samples or every channel's
// opacity is 0, as the exact shader does. Every rect lies inside the target (make_scene).
template <class Visit>
void for_each_fragment(std::span<const crisp::DrawnGlyph> drawn, std::span<const uint16_t> atlas, uint32_t atlas_width,
                       uint32_t width, Visit&& visit) {
    crisp::oit::Fragment f;
    for (const crisp::DrawnGlyph& g : drawn) {
        f.depth = g.instance.depth;
        f.paint_order = g.instance.paint_order;
        for (uint32_t j = 0; j < g.instance.height; ++j) {
            for (uint32_t i = 0; i < g.instance.width; ++i) {
                const uint16_t* texel = &atlas[4 * (size_t{g.atlas_y + j} * atlas_width + g.atlas_x + i)];
                if (texel[3] == 0) continue;
                const float scale = static_cast<float>(crisp::kCoverageOne) * static_cast<float>(texel[3]);
                bool visible = false;
                for (int c = 0; c < 3; ++c) {
                    const float opacity = g.instance.color[3] * std::min(static_cast<float>(texel[c]) / scale, 1.0f);
                    visible = visible || opacity != 0.0f;
                    f.transmittance[c] = 1.0f - opacity;
                    f.light[c] = g.instance.color[c] * opacity;
                }
                if (!visible) continue;
                visit(static_cast<size_t>(g.instance.y + static_cast<int32_t>(j)) * width +
                          static_cast<size_t>(g.instance.x + static_cast<int32_t>(i)),
                      f);
            }
        }
    }
}

struct CpuExact {
    std::vector<uint8_t> codes;
    uint64_t fragments = 0;
    uint32_t max_overlap = 0;
};

// The exact composite on the CPU (oit::composite_exact, in double precision) of those fragments.
CpuExact cpu_exact(std::span<const crisp::DrawnGlyph> drawn, std::span<const uint16_t> atlas, uint32_t atlas_width,
                   uint32_t width, uint32_t height, const crisp::oit::LinearRgb& background) {
    const size_t pixels = size_t{width} * height;
    // Per-pixel lists in one array: count, prefix sum, fill.
    std::vector<size_t> first(pixels + 1, 0);
    for_each_fragment(drawn, atlas, atlas_width, width,
                      [&](size_t pixel, const crisp::oit::Fragment&) { ++first[pixel + 1]; });
    for (size_t p = 0; p < pixels; ++p) first[p + 1] += first[p];
    std::vector<crisp::oit::Fragment> fragments(first[pixels]);
    std::vector<size_t> next(first.begin(), first.end() - 1);
    for_each_fragment(drawn, atlas, atlas_width, width,
                      [&](size_t pixel, const crisp::oit::Fragment& f) { fragments[next[pixel]++] = f; });

    CpuExact result;
    result.codes.resize(pixels * 3);
    result.fragments = fragments.size();
    for (size_t p = 0; p < pixels; ++p) {
        const std::span<const crisp::oit::Fragment> list(fragments.data() + first[p], first[p + 1] - first[p]);
        result.max_overlap = std::max(result.max_overlap, static_cast<uint32_t>(list.size()));
        const crisp::oit::LinearRgb rgb = crisp::oit::composite_exact(list, background);
        for (size_t c = 0; c < 3; ++c) result.codes[3 * p + c] = crisp::linear_to_srgb8(rgb[c]);
    }
    return result;
}

// ---- Measuring

struct ModeRun {
    crisp::CompositeMode mode;
    VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;  // tiled and draw: the target image's
    bool with_renderer = false;                       // tiled: the renderer's frame timed too
    bool rebin = false;  // tiled: bin every frame (reuse_static_bins off), as for text that changes
};

// The run a --modes name stands for; nullopt for an unknown name.
std::optional<ModeRun> parse_mode_run(const std::string& name) {
    if (name == "tiled-rgba8") return ModeRun{crisp::CompositeMode::tiled, VK_FORMAT_R8G8B8A8_UNORM, false};
    if (name == "frame") return ModeRun{crisp::CompositeMode::tiled, VK_FORMAT_R32G32B32A32_SFLOAT, true};
    if (name == "tiled-rebin") return ModeRun{crisp::CompositeMode::tiled, VK_FORMAT_R32G32B32A32_SFLOAT, false, true};
    const std::optional<crisp::CompositeMode> mode = crisp::parse_composite_mode(name);
    if (!mode) return std::nullopt;
    return ModeRun{*mode};
}

bool is_reference(const ModeRun& run) {
    return run.mode != crisp::CompositeMode::tiled && run.mode != crisp::CompositeMode::draw;
}

struct Measurement {
    ModeRun run;
    crisp::CompositorStats stats;  // after the last frame
    uint32_t warmup_frames = 0;
    std::vector<double> gpu_ms;  // the timed frames
    double median_ms = 0.0;
    ImageError error;  // against the exact mode
    std::vector<uint8_t> codes;
};

struct SceneResult {
    uint32_t layers = 0;
    float alpha = 0.0f;
    size_t glyphs = 0;
    size_t drawn = 0;
    uint32_t converge_frames = 0;
    uint32_t exact_nodes_per_pixel = 0;
    std::optional<CpuExact> cpu;  // codes dropped once compared
    ImageError exact_vs_cpu;
    std::vector<Measurement> modes;
};

std::string mode_label(const ModeRun& run) {
    if (run.with_renderer) return "frame: renderer + tiled";
    std::string label = crisp::composite_mode_name(run.mode);
    if (run.format == VK_FORMAT_R8G8B8A8_UNORM) label += " rgba8";
    if (run.rebin) label += ", binned every frame";
    return label;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n == 0 ? 0.0 : n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The tile and draw paths' target images: cleared to the background before each frame, read back
// after the last.
struct Targets {
    crisp::Image rgba32f;  // storage, colour attachment
    crisp::Image rgba8;    // storage
    crisp::Image load;     // kClockLoadWidth x kClockLoadHeight RGBA32F, cleared for the clock load
    const crisp::Image& of(VkFormat format) const { return format == VK_FORMAT_R8G8B8A8_UNORM ? rgba8 : rgba32f; }
};

// Every earlier use of a target image, as the source of its barriers.
constexpr VkPipelineStageFlags kAnyStage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
constexpr VkAccessFlags kAnyAccess = VK_ACCESS_MEMORY_WRITE_BIT | VK_ACCESS_MEMORY_READ_BIT;

struct Bench {
    const Args& args;
    crisp::HeadlessContext& context;
    crisp::Renderer& renderer;
    const crisp::tools::GpuTimer& timer;
    crisp::Buffer& target_readback;
    Targets& targets;
    std::vector<std::string>& warnings;

    void warn(const std::string& text) {
        std::fprintf(stderr, "warning: %s\n", text.c_str());
        warnings.push_back(text);
    }

    // The run's commands: the tile path, the draw path in a dynamic-rendering pass, or a reference mode.
    void record(VkCommandBuffer cb, crisp::Compositor& compositor, const ModeRun& run,
                const crisp::CompositeParams& params) {
        const VkRect2D rect{{0, 0}, {args.width, args.height}};
        const crisp::Image& image = targets.of(run.format);
        crisp::Status s;
        if (run.mode == crisp::CompositeMode::tiled) {
            if (run.with_renderer) s = renderer.record(cb);
            if (s) {
                const crisp::CompositeTarget target{image.view(), run.format, VK_FORMAT_UNDEFINED, rect.extent, rect};
                s = compositor.record(cb, renderer.drawn_frame(), target);
            }
        } else if (run.mode == crisp::CompositeMode::draw) {
            crisp::tools::begin_rendering_over(cb, image.view(), rect);
            s = compositor.record_draw(cb, renderer.drawn_frame(), rect);
            vkCmdEndRendering(cb);
        } else {
            s = compositor.record_reference(cb, renderer.drawn_frame(), params);
        }
        if (!s) fail(mode_label(run) + ": " + s.error().message);
    }

    // Clears the target image of `format` to the background.
    void clear_target(VkCommandBuffer cb, VkFormat format, const crisp::CompositeParams& params) {
        clear_image(cb, targets.of(format).handle(), format, params);
    }

    void clear_image(VkCommandBuffer cb, VkImage image, VkFormat format, const crisp::CompositeParams& params) {
        const crisp::vk::Functions& fn = context.functions();
        crisp::vk::image_barrier(fn, cb, image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, kAnyStage, kAnyAccess,
                                 VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        VkClearColorValue colour{};
        for (int c = 0; c < 4; ++c) colour.float32[c] = params.background[c];
        if (format == VK_FORMAT_R8G8B8A8_UNORM) {
            for (int c = 0; c < 3; ++c) colour.float32[c] = kBackgroundSrgb;  // the image holds sRGB codes
        }
        const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdClearColorImage(cb, image, VK_IMAGE_LAYOUT_GENERAL, &colour, 1, &range);
        crisp::vk::image_barrier(fn, cb, image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, kAnyStage, kAnyAccess,
                                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                     VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    }

    void read_back(VkCommandBuffer cb, crisp::Compositor& compositor, const ModeRun& run) {
        if (is_reference(run)) {
            compositor.record_target_readback(cb, target_readback.handle());
            return;
        }
        const VkImage image = targets.of(run.format).handle();
        const crisp::vk::Functions& fn = context.functions();
        crisp::vk::image_barrier(fn, cb, image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                 kAnyStage, kAnyAccess, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {args.width, args.height, 1};
        vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target_readback.handle(), 1, &region);
        crisp::vk::image_barrier(fn, cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                                 kAnyStage, kAnyAccess, VK_PIPELINE_STAGE_TRANSFER_BIT, 0);
        crisp::vk::memory_barrier(fn, cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                                  VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    }

    // 8-bit sRGB codes of the image read back (RGBA32F premultiplied over an opaque background, or
    // R8G8B8A8 holding the codes).
    std::vector<uint8_t> codes_read_back(const ModeRun& run, const std::string& scene_name) {
        const size_t pixels = size_t{args.width} * args.height;
        if (!is_reference(run) && run.format == VK_FORMAT_R8G8B8A8_UNORM) {
            std::vector<uint8_t> codes(pixels * 3);
            const std::byte* bytes = target_readback.mapped().data();
            for (size_t p = 0; p < pixels; ++p) {
                for (size_t c = 0; c < 3; ++c) codes[3 * p + c] = static_cast<uint8_t>(bytes[4 * p + c]);
            }
            return codes;
        }
        std::vector<float> rgba(pixels * 4);
        std::memcpy(rgba.data(), target_readback.mapped().data(), rgba.size() * sizeof(float));
        float alpha_error = 0.0f;
        std::vector<uint8_t> codes = srgb_codes(rgba, alpha_error);
        if (alpha_error > 1e-3f) {
            warn(scene_name + ", " + mode_label(run) + ": target alpha off 1 by up to " + std::to_string(alpha_error) +
                 " over an opaque background");
        }
        return codes;
    }

    Measurement measure(crisp::Compositor& compositor, const Scene& scene, const std::string& scene_name,
                        const ModeRun& run) {
        Measurement m;
        m.run = run;
        crisp::CompositeParams params;
        params.mode = run.mode;
        params.path = args.path;
        const float grey = crisp::srgb_to_linear(kBackgroundSrgb);
        params.background[0] = params.background[1] = params.background[2] = grey;
        params.background[3] = 1.0f;
        // One frame; its GPU time in ms.
        auto frame = [&](bool last) {
            // The text has converged: the renderer would record nothing but a barrier, and its
            // drawn() list stays valid until its next begin_frame(). Leaving it out keeps the GPU's
            // idle gaps between frames short; the frame run puts it in, with its CPU side.
            if (run.with_renderer) {
                renderer.begin_frame();
                renderer.draw(scene.glyphs, scene.visible);
            }
            const crisp::Status status = context.submit_and_wait([&](VkCommandBuffer cb) {
                for (uint32_t k = 0; k < args.clock_load; ++k) {
                    clear_image(cb, targets.load.handle(), VK_FORMAT_R32G32B32A32_SFLOAT, params);
                }
                if (!is_reference(run)) clear_target(cb, run.format, params);  // the tile and draw paths' image
                // The clears are not the mode's cost.
                timer.begin(cb, !is_reference(run) || args.clock_load > 0);
                record(cb, compositor, run, params);
                timer.end(cb);
                if (last) read_back(cb, compositor, run);
            });
            if (!status) fail(status.error().message);
            const crisp::Result<double> ms = timer.milliseconds();
            if (!ms) fail(ms.error().message);
            return *ms;
        };
        {
            // The compositor's slots hold the frames the run before composited (the renderer's last
            // ones, or one again and again): frames of the renderer alone move past them, so that
            // this run's first record call finds slots it may reuse (the frame-slot rule of
            // compositor.hpp); the text has converged, so they draw the same.
            for (uint32_t k = 0; k < kFramesInFlight; ++k) {
                renderer.begin_frame();
                renderer.draw(scene.glyphs, scene.visible);
                crisp::Status recorded;
                const crisp::Status status =
                    context.submit_and_wait([&](VkCommandBuffer cb) { recorded = renderer.record(cb); });
                if (!recorded || !status) fail((recorded ? status : recorded).error().message);
            }
        }
        const auto start = std::chrono::steady_clock::now();
        auto elapsed_ms = [&] {
            return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        };
        while (m.warmup_frames < args.warmup || elapsed_ms() < args.warmup_ms) {
            frame(false);
            ++m.warmup_frames;
        }
        for (uint32_t f = 0; f < args.frames; ++f) m.gpu_ms.push_back(frame(f + 1 == args.frames));
        m.stats = compositor.stats();
        m.median_ms = median(m.gpu_ms);
        m.codes = codes_read_back(run, scene_name);
        return m;
    }
};

// ---- Output

struct Header {
    std::string device, driver_name, driver_info, api;
    uint32_t driver_version = 0;
    bool storage_without_format = false;
    std::string layout;
    std::vector<std::string> compositor_warnings;
    std::vector<crisp::ShaderStatistic> shader_statistics;  // the first compositor's
};

double buffer_bytes_per_pixel(const Measurement& m, const Args& args) {
    return static_cast<double>(m.stats.buffer_bytes) / (static_cast<double>(args.width) * args.height);
}

void write_mode(crisp::JsonWriter& json, const Args& args, const Measurement& m) {
    json.begin_object()
        .field("mode", crisp::composite_mode_name(m.run.mode))
        .field("warmup_frames", m.warmup_frames)
        .field("gpu_ms_median", m.median_ms)
        .field("gpu_ms", m.gpu_ms)
        .field("rmse", m.error.rmse)
        .field("max", m.error.max)
        .field("buffer_bytes", m.stats.buffer_bytes)
        .field("buffer_bytes_per_pixel", buffer_bytes_per_pixel(m, args))
        .field("quads", m.stats.quads)
        .field("bins_reused", m.stats.bins_reused)
        .field("measured", m.stats.measured)
        .field("max_overlap", m.stats.max_overlap)
        .field("tail_pixels", m.stats.tail_pixels)
        .field("exact_lost_nodes", m.stats.exact_lost_nodes)
        .field("exact_dropped", m.stats.exact_dropped)
        .field("label", mode_label(m.run))
        .field("busy_tiles", m.stats.busy_tiles)
        .field("exact_tiles", m.stats.exact_tiles)
        .field("layered_tiles", m.stats.layered_tiles)
        .field("tile_pairs", m.stats.tile_pairs)
        .end_object();
}

void write_scene(crisp::JsonWriter& json, const Args& args, const SceneResult& r) {
    json.begin_object()
        .field("layers", r.layers)
        .field("alpha", r.alpha)
        .field("glyphs", r.glyphs)
        .field("drawn_glyphs", r.drawn)
        .field("converge_frames", r.converge_frames)
        .field("exact_nodes_per_pixel", r.exact_nodes_per_pixel);
    if (r.cpu) {
        json.field("cpu_fragments", r.cpu->fragments).field("cpu_max_overlap", r.cpu->max_overlap).key("exact_vs_cpu");
        json.begin_object().field("rmse", r.exact_vs_cpu.rmse).field("max", r.exact_vs_cpu.max).end_object();
    }
    json.key("modes").begin_array();
    for (const Measurement& m : r.modes) write_mode(json, args, m);
    json.end_array().end_object();
}

void to_json(crisp::JsonWriter& json, const Args& args, const Header& header, const std::vector<SceneResult>& scenes,
             const std::vector<std::string>& warnings) {
    json.begin_object()
        .field("device", header.device)
        .field("driver_name", header.driver_name)
        .field("driver_info", header.driver_info)
        .field("driver_version", header.driver_version)
        .field("api_version", header.api)
        .field("storage_without_format", header.storage_without_format)
        .field("layout", header.layout)
        .field("quad_path", crisp::quad_path_name(args.path))
        .field("contrast", args.contrast == crisp::ContrastMode::linear ? "linear" : "corrected");
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.field("font", args.font)
        .field("size", args.size)
        .field("samples", args.samples)
        .field("subpixel_steps", args.subpixel_steps)
        .field("warmup_frames", args.warmup)
        .field("warmup_ms", args.warmup_ms)
        .field("clock_load", args.clock_load)
        .field("timed_frames", args.frames)
        .field("background_srgb", kBackgroundSrgb)
        .field("target_bytes_per_pixel", kTargetBytesPerPixel);
    json.key("scenes").begin_array();
    for (const SceneResult& r : scenes) write_scene(json, args, r);
    json.end_array().field("warnings", warnings).end_object();
}

void print_markdown(std::FILE* out, const Args& args, const Header& header, const std::vector<SceneResult>& scenes,
                    const std::vector<std::string>& warnings) {
    std::fprintf(out, "Device: %s, driver %s (%s); Vulkan %s in use.\n", header.device.c_str(),
                 header.driver_name.c_str(), header.driver_info.c_str(), header.api.c_str());
    std::fprintf(out,
                 "Reference quad passes: %s. Contrast %s. Canvas %ux%u; %s at %g px, layout %s, %u "
                 "subpixel steps, %u samples per glyph; background sRGB %g grey.\n",
                 crisp::quad_path_name(args.path),
                 args.contrast == crisp::ContrastMode::linear ? "linear" : "corrected", args.width, args.height,
                 args.font.c_str(), static_cast<double>(args.size), header.layout.c_str(), args.subpixel_steps,
                 args.samples, static_cast<double>(kBackgroundSrgb));
    for (const std::string& w : header.compositor_warnings) std::fprintf(out, "Compositor: %s.\n", w.c_str());
    const std::string load = args.clock_load == 0
                                 ? "no clock load"
                                 : "each frame after " + std::to_string(args.clock_load) + " untimed clears of a " +
                                       std::to_string(kClockLoadWidth) + "x" + std::to_string(kClockLoadHeight) +
                                       " RGBA32F image that keep the GPU's clocks up";
    std::fprintf(out,
                 "GPU ms: median of %u frames after at least %u warm-up frames and %g ms, timestamps around the "
                 "mode's record call alone (frame: the renderer's record() of the converged text too), %s. "
                 "RMSE and max: 8-bit sRGB codes against %s, over all pixels and channels. B/px: the buffers the "
                 "mode uses (CompositorStats::buffer_bytes / pixels: the tile and draw paths' quads and bins, the "
                 "reference modes' per-pixel buffers); the target image adds %u B/px (RGBA32F) or 4 (rgba8).\n",
                 args.frames, args.warmup, args.warmup_ms, load.c_str(),
                 args.cpu_check ? "the exact CPU reference (double precision, every fragment)" : "the exact mode",
                 kTargetBytesPerPixel);
    for (const float alpha : args.alphas) {
        std::fprintf(out, "\n### alpha %g\n\n", static_cast<double>(alpha));
        std::fprintf(
            out,
            "| layers | mode | GPU ms | RMSE | max | B/px | max overlap | tail pixels | tiles: exact / layered |\n"
            "|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
        for (const SceneResult& r : scenes) {
            if (r.alpha != alpha) continue;
            for (const Measurement& m : r.modes) {
                const bool exact = m.run.mode == crisp::CompositeMode::exact;
                const bool tiled = m.run.mode == crisp::CompositeMode::tiled;
                char error[64] = "reference";
                if (!exact || args.cpu_check)
                    std::snprintf(error, sizeof error, "%.3f | %d", m.error.rmse, m.error.max);
                char overlap[32] = "";
                if ((exact || tiled) && m.stats.measured)
                    std::snprintf(overlap, sizeof overlap, "%u", m.stats.max_overlap);
                char tail[32] = "";
                if (tiled && m.stats.measured) std::snprintf(tail, sizeof tail, "%u", m.stats.tail_pixels);
                char tiles[48] = "";
                if (tiled && m.stats.measured) {
                    std::snprintf(tiles, sizeof tiles, "%u / %u", m.stats.exact_tiles, m.stats.layered_tiles);
                }
                std::fprintf(out, "| %u | %s | %.4g | %s%s | %.2f | %s | %s | %s |\n", r.layers,
                             mode_label(m.run).c_str(), m.median_ms, error, exact && !args.cpu_check ? " | " : "",
                             buffer_bytes_per_pixel(m, args), overlap, tail, tiles);
            }
        }
    }
    std::fprintf(out,
                 "\n### Scenes and the exact mode\n\n"
                 "| layers | alpha | glyphs | frames to converge | fragments / px | max overlap | exact nodes / px | "
                 "lost nodes | dropped | exact vs CPU: RMSE | max |\n"
                 "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const SceneResult& r : scenes) {
        const Measurement* exact = nullptr;
        for (const Measurement& m : r.modes) {
            if (m.run.mode == crisp::CompositeMode::exact) exact = &m;
        }
        const double pixels = static_cast<double>(args.width) * args.height;
        std::fprintf(out, "| %u | %g | %zu | %u | ", r.layers, static_cast<double>(r.alpha), r.drawn,
                     r.converge_frames);
        if (r.cpu)
            std::fprintf(out, "%.2f | %u | ", static_cast<double>(r.cpu->fragments) / pixels, r.cpu->max_overlap);
        else
            std::fprintf(out, " | %u | ", exact ? exact->stats.max_overlap : 0u);
        std::fprintf(out, "%u | %llu | %llu | ", r.exact_nodes_per_pixel,
                     static_cast<unsigned long long>(exact ? exact->stats.exact_lost_nodes : 0),
                     static_cast<unsigned long long>(exact ? exact->stats.exact_dropped : 0));
        if (r.cpu)
            std::fprintf(out, "%.3f | %d |\n", r.exact_vs_cpu.rmse, r.exact_vs_cpu.max);
        else
            std::fprintf(out, "not checked | |\n");
    }
    if (!warnings.empty()) {
        std::fprintf(out, "\nWarnings:\n\n");
        for (const std::string& w : warnings) std::fprintf(out, "- %s\n", w.c_str());
    }
}

crisp::Renderer make_renderer(const crisp::HeadlessContext& context, const Args& args,
                              const crisp::SubpixelLayout& layout, const crisp::Font& font) {
    crisp::RendererCreateInfo info = crisp::renderer_create_info(context);
    info.frames_in_flight = kFramesInFlight;
    info.atlas.max_samples = args.samples;
    info.atlas.frame_budget = uint64_t{1} << 50;  // unbounded: converge in as few frames as the ramp allows
    info.layout = layout;
    info.contrast.mode = args.contrast;
    auto renderer = crisp::Renderer::create(info);
    if (!renderer) fail(renderer.error().message);
    if (auto s = renderer->add_font(font); !s) fail(s.error().message);
    return std::move(*renderer);
}

// Enough prose to fill the canvas: lines at the given size, generously estimated.
std::string prose_for(const Args& args) {
    const std::string prose =
        "The quick brown fox jumps over the lazy dog. Pack my box with five dozen liquor jugs. Sphinx of "
        "black quartz, judge my vow! How vexingly quick daft zebras jump; 0123456789. ";
    const double characters = (static_cast<double>(args.width) / (0.3 * static_cast<double>(args.size)) + 1.0) *
                              (static_cast<double>(args.height) / static_cast<double>(args.size) + 1.0);
    std::string text;
    while (static_cast<double>(text.size()) < characters) text += prose;
    return text;
}

// The tile and draw paths' target images, and the clock load's image where there is a load, zeroed
// and in GENERAL, where the frames keep them.
void make_targets(crisp::HeadlessContext& context, const Args& args, Targets& targets) {
    struct TargetDesc {
        crisp::Image* image;
        VkFormat format;
        VkImageUsageFlags usage;
        uint32_t width, height;
    };
    std::vector<TargetDesc> target_descs = {
        {&targets.rgba32f, VK_FORMAT_R32G32B32A32_SFLOAT,
         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, args.width, args.height},
        {&targets.rgba8, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT, args.width, args.height},
    };
    if (args.clock_load > 0) {
        target_descs.push_back({&targets.load, VK_FORMAT_R32G32B32A32_SFLOAT, 0, kClockLoadWidth, kClockLoadHeight});
    }
    for (const TargetDesc& d : target_descs) {
        crisp::ImageDesc desc;
        desc.format = d.format;
        desc.width = d.width;
        desc.height = d.height;
        desc.usage = d.usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        auto made = context.create_image(desc);
        if (!made) fail(made.error().message);
        *d.image = std::move(*made);
        const std::vector<std::byte> zeros(size_t{d.width} * d.height * crisp::format_texel_size(d.format));
        if (crisp::Status st = context.upload(*d.image, zeros, VK_IMAGE_LAYOUT_GENERAL); !st) fail(st.error().message);
    }
}

Header make_header(const crisp::HeadlessContext& context, bool storage_without_format, const std::string& layout) {
    Header header;
    header.device = context.device_name();
    header.driver_name = context.driver_name();
    header.driver_info = context.driver_info();
    header.driver_version = context.driver_version();
    header.api = crisp::vk::version_string(context.api_version());
    header.storage_without_format = storage_without_format;
    header.layout = layout;
    return header;
}

// One scene after another: the text converged, a compositor for it, every mode measured, and
// each mode's error against the reference.
struct SceneRunner {
    const Args& args;
    crisp::HeadlessContext& context;
    crisp::Renderer& renderer;
    Bench& bench;
    Header& header;
    const crisp::Font& font;
    const std::string& text;
    const std::vector<ModeRun>& runs;
    crisp::Buffer* atlas_readback;  // with the CPU check only
    uint64_t pool_cap;              // exact nodes per pixel the device's buffers allow

    // The compositor of every mode, and one that bins every frame (tiled-rebin).
    std::pair<crisp::Compositor, crisp::Compositor> make_compositors(uint32_t exact_nodes_per_pixel) {
        crisp::CompositorCreateInfo info = crisp::compositor_create_info(context);
        info.width = args.width;
        info.height = args.height;
        info.frames_in_flight = kFramesInFlight;
        info.exact_nodes_per_pixel = exact_nodes_per_pixel;
        info.reference_modes = std::any_of(runs.begin(), runs.end(), is_reference);
        info.draw_format = VK_FORMAT_R32G32B32A32_SFLOAT;
        auto compositor = crisp::Compositor::create(info);
        if (!compositor) fail(compositor.error().message);
        info.reuse_static_bins = false;
        info.reference_modes = false;
        auto rebinning = crisp::Compositor::create(info);
        if (!rebinning) fail(rebinning.error().message);
        if (header.shader_statistics.empty()) header.shader_statistics = compositor->shader_statistics();
        for (const std::string& w : compositor->warnings()) {
            std::vector<std::string>& seen = header.compositor_warnings;
            if (std::find(seen.begin(), seen.end(), w) == seen.end()) seen.push_back(w);
        }
        return {std::move(*compositor), std::move(*rebinning)};
    }

    // Each mode's error against the exact CPU reference (or, without it, the exact mode).
    void compare_modes(SceneResult& result, const Measurement* exact, const std::string& name) {
        if (!args.cpu_check) {
            for (Measurement& m : result.modes) m.error = compare(m.codes, exact->codes);
            return;
        }
        std::fprintf(stderr, "%s: CPU reference\n", name.c_str());
        const crisp::Status status = context.submit_and_wait(
            [&](VkCommandBuffer cb) { renderer.record_atlas_readback(cb, atlas_readback->handle()); });
        if (!status) fail(status.error().message);
        const crisp::AtlasConfig& atlas_config = renderer.atlas().config();
        std::vector<uint16_t> atlas(size_t{atlas_config.width} * atlas_config.height * 4);
        std::memcpy(atlas.data(), atlas_readback->mapped().data(), atlas.size() * sizeof(uint16_t));
        const float grey = crisp::srgb_to_linear(kBackgroundSrgb);
        result.cpu =
            cpu_exact(renderer.drawn(), atlas, atlas_config.width, args.width, args.height, {grey, grey, grey});
        if (exact) result.exact_vs_cpu = compare(exact->codes, result.cpu->codes);
        for (Measurement& m : result.modes) m.error = compare(m.codes, result.cpu->codes);
        result.cpu->codes = {};
    }

    SceneResult run(uint32_t layers, float alpha) {
        const std::string name = std::to_string(layers) + " layers, alpha " + std::to_string(alpha).substr(0, 4);
        std::fprintf(stderr, "%s: laying out\n", name.c_str());
        const Scene scene = make_scene(args, font, text, layers, alpha);
        SceneResult result;
        result.layers = layers;
        result.alpha = alpha;
        result.glyphs = scene.glyphs.size();
        std::fprintf(stderr, "%s: %zu glyphs, converging\n", name.c_str(), scene.glyphs.size());
        result.converge_frames = converge(context, renderer, scene);
        if (!renderer.converged()) bench.warn(name + ": the text did not converge");
        result.drawn = renderer.drawn().size();
        if (renderer.stats().failed_glyphs > 0) {
            bench.warn(name + ": " + std::to_string(renderer.stats().failed_glyphs) +
                       " glyphs did not fit the atlas and are not drawn");
        }

        // The pool holds every fragment when it has a node per texel of every rect.
        const uint64_t pixels = uint64_t{args.width} * args.height;
        const uint64_t wanted = std::max<uint64_t>(1, (scene.rect_texels + pixels - 1) / pixels);
        result.exact_nodes_per_pixel = static_cast<uint32_t>(std::min(wanted, pool_cap));
        if (wanted > pool_cap) {
            bench.warn(name + ": the exact node pool is capped at " + std::to_string(pool_cap) +
                       " nodes per pixel (64, or maxStorageBufferRange) below the " + std::to_string(wanted) +
                       " the rects could need");
        }
        auto [compositor, rebinning] = make_compositors(result.exact_nodes_per_pixel);
        for (const ModeRun& run : runs) {
            std::fprintf(stderr, "%s: %s\n", name.c_str(), mode_label(run).c_str());
            result.modes.push_back(bench.measure(run.rebin ? rebinning : compositor, scene, name, run));
        }
        const Measurement* exact = nullptr;
        for (const Measurement& m : result.modes) {
            if (m.run.mode == crisp::CompositeMode::exact) exact = &m;
        }
        if (exact && (exact->stats.exact_lost_nodes > 0 || exact->stats.exact_dropped > 0)) {
            bench.warn(name + ": the exact mode lost " + std::to_string(exact->stats.exact_lost_nodes) +
                       " fragments (node pool) and dropped " + std::to_string(exact->stats.exact_dropped) +
                       " (past 64 per pixel): it is not exact here");
        }
        if (exact && !exact->stats.measured) bench.warn(name + ": the exact mode's stats were not measured");
        compare_modes(result, exact, name);
        for (Measurement& m : result.modes) m.codes = {};
        return result;
    }
};

// The suite's arguments: the options given, else its defaults (smaller with --quick).
Args args_from(const crisp::bench::Session& session) {
    const crisp::bench::Options& o = session.options;
    Args args;
    if (!o.fonts.empty()) args.font = o.fonts.front();
    if (o.layout) args.layout = *o.layout;
    args.size = o.size.value_or(args.size);
    args.width = o.width.value_or(o.quick ? 128 : args.width);
    args.height = o.height.value_or(o.quick ? 64 : args.height);
    args.layers = o.layers;
    args.alphas = o.alphas;
    args.modes = o.modes;
    // --quick, and a CPU device (the sweep scripts/bench_compositing.sh ran on lavapipe), take
    // fewer scenes where the options do not name them.
    if ((o.quick || session.cpu_device) && !o.scenes_given) {
        args.layers = o.quick ? std::vector<uint32_t>{1, 4} : std::vector<uint32_t>{1, 4, 32};
        args.alphas = {0.9f};
    }
    args.frames = o.frames.value_or(o.quick ? 2 : args.frames);
    args.warmup = o.warmup.value_or(args.warmup);
    args.warmup_ms = o.warmup_ms.value_or(o.quick ? 0.0 : args.warmup_ms);
    args.clock_load = o.clock_load.value_or(session.cpu_device ? 0 : o.quick ? 1 : args.clock_load);
    args.samples = o.samples.value_or(o.quick ? 16 : args.samples);
    args.subpixel_steps = o.subpixel_steps;
    args.path = o.quad_path;
    args.cpu_check = o.cpu_check;
    args.contrast = o.contrast;
    return args;
}

}  // namespace

void crisp::bench::run_compositing(Session& session) {
    const Args args = args_from(session);
    std::vector<ModeRun> runs;
    for (const std::string& name : args.modes) runs.push_back(*parse_mode_run(name));  // checked by parse_options
    crisp::HeadlessContext* context = session.context;

    auto baked = crisp::bake_font_file(args.font, crisp::BakeOptions{});
    if (!baked) ::fail(baked.error().message);
    auto font = crisp::Font::create(std::move(baked->asset), 1);
    if (!font) ::fail(font.error().message);
    auto layout = crisp::resolve_subpixel_layout(args.layout);
    if (!layout) ::fail(layout.error().message);
    crisp::Renderer renderer = make_renderer(*context, args, *layout, *font);
    const std::string text = prose_for(args);

    auto timer = crisp::tools::GpuTimer::create(*context);
    if (!timer) ::fail(timer.error().message);
    const size_t pixels = size_t{args.width} * args.height;
    auto target_readback = context->create_buffer(pixels * 4 * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                  crisp::MemoryUsage::readback);
    if (!target_readback) ::fail(target_readback.error().message);
    std::optional<crisp::Buffer> atlas_readback;
    if (args.cpu_check) {
        const crisp::AtlasConfig& atlas_config = renderer.atlas().config();
        auto buffer = context->create_buffer(size_t{atlas_config.width} * atlas_config.height * 4 * sizeof(uint16_t),
                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT, crisp::MemoryUsage::readback);
        if (!buffer) ::fail(buffer.error().message);
        atlas_readback = std::move(*buffer);
    }
    Targets targets;
    make_targets(*context, args, targets);

    std::vector<std::string> warnings;
    Bench bench{args, *context, renderer, *timer, *target_readback, targets, warnings};
    Header header = make_header(*context, session.storage_without_format, layout->name);
    const uint64_t range = context->properties().limits.maxStorageBufferRange;
    const uint64_t pool_cap =
        std::min<uint64_t>(crisp::kMaxExactFragmentsPerPixel, range / (uint64_t{kExactNodeBytes} * pixels));
    SceneRunner scenes{
        args,    *context, renderer, bench, header, *font, text, runs, atlas_readback ? &*atlas_readback : nullptr,
        pool_cap};
    std::vector<SceneResult> results;
    for (const uint32_t layers : args.layers) {
        for (const float alpha : args.alphas) results.push_back(scenes.run(layers, alpha));
    }

    to_json(session.json, args, header, results, warnings);
    print_markdown(session.md, args, header, results, warnings);
    if (session.options.shader_stats) crisp::tools::print_shader_statistics(session.md, header.shader_statistics);
    for (const std::string& w : warnings) session.warnings.push_back("compositing: " + w);
}
