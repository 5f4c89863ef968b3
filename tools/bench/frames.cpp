// crisp-bench --suite frames (formerly crisp-bench-gpu): GPU time of the rasterizer for a screen of
// text, from its first frame (new glyphs, 8 samples each) through the converging frames to
// converged static text, per subpixel layout and sample kind. Measures with Vulkan timestamp
// queries around the recorded work. Also FreeType's CPU time for the same new glyphs (the peer of
// the coverage suite), so that error can be set against time.
#include "bench.hpp"
#include "frame_loop.hpp"
#include "freetype_reference.hpp"
#include "gpu_tools.hpp"
#include "headless_context.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "frames";

[[noreturn]] void fail(const std::string& message) {
    bench::fail(kSuite, message);
}

}  // namespace

std::vector<crisp::GlyphInstance> screen_of_text(const FrameArgs& args, const crisp::Font& font) {
    const std::string prose =
        "It was the best of times, it was the worst of times, it was the age of wisdom, it was the age of "
        "foolishness, it was the epoch of belief, it was the epoch of incredulity, it was the season of Light, "
        "it was the season of Darkness, it was the spring of hope, it was the winter of despair. ";
    std::string text;
    while (text.size() < 400000) text += prose;
    const crisp::Font* fonts[] = {&font};
    crisp::TextStyle style;
    style.size = args.size;
    crisp::LayoutOptions layout_options;
    layout_options.origin_x = 4.25f;
    layout_options.origin_y = args.size;
    layout_options.wrap_width = static_cast<float>(args.width) - 8.0f;
    auto laid = crisp::layout_text(fonts, text, style, layout_options);
    if (!laid) fail(laid.error().message);
    std::vector<crisp::GlyphInstance> screen;
    for (const crisp::GlyphInstance& g : laid->glyphs) {
        if (g.y + static_cast<int32_t>(g.height) <= static_cast<int32_t>(args.height)) screen.push_back(g);
    }
    return screen;
}

crisp::Renderer make_renderer(const crisp::HeadlessContext& context, const FrameArgs& args,
                              const crisp::SubpixelLayout& layout, const crisp::Font& font) {
    crisp::RendererCreateInfo info = crisp::renderer_create_info(context);
    info.atlas.max_samples = args.samples;
    info.atlas.frame_budget = args.frame_budget;
    info.layout = layout;
    info.atlas_memory_budget = uint64_t{args.atlas_budget_mib} << 20;
    info.shared_row_roots = !args.no_shared_rows;
    info.sample_kind = args.sample_kind;
    auto renderer = crisp::Renderer::create(info);
    if (!renderer) fail(renderer.error().message);
    if (auto s = renderer->add_font(font); !s) fail(s.error().message);
    return std::move(*renderer);
}

std::vector<Frame> run_frames(crisp::HeadlessContext& context, crisp::Renderer& renderer,
                              const std::vector<crisp::GlyphInstance>& screen, uint32_t max_frames,
                              const crisp::DrawOptions* options) {
    auto timer = crisp::tools::GpuTimer::create(context);
    if (!timer) fail(timer.error().message);
    std::vector<Frame> frames;
    for (uint32_t f = 0; f < max_frames; ++f) {
        double cpu_ms = 0.0;
        const auto status = context.submit_and_wait([&](VkCommandBuffer cb) {
            const auto start = std::chrono::steady_clock::now();
            renderer.begin_frame();
            if (options) {
                renderer.draw(screen, *options);
            } else {
                renderer.draw(screen);
            }
            timer->begin(cb);
            if (auto s = renderer.record(cb); !s) fail(s.error().message);
            timer->end(cb);
            cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        });
        if (!status) fail(status.error().message);
        const crisp::Result<double> gpu_ms = timer->milliseconds();
        if (!gpu_ms) fail(gpu_ms.error().message);
        Frame frame;
        frame.index = f;
        frame.samples = renderer.stats().samples;
        frame.items = renderer.stats().work_items;
        frame.curve_tests = renderer.stats().curve_tests;
        frame.gpu_ms = *gpu_ms;
        frame.cpu_ms = cpu_ms;
        frames.push_back(frame);
        if (renderer.converged() && frame.items == 0) break;
        if ((f + 1) % 128 == 0) progress(kSuite, "frame " + std::to_string(f + 1));
    }
    return frames;
}

