// crisp-layout-editor: fit subpixel anti-aliasing to a monitor, live (docs/layout-editor.md).
#include "editor_model.hpp"
#include "editor_view.hpp"
#include "export.hpp"
#include "gpu_frame.hpp"
#include "vulkan_window.hpp"

#include "cli.hpp"
#include "image_io.hpp"
#include "output_files.hpp"

#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/subpixel.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace {

using namespace crisp::editor;

// Exit codes (also in --help and docs/layout-editor.md).
constexpr int kExitOk = 0;
constexpr int kExitUsage = 1;
constexpr int kExitFont = 2;
constexpr int kExitVulkan = 3;
constexpr int kExitValidation = 4;
constexpr int kExitScreenshot = 5;
constexpr int kExitWrite = kExitScreenshot;  // the --export form could not be written

constexpr const char* kSynopsis = R"(Usage: crisp-layout-editor [options]

Shows a subpixel layout (the sample rectangle of each colour channel within a pixel) magnified,
lets you drag, nudge and type its rectangles, and previews text rendered by crisp with it.

)";

constexpr const char* kExitCodes = R"(
Exit codes: 0 success; 1 bad command line; 2 the font could not be loaded; 3 no window or no
Vulkan device (or a Vulkan failure); 4 the validation layer reported a message; 5 the screenshot
could not be written, or must not be (the --font or --layout file, a read-only file, a device:
refused before the window opens; docs/limits.md), or the --export form could not be written.
With --export, a --layout that does not load is exit code 1.
)";

struct Args {
    std::string layout = "rgb";
    std::string save_to;
    std::string font = CRISP_EDITOR_DEFAULT_FONT;
    uint64_t frames = 0;  // 0: until the window closes
    std::string screenshot;
    bool validation = false;
    bool print_geometry = false;
    std::string export_form;  // print the layout in this form and quit, without a window
    // The starting size, window pixels; none: kWindowWidth x kWindowHeight at the monitor's
    // content scale, within its work area.
    std::optional<std::pair<uint32_t, uint32_t>> window;
    float ui_scale = 0.0f;  // window pixels per interface pixel; 0: the monitor's content scale
    // The preview's text, sizes, colours and zoom.
    std::string text = kDefaultPreviewText;
    std::vector<float> sizes = {9.0f, 11.0f, 13.0f, 16.0f, 20.0f};
    PreviewColours colours;
    std::string zoom = "1";
    bool compare = false;
};

// The window sizes --window takes, each side.
constexpr crisp::cli::Range<uint32_t> kWindowSides{64, 8192, false, " pixels"};

// --window WxH: "1366x768".
crisp::Status parse_window(std::string_view text, std::optional<std::pair<uint32_t, uint32_t>>& target) {
    const std::vector<std::string_view> sides = crisp::cli::split(text, 'x');
    if (sides.size() != 2) {
        return crisp::Error{crisp::ErrorCode::invalid_argument,
                            "--window: '" + crisp::cli::printable(text) + "' is not WIDTHxHEIGHT (such as 1366x768)"};
    }
    uint32_t size[2] = {};
    for (size_t i = 0; i < 2; ++i) {
        const crisp::Result<uint32_t> side =
            crisp::cli::CommandLine::checked_number<uint32_t>("--window", sides[i], kWindowSides);
        if (!side) return side.error();
        size[i] = *side;
    }
    target = std::pair{size[0], size[1]};
    return {};
}

