// crisp-bench-gpu: GPU time of the rasterizer for a screen of text, from its first frame (new
// glyphs, 8 samples each) through the converging frames to converged static text. Measures with
// Vulkan timestamp queries around the recorded work; prints Markdown (or JSON with --json).
#include "cli.hpp"
#include "gpu_tools.hpp"
#include "headless_context.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

struct Args {
    std::string font = "fonts/DejaVuSans.ttf";
    std::string layout = "rgb";
    std::string device;
    float size = 16.0f;
    uint32_t width = 1920, height = 1080;
    uint32_t samples = 512;
    uint32_t max_frames = 1000;
    uint32_t atlas_budget_mib = 0;  // 0: the atlas keeps its 2048x2048
    uint64_t frame_budget = uint64_t{1} << 50;  // curve tests per frame; default: unbounded
    bool no_shared_rows = false;
    crisp::SampleKind sample_kind = crisp::SampleKind::rows;
    bool validate = false;
    bool shader_stats = false;
};

// Parses the command line; prints --help, or the help on stderr and exits 2 on a usage error.
Args parse(int argc, char** argv) {
    Args args;
    crisp::cli::CommandLine cli(
        "crisp-bench-gpu",
        "usage: crisp-bench-gpu [options]\n"
        "Fills a canvas with text and measures the rasterizer's GPU time per frame, from new text\n"
        "(8 samples per glyph) to converged static text, with timestamp queries.\n\n");
    cli.on_usage_error(2, "", true);
    cli.text("--font", "PATH", "a font file, baked at start (default fonts/DejaVuSans.ttf)", args.font);
    cli.number<float>("--size", "PX", "pixels per em (default 16)", args.size);
    cli.option("--canvas", "WxH", "canvas filled with lines of text (default 1920x1080)",
               [&args](std::string_view text) -> crisp::Status {
                   auto sides = crisp::cli::parse_number_list<uint32_t>("--canvas", text, 'x');
                   if (!sides) return sides.error();
                   if (sides->size() != 2) {
                       return crisp::Error{crisp::ErrorCode::invalid_argument,
                                           "--canvas: '" + crisp::cli::printable(text) + "' is not WxH"};
                   }
                   args.width = (*sides)[0];
                   args.height = (*sides)[1];
                   return {};
               });
    cli.text("--layout", "NAME", "subpixel layout preset or file (default rgb)", args.layout);
    cli.number<uint32_t>("--samples", "N", "samples per glyph to converge to (default 512)", args.samples);
    cli.number<uint32_t>("--frames", "N", "stop after N frames even if not converged (default 1000)", args.max_frames);
    cli.number<uint32_t>("--atlas-budget", "MIB",
                         "let the 2048x2048 atlas grow to MIB mebibytes (default 0: it does not)",
                         args.atlas_budget_mib);
    cli.number<uint64_t>("--frame-budget", "TESTS",
                         "curve tests per frame (default 2^50, unbounded;\nthe library's default is 2^26)",
                         args.frame_budget);
    cli.flag("--no-shared-rows", "solve roots per channel even where channels share rows", args.no_shared_rows);
    cli.choice<crisp::SampleKind>(
        "--sample-kind", "KIND", "rows (exact in x, the default) or points", args.sample_kind,
        {crisp::SampleKind::rows, crisp::SampleKind::points},
        [](const crisp::SampleKind& kind) { return std::string(kind == crisp::SampleKind::rows ? "rows" : "points"); });
    cli.text("--device", "TEXT", "pick a device whose name contains TEXT", args.device);
    cli.flag("--validate", "turn the validation layer on", args.validate);
    cli.flag("--shader-stats",
             "the driver's statistics of the raster shader\n(registers, ...), where the device offers them",
             args.shader_stats);
    cli.parse(argc, argv);
    return args;
}

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "crisp-bench-gpu: %s\n", message.c_str());
    std::exit(1);
}

struct Frame {
    uint32_t index = 0;
    uint64_t samples = 0;
    uint32_t items = 0;
    uint64_t curve_tests = 0;
    double gpu_ms = 0.0;
};

