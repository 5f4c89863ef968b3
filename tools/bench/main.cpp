// crisp-bench: crisp's benchmarks as suites of one tool (docs/benchmarks.md). main: the options,
// the device, each suite in turn, then the report: Markdown on stdout and, unless --no-files,
// DIR/NAME.md, DIR/NAME.json and the plots scripts/plot_bench.py makes from the JSON.
#include "bench.hpp"
#include "cli.hpp"
#include "gpu_tools.hpp"
#include "vk/resources.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace crisp::bench {

void fail(std::string_view suite, const std::string& message) {
    std::fprintf(stderr, "crisp-bench: %.*s: %s\n", static_cast<int>(suite.size()), suite.data(), message.c_str());
    std::exit(1);
}

std::string data_file(const std::string& relative) {
    std::error_code ec;
    if (std::filesystem::exists(relative, ec)) return relative;
    const std::filesystem::path built = std::filesystem::path(CRISP_SOURCE_DIR) / relative;
    return std::filesystem::exists(built, ec) ? built.string() : relative;
}

void progress(std::string_view suite, const std::string& message) {
    std::fprintf(stderr, "[%.*s] %s\n", static_cast<int>(suite.size()), suite.data(), message.c_str());
}

void Session::warn(std::string_view suite, const std::string& text) {
    std::fprintf(stderr, "crisp-bench: %.*s: warning: %s\n", static_cast<int>(suite.size()), suite.data(),
                 text.c_str());
    warnings.push_back(std::string(suite) + ": " + text);
}

void Session::heading(const std::string& text) {
    std::fprintf(md, "\n### %s\n\n", text.c_str());
}

const char* sample_kind_name(SampleKind kind) {
    return kind == SampleKind::rows ? "rows" : "points";
}

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) != 0) continue;
        const size_t colon = line.find(':');
        if (colon != std::string::npos) return line.substr(std::min(colon + 2, line.size()));
    }
    return "unknown CPU";
}

std::string build_description() {
    std::string build = CRISP_BENCH_BUILD_TYPE[0] ? CRISP_BENCH_BUILD_TYPE : "no CMAKE_BUILD_TYPE";
#ifdef __OPTIMIZE__
    build += ", optimized";
#else
    build += ", NOT optimized";
#endif
#ifdef NDEBUG
    build += ", assertions off";
#else
    build += ", assertions on";
#endif
#if defined(__clang__)
    build += ", Clang " __clang_version__;
#elif defined(__GNUC__)
    build += ", GCC " __VERSION__;
#endif
    return build;
}

namespace {

// The device's name as a file name: lavapipe for Mesa's llvmpipe, else lower case with runs of
// anything but letters and digits as one '-' ("NVIDIA H200" -> nvidia-h200).
std::string device_slug(const HeadlessContext* context) {
    if (!context) return "cpu";
    if (context->driver_name() == "llvmpipe") return "lavapipe";
    std::string slug;
    for (const char c : context->device_name()) {
        if (std::isalnum(static_cast<unsigned char>(c))) {
            slug += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        } else if (!slug.empty() && slug.back() != '-') {
            slug += '-';
        }
    }
    while (!slug.empty() && slug.back() == '-') slug.pop_back();
    return slug.empty() ? "device" : slug;
}

std::string utc_now() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", &tm);
    return text;
}

void run_suite(Session& session, const std::string& name) {
    if (name == "frames") return run_frames(session);
    if (name == "coverage") return run_coverage(session);
    if (name == "compositing") return run_compositing(session);
    if (name == "scaling") return run_scaling(session);
    if (name == "atlas") return run_atlas(session);
    if (name == "frame-cpu") return run_frame_cpu(session);
    if (name == "cpu") return run_cpu(session);
    if (name == "contrast") return run_contrast(session);
    if (name == "colour") return run_colour(session);
    if (name == "transform") return run_transform(session);
    if (name == "effects") return run_effects(session);
}