Args parse_args(int argc, char** argv) {
    Args args;
    const char* env = std::getenv("CRISP_VALIDATION");
    args.validation = env && std::strcmp(env, "0") != 0 && env[0] != '\0';
    crisp::cli::CommandLine cli("crisp-layout-editor", kSynopsis);
    cli.on_usage_error(kExitUsage, " (see --help)").section("Options:").epilogue(kExitCodes);
    cli.text("--layout", "FILE|PRESET",
             "start from a layout file (JSON, docs/subpixel.md) or a preset (gray, rgb,\n"
             "bgr, vrgb, vbgr, qd-oled, woled, pentile); default rgb. A file that does\n"
             "not load is reported in the window and the editor starts from rgb.",
             args.layout);
    cli.text("--save-to", "FILE", "where Save (Ctrl+S) writes; default: the --layout file", args.save_to);
    cli.text("--font", "FILE", "the font for all text (TrueType/OpenType); default: DejaVu Sans", args.font);
    cli.number<uint64_t>("--frames", "N", "quit after N frames", args.frames, {1, UINT64_MAX});
    cli.text("--screenshot", "PATH", "with --frames: write the window's last frame as a PNG, then quit",
             args.screenshot);
    cli.flag("--validation",
             "turn on VK_LAYER_KHRONOS_validation; any warning or error it reports\n"
             "makes the exit code 4 (also: CRISP_VALIDATION=1 in the environment)",
             args.validation);
    cli.option("--window", "WxH",
               "the window's starting size in window pixels, each side 64..8192 (it can\n"
               "be resized); default 1280x800 times the monitor's content scale, within\n"
               "its work area. --screenshot writes a picture of this size",
               [&args](std::string_view text) { return parse_window(text, args.window); });
    cli.number("--ui-scale", "S",
               "window pixels per interface pixel, 0.25..4; default the monitor's content\n"
               "scale (1 where the window system does not say). A window smaller than\n"
               "1280x800 interface pixels draws everything smaller",
               args.ui_scale, crisp::cli::Range<float>{0.25f, 4.0f});
    cli.text("--text", "TEXT",
             "the preview's text, in place of its sample paragraph (it can also be typed\n"
             "in the window's Text field)",
             args.text);
    cli.option("--sizes", "LIST",
               "the sizes the preview shows its text at, pixels, separated by spaces or\n"
               "commas: 1 to 8 of them, each 4..72; default \"9 11 13 16 20\"",
               [&args](std::string_view text) -> crisp::Status {
                   std::string why;
                   std::optional<std::vector<float>> sizes = parse_preview_sizes(text, &why);
                   if (!sizes) {
                       return crisp::Error{crisp::ErrorCode::invalid_argument,
                                           "--sizes: '" + crisp::cli::printable(text) + "' " + why};
                   }
                   args.sizes = std::move(*sizes);
                   return {};
               });
    cli.option("--colours", "COLOURS",
               "the first preview panel's text and background colours, \"#RRGGBB on #RRGGBB\",\n"
               "or a preset: dark-on-light (default), light-on-dark, yellow-on-blue; the\n"
               "second panel shows them swapped",
               [&args](std::string_view text) -> crisp::Status {
                   std::string why;
                   std::optional<PreviewColours> colours = parse_preview_colours(text, &why);
                   if (!colours) {
                       return crisp::Error{crisp::ErrorCode::invalid_argument,
                                           "--colours: '" + crisp::cli::printable(text) + "' " + why};
                   }
                   args.colours = *colours;
                   return {};
               });
    cli.choice("--zoom", "N",
               "start with the preview zoomed N times (1, 2 or 4; Z cycles them): the\n"
               "other panel shows the outlined area's pixels magnified",
               args.zoom, {"1", "2", "4"});
    cli.flag("--compare",
             "start in compare mode: candidate layouts around the --layout side by side\n"
             "(V or the Compare button toggles it; a click or 1-4 picks one)",
             args.compare);
    cli.flag("--print-geometry",
             "print the widgets' positions (window pixels, for the --window size, default\n"
             "1280x800, at --ui-scale, default 1) as JSON and quit (for scripted input)",
             args.print_geometry);
    std::vector<std::string> forms(export_form_names().begin(), export_form_names().end());
    cli.choice("--export", "FORM",
               "print the --layout for other software and quit, without a window:\n"
               "fontconfig (rgba and lcdfilter as XML) or freetype (the positions\n"
               "FT_Library_SetLcdGeometry takes); what the form cannot express is a\n"
               "note on stderr",
               args.export_form, std::move(forms));
    cli.parse(argc, argv);
    if (!args.screenshot.empty() && args.frames == 0) cli.fail("--screenshot needs --frames N");
    if (!args.export_form.empty() && (!args.screenshot.empty() || args.frames != 0)) {
        cli.fail("--export prints and quits: it takes no --frames or --screenshot");
    }
    return args;
}

