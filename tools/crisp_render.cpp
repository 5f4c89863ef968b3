// crisp-render: renders text with the GPU renderer until it converges, composites the glyphs on the
// GPU with crisp::Compositor into a PNG and, on request, reads the atlas back for a PFM of the
// text's coverage. The text comes from the command line or from a scene file.
#include "cli.hpp"
#include "gpu_tools.hpp"
#include "headless_context.hpp"
#include "image_io.hpp"
#include "json_writer.hpp"
#include "output_files.hpp"
#include "scene.hpp"

#include <crisp/asset.hpp>
#include <crisp/atlas.hpp>
#include <crisp/compositor.hpp>
#include <crisp/contrast.hpp>
#include <crisp/effects.hpp>
#include <crisp/font.hpp>
#include <crisp/glyph.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <new>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_set>
#include <utility>
#include <vector>

namespace {

// Exit codes, documented in --help and docs/crisp-render.md.
enum ExitCode : int {
    kExitOk = 0,
    kExitInternal = 1,  // a bug, or glyphs the renderer could not draw
    kExitUsage = 2,     // bad command line
    kExitFont = 3,      // a font asset cannot be loaded
    kExitOutput = 4,    // an output file cannot be written
    kExitVulkan = 5,    // no usable Vulkan device, a Vulkan failure, or validation messages
    kExitLayout = 6,    // --layout (or the scene's layout) is neither a preset nor a valid layout file
    kExitScene = 7,     // --scene cannot be read, is not a valid scene, or a run cannot be laid out
};

constexpr uint32_t kDefaultSamples = 512;
// Glyphs one render lays out, all runs together: a 3840x2160 screen of 12 px text is 80,000, and 32
// layers of 18 px text over it about a million; the atlas and the GPU buffers stay far below a GiB.
constexpr size_t kMaxGlyphs = size_t{4} << 20;
constexpr uint32_t kMaxCanvas = 16384;
// The default schedule reaches kMaxRendererSamples in about 1030 frames; far more means the
// renderer stopped making progress.
constexpr uint32_t kMaxFrames = 100000;
// --max-seconds: a run's rendering stops at the first frame that ends past it (docs/crisp-render.md,
// "Bounded work"), so that no small hostile input takes minutes: the compositing and writing that
// follow leave a run on a 2-core lavapipe machine well under a minute.
constexpr double kDefaultMaxSeconds = 30.0;
constexpr double kMaxMaxSeconds = 86400.0;
// Smallest atlas side the tool asks for; it grows to hold every glyph of the text at once.
constexpr uint32_t kMinAtlasSide = 256;
constexpr uint32_t kAtlasTexelBytes = 8;    // R16G16B16A16_UINT
constexpr uint32_t kTargetTexelBytes = 16;  // the compositor's R32G32B32A32_SFLOAT
// The canvas is composited in bands of at most this many bytes of target, whole tiles' rows each
// (see "Compositing in bands").
constexpr uint64_t kBandBytes = uint64_t{32} << 20;
constexpr uint32_t kBandRowStep = 16;

constexpr const char* kSynopsis = R"(usage: crisp-render --font A.crisp [--font B.crisp ...] --text UTF8 --size PX
                    --origin X,Y --canvas W,H -o OUT.png [options]
       crisp-render --scene SCENE.json -o OUT.png [options]

Renders text with crisp's GPU rasterizer, frame after frame until every glyph holds its samples,
then composites the glyphs over the background on the GPU (crisp::Compositor) with the contrast
model's correction, so that dark text on light is as heavy as light text on dark (docs/contrast.md),
or in linear light, the coverage as it is, with --contrast linear.

)";

constexpr const char* kExitCodes = R"(
exit codes:
  0 success, also a run stopped by --max-seconds or --max-frames before the text converged
    (its outputs hold the text as it was then, and a warning on stderr says so)
  2 usage error   3 font asset cannot be loaded   4 output not writable
  5 Vulkan unavailable or failed, or validation messages   6 bad --layout or scene layout
  7 bad --scene file (unreadable, invalid, or a run the layout refuses)   1 internal error

outputs are written whole, then renamed into place (docs/limits.md): an existing file is replaced
keeping its mode and owner; one that is read-only or another user's, an input (a scene's fonts and
layout too), the other output, a device, FIFO or directory, or a link to one is refused (exit 4)
before any rendering.
)";

struct Arguments {
    std::vector<std::string> fonts;
    std::optional<std::string> text;
    std::optional<float> size;
    std::optional<std::array<float, 2>> origin;
    std::optional<std::array<uint32_t, 2>> canvas;
    std::optional<std::string> layout;
    uint32_t samples = kDefaultSamples;
    double max_seconds = kDefaultMaxSeconds;  // 0: no time limit
    std::optional<uint32_t> max_frames;       // given: a stop there is not a failure
    std::optional<std::array<float, 4>> color;
    std::optional<std::array<float, 4>> background;
    std::optional<uint32_t> palette;                // TextStyle::palette of the command line's text
    std::optional<std::array<float, 4>> transform;  // the 2x2 of DrawOptions::transform, about the origin
    bool no_colour = false;                         // LayoutOptions::colour_glyphs off: colour glyphs as plain outlines
    // The command line's text's effects: --outline, --shadow, --glow and --weight, with the
    // outline's placement and join.
    std::optional<crisp::TextOutline> outline;
    std::optional<crisp::TextShadow> shadow;
    std::optional<crisp::TextGlow> glow;
    std::optional<float> weight;
    crisp::OutlinePlacement outline_placement = crisp::OutlinePlacement::outside;
    crisp::LineJoin outline_join = crisp::LineJoin::round;
    float miter_limit = 4.0f;
    std::string scene;
    crisp::CompositeMode composite = crisp::CompositeMode::tiled;
    std::string backdrop = "flat";
    crisp::QuadPath path = crisp::QuadPath::raster;
    crisp::TextContrast contrast;  // the renderer's; a scene's runs may carry their own
    bool contrast_given = false;   // some contrast option was given: a layout file's settings yield
    std::string output;
    std::string coverage_output;
    std::optional<uint32_t> band_rows;  // rows composited at once; not given: as many as kBandBytes hold
    bool json = false;
    bool quiet = false;
#ifdef NDEBUG
    bool validate = false;
#else
    bool validate = true;  // debug builds run with the validation layer on
#endif
    std::string device;
};

[[noreturn]] void fail(int code, const std::string& message) {
    std::fprintf(stderr, "crisp-render: %s\n", message.c_str());
    std::exit(code);
}

// "R,G,B" or "R,G,B,A", each in [0, 1], alpha 1 when not given.
crisp::Result<std::array<float, 4>> parse_color(std::string_view option, std::string_view text) {
    const crisp::Result<std::vector<float>> values = crisp::cli::parse_number_list<float>(option, text);
    if (!values) return values.error();
    auto refuse = [&](const std::string& why) { return crisp::Error{crisp::ErrorCode::invalid_argument, why}; };
    if (values->size() != 3 && values->size() != 4) {
        return refuse(std::string(option) + " takes R,G,B or R,G,B,A, not '" + crisp::cli::printable(text) + "'");
    }
    std::array<float, 4> color = {0.0f, 0.0f, 0.0f, 1.0f};
    for (size_t i = 0; i < values->size(); ++i) {
        if (!((*values)[i] >= 0.0f && (*values)[i] <= 1.0f)) {
            return refuse(std::string(option) + ": components are in [0, 1] (sRGB, straight alpha); '" +
                          crisp::cli::printable(text) + "' is not");
        }
        color[i] = (*values)[i];
    }
    return color;
}

// `values` from `first` on as a colour (R,G,B or R,G,B,A) into `color`, where there are any.
crisp::Status colour_after(std::string_view option, std::string_view text, const std::vector<float>& values,
                           size_t first, std::array<float, 4>& color) {
    if (values.size() == first) return {};
    const size_t n = values.size() - first;
    if (n != 3 && n != 4) {
        return crisp::Error{crisp::ErrorCode::invalid_argument,
                            std::string(option) + ": the colour after " + std::to_string(first) +
                                (first == 1 ? " number" : " numbers") + " is R,G,B or R,G,B,A, not '" +
                                crisp::cli::printable(text) + "'"};
    }
    for (size_t i = 0; i < n; ++i) {
        if (!(values[first + i] >= 0.0f && values[first + i] <= 1.0f)) {
            return crisp::Error{crisp::ErrorCode::invalid_argument,
                                std::string(option) + ": colour components are in [0, 1] (sRGB, straight alpha); '" +
                                    crisp::cli::printable(text) + "' is not"};
        }
        color[i] = values[first + i];
    }
    if (n == 3) color[3] = 1.0f;
    return {};
}

// Refuses `text` for `option` unless values [first, first + count) are there and lie in [lo, hi]
// ((lo, hi] where `open_below`): "OPTION: WHAT, not 'TEXT'".
crisp::Status check_values(std::string_view option, std::string_view text, const std::vector<float>& values,
                           size_t first, size_t count, float lo, float hi, bool open_below, std::string_view what) {
    bool good = values.size() >= first + count;
    for (size_t i = first; good && i < first + count; ++i) {
        good = (open_below ? values[i] > lo : values[i] >= lo) && values[i] <= hi;
    }
    if (good) return {};
    return crisp::Error{crisp::ErrorCode::invalid_argument,
                        std::string(option) + ": " + std::string(what) + ", not '" + crisp::cli::printable(text) + "'"};
}

// "WIDTH[,R,G,B[,A]]": an outline (its placement and join come from their own options).
crisp::Result<crisp::TextOutline> parse_outline(std::string_view text) {
    const crisp::Result<std::vector<float>> values = crisp::cli::parse_number_list<float>("--outline", text);
    if (!values) return values.error();
    crisp::TextOutline outline;
    if (crisp::Status s = check_values("--outline", text, *values, 0, 1, 0.0f, crisp::kMaxEffectWidth, false,
                                       "WIDTH is pixels in [0, 4096]");
        !s) {
        return s.error();
    }
    outline.width = (*values)[0];
    if (crisp::Status s = colour_after("--outline", text, *values, 1, outline.color); !s) return s.error();
    return outline;
}

// "DX,DY,BLUR[,R,G,B[,A]]": a drop shadow, blurred by a radius of BLUR px (0: a hard one).
crisp::Result<crisp::TextShadow> parse_shadow(std::string_view text) {
    const crisp::Result<std::vector<float>> values = crisp::cli::parse_number_list<float>("--shadow", text);
    if (!values) return values.error();
    if (values->size() < 3) {
        return crisp::Error{crisp::ErrorCode::invalid_argument,
                            "--shadow takes DX,DY,BLUR[,R,G,B[,A]], not '" + crisp::cli::printable(text) + "'"};
    }
    crisp::TextShadow shadow;
    if (crisp::Status s = check_values("--shadow", text, *values, 0, 2, -crisp::kMaxShadowOffset,
                                       crisp::kMaxShadowOffset, false, "DX and DY are pixels in [-4096, 4096]");
        !s) {
        return s.error();
    }
    shadow.offset_x = (*values)[0];
    shadow.offset_y = (*values)[1];
    if (crisp::Status s = check_values("--shadow", text, *values, 2, 1, 0.0f, crisp::kMaxEffectBlur, false,
                                       "BLUR is a radius in pixels in [0, 128]");
        !s) {
        return s.error();
    }
    shadow.blur = (*values)[2];
    if (crisp::Status s = colour_after("--shadow", text, *values, 3, shadow.color); !s) return s.error();
    return shadow;
}

// "RADIUS[,R,G,B[,A]]": a glow of that blur radius in pixels.
crisp::Result<crisp::TextGlow> parse_glow(std::string_view text) {
    const crisp::Result<std::vector<float>> values = crisp::cli::parse_number_list<float>("--glow", text);
    if (!values) return values.error();
    if (crisp::Status s = check_values("--glow", text, *values, 0, 1, 0.0f, crisp::kMaxEffectBlur, true,
                                       "RADIUS is pixels in (0, 128]");
        !s) {
        return s.error();
    }
    crisp::TextGlow glow;
    glow.radius = (*values)[0];
    if (crisp::Status s = colour_after("--glow", text, *values, 1, glow.color); !s) return s.error();
    return glow;
}

