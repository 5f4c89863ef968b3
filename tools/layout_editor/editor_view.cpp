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

// Positions of the widgets that keep their place, interface pixels (EditorView::Geometry has the
// others, laid out for the window's size from these at kMinimumWidth x kMinimumHeight).
constexpr float kMargin = 16.0f;
constexpr float kToolbarY = 10.0f, kButtonHeight = 28.0f;
constexpr float kPresetX = kMargin, kPresetWidth = 82.0f, kPresetStride = 88.0f;
constexpr float kCommandX = 736.0f, kCommandWidth = 64.0f, kCommandStride = 70.0f;
constexpr float kPathFieldX = 1016.0f, kRecentButtonWidth = 60.0f, kRecentWidth = 520.0f, kRecentRow = 24.0f;
// The preview's controls, a row above it: its text, sizes and colours, the colour presets, zoom.
constexpr float kPreviewRowY = 44.0f, kPreviewRowHeight = 26.0f;
constexpr float kTextLabelWidth = 34.0f, kSizesLabelWidth = 36.0f, kColoursLabelWidth = 50.0f;
constexpr float kSizesFieldWidth = 110.0f, kColoursFieldWidth = 150.0f, kColoursButtonWidth = 64.0f,
                kZoomButtonWidth = 70.0f, kCompareButtonWidth = 76.0f, kRowGap = 6.0f;
// The quit prompt, centred in the window.
constexpr float kPromptWidth = 440.0f, kPromptHeight = 124.0f, kPromptButtonWidth = 96.0f;
// The number fields: wide enough for "-0.08333" (fitted_number shortens what is longer).
constexpr float kFieldsX = 52.0f, kFieldsY = 384.0f, kFieldWidth = 68.0f, kFieldStrideX = 72.0f, kFieldHeight = 26.0f,
                kFieldStrideY = 30.0f;
constexpr float kFieldTextSize = 12.0f, kFieldPadding = 5.0f;
// The preview: two panels of paragraphs and two strips below them (the moving line and the
// fringe test), light left and dark right; what the window adds goes half to the panels' height.
constexpr float kPreviewX = 360.0f, kPreviewY = kPreviewRowY + kPreviewRowHeight + 8.0f, kPreviewGap = 12.0f;
constexpr float kPanelWidth = 446.0f, kPanelHeight = 278.0f, kStripHeight = 92.0f, kStripGap = 6.0f;
// The contrast controls: the preview's mode, gamma, contrast and stem darkening, and Reset; a row
// below the strips.
constexpr float kContrastGap = 8.0f, kContrastHeight = kButtonHeight;
constexpr float kModeButtonX = 424.0f, kModeButtonWidth = 88.0f;
constexpr float kContrastFieldX[] = {572.0f, 696.0f, 862.0f};  // gamma, contrast, stem darkening
constexpr float kContrastLabelWidth[] = {48.0f, 56.0f, 96.0f};
constexpr float kContrastFieldWidth = 56.0f;
constexpr float kResetButtonX = 932.0f, kResetButtonWidth = 60.0f;
// The magnified rendered pixels, below the contrast row down to the status line.
constexpr float kRenderedViewGap = 20.0f, kRenderedViewHeight = 246.0f, kStatusHeight = 34.0f;
// The left column's text: the layout's name, the messages below it, the help at the bottom.
constexpr float kLayoutNameY = 490.0f, kMessagesY = 514.0f, kHelpY = 628.0f;
constexpr float kMessageSize = 11.0f, kMessageLine = 14.0f, kMessageWidth = 330.0f;
constexpr float kHelpSize = 11.0f, kHelpLine = 17.0f;
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

constexpr const char* kPromptButtons[] = {"Save (S)", "Discard (D)", "Cancel (Esc)"};
constexpr int kZooms[] = {1, 2, 4};

// A text item's box, about: its width estimated (or its wrap width), its lines as wrap_text says.
Rect item_box(const TextItem& item) {
    float width = estimated_text_width(item.text, item.size);
    float lines = 1.0f;
    if (item.wrap_width > 0.0f) {
        lines = static_cast<float>(std::max<size_t>(1, wrap_text(item.text, item.wrap_width, item.size).size()));
        if (item.max_lines > 0) lines = std::min(lines, static_cast<float>(item.max_lines));
        width = item.wrap_width;
    }
    return {item.x, item.y - item.size, width, item.size * 1.2f * lines};
}

bool overlaps(const Rect& a, const Rect& b) {
    return a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height;
}

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

Rect intersect(const Rect& a, const Rect& b) {
    const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
    const float x1 = std::min(a.x + a.width, b.x + b.width), y1 = std::min(a.y + a.height, b.y + b.height);
    return {x0, y0, std::max(0.0f, x1 - x0), std::max(0.0f, y1 - y0)};
}

void button(Canvas& canvas, std::vector<TextItem>& text, const Rect& rect, const std::string& label, bool highlighted,
            bool enabled = true) {
    canvas.fill(rect, highlighted ? Color{92, 84, 52} : kButton);
    canvas.outline(rect, highlighted ? kActive : kButtonBorder);
    text.push_back({label, rect.x + 8.0f, rect.y + 19.0f, 13.0f, enabled ? kPanelText : Color{120, 120, 124}});
}

}  // namespace

EditorView::EditorView(LayoutModel& model, std::filesystem::path path) : model_(model), path_(path.string()) {
    resize(kWindowWidth, kWindowHeight, 1.0f);
}

