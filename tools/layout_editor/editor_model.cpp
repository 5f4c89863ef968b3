#include "editor_model.hpp"

#include "cli.hpp"
#include "core/file_io.hpp"
#include "json_writer.hpp"

#include <crisp/glyph.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>

namespace crisp::editor {
namespace {

constexpr float kLow = -static_cast<float>(kGlyphPadding);
constexpr float kHigh = 1.0f + static_cast<float>(kGlyphPadding);

// Steps per pixel, as kEditStep's inverse (96).
constexpr double kStepsPerPixel = 96.0;
static_assert(static_cast<float>(1.0 / kStepsPerPixel) == kEditStep);

// The nearest grid value to `value`, as the float nearest k / 96.
float snap(float value) {
    return static_cast<float>(std::round(static_cast<double>(value) * kStepsPerPixel) / kStepsPerPixel);
}

void snap_rect_to_grid(SampleRect& rect) {
    for (float* value : {&rect.x0, &rect.y0, &rect.x1, &rect.y1}) *value = snap_to_grid_if_near(*value);
}

float& parameter_ref(TextContrast& contrast, ContrastParameter parameter) {
    switch (parameter) {
        case ContrastParameter::gamma:
            return contrast.gamma;
        case ContrastParameter::contrast:
            return contrast.contrast;
        default:
            return contrast.stem_darkening;
    }
}

float& coordinate_ref(SampleRect& rect, int coordinate) {
    switch (coordinate) {
        case 0:
            return rect.x0;
        case 1:
            return rect.y0;
        case 2:
            return rect.x1;
        default:
            return rect.y1;
    }
}

// Moves [lo, hi] by `delta`, stopping at the bounds; the size stays.
void shift_span(float& lo, float& hi, float delta) {
    delta = std::clamp(delta, kLow - lo, kHigh - hi);
    lo += delta;
    hi += delta;
}

std::string_view trim_spaces(std::string_view text) {
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
    return text;
}

}  // namespace

Result<SubpixelLayout> load_layout_argument(std::string_view preset_or_file) {
    if (Result<SubpixelLayout> preset = subpixel_preset(preset_or_file); preset) return preset;
    const std::filesystem::path path(preset_or_file);
    Result<SubpixelLayout> loaded = load_subpixel_layout_file(path);
    std::error_code ignored;
    if (loaded || std::filesystem::exists(path, ignored)) return loaded;
    std::string presets;
    for (const std::string_view name : subpixel_preset_names())
        presets += (presets.empty() ? "" : ", ") + std::string(name);
    return Error{loaded.error().code, loaded.error().message + "; nor is it a preset (" + presets + ")"};
}

std::optional<float> parse_typed_number(std::string_view text, std::string* why) {
    const size_t slash = text.find('/');
    if (slash == std::string_view::npos) return cli::parse_number<float>(text, why);
    auto refuse = [&](std::string reason) -> std::optional<float> {
        if (why) *why = std::move(reason);
        return std::nullopt;
    };
    std::string part_why;
    const std::string_view numerator_text = trim_spaces(text.substr(0, slash));
    const std::optional<double> numerator = cli::parse_number<double>(numerator_text, &part_why);
    if (!numerator)
        return refuse("is not a fraction: its numerator '" + cli::printable(numerator_text) + "' " + part_why);
    const std::string_view denominator_text = trim_spaces(text.substr(slash + 1));
    const std::optional<double> denominator = cli::parse_number<double>(denominator_text, &part_why);
    if (!denominator) {
        return refuse("is not a fraction: its denominator '" + cli::printable(denominator_text) + "' " + part_why);
    }
    if (*denominator == 0.0) return refuse("divides by zero");
    const double quotient = *numerator / *denominator;
    if (!std::isfinite(quotient) || std::fabs(quotient) > static_cast<double>(std::numeric_limits<float>::max())) {
        return refuse("is out of range for a 32-bit float (too large)");
    }
    return static_cast<float>(quotient);
}

float snap_to_grid_if_near(float value) {
    const double steps = static_cast<double>(value) * kStepsPerPixel;
    const double nearest = std::round(steps);
    return std::fabs(steps - nearest) < 1e-3 ? static_cast<float>(nearest / kStepsPerPixel) : value;
}

std::string format_number(float value) {
    char buffer[64];  // fixed notation of float's largest value is 39 digits
    // Fixed notation keeps 0.0001 from becoming 1e-04; the editor's values stay near [-1, 2].
    const std::to_chars_result written =
        std::fabs(value) >= 1e-4f || value == 0.0f
            ? std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed)
            : std::to_chars(buffer, buffer + sizeof buffer, value);
    return written.ec == std::errc{} ? std::string(buffer, written.ptr) : std::string("?");
}