// The command line's text's effects; nullopt where none was asked for.
std::optional<crisp::TextEffects> effects_of(const Arguments& args) {
    if (!args.outline && !args.shadow && !args.glow && !args.weight) return std::nullopt;
    crisp::TextEffects effects;
    effects.weight = args.weight.value_or(0.0f);
    effects.outline = args.outline;
    if (effects.outline) {
        effects.outline->placement = args.outline_placement;
        effects.outline->join = args.outline_join;
        effects.outline->miter_limit = args.miter_limit;
    }
    effects.shadow = args.shadow;
    effects.glow = args.glow;
    return effects;
}

// "A,B,C,D": a 2x2 linear part that valid_transform() accepts.
crisp::Result<std::array<float, 4>> parse_transform(std::string_view text) {
    const crisp::Result<std::vector<float>> values = crisp::cli::parse_number_list<float>("--transform", text);
    if (!values) return values.error();
    auto refuse = [&](const std::string& why) { return crisp::Error{crisp::ErrorCode::invalid_argument, why}; };
    if (values->size() != 4) return refuse("--transform takes A,B,C,D, not '" + crisp::cli::printable(text) + "'");
    const std::array<float, 4> m = {(*values)[0], (*values)[1], (*values)[2], (*values)[3]};
    if (!crisp::valid_transform({m[0], m[1], m[2], m[3], 0.0f, 0.0f})) {
        return refuse("--transform '" + crisp::cli::printable(text) +
                      "': entries must be finite and at most 65536, and |A D - B C| at least 2^-16");
    }
    return m;
}

// An option whose value `parse` turns into `target` (an optional), or refuses.
template <class T, class Parse>
crisp::cli::CommandLine::Apply store(std::optional<T>& target, Parse parse) {
    return [&target, parse](std::string_view text) -> crisp::Status {
        crisp::Result<T> value = parse(text);
        if (!value) return value.error();
        target = *value;
        return {};
    };
}

crisp::Result<std::array<float, 2>> parse_origin(std::string_view text) {
    const crisp::Result<std::vector<float>> xy = crisp::cli::parse_number_list<float>("--origin", text);
    if (!xy) return xy.error();
    if (xy->size() != 2)
        return crisp::Error{crisp::ErrorCode::invalid_argument,
                            "--origin takes X,Y, not '" + crisp::cli::printable(text) + "'"};
    return std::array<float, 2>{(*xy)[0], (*xy)[1]};
}

crisp::Result<std::array<uint32_t, 2>> parse_canvas(std::string_view text) {
    const crisp::Result<std::vector<uint32_t>> wh = crisp::cli::parse_number_list<uint32_t>("--canvas", text);
    if (!wh) return wh.error();
    auto refuse = [&](const std::string& why) { return crisp::Error{crisp::ErrorCode::invalid_argument, why}; };
    if (wh->size() != 2) return refuse("--canvas takes W,H, not '" + crisp::cli::printable(text) + "'");
    const uint32_t w = (*wh)[0], h = (*wh)[1];
    if (w < 1 || w > kMaxCanvas || h < 1 || h > kMaxCanvas) {
        return refuse("--canvas: width and height are each 1..16384, not '" + crisp::cli::printable(text) + "'");
    }
    return std::array<uint32_t, 2>{w, h};
}

// The text the command line describes (or --scene), as --help lists it.
void declare_text_options(crisp::cli::CommandLine& cli, Arguments& args) {
    cli.section("the text (all required, unless --scene gives it):");
    cli.repeated("--font", "FILE.crisp", "a font asset (crisp-bake makes them); repeat for a fallback chain",
                 args.fonts);
    cli.text("--text", "UTF8", "the text; line breaks start new lines", args.text);
    cli.number<float>("--size", "PX", "pixels per em, in (0, 4096]", args.size,
                      {0.0f, crisp::kMaxTextSize, true, " pixels per em"});
    cli.option("--origin", "X,Y",
               "pen position of the first glyph on its baseline, canvas pixels, y down;\n"
               "fractional values are kept (quantized to 1/256 px), never rounded",
               store(args.origin, parse_origin));
    cli.option("--canvas", "W,H", "image size in pixels, each 1..16384", store(args.canvas, parse_canvas));
    cli.option("--scene", "SCENE.json",
               "a scene file instead (docs/scene-format.md): fonts, canvas, background,\n"
               "layout and runs of text with colours and depths; none of --font, --text,\n"
               "--size, --origin, --canvas, --color, --background, --layout may be given",
               [&args](std::string_view name) -> crisp::Status {
                   if (name.empty())
                       return crisp::Error{crisp::ErrorCode::invalid_argument, "--scene needs a file name"};
                   args.scene = name;
                   return {};
               });
    cli.section("required:");
    cli.text("-o, --output", "OUT.png", "the composited image, 8-bit sRGB", args.output);
}

const char* contrast_mode_name(crisp::ContrastMode mode) {
    return mode == crisp::ContrastMode::linear ? "linear" : "corrected";
}

// The contrast model's settings (include/crisp/contrast.hpp), with its ranges.
void declare_contrast_options(crisp::cli::CommandLine& cli, crisp::TextContrast& contrast) {
    cli.choice<crisp::ContrastMode>(
        "--contrast", "linear|corrected",
        "how coverage is blended: corrected (the default) as if in a space of\n"
        "--gamma between the text's and the background's luminance, so that dark\n"
        "text on light is as heavy as light on dark; linear: the coverage as it is,\n"
        "in linear light (docs/contrast.md)",
        contrast.mode, {crisp::ContrastMode::corrected, crisp::ContrastMode::linear},
        [](const crisp::ContrastMode& mode) { return std::string(contrast_mode_name(mode)); });
    cli.number<float>("--gamma", "G", "corrected: the blend space's gamma, in [1, 4] (default 2.2; 1: linear light)",
                      contrast.gamma, {1.0f, 4.0f});
    cli.number<float>("--enhanced-contrast", "K",
                      "corrected: enhanced contrast, in [0, 4] (default 0); larger makes all\n"
                      "text heavier, light and dark alike",
                      contrast.contrast, {0.0f, 4.0f});
    cli.number<float>("--stem-darkening", "S",
                      "corrected: stem darkening by size, in [0, 4] (default 0, off; 1: as\n"
                      "FreeType's CFF engine); thin stems at small sizes gain most",
                      contrast.stem_darkening, {0.0f, 4.0f});
}

// How it is rendered and composited, what is reported, and on which device.
void declare_render_options(crisp::cli::CommandLine& cli, Arguments& args) {
    using crisp::CompositeMode;
    cli.section("options:");
    cli.text("--layout", "NAME|FILE.json",
             "subpixel layout: gray, rgb, bgr, vrgb, vbgr, qd-oled, woled, pentile,\n"
             "or a layout file (default: rgb)",
             args.layout);
    cli.number<uint32_t>("--samples", "N", "samples per glyph texel and channel, 1..1023 (default 512)", args.samples,
                         {1, crisp::kMaxRendererSamples});
    cli.number<double>("--max-seconds", "S",
                       "stop rendering at the first frame that ends S seconds after the start\n"
                       "(0..86400, default 30; 0: no limit) and write the text as it is then,\n"
                       "partly converged, with a warning (exit 0)",
                       args.max_seconds, {0.0, kMaxMaxSeconds});
    cli.number<uint32_t>("--band-rows", "N",
                         "composite the canvas N rows at a time, N a multiple of 16 (default:\n"
                         "as many as 32 MiB of 16-byte pixels hold; the image is the same)",
                         args.band_rows, {16, 16384});
    cli.number<uint32_t>("--max-frames", "N",
                         "stop rendering after N frames (1..100000) the same way, if the text\n"
                         "has not converged by then",
                         args.max_frames, {1, kMaxFrames});
    auto color = [](const char* option) {
        return [option](std::string_view text) { return parse_color(option, text); };
    };
    cli.option("--color", "R,G,B[,A]", "text colour, sRGB components in [0, 1], straight alpha (default 0,0,0,1)",
               store(args.color, color("--color")));
    cli.option("--background", "R,G,B[,A]",
               "background, the same way (default 1,1,1,1); with alpha below 1 the PNG\n"
               "has an alpha channel",
               store(args.background, color("--background")));
    cli.number<uint32_t>("--palette", "N",
                         "CPAL palette of colour glyphs, 0..255 (default 0); a font with fewer\n"
                         "palettes draws its palette 0",
                         args.palette, {0, crisp::kMaxPalettes - 1});
    cli.option("--transform", "A,B,C,D",
               "draw the text transformed about --origin by the 2x2 matrix (y down):\n"
               "x' = A x + B y, y' = C x + D y; e.g. 0.8,-0.6,0.6,0.8 rotates it 36.87\n"
               "degrees clockwise, -1,0,0,1 mirrors it; |A D - B C| at least 2^-16\n"
               "(docs/transforms.md)",
               store(args.transform, [](std::string_view text) { return parse_transform(text); }));
    cli.option("--outline", "WIDTH[,R,G,B[,A]]",
               "an outline WIDTH pixels wide in the colour (as --color; default\n"
               "0,0,0,1), outside the glyph (the band between its edge and its edge\n"
               "grown by WIDTH), drawn under it; exact at every size (docs/effects.md)",
               store(args.outline, [](std::string_view text) { return parse_outline(text); }));
    cli.choice<crisp::OutlinePlacement>(
        "--outline-placement", "outside|inside|centred",
        "where the outline lies: outside the glyph (default, under it), inside\n"
        "it, or centred on its edge (both over it)",
        args.outline_placement,
        {crisp::OutlinePlacement::outside, crisp::OutlinePlacement::inside, crisp::OutlinePlacement::centred},
        [](const crisp::OutlinePlacement& p) { return std::string(crisp::outline_placement_name(p)); });
    cli.choice<crisp::LineJoin>("--outline-join", "round|miter|bevel",
                                "how the outline turns corners (default round; miter keeps them sharp\n"
                                "up to --miter-limit)",
                                args.outline_join,
                                {crisp::LineJoin::round, crisp::LineJoin::miter, crisp::LineJoin::bevel},
                                [](const crisp::LineJoin& j) { return std::string(crisp::line_join_name(j)); });
    cli.number<float>("--miter-limit", "L",
                      "miter joins: corners whose miter ratio 1/sin(angle/2) passes L are\n"
                      "bevelled, in [1, 128] (default 4)",
                      args.miter_limit, {1.0f, crisp::kMaxMiterLimit});
    cli.option("--shadow", "DX,DY,BLUR[,R,G,B[,A]]",
               "a drop shadow: the text (with its outline) moved by DX,DY pixels and\n"
               "blurred by a radius of BLUR pixels (0: hard, up to 128), in the colour\n"
               "(default 0,0,0,0.5), under it",
               store(args.shadow, [](std::string_view text) { return parse_shadow(text); }));
    cli.option("--glow", "RADIUS[,R,G,B[,A]]",
               "a glow: the text (with its outline) blurred by a radius of RADIUS\n"
               "pixels (up to 128), in the colour (default 1,1,1,0.75), under its\n"
               "outline and over its shadow",
               store(args.glow, [](std::string_view text) { return parse_glow(text); }));
    cli.option("--weight", "PX",
               "grow (positive) or shrink (negative) every stem by PX pixels on each\n"
               "side: bolder or thinner text from the same font",
               store(args.weight, [](std::string_view text) -> crisp::Result<float> {
                   const crisp::Result<std::vector<float>> v = crisp::cli::parse_number_list<float>("--weight", text);
                   if (!v) return v.error();
                   const std::vector<float> one = v->size() == 1 ? *v : std::vector<float>{};  // no more
                   if (crisp::Status s = check_values("--weight", text, one, 0, 1, -crisp::kMaxEffectWidth,
                                                      crisp::kMaxEffectWidth, false, "PX is pixels in [-4096, 4096]");
                       !s) {
                       return s.error();
                   }
                   return (*v)[0];
               }));
    cli.flag("--no-colour",
             "draw colour glyphs (COLR layers, bitmap emoji) as their plain outline in\n"
             "the text colour, as fonts without colour tables are drawn",
             args.no_colour);
    cli.choice<CompositeMode>("--composite", "MODE",
                              "how the glyphs are blended over what is behind them: tiled (screen\n"
                              "tiles in workgroup memory, exact front to back; the default), draw\n"
                              "(sorted quads blended in a render pass), or a reference mode: unsorted\n"
                              "(paint order, no OIT), wboit (weighted blended OIT) or exact\n"
                              "(per-pixel sorted lists)",
                              args.composite,
                              {CompositeMode::tiled, CompositeMode::draw, CompositeMode::unsorted, CompositeMode::wboit,
                               CompositeMode::exact},
                              [](const CompositeMode& mode) { return std::string(crisp::composite_mode_name(mode)); });
    cli.choice("--backdrop", "KIND",
               "tiled and draw: what the text is drawn over, in the canvas image:\n"
               "flat (the background colour; the default), gradient (a ramp from the\n"
               "background to its complement with soft stripes) or photo (smooth colour\n"
               "fields and fine detail, like a photograph)",
               args.backdrop, {"flat", "gradient", "photo"});
    cli.choice<crisp::QuadPath>("--path", "raster|compute",
                                "wboit and exact: how their glyph passes run, rasterized quads\n"
                                "(default) or compute over 8x8 tiles of each quad; the same image",
                                args.path, {crisp::QuadPath::raster, crisp::QuadPath::compute},
                                [](const crisp::QuadPath& path) { return std::string(crisp::quad_path_name(path)); });
    declare_contrast_options(cli, args.contrast);
    cli.text("--coverage-out", "OUT.pfm", "the text's linear coverage per channel as a PFM image",
             args.coverage_output);
    cli.flag("--json", "print the report as one JSON object on stdout (compositor notes go\ninto it instead of stderr)",
             args.json);
    cli.flag("-q, --quiet", "no report on stdout, no notes or warnings on stderr (errors still)", args.quiet);
    cli.flag("--validate",
             "turn on the Vulkan validation layer (always on in debug builds); any\n"
             "warning or error it reports fails the run (exit 5)",
             args.validate);
    cli.text("--device", "NAME", "use the Vulkan device whose name contains NAME", args.device);
}