// The characters the editor's text uses: printable ASCII, the em dash and a few more.
// The --text's characters too, so that the person's own text shows.
std::vector<uint32_t> editor_codepoints(std::string_view text) {
    std::vector<uint32_t> codepoints;
    for (uint32_t c = 0x20; c < 0x7F; ++c) codepoints.push_back(c);
    for (uint32_t c : {0x00D7u, 0x2013u, 0x2014u, 0x2026u, 0xFFFDu}) codepoints.push_back(c);
    for (const uint32_t c : crisp::decode_utf8(text)) {
        if (c >= 0x20 && std::find(codepoints.begin(), codepoints.end(), c) == codepoints.end())
            codepoints.push_back(c);
    }
    return codepoints;
}

std::optional<crisp::Font> load_font(const std::string& path, std::string_view text) {
    crisp::BakeOptions options;
    options.codepoints = editor_codepoints(text);
    options.all_glyphs = false;
    options.allow_failed = true;
    crisp::Result<crisp::BakeResult> baked = crisp::bake_font_file(path, options);
    if (!baked) {
        std::fprintf(stderr, "crisp-layout-editor: --font %s: %s\n", crisp::cli::printable(path).c_str(),
                     baked.error().message.c_str());
        return std::nullopt;
    }
    crisp::Result<crisp::Font> font = crisp::Font::create(std::move(baked->asset), 1);
    if (!font) {
        std::fprintf(stderr, "crisp-layout-editor: --font %s: %s\n", crisp::cli::printable(path).c_str(),
                     font.error().message.c_str());
        return std::nullopt;
    }
    return std::move(*font);
}

// The text of one frame as glyph instances, for the interface's renderer and the preview's.
struct FrameText {
    std::vector<crisp::GlyphInstance> interface_glyphs;
    std::vector<crisp::GlyphInstance> preview_glyphs;
    // Compare mode: each candidate's text, for its own renderer.
    std::vector<std::vector<crisp::GlyphInstance>> candidate_glyphs;
    // Paint orders of moving preview text: it never converges, so the status line leaves it out.
    std::vector<std::pair<uint32_t, uint32_t>> moving;
    // Paint orders of text that changes every frame (the status line): left out of settling.
    std::vector<std::pair<uint32_t, uint32_t>> live;
};

bool in_ranges(const std::vector<std::pair<uint32_t, uint32_t>>& ranges, uint32_t order) {
    return std::any_of(ranges.begin(), ranges.end(),
                       [order](const auto& range) { return order >= range.first && order < range.second; });
}

// The items' positions and sizes are interface pixels: `scale` window pixels each.
void lay_out(crisp::Layouter& layouter, const crisp::Font& font, const std::vector<TextItem>& items, float scale,
             FrameText& out, std::vector<std::string>& errors) {
    out.interface_glyphs.clear();
    out.preview_glyphs.clear();
    out.candidate_glyphs.assign(kMaxCandidates, {});
    out.moving.clear();
    out.live.clear();
    const crisp::Font* fonts[] = {&font};
    crisp::TextLayout laid;
    uint32_t paint_order = 0;
    for (const TextItem& item : items) {
        crisp::TextStyle style;
        style.size = item.size * scale;
        style.color[0] = static_cast<float>(item.color.r) / 255.0f;
        style.color[1] = static_cast<float>(item.color.g) / 255.0f;
        style.color[2] = static_cast<float>(item.color.b) / 255.0f;
        crisp::LayoutOptions options;
        options.origin_x = item.x * scale;
        options.origin_y = item.y * scale;
        options.wrap_width = item.wrap_width * scale;
        options.first_paint_order = paint_order;
        options.max_lines = item.max_lines;
        if (crisp::Status status = layouter.layout(fonts, item.text, style, options, laid); !status) {
            errors.push_back(status.error().message);
            continue;
        }
        if (item.moving) out.moving.emplace_back(paint_order, laid.next_paint_order);
        if (item.live) out.live.emplace_back(paint_order, laid.next_paint_order);
        paint_order = laid.next_paint_order;
        auto& target = item.candidate >= 0 && static_cast<size_t>(item.candidate) < kMaxCandidates
                           ? out.candidate_glyphs[static_cast<size_t>(item.candidate)]
                       : item.preview ? out.preview_glyphs
                                      : out.interface_glyphs;
        target.insert(target.end(), laid.glyphs.begin(), laid.glyphs.end());
    }
}