void EditorView::resize(uint32_t width, uint32_t height, float content_scale) {
    if (width == 0 || height == 0 || !(content_scale > 0.0f)) return;
    window_width_ = width;
    window_height_ = height;
    content_scale_ = content_scale;
    const float window_width = static_cast<float>(width), window_height = static_cast<float>(height);
    // The content scale, or as much less as the widgets need to fit.
    scale_ = std::min({content_scale, window_width / kMinimumWidth, window_height / kMinimumHeight});
    width_ = window_width / scale_;
    height_ = window_height / scale_;
    const float extra_width = std::max(0.0f, width_ - kMinimumWidth);
    const float extra_height = std::max(0.0f, height_ - kMinimumHeight);
    Geometry& g = geometry_;
    g.recent_button = {width_ - kMargin - kRecentButtonWidth, kToolbarY, kRecentButtonWidth, kButtonHeight};
    g.path_field = {kPathFieldX, kToolbarY, g.recent_button.x - kRowGap - kPathFieldX, kButtonHeight};
    const float panel_width = kPanelWidth + extra_width / 2.0f, panel_height = kPanelHeight + extra_height / 2.0f;
    const float dark_x = kPreviewX + panel_width + kPreviewGap;
    g.light_panel = {kPreviewX, kPreviewY, panel_width, panel_height};
    g.dark_panel = {dark_x, kPreviewY, panel_width, panel_height};
    const float strip_y = kPreviewY + panel_height + kStripGap;
    g.light_strip = {kPreviewX, strip_y, panel_width, kStripHeight};
    g.dark_strip = {dark_x, strip_y, panel_width, kStripHeight};
    g.contrast_y = strip_y + kStripHeight + kContrastGap;
    g.mode_button = {kModeButtonX, g.contrast_y, kModeButtonWidth, kContrastHeight};
    g.reset_button = {kResetButtonX, g.contrast_y, kResetButtonWidth, kContrastHeight};
    g.status_bar = {0.0f, height_ - kStatusHeight, width_, kStatusHeight};
    // The preview's row, from its right end: zoom, colour presets, colours, sizes; the text field
    // takes what is left.
    const float right = dark_x + panel_width;
    g.zoom_button = {right - kZoomButtonWidth, kPreviewRowY, kZoomButtonWidth, kPreviewRowHeight};
    g.compare_button = {g.zoom_button.x - kRowGap - kCompareButtonWidth, kPreviewRowY, kCompareButtonWidth,
                        kPreviewRowHeight};
    g.colours_button = {g.compare_button.x - kRowGap - kColoursButtonWidth, kPreviewRowY, kColoursButtonWidth,
                        kPreviewRowHeight};
    g.colours_field = {g.colours_button.x - kRowGap - kColoursFieldWidth, kPreviewRowY, kColoursFieldWidth,
                       kPreviewRowHeight};
    g.sizes_field = {g.colours_field.x - kColoursLabelWidth - kSizesFieldWidth, kPreviewRowY, kSizesFieldWidth,
                     kPreviewRowHeight};
    const float text_x = kPreviewX + kTextLabelWidth;
    g.text_field = {text_x, kPreviewRowY, g.sizes_field.x - kSizesLabelWidth - text_x, kPreviewRowHeight};
    const float rendered_y = g.contrast_y + kContrastHeight + kRenderedViewGap;
    g.rendered_view = {kPreviewX, rendered_y, dark_x + panel_width - kPreviewX,
                       std::max(kRenderedViewHeight, g.status_bar.y - 10.0f - rendered_y)};
    // Until a click chooses otherwise, the magnified view looks at the fringe test's strokes.
    if (!crop_chosen_) {
        crop_x_ = g.light_strip.x + 4.0f;
        crop_y_ = g.light_strip.y + 30.0f;
    }
    clamp_crop();
}

Rect EditorView::contrast_field(int parameter) const {
    return {kContrastFieldX[parameter], geometry_.contrast_y, kContrastFieldWidth, kContrastHeight};
}

Rect EditorView::preview_area() const {
    const Geometry& g = geometry_;
    return {g.light_panel.x, g.light_panel.y, g.dark_panel.x + g.dark_panel.width - g.light_panel.x,
            g.light_strip.y + g.light_strip.height - g.light_panel.y};
}

int EditorView::crop_columns() const {
    return static_cast<int>(geometry_.rendered_view.width / static_cast<float>(kRenderedScale));
}

int EditorView::crop_rows() const {
    const Rect area = preview_area();
    // Never taller than the preview, whose pixels it shows.
    return std::min(static_cast<int>(geometry_.rendered_view.height / static_cast<float>(kRenderedScale)),
                    static_cast<int>(area.height * scale_));
}

// The magnified area stays within the preview, in whole window pixels.
void EditorView::clamp_crop() {
    const Rect area = preview_area();
    const float columns = static_cast<float>(crop_columns()) / scale_;
    const float rows = static_cast<float>(crop_rows()) / scale_;
    crop_x_ = std::clamp(crop_x_, area.x, std::max(area.x, area.x + area.width - columns));
    crop_y_ = std::clamp(crop_y_, area.y, std::max(area.y, area.y + area.height - rows));
    crop_x_ = std::round(crop_x_ * scale_) / scale_;
    crop_y_ = std::round(crop_y_ * scale_) / scale_;
}

float EditorView::field_number(const Field& field) const {
    if (field.kind == Field::Kind::contrast) {
        return contrast_parameter(model_.contrast(), static_cast<ContrastParameter>(field.coordinate));
    }
    return rect_coordinate(model_.layout().channels[static_cast<size_t>(field.channel)], field.coordinate);
}

std::vector<EditorView::Field> EditorView::fields() const {
    std::vector<Field> out;
    for (int channel = 0; channel < 3; ++channel) {
        for (int coordinate = 0; coordinate < 4; ++coordinate) {
            out.push_back({{kFieldsX + static_cast<float>(coordinate) * kFieldStrideX,
                            kFieldsY + static_cast<float>(channel) * kFieldStrideY, kFieldWidth, kFieldHeight},
                           Field::Kind::coordinate,
                           channel,
                           coordinate});
        }
    }
    for (int parameter = 0; parameter < 3; ++parameter) {
        out.push_back({contrast_field(parameter), Field::Kind::contrast, -1, parameter});
    }
    out.push_back({geometry_.path_field, Field::Kind::path});
    out.push_back({geometry_.text_field, Field::Kind::text});
    out.push_back({geometry_.sizes_field, Field::Kind::sizes});
    out.push_back({geometry_.colours_field, Field::Kind::colours});
    return out;
}

