#include "editor_model.hpp"

#include "cli.hpp"
#include "core/file_io.hpp"
#include "core/utf8.hpp"
#include "json_writer.hpp"

#include <crisp/glyph.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

bool continuation(char c) {
    return (static_cast<unsigned char>(c) & 0xC0) == 0x80;
}

// Valid UTF-8 decodes and encodes back to itself; anything ill-formed became U+FFFD.
bool valid_utf8(std::string_view text) {
    std::string again;
    for (const uint32_t codepoint : decode_utf8(text)) append_utf8(again, codepoint);
    return again == text;
}

// Words separated by any of `separators`, empty ones left out.
std::vector<std::string_view> words(std::string_view text, std::string_view separators) {
    std::vector<std::string_view> out;
    size_t start = 0;
    while (start < text.size()) {
        const size_t end = std::min(text.find_first_of(separators, start), text.size());
        if (end > start) out.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return out;
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

TextEdit::TextEdit(std::string text) : text_(std::move(text)), cursor_(text_.size()), anchor_(cursor_) {}

size_t TextEdit::boundary_at_or_before(size_t offset) const {
    offset = std::min(offset, text_.size());
    while (offset > 0 && offset < text_.size() && continuation(text_[offset])) --offset;
    return offset;
}

size_t TextEdit::next_boundary(size_t offset) const {
    if (offset >= text_.size()) return text_.size();
    ++offset;
    while (offset < text_.size() && continuation(text_[offset])) ++offset;
    return offset;
}

size_t TextEdit::previous_boundary(size_t offset) const {
    return offset == 0 ? 0 : boundary_at_or_before(offset - 1);
}

void TextEdit::move_to(size_t offset, bool extend) {
    cursor_ = boundary_at_or_before(offset);
    if (!extend) anchor_ = cursor_;
}

void TextEdit::left(bool extend) {
    if (has_selection() && !extend) {
        move_to(selection().first);
    } else {
        move_to(previous_boundary(cursor_), extend);
    }
}

void TextEdit::right(bool extend) {
    if (has_selection() && !extend) {
        move_to(selection().second);
    } else {
        move_to(next_boundary(cursor_), extend);
    }
}

void TextEdit::select_all() {
    anchor_ = 0;
    cursor_ = text_.size();
}

void TextEdit::insert(std::string_view utf8) {
    std::string kept;
    for (const char c : utf8) {
        if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7F) kept += c;
    }
    const auto [first, last] = selection();
    text_.replace(first, last - first, kept);
    cursor_ = anchor_ = first + kept.size();
}

void TextEdit::insert_codepoint(uint32_t codepoint) {
    if (codepoint > 0x10FFFF || (codepoint >= 0xD800 && codepoint <= 0xDFFF)) return;
    std::string utf8;
    append_utf8(utf8, codepoint);
    insert(utf8);
}

void TextEdit::backspace() {
    if (!has_selection()) anchor_ = previous_boundary(cursor_);
    insert("");
}

void TextEdit::erase() {
    if (!has_selection()) anchor_ = next_boundary(cursor_);
    insert("");
}

size_t TextEdit::offset_at(float x, float size, const MeasureText& measure, size_t first) const {
    first = boundary_at_or_before(first);
    const std::string_view text = text_;
    size_t best = first;
    float best_distance = std::fabs(x);
    for (size_t offset = next_boundary(first); offset > first && offset <= text_.size();) {
        const float distance = std::fabs(x - measure(text.substr(first, offset - first), size));
        if (distance < best_distance) {
            best = offset;
            best_distance = distance;
        }
        if (offset == text_.size()) break;
        offset = next_boundary(offset);
    }
    return best;
}

std::pair<size_t, size_t> TextEdit::visible(float room, float size, const MeasureText& measure, size_t first) const {
    const std::string_view text = text_;
    first = std::min(boundary_at_or_before(first), cursor_);
    // Scrolled right as little as puts the cursor inside.
    while (first < cursor_ && measure(text.substr(first, cursor_ - first), size) > room) first = next_boundary(first);
    size_t last = cursor_;
    while (last < text_.size()) {
        const size_t next = next_boundary(last);
        if (measure(text.substr(first, next - first), size) > room) break;
        last = next;
    }
    return {first, last};
}

std::filesystem::path recent_files_path() {
    const char* config = std::getenv("XDG_CONFIG_HOME");
    std::filesystem::path base;
    if (config && config[0] != '\0' && std::filesystem::path(config).is_absolute()) {
        base = config;
    } else if (const char* home = std::getenv("HOME"); home && home[0] != '\0') {
        base = std::filesystem::path(home) / ".config";
    } else {
        return {};
    }
    return base / "crisp" / "layout-editor-recent";
}

Result<std::vector<std::string>> read_recent_files(const std::filesystem::path& file) {
    std::error_code error;
    if (!std::filesystem::exists(std::filesystem::symlink_status(file, error))) return std::vector<std::string>{};
    Result<std::vector<std::byte>> bytes = read_file(file, 64 * 1024);
    if (!bytes) return bytes.error();
    const std::string text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
    const std::string name = cli::printable_path(file.string());
    auto refuse = [&](const std::string& why) { return Error{ErrorCode::invalid_argument, name + ": " + why}; };
    if (text.find('\0') != std::string::npos) return refuse("holds a NUL byte: not a list of paths");
    if (!valid_utf8(text)) return refuse("is not UTF-8 text");
    std::vector<std::string> recent;
    for (const std::string_view line : words(text, "\n")) {
        if (!std::filesystem::path(line).is_absolute()) {
            return refuse("line " + std::to_string(recent.size() + 1) + " ('" + cli::printable(line) +
                          "') is not an absolute path");
        }
        if (recent.size() == kMaxRecentFiles) {
            return refuse("holds more than " + std::to_string(kMaxRecentFiles) + " paths");
        }
        recent.emplace_back(line);
    }
    return recent;
}

std::vector<std::string> add_recent_file(std::vector<std::string> recent, const std::string& path) {
    if (path.empty() || path.find_first_of("\r\n") != std::string::npos) return recent;
    std::error_code error;
    const std::filesystem::path absolute = std::filesystem::absolute(path, error).lexically_normal();
    if (error) return recent;
    const std::string entry = absolute.string();
    recent.erase(std::remove(recent.begin(), recent.end(), entry), recent.end());
    recent.insert(recent.begin(), entry);
    if (recent.size() > kMaxRecentFiles) recent.resize(kMaxRecentFiles);
    return recent;
}

Status write_recent_files(const std::filesystem::path& file, const std::vector<std::string>& recent) {
    std::error_code error;
    std::filesystem::create_directories(file.parent_path(), error);
    if (error) {
        return Error{ErrorCode::io, cli::printable_path(file.parent_path().string()) + ": " + error.message()};
    }
    std::string text;
    for (const std::string& path : recent) text += path + "\n";
    return write_file_atomically(file, std::as_bytes(std::span(text.data(), text.size())));
}

std::optional<std::vector<float>> parse_preview_sizes(std::string_view text, std::string* why) {
    auto refuse = [&](std::string reason) -> std::optional<std::vector<float>> {
        if (why) *why = std::move(reason);
        return std::nullopt;
    };
    std::vector<float> sizes;
    for (const std::string_view word : words(text, " ,\t")) {
        std::string number_why;
        const std::optional<float> size = cli::parse_number<float>(word, &number_why);
        if (!size) return refuse("'" + cli::printable(word) + "' " + number_why);
        if (!(*size >= kMinPreviewSize && *size <= kMaxPreviewSize)) {
            return refuse(format_number(*size) + " is outside " + format_number(kMinPreviewSize) + " to " +
                          format_number(kMaxPreviewSize) + " pixels");
        }
        if (sizes.size() == kMaxPreviewSizes) {
            return refuse("more than " + std::to_string(kMaxPreviewSizes) + " sizes");
        }
        sizes.push_back(*size);
    }
    if (sizes.empty()) return refuse("has no sizes: expected pixel sizes such as \"9 11 13 16 20\"");
    return sizes;
}

std::string format_preview_sizes(const std::vector<float>& sizes) {
    std::string text;
    for (const float size : sizes) text += (text.empty() ? "" : " ") + format_number(size);
    return text;
}

std::span<const std::pair<const char*, PreviewColours>> preview_colour_presets() {
    static constexpr std::pair<const char*, PreviewColours> kPresets[] = {
        {"dark-on-light", {{20, 20, 24}, {250, 248, 240}}},
        {"light-on-dark", {{236, 236, 230}, {16, 17, 20}}},
        {"yellow-on-blue", {{255, 226, 122}, {27, 58, 140}}},
    };
    return kPresets;
}

std::optional<PreviewColours> parse_preview_colours(std::string_view text, std::string* why) {
    auto refuse = [&](std::string reason) -> std::optional<PreviewColours> {
        if (why) *why = std::move(reason);
        return std::nullopt;
    };
    const std::string_view trimmed = trim_spaces(text);
    for (const auto& [name, colours] : preview_colour_presets()) {
        if (trimmed == name) return colours;
    }
    std::vector<std::string_view> parts = words(text, " /\t");
    if (parts.size() == 3 && parts[1] == "on") parts.erase(parts.begin() + 1);
    std::string presets;
    for (const auto& [name, colours] : preview_colour_presets())
        presets += (presets.empty() ? "" : ", ") + std::string(name);
    if (parts.size() != 2) {
        return refuse("is not two colours (text and background, such as \"#141418 on #FAF8F0\") nor a preset (" +
                      presets + ")");
    }
    Color colour[2];
    for (size_t i = 0; i < 2; ++i) {
        std::string_view hex = parts[i];
        if (!hex.empty() && hex.front() == '#') hex.remove_prefix(1);
        const bool digits = hex.size() == 6 && std::all_of(hex.begin(), hex.end(), [](char c) {
                                return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
                            });
        if (!digits)
            return refuse("'" + cli::printable(parts[i]) + "' is not a colour: expected #RRGGBB (six hex digits)");
        const auto channel = [&](size_t at) {
            return static_cast<uint8_t>(std::strtoul(std::string(hex.substr(at, 2)).c_str(), nullptr, 16));
        };
        colour[i] = {channel(0), channel(2), channel(4)};
    }
    const PreviewColours colours{colour[0], colour[1]};
    if (colours.foreground == colours.background) {
        return refuse("has the same colour for the text and its background: the text would not show");
    }
    return colours;
}

std::string format_preview_colours(const PreviewColours& colours) {
    char text[32];
    std::snprintf(text, sizeof text, "#%02X%02X%02X on #%02X%02X%02X", colours.foreground.r, colours.foreground.g,
                  colours.foreground.b, colours.background.r, colours.background.g, colours.background.b);
    return text;
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

namespace {

// The rectangles mirrored left to right (horizontal) or top to bottom within the pixel: the order
// of the channels along that axis reversed, so rgb becomes bgr.
SubpixelLayout mirrored(const SubpixelLayout& layout, bool horizontal) {
    SubpixelLayout out = layout;
    for (SampleRect& rect : out.channels) {
        float& lo = horizontal ? rect.x0 : rect.y0;
        float& hi = horizontal ? rect.x1 : rect.y1;
        const float new_lo = 1.0f - hi, new_hi = 1.0f - lo;
        lo = new_lo;
        hi = new_hi;
        snap_rect_to_grid(rect);
    }
    return out;
}

// Every rectangle `steps` edit steps wider on each side (narrower for negative steps), about its
// centre: within the bounds, never narrower than kMinRectSize.
SubpixelLayout widened(const SubpixelLayout& layout, int steps) {
    SubpixelLayout out = layout;
    const float delta = static_cast<float>(steps) * kEditStep;
    for (SampleRect& rect : out.channels) {
        if (rect.x1 - rect.x0 + 2.0f * delta < kMinRectSize) continue;  // too narrow already
        rect.x0 = snap(std::max(kLow, rect.x0 - delta));
        rect.x1 = snap(std::min(kHigh, rect.x1 + delta));
    }
    return out;
}

}  // namespace

std::vector<Candidate> layout_candidates(const SubpixelLayout& current) {
    std::vector<Candidate> out;
    if (!validate_subpixel_layout(current)) return out;
    SubpixelLayout reversed = mirrored(current, true);
    if (reversed.channels == current.channels) reversed = mirrored(current, false);
    const std::pair<const char*, SubpixelLayout> tries[] = {{"Current", current},
                                                            {"Order reversed", std::move(reversed)},
                                                            {"Narrower", widened(current, -kCandidateSteps)},
                                                            {"Wider", widened(current, kCandidateSteps)}};
    std::string edited = current.name;
    if (!edited.ends_with("-edited")) edited += "-edited";
    for (const auto& [label, layout] : tries) {
        if (out.size() == kMaxCandidates || !validate_subpixel_layout(layout)) continue;
        const bool seen = std::any_of(out.begin(), out.end(),
                                      [&](const Candidate& c) { return c.layout.channels == layout.channels; });
        if (seen) continue;
        Candidate candidate{label, layout};
        if (!out.empty()) {
            candidate.layout.name = edited;
            for (const std::string_view name : subpixel_preset_names()) {
                if (subpixel_preset(name)->channels == layout.channels) candidate.layout.name = name;
            }
        }
        out.push_back(std::move(candidate));
    }
    return out;
}

}  // namespace crisp::editor
