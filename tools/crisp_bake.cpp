// crisp-bake: turns a font into a .crisp asset, or checks an asset.
#include "cli.hpp"
#include "json_writer.hpp"
#include "output_files.hpp"

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

// What the report keeps of crisp's own sentences about a font (colour notes, fallbacks): they
// quote the font only in tags and numbers, so they are escaped but seldom shortened.
constexpr size_t kSentenceChars = 1000;

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

constexpr const char* kSynopsis = R"(usage: crisp-bake FONT [options]
       crisp-bake --check ASSET.crisp [--json]

Bakes a font (TrueType, OpenType CFF/CFF2, a collection, a variable font) into a .crisp asset:
quadratic curves in em units, cut into bands, with the font's metrics and bytes.

)";

constexpr const char* kExitCodes = R"(
exit codes:
  0 success   2 usage error   3 unreadable or unsupported font   4 output not writable
  5 glyphs failed   6 invalid asset (--check)   1 internal error

the asset is written whole, then renamed into place (docs/limits.md): an existing file is replaced
keeping its mode and owner; one that is read-only or another user's, the font, a device, FIFO or
directory, or a link to one is refused (exit 4) before any baking.
)";

struct Arguments {
    std::string font;
    std::string output;
    std::string check;
    crisp::BakeOptions bake;
    bool json = false;
    bool quiet = false;
};

// Appends a parsed list of code points (or the parser's error) to the bake's.
template <class Parsed>
crisp::Status append_codepoints(crisp::BakeOptions& bake, Parsed parsed) {
    if (!parsed) return parsed.error();
    bake.codepoints.insert(bake.codepoints.end(), parsed->begin(), parsed->end());
    return {};
}

void declare_options(crisp::cli::CommandLine& cli, Arguments& args, std::vector<uint32_t>& text_codepoints) {
    crisp::BakeOptions& bake = args.bake;
    cli.on_usage_error(kExitUsage, "\n(run crisp-bake --help for usage)").section("options:");
    cli.text("-o, --output", "OUT.crisp", "where to write the asset (default: FONT's name with .crisp, here)",
             args.output);
    cli.number<uint32_t>("--face", "N", "face N of a collection (.ttc); default 0", bake.face_index);
    cli.option("--var", "TAG=VALUE", "a variation axis value, e.g. --var wght=700; repeatable",
               [&bake](std::string_view text) -> crisp::Status {
                   auto variation = crisp::parse_variation(text);
                   if (!variation) return variation.error();
                   bake.variations.push_back(*variation);
                   return {};
               });
    cli.codepoints("--text", "UTF8",
                   "bake only the glyphs this text needs (with ligatures and\n"
                   "alternates shaping can substitute, and .notdef)",
                   text_codepoints);
    cli.option("--codepoints", "RANGES", "the same for code points: U+0020-007E,0x4E00-0x4E10,65",
               [&bake](std::string_view text) { return append_codepoints(bake, crisp::parse_codepoint_ranges(text)); });
    cli.number<float>("--tolerance", "EM", "largest cubic-to-quadratic deviation in em (default 1/16384)",
                      bake.tolerance_em, {0.0f, 0.1f, true, " em"});
    cli.number<float>("--max-size", "PX",
                      "the largest size the asset is drawn at, 1..1024 px per em: cubics are\n"
                      "lowered within 1/1024 px at that size (default 16, --tolerance 1/16384)",
                      bake.max_size_px, {1.0f, crisp::kMaxBakeSizePx, false, " px"});
    cli.flag("--split-y-extrema", "split curves at their y-extrema (measured not to pay; see docs)",
             bake.split_y_extrema);
    cli.number<uint32_t>("--max-curves", "N", "a glyph with more than N curves fails, 1..4096 (default 4096)",
                         bake.max_curves_per_glyph, {1, crisp::kMaxCurvesPerGlyph});
    cli.flag("--allow-failed", "bake failed glyphs as empty glyphs instead of giving up", bake.allow_failed);
    cli.flag("--json", "print the report as JSON on stdout", args.json);
    cli.flag("-q, --quiet", "no progress bar and no report (errors still go to stderr)", args.quiet);
    cli.text("--check", "ASSET", "validate an asset and print its summary", args.check);
    cli.positional([&args](std::string_view font) -> crisp::Status {
        if (!args.font.empty()) {
            return crisp::Error{crisp::ErrorCode::invalid_argument,
                                "more than one font given ('" + crisp::cli::printable_path(args.font) + "' and '" +
                                    crisp::cli::printable_path(font) + "')"};
        }
        args.font = font;
        return {};
    });
    cli.epilogue(kExitCodes);
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments args;
    std::vector<uint32_t> text_codepoints;
    crisp::cli::CommandLine cli("crisp-bake", kSynopsis);
    declare_options(cli, args, text_codepoints);
    cli.parse(argc, argv);
    if (cli.given("--text") && cli.given("--codepoints")) cli.fail("--text and --codepoints exclude each other");
    if (cli.given("--tolerance") && cli.given("--max-size")) {
        cli.fail("--tolerance and --max-size exclude each other (--max-size sets the tolerance)");
    }
    if (cli.given("--text") || cli.given("--codepoints")) args.bake.all_glyphs = false;
    args.bake.codepoints.insert(args.bake.codepoints.end(), text_codepoints.begin(), text_codepoints.end());
    if (!args.check.empty()) {
        if (!args.font.empty()) cli.fail("--check takes an asset, not a font");
        return args;
    }
    if (args.font.empty()) cli.fail("no font given");
    if (args.output.empty()) {
        std::string stem = std::filesystem::path(args.font).stem().string();
        if (args.bake.face_index > 0) stem += "-face" + std::to_string(args.bake.face_index);
        args.output = stem + ".crisp";
    }
    return args;
}

