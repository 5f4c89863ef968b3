// crisp-bake: turns a font into a .crisp asset, or checks an asset.
#include "cli.hpp"
#include "file_io.hpp"
#include "json.hpp"
#include "utf8.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace {

// Exit codes, documented in --help and docs/crisp-bake.md.
enum ExitCode : int {
    kExitOk = 0,
    kExitInternal = 1,      // a bug: the baked asset failed its own validation
    kExitUsage = 2,         // bad command line
    kExitFont = 3,          // the font cannot be read or is not supported
    kExitOutput = 4,        // the asset cannot be written
    kExitGlyphs = 5,        // glyphs failed to convert (without --allow-failed)
    kExitInvalidAsset = 6,  // --check: the asset is invalid or unreadable
};

constexpr const char* kUsage = R"(usage: crisp-bake FONT [options]
       crisp-bake --check ASSET.crisp [--json]

Bakes a font (TrueType, OpenType CFF/CFF2, a collection, a variable font) into a .crisp asset:
quadratic curves in em units, cut into bands, with the font's metrics and bytes.

options:
  -o, --output OUT.crisp   where to write the asset (default: FONT's name with .crisp, here)
  --face N                 face N of a collection (.ttc); default 0
  --var TAG=VALUE          a variation axis value, e.g. --var wght=700; repeatable
  --text UTF8              bake only the glyphs this text needs (with ligatures and
                           alternates shaping can substitute, and .notdef)
  --codepoints RANGES      the same for code points: U+0020-007E,0x4E00-0x4E10,65
  --tolerance EM           largest cubic-to-quadratic deviation in em (default 1/4096)
  --split-y-extrema        split curves at their y-extrema (measured not to pay; see docs)
  --max-curves N           a glyph with more than N curves fails, 1..4096 (default 4096)
  --allow-failed           bake failed glyphs as empty glyphs instead of giving up
  --json                   print the report as JSON on stdout
  -q, --quiet              no progress bar and no report (errors still go to stderr)
  --check ASSET            validate an asset and print its summary
  -h, --help               this text

exit codes:
  0 success   2 usage error   3 unreadable or unsupported font   4 output not writable
  5 glyphs failed   6 invalid asset (--check)   1 internal error
)";

struct Arguments {
    std::string font;
    std::string output;
    std::string check;
    crisp::BakeOptions bake;
    bool json = false;
    bool quiet = false;
};

[[noreturn]] void usage_error(const std::string& message) {
    std::fprintf(stderr, "crisp-bake: %s\n(run crisp-bake --help for usage)\n", message.c_str());
    std::exit(kExitUsage);
}

