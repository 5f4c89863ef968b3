#include "editor_view.hpp"

#include "cli.hpp"
#include "json_writer.hpp"

#include <GLFW/glfw3.h>

#include <crisp/glyph.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

namespace crisp::editor {
namespace {

// Positions of the widgets, window pixels.
constexpr float kMargin = 16.0f;
constexpr float kToolbarY = 10.0f, kButtonHeight = 28.0f;
constexpr float kPresetX = kMargin, kPresetWidth = 82.0f, kPresetStride = 88.0f;
constexpr float kCommandX = 736.0f, kCommandWidth = 64.0f, kCommandStride = 70.0f;
constexpr Rect kPathField{1016.0f, kToolbarY, 248.0f, kButtonHeight};
constexpr float kFieldsX = 72.0f, kFieldsY = 384.0f, kFieldWidth = 60.0f, kFieldStrideX = 66.0f, kFieldHeight = 26.0f,
                kFieldStrideY = 30.0f;
constexpr Rect kLightPanel{360.0f, 52.0f, 446.0f, 278.0f};
constexpr Rect kDarkPanel{818.0f, 52.0f, 446.0f, 278.0f};
constexpr Rect kLightStrip{360.0f, 336.0f, 446.0f, 92.0f};  // the moving line and the fringe test
constexpr Rect kDarkStrip{818.0f, 336.0f, 446.0f, 92.0f};
// The contrast controls: the preview's mode, gamma, contrast and stem darkening, and Reset.
constexpr float kContrastY = 436.0f, kContrastHeight = kButtonHeight;
constexpr Rect kModeButton{424.0f, kContrastY, 88.0f, kContrastHeight};
constexpr float kContrastFieldX[] = {572.0f, 696.0f, 862.0f};  // gamma, contrast, stem darkening
constexpr float kContrastLabelWidth[] = {48.0f, 56.0f, 96.0f};
constexpr float kContrastFieldWidth = 56.0f;
constexpr Rect kResetButton{932.0f, kContrastY, 60.0f, kContrastHeight};
constexpr int kContrastChannel = 3;  // Field::channel of the contrast fields
constexpr Rect kRenderedView{360.0f, 484.0f, 904.0f, 272.0f};
constexpr Rect kStatusBar{0.0f, 766.0f, 1280.0f, 34.0f};
constexpr int kCropWidth = static_cast<int>(904 / kRenderedScale);
constexpr int kCropHeight = static_cast<int>(272 / kRenderedScale);
// How near an edge (screen pixels) a press grabs it rather than the rectangle.
constexpr float kEdgeGrab = 5.0f;

constexpr Color kBackground{38, 40, 44};
constexpr Color kPanelText{225, 226, 228};
constexpr Color kDimText{160, 164, 170};
constexpr Color kButton{64, 68, 76};
constexpr Color kButtonBorder{110, 116, 126};
constexpr Color kActive{230, 180, 60};
constexpr Color kErrorText{255, 120, 110};
constexpr Color kLightBackground{250, 248, 240};
constexpr Color kLightInk{20, 20, 24};
constexpr Color kDarkBackground{16, 17, 20};
constexpr Color kDarkInk{236, 236, 230};
constexpr std::array<Color, 3> kChannelColors = {Color{255, 0, 0}, Color{0, 255, 0}, Color{0, 0, 255}};
constexpr std::array<Color, 3> kChannelOutline = {Color{255, 110, 110}, Color{110, 255, 110}, Color{120, 150, 255}};
constexpr const char* kChannelNames[] = {"R", "G", "B"};
constexpr const char* kCoordinateNames[] = {"x0", "y0", "x1", "y1"};
constexpr const char* kCommands[] = {"Undo", "Redo", "Load", "Save"};
constexpr const char* kContrastLabels[] = {"gamma", "contrast", "stem darkening"};
constexpr const char* kContrastKeys[] = {"gamma", "contrast", "stem_darkening"};  // geometry_json, JSON

constexpr const char* kParagraph =
    "Subpixel text fitted to your own monitor: sharp stems, no fringes. 0123456789 (fi fl)";
constexpr float kParagraphSizes[] = {9.0f, 11.0f, 13.0f, 16.0f, 20.0f};

Rect preset_button(size_t i) {
    return {kPresetX + static_cast<float>(i) * kPresetStride, kToolbarY, kPresetWidth, kButtonHeight};
}
Rect command_button(size_t i) {
    return {kCommandX + static_cast<float>(i) * kCommandStride, kToolbarY, kCommandWidth, kButtonHeight};
}

Rect channel_rect_on_screen(const SampleRect& rect, float cell_x, float cell_y) {
    return {cell_x + rect.x0 * kMagnifiedPixelScale, cell_y + rect.y0 * kMagnifiedPixelScale,
            (rect.x1 - rect.x0) * kMagnifiedPixelScale, (rect.y1 - rect.y0) * kMagnifiedPixelScale};
}

Rect contrast_field(int parameter) {
    return {kContrastFieldX[parameter], kContrastY, kContrastFieldWidth, kContrastHeight};
}

Rect intersect(const Rect& a, const Rect& b) {
    const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
    const float x1 = std::min(a.x + a.width, b.x + b.width), y1 = std::min(a.y + a.height, b.y + b.height);
    return {x0, y0, std::max(0.0f, x1 - x0), std::max(0.0f, y1 - y0)};
}

std::string format_number(float value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.5g", static_cast<double>(value));
    return buffer;
}

void button(Canvas& canvas, std::vector<TextItem>& text, const Rect& rect, const std::string& label, bool highlighted,
            bool enabled = true) {
    canvas.fill(rect, highlighted ? Color{92, 84, 52} : kButton);
    canvas.outline(rect, highlighted ? kActive : kButtonBorder);
    text.push_back({label, rect.x + 8.0f, rect.y + 19.0f, 13.0f, enabled ? kPanelText : Color{120, 120, 124}});
}

}  // namespace

EditorView::EditorView(LayoutModel& model, std::filesystem::path path)
    : model_(model),
      path_(path.string()),
      crop_x_(static_cast<int>(kLightStrip.x) + 4),
      crop_y_(static_cast<int>(kLightStrip.y) + 30) {}

std::string EditorView::field_value(const Field& field) const {
    if (field.channel == kContrastChannel) {
        return format_number(contrast_parameter(model_.contrast(), static_cast<ContrastParameter>(field.coordinate)));
    }
    return format_number(
        rect_coordinate(model_.layout().channels[static_cast<size_t>(field.channel)], field.coordinate));
}

std::vector<EditorView::Field> EditorView::fields() const {
    std::vector<Field> out;
    for (int channel = 0; channel < 3; ++channel) {
        for (int coordinate = 0; coordinate < 4; ++coordinate) {
            out.push_back({{kFieldsX + static_cast<float>(coordinate) * kFieldStrideX,
                            kFieldsY + static_cast<float>(channel) * kFieldStrideY, kFieldWidth, kFieldHeight},
                           channel,
                           coordinate});
        }
    }
    for (int parameter = 0; parameter < 3; ++parameter) {
        out.push_back({contrast_field(parameter), kContrastChannel, parameter});
    }
    out.push_back({kPathField, -1, 0});
    return out;
}

std::string EditorView::geometry_json() {
    crisp::JsonWriter json;
    auto rect = [&json](std::string_view key, const Rect& r) {
        json.key(key).begin_array().value(r.x).value(r.y).value(r.width).value(r.height).end_array();
    };
    json.begin_object();
    json.key("window").begin_array().value(kWindowWidth).value(kWindowHeight).end_array();
    json.key("pixel_origin").begin_array().value(kPixelOriginX).value(kPixelOriginY).end_array();
    json.field("pixel_scale", kMagnifiedPixelScale).field("edit_step", kEditStep);
    json.key("presets").begin_object();
    const auto names = subpixel_preset_names();
    for (size_t i = 0; i < names.size(); ++i) rect(names[i], preset_button(i));
    json.end_object().key("commands").begin_object();
    for (size_t i = 0; i < 4; ++i) rect(kCommands[i], command_button(i));
    json.end_object().key("fields").begin_object();
    for (int channel = 0; channel < 3; ++channel) {
        for (int coordinate = 0; coordinate < 4; ++coordinate) {
            rect(std::string(1, "rgb"[channel]) + "." + kCoordinateNames[coordinate],
                 {kFieldsX + static_cast<float>(coordinate) * kFieldStrideX,
                  kFieldsY + static_cast<float>(channel) * kFieldStrideY, kFieldWidth, kFieldHeight});
        }
    }
    json.end_object().key("contrast").begin_object();
    rect("mode", kModeButton);
    for (int parameter = 0; parameter < 3; ++parameter) rect(kContrastKeys[parameter], contrast_field(parameter));
    rect("reset", kResetButton);
    json.end_object();
    rect("path_field", kPathField);
    rect("magnified_pixel", {kPixelOriginX - kMagnifiedPixelScale, kPixelOriginY - kMagnifiedPixelScale,
                             3 * kMagnifiedPixelScale, 3 * kMagnifiedPixelScale});
    rect("preview", {kLightPanel.x, kLightPanel.y, kDarkPanel.x + kDarkPanel.width - kLightPanel.x,
                     kLightStrip.y + kLightStrip.height - kLightPanel.y});
    // The paragraphs only: no moving text, so they change only when the layout does.
    rect("preview_paragraphs",
         {kLightPanel.x, kLightPanel.y, kDarkPanel.x + kDarkPanel.width - kLightPanel.x, kLightPanel.height});
    rect("rendered_pixels", kRenderedView);
    rect("status", kStatusBar);
    json.end_object();
    return json.text();
}

void EditorView::report(std::string text, bool error) {
    messages_.push_back({std::move(text), error});
    if (messages_.size() > 4) messages_.erase(messages_.begin());
}

bool EditorView::save() {
    if (path_.empty()) {
        report("Save: no file; type a path in the file field first", true);
        return false;
    }
    if (Status status = save_subpixel_layout_file(model_.layout(), path_); !status) {
        report("Save failed: " + status.error().message, true);
        return false;
    }
    model_.mark_saved();
    report("Saved " + path_, false);
    return true;
}

bool EditorView::load() {
    if (path_.empty()) {
        report("Load: no file; type a path in the file field first", true);
        return false;
    }
    Result<SubpixelLayout> loaded = load_subpixel_layout_file(path_);
    if (!loaded) {
        report("Load failed: " + loaded.error().message, true);
        return false;
    }
    if (Status status = model_.replace(*loaded); !status) {
        report("Load failed: " + status.error().message, true);
        return false;
    }
    model_.mark_saved();
    report("Loaded " + path_, false);
    return true;
}

void EditorView::begin_field_edit(int index) {
    active_field_ = index;
    field_fresh_ = true;
    const Field field = fields()[static_cast<size_t>(index)];
    field_text_ = field.channel < 0 ? path_ : field_value(field);
    model_.select(field.channel);
}

void EditorView::commit_field_edit() {
    if (active_field_ < 0) return;
    const Field field = fields()[static_cast<size_t>(active_field_)];
    active_field_ = -2;
    if (field.channel < 0) {
        path_ = field_text_;
        return;
    }
    std::string why;
    const std::optional<float> value = parse_typed_number(field_text_, &why);
    const bool contrast = field.channel == kContrastChannel;
    const std::string what = contrast
                                 ? std::string(kContrastLabels[field.coordinate])
                                 : std::string(kChannelNames[field.channel]) + " " + kCoordinateNames[field.coordinate];
    if (!value) {
        report(what + ": \"" + cli::printable(field_text_) + "\" " + why, true);
        return;
    }
    const Status status = contrast
                              ? model_.set_contrast_parameter(static_cast<ContrastParameter>(field.coordinate), *value)
                              : model_.set_coordinate(field.channel, field.coordinate, *value);
    if (!status) report(what + ": " + status.error().message, true);
}

void EditorView::handle(const InputEvent& event) {
    switch (event.kind) {
        case InputEvent::Kind::mouse_move:
            if (model_.dragging()) {
                model_.drag_to((static_cast<float>(event.x) - drag_x_) / kMagnifiedPixelScale,
                               (static_cast<float>(event.y) - drag_y_) / kMagnifiedPixelScale);
            }
            break;
        case InputEvent::Kind::mouse_down:
            if (event.button == GLFW_MOUSE_BUTTON_LEFT) handle_mouse_down(event);
            break;
        case InputEvent::Kind::mouse_up:
            if (event.button == GLFW_MOUSE_BUTTON_LEFT) model_.end_drag();
            break;
        case InputEvent::Kind::key:
            handle_key(event);
            break;
        case InputEvent::Kind::character:
            if (active_field_ >= 0 && event.codepoint >= 0x20 && event.codepoint < 0x7F) {
                // The first character typed replaces the value shown, as in a selected field.
                if (field_fresh_) field_text_.clear();
                field_fresh_ = false;
                field_text_ += static_cast<char>(event.codepoint);
            }
            break;
    }
}

void EditorView::handle_key(const InputEvent& event) {
    const bool control = (event.mods & GLFW_MOD_CONTROL) != 0;
    const bool shift = (event.mods & GLFW_MOD_SHIFT) != 0;
    if (active_field_ >= 0) {
        if (event.key == GLFW_KEY_ENTER || event.key == GLFW_KEY_KP_ENTER || event.key == GLFW_KEY_TAB) {
            commit_field_edit();
        } else if (event.key == GLFW_KEY_ESCAPE) {
            active_field_ = -2;
        } else if (event.key == GLFW_KEY_BACKSPACE && !field_text_.empty()) {
            field_fresh_ = false;
            field_text_.pop_back();
        }
        return;
    }
    if (control && event.key == GLFW_KEY_Z) {
        shift ? model_.redo() : model_.undo();
    } else if (control && event.key == GLFW_KEY_Y) {
        model_.redo();
    } else if (control && event.key == GLFW_KEY_S) {
        save();
    } else if (control && event.key == GLFW_KEY_O) {
        load();
    } else if (control && event.key == GLFW_KEY_Q) {
        quit_ = true;
    } else if (event.key == GLFW_KEY_TAB) {
        model_.select((model_.selected() + (shift ? 2 : 1)) % 3);
    } else if (!control && event.key == GLFW_KEY_M) {
        model_.toggle_contrast_mode();
    } else if (!control && (event.key == GLFW_KEY_G || event.key == GLFW_KEY_C || event.key == GLFW_KEY_D)) {
        const ContrastParameter parameter = event.key == GLFW_KEY_G   ? ContrastParameter::gamma
                                            : event.key == GLFW_KEY_C ? ContrastParameter::contrast
                                                                      : ContrastParameter::stem_darkening;
        model_.step_contrast(parameter, shift ? -1 : 1);
    } else if (!control) {
        const int step = shift ? 8 : 1;
        switch (event.key) {
            case GLFW_KEY_LEFT:
                model_.nudge(-step, 0);
                break;
            case GLFW_KEY_RIGHT:
                model_.nudge(step, 0);
                break;
            case GLFW_KEY_UP:
                model_.nudge(0, -step);
                break;
            case GLFW_KEY_DOWN:
                model_.nudge(0, step);
                break;
            default:
                break;
        }
    }
}

void EditorView::handle_mouse_down(const InputEvent& event) {
    const float x = static_cast<float>(event.x), y = static_cast<float>(event.y);
    commit_field_edit();
    const auto names = subpixel_preset_names();
    for (size_t i = 0; i < names.size(); ++i) {
        if (!preset_button(i).contains(x, y)) continue;
        if (Status status = model_.apply_preset(names[i]); !status) report(status.error().message, true);
        return;
    }
    for (size_t i = 0; i < 4; ++i) {
        if (!command_button(i).contains(x, y)) continue;
        if (i == 0) model_.undo();
        if (i == 1) model_.redo();
        if (i == 2) load();
        if (i == 3) save();
        return;
    }
    if (kModeButton.contains(x, y)) {
        model_.toggle_contrast_mode();
        return;
    }
    if (kResetButton.contains(x, y)) {
        (void)model_.set_contrast(std::nullopt);  // none is always accepted
        return;
    }
    const std::vector<Field> all = fields();
    for (size_t i = 0; i < all.size(); ++i) {
        if (all[i].rect.contains(x, y)) {
            begin_field_edit(static_cast<int>(i));
            return;
        }
    }
    if (start_drag(x, y)) return;
    for (const Rect& panel : {kLightPanel, kDarkPanel, kLightStrip, kDarkStrip}) {
        if (panel.contains(x, y)) {
            crop_x_ = std::clamp(static_cast<int>(x) - kCropWidth / 2, static_cast<int>(kLightPanel.x),
                                 static_cast<int>(kDarkPanel.x + kDarkPanel.width) - kCropWidth);
            crop_y_ = std::clamp(static_cast<int>(y) - kCropHeight / 2, static_cast<int>(kLightPanel.y),
                                 static_cast<int>(kLightStrip.y + kLightStrip.height) - kCropHeight);
            return;
        }
    }
}

bool EditorView::start_drag(float x, float y) {
    const float u = (x - kPixelOriginX) / kMagnifiedPixelScale;
    const float v = (y - kPixelOriginY) / kMagnifiedPixelScale;
    const float grab = kEdgeGrab / kMagnifiedPixelScale;
    const int selected = model_.selected();
    const std::array<int, 3> order = {selected, (selected + 1) % 3, (selected + 2) % 3};
    auto begin = [&](int channel, Handle handle) {
        model_.begin_drag(channel, handle);
        drag_x_ = x;
        drag_y_ = y;
        return true;
    };
    // Edges first (the selected rectangle's before the others'), then bodies.
    for (int channel : order) {
        const SampleRect& r = model_.layout().channels[static_cast<size_t>(channel)];
        const bool within_x = u >= r.x0 - grab && u <= r.x1 + grab;
        const bool within_y = v >= r.y0 - grab && v <= r.y1 + grab;
        if (within_y && std::abs(u - r.x0) <= grab) return begin(channel, Handle::left);
        if (within_y && std::abs(u - r.x1) <= grab) return begin(channel, Handle::right);
        if (within_x && std::abs(v - r.y0) <= grab) return begin(channel, Handle::top);
        if (within_x && std::abs(v - r.y1) <= grab) return begin(channel, Handle::bottom);
    }
    for (int channel : order) {
        const SampleRect& r = model_.layout().channels[static_cast<size_t>(channel)];
        if (u >= r.x0 && u <= r.x1 && v >= r.y0 && v <= r.y1) return begin(channel, Handle::body);
    }
    return false;
}

void EditorView::draw(Canvas& canvas, std::span<const uint8_t> previous, const FrameStats& stats,
                      std::vector<TextItem>& text) {
    canvas.clear(kBackground);
    draw_toolbar(canvas, text);
    draw_magnified_pixel(canvas, text);
    draw_fields(canvas, text);
    draw_contrast(canvas, text);
    draw_side_text(text);
    draw_preview(canvas, stats, text);
    draw_rendered_pixels(canvas, previous, text);
    draw_status(canvas, stats, text);
}

void EditorView::draw_toolbar(Canvas& canvas, std::vector<TextItem>& text) const {
    const auto names = subpixel_preset_names();
    for (size_t i = 0; i < names.size(); ++i) {
        const bool current = model_.layout().name == names[i];
        button(canvas, text, preset_button(i), std::string(names[i]), current);
    }
    const bool enabled[] = {model_.can_undo(), model_.can_redo(), true, true};
    for (size_t i = 0; i < 4; ++i) button(canvas, text, command_button(i), kCommands[i], false, enabled[i]);
}

void EditorView::draw_magnified_pixel(Canvas& canvas, std::vector<TextItem>& text) const {
    const float s = kMagnifiedPixelScale;
    text.push_back({"Magnified pixel: drag an edge or a rectangle", kMargin, 56.0f, 12.0f, kDimText});
    const Rect area{kPixelOriginX - s, kPixelOriginY - s, 3 * s, 3 * s};
    canvas.fill(area, Color{12, 12, 14});
    const SubpixelLayout& layout = model_.layout();
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            const float cell_x = kPixelOriginX + static_cast<float>(i) * s;
            const float cell_y = kPixelOriginY + static_cast<float>(j) * s;
            const float weight = (i == 0 && j == 0) ? 0.7f : 0.25f;
            for (size_t c = 0; c < 3; ++c) {
                // Light a neighbour throws past the shown pixels stays out of the other widgets.
                canvas.add(intersect(channel_rect_on_screen(layout.channels[c], cell_x, cell_y), area),
                           kChannelColors[c], weight);
            }
        }
    }
    // The pixel grid over the light, then the centre pixel's rectangles outlined, selected on top.
    for (int k = 0; k <= 3; ++k) {
        const float offset = static_cast<float>(k) * s;
        canvas.fill({area.x + offset - (k == 3 ? 1.0f : 0.0f), area.y, 1.0f, area.height}, Color{90, 90, 96});
        canvas.fill({area.x, area.y + offset - (k == 3 ? 1.0f : 0.0f), area.width, 1.0f}, Color{90, 90, 96});
    }
    canvas.outline({kPixelOriginX, kPixelOriginY, s, s}, Color{200, 200, 200});
    const int selected = model_.selected();
    for (int n = 1; n <= 3; ++n) {
        const size_t c = static_cast<size_t>((selected + n) % 3);
        const Rect r = channel_rect_on_screen(layout.channels[c], kPixelOriginX, kPixelOriginY);
        const bool is_selected = static_cast<int>(c) == selected;
        canvas.outline(r, kChannelOutline[c], is_selected ? 2.0f : 1.0f);
        if (is_selected) {
            const float h = 3.0f;  // edge handles
            canvas.fill({r.x + r.width / 2 - h, r.y - h, 2 * h, 2 * h}, kActive);
            canvas.fill({r.x + r.width / 2 - h, r.y + r.height - h, 2 * h, 2 * h}, kActive);
            canvas.fill({r.x - h, r.y + r.height / 2 - h, 2 * h, 2 * h}, kActive);
            canvas.fill({r.x + r.width - h, r.y + r.height / 2 - h, 2 * h, 2 * h}, kActive);
        }
        text.push_back(
            {kChannelNames[c], r.x + r.width / 2 - 4.0f, r.y + r.height / 2 + 5.0f, 14.0f, Color{255, 255, 255}});
    }
}