// With --scene, none of what the scene says may be given; without, all of the text's options must be.
void check_text_source(const crisp::cli::CommandLine& cli, const Arguments& args) {
    if (!args.scene.empty()) {
        // The scene says all of these; a second source would leave one of them ignored.
        std::string given;
        for (const char* name : {"--font", "--text", "--size", "--origin", "--canvas", "--color", "--background",
                                 "--palette", "--layout", "--transform", "--outline", "--outline-placement",
                                 "--outline-join", "--miter-limit", "--shadow", "--glow", "--weight"}) {
            if (cli.given(name)) given += std::string(given.empty() ? "" : ", ") + name;
        }
        if (!given.empty()) {
            cli.fail("--scene gives the text, fonts, canvas, colours and layout: " + given +
                     " must not be given with it");
        }
        return;
    }
    if (args.fonts.empty()) cli.fail("no --font given (or --scene)");
    if (args.fonts.size() > crisp::kMaxSceneFonts) {
        cli.fail("at most " + std::to_string(crisp::kMaxSceneFonts) + " fonts, not " +
                 std::to_string(args.fonts.size()));
    }
    if (!args.text) cli.fail("no --text given");
    if (!args.size) cli.fail("no --size given");
    if (!args.origin) cli.fail("no --origin given");
    if (!args.canvas) cli.fail("no --canvas given");
    if (!args.outline &&
        (cli.given("--outline-placement") || cli.given("--outline-join") || cli.given("--miter-limit")))
        cli.fail("--outline-placement, --outline-join and --miter-limit shape --outline: give it too");
    if (const std::optional<crisp::TextEffects> effects = effects_of(args)) {
        if (crisp::Status valid = crisp::validate_text_effects(*effects, *args.size); !valid) {
            cli.fail(valid.error().message);
        }
    }
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments args;
    crisp::cli::CommandLine cli("crisp-render", kSynopsis);
    cli.on_usage_error(kExitUsage, "\n(run crisp-render --help for usage)").epilogue(kExitCodes);
    declare_text_options(cli, args);
    declare_render_options(cli, args);
    cli.parse(argc, argv);
    check_text_source(cli, args);
    if (args.output.empty()) cli.fail("no output given (-o OUT.png)");
    if (cli.given("--path") && args.composite != crisp::CompositeMode::wboit &&
        args.composite != crisp::CompositeMode::exact) {
        cli.fail(
            "--path applies to --composite wboit and exact only (tiled always computes; draw and unsorted "
            "are always rasterized)");
    }
    if (args.band_rows && *args.band_rows % kBandRowStep != 0) {
        cli.fail("--band-rows is a multiple of 16 (the compositors' tiles), not " + std::to_string(*args.band_rows));
    }
    if (args.backdrop != "flat" && args.composite != crisp::CompositeMode::tiled &&
        args.composite != crisp::CompositeMode::draw) {
        cli.fail(
            "--backdrop applies to --composite tiled and draw only (the reference modes draw over a flat "
            "background)");
    }
    if (args.contrast.mode == crisp::ContrastMode::linear &&
        (cli.given("--gamma") || cli.given("--enhanced-contrast") || cli.given("--stem-darkening"))) {
        cli.fail(
            "--gamma, --enhanced-contrast and --stem-darkening apply to --contrast corrected only (linear "
            "blends the coverage as it is)");
    }
    args.contrast_given = cli.given("--contrast") || cli.given("--gamma") || cli.given("--enhanced-contrast") ||
                          cli.given("--stem-darkening");
    // The options' ranges are the model's; this names a setting they let through, should they part.
    if (crisp::Status valid = crisp::validate_text_contrast(args.contrast); !valid) cli.fail(valid.error().message);
    if (!args.coverage_output.empty() && std::filesystem::path(args.coverage_output).lexically_normal() ==
                                             std::filesystem::path(args.output).lexically_normal()) {
        cli.fail("-o and --coverage-out name the same file");
    }
    return args;
}

// The outputs (-o, then --coverage-out), refused before any rendering when one cannot be written
// (its directory missing, its name too long), must not be replaced (a device node, directory,
// FIFO, a read-only file), is one of the inputs or is the other output. The inputs a scene names
// are added once it is read (load_job()).
crisp::OutputFiles declare_outputs(const Arguments& args) {
    std::vector<std::filesystem::path> inputs(args.fonts.begin(), args.fonts.end());
    if (!args.scene.empty()) inputs.emplace_back(args.scene);
    if (args.layout && !crisp::subpixel_preset(*args.layout)) inputs.emplace_back(*args.layout);
    crisp::OutputFiles outputs(std::move(inputs));
    for (const std::string& path : {args.output, args.coverage_output}) {
        if (path.empty()) continue;
        if (const crisp::Status checked = outputs.add(path); !checked) fail(kExitOutput, checked.error().message);
    }
    return outputs;
}

// ---- Rendering

int exit_code_for_vulkan(const crisp::Error& error) {
    const bool vulkan = error.code == crisp::ErrorCode::vulkan || error.code == crisp::ErrorCode::device_lost;
    return vulkan ? kExitVulkan : kExitInternal;
}

// The side of a square atlas that holds every distinct glyph of the text at once, with room to
// spare for the allocator's alignment.
uint32_t atlas_side_for(std::span<const crisp::GlyphInstance> glyphs) {
    std::unordered_set<crisp::GlyphKey, crisp::GlyphKeyHash> keys;
    uint64_t cells = 0;
    uint32_t widest = 1, tallest = 1;
    for (const crisp::GlyphInstance& glyph : glyphs) {
        if (glyph.width == 0 || glyph.height == 0 || !keys.insert(glyph.key).second) continue;
        const crisp::AtlasBlock block = crisp::atlas_block(glyph.width, glyph.height);
        cells += uint64_t{block.cells_x} * block.cells_y;
        widest = std::max(widest, block.cells_x);
        tallest = std::max(tallest, block.cells_y);
    }
    uint32_t side = kMinAtlasSide;
    while (side < crisp::kAtlasMaxSize &&
           (side / crisp::kAtlasCellSize < std::max(widest, tallest) ||
            uint64_t{side / crisp::kAtlasCellSize} * (side / crisp::kAtlasCellSize) < 2 * cells)) {
        side *= 2;
    }
    return side;
}

// Glyphs whose rect misses the canvas change no pixel: they are not drawn.
bool touches_canvas(const crisp::GlyphInstance& glyph, uint32_t width, uint32_t height) {
    const int64_t x0 = glyph.x, y0 = glyph.y;
    const int64_t x1 = x0 + glyph.width, y1 = y0 + glyph.height;
    return glyph.width > 0 && glyph.height > 0 && x1 > 0 && y1 > 0 && x0 < int64_t{width} && y0 < int64_t{height};
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// --max-seconds, counted from the run's start.
struct RunClock {
    std::chrono::steady_clock::time_point start;
    double max_seconds = 0.0;  // 0: no limit
    bool past_limit() const { return max_seconds > 0.0 && milliseconds_since(start) >= max_seconds * 1000.0; }
};

// What is drawn: the scene (from --scene, or the one run the command line describes), its
// resolved subpixel layout and fonts, and the glyphs its runs laid out.
struct Job {
    crisp::Scene scene;
    crisp::SubpixelLayout subpixel_layout;
    // The renderer's contrast settings: the options', or where none was given the layout file's
    // (a monitor's, docs/subpixel.md), else the model's defaults.
    crisp::TextContrast contrast;
    std::vector<crisp::Font> fonts;            // FontIds 1, 2, ... in scene order
    std::vector<crisp::GlyphInstance> glyphs;  // every run's glyphs that touch the canvas, in paint order
    // One draw() each: consecutive runs' glyphs with the same contrast settings (nullopt: the
    // renderer's), so that the command line's text is one draw, as before scenes carried contrast.
    struct Draw {
        size_t first = 0, count = 0;  // in glyphs
        std::optional<crisp::TextContrast> contrast;
        std::optional<crisp::TextTransform> transform;  // a run's, about its origin
        std::optional<crisp::TextEffects> effects;      // a run's
    };
    std::vector<Draw> draws;
    // Underlines and strikethroughs, drawn into the backdrop beneath the text, with their run's
    // transform (about its origin) where it has one.
    struct Decoration {
        crisp::TextDecoration rect;
        std::optional<crisp::TextTransform> transform;
    };
    std::vector<Decoration> decorations;
    size_t laid_out = 0;  // instances the text layouts produced, culled ones included
    uint32_t missing = 0, blank = 0, out_of_range = 0;
    uint32_t colour_glyphs = 0, colour_layers = 0;  // TextLayout's, culled ones included
};

struct CompositeReport {
    crisp::CompositorStats stats;  // the image's frame; its measurements are the first frame's
    std::vector<std::string> warnings;
    bool storage_without_format = false;  // the device's, as the context enabled it
    // CPU wall time of each composite frame (record, submit and wait), over all the canvas's bands.
    std::vector<double> frame_ms;
    uint32_t bands = 0;          // the canvas's bands, each composited apart (see kBandBytes)
    uint32_t band_rows = 0;      // rows of each band but the last
    std::vector<std::byte> png;  // the image, encoded band by band
};

struct RenderReport {
    uint64_t frames = 0;
    bool converged = false;
    // Why rendering stopped short of convergence: "" (it converged), "max-seconds" or "max-frames".
    std::string stopped;
    double stopped_ms = 0.0;  // since the run's start, when it stopped
    std::vector<double> frame_ms;
    double render_ms = 0.0;
    double readback_ms = 0.0;
    uint32_t min_samples = 0;  // over the glyphs drawn in the last frame
    uint32_t max_samples = 0;
    crisp::RendererStats last_frame;
    uint64_t total_samples = 0;
    uint64_t total_curve_tests = 0;
    uint64_t total_bitmap_uploads = 0;  // bitmap glyph images uploaded, all frames together
    uint32_t max_bitmap_misses = 0;     // image layers drawn without their image, in the worst frame
    crisp::AtlasStats atlas;
    uint32_t atlas_side = 0;
    std::vector<crisp::DrawnGlyph> drawn;  // the last frame's, in paint order
    // With --coverage-out only:
    std::vector<uint16_t> texels;      // RGBA16 of every drawn glyph's rect, at texel_offset[i]
    std::vector<size_t> texel_offset;  // per drawn glyph, in uint16_t units
    CompositeReport composite;
};

// One composite frame: `record` fills a command buffer, which is submitted and waited for; its wall
// time goes into out.frame_ms. kExitOk, or the exit code of a failed record or submission (said
// on stderr).
int run_composite_frame(crisp::HeadlessContext& context, int frame, CompositeReport& out,
                        const std::function<crisp::Status(VkCommandBuffer)>& record) {
    const auto frame_start = std::chrono::steady_clock::now();
    crisp::Status recorded;
    const crisp::Status submitted =
        context.submit_and_wait([&](VkCommandBuffer command_buffer) { recorded = record(command_buffer); });
    if (out.frame_ms.size() < static_cast<size_t>(frame)) out.frame_ms.resize(static_cast<size_t>(frame), 0.0);
    out.frame_ms[static_cast<size_t>(frame) - 1] += milliseconds_since(frame_start);
    for (const crisp::Status& status : {std::cref(recorded), std::cref(submitted)}) {
        if (!status) {
            std::fprintf(stderr, "crisp-render: composite frame %d: %s\n", frame, status.error().message.c_str());
            return exit_code_for_vulkan(status.error());
        }
    }
    return kExitOk;
}

// What the text is drawn over (--backdrop), premultiplied linear RGBA, top row first, for the
// canvas's rows [y0, y0 + rows) of `height`: the scene's background colour, a ramp from it to its
// complement with soft diagonal stripes, or smooth colour fields with fine detail, as a photograph has.
std::vector<float> backdrop_pixels(const std::string& kind, uint32_t width, uint32_t height, uint32_t y0, uint32_t rows,
                                   const float (&background)[4]) {
    std::array<float, 3> base{};
    for (size_t c = 0; c < 3; ++c) base[c] = crisp::srgb_to_linear(background[c]);
    const float alpha = background[3];
    std::vector<float> pixels(size_t{width} * rows * 4);
    for (uint32_t y = y0; y < y0 + rows; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const float u = width > 1 ? static_cast<float>(x) / static_cast<float>(width - 1) : 0.0f;
            const float v = height > 1 ? static_cast<float>(y) / static_cast<float>(height - 1) : 0.0f;
            std::array<float, 3> colour = base;
            if (kind == "gradient") {
                const float stripe = 0.5f + 0.5f * std::sin(static_cast<float>(x + y) * 0.35f);
                for (size_t c = 0; c < 3; ++c) {
                    const float ramp = base[c] + (1.0f - 2.0f * base[c]) * u;
                    colour[c] = std::clamp(ramp * (0.85f + 0.15f * stripe), 0.0f, 1.0f);
                }
            } else if (kind == "photo") {
                // A sky-to-ground ramp, three soft blobs of colour and a fine texture.
                const std::array<std::array<float, 5>, 3> blobs = {
                    {{0.25f, 0.3f, 0.9f, 0.5f, 0.2f}, {0.7f, 0.6f, 0.2f, 0.7f, 0.3f}, {0.5f, 0.9f, 0.8f, 0.2f, 0.6f}}};
                colour = {0.35f + 0.3f * v, 0.5f + 0.1f * v, 0.8f - 0.5f * v};
                for (const auto& b : blobs) {
                    const float dx = u - b[0], dy = v - b[1];
                    const float weight = std::exp(-(dx * dx + dy * dy) * 12.0f);
                    for (size_t c = 0; c < 3; ++c) colour[c] += weight * (b[c + 2] - colour[c]);
                }
                const float grain =
                    0.04f * std::sin(static_cast<float>(x) * 1.7f) * std::sin(static_cast<float>(y) * 2.3f);
                for (float& c : colour) c = std::clamp(c + grain, 0.0f, 1.0f);
            }
            float* p = &pixels[(size_t{y - y0} * width + x) * 4];
            for (size_t c = 0; c < 3; ++c) p[c] = colour[c] * alpha;
            p[3] = alpha;
        }
    }
    return pixels;
}