template <class T>
T parse_number(std::string_view option, std::string_view text) {
    std::string why;
    const std::optional<T> value = crisp::cli::parse_number<T>(text, &why);
    if (!value) usage_error(std::string(option) + ": '" + std::string(text) + "' " + why);
    return *value;
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments args;
    bool have_text = false, have_codepoints = false;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        auto value = [&]() -> std::string_view {
            if (i + 1 >= argc) usage_error(std::string(arg) + " needs a value");
            return argv[++i];
        };
        if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            std::exit(kExitOk);
        } else if (arg == "-o" || arg == "--output") {
            args.output = value();
        } else if (arg == "--face") {
            args.bake.face_index = parse_number<uint32_t>(arg, value());
        } else if (arg == "--var") {
            auto variation = crisp::parse_variation(value());
            if (!variation) usage_error(variation.error().message);
            args.bake.variations.push_back(*variation);
        } else if (arg == "--text") {
            have_text = true;
            const auto codepoints = crisp::decode_utf8(value());
            args.bake.codepoints.insert(args.bake.codepoints.end(), codepoints.begin(), codepoints.end());
            args.bake.all_glyphs = false;
        } else if (arg == "--codepoints") {
            have_codepoints = true;
            auto codepoints = crisp::parse_codepoint_ranges(value());
            if (!codepoints) usage_error(codepoints.error().message);
            args.bake.codepoints.insert(args.bake.codepoints.end(), codepoints->begin(), codepoints->end());
            args.bake.all_glyphs = false;
        } else if (arg == "--tolerance") {
            args.bake.tolerance_em = parse_number<float>(arg, value());
            if (!(args.bake.tolerance_em > 0.0f && args.bake.tolerance_em <= 0.1f)) {
                usage_error("--tolerance must be in (0, 0.1] em");
            }
        } else if (arg == "--split-y-extrema") {
            args.bake.split_y_extrema = true;
        } else if (arg == "--max-curves") {
            args.bake.max_curves_per_glyph = parse_number<uint32_t>(arg, value());
            if (args.bake.max_curves_per_glyph == 0 || args.bake.max_curves_per_glyph > crisp::kMaxCurvesPerGlyph) {
                usage_error("--max-curves must be 1 to " + std::to_string(crisp::kMaxCurvesPerGlyph));
            }
        } else if (arg == "--allow-failed") {
            args.bake.allow_failed = true;
        } else if (arg == "--json") {
            args.json = true;
        } else if (arg == "-q" || arg == "--quiet") {
            args.quiet = true;
        } else if (arg == "--check") {
            args.check = value();
        } else if (arg.size() > 1 && arg[0] == '-') {
            usage_error("unknown option " + std::string(arg));
        } else if (args.font.empty()) {
            args.font = arg;
        } else {
            usage_error("more than one font given ('" + args.font + "' and '" + std::string(arg) + "')");
        }
    }
    if (have_text && have_codepoints) usage_error("--text and --codepoints exclude each other");
    if (!args.check.empty()) {
        if (!args.font.empty()) usage_error("--check takes an asset, not a font");
        return args;
    }
    if (args.font.empty()) usage_error("no font given");
    if (args.output.empty()) {
        std::string stem = std::filesystem::path(args.font).stem().string();
        if (args.bake.face_index > 0) stem += "-face" + std::to_string(args.bake.face_index);
        args.output = stem + ".crisp";
    }
    return args;
}

std::string json_string(std::string_view s) {
    return crisp::json::quote(s);
}

std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", v);
    return buffer;
}

double peak_rss_bytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) * 1024.0;
}

std::string human_bytes(double bytes) {
    char buffer[32];
    if (bytes >= 1024.0 * 1024.0)
        std::snprintf(buffer, sizeof buffer, "%.1f MiB", bytes / (1024.0 * 1024.0));
    else if (bytes >= 1024.0)
        std::snprintf(buffer, sizeof buffer, "%.1f KiB", bytes / 1024.0);
    else
        std::snprintf(buffer, sizeof buffer, "%.0f B", bytes);
    return buffer;
}

void draw_progress(uint32_t done, uint32_t total) {
    constexpr int kWidth = 40;
    const int filled = total ? static_cast<int>(static_cast<uint64_t>(done) * kWidth / total) : kWidth;
    std::fprintf(stderr, "\r  [%.*s%*s] %u/%u glyphs", filled, "########################################",
                 kWidth - filled, "", done, total);
    if (done == total) std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
}

std::string axes_text(const crisp::FontInfo& info) {
    std::string text;
    for (const crisp::AxisValue& axis : info.axes) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "%s%s=%g [%g..%g]", text.empty() ? "" : ", ",
                      crisp::tag_to_string(axis.tag).c_str(), static_cast<double>(axis.value),
                      static_cast<double>(axis.minimum), static_cast<double>(axis.maximum));
        text += buffer;
    }
    return text;
}

std::string axes_json(const crisp::FontInfo& info) {
    std::string text = "[";
    for (const crisp::AxisValue& axis : info.axes) {
        text += (text.size() > 1 ? ", " : "") + std::string("{\"tag\": ") +
                json_string(crisp::tag_to_string(axis.tag)) + ", \"value\": " + json_number(axis.value) +
                ", \"min\": " + json_number(axis.minimum) + ", \"default\": " + json_number(axis.default_value) +
                ", \"max\": " + json_number(axis.maximum) + "}";
    }
    return text + "]";
}