// A screen of prose: lines of text at the given size until the canvas is full.
std::vector<crisp::GlyphInstance> screen_of_text(const Args& args, const crisp::Font& font) {
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

crisp::Renderer make_renderer(const crisp::HeadlessContext& context, const Args& args,
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

// Draws the screen frame after frame, each timed on the GPU, until it converges or max_frames.
std::vector<Frame> run_frames(crisp::HeadlessContext& context, crisp::Renderer& renderer,
                              const std::vector<crisp::GlyphInstance>& screen, uint32_t max_frames) {
    auto timer = crisp::tools::GpuTimer::create(context);
    if (!timer) fail(timer.error().message);
    std::vector<Frame> frames;
    for (uint32_t f = 0; f < max_frames; ++f) {
        renderer.begin_frame();
        renderer.draw(screen);
        const auto status = context.submit_and_wait([&](VkCommandBuffer cb) {
            timer->begin(cb);
            if (auto s = renderer.record(cb); !s) fail(s.error().message);
            timer->end(cb);
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
        frames.push_back(frame);
        if (renderer.converged() && frame.items == 0) break;
    }
    return frames;
}

void print_markdown(const Args& args, const crisp::HeadlessContext& context, const crisp::Renderer& renderer,
                    const std::string& layout_name, size_t screen_glyphs, const std::vector<Frame>& frames) {
    const crisp::AtlasStats& atlas = renderer.atlas().stats();
    const crisp::RendererStats& last = renderer.stats();
    std::printf(
        "Device: %s, driver %s (%s). Canvas %ux%u, %s at %.4g px, %s samples, layout %s%s, %zu glyphs on screen, "
        "%u atlas entries (%ux%u atlas, %u of %u cells). Last frame: %u glyphs drawn, %u failed, %u at "
        "coarser subpixel steps (%u per pixel).\n\n",
        context.device_name().c_str(), context.driver_name().c_str(), context.driver_info().c_str(), args.width,
        args.height, args.font.c_str(), static_cast<double>(args.size),
        args.sample_kind == crisp::SampleKind::rows ? "row" : "point", layout_name.c_str(),
        args.no_shared_rows ? " (roots per channel)" : "", screen_glyphs, atlas.resident_glyphs,
        renderer.atlas().config().width, renderer.atlas().config().height, atlas.used_cells, atlas.usable_cells,
        last.drawn_glyphs, last.failed_glyphs, last.coarsened_glyphs, last.subpixel_steps);
    std::printf(
        "| frame | samples per glyph added | glyphs refined | curve tests (estimate) | GPU ms | "
        "curve tests per second |\n|---:|---:|---:|---:|---:|---:|\n");
    double total_ms = 0.0;
    for (const Frame& f : frames) {
        total_ms += f.gpu_ms;
        const bool show = f.index < 6 || f.index + 1 == frames.size() || (f.index & (f.index - 1)) == 0;
        if (!show) continue;
        std::printf("| %u | %.3g | %u | %.3g | %.3f | %.3g |\n", f.index + 1,
                    f.items ? static_cast<double>(f.samples) / f.items : 0.0, f.items,
                    static_cast<double>(f.curve_tests), f.gpu_ms,
                    f.gpu_ms > 0 ? static_cast<double>(f.curve_tests) / (f.gpu_ms * 1e-3) : 0.0);
    }
    std::printf("\n%zu frames, %.1f ms of GPU time in all; converged: %s.\n", frames.size(), total_ms,
                renderer.converged() ? "yes" : "no");
}

}  // namespace

int main(int argc, char** argv) {
    const Args args = parse(argc, argv);
    crisp::HeadlessContextOptions options;
    options.validation = args.validate;
    options.device_name_contains = args.device;
    options.shader_statistics = args.shader_stats;
    bool storage_without_format = false;  // the rasterizer does not use it
    auto context = crisp::tools::create_context(options, storage_without_format);
    if (!context) fail(context.error().message);

    auto baked = crisp::bake_font_file(args.font, crisp::BakeOptions{});
    if (!baked) fail(baked.error().message);
    auto font = crisp::Font::create(std::move(baked->asset), 1);
    if (!font) fail(font.error().message);
    auto layout = crisp::resolve_subpixel_layout(args.layout);
    if (!layout) fail(layout.error().message);
    {
        crisp::Renderer renderer = make_renderer(*context, args, *layout, *font);
        const std::vector<crisp::GlyphInstance> screen = screen_of_text(args, *font);
        const std::vector<Frame> frames = run_frames(*context, renderer, screen, args.max_frames);
        print_markdown(args, *context, renderer, layout->name, screen.size(), frames);
        if (args.shader_stats) crisp::tools::print_shader_statistics(renderer.shader_statistics());
    }
    const auto messages = context->validation_messages();
    if (messages.errors + messages.warnings > 0) {
        for (const auto& m : messages.recent) std::fprintf(stderr, "%s\n", m.c_str());
        return 1;
    }
    return 0;
}