void EditorView::draw_fields(Canvas& canvas, std::vector<TextItem>& text) const {
    for (int coordinate = 0; coordinate < 4; ++coordinate) {
        text.push_back({kCoordinateNames[coordinate], kFieldsX + static_cast<float>(coordinate) * kFieldStrideX + 4.0f,
                        kFieldsY - 6.0f, 12.0f, kDimText});
    }
    const std::vector<Field> all = fields();
    for (size_t i = 0; i < all.size(); ++i) {
        const Field& field = all[i];
        const bool active = static_cast<int>(i) == active_field_;
        canvas.fill(field.rect, active ? Color{20, 20, 22} : Color{28, 30, 34});
        canvas.outline(field.rect, active ? kActive : kButtonBorder);
        std::string value;
        if (active) {
            value = field_text_ + "_";
        } else if (field.channel < 0) {
            value = path_.empty() ? "(no file)" : path_;
        } else {
            value = field_value(field);
        }
        // Long paths show their end, where the file name is.
        const size_t room = field.channel < 0 ? 34 : 9;
        if (value.size() > room) value = "..." + value.substr(value.size() - room + 3);
        text.push_back({cli::printable(value), field.rect.x + 5.0f, field.rect.y + 18.0f, 12.0f, kPanelText});
        if (field.coordinate == 0 && field.channel >= 0 && field.channel < 3) {
            const bool selected = field.channel == model_.selected();
            const Rect swatch{kMargin + 8.0f, field.rect.y + 3.0f, 20.0f, 20.0f};
            canvas.fill(swatch, kChannelColors[static_cast<size_t>(field.channel)]);
            if (selected)
                canvas.outline({swatch.x - 3, swatch.y - 3, swatch.width + 6, swatch.height + 6}, kActive, 2.0f);
        }
    }
}