int run_check(const Arguments& args) {
    auto asset = crisp::load_asset_file(args.check);
    if (!asset) {
        std::fprintf(stderr, "crisp-bake: %s: %s\n", args.check.c_str(), asset.error().message.c_str());
        if (args.json) {
            std::printf("{\"valid\": false, \"error\": %s, \"message\": %s}\n",
                        json_string(crisp::error_code_name(asset.error().code)).c_str(),
                        json_string(asset.error().message).c_str());
        }
        return kExitInvalidAsset;
    }
    const crisp::FontInfo& info = asset->info;
    uint64_t baked = 0, failed = 0, outlined = 0, slots = 0, bands = 0;
    for (const crisp::GlyphRecord& glyph : asset->glyphs) {
        baked += (glyph.flags & crisp::kGlyphBaked) != 0;
        failed += (glyph.flags & crisp::kGlyphFailed) != 0;
        outlined += glyph.curve_count > 0;
        slots += glyph.curve_count;
        bands += glyph.band_count;
    }
    if (args.json) {
        std::printf(
            "{\"valid\": true, \"family\": %s, \"style\": %s, \"units_per_em\": %u, \"face_index\": %u, "
            "\"ascender\": %d, \"descender\": %d, \"line_gap\": %d, \"cubic\": %s, \"axes\": %s, "
            "\"glyphs\": %zu, \"baked_glyphs\": %llu, \"failed_glyphs\": %llu, \"outlined_glyphs\": %llu, "
            "\"curve_slots\": %llu, \"points\": %zu, \"bands\": %llu, \"band_words\": %zu, "
            "\"font_bytes\": %zu, \"tolerance_em\": %s, \"max_deviation_em\": %s}\n",
            json_string(info.family).c_str(), json_string(info.style).c_str(), info.units_per_em, info.face_index,
            info.ascender, info.descender, info.line_gap, (info.flags & crisp::kFontCubic) ? "true" : "false",
            axes_json(info).c_str(), asset->glyphs.size(), static_cast<unsigned long long>(baked),
            static_cast<unsigned long long>(failed), static_cast<unsigned long long>(outlined),
            static_cast<unsigned long long>(slots), asset->points.size(), static_cast<unsigned long long>(bands),
            asset->band_words.size(), asset->font_bytes.size(), json_number(info.tolerance_em).c_str(),
            json_number(info.max_deviation_em).c_str());
    } else if (!args.quiet) {
        std::printf("%s: valid crisp asset (version %u)\n", args.check.c_str(), crisp::kAssetVersion);
        std::printf("  font        %s %s, face %u, %u units per em%s\n", crisp::cli::printable(info.family).c_str(),
                    crisp::cli::printable(info.style).c_str(),
                    info.face_index, info.units_per_em, (info.flags & crisp::kFontCubic) ? ", cubic outlines" : "");
        if (!info.axes.empty()) std::printf("  axes        %s\n", axes_text(info).c_str());
        std::printf("  metrics     ascender %d, descender %d, line gap %d\n", info.ascender, info.descender,
                    info.line_gap);
        std::printf("  glyphs      %zu in the face, %llu baked (%llu with outlines, %llu failed)\n",
                    asset->glyphs.size(), static_cast<unsigned long long>(baked),
                    static_cast<unsigned long long>(outlined), static_cast<unsigned long long>(failed));
        std::printf("  curves      %llu slots, %zu points; %llu bands, %zu bitset words\n",
                    static_cast<unsigned long long>(slots), asset->points.size(),
                    static_cast<unsigned long long>(bands), asset->band_words.size());
        std::printf("  lowering    tolerance %.3g em, largest deviation %.3g em\n",
                    static_cast<double>(info.tolerance_em), static_cast<double>(info.max_deviation_em));
        std::printf("  font bytes  %s\n", human_bytes(static_cast<double>(asset->font_bytes.size())).c_str());
    }
    return kExitOk;
}