float estimated_text_width(std::string_view text, float size) {
    float em = 0.0f;
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if ((byte & 0xC0) == 0x80) continue;  // a UTF-8 continuation: counted at its first byte
        if (c >= '0' && c <= '9') {
            em += 0.64f;
        } else if (c == '.' || c == ',' || c == ' ' || c == '-' || c == ':' || c == ';' || c == '/') {
            em += 0.4f;
        } else if (c == 'm' || c == 'w' || c == 'M' || c == 'W' || c == '%' || c == '@' || byte >= 0x80) {
            em += 1.0f;
        } else if (c >= 'a' && c <= 'z') {
            em += 0.65f;
        } else if (c >= 'A' && c <= 'Z') {
            em += 0.8f;
        } else {
            em += 0.7f;
        }
    }
    return em * size;
}

std::string fitted_number(float value, float width, float size) {
    std::string text = format_number(value);
    const size_t point = text.find('.');
    if (estimated_text_width(text, size) <= width || point == std::string::npos) return text;
    for (int decimals = static_cast<int>(text.size() - point) - 2; decimals >= 0; --decimals) {
        char buffer[48];
        std::snprintf(buffer, sizeof buffer, "%.*f", decimals, static_cast<double>(value));
        text = buffer;
        if (estimated_text_width(text, size) <= width) break;
    }
    return text;
}

std::vector<std::string> wrap_text(std::string_view text, float width, float size) {
    std::vector<std::string> lines;
    while (!text.empty()) {
        // The longest prefix that fits, at least one character, ended at a space where there is one.
        size_t fits = 0;
        while (fits < text.size() && estimated_text_width(text.substr(0, fits + 1), size) <= width) ++fits;
        if (fits == text.size()) {
            lines.emplace_back(text);
            break;
        }
        // A UTF-8 sequence stays whole.
        while (fits > 0 && (static_cast<unsigned char>(text[fits]) & 0xC0) == 0x80) --fits;
        if (fits == 0) {
            fits = 1;
            while (fits < text.size() && (static_cast<unsigned char>(text[fits]) & 0xC0) == 0x80) ++fits;
        }
        const size_t space = text.substr(0, fits + 1).rfind(' ');
        if (space != std::string_view::npos && space > 0) {
            lines.emplace_back(text.substr(0, space));
            text.remove_prefix(space + 1);
        } else {
            lines.emplace_back(text.substr(0, fits));
            text.remove_prefix(fits);
        }
    }
    return lines;
}

std::string layout_file_text(const SubpixelLayout& layout) {
    constexpr const char* kChannelKeys[] = {"r", "g", "b"};
    crisp::JsonWriter json;
    json.begin_object().field("name", layout.name);
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        json.key(kChannelKeys[c]).begin_array();
        for (const float value : {r.x0, r.y0, r.x1, r.y1}) json.value(value);
        json.end_array();
    }
    if (const std::optional<TextContrast>& contrast = layout.contrast) {
        json.key("contrast").begin_object();
        json.field("mode", contrast->mode == ContrastMode::linear ? "linear" : "corrected");
        json.field("gamma", contrast->gamma).field("contrast", contrast->contrast);
        json.field("stem_darkening", contrast->stem_darkening).end_object();
    }
    json.end_object();
    return json.line();
}

Status save_layout_file(const SubpixelLayout& layout, const std::filesystem::path& path) {
    if (Status status = validate_subpixel_layout(layout); !status) return status;
    const std::string text = layout_file_text(layout);
    return write_file_atomically(path, std::as_bytes(std::span(text.data(), text.size())));
}

float rect_coordinate(const SampleRect& rect, int coordinate) {
    SampleRect copy = rect;
    return coordinate_ref(copy, coordinate);
}

float contrast_parameter(const TextContrast& contrast, ContrastParameter parameter) {
    TextContrast copy = contrast;
    return parameter_ref(copy, parameter);
}

std::pair<float, float> contrast_range(ContrastParameter parameter) {
    return parameter == ContrastParameter::gamma ? std::pair{1.0f, 4.0f} : std::pair{0.0f, 4.0f};
}

LayoutModel::LayoutModel(SubpixelLayout initial) : layout_(std::move(initial)), saved_(layout_) {}

void LayoutModel::select(int channel) {
    if (channel >= 0 && channel < 3) selected_ = channel;
}

void LayoutModel::push_undo() {
    undo_.push_back(layout_);
    redo_.clear();
}

void LayoutModel::changed() {
    ++revision_;
}

void LayoutModel::rename_if_preset() {
    const auto names = subpixel_preset_names();
    if (std::find(names.begin(), names.end(), layout_.name) != names.end()) layout_.name += "-edited";
}

Status LayoutModel::set_coordinate(int channel, int coordinate, float value) {
    if (channel < 0 || channel > 2 || coordinate < 0 || coordinate > 3) {
        return Error{ErrorCode::invalid_argument, "no such channel or coordinate"};
    }
    SubpixelLayout next = layout_;
    coordinate_ref(next.channels[static_cast<size_t>(channel)], coordinate) = value;
    if (Status status = validate_subpixel_layout(next); !status) return status;
    if (next == layout_) return {};
    push_undo();
    layout_ = std::move(next);
    rename_if_preset();
    changed();
    return {};
}

