// crisp-bench --suite colour: what colour glyphs cost beside monochrome text (docs/colour.md). Three
// screens of the same number of glyphs at the same size: bitmap emoji (Noto Color Emoji, one image
// layer each), the COLRv1 test font's colour glyphs (gradients, transforms, composites: several
// layers each) and DejaVu Sans letters. Per screen: frame 1 (every glyph new: layout, draw and
// record on the CPU; the renderer's record and the tile path's composite on the GPU, each between
// timestamp queries) and a frame once converged (the same layout drawn again), with the quads, the
// colour layers and paints, the bitmap uploads, and the GPU ms per quad.
#include "bench.hpp"
#include "gpu_tools.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "colour";
constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr float kMargin = 4.0f;
// Glyphs a line holds: the widest glyph measured (Noto Color Emoji's advance, 2550/2048 em) with room
// to spare, so that every screen has the same lines of the same count.
constexpr float kPitchEm = 1.3f;
constexpr float kLineEm = 1.25f;
constexpr uint32_t kMaxFrames = 1000;
const char* const kNotoColorEmoji = "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf";

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct ScreenSpec {
    std::string name;  // "bitmap", "colrv1", "monochrome"
    std::string font;
    std::vector<uint32_t> codepoints;  // cycled through
};

// One timed frame.
struct FrameCost {
    double layout_ms = 0.0;     // CPU: layout_text of the whole screen (frame 1 only)
    double cpu_ms = 0.0;        // CPU: begin_frame, draw and both records
    double raster_ms = 0.0;     // GPU: Renderer::record
    double composite_ms = 0.0;  // GPU: Compositor::record (the tile path)
    uint32_t quads = 0;
    uint32_t colour_layers = 0;
    uint32_t frame_paints = 0;
    uint32_t bitmap_uploads = 0;
    uint32_t bitmap_misses = 0;
    uint32_t work_items = 0;

    double gpu_ms() const { return raster_ms + composite_ms; }
    double us_per_quad() const { return quads ? gpu_ms() * 1e3 / quads : 0.0; }
};

struct ScreenResult {
    ScreenSpec spec;
    std::string skipped;  // why the screen was not measured; empty when it was
    uint32_t glyphs = 0;  // shaped glyphs on the screen
    uint32_t colour_glyphs = 0;
    uint32_t instances = 0;  // layout instances: a colour glyph's layers count one each
    uint32_t frames = 0;     // frames to converge
    bool converged = false;
    uint32_t atlas_entries = 0;
    FrameCost first, last;
};

std::string utf8(uint32_t c) {
    if (c < 0x80) return std::string(1, static_cast<char>(c));
    if (c < 0x800) return {static_cast<char>(0xC0 | (c >> 6)), static_cast<char>(0x80 | (c & 0x3F))};
    if (c < 0x10000) {
        return {static_cast<char>(0xE0 | (c >> 12)), static_cast<char>(0x80 | ((c >> 6) & 0x3F)),
                static_cast<char>(0x80 | (c & 0x3F))};
    }
    return {static_cast<char>(0xF0 | (c >> 18)), static_cast<char>(0x80 | ((c >> 12) & 0x3F)),
            static_cast<char>(0x80 | ((c >> 6) & 0x3F)), static_cast<char>(0x80 | (c & 0x3F))};
}

std::vector<uint32_t> range(uint32_t first, uint32_t last) {
    std::vector<uint32_t> codepoints;
    for (uint32_t c = first; c <= last; ++c) codepoints.push_back(c);
    return codepoints;
}

struct Args {
    uint32_t count = 1000;
    float size = 32.0f;
    uint32_t width = 1920, height = 1080;
    uint32_t samples = 512;
};

uint32_t per_line(const Args& args) {
    return std::max(1u,
                    static_cast<uint32_t>((static_cast<float>(args.width) - 2.0f * kMargin) / (args.size * kPitchEm)));
}