void EditorView::draw_contrast(Canvas& canvas, std::vector<TextItem>& text) const {
    const TextContrast contrast = model_.contrast();
    const bool linear = contrast.mode == ContrastMode::linear;
    text.push_back({"Contrast", kRenderedView.x, kContrastY + 18.0f, 12.0f, kDimText});
    button(canvas, text, kModeButton, linear ? "linear" : "corrected", false);
    for (int parameter = 0; parameter < 3; ++parameter) {
        const Rect field = contrast_field(parameter);
        // The labels sit left of their fields; the parameters do nothing in linear mode.
        text.push_back({kContrastLabels[parameter], field.x - kContrastLabelWidth[parameter], kContrastY + 18.0f, 12.0f,
                        linear ? Color{120, 120, 124} : kDimText});
    }
    const bool has = model_.layout().contrast.has_value();
    button(canvas, text, kResetButton, "Reset", false, has);
    text.push_back({has ? "the layout's own (saved with it)" : "crisp's default (the layout has none)",
                    kResetButton.x + kResetButton.width + 12.0f, kContrastY + 18.0f, 12.0f, kDimText});
}

void EditorView::draw_side_text(std::vector<TextItem>& text) const {
    const SubpixelLayout& layout = model_.layout();
    text.push_back({"Layout: " + cli::printable(layout.name.empty() ? "(unnamed)" : layout.name) +
                        (model_.modified() ? "  (modified)" : ""),
                    kMargin, 490.0f, 13.0f, kPanelText});
    float y = 514.0f;
    for (const Message& message : messages_) {
        // A message is crisp's sentence, wrapped below: escaped, but kept whole.
        text.push_back(
            {cli::printable(message.text, 1000), kMargin, y, 11.0f, message.error ? kErrorText : kDimText, 330.0f});
        y += 28.0f;
    }
    const char* help[] = {
        "Drag an edge or a rectangle in the magnified pixel.",
        "Arrows nudge the selected one 1/96 px (Shift: 1/12).",
        "Tab selects the next channel; click a number to type.",
        "Ctrl+Z undo, Ctrl+Y redo, Ctrl+S save, Ctrl+O load,",
        "Ctrl+Q quit.",
        "Click the preview to choose what is magnified.",
        "G, C, D raise gamma, contrast, stem darkening by 0.1,",
        "with Shift lower them; M: linear or corrected.",
    };
    y = 628.0f;
    for (const char* line : help) {
        text.push_back({line, kMargin, y, 11.0f, kDimText});
        y += 17.0f;
    }
}