// Paints the decorations over the backdrop (premultiplied linear RGBA), each pixel by the area of
// it the rectangle covers: exactly for an untransformed run's, by 8 x 8 samples for a transformed
// one's (its rectangle mapped about the run's origin). `pixels` are the canvas's rows [y0, y0 + rows).
void paint_decorations(std::vector<float>& pixels, uint32_t width, uint32_t first_row, uint32_t rows,
                       std::span<const Job::Decoration> decorations) {
    for (const Job::Decoration& decoration : decorations) {
        const crisp::TextDecoration& r = decoration.rect;
        double x0 = static_cast<double>(r.x), y0 = static_cast<double>(r.y);
        double x1 = x0 + static_cast<double>(r.width), y1 = y0 + static_cast<double>(r.height);
        // The rectangle's corners on the canvas, and for a transform the inverse map back to it.
        std::array<std::array<double, 2>, 4> corners = {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}};
        const auto& t = decoration.transform;
        if (t) {
            for (auto& [x, y] : corners) {
                const double dx = x - static_cast<double>(t->pivot_x), dy = y - static_cast<double>(t->pivot_y);
                x = static_cast<double>(t->pivot_x) + static_cast<double>(t->a) * dx + static_cast<double>(t->b) * dy;
                y = static_cast<double>(t->pivot_y) + static_cast<double>(t->c) * dx + static_cast<double>(t->d) * dy;
            }
        }
        double left = corners[0][0], right = left, top = corners[0][1], bottom = top;
        for (const auto& [x, y] : corners) {
            left = std::min(left, x);
            right = std::max(right, x);
            top = std::min(top, y);
            bottom = std::max(bottom, y);
        }
        const auto clamp_x = [&](double v) { return static_cast<int64_t>(std::clamp(v, 0.0, double(width))); };
        const auto clamp_y = [&](double v) {
            return static_cast<int64_t>(std::clamp(v, double(first_row), double(uint64_t{first_row} + rows)));
        };
        const int64_t px0 = clamp_x(std::floor(left)), px1 = clamp_x(std::ceil(right));
        const int64_t py0 = clamp_y(std::floor(top)), py1 = clamp_y(std::ceil(bottom));
        double inverse[4] = {1.0, 0.0, 0.0, 1.0};
        if (t) {
            const double a = static_cast<double>(t->a), b = static_cast<double>(t->b);
            const double c = static_cast<double>(t->c), d = static_cast<double>(t->d);
            const double det = a * d - b * c;
            inverse[0] = d / det;
            inverse[1] = -b / det;
            inverse[2] = -c / det;
            inverse[3] = a / det;
        }
        const double alpha = static_cast<double>(r.color[3]);
        for (int64_t py = py0; py < py1; ++py) {
            for (int64_t px = px0; px < px1; ++px) {
                double cover = 0.0;
                if (!t) {
                    const double w = std::min(x1, double(px + 1)) - std::max(x0, double(px));
                    const double h = std::min(y1, double(py + 1)) - std::max(y0, double(py));
                    cover = std::max(0.0, w) * std::max(0.0, h);
                } else {
                    constexpr int kSamples = 8;
                    for (int sy = 0; sy < kSamples; ++sy) {
                        for (int sx = 0; sx < kSamples; ++sx) {
                            const double dx = double(px) + (sx + 0.5) / kSamples - static_cast<double>(t->pivot_x);
                            const double dy = double(py) + (sy + 0.5) / kSamples - static_cast<double>(t->pivot_y);
                            const double x = static_cast<double>(t->pivot_x) + inverse[0] * dx + inverse[1] * dy;
                            const double y = static_cast<double>(t->pivot_y) + inverse[2] * dx + inverse[3] * dy;
                            if (x >= x0 && x < x1 && y >= y0 && y < y1) cover += 1.0 / (kSamples * kSamples);
                        }
                    }
                }
                if (cover <= 0.0) continue;
                float* p = &pixels[(static_cast<size_t>(py - first_row) * width + static_cast<size_t>(px)) * 4];
                const double a = alpha * cover;
                for (int ch = 0; ch < 3; ++ch)
                    p[ch] = static_cast<float>(static_cast<double>(r.color[ch]) * a +
                                               static_cast<double>(p[ch]) * (1.0 - a));
                p[3] = static_cast<float>(a + static_cast<double>(p[3]) * (1.0 - a));
            }
        }
    }
}

// ---- Compositing in bands

// crisp-render composites the canvas in bands of whole rows, each band's R32G32B32A32 image at most
// kBandBytes, one band after another through the same compositor, so that its memory follows the
// text rather than the canvas: a band's image, its backdrop, the upload and the readback are
// band-sized, and the PNG is encoded band by band (only its compressed bytes are held whole). A
// band is a whole number of the compositors' tiles (16 rows: the tile path's, twice the reference
// compute path's), so each pixel is composited from the same glyphs in the same tile as on a whole
// canvas; and the glyphs reaching a band move up by whole pixels, keeping their subpixel phase.

struct Band {
    uint32_t y0 = 0;
    uint32_t rows = 0;
};

std::vector<Band> canvas_bands(const Arguments& args, uint32_t width, uint32_t height) {
    const uint64_t fit = kBandBytes / (uint64_t{width} * kTargetTexelBytes) / kBandRowStep * kBandRowStep;
    const auto rows = static_cast<uint32_t>(std::min<uint64_t>(
        args.band_rows.value_or(static_cast<uint32_t>(std::max<uint64_t>(fit, kBandRowStep))), height));
    std::vector<Band> bands;
    for (uint32_t y0 = 0; y0 < height; y0 += rows) bands.push_back({y0, std::min(rows, height - y0)});
    return bands;
}

// For each band of `rows` rows (the last may be shorter), the glyphs whose rects reach it.
std::vector<std::vector<uint32_t>> glyphs_by_band(std::span<const crisp::DrawnGlyph> glyphs, uint32_t rows,
                                                  size_t bands) {
    std::vector<std::vector<uint32_t>> members(bands);
    for (size_t g = 0; g < glyphs.size(); ++g) {
        const crisp::GlyphInstance& instance = glyphs[g].instance;
        const int64_t bottom = int64_t{instance.y} + instance.height;  // exclusive
        if (instance.width == 0 || instance.height == 0 || bottom <= 0) continue;
        const int64_t top = std::max<int64_t>(instance.y, 0);
        const auto last = std::min<int64_t>((bottom - 1) / rows, static_cast<int64_t>(bands) - 1);
        for (int64_t b = top / rows; b <= last; ++b)
            members[static_cast<size_t>(b)].push_back(static_cast<uint32_t>(g));
    }
    return members;
}

// The renderer's frame as one band sees it: the glyphs that reach its rows, moved up by its first
// row, with the paints that follow them (their maps from target pixels and their clips moved too).
// The whole canvas's frame where the band is the canvas.
class BandFrames {
public:
    BandFrames(const crisp::DrawnFrame& frame, std::span<const Band> bands) : frame_(frame) {
        if (bands.size() > 1) members_ = glyphs_by_band(frame.glyphs, bands[0].rows, bands.size());
    }

    crisp::DrawnFrame of(size_t band, const Band& rows) {
        if (members_.empty()) return frame_;
        const auto dy = static_cast<float>(rows.y0);
        glyphs_.clear();
        for (const uint32_t g : members_[band]) {
            crisp::DrawnGlyph glyph = frame_.glyphs[g];
            glyph.instance.y -= static_cast<int32_t>(rows.y0);
            glyph.instance.pen_y -= dy;
            glyphs_.push_back(glyph);
        }
        paints_.assign(frame_.paints.begin(), frame_.paints.end());
        for (crisp::FramePaint& paint : paints_) {
            // q = M (x, y + y0) + t: the translation takes M's y column times y0.
            paint.to_paint[2] += paint.to_paint[1] * dy;
            paint.to_paint[5] += paint.to_paint[4] * dy;
            paint.clip[1] -= dy;
            paint.clip[3] -= dy;
        }
        crisp::DrawnFrame frame = frame_.with_glyphs(glyphs_);
        frame.paints = paints_;
        return frame;
    }

private:
    crisp::DrawnFrame frame_;
    std::vector<std::vector<uint32_t>> members_;  // per band, the glyphs reaching it; empty: one band
    std::vector<crisp::DrawnGlyph> glyphs_;
    std::vector<crisp::FramePaint> paints_;
};