class ColourSuite {
public:
    ColourSuite(Session& session, const Args& args) : context_(*session.context), args_(args) {
        CompositorCreateInfo info = compositor_create_info(context_);
        info.frames_in_flight = 1;
        auto compositor = Compositor::create(info);
        if (!compositor) fail(kSuite, compositor.error().message);
        if (!compositor->supports_target_format(kFormat)) fail(kSuite, "the device cannot store to RGBA32F");
        compositor_.emplace(std::move(*compositor));
        ImageDesc desc;
        desc.format = kFormat;
        desc.width = args.width;
        desc.height = args.height;
        desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        auto target = context_.create_image(desc);
        if (!target) fail(kSuite, target.error().message);
        target_.emplace(std::move(*target));
        const std::vector<float> grey(size_t{args.width} * args.height * 4, 0.5f);
        if (Status s = context_.upload(*target_, std::as_bytes(std::span(grey)), VK_IMAGE_LAYOUT_GENERAL); !s) {
            fail(kSuite, s.error().message);
        }
        for (GpuTimerSlot& slot : timers_) {
            auto timer = tools::GpuTimer::create(context_);
            if (!timer) fail(kSuite, timer.error().message);
            slot.emplace(std::move(*timer));
        }
    }

    // `count` glyphs of `spec` drawn until converged, frame 1 and a converged frame timed.
    ScreenResult run(const ScreenSpec& spec, uint32_t count) {
        ScreenResult result;
        result.spec = spec;
        if (!std::filesystem::exists(spec.font)) {
            result.skipped = spec.font + " is missing (Debian: fonts-noto-color-emoji; scripts/setup.sh)";
            return result;
        }
        BakeOptions bake;
        bake.all_glyphs = false;
        bake.codepoints = spec.codepoints;
        auto baked = bake_font_file(spec.font, bake);
        if (!baked) fail(kSuite, spec.font + ": " + baked.error().message);
        auto font = Font::create(std::move(baked->asset), 1);
        if (!font) fail(kSuite, spec.font + ": " + font.error().message);

        RendererCreateInfo info = renderer_create_info(context_);
        info.atlas.max_samples = args_.samples;
        info.atlas.frame_budget = uint64_t{1} << 50;
        auto renderer = Renderer::create(info);
        if (!renderer) fail(kSuite, renderer.error().message);
        if (Status s = renderer->add_font(*font); !s) fail(kSuite, s.error().message);

        // Frame 1: the layout is part of what a new screen costs.
        const Clock::time_point layout_start = Clock::now();
        const std::vector<GlyphInstance> screen = lay_out(*font, spec.codepoints, count, result);
        result.first.layout_ms = ms_since(layout_start);
        result.instances = static_cast<uint32_t>(screen.size());
        frame(*renderer, screen, result.first, true);
        // The converging frames are not composited: what they cost is the frames suite's.
        for (result.frames = 1; !(renderer->converged() && result.last.work_items == 0); ++result.frames) {
            if (result.frames == kMaxFrames) break;
            frame(*renderer, screen, result.last, false);
        }
        result.converged = renderer->converged();
        // The converged frame timed on its own (the loop's last one may still have refined).
        frame(*renderer, screen, result.last, true);
        result.atlas_entries = renderer->atlas().stats().resident_glyphs;
        return result;
    }

private:
    using GpuTimerSlot = std::optional<tools::GpuTimer>;

    // Lines of per_line() glyphs, each laid out as one text, their paint orders consecutive; the
    // count's glyphs cycle through `codepoints`.
    std::vector<GlyphInstance> lay_out(const Font& font, const std::vector<uint32_t>& codepoints, uint32_t count,
                                       ScreenResult& result) const {
        const Font* fonts[] = {&font};
        TextStyle style;
        style.size = args_.size;
        const uint32_t line_glyphs = per_line(args_);
        std::vector<GlyphInstance> glyphs;
        uint32_t order = 0;
        for (uint32_t first = 0, line = 0; first < count; first += line_glyphs, ++line) {
            std::string text;
            for (uint32_t i = first; i < std::min(count, first + line_glyphs); ++i) {
                text += utf8(codepoints[i % codepoints.size()]);
            }
            LayoutOptions options;
            options.origin_x = kMargin + 0.25f;
            options.origin_y = kMargin + args_.size * (1.0f + kLineEm * static_cast<float>(line));
            options.first_paint_order = order;
            auto laid = layout_text(fonts, text, style, options);
            if (!laid) fail(kSuite, laid.error().message);
            order = laid->next_paint_order;
            result.glyphs += laid->shaped_glyphs;
            result.colour_glyphs += laid->colour_glyphs;
            glyphs.insert(glyphs.end(), laid->glyphs.begin(), laid->glyphs.end());
        }
        return glyphs;
    }