void print_report(const Arguments& args, const crisp::FontInfo& info, const crisp::BakeReport& r) {
    const double px16 = 16.0;
    if (args.json) {
        std::string failed = "[";
        for (const uint32_t id : r.failed_glyph_ids) failed += (failed.size() > 1 ? ", " : "") + std::to_string(id);
        failed += "]";
        std::printf(
            "{\"font\": %s, \"face_index\": %u, \"family\": %s, \"style\": %s, \"units_per_em\": %u, \"axes\": %s, "
            "\"output\": %s, \"glyphs\": %u, \"baked_glyphs\": %u, \"empty_glyphs\": %u, \"failed_glyphs\": %u, "
            "\"failed_glyph_ids\": %s, \"curves\": %llu, \"lines\": %llu, \"quadratics\": %llu, \"cubics\": %llu, "
            "\"cubic_pieces\": %llu, \"dropped_zero_length\": %llu, \"closed_contours\": %llu, \"y_splits\": %llu, "
            "\"curves_per_glyph\": {\"mean\": %s, \"max\": %u}, "
            "\"bands\": {\"total\": %llu, \"max_per_glyph\": %u, \"max_curves_per_band\": %u, "
            "\"mean_curves_per_band\": %s, \"mean_curve_tests_per_ray\": %s}, "
            "\"cubic_lowering\": {\"tolerance_em\": %s, \"max_deviation_em\": %s, \"max_deviation_px_at_16px\": %s, "
            "\"seed_split_max_deviation_em\": %s, \"seed_split_max_deviation_px_at_16px\": %s, \"seed_split_pieces\": "
            "%llu}, "
            "\"asset_bytes\": %llu, \"seconds\": %s, \"peak_rss_bytes\": %s}\n",
            json_string(args.font).c_str(), info.face_index, json_string(info.family).c_str(),
            json_string(info.style).c_str(), info.units_per_em, axes_json(info).c_str(),
            json_string(args.output).c_str(), r.glyph_count, r.baked_glyphs, r.empty_glyphs, r.failed_glyphs,
            failed.c_str(), static_cast<unsigned long long>(r.curve_count),
            static_cast<unsigned long long>(r.line_count), static_cast<unsigned long long>(r.quadratic_count),
            static_cast<unsigned long long>(r.cubic_count), static_cast<unsigned long long>(r.cubic_pieces),
            static_cast<unsigned long long>(r.dropped_zero_length), static_cast<unsigned long long>(r.closed_contours),
            static_cast<unsigned long long>(r.y_splits), json_number(r.mean_curves_per_glyph).c_str(),
            r.max_curves_per_glyph, static_cast<unsigned long long>(r.band_count), r.max_bands_per_glyph,
            r.max_curves_per_band, json_number(r.mean_curves_per_band).c_str(),
            json_number(r.mean_curve_tests_per_ray).c_str(),
            json_number(static_cast<double>(info.tolerance_em)).c_str(), json_number(r.max_deviation_em).c_str(),
            json_number(r.max_deviation_em * px16).c_str(), json_number(r.seed_max_deviation_em).c_str(),
            json_number(r.seed_max_deviation_em * px16).c_str(), static_cast<unsigned long long>(r.seed_cubic_pieces),
            static_cast<unsigned long long>(r.asset_bytes), json_number(r.seconds).c_str(),
            json_number(peak_rss_bytes()).c_str());
        return;
    }
    if (args.quiet) return;
    std::printf("%s -> %s\n", args.font.c_str(), args.output.c_str());
    std::printf("  font          %s %s, face %u, %u units per em\n", crisp::cli::printable(info.family).c_str(),
                crisp::cli::printable(info.style).c_str(),
                info.face_index, info.units_per_em);
    if (!info.axes.empty()) std::printf("  axes          %s\n", axes_text(info).c_str());
    std::printf("  glyphs        %u in the face, %u baked (%u empty), %u failed\n", r.glyph_count, r.baked_glyphs,
                r.empty_glyphs, r.failed_glyphs);
    std::printf(
        "  curves        %llu: %llu from lines, %llu quadratics, %llu from %llu cubics; %llu zero-length dropped\n",
        static_cast<unsigned long long>(r.curve_count), static_cast<unsigned long long>(r.line_count),
        static_cast<unsigned long long>(r.quadratic_count), static_cast<unsigned long long>(r.cubic_pieces),
        static_cast<unsigned long long>(r.cubic_count), static_cast<unsigned long long>(r.dropped_zero_length));
    std::printf("  per glyph     mean %.1f curves, max %u\n", r.mean_curves_per_glyph, r.max_curves_per_glyph);
    std::printf(
        "  bands         %llu in all, up to %u per glyph; curves per band mean %.2f, max %u; "
        "a ray tests %.2f curves on average\n",
        static_cast<unsigned long long>(r.band_count), r.max_bands_per_glyph, r.mean_curves_per_band,
        r.max_curves_per_band, r.mean_curve_tests_per_ray);
    if (r.cubic_count > 0) {
        std::printf("  cubics        tolerance %.3g em; largest deviation %.3g em (%.4f px at 16 px) in %llu pieces\n",
                    static_cast<double>(info.tolerance_em), r.max_deviation_em, r.max_deviation_em * px16,
                    static_cast<unsigned long long>(r.cubic_pieces));
        std::printf("                the seed's split in two: %.3g em (%.4f px at 16 px) in %llu pieces\n",
                    r.seed_max_deviation_em, r.seed_max_deviation_em * px16,
                    static_cast<unsigned long long>(r.seed_cubic_pieces));
    }
    std::printf("  asset         %s\n", human_bytes(static_cast<double>(r.asset_bytes)).c_str());
    std::printf("  time          %.2f s, peak memory %s\n", r.seconds, human_bytes(peak_rss_bytes()).c_str());
}