// A band's compositor statistics added to the canvas's: counts summed (a glyph reaching two bands
// is two quads), the most overlap the most of any band, measured where every band was.
void add_band_stats(crisp::CompositorStats& total, const crisp::CompositorStats& band, bool first) {
    if (first) {
        total = band;
        return;
    }
    total.tiles += band.tiles;
    total.bins_reused = total.bins_reused && band.bins_reused;
    total.tile_batches += band.tile_batches;
    total.quads += band.quads;
    total.buffer_bytes = std::max(total.buffer_bytes, band.buffer_bytes);
    total.measured = total.measured && band.measured;
    total.max_overlap = std::max(total.max_overlap, band.max_overlap);
    total.tail_pixels += band.tail_pixels;
    total.exact_lost_nodes += band.exact_lost_nodes;
    total.exact_dropped += band.exact_dropped;
    total.busy_tiles += band.busy_tiles;
    total.exact_tiles += band.exact_tiles;
    total.layered_tiles += band.layered_tiles;
    total.tile_pairs += band.tile_pairs;
    total.tile_empty_pairs += band.tile_empty_pairs;
    total.tile_hidden_pairs += band.tile_hidden_pairs;
}

// Encodes each band's premultiplied RGBA as the PNG's rows: RGB over an opaque background (alpha is
// 1 everywhere, so the colour is as it is), else RGBA with the colour divided by alpha.
crisp::Status add_png_rows(crisp::PngRowEncoder& png, std::span<const float> rgba, bool opaque) {
    const size_t pixels = rgba.size() / 4;
    const size_t channels = opaque ? 3 : 4;
    std::vector<float> out(pixels * channels);
    for (size_t p = 0; p < pixels; ++p) {
        const float* source = &rgba[p * 4];
        float* pixel = &out[p * channels];
        if (opaque) {
            std::copy(source, source + 3, pixel);
            continue;
        }
        const float alpha = source[3];
        for (size_t c = 0; c < 3; ++c) pixel[c] = alpha > 0.0f ? source[c] / alpha : 0.0f;
        pixel[3] = alpha;
    }
    return png.add_rows(out);
}

// What every band's compositing shares: the bands, their frames, the PNG they go into.
struct BandedImage {
    std::vector<Band> bands;
    BandFrames frames;
    crisp::PngRowEncoder png;
    bool opaque = true;
};

crisp::Result<BandedImage> banded_image(const Arguments& args, const Job& job, const crisp::Renderer& renderer,
                                        CompositeReport& out) {
    const uint32_t width = job.scene.width, height = job.scene.height;
    const bool opaque = job.scene.background[3] >= 1.0f;
    std::vector<Band> bands = canvas_bands(args, width, height);
    crisp::Result<crisp::PngRowEncoder> png = crisp::PngRowEncoder::create(width, height, opaque ? 3 : 4);
    if (!png) return png.error();
    out.bands = static_cast<uint32_t>(bands.size());
    out.band_rows = bands.front().rows;
    BandFrames frames(renderer.drawn_frame(), bands);
    return BandedImage{std::move(bands), std::move(frames), std::move(*png), opaque};
}

int png_failed(const crisp::Error& error) {
    std::fprintf(stderr, "crisp-render: encoding the PNG: %s\n", error.message.c_str());
    return error.code == crisp::ErrorCode::io ? kExitOutput : kExitInternal;
}

// The tile or draw path: each band's backdrop is uploaded into an R32G32B32A32_SFLOAT image of the
// band and the band's glyphs composited into it, twice from the same backdrop (the first frame's
// tile counts arrive with the second; once when the first ends past --max-seconds), then read back
// into the PNG.
int composite_into_image(crisp::HeadlessContext& context, const crisp::Renderer& renderer, const Arguments& args,
                         const Job& job, const RunClock& clock, RenderReport& report) {
    CompositeReport& out = report.composite;
    const bool draw = args.composite == crisp::CompositeMode::draw;
    constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
    const uint32_t width = job.scene.width;
    crisp::CompositorCreateInfo info = crisp::compositor_create_info(context);
    info.frames_in_flight = 1;  // every frame is waited for, so the next one has its measurements
    if (draw) info.draw_format = kFormat;
    crisp::Result<crisp::Compositor> created = crisp::Compositor::create(info);
    if (!created) {
        std::fprintf(stderr, "crisp-render: cannot create the compositor: %s\n", created.error().message.c_str());
        return exit_code_for_vulkan(created.error());
    }
    crisp::Compositor& compositor = *created;
    out.warnings = compositor.warnings();
    crisp::Result<BandedImage> banded = banded_image(args, job, renderer, out);
    if (!banded) return png_failed(banded.error());
    const VkImageUsageFlags usage = (draw ? VkImageUsageFlags{VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT}
                                          : VkImageUsageFlags{VK_IMAGE_USAGE_STORAGE_BIT}) |
                                    VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    crisp::Result<crisp::Image> image = context.create_image({kFormat, width, banded->bands.front().rows, usage});
    if (!image) {
        std::fprintf(stderr, "crisp-render: cannot make the canvas image: %s\n", image.error().message.c_str());
        return exit_code_for_vulkan(image.error());
    }
    bool past_limit = false;
    for (size_t b = 0; b < banded->bands.size(); ++b) {
        const Band& band = banded->bands[b];
        if (band.rows != banded->bands.front().rows) {  // the last band, shorter
            image = context.create_image({kFormat, width, band.rows, usage});
            if (!image) {
                std::fprintf(stderr, "crisp-render: cannot make the canvas image: %s\n", image.error().message.c_str());
                return exit_code_for_vulkan(image.error());
            }
        }
        std::vector<float> backdrop =
            backdrop_pixels(args.backdrop, width, job.scene.height, band.y0, band.rows, job.scene.background);
        paint_decorations(backdrop, width, band.y0, band.rows, job.decorations);
        const crisp::DrawnFrame frame = banded->frames.of(b, band);
        const VkRect2D rect{{0, 0}, {width, band.rows}};
        constexpr int kCompositeFrames = 2;
        for (int composite_frame = 1; composite_frame <= kCompositeFrames; ++composite_frame) {
            if (crisp::Status s = context.upload(*image, std::as_bytes(std::span(backdrop)), VK_IMAGE_LAYOUT_GENERAL);
                !s) {
                std::fprintf(stderr, "crisp-render: cannot upload the backdrop: %s\n", s.error().message.c_str());
                return exit_code_for_vulkan(s.error());
            }
            const int code = run_composite_frame(context, composite_frame, out, [&](VkCommandBuffer command_buffer) {
                if (!draw) {
                    const crisp::CompositeTarget target{
                        image->view(), kFormat, VK_FORMAT_UNDEFINED, {width, band.rows}, rect};
                    return compositor.record(command_buffer, frame, target);
                }
                crisp::tools::begin_rendering_over(command_buffer, image->view(), rect);
                crisp::Status recorded = compositor.record_draw(command_buffer, frame, rect);
                vkCmdEndRendering(command_buffer);
                return recorded;
            });
            if (code != kExitOk) return code;
            // The first frame's image is the same, without measurements; the bands after it too.
            past_limit = past_limit || clock.past_limit();
            if (past_limit) break;
        }
        add_band_stats(out.stats, compositor.stats(), b == 0);
        std::vector<float>().swap(backdrop);
        crisp::Result<std::vector<std::byte>> bytes = context.read_image(*image, VK_IMAGE_LAYOUT_GENERAL);
        if (!bytes) {
            std::fprintf(stderr, "crisp-render: cannot read the canvas back: %s\n", bytes.error().message.c_str());
            return exit_code_for_vulkan(bytes.error());
        }
        std::vector<float> rgba(bytes->size() / sizeof(float));
        std::memcpy(rgba.data(), bytes->data(), rgba.size() * sizeof(float));
        if (crisp::Status s = add_png_rows(banded->png, rgba, banded->opaque); !s) return png_failed(s.error());
    }
    crisp::Result<std::vector<std::byte>> png = banded->png.finish();
    if (!png) return png_failed(png.error());
    out.png = std::move(*png);
    return kExitOk;
}

// Composites the renderer's last frame twice a band, the same glyphs both times: the first frame
// measures the overlap (what the report gives; measurements arrive one frame later), the second
// is the image, read back into the PNG. A first frame that ends past --max-seconds is the image,
// and nothing is measured (nor in the bands after it).
int composite(crisp::HeadlessContext& context, const crisp::Renderer& renderer, const Arguments& args, const Job& job,
              const RunClock& clock, RenderReport& report) {
    CompositeReport& out = report.composite;
    if (args.composite == crisp::CompositeMode::tiled || args.composite == crisp::CompositeMode::draw) {
        return composite_into_image(context, renderer, args, job, clock, report);
    }
    // The reference modes composite over a flat background, where there is no backdrop to draw
    // decorations into.
    if (!job.decorations.empty()) {
        out.warnings.push_back(std::to_string(job.decorations.size()) +
                               " underlines and strikethroughs are not drawn: the reference modes draw over a flat "
                               "background (--composite tiled and draw draw them)");
    }
    crisp::Result<BandedImage> banded = banded_image(args, job, renderer, out);
    if (!banded) return png_failed(banded.error());
    crisp::CompositeParams params;
    params.mode = args.composite;
    params.path = args.path;
    for (size_t c = 0; c < 3; ++c) params.background[c] = crisp::srgb_to_linear(job.scene.background[c]);
    params.background[3] = job.scene.background[3];

    // The reference modes' target and per-pixel buffers are the compositor's, made for its size: one
    // compositor for the bands of equal height, another for a shorter last band.
    std::optional<crisp::Compositor> compositor;
    uint32_t compositor_rows = 0;
    bool past_limit = false;
    for (size_t b = 0; b < banded->bands.size(); ++b) {
        const Band& band = banded->bands[b];
        if (band.rows != compositor_rows) {
            compositor.reset();
            crisp::CompositorCreateInfo info = crisp::compositor_create_info(context);
            info.width = job.scene.width;
            info.height = band.rows;
            info.frames_in_flight = 1;  // every frame is waited for, so the next one has its measurements
            info.reference_modes = true;
            if (args.composite != crisp::CompositeMode::exact) info.exact_nodes_per_pixel = 0;  // no node pool
            crisp::Result<crisp::Compositor> created = crisp::Compositor::create(info);
            if (!created) {
                std::fprintf(stderr, "crisp-render: cannot create the compositor: %s\n",
                             created.error().message.c_str());
                return exit_code_for_vulkan(created.error());
            }
            compositor.emplace(std::move(*created));
            compositor_rows = band.rows;
            for (const std::string& warning : compositor->warnings()) {
                if (std::find(out.warnings.begin(), out.warnings.end(), warning) == out.warnings.end())
                    out.warnings.push_back(warning);
            }
        }
        const size_t pixels = size_t{job.scene.width} * band.rows;
        crisp::Result<crisp::Buffer> buffer = context.create_buffer(
            pixels * kTargetTexelBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, crisp::MemoryUsage::readback);
        if (!buffer) {
            std::fprintf(stderr, "crisp-render: cannot make the image's readback buffer: %s\n",
                         buffer.error().message.c_str());
            return exit_code_for_vulkan(buffer.error());
        }
        const crisp::DrawnFrame frame = banded->frames.of(b, band);
        constexpr int kCompositeFrames = 2;
        for (int composite_frame = 1; composite_frame <= kCompositeFrames; ++composite_frame) {
            const int code = run_composite_frame(context, composite_frame, out, [&](VkCommandBuffer command_buffer) {
                crisp::Status recorded = compositor->record_reference(command_buffer, frame, params);
                // Every frame's image is read back: the first is the last where it ends past the limit.
                if (recorded) compositor->record_target_readback(command_buffer, buffer->handle());
                return recorded;
            });
            if (code != kExitOk) return code;
            past_limit = past_limit || clock.past_limit();
            if (past_limit) break;
        }
        add_band_stats(out.stats, compositor->stats(), b == 0);
        std::vector<float> rgba(pixels * 4);
        std::memcpy(rgba.data(), buffer->mapped().data(), pixels * kTargetTexelBytes);
        if (crisp::Status s = add_png_rows(banded->png, rgba, banded->opaque); !s) return png_failed(s.error());
    }
    crisp::Result<std::vector<std::byte>> png = banded->png.finish();
    if (!png) return png_failed(png.error());
    out.png = std::move(*png);
    return kExitOk;
}