    void frame(Renderer& renderer, const std::vector<GlyphInstance>& screen, FrameCost& cost, bool composited) {
        const tools::GpuTimer& raster = *timers_[0];
        const tools::GpuTimer& composite = *timers_[1];
        const VkRect2D rect{{0, 0}, {args_.width, args_.height}};
        double cpu_ms = 0.0;
        Status recorded;
        const Status submitted = context_.submit_and_wait([&](VkCommandBuffer cb) {
            const Clock::time_point start = Clock::now();
            renderer.begin_frame();
            renderer.draw(screen);
            raster.begin(cb);
            recorded = renderer.record(cb);
            raster.end(cb);
            if (!recorded || !composited) return;
            composite.begin(cb, true);
            const CompositeTarget target{target_->view(), kFormat, VK_FORMAT_UNDEFINED, rect.extent, rect};
            recorded = compositor_->record(cb, renderer.drawn_frame(), target);
            composite.end(cb);
            cpu_ms = ms_since(start);
        });
        if (!recorded) fail(kSuite, recorded.error().message);
        if (!submitted) fail(kSuite, submitted.error().message);
        const RendererStats& stats = renderer.stats();
        cost.work_items = stats.work_items;
        if (!composited) return;
        const Result<double> raster_ms = raster.milliseconds(), composite_ms = composite.milliseconds();
        if (!raster_ms) fail(kSuite, raster_ms.error().message);
        if (!composite_ms) fail(kSuite, composite_ms.error().message);
        cost.cpu_ms = cpu_ms;
        cost.raster_ms = *raster_ms;
        cost.composite_ms = *composite_ms;
        cost.quads = compositor_->stats().quads;
        cost.colour_layers = stats.colour_layers;
        cost.frame_paints = stats.frame_paints;
        cost.bitmap_uploads = stats.bitmap_uploads;
        cost.bitmap_misses = stats.bitmap_misses;
    }

    HeadlessContext& context_;
    const Args args_;
    std::optional<Compositor> compositor_;
    std::optional<Image> target_;
    GpuTimerSlot timers_[2];
};

void print_markdown(std::FILE* md, const Args& args, const std::vector<ScreenResult>& results) {
    std::fprintf(md,
                 "Three screens of %u glyphs at %.4g px on a %ux%u RGBA32F canvas, %u to a line: bitmap emoji (Noto "
                 "Color Emoji, U+1F600-1F64F: one image layer each), every colour glyph of tests/fonts/colour/"
                 "colrv1.ttf (its gradients, transforms and composites: their layers) and DejaVu Sans letters "
                 "(monochrome). Layout rgb, %u samples, an unbounded frame budget. Frame 1: every glyph new; layout "
                 "(CPU ms of layout_text, all lines), then begin_frame, draw and the records (CPU ms), Renderer::"
                 "record and Compositor::record on the tile path (GPU ms, timestamp queries around each). Converged: "
                 "a frame once every glyph holds its samples, the same layout drawn again (the frames between are "
                 "rasterized, not composited). Quads: the compositor's "
                 "(a colour glyph's layers one each). us/quad: GPU (raster + composite) microseconds per quad.\n\n",
                 args.count, double{args.size}, args.width, args.height, per_line(args), args.samples);
    std::fprintf(
        md,
        "| screen | frame | layout CPU ms | CPU ms | raster GPU ms | composite GPU ms | quads | colour "
        "layers | paints | bitmap uploads | us/quad |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const ScreenResult& r : results) {
        if (!r.skipped.empty()) continue;
        for (const bool first : {true, false}) {
            const FrameCost& c = first ? r.first : r.last;
            char layout_ms[32] = "";
            if (first) std::snprintf(layout_ms, sizeof layout_ms, "%.3f", c.layout_ms);
            std::fprintf(md, "| %s | %s | %s | %.3f | %.3f | %.3f | %u | %u | %u | %u | %.3f |\n", r.spec.name.c_str(),
                         first ? "1" : "converged", layout_ms, c.cpu_ms, c.raster_ms, c.composite_ms, c.quads,
                         c.colour_layers, c.frame_paints, c.bitmap_uploads, c.us_per_quad());
        }
    }
    std::fprintf(md,
                 "\n| screen | shaped glyphs | colour glyphs | layout instances | atlas entries | frames to "
                 "converge | bitmap misses (frame 1) |\n|---|---:|---:|---:|---:|---:|---:|\n");
    for (const ScreenResult& r : results) {
        if (!r.skipped.empty()) {
            std::fprintf(md, "| %s | skipped: %s | | | | | |\n", r.spec.name.c_str(), r.skipped.c_str());
            continue;
        }
        std::fprintf(md, "| %s | %u | %u | %u | %u | %u%s | %u |\n", r.spec.name.c_str(), r.glyphs, r.colour_glyphs,
                     r.instances, r.atlas_entries, r.frames, r.converged ? "" : " (not converged)",
                     r.first.bitmap_misses);
    }
}