namespace {

void print_markdown(std::FILE* out, const FrameArgs& args, const crisp::Renderer& renderer,
                    const std::string& layout_name, size_t screen_glyphs, const std::vector<Frame>& frames) {
    const crisp::AtlasStats& atlas = renderer.atlas().stats();
    const crisp::RendererStats& last = renderer.stats();
    std::fprintf(out,
                 "Canvas %ux%u, %s at %.4g px, %s samples, layout %s%s, %zu glyphs on screen, "
                 "%u atlas entries (%ux%u atlas, %u of %u cells). Last frame: %u glyphs drawn, %u failed, %u at "
                 "coarser subpixel steps (%u per pixel).\n\n",
                 args.width, args.height, args.font.c_str(), static_cast<double>(args.size),
                 args.sample_kind == crisp::SampleKind::rows ? "row" : "point", layout_name.c_str(),
                 args.no_shared_rows ? " (roots per channel)" : "", screen_glyphs, atlas.resident_glyphs,
                 renderer.atlas().config().width, renderer.atlas().config().height, atlas.used_cells,
                 atlas.usable_cells, last.drawn_glyphs, last.failed_glyphs, last.coarsened_glyphs, last.subpixel_steps);
    std::fprintf(out,
                 "| frame | samples per glyph added | glyphs refined | curve tests (estimate) | GPU ms | "
                 "curve tests per second |\n|---:|---:|---:|---:|---:|---:|\n");
    double total_ms = 0.0;
    for (const Frame& f : frames) {
        total_ms += f.gpu_ms;
        const bool show = f.index < 6 || f.index + 1 == frames.size() || (f.index & (f.index - 1)) == 0;
        if (!show) continue;
        std::fprintf(out, "| %u | %.3g | %u | %.3g | %.3f | %.3g |\n", f.index + 1,
                     f.items ? static_cast<double>(f.samples) / f.items : 0.0, f.items,
                     static_cast<double>(f.curve_tests), f.gpu_ms,
                     f.gpu_ms > 0 ? static_cast<double>(f.curve_tests) / (f.gpu_ms * 1e-3) : 0.0);
    }
    std::fprintf(out, "\n%zu frames, %.1f ms of GPU time in all; converged: %s.\n", frames.size(), total_ms,
                 renderer.converged() ? "yes" : "no");
}

// FreeType's CPU time to render the screen's atlas entries once each (the median of 3 renders of
// each), in `mode`: what the peer spends on the same new glyphs.
double freetype_screen_ms(const std::string& font_path, const Font& font, const Renderer& renderer,
                          freetype::PeerMode mode) {
    auto face = freetype::Face::open_file(font_path);
    if (!face) fail(font_path + ": " + face.error().message);
    std::set<std::tuple<uint32_t, uint32_t, uint32_t, uint8_t, uint8_t>> seen;
    double seconds = 0.0;
    for (const DrawnGlyph& d : renderer.drawn()) {
        const GlyphKey& key = d.instance.key;
        if (!seen.emplace(key.glyph, key.size_x, key.size_y, key.subpixel_x, key.subpixel_y).second) continue;
        const GlyphRect rect = glyph_rect(font.asset().glyphs[key.glyph], key);
        if (rect.width == 0) continue;
        auto peer = freetype::render_peer(*face, key, rect, mode, 3);
        if (!peer) fail("FreeType: " + peer.error().message);
        seconds += peer->seconds_per_glyph;
    }
    return seconds * 1e3;
}

void write_run_json(JsonWriter& json, const FrameArgs& args, const Renderer& renderer, size_t screen_glyphs,
                    const std::vector<Frame>& frames) {
    json.begin_object()
        .field("layout", args.layout)
        .field("sample_kind", sample_kind_name(args.sample_kind))
        .field("font", args.font)
        .field("size", args.size)
        .field("samples", args.samples)
        .field("no_shared_rows", args.no_shared_rows)
        .field("atlas_budget_mib", args.atlas_budget_mib)
        .field("frame_budget", args.frame_budget)
        .field("screen_glyphs", screen_glyphs)
        .field("atlas_entries", renderer.atlas().stats().resident_glyphs)
        .field("converged", renderer.converged());
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.key("frames").begin_array();
    for (const Frame& f : frames) {
        json.begin_object()
            .field("frame", f.index + 1)
            .field("samples", f.samples)
            .field("glyphs_refined", f.items)
            .field("curve_tests", f.curve_tests)
            .field("gpu_ms", f.gpu_ms)
            .end_object();
    }
    json.end_array().end_object();
}

}  // namespace