// Reads back each drawn glyph's atlas rect (once per rect: glyphs with equal keys share one), for
// the coverage image.
int read_atlas_rects(crisp::HeadlessContext& context, const crisp::Renderer& renderer, RenderReport& report) {
    const auto readback_start = std::chrono::steady_clock::now();
    std::map<std::pair<uint32_t, uint32_t>, size_t> rect_offset;
    std::vector<VkBufferImageCopy> regions;
    size_t texel_count = 0;
    report.texel_offset.resize(report.drawn.size());
    for (size_t i = 0; i < report.drawn.size(); ++i) {
        const crisp::DrawnGlyph& glyph = report.drawn[i];
        const auto [it, inserted] = rect_offset.try_emplace({glyph.atlas_x, glyph.atlas_y}, texel_count);
        report.texel_offset[i] = it->second * 4;
        if (!inserted) continue;
        VkBufferImageCopy region{};
        region.bufferOffset = texel_count * kAtlasTexelBytes;
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageOffset = {static_cast<int32_t>(glyph.atlas_x), static_cast<int32_t>(glyph.atlas_y), 0};
        region.imageExtent = {glyph.instance.width, glyph.instance.height, 1};
        regions.push_back(region);
        texel_count += size_t{glyph.instance.width} * glyph.instance.height;
    }
    // record() made the atlas readable by transfers; the read orders the copy after the last
    // frame's dispatch and the compositor's reads (earlier submissions) and returns the atlas to
    // GENERAL, where the renderer keeps it.
    const crisp::Result<std::vector<std::byte>> texels = context.read_image_regions(
        renderer.atlas_image(), VK_IMAGE_LAYOUT_GENERAL, regions, texel_count * kAtlasTexelBytes);
    if (!texels) {
        std::fprintf(stderr, "crisp-render: reading the atlas back: %s\n", texels.error().message.c_str());
        return exit_code_for_vulkan(texels.error());
    }
    report.texels.resize(texel_count * 4);
    std::memcpy(report.texels.data(), texels->data(), texel_count * kAtlasTexelBytes);
    report.readback_ms = milliseconds_since(readback_start);
    return kExitOk;
}

int render(crisp::HeadlessContext& context, const Arguments& args, const Job& job, const RunClock& clock,
           RenderReport& report) {
    crisp::RendererCreateInfo info = crisp::renderer_create_info(context);
    info.layout = job.subpixel_layout;
    info.atlas.max_samples = args.samples;
    for (uint32_t& samples : info.atlas.ramp) samples = std::min(samples, args.samples);
    // Effect layers take atlas entries of their own: the outline's, the shadow's and the glow's (the
    // glyph with its outline), each as large as the glyph grown by the outline's reach and its blur's.
    std::vector<crisp::GlyphInstance> entries = job.glyphs;
    for (const Job::Draw& draw : job.draws) {
        if (!draw.effects) continue;
        const crisp::TextEffects& e = *draw.effects;
        const float reach = (e.outline ? e.outline->width : 0.0f) + std::max(e.weight, 0.0f);
        const float blur = std::max(e.shadow ? e.shadow->blur : 0.0f, e.glow ? e.glow->radius : 0.0f);
        const auto grow = static_cast<uint32_t>(2.0f * (std::ceil(reach) + std::ceil(blur + 1.0f)) + 2.0f);
        for (size_t i = draw.first; i < draw.first + draw.count; ++i) {
            for (uint32_t layer = 1; layer <= 3; ++layer) {
                crisp::GlyphInstance g = job.glyphs[i];
                if (g.width == 0 || g.height == 0) continue;
                g.key.effect = layer;  // a key apart from the glyph's
                g.width += grow;
                g.height += grow;
                entries.push_back(g);
            }
        }
    }
    report.atlas_side = atlas_side_for(entries);
    info.atlas.width = info.atlas.height = report.atlas_side;
    info.contrast = job.contrast;

    crisp::Result<crisp::Renderer> created = crisp::Renderer::create(info);
    if (!created) {
        std::fprintf(stderr, "crisp-render: cannot create the renderer: %s\n", created.error().message.c_str());
        return exit_code_for_vulkan(created.error());
    }
    crisp::Renderer& renderer = *created;
    for (const crisp::Font& font : job.fonts) {
        if (crisp::Status status = renderer.add_font(font); !status) {
            std::fprintf(stderr, "crisp-render: cannot add font %u (%s): %s\n", font.id(),
                         crisp::cli::printable_path(job.scene.fonts[font.id() - 1]).c_str(),
                         status.error().message.c_str());
            return exit_code_for_vulkan(status.error());
        }
    }

    const auto render_start = std::chrono::steady_clock::now();
    auto frame_start = render_start;
    const crisp::Result<uint32_t> frames = crisp::harness::render_until_converged(
        context, renderer, args.max_frames.value_or(kMaxFrames),
        [&] {
            frame_start = std::chrono::steady_clock::now();
            const VkRect2D canvas{{0, 0}, {job.scene.width, job.scene.height}};
            for (const Job::Draw& draw : job.draws) {
                const std::span<const crisp::GlyphInstance> glyphs(job.glyphs.data() + draw.first, draw.count);
                if (!draw.contrast && !draw.transform && !draw.effects) {
                    renderer.draw(glyphs, canvas);
                    continue;
                }
                crisp::DrawOptions options;
                options.visible = canvas;
                options.contrast = draw.contrast;
                options.transform = draw.transform;
                options.effects = draw.effects;
                renderer.draw(glyphs, options);
            }
        },
        [&] {
            report.frame_ms.push_back(milliseconds_since(frame_start));
            report.total_samples += renderer.stats().samples;
            report.total_curve_tests += renderer.stats().curve_tests;
            report.total_bitmap_uploads += renderer.stats().bitmap_uploads;
            report.max_bitmap_misses = std::max(report.max_bitmap_misses, renderer.stats().bitmap_misses);
            if (!renderer.converged() && clock.past_limit()) {
                report.stopped = "max-seconds";
                return false;
            }
            return true;
        });
    if (!frames) {
        std::fprintf(stderr, "crisp-render: frame %llu: %s\n",
                     static_cast<unsigned long long>(report.frame_ms.size() + 1), frames.error().message.c_str());
        return exit_code_for_vulkan(frames.error());
    }
    report.frames = *frames;
    report.converged = renderer.converged();
    if (!report.converged && report.stopped.empty()) {
        if (!args.max_frames) {
            std::fprintf(stderr, "crisp-render: the renderer did not converge in %llu frames\n",
                         static_cast<unsigned long long>(kMaxFrames));
            return kExitInternal;
        }
        report.stopped = "max-frames";
    }
    report.render_ms = milliseconds_since(render_start);
    report.stopped_ms = milliseconds_since(clock.start);
    report.last_frame = renderer.stats();
    report.atlas = renderer.atlas().stats();

    report.drawn.assign(renderer.drawn().begin(), renderer.drawn().end());
    std::stable_sort(report.drawn.begin(), report.drawn.end(),
                     [](const crisp::DrawnGlyph& a, const crisp::DrawnGlyph& b) {
                         return a.instance.paint_order < b.instance.paint_order;
                     });
    if (!report.drawn.empty()) {
        report.min_samples = UINT32_MAX;
        for (const crisp::DrawnGlyph& glyph : report.drawn) {
            report.min_samples = std::min(report.min_samples, glyph.samples);
            report.max_samples = std::max(report.max_samples, glyph.samples);
        }
    }

    if (const int code = composite(context, renderer, args, job, clock, report); code != kExitOk) return code;
    if (args.coverage_output.empty() || report.drawn.empty()) return kExitOk;
    return read_atlas_rects(context, renderer, report);
}

// ---- Images

// The text's linear coverage per channel, ignoring colours and alphas, of the canvas's rows
// [band.y0, band.y0 + band.rows), from the glyphs `members` names: where glyphs overlap,
// 1 - (1 - c1)(1 - c2)...
std::vector<float> coverage_rows(uint32_t width, const Band& band, const RenderReport& report,
                                 std::span<const uint32_t> members) {
    std::vector<float> uncovered(size_t{width} * band.rows * 3, 1.0f);
    const int64_t top = band.y0, bottom = int64_t{band.y0} + band.rows;
    for (const uint32_t g : members) {
        const crisp::GlyphInstance& instance = report.drawn[g].instance;
        const uint16_t* texels = report.texels.data() + report.texel_offset[g];
        for (uint32_t j = 0; j < instance.height; ++j) {
            const int64_t y = int64_t{instance.y} + j;
            if (y < top || y >= bottom) continue;
            for (uint32_t i = 0; i < instance.width; ++i) {
                const int64_t x = int64_t{instance.x} + i;
                if (x < 0 || x >= int64_t{width}) continue;
                const uint16_t* texel = texels + (size_t{j} * instance.width + i) * 4;
                if (texel[3] == 0) continue;
                const float full = static_cast<float>(crisp::kCoverageOne) * static_cast<float>(texel[3]);
                const size_t p = (static_cast<size_t>(y - top) * width + static_cast<size_t>(x)) * 3;
                for (size_t c = 0; c < 3; ++c)
                    uncovered[p + c] *= 1.0f - std::min(static_cast<float>(texel[c]) / full, 1.0f);
            }
        }
    }
    for (float& value : uncovered) value = 1.0f - value;
    return uncovered;
}

// Writes the coverage PFM band by band, from the bottom band up as the file stores its rows, so
// that it is never held whole (16384 x 16384 is 3 GiB).
crisp::OutputWriter coverage_writer(const Arguments& args, const Job& job, const RenderReport& report) {
    return [&args, &job, &report](const std::function<crisp::Status(std::span<const std::byte>)>& put) {
        const uint32_t width = job.scene.width, height = job.scene.height;
        const std::vector<Band> bands = canvas_bands(args, width, height);
        const std::vector<std::vector<uint32_t>> members =
            glyphs_by_band(report.texels.empty() ? std::span<const crisp::DrawnGlyph>{} : report.drawn,
                           bands.front().rows, bands.size());
        const std::string header = crisp::pfm_header(width, height);
        if (crisp::Status s = put(std::as_bytes(std::span(header))); !s) return s;
        std::vector<std::byte> bytes;
        for (size_t b = bands.size(); b-- > 0;) {
            bytes.clear();
            crisp::append_pfm_rows(bytes, width, coverage_rows(width, bands[b], report, members[b]));
            if (crisp::Status s = put(bytes); !s) return s;
        }
        return crisp::Status{};
    };
}

// ---- Report

// Distinct glyphs (atlas entries, effect layers included) the last frame drew that hold every sample.
uint32_t converged_glyphs(const RenderReport& r) {
    return r.atlas.pinned_glyphs - r.atlas.refining_glyphs;
}
// Glyph instances of the last frame left out of the image because they hold no sample yet.
uint32_t glyphs_without_samples(const RenderReport& r) {
    const crisp::RendererStats& f = r.last_frame;
    return f.skipped_glyphs - std::min(f.skipped_glyphs, f.failed_glyphs + f.unknown_fonts);
}

struct Summary {
    const Arguments* args = nullptr;
    const crisp::HeadlessContext* context = nullptr;
    const Job* job = nullptr;
    const RenderReport* render = nullptr;
    uint32_t culled_glyphs = 0;
    double write_ms = 0.0;
    double total_ms = 0.0;
    crisp::ValidationMessages validation;
};

bool is_exact(const CompositeReport& c) {
    return c.stats.mode == crisp::CompositeMode::exact;
}
bool is_tiled(const CompositeReport& c) {
    return c.stats.mode == crisp::CompositeMode::tiled;
}
// The measured max overlap, for the modes that measure it.
bool has_overlap(const CompositeReport& c) {
    return c.stats.measured && (is_exact(c) || is_tiled(c));
}

