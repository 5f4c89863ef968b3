// crisp-bench: one benchmark tool with suites (docs/benchmarks.md). What the suites share: the
// option table (options.cpp), the device, the report they write into, and what one suite leaves
// for another (the frames suite's GPU time per sample count, which the coverage suite's errors
// are plotted against).
#pragma once

#include "headless_context.hpp"
#include "json_writer.hpp"

#include <crisp/compositor.hpp>
#include <crisp/renderer.hpp>

#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace crisp::bench {

// `relative`, a file of the source tree ("fonts/DejaVuSans.ttf"), where this run finds it: from
// the working directory where it is there, else in the source tree crisp-bench was built from
// (CRISP_SOURCE_DIR), so that it runs from anywhere; as given where neither holds it (the error
// that follows names it).
std::string data_file(const std::string& relative);

// The command line. Options several suites read are optional: each suite has its own default,
// which it uses where the option was not given (the --help text lists them).
struct Options {
    std::vector<std::string> suites;  // in the order they run
    bool quick = false;
    std::string out_dir = "docs/results";
    std::string name;  // file name stem; empty: the device's slug
    bool write_files = true;
    bool plots = true;
    bool json = false;  // JSON on stdout instead of Markdown
    std::string json_out;
    std::string device;
    bool validate = false;
    bool validate_sync = false;
    bool shader_stats = false;  // frames, compositing: the driver's statistics of their shaders
    std::string command;        // the command line, as the result file records it

    // Shared by several suites.
    std::vector<std::string> fonts;  // --font: the text's font; coverage: fonts added to its set
    std::optional<float> size;
    std::optional<uint32_t> width, height;  // --canvas
    std::optional<std::string> layout;
    std::optional<uint32_t> samples;
    std::optional<uint32_t> frames;
    std::optional<uint32_t> warmup;

    // frames
    uint32_t atlas_budget_mib = 0;
    uint64_t frame_budget = uint64_t{1} << 50;  // unbounded
    bool no_shared_rows = false;
    std::optional<SampleKind> sample_kind;  // none: both

    // compositing
    std::vector<std::string> modes = {"tiled", "tiled-rebin", "tiled-rgba8", "frame",
                                      "draw",  "exact",       "unsorted",    "wboit"};
    std::vector<uint32_t> layers = {1, 2, 4, 8, 16, 32};
    std::vector<float> alphas = {0.9f, 0.3f};
    bool scenes_given = false;  // --layers or --alphas
    std::optional<double> warmup_ms;
    std::optional<uint32_t> clock_load;
    uint32_t subpixel_steps = 4;
    QuadPath quad_path = QuadPath::raster;
    bool cpu_check = true;
    // The renderer's contrast mode: linear by default, so that every mode composites the same
    // coverage and the modes' errors compare compositing alone; corrected measures the contrast
    // model's passes.
    ContrastMode contrast = ContrastMode::linear;

    // frame-cpu
    std::vector<std::string> variants = {"static", "changed", "moving"};

    // cpu
    std::string dejavu = data_file("fonts/DejaVuSans.ttf");
    std::string inter = data_file("fonts/Inter-Regular.otf");
    std::string cjk = "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc";
    std::optional<int> runs;
    std::string only;

    // contrast
    std::string pictures_dir;  // empty: out_dir

    // coverage
    uint32_t cells_gray = 16;
    uint32_t cells_rgb = 64;
    // --glyph PATH:PX:TEXT, repeatable: these glyphs instead of the suite's set.
    struct CoverageGlyph {
        std::string path;
        float size = 16.0f;
        std::string text;
    };
    std::vector<CoverageGlyph> coverage_glyphs;
    std::optional<float> tolerance;  // --tolerance: the bake's cubic-to-quadratic tolerance, em

    // colour
    std::optional<uint32_t> glyphs;

    // atlas
    std::vector<uint32_t> steps = {256, 64, 16, 8, 4, 2, 1};
    bool steps_given = false;
};