void run_frames(Session& session) {
    const Options& o = session.options;
    FrameArgs base;
    if (!o.fonts.empty()) base.font = o.fonts.front();
    base.size = o.size.value_or(16.0f);
    base.width = o.width.value_or(o.quick ? 256 : session.cpu_device ? 640 : 1920);
    base.height = o.height.value_or(o.quick ? 128 : session.cpu_device ? 360 : 1080);
    base.samples = o.samples.value_or(o.quick ? 16 : 512);
    base.max_frames = o.frames.value_or(1000);
    base.atlas_budget_mib = o.atlas_budget_mib;
    base.frame_budget = o.frame_budget;
    base.no_shared_rows = o.no_shared_rows;
    const std::vector<std::string> layouts =
        o.layout ? std::vector<std::string>{*o.layout} : std::vector<std::string>{"gray", "rgb"};
    const std::vector<SampleKind> kinds = o.sample_kind ? std::vector<SampleKind>{*o.sample_kind}
                                                        : std::vector<SampleKind>{SampleKind::rows, SampleKind::points};

    auto baked = bake_font_file(base.font, BakeOptions{});
    if (!baked) fail(baked.error().message);
    auto font = Font::create(std::move(baked->asset), 1);
    if (!font) fail(font.error().message);
    HeadlessContext& context = *session.context;

    const std::string budget = base.frame_budget == FrameArgs{}.frame_budget
                                   ? "an unbounded frame budget"
                                   : "a frame budget of " + std::to_string(base.frame_budget) + " curve tests";
    std::fprintf(session.md,
                 "A canvas of prose, every glyph new in frame 1, drawn until every glyph holds its samples; GPU ms "
                 "from timestamp queries around Renderer::record, with %s (the default ramp: 8, 4, 2, then 1 "
                 "sample per frame). Curve tests: the renderer's estimate. Rows shown: frames 1-6, powers of two "
                 "and the last; every frame is in the JSON.\n",
                 budget.c_str());
    session.json.begin_object().key("runs").begin_array();
    for (const std::string& layout_name : layouts) {
        auto layout = resolve_subpixel_layout(layout_name);
        if (!layout) fail(layout.error().message);
        for (const SampleKind kind : kinds) {
            FrameArgs args = base;
            args.layout = layout_name;
            args.sample_kind = kind;
            session.heading(std::string("frames: ") + layout->name + ", " + sample_kind_name(kind));
            Renderer renderer = make_renderer(context, args, *layout, *font);
            const std::vector<GlyphInstance> screen = screen_of_text(args, *font);
            progress(kSuite, layout->name + ", " + sample_kind_name(kind) + ": " + std::to_string(screen.size()) +
                                 " glyphs on a " + std::to_string(args.width) + "x" + std::to_string(args.height) +
                                 " canvas");
            const std::vector<Frame> frames = run_frames(context, renderer, screen, args.max_frames);
            print_markdown(session.md, args, renderer, layout->name, screen.size(), frames);
            if (o.shader_stats) tools::print_shader_statistics(session.md, renderer.shader_statistics());
            write_run_json(session.json, args, renderer, screen.size(), frames);

            // The samples every glyph holds after each frame, for the error against time: only where
            // the budget is unbounded, so that every glyph gets the same samples in a frame.
            if (args.frame_budget == FrameArgs{}.frame_budget) {
                TimeCurve& curve = session.frame_time[{layout->name, sample_kind_name(kind)}];
                double samples = 0.0, ms = 0.0;
                for (const Frame& f : frames) {
                    if (f.items == 0) break;
                    samples += static_cast<double>(f.samples) / f.items;
                    ms += f.gpu_ms;
                    curve.samples.push_back(static_cast<uint32_t>(samples + 0.5));
                    curve.cumulative_ms.push_back(ms);
                }
            }
            // FreeType, the coverage suite's peer, on the same new glyphs: gray beside gray, LCD beside rgb.
            std::vector<std::pair<freetype::PeerMode, const char*>> peers;
            if (layout->name == "gray") peers = {{freetype::PeerMode::gray, "gray"}};
            if (layout->name == "rgb") {
                peers = {{freetype::PeerMode::lcd, "lcd"}, {freetype::PeerMode::lcd_unfiltered, "lcd-unfiltered"}};
            }
            for (const auto& [peer, peer_name] : peers) {
                if (session.freetype_screen_ms.count(peer_name)) continue;
                session.freetype_screen_ms[peer_name] = freetype_screen_ms(args.font, *font, renderer, peer);
                session.frames_screen_entries = renderer.atlas().stats().resident_glyphs;
                std::fprintf(
                    session.md,
                    "\nFreeType %s (the coverage suite's peer) renders the same %u atlas entries in %.3f ms of "
                    "CPU time on one thread.\n",
                    peer_name, renderer.atlas().stats().resident_glyphs, session.freetype_screen_ms[peer_name]);
            }
        }
    }
    session.json.end_array().key("freetype_screen_ms").begin_object();
    for (const auto& [mode, ms] : session.freetype_screen_ms) session.json.field(mode, ms);
    session.json.end_object().field("screen_atlas_entries", session.frames_screen_entries).end_object();
}

}  // namespace crisp::bench