void write_composite(crisp::JsonWriter& json, const Arguments& args, const CompositeReport& c) {
    const crisp::CompositorStats& s = c.stats;
    const bool exact = s.measured && is_exact(c);
    const bool tiles = s.measured && is_tiled(c);
    auto when = [](bool present, uint64_t v) { return present ? std::optional<uint64_t>(v) : std::nullopt; };
    json.begin_object()
        .field("mode", crisp::composite_mode_name(s.mode))
        .field("path", crisp::quad_path_name(s.path))
        .field("storage_without_format", c.storage_without_format)
        .field("quads", s.quads)
        .field("bins_reused", s.bins_reused)
        .field("buffer_bytes", s.buffer_bytes)
        .field("measured", s.measured)
        .field("max_overlap", when(has_overlap(c), s.max_overlap))
        .field("tail_pixels", when(tiles, s.tail_pixels))
        .key("tiles");
    if (tiles) {
        json.begin_object()
            .field("busy", s.busy_tiles)
            .field("exact", s.exact_tiles)
            .field("layered", s.layered_tiles)
            .field("pairs", s.tile_pairs)
            .field("empty_pairs", s.tile_empty_pairs)
            .field("hidden_pairs", s.tile_hidden_pairs)
            .end_object();
    } else {
        json.null();
    }
    json.field("backdrop", args.backdrop)
        .field("exact_lost_nodes", when(exact, s.exact_lost_nodes))
        .field("exact_dropped", when(exact, s.exact_dropped))
        .field("bands", c.bands)
        .field("band_rows", c.band_rows)
        .field("frame_ms", c.frame_ms)
        .field("ms", c.frame_ms.empty() ? 0.0 : c.frame_ms.back())
        .field("warnings", c.warnings)
        .end_object();
}

void write_glyphs_and_timings(crisp::JsonWriter& json, const Summary& s) {
    const Job& job = *s.job;
    const RenderReport& r = *s.render;
    const crisp::RendererStats& last = r.last_frame;
    json.key("glyphs").begin_object();
    json.field("laid_out", job.laid_out)
        .field("culled", s.culled_glyphs)
        .field("drawn", last.drawn_glyphs)
        .field("skipped", last.skipped_glyphs)
        .field("failed", last.failed_glyphs)
        .field("unknown_fonts", last.unknown_fonts)
        .field("missing", job.missing)
        .field("blank", job.blank)
        .field("out_of_range", job.out_of_range)
        .end_object();
    json.key("effects").begin_object();
    json.field("layers", last.effect_layers)
        .field("texels", last.effect_texels)
        .field("failed", last.failed_effects)
        .field("derived_glyphs", last.derived_glyphs)
        .field("derived_bytes", last.derived_bytes)
        .end_object();
    json.key("colour").begin_object();
    json.field("enabled", !s.args->no_colour)
        .field("glyphs", job.colour_glyphs)
        .field("layers", job.colour_layers)
        .field("drawn_layers", last.colour_layers)
        .field("paints", last.frame_paints)
        .field("bitmap_uploads", r.total_bitmap_uploads)
        .field("bitmap_misses", r.max_bitmap_misses)
        .end_object();
    json.field("total_samples", r.total_samples).field("total_curve_tests", r.total_curve_tests);
    json.key("composite");
    write_composite(json, *s.args, r.composite);
    double frame_total = 0.0;
    for (const double ms : r.frame_ms) frame_total += ms;
    const std::vector<double>& composite_ms = r.composite.frame_ms;
    json.key("timings").begin_object();
    json.field("frame_ms", r.frame_ms)
        .field("frames_ms", frame_total)
        .field("mean_frame_ms", r.frames ? frame_total / static_cast<double>(r.frames) : 0.0)
        .field("composite_ms", composite_ms.empty() ? 0.0 : composite_ms.back())
        .field("readback_ms", r.readback_ms)
        .field("write_ms", s.write_ms)
        .field("total_ms", s.total_ms)
        .end_object();
}

// A string, or null where it is empty.
std::optional<std::string> unless_empty(const std::string& text) {
    return text.empty() ? std::nullopt : std::optional<std::string>(text);
}

// The scene's runs drawn with contrast settings of their own rather than the command line's.
size_t own_contrast_runs(const crisp::Scene& scene) {
    return static_cast<size_t>(std::count_if(scene.runs.begin(), scene.runs.end(),
                                             [](const crisp::SceneRun& run) { return run.contrast.has_value(); }));
}

// "corrected, gamma 2.2, contrast 0, stem darkening 0" or "linear", and the runs that say otherwise.
std::string human_contrast(const crisp::TextContrast& contrast, const crisp::Scene& scene) {
    std::string out = contrast_mode_name(contrast.mode);
    if (contrast.mode == crisp::ContrastMode::corrected) {
        char settings[96];
        std::snprintf(settings, sizeof settings, ", gamma %g, contrast %g, stem darkening %g",
                      static_cast<double>(contrast.gamma), static_cast<double>(contrast.contrast),
                      static_cast<double>(contrast.stem_darkening));
        out += settings;
    }
    if (const size_t own = own_contrast_runs(scene); own > 0) {
        out += " (" + std::to_string(own) + (own == 1 ? " run has its own" : " runs have their own") + ")";
    }
    return out;
}

void print_json(const Summary& s) {
    const Arguments& args = *s.args;
    const Job& job = *s.job;
    const RenderReport& r = *s.render;
    crisp::JsonWriter json;
    json.begin_object().field("frames", r.frames).field("converged", r.converged);
    json.field("stopped", unless_empty(r.stopped)).field("max_seconds", args.max_seconds);
    json.key("samples").begin_object();
    json.field("target", args.samples).field("min", r.min_samples).field("max", r.max_samples);
    json.field("glyphs", r.atlas.pinned_glyphs).field("converged_glyphs", converged_glyphs(r)).end_object();
    write_glyphs_and_timings(json, s);
    json.key("atlas").begin_object();
    json.field("width", r.atlas_side)
        .field("height", r.atlas_side)
        .field("occupancy", r.atlas.occupancy)
        .field("resident", r.atlas.resident_glyphs)
        .field("allocations", r.atlas.total.allocations)
        .field("evictions", r.atlas.total.evictions)
        .field("failed_full", r.atlas.total.failed_full)
        .field("failed_too_large", r.atlas.total.failed_too_large)
        .field("budget_overruns", r.atlas.total.budget_overruns)
        .end_object();
    json.key("device").begin_object();
    json.field("name", s.context->device_name())
        .field("driver", s.context->driver_name())
        .field("driver_info", s.context->driver_info())
        .end_object();
    json.field("layout", job.subpixel_layout.name);
    json.key("contrast").begin_object();
    json.field("mode", contrast_mode_name(job.contrast.mode))
        .field("gamma", job.contrast.gamma)
        .field("contrast", job.contrast.contrast)
        .field("stem_darkening", job.contrast.stem_darkening)
        .field("own_runs", own_contrast_runs(job.scene))
        .end_object();
    json.field("scene", unless_empty(args.scene)).field("runs", job.scene.runs.size());
    json.field("size", args.scene.empty() ? args.size : std::nullopt).key("origin");
    if (args.scene.empty()) {
        json.begin_array().value((*args.origin)[0]).value((*args.origin)[1]).end_array();
    } else {
        json.null();
    }
    json.key("canvas").begin_object().field("width", job.scene.width).field("height", job.scene.height).end_object();
    json.key("outputs").begin_object();
    json.field("png", args.output).field("coverage", unless_empty(args.coverage_output)).end_object();
    if (args.validate) {
        json.key("validation").begin_object();
        json.field("warnings", s.validation.warnings).field("errors", s.validation.errors).end_object();
    }
    json.end_object();
    std::fputs(json.line().c_str(), stdout);
}

// "tiled, compute path, max overlap 3, 30 tiles (30 exact, 0 layered), 1.2 ms"
std::string human_composite(const Arguments& args, const CompositeReport& c) {
    const crisp::CompositorStats& s = c.stats;
    std::string out = crisp::composite_mode_name(s.mode);
    if (s.path == crisp::QuadPath::compute) out += ", compute path";
    if (has_overlap(c)) out += ", max overlap " + std::to_string(s.max_overlap);
    if (s.measured && is_exact(c)) {
        out += ", " + std::to_string(s.exact_lost_nodes) + " lost, " + std::to_string(s.exact_dropped) + " dropped";
    }
    if (s.measured && is_tiled(c)) {
        out += ", " + std::to_string(s.busy_tiles) + " tiles (" + std::to_string(s.exact_tiles) + " exact, " +
               std::to_string(s.layered_tiles) + " layered)";
    }
    if (args.backdrop != "flat") out += ", over a " + args.backdrop + " backdrop";
    if (c.bands > 1) out += ", in " + std::to_string(c.bands) + " bands of " + std::to_string(c.band_rows) + " rows";
    char ms[32];
    std::snprintf(ms, sizeof ms, ", %.1f ms", c.frame_ms.empty() ? 0.0 : c.frame_ms.back());
    return out + ms;
}

void print_human(const Summary& s) {
    const Arguments& args = *s.args;
    const Job& job = *s.job;
    const RenderReport& r = *s.render;
    double frame_total = 0.0;
    for (const double ms : r.frame_ms) frame_total += ms;
    std::printf("%s (%ux%u)%s%s\n", crisp::cli::printable_path(args.output).c_str(), job.scene.width, job.scene.height,
                args.coverage_output.empty() ? "" : ", coverage in ", args.coverage_output.c_str());
    if (!args.scene.empty())
        std::printf("  scene    %s, %zu runs\n", crisp::cli::printable_path(args.scene).c_str(), job.scene.runs.size());
    std::printf("  device   %s (%s, %s)\n", s.context->device_name().c_str(), s.context->driver_name().c_str(),
                s.context->driver_info().c_str());
    std::printf("  layout   %s, %u samples per texel and channel\n",
                crisp::cli::printable(job.subpixel_layout.name).c_str(), args.samples);
    std::printf("  glyphs   %u drawn, %zu laid out (%u outside the canvas), %u missing, %u failed\n",
                r.last_frame.drawn_glyphs, job.laid_out, s.culled_glyphs, job.missing, r.last_frame.failed_glyphs);
    if (job.colour_glyphs > 0 || r.max_bitmap_misses > 0) {
        std::printf("  colour   %u glyphs as %u layers (%u drawn, %u paints), %llu bitmap uploads, %u missed\n",
                    job.colour_glyphs, job.colour_layers, r.last_frame.colour_layers, r.last_frame.frame_paints,
                    static_cast<unsigned long long>(r.total_bitmap_uploads), r.max_bitmap_misses);
    }
    if (r.last_frame.effect_layers > 0 || r.last_frame.failed_effects > 0) {
        std::printf("  effects  %u layers (%llu texels), %u derived outlines (%llu bytes), %u failed\n",
                    r.last_frame.effect_layers, static_cast<unsigned long long>(r.last_frame.effect_texels),
                    r.last_frame.derived_glyphs, static_cast<unsigned long long>(r.last_frame.derived_bytes),
                    r.last_frame.failed_effects);
    }
    std::printf("  frames   %llu, %.1f ms (%.2f ms per frame)%s\n", static_cast<unsigned long long>(r.frames),
                frame_total, r.frames ? frame_total / static_cast<double>(r.frames) : 0.0,
                r.stopped.empty() ? "" : (", stopped by --" + r.stopped + ", not converged").c_str());
    std::printf("  blend    %s\n", human_composite(args, r.composite).c_str());
    std::printf("  contrast %s\n", human_contrast(job.contrast, job.scene).c_str());
    std::printf("  atlas    %ux%u, %.1f%% occupied, %u resident, %llu allocations, %llu evictions\n", r.atlas_side,
                r.atlas_side, 100.0 * static_cast<double>(r.atlas.occupancy), r.atlas.resident_glyphs,
                static_cast<unsigned long long>(r.atlas.total.allocations),
                static_cast<unsigned long long>(r.atlas.total.evictions));
}

// ---- The run

// The one run the command line describes, as a scene.
crisp::Scene scene_from_arguments(const Arguments& args) {
    crisp::Scene scene;
    scene.fonts = args.fonts;
    scene.width = (*args.canvas)[0];
    scene.height = (*args.canvas)[1];
    if (args.background) std::copy(args.background->begin(), args.background->end(), scene.background);
    scene.layout = args.layout.value_or("rgb");
    crisp::SceneRun run;
    run.text = *args.text;
    run.size = *args.size;
    run.origin_x = (*args.origin)[0];
    run.origin_y = (*args.origin)[1];
    if (args.color) std::copy(args.color->begin(), args.color->end(), run.color);
    scene.palette = run.palette = args.palette.value_or(0);
    run.transform = args.transform;
    run.effects = effects_of(args);
    scene.runs.push_back(std::move(run));
    return scene;
}