// The renderers of the preview's text: the preview's, and in compare mode the candidates'.
std::vector<const crisp::Renderer*> preview_renderers(const GpuFrame& gpu) {
    std::vector<const crisp::Renderer*> renderers = {&gpu.preview_renderer()};
    for (size_t i = 0; i < gpu.candidate_count(); ++i) renderers.push_back(&gpu.candidate_renderer(i));
    return renderers;
}

FrameStats measure(const GpuFrame& gpu, const FrameText& text, uint64_t frame) {
    FrameStats stats;
    stats.frame = frame;
    stats.target_samples = kPreviewMaxSamples;
    stats.gpu_ms = gpu.gpu_milliseconds().value_or(-1.0);
    bool first = true;
    for (const crisp::Renderer* renderer : preview_renderers(gpu)) {
        // The fullest atlas: the one that would run out first.
        stats.atlas_occupancy = std::max(stats.atlas_occupancy, renderer->atlas().stats().occupancy);
        for (const crisp::DrawnGlyph& glyph : renderer->drawn()) {
            if (in_ranges(text.moving, glyph.instance.paint_order)) continue;
            stats.min_samples = first ? glyph.samples : std::min(stats.min_samples, glyph.samples);
            stats.max_samples = first ? glyph.samples : std::max(stats.max_samples, glyph.samples);
            first = false;
            ++stats.glyphs;
        }
    }
    return stats;
}

// Whether the last frame drawn shows every glyph converged, but those of text that changes every
// frame: the next frame would look the same, so the editor can wait for input.
bool settled(const GpuFrame& gpu, const FrameText& text) {
    std::vector<const crisp::Renderer*> renderers = preview_renderers(gpu);
    renderers.push_back(&gpu.interface_renderer());
    for (const crisp::Renderer* renderer : renderers) {
        for (const crisp::DrawnGlyph& glyph : renderer->drawn()) {
            if (glyph.samples < kPreviewMaxSamples && !in_ranges(text.live, glyph.instance.paint_order)) return false;
        }
    }
    return true;
}

// Frames the moving line goes on moving once the rest of the preview has converged.
constexpr uint64_t kMovingAfterConverged = 32;

// The --screenshot file, refused before the window opens when it cannot or must not be written:
// the --font or --layout file under any name (a screenshot used to replace its own layout file).
std::optional<crisp::OutputFiles> declare_screenshot(const Args& args) {
    std::vector<std::filesystem::path> inputs = {args.font};
    if (!crisp::subpixel_preset(args.layout)) inputs.emplace_back(args.layout);
    crisp::OutputFiles outputs(std::move(inputs));
    if (crisp::Status status = outputs.add(args.screenshot); !status) {
        std::fprintf(stderr, "crisp-layout-editor: --screenshot: %s\n", status.error().message.c_str());
        return std::nullopt;
    }
    return outputs;
}

