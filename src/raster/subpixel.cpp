#include "core/file_io.hpp"
#include "core/limits.hpp"
#include "core/json.hpp"
#include "core/utf8.hpp"

#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <charconv>
#include <cmath>

namespace crisp {

namespace {

constexpr float kThird = 1.0f / 3.0f;
constexpr float kTwoThirds = 2.0f / 3.0f;
constexpr const char* kChannelNames[3] = {"r", "g", "b"};

constexpr std::string_view kPresetNames[] = {"gray", "rgb", "bgr", "vrgb", "vbgr", "qd-oled", "woled", "pentile"};

constexpr const char* kContrastNames[2] = {"linear", "corrected"};  // by ContrastMode

SubpixelLayout make(std::string_view name, SampleRect r, SampleRect g, SampleRect b) {
    SubpixelLayout layout;
    layout.name = std::string(name);
    layout.channels = {r, g, b};
    return layout;
}

// Past this magnitude a layout's number means nothing (its rectangles lie within [-1, 2], its
// contrast settings within a few units): refused as out of range before it becomes a float.
constexpr double kMaxNumber = 1e6;

std::string out_of_range(double value) {
    std::string text = "expected a number, at most 1e6 in magnitude: ";
    json::append_number(text, value);
    return text + " is out of range";
}

Error bad_contrast(const std::string& what) {
    return Error{ErrorCode::invalid_argument, "subpixel layout: contrast" + what};
}

// The "contrast" member: every member optional, the others TextContrast's defaults. Ranges are
// validate_subpixel_layout's to check.
Result<TextContrast> parse_contrast(const json::Value& value) {
    if (value.type != json::Value::Type::object) return bad_contrast(": expected an object");
    TextContrast contrast;
    for (const auto& [key, member] : value.object) {
        if (key == "mode") {
            if (member.type == json::Value::Type::string && member.string == kContrastNames[0]) {
                contrast.mode = ContrastMode::linear;
            } else if (member.type == json::Value::Type::string && member.string == kContrastNames[1]) {
                contrast.mode = ContrastMode::corrected;
            } else {
                return bad_contrast(".mode: expected \"linear\" or \"corrected\"");
            }
            continue;
        }
        float* field = key == "gamma"            ? &contrast.gamma
                       : key == "contrast"       ? &contrast.contrast
                       : key == "stem_darkening" ? &contrast.stem_darkening
                                                 : nullptr;
        if (!field) {
            return bad_contrast(": unknown member \"" + printable(key) +
                                "\" (expected mode, gamma, contrast, stem_darkening)");
        }
        if (member.type != json::Value::Type::number) return bad_contrast("." + key + ": expected a number");
        if (std::fabs(member.number) > kMaxNumber) return bad_contrast("." + key + ": " + out_of_range(member.number));
        *field = static_cast<float>(member.number);
    }
    return contrast;
}

// A float in its shortest form that reads back to the same float: 2.2, not 2.2000000476837158.
void append_float(std::string& out, float value) {
    char buffer[32];
    const auto written = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, written.ptr);
}

}  // namespace

std::span<const std::string_view> subpixel_preset_names() {
    return kPresetNames;
}

Result<SubpixelLayout> subpixel_preset(std::string_view name) {
    const SampleRect full{0, 0, 1, 1};
    const SampleRect left{0, 0, kThird, 1}, middle{kThird, 0, kTwoThirds, 1}, right{kTwoThirds, 0, 1, 1};
    const SampleRect top{0, 0, 1, kThird}, centre{0, kThird, 1, kTwoThirds}, bottom{0, kTwoThirds, 1, 1};
    if (name == "gray") return make(name, full, full, full);
    if (name == "rgb") return make(name, left, middle, right);
    if (name == "bgr") return make(name, right, middle, left);
    if (name == "vrgb") return make(name, top, centre, bottom);
    if (name == "vbgr") return make(name, bottom, centre, top);
    // Samsung's QD-OLED triad: green above, red below left, blue below right.
    if (name == "qd-oled") return make(name, {0, 0.5f, 0.5f, 1}, {0.25f, 0, 0.75f, 0.5f}, {0.5f, 0.5f, 1, 1});
    // LG's WOLED stripes red, white, blue, green; the white subpixel is not driven.
    if (name == "woled") return make(name, {0, 0, 0.25f, 1}, {0.75f, 0, 1, 1}, {0.5f, 0, 0.75f, 1});
    // RGBG PenTile averaged over a pixel pair: red and blue share the left column, green the right.
    if (name == "pentile") return make(name, {0, 0, 0.5f, 0.5f}, {0.5f, 0, 1, 1}, {0, 0.5f, 0.5f, 1});
    std::string known;
    for (const std::string_view preset : kPresetNames) known += (known.empty() ? "" : ", ") + std::string(preset);
    return Error{ErrorCode::invalid_argument,
                 "unknown subpixel layout '" + printable(name) + "' (presets: " + known + "; or give a layout file)"};
}

Status validate_subpixel_layout(const SubpixelLayout& layout) {
    constexpr auto kLow = static_cast<float>(-kGlyphPadding);
    constexpr auto kHigh = static_cast<float>(1 + kGlyphPadding);
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        const std::string what = std::string("subpixel layout: channel ") + kChannelNames[c];
        if (!std::isfinite(r.x0) || !std::isfinite(r.y0) || !std::isfinite(r.x1) || !std::isfinite(r.y1)) {
            return Error{ErrorCode::invalid_argument, what + ": coordinates must be finite"};
        }
        if (!(r.x0 < r.x1) || !(r.y0 < r.y1)) {
            return Error{ErrorCode::invalid_argument, what + ": needs x0 < x1 and y0 < y1"};
        }
        if (r.x0 < kLow || r.y0 < kLow || r.x1 > kHigh || r.y1 > kHigh) {
            return Error{ErrorCode::invalid_argument, what + ": reaches more than " + std::to_string(kGlyphPadding) +
                                                          " pixel past its pixel (rectangles must lie within [-1, 2])"};
        }
    }
    if (layout.contrast) {
        if (Status status = validate_text_contrast(*layout.contrast); !status) {
            return Error{ErrorCode::invalid_argument, "subpixel layout: " + status.error().message};
        }
    }
    return {};
}