// The error at each sample count against the GPU ms the frames suite spent reaching that count:
// where both suites ran, per layout and sample kind.
void print_error_against_time(Session& session) {
    if (session.frame_time.empty() || session.coverage_error.empty()) return;
    std::fprintf(session.md, "\n## Error against cumulative GPU time (frames and coverage together)\n\n");
    std::fprintf(session.md,
                 "The coverage suite's error at N samples, against the GPU ms the frames suite's screen took to give "
                 "every glyph N samples (the frames summed from new text on; N only where a frame ends on it). "
                 "FreeType: its error, against the CPU ms (one thread) it takes to render the screen's %zu atlas "
                 "entries.\n\n",
                 session.frames_screen_entries);
    std::fprintf(session.md,
                 "| layout | samples | cumulative GPU ms | mean | worst texel |\n|---|---|---:|---:|---:|\n");
    for (const auto& [key, curve] : session.frame_time) {
        const auto errors = session.coverage_error.find(key);
        if (errors == session.coverage_error.end()) continue;
        for (const ErrorPoint& e : errors->second) {
            for (size_t f = 0; f < curve.samples.size(); ++f) {
                if (curve.samples[f] != e.samples) continue;
                std::fprintf(session.md, "| %s | %u %s | %.1f | %.4f | %.4f |\n", key.first.c_str(), e.samples,
                             key.second.c_str(), curve.cumulative_ms[f], e.mean, e.worst);
            }
        }
    }
    for (const auto& [mode, ms] : session.freetype_screen_ms) {
        const auto error = session.freetype_error.find(mode);
        if (error == session.freetype_error.end()) continue;
        std::fprintf(session.md, "| %s | FreeType %s (CPU ms) | %.2f | %.4f | %.4f |\n",
                     mode == "gray" ? "gray" : "rgb", mode.c_str(), ms, error->second.mean, error->second.worst);
    }
}

// Runs scripts/plot_bench.py on the JSON with the first python3 that has matplotlib (the one on
// PATH, else Debian's); returns the PNGs it wrote, or says how to make them.
std::vector<std::string> make_plots(const std::filesystem::path& json_path, std::string& note) {
    const std::string script = std::string(CRISP_SOURCE_DIR) + "/scripts/plot_bench.py";
    const std::string how = "python3 scripts/plot_bench.py " + json_path.string();
    std::string python;
    for (const char* candidate : {"python3", "/usr/bin/python3"}) {
        if (std::system((std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            python = candidate;
            break;
        }
    }
    if (python.empty()) {
        note =
            "No plots: python3 with matplotlib was not found (Debian: python3-matplotlib, which "
            "scripts/setup.sh installs). Make them with `" +
            how + "`.";
        return {};
    }
    const std::string command = python + " '" + script + "' '" + json_path.string() + "'";
    std::vector<std::string> pngs;
    std::FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) {
        note = "No plots: could not run " + script + ". Make them with `" + how + "`.";
        return {};
    }
    char line[4096];
    while (std::fgets(line, sizeof line, pipe)) {
        std::string name = line;
        while (!name.empty() && (name.back() == '\n' || name.back() == '\r')) name.pop_back();
        if (!name.empty()) pngs.push_back(std::filesystem::path(name).filename().string());
    }
    if (pclose(pipe) != 0) note = "scripts/plot_bench.py failed (its message is above); `" + how + "` retries.";
    return pngs;
}

// Every suite in turn, each under its heading and key: opens the JSON document and its "suites"
// object (finish_json closes them); returns the Markdown the suites wrote.
std::string run_suites(Session& session) {
    char* body = nullptr;
    size_t body_size = 0;
    session.md = open_memstream(&body, &body_size);
    if (!session.md) fail("report", "open_memstream failed");
    session.json.begin_object().key("suites").begin_object();
    for (const std::string& suite : session.options.suites) {
        const auto start = std::chrono::steady_clock::now();
        progress(suite, "start");
        const auto info =
            std::find_if(std::begin(kSuites), std::end(kSuites), [&](const SuiteInfo& s) { return suite == s.name; });
        std::fprintf(session.md, "\n## %s: %s\n\n", suite.c_str(), info->summary);
        session.json.key(suite);
        run_suite(session, suite);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress(suite, "done in " + std::to_string(static_cast<int>(seconds + 0.5)) + " s");
        std::fprintf(session.md, "\n(%s suite: %.0f s of wall time.)\n", suite.c_str(), seconds);
    }
    print_error_against_time(session);
    std::fclose(session.md);
    const std::string tables(body, body_size);
    std::free(body);
    return tables;
}

std::string device_name(const HeadlessContext* context) {
    return context ? context->device_name() : "none (CPU suites only)";
}

std::string driver_name(const HeadlessContext* context) {
    return context->driver_name() + " (" + context->driver_info() + ")";
}

// The report's first lines: what made it (the command), on what device, CPU and build, and when.
std::string report_header(const Session& session) {
    const Options& options = session.options;
    const HeadlessContext* context = session.context;
    std::string header = "# crisp-bench: " + device_name(context) + "\n\nMade by, from the repository root:\n\n    " +
                         options.command + "\n\n";
    header += "Device: " + device_name(context) + (context ? ", driver " + driver_name(context) : "") +
              (context ? ", Vulkan " + vk::version_string(context->api_version()) : "") + ". CPU: " + cpu_model() +
              ", " + std::to_string(std::thread::hardware_concurrency()) +
              " hardware threads. Build: " + build_description() + ". Run " + utc_now() +
              (options.quick ? "; --quick: the numbers mean little" : "") +
              (options.validate ? "; validation layer on: the times are not the library's" : "") + ".\n";
    return header;
}

// Closes the "suites" object, adds what the run was (as the header says it) and closes the document.
void finish_json(Session& session) {
    const Options& options = session.options;
    session.json.end_object()
        .field("tool", "crisp-bench")
        .field("command", options.command)
        .field("device", device_name(session.context))
        .field("driver", session.context ? driver_name(session.context) : "")
        .field("cpu_device", session.cpu_device)
        .field("cpu", cpu_model())
        .field("hardware_threads", std::thread::hardware_concurrency())
        .field("build", build_description())
        .field("date", utc_now())
        .field("quick", options.quick)
        .field("validation", options.validate)
        .field("warnings", session.warnings)
        .end_object();
}

// DIR/NAME.json, the plots made from it, and DIR/NAME.md: the header, warnings, tables and plots.
void write_result_files(Session& session, const std::string& header, const std::string& tables) {
    const Options& options = session.options;
    const std::string& name = session.name;
    std::error_code ec;
    std::filesystem::create_directories(options.out_dir, ec);
    const std::filesystem::path json_path = std::filesystem::path(options.out_dir) / (name + ".json");
    if (Status s = session.json.write_file(json_path); !s) fail("report", s.error().message);
    std::string note;
    std::vector<std::string> pngs;
    if (options.plots) pngs = make_plots(json_path, note);
    std::string plots = "\n## Plots\n\nFrom " + json_path.filename().string() + " by scripts/plot_bench.py.\n\n";
    for (const std::string& png : pngs) plots += "![" + png + "](" + png + ")\n\n";
    if (!note.empty()) plots += note + "\n";
    if (!options.plots) plots += "Not made (--no-plots): `python3 scripts/plot_bench.py " + json_path.string() + "`.\n";
    const std::filesystem::path md_path = std::filesystem::path(options.out_dir) / (name + ".md");
    std::ofstream md(md_path, std::ios::binary);
    md << header;
    if (!session.warnings.empty()) {
        md << "\nWarnings:\n\n";
        for (const std::string& w : session.warnings) md << "- " << w << "\n";
    }
    md << tables << plots;
    if (!md.good()) fail("report", "could not write " + md_path.string());
    progress("report", "wrote " + md_path.string() + ", " + json_path.string() + " and " + std::to_string(pngs.size()) +
                           " plots");
}

}  // namespace
}  // namespace crisp::bench