bool write_screenshot(const crisp::OutputFiles& output, std::span<const uint8_t> rgba, uint32_t width,
                      uint32_t height) {
    if (rgba.size() != size_t{width} * height * 4) {
        std::fprintf(stderr, "crisp-layout-editor: --screenshot: no frame of the window's size was completed\n");
        return false;
    }
    std::vector<float> pixels(size_t{width} * height * 3);
    for (size_t i = 0; i < size_t{width} * height; ++i) {
        for (size_t c = 0; c < 3; ++c)
            pixels[i * 3 + c] = crisp::srgb_to_linear(static_cast<float>(rgba[i * 4 + c]) / 255.0f);
    }
    crisp::Result<std::vector<std::byte>> png = crisp::encode_png_srgb8(width, height, 3, pixels);
    crisp::Status status = png ? crisp::Status{} : crisp::Status{png.error()};
    if (png) {
        const std::span<const std::byte> contents[] = {*png};
        status = output.write(contents);
    }
    if (!status) {
        std::fprintf(stderr, "crisp-layout-editor: --screenshot: %s\n", status.error().message.c_str());
        return false;
    }
    return true;
}

// The window's life: returns the exit code. Everything Vulkan is gone when it returns, except the
// window, whose validation count the caller reads.
int run(const Args& args, const std::optional<crisp::OutputFiles>& screenshot, VulkanWindow& window,
        const crisp::Font& font, LayoutModel& model, EditorView& view) {
    crisp::Result<std::unique_ptr<GpuFrame>> created = GpuFrame::create(window, font, model.layout(), model.contrast());
    if (!created) {
        std::fprintf(stderr, "crisp-layout-editor: Vulkan: %s\n", created.error().message.c_str());
        return kExitVulkan;
    }
    GpuFrame& gpu = **created;
    crisp::Layouter layouter;
    std::vector<TextItem> items;
    FrameText text;
    uint64_t applied_revision = model.revision();
    // What the preview's renderer has: a change of contrast alone keeps the samples.
    std::array<crisp::SampleRect, 3> applied_channels = model.layout().channels;
    crisp::TextContrast applied_contrast = model.contrast();
    std::vector<crisp::SubpixelLayout> applied_candidates;  // compare mode's, as the renderers have them
    crisp::TextContrast candidates_contrast = model.contrast();
    uint64_t frame = 0;
    // With no --frames, once two frames in a row show every glyph converged and the moving line
    // has stopped, the loop sleeps until the window system has something rather than drawing the
    // same frame again; it also sleeps while the window is minimized.
    uint32_t settled_frames = 0;
    uint64_t converged_since = UINT64_MAX;  // the frame the preview's paragraphs converged in
    while (!view.quit_requested()) {
        // The close button asks as Ctrl+Q does; the request is cleared so that Cancel goes on.
        if (window.should_close()) {
            window.set_should_close(false);
            view.request_quit();
            if (view.quit_requested()) break;
        }
        if (crisp::Status status = gpu.wait(); !status) {
            std::fprintf(stderr, "crisp-layout-editor: %s\n", status.error().message.c_str());
            return kExitVulkan;
        }
        if (args.frames != 0 && frame >= args.frames) break;
        FrameStats stats = measure(gpu, text, frame);
        // Since the last edit: the moving line's glyphs share atlas entries with the paragraphs,
        // and a paragraph glyph may dip below the target while the line moves.
        const bool converged = stats.glyphs > 0 && stats.min_samples >= stats.target_samples;
        if (converged && converged_since == UINT64_MAX) converged_since = frame;
        stats.line_moving = converged_since == UINT64_MAX || frame < converged_since + kMovingAfterConverged;
        settled_frames = !stats.line_moving && settled(gpu, text) ? settled_frames + 1 : 0;
        const bool drawable = window.drawable();
        const bool wait = args.frames == 0 && (settled_frames >= 2 || !drawable);
        const std::vector<InputEvent> events = window.poll_events(wait);
        if (!events.empty()) settled_frames = 0;
        for (const InputEvent& event : events) view.handle(event);
        if (!window.drawable()) continue;
        if (model.revision() != applied_revision) {
            applied_revision = model.revision();
            converged_since = UINT64_MAX;  // the line moves again while the edit converges
            if (model.layout().channels != applied_channels) {
                applied_channels = model.layout().channels;
                if (crisp::Status status = gpu.set_preview_layout(model.layout()); !status) {
                    view.report(status.error().message, true);
                }
            }
            if (model.contrast() != applied_contrast) {
                applied_contrast = model.contrast();
                if (crisp::Status status = gpu.set_preview_contrast(applied_contrast); !status) {
                    view.report(status.error().message, true);
                }
            }
        }
        crisp::Result<VulkanWindow::Acquired> acquired = window.acquire();
        if (!acquired) {
            std::fprintf(stderr, "crisp-layout-editor: %s\n", acquired.error().message.c_str());
            return kExitVulkan;
        }
        if (acquired->image == VK_NULL_HANDLE) continue;  // the swapchain was rebuilt
        // The window's size (it may have been resized) and the monitor's scale, for this frame.
        if (crisp::Status status = gpu.match_window(); !status) {
            std::fprintf(stderr, "crisp-layout-editor: %s\n", status.error().message.c_str());
            return kExitVulkan;
        }
        view.resize(window.width(), window.height(), args.ui_scale > 0.0f ? args.ui_scale : window.content_scale());
        Canvas canvas(gpu.canvas(), window.width(), window.height(), view.scale());
        items.clear();
        view.draw(canvas, gpu.previous_frame(), stats, items);
        std::vector<std::string> errors;
        lay_out(layouter, font, items, view.scale(), text, errors);
        for (const std::string& error : errors) view.report("Text layout: " + error, true);
        // The candidates drawn this frame, each with its renderer (none out of compare mode).
        std::vector<crisp::SubpixelLayout> candidate_layouts;
        for (const Candidate& candidate : view.candidates()) candidate_layouts.push_back(candidate.layout);
        if (candidate_layouts != applied_candidates || model.contrast() != candidates_contrast) {
            applied_candidates = candidate_layouts;
            candidates_contrast = model.contrast();
            converged_since = UINT64_MAX;
            if (crisp::Status status = gpu.set_candidates(candidate_layouts, candidates_contrast); !status) {
                view.report("Compare: " + status.error().message, true);
            }
        }
        if (crisp::Status status =
                gpu.render(*acquired, text.interface_glyphs, text.preview_glyphs, text.candidate_glyphs);
            !status) {
            std::fprintf(stderr, "crisp-layout-editor: %s\n", status.error().message.c_str());
            return kExitVulkan;
        }
        if (crisp::Status status = window.present(*acquired); !status) {
            std::fprintf(stderr, "crisp-layout-editor: %s\n", status.error().message.c_str());
            return kExitVulkan;
        }
        ++frame;
    }
    if (crisp::Status status = gpu.wait(); !status) {
        std::fprintf(stderr, "crisp-layout-editor: %s\n", status.error().message.c_str());
        return kExitVulkan;
    }
    if (screenshot && !write_screenshot(*screenshot, gpu.previous_frame(), gpu.width(), gpu.height())) {
        return kExitScreenshot;
    }
    return kExitOk;
}