void EditorView::draw_preview(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const {
    text.push_back({"Preview at native pixels, drawn with this layout", kLightPanel.x, 46.0f, 12.0f, kDimText});
    const std::pair<Rect, Color> panels[] = {{kLightPanel, kLightInk}, {kDarkPanel, kDarkInk}};
    for (const auto& [panel, ink] : panels) {
        const bool light = panel.x == kLightPanel.x;
        canvas.fill(panel, light ? kLightBackground : kDarkBackground);
        float y = panel.y + 16.0f;
        for (float size : kParagraphSizes) {
            text.push_back({kParagraph, panel.x + 10.0f, y, size, ink, panel.width - 20.0f, true});
            y += size * 2.0f * 1.17f + 10.0f;  // two lines of DejaVu Sans and a gap
        }
        const Rect strip = light ? kLightStrip : kDarkStrip;
        canvas.fill(strip, light ? kLightBackground : kDarkBackground);
        // A line moving 1/16 px a frame: a new subpixel offset, and new samples, every frame.
        const float shift = static_cast<float>(stats.frame % 16) / 16.0f;
        text.push_back({"Moving by 1/16 px a frame: Illegible 111 lll", strip.x + 10.0f + shift, strip.y + 20.0f, 13.0f,
                        ink, 0.0f, true, true});
        // The fringe test: thin vertical, horizontal and diagonal strokes.
        text.push_back({"||||||||  \u2014\u2014\u2014\u2014  ////////  \\\\\\\\\\\\\\\\  =====  xxxx", strip.x + 10.0f,
                        strip.y + 50.0f, 14.0f, ink, 0.0f, true});
        text.push_back({"|| || ||  \u2014 \u2014 \u2014  // // //  \\\\ \\\\ \\\\  il1|  mwWM", strip.x + 10.0f,
                        strip.y + 78.0f, 11.0f, ink, 0.0f, true});
    }
    // Where the magnified view of rendered pixels looks, just outside the area it shows.
    canvas.outline({static_cast<float>(crop_x_ - 1), static_cast<float>(crop_y_ - 1),
                    static_cast<float>(kCropWidth + 2), static_cast<float>(kCropHeight + 2)},
                   kActive);
}

void EditorView::draw_rendered_pixels(Canvas& canvas, std::span<const uint8_t> previous,
                                      std::vector<TextItem>& text) const {
    text.push_back({"The outlined preview pixels, x8, lighting this layout's subpixels", kRenderedView.x,
                    kRenderedView.y - 6.0f, 12.0f, kDimText});
    canvas.fill(kRenderedView, Color{0, 0, 0});
    if (previous.size() < size_t{kWindowWidth} * kWindowHeight * 4) return;
    const SubpixelLayout& layout = model_.layout();
    const float s = static_cast<float>(kRenderedScale);
    for (int py = 0; py < kCropHeight; ++py) {
        for (int px = 0; px < kCropWidth; ++px) {
            const size_t source =
                (static_cast<size_t>(crop_y_ + py) * kWindowWidth + static_cast<size_t>(crop_x_ + px)) * 4;
            const float cell_x = kRenderedView.x + static_cast<float>(px) * s;
            const float cell_y = kRenderedView.y + static_cast<float>(py) * s;
            for (size_t c = 0; c < 3; ++c) {
                const SampleRect& r = layout.channels[c];
                // A channel's light stays inside its own pixel's cell, where the subpixel is.
                const float x0 = std::clamp(r.x0, 0.0f, 1.0f), x1 = std::clamp(r.x1, 0.0f, 1.0f);
                const float y0 = std::clamp(r.y0, 0.0f, 1.0f), y1 = std::clamp(r.y1, 0.0f, 1.0f);
                if (x1 <= x0 || y1 <= y0) continue;
                canvas.add({cell_x + x0 * s, cell_y + y0 * s, (x1 - x0) * s, (y1 - y0) * s}, kChannelColors[c],
                           static_cast<float>(previous[source + c]) / 255.0f);
            }
        }
    }
}

void EditorView::draw_status(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const {
    canvas.fill(kStatusBar, Color{24, 25, 28});
    char line[256];
    const char* state = stats.glyphs == 0                           ? "no glyphs yet"
                        : stats.min_samples >= stats.target_samples ? "converged"
                                                                    : "converging";
    char gpu[32] = "GPU -";
    if (stats.gpu_ms >= 0.0) std::snprintf(gpu, sizeof gpu, "GPU %.2f ms/frame", stats.gpu_ms);
    std::snprintf(line, sizeof line,
                  "frame %llu   samples per glyph %u to %u of %u (%s)   atlas %.1f%% occupied   %s   %u preview glyphs",
                  static_cast<unsigned long long>(stats.frame), stats.min_samples, stats.max_samples,
                  stats.target_samples, state, static_cast<double>(stats.atlas_occupancy) * 100.0, gpu, stats.glyphs);
    text.push_back({line, kMargin, kStatusBar.y + 22.0f, 13.0f, kPanelText});
}

}  // namespace crisp::editor