// Lays out every run in file order, paint order continuing from run to run so that later runs
// are in front at equal depth. A run's font comes first in its chain, the scene's others follow
// in order as fallbacks.
void lay_out(const Arguments& args, Job& job) {
    crisp::Layouter layouter;
    crisp::TextLayout text;
    uint32_t paint_order = 0;
    // The chain of each font: it first, the scene's others in order as fallbacks.
    std::vector<std::vector<const crisp::Font*>> chains(job.fonts.size());
    for (size_t first = 0; first < job.fonts.size(); ++first) {
        chains[first].push_back(&job.fonts[first]);
        for (size_t f = 0; f < job.fonts.size(); ++f) {
            if (f != first) chains[first].push_back(&job.fonts[f]);
        }
    }
    std::vector<crisp::TextSpan> spans;
    std::vector<std::vector<crisp::FontFeature>> features;  // the run's, then each span's
    for (size_t i = 0; i < job.scene.runs.size(); ++i) {
        const crisp::SceneRun& run = job.scene.runs[i];
        features.assign(run.spans.size() + 1, {});
        // A scene style as the layout's (sRGB colours: the layouter linearizes them).
        const auto style_of = [&](uint32_t font, float size, const float(&color)[4], uint32_t palette,
                                  const crisp::SceneTextStyle& scene_style, std::vector<crisp::FontFeature>& own) {
            crisp::TextStyle style;
            style.size = size;
            std::copy(std::begin(color), std::end(color), style.color);
            style.depth = run.depth;
            style.palette = palette;
            if (font != run.font) style.fonts = chains[font];
            for (const crisp::SceneFeature& feature : scene_style.features) {
                crisp::FontFeature out;
                std::copy(feature.tag.begin(), feature.tag.end(), out.tag);
                out.value = feature.value;
                own.push_back(out);
            }
            style.features = own;
            style.letter_spacing = scene_style.letter_spacing;
            style.baseline_shift = scene_style.baseline_shift;
            style.underline = scene_style.underline;
            style.strikethrough = scene_style.strikethrough;
            style.skip_ink = scene_style.skip_ink;
            return style;
        };
        const crisp::TextStyle style = style_of(run.font, run.size, run.color, run.palette, run.style, features[0]);
        spans.clear();
        for (size_t k = 0; k < run.spans.size(); ++k) {
            const crisp::SceneSpan& span = run.spans[k];
            spans.push_back({span.begin, span.end,
                             style_of(span.font, span.size, span.color, span.palette, span.style, features[k + 1])});
        }
        crisp::LayoutOptions options;
        options.colour_glyphs = !args.no_colour;
        options.origin_x = run.origin_x;
        options.origin_y = run.origin_y;
        options.first_paint_order = paint_order;
        options.wrap_width = run.wrap_width;
        options.align = run.align;
        options.line_height = run.line_height;
        options.line_spacing = run.line_spacing;
        options.max_lines = run.max_lines;
        options.trimming = run.trimming;
        options.scale = run.scale;
        options.tab_stops = run.tab_stops;
        if (crisp::Status status = layouter.layout(chains[run.font], run.text, style, spans, options, text); !status) {
            const bool input = status.error().code == crisp::ErrorCode::invalid_argument;
            if (args.scene.empty()) {
                fail(input ? kExitUsage : kExitInternal, "cannot lay out the text: " + status.error().message);
            }
            fail(input ? kExitScene : kExitInternal,
                 args.scene + ": runs[" + std::to_string(i) + "]: cannot lay out the text: " + status.error().message);
        }
        paint_order = text.next_paint_order;
        job.laid_out += text.glyphs.size();
        if (job.laid_out > kMaxGlyphs) {
            fail(args.scene.empty() ? kExitUsage : kExitScene,
                 (args.scene.empty() ? std::string("the text") : args.scene) + " lays out more than " +
                     std::to_string(kMaxGlyphs) + " glyphs, crisp-render's limit (docs/limits.md)");
        }
        job.missing += text.missing_glyphs;
        job.blank += text.blank_glyphs;
        job.out_of_range += text.out_of_range_glyphs;
        job.colour_glyphs += text.colour_glyphs;
        job.colour_layers += text.colour_layers;
        // A transformed run is a draw of its own, about its origin; the renderer culls its glyphs
        // where they land.
        std::optional<crisp::TextTransform> transform;
        if (run.transform) {
            const auto& m = *run.transform;
            transform = crisp::TextTransform{m[0], m[1], m[2], m[3], run.origin_x, run.origin_y};
        }
        if (job.draws.empty() || job.draws.back().contrast != run.contrast || transform || job.draws.back().transform ||
            run.effects != job.draws.back().effects) {
            job.draws.push_back({job.glyphs.size(), 0, run.contrast, transform, run.effects});
        }
        for (const crisp::TextDecoration& decoration : text.decorations)
            job.decorations.push_back({decoration, transform});
        const size_t before = job.glyphs.size();
        for (const crisp::GlyphInstance& glyph : text.glyphs) {
            if (transform ? glyph.width > 0 : touches_canvas(glyph, job.scene.width, job.scene.height))
                job.glyphs.push_back(glyph);
        }
        job.draws.back().count += job.glyphs.size() - before;
    }
}

// The scene (from --scene, or the one run the command line describes), its subpixel layout and
// fonts, and its runs laid out; exits on a failure. A scene's fonts and layout file join the
// inputs no output may be, before any of them is read (`-o a.crisp` used to replace a scene's asset).
Job load_job(const Arguments& args, crisp::OutputFiles& outputs) {
    Job job;
    if (args.scene.empty()) {
        job.scene = scene_from_arguments(args);
    } else {
        crisp::Result<crisp::Scene> scene = crisp::load_scene_file(args.scene);
        if (!scene) fail(kExitScene, scene.error().message);
        job.scene = std::move(*scene);
        std::vector<std::string> inputs = job.scene.fonts;
        if (!crisp::subpixel_preset(job.scene.layout)) inputs.push_back(job.scene.layout);
        for (const std::string& input : inputs) {
            if (const crisp::Status checked = outputs.add_input(input); !checked)
                fail(kExitOutput, checked.error().message);
        }
    }

    crisp::Result<crisp::SubpixelLayout> subpixel_layout = crisp::resolve_subpixel_layout(job.scene.layout);
    if (!subpixel_layout) {
        fail(kExitLayout, (args.scene.empty() ? "--layout " : crisp::cli::printable_path(args.scene) + ": layout ") +
                              crisp::cli::printable_path(job.scene.layout) + ": " + subpixel_layout.error().message);
    }
    job.subpixel_layout = std::move(*subpixel_layout);
    job.contrast = !args.contrast_given && job.subpixel_layout.contrast ? *job.subpixel_layout.contrast : args.contrast;

    job.fonts.reserve(job.scene.fonts.size());
    for (size_t i = 0; i < job.scene.fonts.size(); ++i) {
        const std::string& path = job.scene.fonts[i];
        crisp::Result<crisp::FontAsset> asset = crisp::load_asset_file(path);
        if (!asset) fail(kExitFont, crisp::cli::printable_path(path) + ": " + asset.error().message);
        crisp::Result<crisp::Font> font = crisp::Font::create(std::move(*asset), static_cast<crisp::FontId>(i + 1));
        if (!font) fail(kExitFont, crisp::cli::printable_path(path) + ": " + font.error().message);
        job.fonts.push_back(std::move(*font));
    }
    lay_out(args, job);
    return job;
}

// Encodes the PNG (and the PFM), then puts both in place together: a failure replaces neither.
// Errors return (the context is destroyed on the way out), never exit with live Vulkan objects.
int write_outputs(const crisp::OutputFiles& outputs, const Arguments& args, const Job& job, RenderReport& report) {
    auto write_failed = [](const crisp::Error& error) {
        std::fprintf(stderr, "crisp-render: %s\n", error.message.c_str());
        return error.code == crisp::ErrorCode::io ? kExitOutput : kExitInternal;
    };
    const std::vector<std::byte> png = std::move(report.composite.png);
    std::vector<crisp::OutputWriter> writers = {
        [&png](const std::function<crisp::Status(std::span<const std::byte>)>& put) { return put(png); }};
    if (!args.coverage_output.empty()) writers.push_back(coverage_writer(args, job, report));
    if (crisp::Status status = outputs.write_streamed(writers); !status) return write_failed(status.error());
    return kExitOk;
}

// The compositor's notes and what the image lacks, on stderr; the exit code of glyphs not drawn
// or of validation messages.
int report_problems(const Arguments& args, const RenderReport& report, const crisp::ValidationMessages& validation) {
    if (!args.quiet && !report.stopped.empty()) {
        std::fprintf(stderr, "crisp-render: warning: stopped after %llu frame%s / %.1f s: %u of %u glyphs converged",
                     static_cast<unsigned long long>(report.frames), report.frames == 1 ? "" : "s",
                     report.stopped_ms / 1000.0, converged_glyphs(report), report.atlas.pinned_glyphs);
        if (const uint32_t waiting = glyphs_without_samples(report); waiting > 0) {
            std::fprintf(stderr, ", %u not drawn (no sample yet)", waiting);
        }
        std::fprintf(stderr, "; --%s to change\n", report.stopped.c_str());
    }
    const CompositeReport& composite = report.composite;
    if (!args.quiet && !args.json) {
        for (const std::string& warning : composite.warnings) {
            std::fprintf(stderr, "crisp-render: compositor: %s\n", warning.c_str());
        }
    }
    const crisp::CompositorStats& stats = composite.stats;
    if (!args.quiet && is_exact(composite) && stats.measured &&
        (stats.exact_lost_nodes > 0 || stats.exact_dropped > 0)) {
        std::fprintf(stderr,
                     "crisp-render: warning: the exact compositor lost %llu fragments (its node pool was full) and "
                     "dropped %llu (past %u per pixel); the image lacks them\n",
                     static_cast<unsigned long long>(stats.exact_lost_nodes),
                     static_cast<unsigned long long>(stats.exact_dropped), crisp::kMaxExactFragmentsPerPixel);
    }

    int code = kExitOk;
    if (report.last_frame.failed_glyphs > 0 || report.last_frame.unknown_fonts > 0) {
        std::fprintf(stderr,
                     "crisp-render: %u glyphs could not be drawn (atlas full or glyph too large), %u had no font; "
                     "the image lacks them\n",
                     report.last_frame.failed_glyphs, report.last_frame.unknown_fonts);
        code = kExitInternal;
    }
    if (validation.warnings + validation.errors > 0) {
        std::fprintf(stderr, "crisp-render: the validation layer reported %u errors and %u warnings:\n",
                     validation.errors, validation.warnings);
        for (const std::string& message : validation.recent) std::fprintf(stderr, "  %s\n", message.c_str());
        code = kExitVulkan;
    }
    return code;
}

int run(const Arguments& args) {
    const auto start = std::chrono::steady_clock::now();
    crisp::OutputFiles outputs = declare_outputs(args);
    const Job job = load_job(args, outputs);

    RenderReport report;
    crisp::HeadlessContextOptions options;
    options.validation = args.validate;
    options.device_name_contains = args.device;
    crisp::Result<crisp::HeadlessContext> context =
        crisp::tools::create_context(options, report.composite.storage_without_format);
    if (!context) fail(exit_code_for_vulkan(context.error()), "Vulkan: " + context.error().message);

    if (const int code = render(*context, args, job, RunClock{start, args.max_seconds}, report); code != kExitOk)
        return code;
    // The renderer and compositor are gone: every message the validation layer had for them has arrived.
    Summary summary;
    summary.validation = context->validation_messages();

    const auto write_start = std::chrono::steady_clock::now();
    if (const int code = write_outputs(outputs, args, job, report); code != kExitOk) return code;
    summary.write_ms = milliseconds_since(write_start);
    summary.total_ms = milliseconds_since(start);

    summary.args = &args;
    summary.context = &*context;
    summary.job = &job;
    summary.render = &report;
    summary.culled_glyphs = static_cast<uint32_t>(job.laid_out - job.glyphs.size());
    if (args.json) {
        print_json(summary);
    } else if (!args.quiet) {
        print_human(summary);
    }
    return report_problems(args, report, summary.validation);
}

}  // namespace

int main(int argc, char** argv) {
    const Arguments args = parse_arguments(argc, argv);
    try {
        return run(args);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "crisp-render: out of memory\n");
        return kExitInternal;
    }
}