// Every suite, in the order `all` runs them.
struct SuiteInfo {
    const char* name;
    const char* summary;
    bool needs_device;
};
inline constexpr SuiteInfo kSuites[] = {
    {"frames", "GPU ms per frame, new text to converged (was crisp-bench-gpu)", true},
    {"coverage", "atlas error against FreeType's exact area coverage per sample count; FreeType as a peer", true},
    {"compositing", "each compositing mode's GPU ms, error and memory (was crisp-bench-composite)", true},
    {"scaling", "frame cost against the text on screen and against the screen", true},
    {"atlas", "atlas entries of a page at each subpixel quantization, and the error it costs", false},
    {"frame-cpu", "CPU time of a frame of UI text (was crisp-bench-frame)", true},
    {"cpu", "layout and atlas CPU time (was crisp-bench-cpu)", false},
    {"contrast", "ink dark on light against light on dark per contrast setting and size; FreeType as a peer", true},
    {"colour", "colour glyphs (bitmap emoji, COLRv1) beside monochrome text: frame 1, converged, per layer", true},
    {"transform", "rotated, scaled, sheared and perspective text: GPU ms per frame with its error", true},
    {"effects", "outlines, shadows and weight beside plain text: frame 1, converged, composite", true},
};

// Parses argv; prints --help, or exits 2 on a usage error.
Options parse_options(int argc, char** argv);

// A suite's error that ends the run: "crisp-bench: SUITE: MESSAGE" on stderr, exit 1.
[[noreturn]] void fail(std::string_view suite, const std::string& message);
// One line of progress on stderr.
void progress(std::string_view suite, const std::string& message);
// The first "model name" of /proc/cpuinfo, and the build type, optimization, assertions and compiler.
std::string cpu_model();
std::string build_description();

// What the frames suite measured, per layout and sample kind: the samples each glyph holds after
// each frame, and the GPU ms summed through that frame.
struct TimeCurve {
    std::vector<uint32_t> samples;
    std::vector<double> cumulative_ms;
};
// What the coverage suite measured, per layout and sample kind: the errors at each sample count.
struct ErrorPoint {
    uint32_t samples = 0;
    double mean = 0.0;   // mean absolute error per texel channel, averaged over the glyphs
    double worst = 0.0;  // the worst single texel channel over the glyphs
};
using CurveKey = std::pair<std::string, std::string>;  // layout, sample kind ("rows", "points")

// One run of the tool: the device (none for the CPU-only suites alone), the report the suites
// write into, and what they leave for each other.
struct Session {
    explicit Session(const Options& run_options) : options(run_options) {}

    const Options& options;
    std::string name;  // the result files' stem: --name, else the device's slug (-quick with --quick)
    HeadlessContext* context = nullptr;
    bool storage_without_format = false;
    bool cpu_device = false;  // lavapipe and the like: the suites pick smaller defaults
    std::FILE* md = nullptr;  // the Markdown report
    JsonWriter json;          // inside the "suites" object: each suite writes key(name) and its value
    std::vector<std::string> warnings;

    std::map<CurveKey, TimeCurve> frame_time;
    std::map<std::string, double> freetype_screen_ms;  // peer mode ("gray", "lcd") -> CPU ms, the frames' screen
    size_t frames_screen_entries = 0;
    std::map<CurveKey, std::vector<ErrorPoint>> coverage_error;
    std::map<std::string, ErrorPoint> freetype_error;  // peer mode -> error (samples 0)

    void warn(std::string_view suite, const std::string& text);
    // A heading in the Markdown report.
    void heading(const std::string& text);
};

const char* sample_kind_name(SampleKind kind);

void run_frames(Session& session);
void run_coverage(Session& session);
void run_compositing(Session& session);
void run_scaling(Session& session);
void run_atlas(Session& session);
void run_frame_cpu(Session& session);
void run_cpu(Session& session);
void run_contrast(Session& session);
void run_colour(Session& session);
void run_transform(Session& session);
void run_effects(Session& session);

}  // namespace crisp::bench