int exit_code_for(crisp::ErrorCode code) {
    switch (code) {
        case crisp::ErrorCode::invalid_argument:
            return kExitUsage;
        case crisp::ErrorCode::io:
        case crisp::ErrorCode::font_unreadable:
        case crisp::ErrorCode::font_unsupported:
            return kExitFont;
        case crisp::ErrorCode::glyph_failed:
            return kExitGlyphs;
        case crisp::ErrorCode::asset_invalid:
        case crisp::ErrorCode::asset_version:
        case crisp::ErrorCode::vulkan:
        case crisp::ErrorCode::device_lost:
            return kExitInternal;
    }
    return kExitInternal;
}

}  // namespace

int main(int argc, char** argv) {
    Arguments args = parse_arguments(argc, argv);
    if (!args.check.empty()) return run_check(args);

    if (!args.quiet && isatty(STDERR_FILENO)) args.bake.progress = draw_progress;
    // Before any work: an output that cannot or must not be written (a device, a directory, the input).
    const std::filesystem::path input(args.font);
    if (const crisp::Status checked = crisp::check_output_path(args.output, std::span(&input, 1)); !checked) {
        std::fprintf(stderr, "crisp-bake: %s\n", checked.error().message.c_str());
        return kExitOutput;
    }

    auto baked = crisp::bake_font_file(args.font, args.bake);
    if (!baked) {
        std::fprintf(stderr, "crisp-bake: %s: %s\n", args.font.c_str(), baked.error().message.c_str());
        return exit_code_for(baked.error().code);
    }
    crisp::BakeResult& result = *baked;
    const std::vector<std::byte> bytes = crisp::serialize_asset(result.asset);
    result.report.asset_bytes = bytes.size();
    if (const crisp::Status status = crisp::write_file_atomically(args.output, bytes); !status) {
        std::fprintf(stderr, "crisp-bake: %s\n", status.error().message.c_str());
        return kExitOutput;
    }
    if (result.report.failed_glyphs > 0) {
        std::fprintf(stderr, "crisp-bake: warning: %u glyphs failed and were baked empty; first: %s\n",
                     result.report.failed_glyphs, result.report.first_failure.c_str());
    }
    print_report(args, result.asset.info, result.report);
    return kExitOk;
}