// The size at which the asset's tolerance is crisp::kPixelTolerance: what --max-size it was baked
// for (or would have been, for a tolerance given in em).
double tolerance_size_px(const crisp::FontInfo& info) {
    return static_cast<double>(crisp::kPixelTolerance) / static_cast<double>(info.tolerance_em);
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
                      crisp::cli::printable(crisp::tag_to_string(axis.tag)).c_str(), static_cast<double>(axis.value),
                      static_cast<double>(axis.minimum), static_cast<double>(axis.maximum));
        text += buffer;
    }
    return text;
}

void write_axes(crisp::JsonWriter& json, const crisp::FontInfo& info) {
    json.key("axes").begin_array();
    for (const crisp::AxisValue& axis : info.axes) {
        json.begin_object()
            .field("tag", crisp::tag_to_string(axis.tag))
            .field("value", axis.value)
            .field("min", axis.minimum)
            .field("default", axis.default_value)
            .field("max", axis.maximum)
            .end_object();
    }
    json.end_array();
}

int run_check(const Arguments& args) {
    auto asset = crisp::load_asset_file(args.check);
    if (!asset) {
        std::fprintf(stderr, "crisp-bake: %s: %s\n", crisp::cli::printable_path(args.check).c_str(),
                     asset.error().message.c_str());
        if (args.json) {
            crisp::JsonWriter json;
            json.begin_object()
                .field("valid", false)
                .field("error", crisp::error_code_name(asset.error().code))
                .field("message", asset.error().message)
                .end_object();
            std::fputs(json.line().c_str(), stdout);
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
        crisp::JsonWriter json;
        json.begin_object()
            .field("valid", true)
            .field("family", info.family)
            .field("style", info.style)
            .field("units_per_em", info.units_per_em)
            .field("face_index", info.face_index)
            .field("ascender", info.ascender)
            .field("descender", info.descender)
            .field("line_gap", info.line_gap)
            .field("cubic", (info.flags & crisp::kFontCubic) != 0);
        write_axes(json, info);
        json.field("glyphs", asset->glyphs.size())
            .field("baked_glyphs", baked)
            .field("failed_glyphs", failed)
            .field("outlined_glyphs", outlined)
            .field("curve_slots", slots)
            .field("points", asset->points.size())
            .field("bands", bands)
            .field("band_words", asset->band_words.size())
            .field("font_bytes", asset->font_bytes.size())
            .field("tolerance_em", info.tolerance_em)
            .field("tolerance_size_px", tolerance_size_px(info))
            .field("max_deviation_em", info.max_deviation_em)
            .end_object();
        std::fputs(json.line().c_str(), stdout);
    } else if (!args.quiet) {
        std::printf("%s: valid crisp asset (version %u)\n", crisp::cli::printable_path(args.check).c_str(),
                    crisp::kAssetVersion);
        std::printf("  font        %s %s, face %u, %u units per em%s\n", crisp::cli::printable(info.family).c_str(),
                    crisp::cli::printable(info.style).c_str(), info.face_index, info.units_per_em,
                    (info.flags & crisp::kFontCubic) ? ", cubic outlines" : "");
        if (!info.axes.empty()) std::printf("  axes        %s\n", axes_text(info).c_str());
        std::printf("  metrics     ascender %d, descender %d, line gap %d\n", info.ascender, info.descender,
                    info.line_gap);
        std::printf("  glyphs      %zu in the face, %llu baked (%llu with outlines, %llu failed)\n",
                    asset->glyphs.size(), static_cast<unsigned long long>(baked),
                    static_cast<unsigned long long>(outlined), static_cast<unsigned long long>(failed));
        std::printf("  curves      %llu slots, %zu points; %llu bands, %zu bitset words\n",
                    static_cast<unsigned long long>(slots), asset->points.size(),
                    static_cast<unsigned long long>(bands), asset->band_words.size());
        std::printf("  lowering    tolerance %.3g em (1/1024 px at %.4g px), largest deviation %.3g em\n",
                    static_cast<double>(info.tolerance_em), tolerance_size_px(info),
                    static_cast<double>(info.max_deviation_em));
        std::printf("  font bytes  %s\n", human_bytes(static_cast<double>(asset->font_bytes.size())).c_str());
    }
    return kExitOk;
}

// Colour glyphs, or something said about them: only then do the reports speak of colour.
bool has_colour(const crisp::BakeReport& r) {
    return r.colour_glyphs > 0 || r.colour_fallbacks > 0 || !r.colour_notes.empty();
}

crisp::JsonWriter report_json(const Arguments& args, const crisp::FontInfo& info, const crisp::BakeReport& r) {
    const double px16 = 16.0;
    crisp::JsonWriter json;
    json.begin_object()
        .field("font", args.font)
        .field("face_index", info.face_index)
        .field("family", info.family)
        .field("style", info.style)
        .field("units_per_em", info.units_per_em);
    write_axes(json, info);
    json.field("output", args.output)
        .field("glyphs", r.glyph_count)
        .field("baked_glyphs", r.baked_glyphs)
        .field("empty_glyphs", r.empty_glyphs)
        .field("failed_glyphs", r.failed_glyphs)
        .field("failed_glyph_ids", r.failed_glyph_ids)
        .field("curves", r.curve_count)
        .field("lines", r.line_count)
        .field("quadratics", r.quadratic_count)
        .field("cubics", r.cubic_count)
        .field("cubic_pieces", r.cubic_pieces)
        .field("dropped_zero_length", r.dropped_zero_length)
        .field("closed_contours", r.closed_contours)
        .field("y_splits", r.y_splits);
    json.key("curves_per_glyph").begin_object();
    json.field("mean", r.mean_curves_per_glyph).field("max", r.max_curves_per_glyph).end_object();
    json.key("bands").begin_object();
    json.field("total", r.band_count)
        .field("max_per_glyph", r.max_bands_per_glyph)
        .field("max_curves_per_band", r.max_curves_per_band)
        .field("mean_curves_per_band", r.mean_curves_per_band)
        .field("mean_curve_tests_per_ray", r.mean_curve_tests_per_ray)
        .end_object();
    json.key("cubic_lowering").begin_object();
    json.field("tolerance_em", info.tolerance_em)
        .field("max_deviation_em", r.max_deviation_em)
        .field("max_size_px", r.report_size_px)
        .field("max_deviation_px", r.max_deviation_px)
        .field("thirds_coverage_per_edge", 3.0 * r.max_deviation_px)
        .field("max_deviation_px_at_16px", r.max_deviation_em * px16)
        .field("seed_split_max_deviation_em", r.seed_max_deviation_em)
        .field("seed_split_max_deviation_px_at_16px", r.seed_max_deviation_em * px16)
        .field("seed_split_pieces", r.seed_cubic_pieces)
        .end_object();
    if (has_colour(r)) {
        json.key("colour").begin_object();
        json.field("glyphs", r.colour_glyphs)
            .field("layers", r.colour_layers)
            .field("synthetic_glyphs", r.synthetic_glyphs)
            .field("fallbacks", r.colour_fallbacks)
            .field("first_fallback", r.first_colour_fallback)
            .field("notes", r.colour_notes)
            .end_object();
    }
    json.field("asset_bytes", r.asset_bytes)
        .field("seconds", r.seconds)
        .field("peak_rss_bytes", peak_rss_bytes())
        .end_object();
    return json;
}

void print_report(const Arguments& args, const crisp::FontInfo& info, const crisp::BakeReport& r) {
    const double px16 = 16.0;
    if (args.json) {
        std::fputs(report_json(args, info, r).line().c_str(), stdout);
        return;
    }
    if (args.quiet) return;
    std::printf("%s -> %s\n", crisp::cli::printable_path(args.font).c_str(),
                crisp::cli::printable_path(args.output).c_str());
    std::printf("  font          %s %s, face %u, %u units per em\n", crisp::cli::printable(info.family).c_str(),
                crisp::cli::printable(info.style).c_str(), info.face_index, info.units_per_em);
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
        std::printf("  cubics        tolerance %.3g em; largest deviation %.3g em in %llu pieces\n",
                    static_cast<double>(info.tolerance_em), r.max_deviation_em,
                    static_cast<unsigned long long>(r.cubic_pieces));
        std::printf(
            "                at %g px and below: %.5f px (an edge across a third-pixel channel: up to %.4f of it)\n",
            r.report_size_px, r.max_deviation_px, 3.0 * r.max_deviation_px);
        std::printf("                the seed's split in two: %.3g em (%.4f px at 16 px) in %llu pieces\n",
                    r.seed_max_deviation_em, r.seed_max_deviation_em * px16,
                    static_cast<unsigned long long>(r.seed_cubic_pieces));
    }
    if (has_colour(r)) {
        std::printf("  colour        %u glyphs, %u layers, %u synthetic outlines; %u fell back%s%s\n", r.colour_glyphs,
                    r.colour_layers, r.synthetic_glyphs, r.colour_fallbacks, r.colour_fallbacks ? ", first: " : "",
                    crisp::cli::printable(r.first_colour_fallback, kSentenceChars).c_str());
        for (const std::string& note : r.colour_notes)
            std::printf("                %s\n", crisp::cli::printable(note, kSentenceChars).c_str());
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
    crisp::OutputFiles output({args.font});
    if (const crisp::Status checked = output.add(args.output); !checked) {
        std::fprintf(stderr, "crisp-bake: %s\n", checked.error().message.c_str());
        return kExitOutput;
    }

    auto baked = crisp::bake_font_file(args.font, args.bake);
    if (!baked) {
        std::fprintf(stderr, "crisp-bake: %s: %s\n", crisp::cli::printable_path(args.font).c_str(),
                     baked.error().message.c_str());
        return exit_code_for(baked.error().code);
    }
    crisp::BakeResult& result = *baked;
    const std::vector<std::byte> bytes = crisp::serialize_asset(result.asset);
    result.report.asset_bytes = bytes.size();
    const std::span<const std::byte> contents[] = {bytes};
    if (const crisp::Status status = output.write(contents); !status) {
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
