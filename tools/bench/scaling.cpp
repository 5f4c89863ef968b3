// crisp-bench --suite scaling: how a frame's GPU cost follows the text on screen rather than the
// screen. Two series: the same block of text on growing canvases, and growing amounts of text on
// one canvas. Per point, a fresh renderer and tile-path compositor into an RGBA8 storage image,
// timed separately with timestamp queries: frame 1 (every glyph new, 8 samples), a refining frame
// (1 sample each), and static frames once the text has converged.
#include "bench.hpp"
#include "frame_loop.hpp"
#include "gpu_tools.hpp"
#include "vk/barriers.hpp"
#include "vk/resources.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "scaling";
constexpr VkFormat kTargetFormat = VK_FORMAT_R8G8B8A8_UNORM;
// Samples the text converges to: the ramp (8, 4, 2) and 2 frames of 1; enough to reach static text
// quickly, and the frames measured are the same as at 512.
constexpr uint32_t kSamples = 16;
constexpr uint32_t kStaticFrames = 5;

struct Point {
    std::string series;
    uint32_t width = 0, height = 0;
    size_t glyphs = 0;
    uint32_t entries = 0;
    double first_renderer_ms = 0.0, first_compositor_ms = 0.0;
    double refining_renderer_ms = 0.0, refining_compositor_ms = 0.0;  // frame 4: 1 sample per glyph
    double static_renderer_ms = 0.0, static_compositor_ms = 0.0;      // medians over the static frames
};

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values.empty() ? 0.0 : values[values.size() / 2];
}

class Scaling {
public:
    Scaling(HeadlessContext& context, const Font& font, const FrameArgs& args)
        : context_(context), font_(font), args_(args) {}