int main(int argc, char** argv) {
    using namespace crisp::bench;
    const Options options = parse_options(argc, argv);

    const bool needs_device = std::any_of(options.suites.begin(), options.suites.end(), [](const std::string& name) {
        return std::any_of(std::begin(kSuites), std::end(kSuites),
                           [&](const SuiteInfo& s) { return name == s.name && s.needs_device; });
    });
    std::optional<crisp::HeadlessContext> context;
    Session session(options);
    if (needs_device) {
        crisp::HeadlessContextOptions context_options;
        context_options.validation = options.validate;
        context_options.synchronization_validation = options.validate_sync;
        context_options.device_name_contains = options.device;
        context_options.shader_statistics = options.shader_stats;
        auto made = crisp::tools::create_context(context_options, session.storage_without_format);
        if (!made) fail("device", made.error().message);
        context = std::move(*made);
        session.context = &*context;
        session.cpu_device = context->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    }
    session.name =
        !options.name.empty() ? options.name : device_slug(session.context) + (options.quick ? "-quick" : "");

    const std::string tables = run_suites(session);

    const std::string header = report_header(session);
    finish_json(session);
    if (options.write_files) write_result_files(session, header, tables);
    if (options.json) {
        std::fputs(session.json.line().c_str(), stdout);
    } else {
        std::fputs((header + tables).c_str(), stdout);
    }
    if (!options.json_out.empty()) {
        if (crisp::Status s = session.json.write_file(options.json_out); !s) fail("report", s.error().message);
    }
    if (context) {
        const auto messages = context->validation_messages();
        if (messages.errors + messages.warnings > 0) {
            std::fprintf(stderr, "validation: %u errors, %u warnings\n", messages.errors, messages.warnings);
            for (const auto& m : messages.recent) std::fprintf(stderr, "%s\n", m.c_str());
            return 1;
        }
    }
    return 0;
}