std::string EditorView::geometry_json() const {
    crisp::JsonWriter json;
    // Window pixels, where scripted input clicks.
    auto box = [&json, this](const Rect& r) {
        json.begin_array().value(r.x * scale_).value(r.y * scale_).value(r.width * scale_);
        json.value(r.height * scale_).end_array();
    };
    auto rect = [&json, &box](std::string_view key, const Rect& r) {
        json.key(key);
        box(r);
    };
    const Geometry& g = geometry_;
    json.begin_object();
    json.key("window").begin_array().value(window_width_).value(window_height_).end_array();
    json.field("scale", scale_);
    json.key("pixel_origin").begin_array().value(kPixelOriginX * scale_).value(kPixelOriginY * scale_).end_array();
    json.field("pixel_scale", kMagnifiedPixelScale * scale_).field("edit_step", kEditStep);
    json.key("presets").begin_object();
    const auto names = subpixel_preset_names();
    for (size_t i = 0; i < names.size(); ++i) rect(names[i], preset_button(i));
    json.end_object().key("commands").begin_object();
    for (size_t i = 0; i < 4; ++i) rect(kCommands[i], command_button(i));
    json.end_object().key("fields").begin_object();
    const std::vector<Field> all = fields();
    for (const Field& field : all) {
        if (field.kind != Field::Kind::coordinate) continue;
        rect(std::string(1, "rgb"[field.channel]) + "." + kCoordinateNames[field.coordinate], field.rect);
    }
    json.end_object().key("contrast").begin_object();
    rect("mode", g.mode_button);
    for (int parameter = 0; parameter < 3; ++parameter) rect(kContrastKeys[parameter], contrast_field(parameter));
    rect("reset", g.reset_button);
    json.end_object();
    rect("path_field", g.path_field);
    rect("recent_button", g.recent_button);
    json.key("recent_rows").begin_array();
    for (size_t i = 0; i < kMaxRecentFiles; ++i) box(recent_row(i));
    json.end_array();
    json.key("preview_controls").begin_object();
    rect("text", g.text_field);
    rect("sizes", g.sizes_field);
    rect("colours", g.colours_field);
    rect("colour_presets", g.colours_button);
    rect("compare", g.compare_button);
    rect("zoom", g.zoom_button);
    json.end_object();
    json.key("candidates").begin_array();
    for (size_t i = 0; i < kMaxCandidates; ++i) box(candidate_panel(i));
    json.end_array();
    json.key("prompt").begin_object();
    rect("box", prompt_box());
    for (size_t i = 0; i < 3; ++i) rect(std::array{"save", "discard", "cancel"}[i], prompt_button(i));
    json.end_object();
    rect("magnified_pixel", {kPixelOriginX - kMagnifiedPixelScale, kPixelOriginY - kMagnifiedPixelScale,
                             3 * kMagnifiedPixelScale, 3 * kMagnifiedPixelScale});
    rect("preview", preview_area());
    // The paragraphs only: no moving text, so they change only when the layout does.
    rect("preview_paragraphs", {g.light_panel.x, g.light_panel.y, g.dark_panel.x + g.dark_panel.width - g.light_panel.x,
                                g.light_panel.height});
    rect("light_panel", g.light_panel);
    rect("dark_panel", g.dark_panel);
    rect("rendered_pixels", g.rendered_view);
    rect("status", g.status_bar);
    rect("messages", {kMargin, kMessagesY - kMessageLine, kMessageWidth, kHelpY - kMessagesY});
    rect("help", {kMargin, kHelpY - kHelpLine, kMessageWidth, 8 * kHelpLine});
    json.end_object();
    return json.text();
}

void EditorView::report(std::string text, bool error) {
    // The window may show only the start of a long message: stderr has it whole.
    std::fprintf(stderr, "crisp-layout-editor: %s\n", cli::printable(text, 4000).c_str());
    messages_.push_back({std::move(text), error});
    if (messages_.size() > 4) messages_.erase(messages_.begin());
}

void EditorView::remember(const std::string& path) {
    if (recent_file_.empty() || !write_recent_) return;
    recent_ = add_recent_file(std::move(recent_), path);
    if (Status status = write_recent_files(recent_file_, recent_); !status) {
        report("Recent files not kept: " + status.error().message, true);
    }
}

void EditorView::set_recent_file(std::filesystem::path file, bool write) {
    recent_file_ = std::move(file);
    write_recent_ = write;
    recent_.clear();
    if (recent_file_.empty()) return;
    Result<std::vector<std::string>> read = read_recent_files(recent_file_);
    if (!read) {
        report("Recent files ignored: " + read.error().message, true);
        return;
    }
    recent_ = std::move(*read);
}

void EditorView::set_preview(std::string text, std::vector<float> sizes, PreviewColours colours) {
    preview_text_ = std::move(text);
    preview_sizes_ = std::move(sizes);
    colours_ = colours;
}

void EditorView::set_zoom(int zoom) {
    if (std::find(std::begin(kZooms), std::end(kZooms), zoom) != std::end(kZooms)) zoom_ = zoom;
}

void EditorView::request_quit() {
    commit_field_edit();  // a number typed and not yet kept counts as a change
    if (prompt_on_quit_ && model_.modified()) {
        recent_open_ = false;
        prompting_ = true;
    } else {
        quit_ = true;
    }
}

bool EditorView::save() {
    if (path_.empty()) {
        report("Save: no file; type a path in the file field first", true);
        return false;
    }
    if (Status status = save_layout_file(model_.layout(), path_); !status) {
        report("Save failed: " + status.error().message, true);
        return false;
    }
    model_.mark_saved();
    report("Saved " + path_, false);
    remember(path_);
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
    remember(path_);
    return true;
}

std::string EditorView::field_text(const Field& field) const {
    switch (field.kind) {
        case Field::Kind::path:
            return path_;
        case Field::Kind::text:
            return preview_text_;
        case Field::Kind::sizes:
            return format_preview_sizes(preview_sizes_);
        case Field::Kind::colours:
            return format_preview_colours(colours_);
        default:
            return format_number(field_number(field));
    }
}

void EditorView::begin_field_edit(int index) {
    active_field_ = index;
    const Field field = fields()[static_cast<size_t>(index)];
    // All of it selected, shown so: typing replaces it, an arrow key or a click keeps it.
    edit_ = TextEdit(field_text(field));
    edit_.select_all();
    edit_scroll_ = 0;
    if (field.kind == Field::Kind::coordinate) model_.select(field.channel);
}

void EditorView::commit_field_edit() {
    if (active_field_ < 0) return;
    const Field field = fields()[static_cast<size_t>(active_field_)];
    active_field_ = -2;
    const std::string& typed = edit_.text();
    std::string why;
    switch (field.kind) {
        case Field::Kind::path:
            path_ = typed;
            return;
        case Field::Kind::text:
            preview_text_ = typed;
            return;
        case Field::Kind::sizes:
            if (std::optional<std::vector<float>> sizes = parse_preview_sizes(typed, &why); sizes) {
                preview_sizes_ = std::move(*sizes);
            } else {
                report("Sizes: \"" + cli::printable(typed) + "\" " + why, true);
            }
            return;
        case Field::Kind::colours:
            if (std::optional<PreviewColours> colours = parse_preview_colours(typed, &why); colours) {
                colours_ = *colours;
            } else {
                report("Colours: \"" + cli::printable(typed) + "\" " + why, true);
            }
            return;
        default:
            break;
    }
    const std::optional<float> value = parse_typed_number(typed, &why);
    const bool contrast = field.kind == Field::Kind::contrast;
    const std::string what = contrast
                                 ? std::string(kContrastLabels[field.coordinate])
                                 : std::string(kChannelNames[field.channel]) + " " + kCoordinateNames[field.coordinate];
    if (!value) {
        report(what + ": \"" + cli::printable(typed) + "\" " + why, true);
        return;
    }
    const Status status = contrast
                              ? model_.set_contrast_parameter(static_cast<ContrastParameter>(field.coordinate), *value)
                              : model_.set_coordinate(field.channel, field.coordinate, *value);
    if (!status) report(what + ": " + status.error().message, true);
}