Result<SubpixelLayout> parse_subpixel_layout(std::string_view text) {
    auto document = json::parse(text);
    if (!document) return Error{ErrorCode::invalid_argument, "subpixel layout: " + document.error().message};
    const json::Value& root = *document;
    if (root.type != json::Value::Type::object) {
        return Error{ErrorCode::invalid_argument,
                     "subpixel layout: expected an object, got " + std::string(root.type_name())};
    }
    SubpixelLayout layout;
    for (const auto& [key, value] : root.object) {
        if (key == "name") {
            if (value.type != json::Value::Type::string) {
                return Error{ErrorCode::invalid_argument, "subpixel layout: name: expected a string"};
            }
            layout.name = value.string;
            continue;
        }
        if (key == "contrast") {
            Result<TextContrast> contrast = parse_contrast(value);
            if (!contrast) return contrast.error();
            layout.contrast = *contrast;
            continue;
        }
        size_t channel = 3;
        for (size_t c = 0; c < 3; ++c) {
            if (key == kChannelNames[c]) channel = c;
        }
        if (channel == 3) {
            return Error{ErrorCode::invalid_argument, "subpixel layout: unknown member \"" + printable(key) +
                                                          "\" (expected name, r, g, b, contrast)"};
        }
        if (value.type != json::Value::Type::array || value.array.size() != 4) {
            return Error{ErrorCode::invalid_argument,
                         "subpixel layout: " + key + ": expected [x0, y0, x1, y1] in pixels"};
        }
        float coordinates[4];
        for (size_t i = 0; i < 4; ++i) {
            const json::Value& number = value.array[i];
            const std::string where = "subpixel layout: " + key + "[" + std::to_string(i) + "]: ";
            if (number.type != json::Value::Type::number) {
                return Error{ErrorCode::invalid_argument, where + "expected a number"};
            }
            if (std::fabs(number.number) > kMaxNumber) {
                return Error{ErrorCode::invalid_argument, where + out_of_range(number.number)};
            }
            coordinates[i] = static_cast<float>(number.number);
        }
        layout.channels[channel] = {coordinates[0], coordinates[1], coordinates[2], coordinates[3]};
    }
    for (size_t c = 0; c < 3; ++c) {
        if (!root.find(kChannelNames[c])) {
            return Error{ErrorCode::invalid_argument,
                         std::string("subpixel layout: the \"") + kChannelNames[c] + "\" rectangle is missing"};
        }
    }
    if (Status status = validate_subpixel_layout(layout); !status) return status.error();
    return layout;
}

Result<SubpixelLayout> load_subpixel_layout_file(const std::filesystem::path& path) {
    auto bytes = read_file(path, limits::kLayoutFileBytes);
    if (!bytes) return bytes.error();
    const std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
    auto layout = parse_subpixel_layout(text);
    if (!layout)
        return Error{layout.error().code, printable(path.string(), kPrintablePath) + ": " + layout.error().message};
    return layout;
}

std::string subpixel_layout_to_json(const SubpixelLayout& layout) {
    std::string out = "{\"name\": ";
    json::append_string(out, layout.name);
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        out += std::string(", \"") + kChannelNames[c] + "\": [";
        const float values[4] = {r.x0, r.y0, r.x1, r.y1};
        for (size_t i = 0; i < 4; ++i) {
            if (i) out += ", ";
            json::append_number(out, static_cast<double>(values[i]));
        }
        out += "]";
    }
    if (const std::optional<TextContrast>& contrast = layout.contrast) {
        out += ", \"contrast\": {\"mode\": ";
        json::append_string(out, contrast->mode == ContrastMode::linear ? kContrastNames[0] : kContrastNames[1]);
        out += ", \"gamma\": ";
        append_float(out, contrast->gamma);
        out += ", \"contrast\": ";
        append_float(out, contrast->contrast);
        out += ", \"stem_darkening\": ";
        append_float(out, contrast->stem_darkening);
        out += "}";
    }
    return out + "}\n";
}

Status save_subpixel_layout_file(const SubpixelLayout& layout, const std::filesystem::path& path) {
    if (Status status = validate_subpixel_layout(layout); !status) return status;
    const std::string text = subpixel_layout_to_json(layout);
    return write_file_atomically(path, std::as_bytes(std::span(text.data(), text.size())));
}

Result<SubpixelLayout> resolve_subpixel_layout(std::string_view name_or_path) {
    for (const std::string_view preset : kPresetNames) {
        if (preset == name_or_path) return subpixel_preset(preset);
    }
    if (name_or_path.find('/') != std::string_view::npos || name_or_path.ends_with(".json")) {
        return load_subpixel_layout_file(std::filesystem::path(name_or_path));
    }
    return subpixel_preset(name_or_path);
}

bool shares_sample_rows(const SubpixelLayout& layout) {
    const SampleRect& r = layout.channels[0];
    for (const SampleRect& other : layout.channels) {
        if (other.y0 != r.y0 || other.y1 != r.y1) return false;
    }
    return true;
}

}  // namespace crisp
