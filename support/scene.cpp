#include "scene.hpp"

#include "core/file_io.hpp"
#include "core/limits.hpp"
#include "core/json.hpp"
#include "core/utf8.hpp"

#include <crisp/asset.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <optional>

namespace crisp {

namespace {

using Type = json::Value::Type;

constexpr std::string_view kSceneMembers[] = {"fonts", "canvas", "background", "layout", "contrast", "palette", "runs"};
constexpr std::string_view kRunMembers[] = {
    "font",           "text",           "size",         "origin",        "color",    "depth", "contrast",
    "palette",        "transform",      "weight",       "outline",       "shadow",   "glow",  "features",
    "letter_spacing", "baseline_shift", "underline",    "strikethrough", "skip_ink", "spans", "wrap_width",
    "align",          "line_height",    "line_spacing", "max_lines",     "trimming", "scale", "tab_stops"};
constexpr std::string_view kSpanMembers[] = {"begin",          "end",       "font",          "size",
                                             "color",          "palette",   "features",      "letter_spacing",
                                             "baseline_shift", "underline", "strikethrough", "skip_ink"};
constexpr std::string_view kOutlineMembers[] = {"width", "placement", "join", "miter_limit", "color"};
constexpr std::string_view kShadowMembers[] = {"offset", "color", "blur"};
constexpr std::string_view kGlowMembers[] = {"radius", "color"};
constexpr std::string_view kContrastMembers[] = {"mode", "gamma", "contrast", "stem_darkening"};

Error fault(const std::string& path, const std::string& what) {
    return Error{ErrorCode::invalid_argument, "scene: " + path + ": " + what};
}

std::string element(const std::string& path, size_t index) {
    return path + "[" + std::to_string(index) + "]";
}

// The first member of `object` whose name is not in `known`, as an error naming the known ones.
template <size_t N>
std::optional<Error> unknown_member(const json::Value& object, const std::string& path,
                                    const std::string_view (&known)[N]) {
    for (const json::Member& member : object.object) {
        bool found = false;
        for (const std::string_view name : known) found = found || member.name == name;
        if (found) continue;
        std::string list;
        for (const std::string_view name : known) list += (list.empty() ? "" : ", ") + std::string(name);
        std::string what = "unknown member \"" + printable(member.name) + "\" (known: " + list + ")";
        if (path.empty()) return Error{ErrorCode::invalid_argument, "scene: " + what};
        return fault(path, what);
    }
    return std::nullopt;
}

// A path or preset name the operating system can take: non-empty, no NUL (which would cut it).
bool is_usable_name(const json::Value& value) {
    return value.type == Type::string && !value.string.empty() && value.string.find('\0') == std::string::npos;
}

std::optional<Error> read_fonts(const json::Value& value, Scene& scene) {
    if (value.type != Type::array || value.array.empty()) {
        return fault("fonts", "expected a non-empty array of font asset paths");
    }
    if (value.array.size() > kMaxSceneFonts) {
        return fault("fonts",
                     "at most " + std::to_string(kMaxSceneFonts) + " fonts, got " + std::to_string(value.array.size()));
    }
    for (size_t i = 0; i < value.array.size(); ++i) {
        if (!is_usable_name(value.array[i])) {
            return fault(element("fonts", i), "expected a non-empty path string without U+0000");
        }
        scene.fonts.push_back(value.array[i].string);
    }
    return std::nullopt;
}

std::optional<Error> read_canvas(const json::Value& value, Scene& scene) {
    const auto side = [](const json::Value& number) {
        return number.type == Type::number && number.number >= 1.0 &&
               number.number <= static_cast<double>(kMaxSceneCanvas) && number.number == std::floor(number.number);
    };
    if (value.type != Type::array || value.array.size() != 2 || !side(value.array[0]) || !side(value.array[1])) {
        return fault("canvas", "expected [width, height] integers from 1 to " + std::to_string(kMaxSceneCanvas));
    }
    scene.width = static_cast<uint32_t>(value.array[0].number);
    scene.height = static_cast<uint32_t>(value.array[1].number);
    return std::nullopt;
}

// [r, g, b] or [r, g, b, a], each in [0, 1]; a missing alpha is 1.
std::optional<Error> read_color(const json::Value& value, const std::string& path, float (&color)[4]) {
    if (value.type != Type::array || (value.array.size() != 3 && value.array.size() != 4)) {
        return fault(path, "expected [r, g, b] or [r, g, b, a], sRGB numbers from 0 to 1");
    }
    for (size_t i = 0; i < value.array.size(); ++i) {
        const json::Value& component = value.array[i];
        if (component.type != Type::number || !(component.number >= 0.0 && component.number <= 1.0)) {
            return fault(element(path, i), "expected a number from 0 to 1");
        }
        color[i] = static_cast<float>(component.number);
    }
    if (value.array.size() == 3) color[3] = 1.0f;
    return std::nullopt;
}

// A CPAL palette index, an integer below kMaxPalettes (a font without that palette draws its 0).
std::optional<Error> read_palette(const json::Value& value, const std::string& path, uint32_t& palette) {
    if (value.type != Type::number || !(value.number >= 0.0 && value.number < static_cast<double>(kMaxPalettes)) ||
        value.number != std::floor(value.number)) {
        return fault(path, "expected a palette index, an integer from 0 to " + std::to_string(kMaxPalettes - 1));
    }
    palette = static_cast<uint32_t>(value.number);
    return std::nullopt;
}

// A "contrast" object over `contrast`: the members it gives replace those fields. The ranges are
// validate_text_contrast()'s, checked here to name the member's path.
std::optional<Error> read_contrast(const json::Value& value, const std::string& path, TextContrast& contrast) {
    if (value.type != Type::object) return fault(path, "expected an object, got " + std::string(value.type_name()));
    if (auto error = unknown_member(value, path, kContrastMembers)) return error;
    if (const json::Value* mode = value.find("mode")) {
        if (mode->type == Type::string && mode->string == "linear") {
            contrast.mode = ContrastMode::linear;
        } else if (mode->type == Type::string && mode->string == "corrected") {
            contrast.mode = ContrastMode::corrected;
        } else {
            const std::string got =
                mode->type == Type::string ? "\"" + printable(mode->string) + "\"" : mode->type_name();
            return fault(path + ".mode", "expected \"linear\" or \"corrected\", got " + got);
        }
    }
    const auto number = [&](const char* name, double low, double high, float& field) -> std::optional<Error> {
        const json::Value* member = value.find(name);
        if (!member) return std::nullopt;
        std::string range;
        json::append_number(range, low);
        range += ", ";
        json::append_number(range, high);
        if (member->type != Type::number) {
            return fault(path + "." + name,
                         "expected a number in [" + range + "], got " + std::string(member->type_name()));
        }
        if (!(member->number >= low && member->number <= high)) {
            std::string written;
            json::append_number(written, member->number);
            return fault(path + "." + name, written + " is not in [" + range + "]");
        }
        field = static_cast<float>(member->number);
        return std::nullopt;
    };
    if (auto error = number("gamma", 1.0, 4.0, contrast.gamma)) return error;
    if (auto error = number("contrast", 0.0, 4.0, contrast.contrast)) return error;
    if (auto error = number("stem_darkening", 0.0, 4.0, contrast.stem_darkening)) return error;
    return std::nullopt;
}

// A run's "weight", "outline", "shadow" and "glow" (include/crisp/effects.hpp) into `effects`; nullopt
// effects where it has none of them. Ranges as validate_text_effects() at the run's size.
std::optional<Error> read_effects(const json::Value& value, const std::string& path, float size,
                                  std::optional<TextEffects>& out) {
    const json::Value* weight = value.find("weight");
    const json::Value* outline = value.find("outline");
    const json::Value* shadow = value.find("shadow");
    const json::Value* glow = value.find("glow");
    if (!weight && !outline && !shadow && !glow) return std::nullopt;
    TextEffects effects;
    const auto finite = [](const json::Value& v) {
        return v.type == Type::number && std::fabs(v.number) <= static_cast<double>(kMaxEffectWidth);
    };
    if (weight) {
        if (!finite(*weight)) return fault(path + ".weight", "expected a number of pixels in [-4096, 4096]");
        effects.weight = static_cast<float>(weight->number);
    }
    if (outline) {
        const std::string at = path + ".outline";
        if (outline->type != Type::object) return fault(at, "expected an object");
        if (auto error = unknown_member(*outline, at, kOutlineMembers)) return error;
        TextOutline o;
        const json::Value* width = outline->find("width");
        if (!width) return fault(at, "the \"width\" member is missing");
        if (!finite(*width) || width->number < 0.0) return fault(at + ".width", "expected pixels in [0, 4096]");
        o.width = static_cast<float>(width->number);
        const auto named = [&](const char* member, auto parse, auto& field,
                               const char* expected) -> std::optional<Error> {
            const json::Value* v = outline->find(member);
            if (!v) return std::nullopt;
            const auto parsed = parse(v->type == Type::string ? std::string_view(v->string) : std::string_view());
            if (!parsed) return fault(at + "." + member, std::string("expected ") + expected);
            field = *parsed;
            return std::nullopt;
        };
        if (auto error =
                named("placement", parse_outline_placement, o.placement, "\"outside\", \"inside\" or \"centred\"")) {
            return error;
        }
        if (auto error = named("join", parse_line_join, o.join, "\"round\", \"miter\" or \"bevel\"")) return error;
        if (const json::Value* limit = outline->find("miter_limit")) {
            if (limit->type != Type::number ||
                !(limit->number >= 1.0 && limit->number <= static_cast<double>(kMaxMiterLimit))) {
                return fault(at + ".miter_limit", "expected a number in [1, 128]");
            }
            o.miter_limit = static_cast<float>(limit->number);
        }
        if (const json::Value* color = outline->find("color")) {
            float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            if (auto error = read_color(*color, at + ".color", c)) return error;
            std::copy(std::begin(c), std::end(c), o.color.begin());
        }
        effects.outline = o;
    }
    if (shadow) {
        const std::string at = path + ".shadow";
        if (shadow->type != Type::object) return fault(at, "expected an object");
        if (auto error = unknown_member(*shadow, at, kShadowMembers)) return error;
        TextShadow sh;
        if (const json::Value* offset = shadow->find("offset")) {
            const auto within = [](const json::Value& v) {
                return v.type == Type::number && std::fabs(v.number) <= static_cast<double>(kMaxShadowOffset);
            };
            if (offset->type != Type::array || offset->array.size() != 2 || !within(offset->array[0]) ||
                !within(offset->array[1])) {
                return fault(at + ".offset", "expected [dx, dy], pixels in [-4096, 4096]");
            }
            sh.offset_x = static_cast<float>(offset->array[0].number);
            sh.offset_y = static_cast<float>(offset->array[1].number);
        }
        if (const json::Value* color = shadow->find("color")) {
            float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            if (auto error = read_color(*color, at + ".color", c)) return error;
            std::copy(std::begin(c), std::end(c), sh.color.begin());
        }
        if (const json::Value* blur = shadow->find("blur")) {
            if (blur->type != Type::number ||
                !(blur->number >= 0.0 && blur->number <= static_cast<double>(kMaxEffectBlur))) {
                return fault(at + ".blur", "expected a radius of pixels in [0, 128]");
            }
            sh.blur = static_cast<float>(blur->number);
        }
        effects.shadow = sh;
    }
    if (glow) {
        const std::string at = path + ".glow";
        if (glow->type != Type::object) return fault(at, "expected an object");
        if (auto error = unknown_member(*glow, at, kGlowMembers)) return error;
        TextGlow g;
        if (const json::Value* radius = glow->find("radius")) {
            if (radius->type != Type::number ||
                !(radius->number > 0.0 && radius->number <= static_cast<double>(kMaxEffectBlur))) {
                return fault(at + ".radius", "expected a radius of pixels in (0, 128]");
            }
            g.radius = static_cast<float>(radius->number);
        }
        if (const json::Value* color = glow->find("color")) {
            float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            if (auto error = read_color(*color, at + ".color", c)) return error;
            std::copy(std::begin(c), std::end(c), g.color.begin());
        }
        effects.glow = g;
    }
    if (Status valid = validate_text_effects(effects, size); !valid) {
        const std::string& message = valid.error().message;
        return fault(path, message.substr(message.find(": ") + 2));
    }
    out = effects;
    return std::nullopt;
}

// A number member `name` of `object` in [low, high] into `field`; absent: `field` is kept.
std::optional<Error> read_number(const json::Value& object, const std::string& path, const char* name, double low,
                                 double high, float& field) {
    const json::Value* member = object.find(name);
    if (!member) return std::nullopt;
    std::string range;
    json::append_number(range, low);
    range += ", ";
    json::append_number(range, high);
    if (member->type != Type::number || !(member->number >= low && member->number <= high)) {
        std::string got = member->type_name();
        if (member->type == Type::number) {
            got.clear();
            json::append_number(got, member->number);
        }
        return fault(path + "." + name, "expected a number in [" + range + "], got " + got);
    }
    field = static_cast<float>(member->number);
    return std::nullopt;
}

std::optional<Error> read_flag(const json::Value& object, const std::string& path, const char* name, bool& field) {
    const json::Value* member = object.find(name);
    if (!member) return std::nullopt;
    if (member->type != Type::boolean) {
        return fault(path + "." + name, "expected true or false, got " + std::string(member->type_name()));
    }
    field = member->boolean;
    return std::nullopt;
}

// One of `names` (in enum order) into `field`.
template <typename Enum, size_t N>
std::optional<Error> read_choice(const json::Value& object, const std::string& path, const char* name,
                                 const std::string_view (&names)[N], Enum& field) {
    const json::Value* member = object.find(name);
    if (!member) return std::nullopt;
    for (size_t i = 0; i < N; ++i) {
        if (member->type == Type::string && member->string == names[i]) {
            field = static_cast<Enum>(i);
            return std::nullopt;
        }
    }
    std::string list;
    for (const std::string_view choice : names) list += (list.empty() ? "\"" : ", \"") + std::string(choice) + "\"";
    const std::string got =
        member->type == Type::string ? "\"" + printable(member->string) + "\"" : member->type_name();
    return fault(path + "." + name, "expected one of " + list + ", got " + got);
}

// "features": {"liga": 0, "kern": 1, ...}.
std::optional<Error> read_features(const json::Value& object, const std::string& path,
                                   std::vector<SceneFeature>& features) {
    const json::Value* member = object.find("features");
    if (!member) return std::nullopt;
    const std::string where = path + ".features";
    if (member->type != Type::object) {
        return fault(where,
                     "expected an object of OpenType feature tags and values, got " + std::string(member->type_name()));
    }
    features.clear();
    for (const json::Member& feature : member->object) {
        const std::string name = where + "." + printable(feature.name, 16);
        if (feature.name.empty() || feature.name.size() > 4 ||
            !std::all_of(feature.name.begin(), feature.name.end(), [](char c) { return c >= 0x21 && c <= 0x7E; })) {
            return fault(name, "a feature tag is 1 to 4 printable ASCII characters (\"liga\", \"ss01\")");
        }
        const json::Value& value = feature.value;
        if (value.type != Type::number || !(value.number >= 0.0 && value.number <= 65535.0) ||
            value.number != std::floor(value.number)) {
            return fault(name, "expected 0 (off), 1 (on) or an alternate's index, an integer up to 65535");
        }
        SceneFeature out;
        std::copy(feature.name.begin(), feature.name.end(), out.tag.begin());
        out.value = static_cast<uint32_t>(value.number);
        features.push_back(out);
    }
    return std::nullopt;
}

// A run's or span's style members over `style`, their ranges at `size` pixels per em.
std::optional<Error> read_text_style(const json::Value& object, const std::string& path, float size,
                                     SceneTextStyle& style) {
    if (auto error = read_features(object, path, style.features)) return error;
    const double em = static_cast<double>(size);
    if (auto error = read_number(object, path, "letter_spacing", -em, em, style.letter_spacing)) return error;
    if (auto error = read_number(object, path, "baseline_shift", -4.0 * em, 4.0 * em, style.baseline_shift))
        return error;
    if (auto error = read_flag(object, path, "underline", style.underline)) return error;
    if (auto error = read_flag(object, path, "strikethrough", style.strikethrough)) return error;
    return read_flag(object, path, "skip_ink", style.skip_ink);
}

std::optional<Error> read_font_index(const json::Value& font, const std::string& path, const Scene& scene,
                                     uint32_t& index) {
    if (font.type != Type::number || font.number < 0.0 || font.number != std::floor(font.number)) {
        return fault(path, "expected an index into fonts (an integer from 0)");
    }
    const size_t font_count = scene.fonts.size();
    if (font.number >= static_cast<double>(font_count)) {
        std::string written;
        json::append_number(written, font.number);
        return fault(path, "index " + written + " is out of range (the scene has " + std::to_string(font_count) +
                               (font_count == 1 ? " font)" : " fonts)"));
    }
    index = static_cast<uint32_t>(font.number);
    return std::nullopt;
}

// A run's "spans": byte ranges of its text, in order, not overlapping, on code point boundaries,
// each with the run's style where it says nothing.
std::optional<Error> read_spans(const json::Value& value, const std::string& path, const Scene& scene, SceneRun& run) {
    if (value.type != Type::array) {
        return fault(path, "expected an array of span objects, got " + std::string(value.type_name()));
    }
    if (value.array.size() > kMaxSceneSpans) {
        return fault(path,
                     "at most " + std::to_string(kMaxSceneSpans) + " spans, got " + std::to_string(value.array.size()));
    }
    uint32_t previous_end = 0;
    for (size_t i = 0; i < value.array.size(); ++i) {
        const json::Value& object = value.array[i];
        const std::string where = element(path, i);
        if (object.type != Type::object) {
            return fault(where, "expected an object, got " + std::string(object.type_name()));
        }
        if (auto error = unknown_member(object, where, kSpanMembers)) return error;
        SceneSpan span;
        const auto offset = [&](const char* name, uint32_t& field) -> std::optional<Error> {
            const json::Value* member = object.find(name);
            if (!member) return fault(where, std::string("the \"") + name + "\" member is missing");
            const double bytes = static_cast<double>(run.text.size());
            if (member->type != Type::number || !(member->number >= 0.0 && member->number <= bytes) ||
                member->number != std::floor(member->number)) {
                return fault(where + "." + name, "expected a byte offset into the run's text, an integer from 0 to " +
                                                     std::to_string(run.text.size()));
            }
            field = static_cast<uint32_t>(member->number);
            if (field < run.text.size() && (static_cast<unsigned char>(run.text[field]) & 0xC0u) == 0x80u) {
                return fault(where + "." + name,
                             "byte " + std::to_string(field) + " is inside a UTF-8 sequence of the run's text");
            }
            return std::nullopt;
        };
        if (auto error = offset("begin", span.begin)) return error;
        if (auto error = offset("end", span.end)) return error;
        if (span.end < span.begin) return fault(where, "ends before it begins");
        if (span.begin < previous_end) {
            return fault(where, "begins at byte " + std::to_string(span.begin) +
                                    ", inside the span before it (which "
                                    "ends at byte " +
                                    std::to_string(previous_end) +
                                    "): spans must be in order and must "
                                    "not overlap");
        }
        previous_end = span.end;
        span.font = run.font;
        if (const json::Value* font = object.find("font")) {
            if (auto error = read_font_index(*font, where + ".font", scene, span.font)) return error;
        }
        span.size = run.size;
        if (auto error = read_number(object, where, "size", 0.0, static_cast<double>(kMaxSceneTextSize), span.size))
            return error;
        if (!(span.size > 0.0f) ||
            static_cast<double>(span.size) * static_cast<double>(run.scale) > static_cast<double>(kMaxSceneTextSize))
            return fault(where + ".size", "must be in (0, 4096] pixels per em, times the run's scale");
        std::copy(std::begin(run.color), std::end(run.color), span.color);
        if (const json::Value* color = object.find("color")) {
            if (auto error = read_color(*color, where + ".color", span.color)) return error;
        }
        span.palette = run.palette;
        if (const json::Value* palette = object.find("palette")) {
            if (auto error = read_palette(*palette, where + ".palette", span.palette)) return error;
        }
        span.style = run.style;
        if (auto error = read_text_style(object, where, span.size, span.style)) return error;
        run.spans.push_back(std::move(span));
    }
    return std::nullopt;
}

// A run's paragraph members (crisp::LayoutOptions).
std::optional<Error> read_paragraph(const json::Value& value, const std::string& path, SceneRun& run) {
    if (auto error = read_number(value, path, "scale", 1.0 / 64.0, 64.0, run.scale)) return error;
    if (static_cast<double>(run.size) * static_cast<double>(run.scale) > static_cast<double>(kMaxSceneTextSize))
        return fault(path + ".scale", "the size times the scale must be at most 4096 pixels per em");
    if (auto error = read_number(value, path, "wrap_width", 0.0, 1e9, run.wrap_width)) return error;
    constexpr std::string_view kAligns[] = {"left", "center", "right", "start", "end"};
    if (auto error = read_choice(value, path, "align", kAligns, run.align)) return error;
    if (auto error = read_number(value, path, "line_height", 0.0, 65536.0, run.line_height)) return error;
    if (auto error = read_number(value, path, "line_spacing", 1.0 / 64.0, 16.0, run.line_spacing)) return error;
    float max_lines = 0.0f;
    if (auto error = read_number(value, path, "max_lines", 0.0, 1e6, max_lines)) return error;
    if (max_lines != std::floor(max_lines)) return fault(path + ".max_lines", "expected a whole number of lines");
    run.max_lines = static_cast<uint32_t>(max_lines);
    constexpr std::string_view kTrimmings[] = {"none", "end", "start", "middle"};
    if (auto error = read_choice(value, path, "trimming", kTrimmings, run.trimming)) return error;
    if (const json::Value* stops = value.find("tab_stops")) {
        if (stops->type != Type::array || stops->array.size() > 256) {
            return fault(path + ".tab_stops", "expected an array of at most 256 increasing positive numbers (pixels)");
        }
        for (size_t i = 0; i < stops->array.size(); ++i) {
            const json::Value& stop = stops->array[i];
            const double previous = run.tab_stops.empty() ? 0.0 : static_cast<double>(run.tab_stops.back());
            if (stop.type != Type::number || !(stop.number > previous && stop.number <= 1e9)) {
                return fault(element(path + ".tab_stops", i), "expected a number of pixels past the stop before it");
            }
            run.tab_stops.push_back(static_cast<float>(stop.number));
        }
    }
    return std::nullopt;
}

std::optional<Error> read_run(const json::Value& value, const std::string& path, const Scene& scene, SceneRun& run) {
    if (value.type != Type::object) return fault(path, "expected an object, got " + std::string(value.type_name()));
    if (auto error = unknown_member(value, path, kRunMembers)) return error;

    if (const json::Value* font = value.find("font")) {
        if (auto error = read_font_index(*font, path + ".font", scene, run.font)) return error;
    }

    const json::Value* text = value.find("text");
    if (!text) return fault(path, "the \"text\" member is missing");
    if (text->type != Type::string)
        return fault(path + ".text", "expected a string, got " + std::string(text->type_name()));
    run.text = text->string;

    const json::Value* size = value.find("size");
    if (!size) return fault(path, "the \"size\" member is missing");
    if (size->type != Type::number) return fault(path + ".size", "expected a number (pixels per em)");
    if (!(size->number > 0.0 && size->number <= static_cast<double>(kMaxSceneTextSize))) {
        return fault(path + ".size", "must be in (0, 4096]");
    }
    run.size = static_cast<float>(size->number);
    // A size below the smallest float rounds to 0, which the renderer cannot scale by.
    if (!(run.size > 0.0f)) return fault(path + ".size", "must be in (0, 4096]");

    const json::Value* origin = value.find("origin");
    if (!origin) return fault(path, "the \"origin\" member is missing");
    const auto coordinate = [](const json::Value& number) {
        return number.type == Type::number && std::fabs(number.number) <= static_cast<double>(FLT_MAX);
    };
    if (origin->type != Type::array || origin->array.size() != 2 || !coordinate(origin->array[0]) ||
        !coordinate(origin->array[1])) {
        return fault(path + ".origin", "expected [x, y], finite numbers (canvas pixels)");
    }
    run.origin_x = static_cast<float>(origin->array[0].number);
    run.origin_y = static_cast<float>(origin->array[1].number);

    if (const json::Value* color = value.find("color")) {
        if (auto error = read_color(*color, path + ".color", run.color)) return error;
    }

    if (const json::Value* depth = value.find("depth")) {
        if (depth->type != Type::number || !(depth->number >= 0.0 && depth->number <= 1.0)) {
            return fault(path + ".depth", "expected a number from 0 (nearest) to 1 (farthest)");
        }
        run.depth = static_cast<float>(depth->number);
    }

    run.contrast = scene.contrast;
    if (const json::Value* contrast = value.find("contrast")) {
        TextContrast own = scene.contrast.value_or(TextContrast{});
        if (auto error = read_contrast(*contrast, path + ".contrast", own)) return error;
        run.contrast = own;
    }

    run.palette = scene.palette;
    if (const json::Value* palette = value.find("palette")) {
        if (auto error = read_palette(*palette, path + ".palette", run.palette)) return error;
    }

    if (const json::Value* transform = value.find("transform")) {
        const auto entry = [](const json::Value& number) {
            return number.type == Type::number && std::fabs(number.number) <= 65536.0;
        };
        if (transform->type != Type::array || transform->array.size() != 4 ||
            !std::all_of(transform->array.begin(), transform->array.end(), entry)) {
            return fault(path + ".transform", "expected [a, b, c, d], numbers in [-65536, 65536]");
        }
        std::array<float, 4> m{};
        for (size_t i = 0; i < 4; ++i) m[i] = static_cast<float>(transform->array[i].number);
        TextTransform t{m[0], m[1], m[2], m[3], 0.0f, 0.0f};
        if (!valid_transform(t)) {
            return fault(path + ".transform", "is singular: |a d - b c| must be at least 2^-16");
        }
        run.transform = m;
    }
    if (auto error = read_effects(value, path, run.size, run.effects)) return error;
    if (auto error = read_text_style(value, path, run.size, run.style)) return error;
    if (auto error = read_paragraph(value, path, run)) return error;
    if (const json::Value* spans = value.find("spans")) return read_spans(*spans, path + ".spans", scene, run);
    return std::nullopt;
}

}  // namespace

Result<Scene> parse_scene(std::string_view json) {
    auto document = json::parse(json);
    if (!document) return Error{ErrorCode::invalid_argument, "scene: " + document.error().message};
    const json::Value& root = *document;
    if (root.type != Type::object) {
        return Error{ErrorCode::invalid_argument, "scene: expected an object, got " + std::string(root.type_name())};
    }
    if (auto error = unknown_member(root, "", kSceneMembers)) return *error;

    // Members are read in a fixed order, whatever the file's order, so a file with several faults
    // always reports the same one, and runs can check their font index against the font count.
    Scene scene;
    const json::Value* fonts = root.find("fonts");
    if (!fonts) return Error{ErrorCode::invalid_argument, "scene: the \"fonts\" member is missing"};
    if (auto error = read_fonts(*fonts, scene)) return *error;

    const json::Value* canvas = root.find("canvas");
    if (!canvas) return Error{ErrorCode::invalid_argument, "scene: the \"canvas\" member is missing"};
    if (auto error = read_canvas(*canvas, scene)) return *error;

    if (const json::Value* background = root.find("background")) {
        if (auto error = read_color(*background, "background", scene.background)) return *error;
    }

    if (const json::Value* layout = root.find("layout")) {
        if (!is_usable_name(*layout)) {
            return fault("layout", "expected a subpixel preset name or a layout file path (a non-empty string)");
        }
        scene.layout = layout->string;
    }

    if (const json::Value* contrast = root.find("contrast")) {
        TextContrast defaults;
        if (auto error = read_contrast(*contrast, "contrast", defaults)) return *error;
        scene.contrast = defaults;
    }

    if (const json::Value* palette = root.find("palette")) {
        if (auto error = read_palette(*palette, "palette", scene.palette)) return *error;
    }

    const json::Value* runs = root.find("runs");
    if (!runs) return Error{ErrorCode::invalid_argument, "scene: the \"runs\" member is missing"};
    if (runs->type != Type::array) {
        return fault("runs", "expected an array of run objects, got " + std::string(runs->type_name()));
    }
    if (runs->array.size() > kMaxSceneRuns) {
        return fault("runs", "at most " + std::to_string(kMaxSceneRuns) + " runs (docs/limits.md), got " +
                                 std::to_string(runs->array.size()));
    }
    scene.runs.resize(runs->array.size());
    for (size_t i = 0; i < runs->array.size(); ++i) {
        if (auto error = read_run(runs->array[i], element("runs", i), scene, scene.runs[i])) {
            return *error;
        }
    }
    return scene;
}

Result<Scene> load_scene_file(const std::filesystem::path& path) {
    auto bytes = read_file(path, limits::kSceneFileBytes);
    if (!bytes) return bytes.error();
    const std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
    auto scene = parse_scene(text);
    if (!scene)
        return Error{scene.error().code, printable(path.string(), kPrintablePath) + ": " + scene.error().message};
    // Fonts sit beside the scene, wherever it is run from; an empty parent is the working directory.
    const std::filesystem::path directory = path.parent_path();
    for (std::string& font : scene->fonts) {
        const std::filesystem::path font_path(font);
        if (font_path.is_relative() && !directory.empty()) font = (directory / font_path).string();
    }
    return scene;
}

}  // namespace crisp