void write_frame(JsonWriter& json, const FrameCost& c) {
    json.begin_object()
        .field("cpu_ms", c.cpu_ms)
        .field("raster_gpu_ms", c.raster_ms)
        .field("composite_gpu_ms", c.composite_ms)
        .field("quads", c.quads)
        .field("colour_layers", c.colour_layers)
        .field("frame_paints", c.frame_paints)
        .field("bitmap_uploads", c.bitmap_uploads)
        .field("bitmap_misses", c.bitmap_misses)
        .field("glyphs_refined", c.work_items)
        .field("gpu_us_per_quad", c.us_per_quad())
        .end_object();
}

void write_json(JsonWriter& json, const Args& args, const std::vector<ScreenResult>& results) {
    json.begin_object()
        .field("count", args.count)
        .field("size", args.size)
        .field("samples", args.samples)
        .field("per_line", per_line(args));
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.key("screens").begin_array();
    for (const ScreenResult& r : results) {
        json.begin_object().field("name", r.spec.name).field("font", r.spec.font).field("skipped", r.skipped);
        if (r.skipped.empty()) {
            json.field("shaped_glyphs", r.glyphs)
                .field("colour_glyphs", r.colour_glyphs)
                .field("instances", r.instances)
                .field("atlas_entries", r.atlas_entries)
                .field("frames", r.frames)
                .field("converged", r.converged)
                .field("layout_ms", r.first.layout_ms);
            json.key("first");
            write_frame(json, r.first);
            json.key("converged_frame");
            write_frame(json, r.last);
        }
        json.end_object();
    }
    json.end_array().end_object();
}

}  // namespace

void run_colour(Session& session) {
    const Options& o = session.options;
    Args args;
    args.count = o.glyphs.value_or(o.quick ? 100 : 1000);
    args.size = o.size.value_or(o.quick ? 24.0f : 32.0f);
    args.width = o.width.value_or(o.quick ? 512 : 1920);
    const uint32_t lines = (args.count + per_line(args) - 1) / per_line(args);
    const float needed = 2.0f * kMargin + args.size * (1.0f + kLineEm * static_cast<float>(lines));
    args.height = o.height.value_or(std::max(o.quick ? 256u : 1080u, static_cast<uint32_t>(std::ceil(needed))));
    args.samples = o.samples.value_or(o.quick ? 16 : 512);

    std::vector<uint32_t> colrv1 = range(0xE000, 0xE01D);
    // U+E01E draws its plain outline (a composite mode refused, no COLRv0 layers): not a colour glyph.
    const std::vector<uint32_t> rest = range(0xE01F, 0xE029);
    colrv1.insert(colrv1.end(), rest.begin(), rest.end());
    std::vector<uint32_t> letters = range('a', 'z');
    const std::vector<uint32_t> capitals = range('A', 'Z');
    letters.insert(letters.end(), capitals.begin(), capitals.end());
    const std::vector<ScreenSpec> specs = {
        {"bitmap", kNotoColorEmoji, range(0x1F600, 0x1F64F)},
        {"colrv1", std::string(CRISP_SOURCE_DIR) + "/tests/fonts/colour/colrv1.ttf", colrv1},
        {"monochrome", o.dejavu, letters},
    };
    ColourSuite suite(session, args);
    // One line of each screen first, untimed: the compositor builds its pipelines for frames with and
    // without fills at their first use (and lavapipe compiles shaders at their first dispatch), a
    // cost of the first frames an application draws, not of a new screen of text.
    for (const ScreenSpec& spec : specs) suite.run(spec, per_line(args));
    std::vector<ScreenResult> results;
    for (const ScreenSpec& spec : specs) {
        progress(kSuite, spec.name + ": " + std::to_string(args.count) + " glyphs at " +
                             std::to_string(static_cast<int>(args.size)) + " px");
        results.push_back(suite.run(spec, args.count));
        if (!results.back().skipped.empty()) session.warn(kSuite, spec.name + " skipped: " + results.back().skipped);
    }
    print_markdown(session.md, args, results);
    write_json(session.json, args, results);
}

}  // namespace crisp::bench