void LayoutModel::nudge(int dx_steps, int dy_steps) {
    SampleRect rect = layout_.channels[static_cast<size_t>(selected_)];
    shift_span(rect.x0, rect.x1, static_cast<float>(dx_steps) * kEditStep);
    shift_span(rect.y0, rect.y1, static_cast<float>(dy_steps) * kEditStep);
    snap_rect_to_grid(rect);
    if (rect == layout_.channels[static_cast<size_t>(selected_)]) return;
    push_undo();
    layout_.channels[static_cast<size_t>(selected_)] = rect;
    rename_if_preset();
    changed();
}

void LayoutModel::begin_drag(int channel, Handle handle) {
    if (channel < 0 || channel > 2) return;
    selected_ = channel;
    drag_channel_ = channel;
    drag_handle_ = handle;
    drag_start_ = layout_.channels[static_cast<size_t>(channel)];
    drag_before_ = layout_;
}

void LayoutModel::drag_to(float dx, float dy) {
    if (drag_channel_ < 0) return;
    dx = snap(dx);
    dy = snap(dy);
    SampleRect rect = drag_start_;
    switch (drag_handle_) {
        case Handle::left:
            rect.x0 = std::clamp(rect.x0 + dx, kLow, rect.x1 - kMinRectSize);
            break;
        case Handle::right:
            rect.x1 = std::clamp(rect.x1 + dx, rect.x0 + kMinRectSize, kHigh);
            break;
        case Handle::top:
            rect.y0 = std::clamp(rect.y0 + dy, kLow, rect.y1 - kMinRectSize);
            break;
        case Handle::bottom:
            rect.y1 = std::clamp(rect.y1 + dy, rect.y0 + kMinRectSize, kHigh);
            break;
        case Handle::body:
            shift_span(rect.x0, rect.x1, dx);
            shift_span(rect.y0, rect.y1, dy);
            break;
    }
    snap_rect_to_grid(rect);
    SampleRect& current = layout_.channels[static_cast<size_t>(drag_channel_)];
    if (rect == current) return;
    current = rect;
    changed();
}

void LayoutModel::end_drag() {
    if (drag_channel_ < 0) return;
    drag_channel_ = -1;
    if (layout_ == drag_before_) return;
    undo_.push_back(drag_before_);
    redo_.clear();
    rename_if_preset();
}

Status LayoutModel::set_contrast(const std::optional<TextContrast>& contrast) {
    if (contrast) {
        if (Status status = validate_text_contrast(*contrast); !status) return status;
    }
    if (contrast == layout_.contrast) return {};
    push_undo();
    layout_.contrast = contrast;
    rename_if_preset();
    changed();
    return {};
}

Status LayoutModel::set_contrast_parameter(ContrastParameter parameter, float value) {
    TextContrast next = contrast();
    parameter_ref(next, parameter) = value;
    return set_contrast(next);
}

void LayoutModel::step_contrast(ContrastParameter parameter, int steps) {
    const auto [low, high] = contrast_range(parameter);
    const float value = contrast_parameter(contrast(), parameter);
    // Divided rather than multiplied by the step, so that 2.3 is the float nearest 2.3.
    const float per_unit = std::round(1.0f / kContrastStep);
    const float stepped = (std::round(value * per_unit) + static_cast<float>(steps)) / per_unit;
    // Within the range, always: set_contrast cannot refuse it.
    (void)set_contrast_parameter(parameter, std::clamp(stepped, low, high));
}

void LayoutModel::toggle_contrast_mode() {
    TextContrast next = contrast();
    next.mode = next.mode == ContrastMode::linear ? ContrastMode::corrected : ContrastMode::linear;
    (void)set_contrast(next);
}

Status LayoutModel::apply_preset(std::string_view name) {
    Result<SubpixelLayout> preset = subpixel_preset(name);
    if (!preset) return preset.error();
    if (Status status = replace(*preset); !status) return status;
    saved_ = layout_;
    return {};
}

Status LayoutModel::replace(const SubpixelLayout& layout) {
    if (Status status = validate_subpixel_layout(layout); !status) return status;
    if (layout == layout_) return {};
    push_undo();
    layout_ = layout;
    changed();
    return {};
}

bool LayoutModel::undo() {
    if (undo_.empty()) return false;
    redo_.push_back(std::move(layout_));
    layout_ = std::move(undo_.back());
    undo_.pop_back();
    changed();
    return true;
}

bool LayoutModel::redo() {
    if (redo_.empty()) return false;
    undo_.push_back(std::move(layout_));
    layout_ = std::move(redo_.back());
    redo_.pop_back();
    changed();
    return true;
}

}  // namespace crisp::editor