void EditorView::handle(const InputEvent& window_event) {
    // Window pixels to interface pixels.
    InputEvent event = window_event;
    event.x /= static_cast<double>(scale_);
    event.y /= static_cast<double>(scale_);
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
            if (prompting_) {
                handle_prompt_key(event);
            } else {
                handle_key(event);
            }
            break;
        case InputEvent::Kind::character:
            if (prompting_ || active_field_ < 0) break;
            // The font holds ASCII and a few more: other characters only in the preview's text,
            // where one the font lacks shows as its missing-glyph box.
            if (fields()[static_cast<size_t>(active_field_)].kind == Field::Kind::text ||
                (event.codepoint >= 0x20 && event.codepoint < 0x7F)) {
                edit_.insert_codepoint(event.codepoint);
            }
            break;
    }
}

void EditorView::handle_prompt_key(const InputEvent& event) {
    if (event.key == GLFW_KEY_S) {
        prompting_ = false;
        if (save()) quit_ = true;
    } else if (event.key == GLFW_KEY_D) {
        quit_ = true;
    } else if (event.key == GLFW_KEY_ESCAPE) {
        prompting_ = false;
    }
}

bool EditorView::handle_field_key(const InputEvent& event) {
    const bool control = (event.mods & GLFW_MOD_CONTROL) != 0;
    const bool shift = (event.mods & GLFW_MOD_SHIFT) != 0;
    const Field field = fields()[static_cast<size_t>(active_field_)];
    switch (event.key) {
        case GLFW_KEY_TAB: {
            // Commits, and the next keys go to the next field (Shift: the previous one).
            const int count = static_cast<int>(fields().size());
            const int next = (active_field_ + (shift ? count - 1 : 1)) % count;
            commit_field_edit();
            begin_field_edit(next);
            return true;
        }
        case GLFW_KEY_ENTER:
        case GLFW_KEY_KP_ENTER:
            commit_field_edit();
            return true;
        case GLFW_KEY_ESCAPE:
            active_field_ = -2;  // what the field held stays
            return true;
        case GLFW_KEY_LEFT:
            edit_.left(shift);
            return true;
        case GLFW_KEY_RIGHT:
            edit_.right(shift);
            return true;
        case GLFW_KEY_HOME:
            edit_.home(shift);
            return true;
        case GLFW_KEY_END:
            edit_.end(shift);
            return true;
        case GLFW_KEY_BACKSPACE:
            edit_.backspace();
            return true;
        case GLFW_KEY_DELETE:
            edit_.erase();
            return true;
        case GLFW_KEY_UP:
        case GLFW_KEY_DOWN:
            // In the file field, the recent files in turn.
            if (field.kind == Field::Kind::path && !recent_.empty()) {
                const auto at = std::find(recent_.begin(), recent_.end(), edit_.text());
                size_t index = 0;
                if (at != recent_.end()) {
                    const size_t current = static_cast<size_t>(at - recent_.begin());
                    index = (current + (event.key == GLFW_KEY_DOWN ? 1 : recent_.size() - 1)) % recent_.size();
                }
                edit_ = TextEdit(recent_[index]);
            }
            return true;
        default:
            break;
    }
    if (control && event.key == GLFW_KEY_A) {
        edit_.select_all();
        return true;
    }
    // Ctrl+S, Ctrl+Q and the rest act on the field's text once it is committed.
    if (control) {
        commit_field_edit();
        return false;
    }
    return true;
}

