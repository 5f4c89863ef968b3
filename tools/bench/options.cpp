// crisp-bench's option table: one CommandLine gives the parsing and --help. Options that several
// suites read keep the names and meanings the separate tools gave them; each suite takes its own
// default where one is not given.
#include "bench.hpp"
#include "cli.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace crisp::bench {
namespace {

// A comma-separated list of numbers, each within `range`, into `target`.
template <class T>
cli::CommandLine::Apply number_list(std::vector<T>& target, const char* option, cli::Range<T> range) {
    return [&target, option, range](std::string_view text) -> Status {
        target.clear();
        for (const std::string_view item : cli::split(text, ',')) {
            Result<T> value = cli::CommandLine::checked_number<T>(option, item, range);
            if (!value) return value.error();
            target.push_back(*value);
        }
        return {};
    };
}

cli::CommandLine::Apply name_list(std::vector<std::string>& target) {
    return [&target](std::string_view text) {
        const std::vector<std::string_view> names = cli::split(text, ',');
        target.assign(names.begin(), names.end());
        return Status{};
    };
}

// --glyph PATH:PX:TEXT; the path ends at the first colon, the size at the second, the text may hold more.
Status parse_coverage_glyph(Options& options, std::string_view text) {
    const size_t first = text.find(':');
    const size_t second = first == std::string_view::npos ? first : text.find(':', first + 1);
    const Error usage{
        ErrorCode::invalid_argument,
        "--glyph: PATH:PX:TEXT (a font, pixels per em in [1, 4096], text), not '" + cli::printable(text) + "'"};
    if (second == std::string_view::npos || first == 0 || second + 1 == text.size()) return usage;
    const std::optional<float> px = cli::parse_number<float>(text.substr(first + 1, second - first - 1));
    if (!px || !(*px >= 1.0f && *px <= 4096.0f)) return usage;
    options.coverage_glyphs.push_back({std::string(text.substr(0, first)), *px, std::string(text.substr(second + 1))});
    return {};
}

// --canvas W,H or WxH, each side 16..16384.
Status parse_canvas(Options& options, std::string_view text) {
    auto size =
        cli::parse_number_list<uint32_t>("--canvas", text, text.find('x') != std::string_view::npos ? 'x' : ',');
    if (!size) return size.error();
    if (size->size() != 2 || (*size)[0] < 16 || (*size)[1] < 16 || (*size)[0] > 16384 || (*size)[1] > 16384) {
        return Error{ErrorCode::invalid_argument, "--canvas: WxH (or W,H), each side in 16..16384"};
    }
    options.width = (*size)[0];
    options.height = (*size)[1];
    return {};
}

std::string synopsis() {
    std::string text =
        "usage: crisp-bench [--suite NAME]... [--quick] [options]\n"
        "Measures crisp on one Vulkan device and writes DIR/<device>.md (the tables and the command\n"
        "that made them), DIR/<device>.json and PNG plots beside them (scripts/plot_bench.py, where\n"
        "python3 and matplotlib are installed). The Markdown also goes to stdout; progress to stderr.\n"
        "On a CPU device (lavapipe) the suites pick smaller canvases. docs/benchmarks.md.\n\n"
        "suites (--suite, repeatable, or all; default all):\n";
    for (const SuiteInfo& suite : kSuites) {
        text += "  " + std::string(suite.name) + std::string(14 - std::string_view(suite.name).size(), ' ') +
                suite.summary + "\n";
    }
    return text + "\n";
}

void declare_run_options(cli::CommandLine& cli, Options& o) {
    cli.section("the run:");
    cli.option("--suite", "NAME", "a suite to run (repeatable), or all", [&o](std::string_view text) -> Status {
        if (text == "all") {
            for (const SuiteInfo& suite : kSuites) o.suites.emplace_back(suite.name);
            return {};
        }
        const bool known = std::any_of(std::begin(kSuites), std::end(kSuites),
                                       [&](const SuiteInfo& suite) { return text == suite.name; });
        if (!known) {
            std::string names;
            for (const SuiteInfo& suite : kSuites) names += std::string(names.empty() ? "" : ", ") + suite.name;
            return Error{ErrorCode::invalid_argument,
                         "--suite: unknown suite '" + cli::printable(text) + "' (" + names + " or all)"};
        }
        o.suites.emplace_back(text);
        return {};
    });
    cli.flag("--quick",
             "a small run of every suite chosen (under a minute on lavapipe):\n"
             "checks that the tool works; its numbers mean little",
             o.quick);
    cli.text("--out", "DIR", "where the result files go (default docs/results)", o.out_dir);
    cli.text("--name", "NAME",
             "their name (default: the device's, e.g. lavapipe, nvidia-h200;\n"
             "with --quick, that and -quick)",
             o.name);
    cli.flag("--no-files", "write no files: Markdown on stdout only", o.write_files, false);
    cli.flag("--no-plots", "do not run scripts/plot_bench.py", o.plots, false);
    cli.flag("--json", "print JSON instead of Markdown on stdout", o.json);
    cli.text("--json-out", "FILE", "also write the JSON to FILE", o.json_out);
    cli.text("--device", "TEXT", "pick a device whose name contains TEXT", o.device);
    cli.flag("--validate", "turn the validation layer on (the times then mean little)", o.validate);
    cli.flag("--validate-sync", "the validation layer with synchronization validation",
             [&o] { o.validate = o.validate_sync = true; });
    cli.flag("--shader-stats",
             "frames, compositing: the driver's statistics of the rasterizer's and the\n"
             "compositor's shaders (registers, spills, ...) after their tables, where the\n"
             "device offers VK_KHR_pipeline_executable_properties",
             o.shader_stats);
}

void declare_shared_options(cli::CommandLine& cli, Options& o) {
    cli.section("options several suites read (each suite's default in brackets):");
    cli.option("--font", "PATH",
               "the text's font, baked at start [fonts/DejaVuSans.ttf];\n"
               "coverage: a font added to its glyph set (repeatable)",
               [&o](std::string_view text) {
                   o.fonts.emplace_back(text);
                   return Status{};
               });
    cli.number<float>("--size", "PX", "pixels per em [frames, scaling, atlas, frame-cpu 16; compositing 18]", o.size,
                      {4.0f, 256.0f});
    cli.option("--canvas", "WxH",
               "the target, also W,H [frames, frame-cpu 1920x1080, on a CPU device\n"
               "640x360; compositing 512x256; scaling: its text-amount series' canvas]",
               [&o](std::string_view text) { return parse_canvas(o, text); });
    cli.text("--layout", "NAME", "subpixel layout preset or file [frames: gray and rgb; compositing rgb]", o.layout);
    cli.number<uint32_t>("--samples", "N",
                         "samples per glyph to converge to [512; frames, coverage: 16 with --quick];\n"
                         "coverage: its largest sample count",
                         o.samples, {1, 65536});
    cli.number<uint32_t>("--frames", "N",
                         "frames: stop after N frames even if not converged [1000];\n"
                         "compositing: timed frames per mode [10]; frame-cpu: per variant [1000]",
                         o.frames, {1, 1000000});
    cli.number<uint32_t>("--warmup", "N",
                         "untimed runs first: compositing frames per mode, at least 2 [2];\n"
                         "frame-cpu frames per variant [100]; cpu runs per case [3]",
                         o.warmup, {0, 1000000});
}

void declare_suite_options(cli::CommandLine& cli, Options& o) {
    cli.section("frames:");
    cli.number<uint32_t>("--atlas-budget", "MIB",
                         "let the 2048x2048 atlas grow to MIB mebibytes (default 0: it does not)", o.atlas_budget_mib);
    cli.number<uint64_t>("--frame-budget", "TESTS",
                         "curve tests per frame (default 2^50, unbounded;\nthe library's default is 2^26)",
                         o.frame_budget, {1, std::numeric_limits<uint64_t>::max()});
    cli.flag("--no-shared-rows", "solve roots per channel even where channels share rows", o.no_shared_rows);
    cli.choice<std::optional<SampleKind>>(
        "--sample-kind", "KIND", "rows (exact in x) or points (default: both; coverage too)", o.sample_kind,
        {SampleKind::rows, SampleKind::points},
        [](const std::optional<SampleKind>& kind) { return std::string(kind ? sample_kind_name(*kind) : ""); });

    cli.section("coverage:");
    cli.number<uint32_t>("--cells-gray", "S", "reference cells per texel side for gray (default 16)", o.cells_gray,
                         {1, 256});
    cli.number<uint32_t>("--cells-rgb", "S", "... for rgb thirds (default 64)", o.cells_rgb, {1, 256});
    cli.option("--glyph", "PATH:PX:TEXT",
               "the glyphs of TEXT in the font at PATH at PX pixels per em, instead of\n"
               "the suite's set (repeatable; PX in [1, 4096])",
               [&o](std::string_view text) { return parse_coverage_glyph(o, text); });
    cli.number<float>("--tolerance", "EM", "the bake's cubic-to-quadratic tolerance (default: crisp-bake's)",
                      o.tolerance, {1e-7f, 0.1f});

    cli.section("compositing:");
    cli.option("--modes", "LIST",
               "modes, comma-separated, from tiled (the tile path into RGBA32F; static\n"
               "text: the bins are reused), tiled-rebin (binned every frame),\n"
               "tiled-rgba8 (into R8G8B8A8_UNORM), frame (the renderer's converged\n"
               "frame and the tile path together), draw (the draw path, RGBA32F),\n"
               "exact, unsorted and wboit (default: all of them)",
               name_list(o.modes));
    cli.option("--layers", "LIST",
               "layer counts, comma-separated (default 1,2,4,8,16,32; on a CPU\n"
               "device, unless --layers or --alphas is given, 1,4,32 at alpha 0.9)",
               number_list<uint32_t>(o.layers, "--layers", {1, 1024}));
    cli.option("--alphas", "LIST", "text alphas, comma-separated, in (0, 1] (default 0.9,0.3)",
               number_list<float>(o.alphas, "--alphas", {0.0f, 1.0f, true}));
    cli.number<double>("--warmup-ms", "T", "... and more warm-up frames until T ms have passed (default 500)",
                       o.warmup_ms, {0.0, 600000.0});
    cli.number<uint32_t>("--clock-load", "N",
                         "untimed clears of a 3840x2160 RGBA32F image before each frame's\n"
                         "timed commands, so that the GPU keeps its clocks between frames\n"
                         "(default 8; on a CPU device 0)",
                         o.clock_load, {0, 1000});
    cli.number<uint32_t>("--subpixel-steps", "N", "subpixel positions per pixel in glyph keys (default 4)",
                         o.subpixel_steps);
    cli.choice<QuadPath>("--path", "NAME",
                         "quad passes of wboit and exact: raster or compute\n"
                         "(default raster; unsorted is always rasterized)",
                         o.quad_path, {QuadPath::raster, QuadPath::compute},
                         [](const QuadPath& path) { return std::string(quad_path_name(path)); });
    cli.flag("--no-cpu-check", "skip checking the exact mode against the CPU reference", o.cpu_check, false);
    cli.choice<ContrastMode>("--contrast", "MODE",
                             "linear (coverage as it is; the default, so that the modes' errors\n"
                             "compare compositing alone) or corrected (the contrast model's passes)",
                             o.contrast, {ContrastMode::linear, ContrastMode::corrected}, [](const ContrastMode& mode) {
                                 return std::string(mode == ContrastMode::linear ? "linear" : "corrected");
                             });

    cli.section("atlas:");
    cli.option("--steps", "LIST", "subpixel steps per pixel, comma-separated (default 256,64,16,8,4,2,1)",
               number_list<uint32_t>(o.steps, "--steps", {1, 256}));

    cli.section("frame-cpu:");
    cli.option("--variants", "LIST",
               "comma-separated, from static (nothing changes), changed (3 strings laid out\n"
               "again every frame) and moving (as changed, and every label moves every frame)\n"
               "(default static,changed,moving)",
               name_list(o.variants));

    cli.section("cpu, contrast, colour:");
    cli.text("--dejavu", "PATH", "DejaVu Sans (default fonts/DejaVuSans.ttf)", o.dejavu);
    cli.text("--inter", "PATH", "Inter Regular, first font of the fallback chain (default fonts/Inter-Regular.otf)",
             o.inter);
    cli.text("--cjk", "PATH",
             "Noto Sans CJK collection, third font of the chain\n"
             "(default /usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc)",
             o.cjk);
    cli.number<int>("--runs", "N", "timed runs per case (default 21)", o.runs, {1, 1000000});

    cli.section("contrast:");
    cli.text("--pictures", "DIR", "where its pictures go (default: the --out directory)", o.pictures_dir);
    cli.text("--only", "TEXT", "run only the cases whose name contains TEXT", o.only);

    cli.section("colour:");
    cli.number<uint32_t>("--glyphs", "N", "glyphs on each screen (default 1000; 100 with --quick)", o.glyphs,
                         {1, 100000});
}

}  // namespace