    // `glyphs` drawn on a fresh renderer and compositor into a width x height target.
    Point measure(const std::string& series, uint32_t width, uint32_t height,
                  const std::vector<GlyphInstance>& glyphs) {
        progress(kSuite, series + ": " + std::to_string(glyphs.size()) + " glyphs on " + std::to_string(width) + "x" +
                             std::to_string(height));
        auto layout = resolve_subpixel_layout(args_.layout);
        if (!layout) fail(kSuite, layout.error().message);
        FrameArgs args = args_;
        args.samples = kSamples;
        Renderer renderer = make_renderer(context_, args, *layout, font_);
        CompositorCreateInfo compositor_info = compositor_create_info(context_);
        auto compositor = Compositor::create(compositor_info);
        if (!compositor) fail(kSuite, compositor.error().message);
        if (!compositor->supports_target_format(kTargetFormat)) fail(kSuite, "the device cannot store to RGBA8");
        ImageDesc desc;
        desc.format = kTargetFormat;
        desc.width = width;
        desc.height = height;
        desc.usage = VK_IMAGE_USAGE_STORAGE_BIT;
        auto target = context_.create_image(desc);
        if (!target) fail(kSuite, target.error().message);
        const Status to_general = context_.submit_and_wait([&](VkCommandBuffer cb) {
            vk::image_barrier(context_.functions(), cb, target->handle(), VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
        });
        if (!to_general) fail(kSuite, to_general.error().message);
        const VkRect2D visible{{0, 0}, {width, height}};
        const CompositeTarget composite_target{target->view(), kTargetFormat, VK_FORMAT_UNDEFINED, visible.extent,
                                               visible};
        auto renderer_timer = tools::GpuTimer::create(context_);
        auto compositor_timer = tools::GpuTimer::create(context_);
        if (!renderer_timer || !compositor_timer) fail(kSuite, "timestamp queries are not available");

        Point point;
        point.series = series;
        point.width = width;
        point.height = height;
        point.glyphs = glyphs.size();
        std::vector<double> static_renderer, static_compositor;
        for (uint32_t frame = 0;; ++frame) {
            const bool converged_before = renderer.converged() && frame > 0;
            renderer.begin_frame();
            renderer.draw(glyphs, visible);
            const Status status = context_.submit_and_wait([&](VkCommandBuffer cb) {
                vk::memory_barrier(context_.functions(), cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess,
                                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
                renderer_timer->begin(cb, true);
                if (Status s = renderer.record(cb); !s) fail(kSuite, s.error().message);
                renderer_timer->end(cb);
                compositor_timer->begin(cb, true);
                if (Status s = compositor->record(cb, renderer.drawn_frame(), composite_target); !s) {
                    fail(kSuite, s.error().message);
                }
                compositor_timer->end(cb);
            });
            if (!status) fail(kSuite, status.error().message);
            const Result<double> renderer_ms = renderer_timer->milliseconds();
            const Result<double> compositor_ms = compositor_timer->milliseconds();
            if (!renderer_ms || !compositor_ms) fail(kSuite, "reading the timestamps failed");
            if (frame == 0) {
                point.first_renderer_ms = *renderer_ms;
                point.first_compositor_ms = *compositor_ms;
                point.entries = renderer.atlas().stats().resident_glyphs;
            } else if (frame == 3) {
                point.refining_renderer_ms = *renderer_ms;
                point.refining_compositor_ms = *compositor_ms;
            } else if (converged_before) {
                static_renderer.push_back(*renderer_ms);
                static_compositor.push_back(*compositor_ms);
                if (static_renderer.size() == kStaticFrames) break;
            }
            if (frame > 1000) fail(kSuite, "the text did not converge in 1000 frames");
        }
        point.static_renderer_ms = median(static_renderer);
        point.static_compositor_ms = median(static_compositor);
        return point;
    }

private:
    HeadlessContext& context_;
    const Font& font_;
    const FrameArgs& args_;
};

// The glyphs of a screen of text whose rects lie within `width` x `height`.
std::vector<GlyphInstance> within(const std::vector<GlyphInstance>& glyphs, uint32_t width, uint32_t height) {
    std::vector<GlyphInstance> kept;
    for (const GlyphInstance& g : glyphs) {
        if (g.x >= 0 && g.y >= 0 && g.x + static_cast<int64_t>(g.width) <= width &&
            g.y + static_cast<int64_t>(g.height) <= height) {
            kept.push_back(g);
        }
    }
    return kept;
}

}  // namespace

void run_scaling(Session& session) {
    const Options& o = session.options;
    FrameArgs args;
    if (!o.fonts.empty()) args.font = o.fonts.front();
    args.size = o.size.value_or(16.0f);
    args.layout = o.layout.value_or("rgb");
    args.sample_kind = o.sample_kind.value_or(SampleKind::rows);
    args.no_shared_rows = o.no_shared_rows;
    // The canvases: the largest is the text-amount series' canvas; the fixed block of text fills
    // the smallest.
    const uint32_t width = o.width.value_or(o.quick ? 256 : session.cpu_device ? 1280 : 3840);
    const uint32_t height = o.height.value_or(o.quick ? 128 : session.cpu_device ? 720 : 2160);
    const std::vector<uint32_t> divisors = o.quick ? std::vector<uint32_t>{2, 1} : std::vector<uint32_t>{8, 4, 2, 1};

    auto baked = bake_font_file(args.font, BakeOptions{});
    if (!baked) fail(kSuite, baked.error().message);
    auto font = Font::create(std::move(baked->asset), 1);
    if (!font) fail(kSuite, font.error().message);
    FrameArgs full = args;
    full.width = width;
    full.height = height;
    const std::vector<GlyphInstance> screen = screen_of_text(full, *font);
    const uint32_t small_w = std::max(16u, width / divisors.front()),
                   small_h = std::max(16u, height / divisors.front());
    const std::vector<GlyphInstance> block = within(screen, small_w, small_h);

    Scaling scaling(*session.context, *font, args);
    // Once untimed: the first renderer and compositor of the run pay for what a driver does once
    // (lavapipe compiles shaders at their first dispatch).
    scaling.measure("warm-up", small_w, small_h, block);
    std::vector<Point> points;
    for (const uint32_t d : divisors) {
        points.push_back(scaling.measure("same text", std::max(16u, width / d), std::max(16u, height / d), block));
    }
    for (const uint32_t d : divisors) {  // 1/d of the canvas's lines of text
        points.push_back(scaling.measure("more text", width, height, within(screen, width, height / d)));
    }

    std::fprintf(
        session.md,
        "%s at %g px, layout %s, sample kind %s. Same text: the glyphs that fit a %ux%u corner, on canvases "
        "from that to %ux%u. More text: 1/8 to all of the %ux%u canvas's lines. Per point a fresh renderer "
        "and tile-path compositor (RGBA8 storage image); GPU ms from timestamps around each record(): "
        "frame 1 (every glyph new, 8 samples), frame 4 (1 sample each) and the median of %u static frames "
        "once the text holds %u samples. One untimed point first, so that no point pays for what the "
        "driver does once.\n\n"
        "| series | canvas | glyphs | atlas entries | frame 1: renderer ms | compositor ms | frame 4: renderer "
        "ms | compositor ms | static: renderer ms | compositor ms |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        args.font.c_str(), static_cast<double>(args.size), args.layout.c_str(), sample_kind_name(args.sample_kind),
        small_w, small_h, width, height, width, height, kStaticFrames, kSamples);
    session.json.begin_object()
        .field("font", args.font)
        .field("size", args.size)
        .field("layout", args.layout)
        .field("sample_kind", sample_kind_name(args.sample_kind))
        .field("samples", kSamples)
        .key("points")
        .begin_array();
    for (const Point& p : points) {
        std::fprintf(session.md, "| %s | %ux%u | %zu | %u | %.4g | %.4g | %.4g | %.4g | %.4g | %.4g |\n",
                     p.series.c_str(), p.width, p.height, p.glyphs, p.entries, p.first_renderer_ms,
                     p.first_compositor_ms, p.refining_renderer_ms, p.refining_compositor_ms, p.static_renderer_ms,
                     p.static_compositor_ms);
        session.json.begin_object()
            .field("series", p.series)
            .field("width", p.width)
            .field("height", p.height)
            .field("glyphs", p.glyphs)
            .field("atlas_entries", p.entries)
            .field("first_renderer_ms", p.first_renderer_ms)
            .field("first_compositor_ms", p.first_compositor_ms)
            .field("refining_renderer_ms", p.refining_renderer_ms)
            .field("refining_compositor_ms", p.refining_compositor_ms)
            .field("static_renderer_ms", p.static_renderer_ms)
            .field("static_compositor_ms", p.static_compositor_ms)
            .end_object();
    }
    session.json.end_array().end_object();
}

}  // namespace crisp::bench