void EditorView::handle_key(const InputEvent& event) {
    const bool control = (event.mods & GLFW_MOD_CONTROL) != 0;
    const bool shift = (event.mods & GLFW_MOD_SHIFT) != 0;
    if (recent_open_ && event.key == GLFW_KEY_ESCAPE) {
        recent_open_ = false;
        return;
    }
    if (active_field_ >= 0 && handle_field_key(event)) return;
    // V rather than C, which steps the contrast.
    if (!control && (event.key == GLFW_KEY_V || (comparing_ && event.key == GLFW_KEY_ESCAPE))) {
        set_compare(!comparing_ && event.key == GLFW_KEY_V);
        return;
    }
    if (comparing_ && !control && event.key >= GLFW_KEY_1 && event.key <= GLFW_KEY_4) {
        pick_candidate(static_cast<size_t>(event.key - GLFW_KEY_1));
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
        request_quit();
    } else if (!control && event.key == GLFW_KEY_Z) {
        const auto at = std::find(std::begin(kZooms), std::end(kZooms), zoom_);
        zoom_ = at + 1 == std::end(kZooms) || at == std::end(kZooms) ? kZooms[0] : *(at + 1);
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

// The prompt takes every click while it shows; the open list of recent files takes the next one.
bool EditorView::handle_overlay_click(float x, float y) {
    if (prompting_) {
        for (size_t i = 0; i < 3; ++i) {
            if (!prompt_button(i).contains(x, y)) continue;
            handle_prompt_key(
                {InputEvent::Kind::key, 0.0, 0.0, 0, std::array{GLFW_KEY_S, GLFW_KEY_D, GLFW_KEY_ESCAPE}[i]});
        }
        return true;
    }
    if (!recent_open_) return false;
    recent_open_ = false;
    for (size_t i = 0; i < recent_.size(); ++i) {
        if (!recent_row(i).contains(x, y)) continue;
        path_ = recent_[i];
        report("File: " + path_ + " (Load or Save it)", false);
    }
    return true;
}

void EditorView::handle_mouse_down(const InputEvent& event) {
    const float x = static_cast<float>(event.x), y = static_cast<float>(event.y);
    if (handle_overlay_click(x, y)) return;
    const std::vector<Field> all = fields();
    // A click in a text field puts the cursor there; in a number field it selects the number (to
    // be typed over), and a second click puts the cursor.
    for (size_t i = 0; i < all.size(); ++i) {
        const Field& field = all[i];
        if (!field.rect.contains(x, y)) continue;
        const bool number = field.kind == Field::Kind::coordinate || field.kind == Field::Kind::contrast;
        if (static_cast<int>(i) != active_field_) {
            commit_field_edit();
            begin_field_edit(static_cast<int>(i));
            if (number) return;
        }
        edit_.move_to(edit_.offset_at(x - field.rect.x - kFieldPadding, kFieldTextSize, measure_, edit_scroll_));
        return;
    }
    commit_field_edit();
    const Geometry& g = geometry_;
    if (g.recent_button.contains(x, y)) {
        recent_open_ = true;
        return;
    }
    if (g.zoom_button.contains(x, y)) {
        handle_key({InputEvent::Kind::key, 0.0, 0.0, 0, GLFW_KEY_Z});
        return;
    }
    if (g.compare_button.contains(x, y)) {
        set_compare(!comparing_);
        return;
    }
    if (comparing_) {
        for (size_t i = 0; i < candidates_.size(); ++i) {
            if (!candidate_panel(i).contains(x, y)) continue;
            pick_candidate(i);
            return;
        }
    }
    if (g.colours_button.contains(x, y)) {
        // The next preset after the colours shown (the first where they are none).
        const auto presets = preview_colour_presets();
        size_t next = 0;
        for (size_t i = 0; i < presets.size(); ++i) {
            if (presets[i].second == colours_) next = (i + 1) % presets.size();
        }
        colours_ = presets[next].second;
        return;
    }
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
    if (geometry_.mode_button.contains(x, y)) {
        model_.toggle_contrast_mode();
        return;
    }
    if (geometry_.reset_button.contains(x, y)) {
        (void)model_.set_contrast(std::nullopt);  // none is always accepted
        return;
    }
    if (start_drag(x, y)) return;
    for (const Rect& panel : {g.light_panel, g.dark_panel, g.light_strip, g.dark_strip}) {
        if (panel.contains(x, y)) {
            crop_x_ = x - static_cast<float>(crop_columns() / 2) / scale_;
            crop_y_ = y - static_cast<float>(crop_rows() / 2) / scale_;
            crop_chosen_ = true;
            clamp_crop();
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
    if (active_field_ >= 0) {
        const Rect field = fields()[static_cast<size_t>(active_field_)].rect;
        edit_scroll_ = edit_.visible(field.width - 2.0f * kFieldPadding, kFieldTextSize, measure_, edit_scroll_).first;
    }
    draw_fields(canvas, text);
    draw_contrast(canvas, text);
    draw_side_text(text);
    // An undo, a preset or an edit in compare mode: the candidates follow the edited layout.
    if (comparing_ && (candidates_.empty() || candidates_[0].layout != model_.layout())) {
        candidates_ = layout_candidates(model_.layout());
    }
    if (comparing_) {
        draw_candidates(canvas, text);
    } else {
        draw_preview(canvas, stats, text);
        draw_zoom(canvas, previous, text);
    }
    draw_preview_controls(canvas, text);
    draw_rendered_pixels(canvas, previous, text);
    draw_status(canvas, stats, text);
    if (recent_open_) draw_recent(canvas, text);
    if (prompting_) draw_prompt(canvas, text);
}

void EditorView::draw_toolbar(Canvas& canvas, std::vector<TextItem>& text) const {
    const auto names = subpixel_preset_names();
    for (size_t i = 0; i < names.size(); ++i) {
        const bool current = model_.layout().name == names[i];
        button(canvas, text, preset_button(i), std::string(names[i]), current);
    }
    const bool enabled[] = {model_.can_undo(), model_.can_redo(), true, true};
    for (size_t i = 0; i < 4; ++i) button(canvas, text, command_button(i), kCommands[i], false, enabled[i]);
    button(canvas, text, geometry_.recent_button, "Recent", recent_open_, true);
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
        const float room = field.rect.width - 2.0f * kFieldPadding;
        const float text_x = field.rect.x + kFieldPadding;
        std::string value;
        if (active) {
            // The part in view, the selection behind it and the cursor.
            const std::string_view all_text = edit_.text();
            const auto [first, last] = edit_.visible(room, kFieldTextSize, measure_, edit_scroll_);
            value = std::string(all_text.substr(first, last - first));
            const auto x_of = [&](size_t offset) {
                offset = std::clamp(offset, first, last);
                return text_x + measure_(all_text.substr(first, offset - first), kFieldTextSize);
            };
            const auto [begin, end] = edit_.selection();
            if (begin != end) {
                const float x0 = x_of(begin), x1 = x_of(end);
                canvas.fill({x0, field.rect.y + 4.0f, std::max(1.0f, x1 - x0), field.rect.height - 8.0f},
                            Color{60, 90, 150});
            }
            canvas.fill({x_of(edit_.cursor()), field.rect.y + 4.0f, 1.0f, field.rect.height - 8.0f}, kActive);
        } else if (field.kind == Field::Kind::path) {
            value = path_.empty() ? "(no file)" : path_;
        } else if (field.kind == Field::Kind::coordinate || field.kind == Field::Kind::contrast) {
            value = fitted_number(field_number(field), room, kFieldTextSize);
        } else {
            value = field_text(field);
        }
        if (!active) {
            // Text longer than the field shows its end (where a path's file name is); the
            // preview's text, its start.
            value = cli::printable(value, 1000);
            if (field.kind == Field::Kind::text && measure_(value, kFieldTextSize) > room) {
                while (!value.empty() && measure_(value + "...", kFieldTextSize) > room) value.pop_back();
                while (!value.empty() && (static_cast<unsigned char>(value.back()) & 0xC0) == 0x80) value.pop_back();
                if (!value.empty() && (static_cast<unsigned char>(value.back()) & 0x80) != 0) value.pop_back();
                value += "...";
            } else if (measure_(value, kFieldTextSize) > room) {
                const std::string_view ellipsis = "...";
                size_t start = 0;
                while (start < value.size() &&
                       measure_(std::string(ellipsis) + value.substr(start), kFieldTextSize) > room) {
                    ++start;
                }
                while (start < value.size() && (static_cast<unsigned char>(value[start]) & 0xC0) == 0x80) ++start;
                value = std::string(ellipsis) + value.substr(start);
            }
        }
        text.push_back({value, text_x, field.rect.y + 18.0f, kFieldTextSize, kPanelText});
        if (field.kind == Field::Kind::coordinate && field.coordinate == 0) {
            const bool selected = field.channel == model_.selected();
            const Rect swatch{kMargin + 6.0f, field.rect.y + 3.0f, 20.0f, 20.0f};
            canvas.fill(swatch, kChannelColors[static_cast<size_t>(field.channel)]);
            if (selected)
                canvas.outline({swatch.x - 3, swatch.y - 3, swatch.width + 6, swatch.height + 6}, kActive, 2.0f);
        }
    }
}

void EditorView::draw_contrast(Canvas& canvas, std::vector<TextItem>& text) const {
    const Geometry& g = geometry_;
    const TextContrast contrast = model_.contrast();
    const bool linear = contrast.mode == ContrastMode::linear;
    const float baseline = g.contrast_y + 18.0f;
    text.push_back({"Contrast", g.rendered_view.x, baseline, 12.0f, kDimText});
    button(canvas, text, g.mode_button, linear ? "linear" : "corrected", false);
    for (int parameter = 0; parameter < 3; ++parameter) {
        const Rect field = contrast_field(parameter);
        // The labels sit left of their fields; the parameters do nothing in linear mode.
        text.push_back({kContrastLabels[parameter], field.x - kContrastLabelWidth[parameter], baseline, 12.0f,
                        linear ? Color{120, 120, 124} : kDimText});
    }
    const bool has = model_.layout().contrast.has_value();
    button(canvas, text, g.reset_button, "Reset", false, has);
    text.push_back({has ? "the layout's own (saved with it)" : "crisp's default (the layout has none)",
                    g.reset_button.x + g.reset_button.width + 12.0f, baseline, 12.0f, kDimText});
}

void EditorView::draw_side_text(std::vector<TextItem>& text) const {
    const SubpixelLayout& layout = model_.layout();
    text.push_back({"Layout: " + cli::printable(layout.name.empty() ? "(unnamed)" : layout.name) +
                        (model_.modified() ? "  (modified)" : ""),
                    kMargin, kLayoutNameY, 13.0f, kPanelText});
    // The messages, wrapped here into the lines that fit between the name and the help, newest
    // last: older ones give way; a message with more lines than there is room for shows its
    // first lines, the last ending in "..." (every message is also on stderr, whole).
    const size_t room = static_cast<size_t>((kHelpY - kHelpLine - kMessagesY) / kMessageLine) + 1;
    std::vector<std::pair<std::string, bool>> lines;
    for (auto message = messages_.rbegin(); message != messages_.rend() && lines.size() < room; ++message) {
        std::vector<std::string> wrapped = wrap_text(cli::printable(message->text, 1000), kMessageWidth, kMessageSize);
        const size_t left = room - lines.size();
        if (wrapped.size() > left) {
            wrapped.resize(left);
            std::string& last = wrapped.back();
            while (!last.empty() && estimated_text_width(last + "...", kMessageSize) > kMessageWidth) last.pop_back();
            last += "...";
        }
        std::vector<std::pair<std::string, bool>> block;
        for (std::string& line : wrapped) block.emplace_back(std::move(line), message->error);
        lines.insert(lines.begin(), block.begin(), block.end());
    }
    float y = kMessagesY;
    for (const auto& [line, error] : lines) {
        text.push_back({line, kMargin, y, kMessageSize, error ? kErrorText : kDimText});
        y += kMessageLine;
    }
    const char* help[] = {
        "Drag an edge or a rectangle in the magnified pixel.",
        "Arrows nudge the selected one 1/96 px (Shift: 1/12).",
        "Tab: next channel. Click a field to edit: Home, End, Ctrl+A;",
        "Enter keeps, Esc restores, Tab moves on; Up: recent files.",
        "Ctrl+Z/Y undo/redo, Ctrl+S save, Ctrl+O load, Ctrl+Q quit.",
        "Click the preview to magnify it; Z zooms; V compares.",
        "G, C, D raise gamma, contrast, stem darkening by 0.1,",
        "with Shift lower them; M: linear or corrected.",
    };
    y = kHelpY;
    for (const char* line : help) {
        text.push_back({line, kMargin, y, kHelpSize, kDimText});
        y += kHelpLine;
    }
}

void EditorView::draw_preview(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const {
    const Geometry& g = geometry_;
    Rect zoomed{}, zoom_source{};
    const bool zooming = zoom_target(zoomed, zoom_source);
    // The first panel shows the colours as chosen, the second swapped: both polarities in view.
    const std::pair<Rect, PreviewColours> panels[] = {{g.light_panel, colours_},
                                                      {g.dark_panel, {colours_.background, colours_.foreground}}};
    for (const auto& [panel, colours] : panels) {
        const bool light = panel.x == g.light_panel.x;
        const Color ink = colours.foreground;
        canvas.fill(panel, colours.background);
        const bool covered = zooming && zoomed.x == panel.x;
        // Each size's paragraph below the last, as many lines as fit in the panel; wrap_text's
        // estimate is never narrower than the text, so its count of lines is never too few.
        float top = panel.y + 6.0f;
        const float bottom = panel.y + panel.height - 4.0f;
        for (const float size : preview_sizes_) {
            const float line = size * 1.17f;  // DejaVu Sans's line height
            const float wrap = panel.width - 20.0f;
            const auto fit = static_cast<uint32_t>(std::max(0.0f, std::floor((bottom - top) / line)));
            if (fit == 0) break;
            const auto lines = static_cast<uint32_t>(
                std::min<size_t>(fit, std::max<size_t>(1, wrap_text(preview_text_, wrap, size).size())));
            TextItem item{preview_text_, panel.x + 10.0f, top + size * 0.93f, size, ink, wrap, true};
            item.max_lines = fit;
            if (!covered) text.push_back(std::move(item));
            top += static_cast<float>(lines) * line + 8.0f;
        }
        const Rect strip = light ? g.light_strip : g.dark_strip;
        canvas.fill(strip, colours.background);
        // A line moving 1/16 px a frame while the preview converges: a new subpixel offset, and
        // new samples, every frame; then it stops, so that the editor can idle.
        const float shift = stats.line_moving ? static_cast<float>(stats.frame % 16) / 16.0f : 0.0f;
        text.push_back({"Moving by 1/16 px a frame: Illegible 111 lll", strip.x + 10.0f + shift, strip.y + 20.0f, 13.0f,
                        ink, 0.0f, true, stats.line_moving});
        // The fringe test: thin vertical, horizontal and diagonal strokes.
        text.push_back({"||||||||  \u2014\u2014\u2014\u2014  ////////  \\\\\\\\\\\\\\\\  =====  xxxx", strip.x + 10.0f,
                        strip.y + 50.0f, 14.0f, ink, 0.0f, true});
        text.push_back({"|| || ||  \u2014 \u2014 \u2014  // // //  \\\\ \\\\ \\\\  il1|  mwWM", strip.x + 10.0f,
                        strip.y + 78.0f, 11.0f, ink, 0.0f, true});
    }
    // Where the magnified view of rendered pixels looks, just outside the area it shows.
    const float one = 1.0f / scale_;
    canvas.outline({crop_x_ - one, crop_y_ - one, static_cast<float>(crop_columns()) / scale_ + 2.0f * one,
                    static_cast<float>(crop_rows()) / scale_ + 2.0f * one},
                   kActive, one);
    if (zooming) {
        canvas.outline(
            {zoom_source.x - one, zoom_source.y - one, zoom_source.width + 2.0f * one, zoom_source.height + 2.0f * one},
            Color{90, 150, 255}, one);
    }
}

void EditorView::set_compare(bool on) {
    comparing_ = on;
    candidates_ = on ? layout_candidates(model_.layout()) : std::vector<Candidate>{};
}

void EditorView::pick_candidate(size_t i) {
    if (i >= candidates_.size()) return;
    const Candidate picked = candidates_[i];
    if (Status status = model_.pick(picked); !status) {
        report("Pick failed: " + status.error().message, true);
        return;
    }
    report("Picked " + std::to_string(i + 1) + ": " + picked.label + " (" + picked.layout.name + ")", false);
    candidates_ = layout_candidates(model_.layout());
}

Rect EditorView::candidate_panel(size_t i) const {
    const Rect area = preview_area();
    const float gap = kPreviewGap;
    const float width = (area.width - gap) / 2.0f, height = (area.height - gap) / 2.0f;
    return {area.x + static_cast<float>(i % 2) * (width + gap), area.y + static_cast<float>(i / 2) * (height + gap),
            width, height};
}

// Each candidate's panel: its number and label, then the preview's text at its smallest, middle
// and largest size, two lines each at most, in the first panel's colours. Few glyphs: four
// renderers converge together on lavapipe.
void EditorView::draw_candidates(Canvas& canvas, std::vector<TextItem>& text) const {
    std::vector<float> sizes = {preview_sizes_.front(), preview_sizes_[preview_sizes_.size() / 2],
                                preview_sizes_.back()};
    sizes.erase(std::unique(sizes.begin(), sizes.end()), sizes.end());
    for (size_t i = 0; i < kMaxCandidates; ++i) {
        const Rect panel = candidate_panel(i);
        if (i >= candidates_.size()) {
            canvas.fill(panel, Color{30, 31, 34});
            continue;
        }
        const Candidate& candidate = candidates_[i];
        canvas.fill(panel, colours_.background);
        canvas.fill({panel.x, panel.y, panel.width, 22.0f}, kButton);
        if (i == 0) canvas.outline(panel, kActive);
        const std::string label =
            std::to_string(i + 1) + "  " + candidate.label + ": " + candidate.layout.name +
            (i == 0 ? "  (the edited layout)" : "  (click or " + std::to_string(i + 1) + " to pick)");
        text.push_back({label, panel.x + 8.0f, panel.y + 16.0f, 12.0f, kPanelText});
        float top = panel.y + 28.0f;
        const float bottom = panel.y + panel.height - 4.0f;
        for (const float size : sizes) {
            const float line = size * 1.17f;
            const auto fit = static_cast<uint32_t>(std::max(0.0f, std::floor((bottom - top) / line)));
            if (fit == 0) break;
            const float wrap = panel.width - 20.0f;
            const uint32_t lines = std::min<uint32_t>(
                {fit, 2u, static_cast<uint32_t>(std::max<size_t>(1, wrap_text(preview_text_, wrap, size).size()))});
            TextItem item{preview_text_, panel.x + 10.0f, top + size * 0.93f, size, colours_.foreground, wrap};
            item.max_lines = lines;
            item.candidate = static_cast<int>(i);
            text.push_back(std::move(item));
            top += static_cast<float>(lines) * line + 6.0f;
        }
    }
}

bool EditorView::zoom_target(Rect& target, Rect& source) const {
    if (zoom_ == 1) return false;
    const Geometry& g = geometry_;
    // The magnified area is centred where the magnified view of rendered pixels looks; it covers
    // the other side's panel.
    const float centre_x = crop_x_ + static_cast<float>(crop_columns()) / scale_ / 2.0f;
    const float centre_y = crop_y_ + static_cast<float>(crop_rows()) / scale_ / 2.0f;
    const bool from_light = centre_x < g.dark_panel.x;
    target = from_light ? g.dark_panel : g.light_panel;
    const Rect panel = from_light ? g.light_panel : g.dark_panel;
    const Rect side{panel.x, panel.y, panel.width, g.light_strip.y + g.light_strip.height - panel.y};
    // Whole window pixels of the source, each zoom_ window pixels in the target.
    const float k = static_cast<float>(zoom_);
    const float width = std::floor(target.width * scale_ / k) / scale_;
    const float height = std::floor(target.height * scale_ / k) / scale_;
    float x = std::clamp(centre_x - width / 2.0f, side.x, side.x + side.width - width);
    float y = std::clamp(centre_y - height / 2.0f, side.y, side.y + side.height - height);
    x = std::ceil(x * scale_) / scale_;
    y = std::ceil(y * scale_) / scale_;
    source = {x, y, width, height};
    return true;
}

void EditorView::draw_zoom(Canvas& canvas, std::span<const uint8_t> previous, std::vector<TextItem>& text) const {
    Rect target{}, source{};
    if (!zoom_target(target, source)) return;
    char caption[96];
    std::snprintf(caption, sizeof caption, "x%d, nearest neighbour: the blue outline's pixels", zoom_);
    const size_t columns = static_cast<size_t>(std::lround(source.width * scale_));
    const size_t rows = static_cast<size_t>(std::lround(source.height * scale_));
    if (previous.size() == size_t{window_width_} * window_height_ * 4) {
        const size_t left = static_cast<size_t>(std::lround(source.x * scale_));
        const size_t top = static_cast<size_t>(std::lround(source.y * scale_));
        const float cell = static_cast<float>(zoom_) / scale_;
        for (size_t row = 0; row < rows && top + row < window_height_; ++row) {
            for (size_t column = 0; column < columns && left + column < window_width_; ++column) {
                const size_t at = ((top + row) * window_width_ + left + column) * 4;
                canvas.fill({target.x + static_cast<float>(column) * cell, target.y + static_cast<float>(row) * cell,
                             cell, cell},
                            Color{previous[at], previous[at + 1], previous[at + 2]});
            }
        }
    }
    const Rect label{target.x, target.y + target.height - 20.0f, estimated_text_width(caption, 11.0f) + 12.0f, 20.0f};
    canvas.fill(label, Color{24, 25, 28});
    text.push_back({caption, label.x + 6.0f, label.y + 14.0f, 11.0f, kPanelText});
}

void EditorView::draw_preview_controls(Canvas& canvas, std::vector<TextItem>& text) const {
    const Geometry& g = geometry_;
    const float baseline = kPreviewRowY + 17.0f;
    text.push_back({"Text", kPreviewX, baseline, 12.0f, kDimText});
    text.push_back({"sizes", g.sizes_field.x - kSizesLabelWidth + 2.0f, baseline, 12.0f, kDimText});
    text.push_back({"colours", g.colours_field.x - kColoursLabelWidth + 4.0f, baseline, 12.0f, kDimText});
    const Rect presets = g.colours_button, zoom = g.zoom_button;
    canvas.fill(presets, kButton);
    canvas.outline(presets, kButtonBorder);
    text.push_back({"Presets", presets.x + 8.0f, baseline, 12.0f, kPanelText});
    canvas.fill(zoom, zoom_ > 1 ? Color{92, 84, 52} : kButton);
    canvas.outline(zoom, zoom_ > 1 ? kActive : kButtonBorder);
    text.push_back({"Zoom " + std::to_string(zoom_) + "x", zoom.x + 8.0f, baseline, 12.0f, kPanelText});
    const Rect compare = g.compare_button;
    canvas.fill(compare, comparing_ ? Color{92, 84, 52} : kButton);
    canvas.outline(compare, comparing_ ? kActive : kButtonBorder);
    text.push_back({"Compare", compare.x + 8.0f, baseline, 12.0f, kPanelText});
}

Rect EditorView::recent_row(size_t i) const {
    const Rect button = geometry_.recent_button;
    const float width = std::min(kRecentWidth, width_ - 2.0f * kMargin);
    return {button.x + button.width - width, button.y + button.height + 2.0f + static_cast<float>(i) * kRecentRow,
            width, kRecentRow};
}

Rect EditorView::prompt_box() const {
    return {std::floor((width_ - kPromptWidth) / 2.0f), std::floor((height_ - kPromptHeight) / 2.0f), kPromptWidth,
            kPromptHeight};
}

Rect EditorView::prompt_button(size_t i) const {
    const Rect box = prompt_box();
    const float gap = (kPromptWidth - 3.0f * kPromptButtonWidth) / 4.0f;
    return {box.x + gap + static_cast<float>(i) * (kPromptButtonWidth + gap), box.y + box.height - 44.0f,
            kPromptButtonWidth, kButtonHeight};
}

// A box over the rest: the text beneath it is left out (crisp draws text over the canvas).
void EditorView::draw_overlay(Canvas& canvas, const Rect& area, std::vector<TextItem>& text) const {
    std::erase_if(text, [&area](const TextItem& item) { return overlaps(item_box(item), area); });
    canvas.fill(area, Color{30, 32, 36});
    canvas.outline(area, kActive);
}

void EditorView::draw_recent(Canvas& canvas, std::vector<TextItem>& text) const {
    const size_t rows = std::max<size_t>(1, recent_.size());
    const Rect first = recent_row(0);
    draw_overlay(canvas, {first.x, first.y, first.width, static_cast<float>(rows) * kRecentRow}, text);
    if (recent_.empty()) {
        text.push_back(
            {"No recent files yet: they are those saved or loaded", first.x + 8.0f, first.y + 17.0f, 12.0f, kDimText});
        return;
    }
    for (size_t i = 0; i < recent_.size(); ++i) {
        const Rect row = recent_row(i);
        std::string shown = cli::printable(recent_[i], 1000);
        while (shown.size() > 4 && measure_(shown, 12.0f) > row.width - 16.0f) shown.erase(0, 1);
        text.push_back({shown, row.x + 8.0f, row.y + 17.0f, 12.0f, recent_[i] == path_ ? kActive : kPanelText});
    }
}

void EditorView::draw_prompt(Canvas& canvas, std::vector<TextItem>& text) const {
    const Rect box = prompt_box();
    draw_overlay(canvas, box, text);
    text.push_back({"Save changes?", box.x + 16.0f, box.y + 28.0f, 16.0f, kPanelText});
    std::string file = path_.empty() ? "(no file: type a path first)" : cli::printable(path_, 1000);
    while (file.size() > 4 && measure_("The layout is modified. File: " + file, 12.0f) > box.width - 32.0f) {
        file.erase(0, 1);
    }
    text.push_back({"The layout is modified. File: " + file, box.x + 16.0f, box.y + 52.0f, 12.0f, kDimText});
    for (size_t i = 0; i < 3; ++i) button(canvas, text, prompt_button(i), kPromptButtons[i], i == 0);
}

void EditorView::draw_rendered_pixels(Canvas& canvas, std::span<const uint8_t> previous,
                                      std::vector<TextItem>& text) const {
    const Rect view = geometry_.rendered_view;
    text.push_back(
        {"The outlined preview pixels, x8, lighting this layout's subpixels", view.x, view.y - 6.0f, 12.0f, kDimText});
    canvas.fill(view, Color{0, 0, 0});
    if (previous.size() != size_t{window_width_} * window_height_ * 4) return;
    const SubpixelLayout& layout = model_.layout();
    const float s = static_cast<float>(kRenderedScale);
    // The crop's top-left in window pixels (clamp_crop keeps it whole and inside the window).
    const size_t left = static_cast<size_t>(std::lround(crop_x_ * scale_));
    const size_t top = static_cast<size_t>(std::lround(crop_y_ * scale_));
    const int columns = crop_columns(), rows = crop_rows();
    for (int py = 0; py < rows; ++py) {
        const size_t row = top + static_cast<size_t>(py);
        if (row >= window_height_) break;
        for (int px = 0; px < columns; ++px) {
            const size_t column = left + static_cast<size_t>(px);
            if (column >= window_width_) break;
            const size_t source = (row * window_width_ + column) * 4;
            const float cell_x = view.x + static_cast<float>(px) * s;
            const float cell_y = view.y + static_cast<float>(py) * s;
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
    const Rect bar = geometry_.status_bar;
    canvas.fill(bar, Color{24, 25, 28});
    char line[384];
    const char* state = stats.glyphs == 0                           ? "no glyphs yet"
                        : stats.min_samples >= stats.target_samples ? "converged"
                                                                    : "converging";
    char gpu[32] = "GPU -";
    if (stats.gpu_ms >= 0.0) std::snprintf(gpu, sizeof gpu, "GPU %.2f ms/frame", stats.gpu_ms);
    // A window too small for the interface at the monitor's scale is drawn smaller: say so.
    char small[96] = "";
    if (scale_ < content_scale_ * 0.999f) {
        std::snprintf(small, sizeof small, "   window below %.0f x %.0f: drawn at %.0f%%",
                      static_cast<double>(kMinimumWidth * content_scale_),
                      static_cast<double>(kMinimumHeight * content_scale_), static_cast<double>(scale_) * 100.0);
    }
    std::snprintf(
        line, sizeof line,
        "frame %llu   samples per glyph %u to %u of %u (%s)   atlas %.1f%% occupied   %s   %u preview glyphs%s",
        static_cast<unsigned long long>(stats.frame), stats.min_samples, stats.max_samples, stats.target_samples, state,
        static_cast<double>(stats.atlas_occupancy) * 100.0, gpu, stats.glyphs, small);
    TextItem item{line, kMargin, bar.y + 22.0f, 13.0f, kPanelText};
    item.live = true;
    text.push_back(std::move(item));
}

}  // namespace crisp::editor