Options parse_options(int argc, char** argv) {
    Options o;
    cli::CommandLine cli("crisp-bench", synopsis());
    cli.on_usage_error(2, " (crisp-bench --help lists the suites and options)");
    declare_run_options(cli, o);
    declare_shared_options(cli, o);
    declare_suite_options(cli, o);
    cli.epilogue("\nexit status: 0 measured, 1 a failure while measuring (or validation messages), 2 usage.\n");
    cli.parse(argc, argv);
    o.scenes_given = cli.given("--layers") || cli.given("--alphas");
    o.steps_given = cli.given("--steps");
    if (o.suites.empty()) {
        for (const SuiteInfo& suite : kSuites) o.suites.emplace_back(suite.name);
    }
    std::vector<std::string> unique;
    for (const std::string& s : o.suites) {
        if (std::find(unique.begin(), unique.end(), s) == unique.end()) unique.push_back(s);
    }
    o.suites = std::move(unique);
    for (const std::string& mode : o.modes) {
        static const char* const kModes[] = {"tiled", "tiled-rebin", "tiled-rgba8", "frame",
                                             "draw",  "exact",       "unsorted",    "wboit"};
        if (std::find(std::begin(kModes), std::end(kModes), mode) == std::end(kModes)) {
            cli.fail("--modes: unknown mode '" + cli::printable(mode) + "'");
        }
    }
    const bool exact = std::find(o.modes.begin(), o.modes.end(), "exact") != o.modes.end();
    if (!o.cpu_check && !exact) cli.fail("--no-cpu-check needs the exact mode as the reference");
    if (o.warmup && *o.warmup < 2 && std::find(o.suites.begin(), o.suites.end(), "compositing") != o.suites.end()) {
        cli.fail("--warmup: the compositing suite needs at least 2 (its frames in flight)");
    }
    for (const std::string& v : o.variants) {
        if (v != "static" && v != "changed" && v != "moving") {
            cli.fail("--variants: unknown variant '" + cli::printable(v) + "'");
        }
    }
    for (uint32_t s : o.steps) {
        if ((s & (s - 1)) != 0) cli.fail("--steps: " + std::to_string(s) + " is not a power of two");
    }
    for (int i = 0; i < argc; ++i) {
        std::string arg = i == 0 ? "crisp-bench" : cli::printable(argv[i]);
        if (arg.empty() || arg.find_first_of(" \"'$`") != std::string::npos) arg = "'" + arg + "'";
        o.command += (i ? " " : "") + arg;
    }
    return o;
}

}  // namespace crisp::bench