// --export: the layout, a preset or a file, in that form on stdout and its notes on stderr. A
// layout that does not load is a usage error: there is no window to report it in.
int export_to_stdout(const Args& args) {
    const crisp::Result<crisp::SubpixelLayout> layout = load_layout_argument(args.layout);
    if (!layout) {
        std::fprintf(stderr, "crisp-layout-editor: --layout: %s\n", layout.error().message.c_str());
        return kExitUsage;
    }
    const Exported exported = export_layout(*layout, *export_form(args.export_form));
    for (const std::string& note : exported.notes) {
        std::fprintf(stderr, "crisp-layout-editor: note: %s\n", note.c_str());
    }
    if (std::fputs(exported.text.c_str(), stdout) < 0 || std::fflush(stdout) != 0) {
        std::fprintf(stderr, "crisp-layout-editor: --export: stdout could not be written\n");
        return kExitWrite;
    }
    return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
    const Args args = parse_args(argc, argv);
    if (args.print_geometry) {
        crisp::SubpixelLayout rgb = *crisp::subpixel_preset("rgb");
        LayoutModel model(rgb);
        EditorView view(model, {});
        const auto [width, height] = args.window.value_or(std::pair{kWindowWidth, kWindowHeight});
        view.resize(width, height, args.ui_scale > 0.0f ? args.ui_scale : 1.0f);
        std::printf("%s\n", view.geometry_json().c_str());
        return kExitOk;
    }
    if (!args.export_form.empty()) return export_to_stdout(args);

    std::optional<crisp::OutputFiles> screenshot;
    if (!args.screenshot.empty()) {
        screenshot = declare_screenshot(args);
        if (!screenshot) return kExitScreenshot;
    }

    // The starting layout: a preset by name, else a file. A file that fails to load is reported
    // in the window, and the editor starts from rgb with the file still chosen for saving.
    std::string path = args.save_to;
    std::optional<std::string> load_error;
    crisp::SubpixelLayout initial = *crisp::subpixel_preset("rgb");
    if (path.empty() && !crisp::subpixel_preset(args.layout)) path = args.layout;
    if (crisp::Result<crisp::SubpixelLayout> loaded = load_layout_argument(args.layout); loaded) {
        initial = *loaded;
    } else {
        load_error = loaded.error().message;  // on stderr too, as every message the window shows
    }
    LayoutModel model(initial);
    EditorView view(model, path);
    if (load_error) view.report("Load failed: " + *load_error, true);
    view.set_preview(args.text, args.sizes, args.colours);
    view.set_zoom(args.zoom[0] - '0');  // "1", "2" or "4": --zoom's choices
    view.set_compare(args.compare);
    // Scripted runs (--frames) quit without asking, and show the recent files without changing them.
    view.set_prompt_on_quit(args.frames == 0);
    const std::filesystem::path recent = recent_files_path();
    if (recent.empty()) view.report("Recent files not kept: neither XDG_CONFIG_HOME nor HOME is set", true);
    view.set_recent_file(recent, args.frames == 0);
    if (args.frames == 0 && !load_error && !crisp::subpixel_preset(args.layout)) view.remember(args.layout);

    std::optional<crisp::Font> font = load_font(args.font, args.text);
    if (!font) return kExitFont;
    // Fields place their cursors by the font's own advances (blank clusters' too: a caret after
    // a space), at the window's scale.
    crisp::Layouter measurer;
    view.set_measure([&measurer, &font, &view](std::string_view text, float size) {
        const crisp::Font* fonts[] = {&*font};
        crisp::TextStyle style;
        style.size = size * view.scale();
        crisp::TextLayout laid;
        if (!measurer.layout(fonts, text, style, {}, laid)) return estimated_text_width(text, size);
        float width = 0.0f;
        for (const crisp::TextCluster& cluster : laid.clusters) width += cluster.advance;
        return width / view.scale();
    });

    WindowOptions window_options;
    window_options.width = args.window ? args.window->first : kWindowWidth;
    window_options.height = args.window ? args.window->second : kWindowHeight;
    window_options.fit_to_monitor = !args.window;
    window_options.validation = args.validation;
    crisp::Result<std::unique_ptr<VulkanWindow>> window = VulkanWindow::create(window_options);
    if (!window) {
        std::fprintf(stderr, "crisp-layout-editor: %s\n", window.error().message.c_str());
        return kExitVulkan;
    }
    const int code = run(args, screenshot, **window, *font, model, view);
    const uint32_t messages = (*window)->validation_messages();
    window->reset();  // the instance's teardown is validated too
    if (code != kExitOk) return code;
    if (messages > 0) {
        std::fprintf(stderr, "crisp-layout-editor: the validation layer reported %u message(s)\n", messages);
        return kExitValidation;
    }
    return kExitOk;
}
