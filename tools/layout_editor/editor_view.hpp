// crisp-layout-editor: what the window shows and how input edits the layout. The widgets are laid
// out in interface pixels for the window's size (resize()): the left column keeps its place, the
// preview, the magnified rendered pixels and the file field grow with the window, the status line
// stays at the bottom. An interface pixel is the monitor's content scale in window pixels, less
// in a window smaller than kMinimumWidth x kMinimumHeight interface pixels, where everything is
// drawn smaller (and the status line says so) rather than cropped. geometry_json() lists the
// widgets in window pixels, for scripted input. The view draws the panels and widgets on the CPU
// canvas and lists the text crisp draws on top.
#pragma once

#include "canvas.hpp"
#include "editor_model.hpp"
#include "vulkan_window.hpp"

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace crisp::editor {

// The starting window, in interface pixels, and the smallest that the widgets fit in.
inline constexpr uint32_t kWindowWidth = 1280;
inline constexpr uint32_t kWindowHeight = 800;
inline constexpr float kMinimumWidth = 1280.0f;
inline constexpr float kMinimumHeight = 800.0f;
// The magnified pixel: interface pixels per pixel, and where the centre pixel's top-left corner is.
inline constexpr float kMagnifiedPixelScale = 96.0f;
inline constexpr float kPixelOriginX = 136.0f;
inline constexpr float kPixelOriginY = 160.0f;
// The magnified view of rendered pixels: interface pixels per rendered pixel.
inline constexpr uint32_t kRenderedScale = 8;

// A run of text for crisp to draw: a baseline origin, size and wrap width in interface pixels
// (the frame loop scales them to window pixels), sRGB colour.
struct TextItem {
    std::string text;
    float x = 0.0f, y = 0.0f;
    float size = 13.0f;
    Color color{};
    float wrap_width = 0.0f;
    bool preview = false;    // drawn with the edited layout (else with the interface's gray one)
    bool moving = false;     // moves every frame while the preview converges
    bool live = false;       // changes every frame (the status line): left out of settling
    uint32_t max_lines = 0;  // wrapped text: lines past this many are left out; 0: all
    int candidate = -1;      // compare mode: drawn with this candidate's layout (else as `preview` says)
};

// What the status line reports, measured by the frame loop.
struct FrameStats {
    uint64_t frame = 0;
    uint32_t glyphs = 0;       // preview glyphs drawn with samples
    uint32_t min_samples = 0;  // samples per glyph over the preview's glyphs
    uint32_t max_samples = 0;
    uint32_t target_samples = 0;
    float atlas_occupancy = 0.0f;  // the preview atlas, 0..1
    double gpu_ms = 0.0;           // last completed frame, timestamps; negative: not measured
    bool line_moving = true;       // the preview's moving line still moves
};

struct Message {
    std::string text;
    bool error = false;
};

class EditorView {
public:
    // Laid out for a kWindowWidth x kWindowHeight window at scale 1 until resize().
    EditorView(LayoutModel& model, std::filesystem::path path);

    // Lays the widgets out for a window of width x height window pixels on a monitor whose
    // content scale is `content_scale` (window pixels per interface pixel; 1 where unknown). A
    // zero size (a minimized window) or a scale that is not positive keeps the layout as it is.
    void resize(uint32_t width, uint32_t height, float content_scale);
    // Window pixels per interface pixel: the content scale, or less in a small window.
    float scale() const { return scale_; }

    // Applies one input event (positions in window pixels) to the model and the view's own state
    // (fields, file, crop).
    void handle(const InputEvent& event);

    // Draws the frame's CPU part into `canvas` (the window's size, at scale()) and lists its text
    // into `text`. `previous` is the last composited frame (the window's size, RGBA8, sRGB), for
    // the magnified view of rendered pixels; empty before the first frame has completed, or when
    // it is not the size of the window.
    void draw(Canvas& canvas, std::span<const uint8_t> previous, const FrameStats& stats, std::vector<TextItem>& text);

    // Saves to / loads from the file field's path, reporting in the message list.
    bool save();
    bool load();
    void report(std::string text, bool error);

    // Quitting: Ctrl+Q, or the window's close button (the frame loop calls request_quit()). With
    // unsaved changes (and prompt_on_quit) the window asks "Save changes?" first: S saves and
    // quits (a failed save keeps the editor open, the failure shown), D quits, Escape cancels.
    void request_quit();
    bool quit_requested() const { return quit_; }
    bool prompting() const { return prompting_; }
    // False for scripted runs (--frames): they quit at once.
    void set_prompt_on_quit(bool prompt) { prompt_on_quit_ = prompt; }

    // How the window measures text (crisp's layout of its font); estimated_text_width until set.
    void set_measure(MeasureText measure) { measure_ = std::move(measure); }

    // The recent files' list (recent_files_path()): read now, a bad file reported and ignored;
    // with `write`, written on every save and load. An empty path keeps no list.
    void set_recent_file(std::filesystem::path file, bool write);
    const std::vector<std::string>& recent_files() const { return recent_; }
    // Puts `path` first in the list and writes it (a failure reported); nothing without a list.
    void remember(const std::string& path);

    // The preview's text, sizes and colours (--text, --sizes, --colours), as checked by
    // parse_preview_sizes and parse_preview_colours.
    void set_preview(std::string text, std::vector<float> sizes, PreviewColours colours);
    // The preview's zoom: 1, 2 or 4 (Z cycles them); others are ignored.
    void set_zoom(int zoom);

    // Compare mode (V, the Compare button, --compare): the preview shows layout_candidates() of
    // the edited layout side by side, each panel with its own renderer; a click on a panel or
    // keys 1 to 4 pick one (LayoutModel::pick) and the candidates are made again around it.
    // Escape or V leaves.
    void set_compare(bool on);
    bool comparing() const { return comparing_; }
    // The candidates shown (the frame loop gives each its renderer); empty when not comparing.
    const std::vector<Candidate>& candidates() const { return candidates_; }
    // Picks candidate i (reported in the messages); an index with no candidate is ignored.
    void pick_candidate(size_t i);

    // The widgets' positions in window pixels, as JSON, for scripts that drive the window.
    std::string geometry_json() const;

    // Interface pixels per window.
    float width() const { return width_; }
    float height() const { return height_; }

private:
    struct Field {
        enum class Kind : uint8_t { coordinate, contrast, path, text, sizes, colours };
        Rect rect;
        Kind kind = Kind::coordinate;
        int channel = -1;    // Kind::coordinate: the channel
        int coordinate = 0;  // Kind::coordinate: rect_coordinate's; Kind::contrast: the ContrastParameter
    };
    std::string field_text(const Field& field) const;  // what a field shows when not being edited
    std::vector<Field> fields() const;
    float field_number(const Field& field) const;  // a number field's value
    void begin_field_edit(int index);
    void commit_field_edit();
    void handle_key(const InputEvent& event);
    bool handle_field_key(const InputEvent& event);
    void handle_prompt_key(const InputEvent& event);
    bool handle_overlay_click(float x, float y);
    void handle_mouse_down(const InputEvent& event);
    bool start_drag(float x, float y);

    void draw_toolbar(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_magnified_pixel(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_fields(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_contrast(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_side_text(std::vector<TextItem>& text) const;
    void draw_preview(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const;
    void draw_candidates(Canvas& canvas, std::vector<TextItem>& text) const;
    // Compare mode's panel i of kMaxCandidates, two by two over preview_area().
    Rect candidate_panel(size_t i) const;
    void draw_rendered_pixels(Canvas& canvas, std::span<const uint8_t> previous, std::vector<TextItem>& text) const;
    void draw_status(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const;
    void draw_preview_controls(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_zoom(Canvas& canvas, std::span<const uint8_t> previous, std::vector<TextItem>& text) const;
    void draw_overlay(Canvas& canvas, const Rect& area, std::vector<TextItem>& text) const;
    void draw_recent(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_prompt(Canvas& canvas, std::vector<TextItem>& text) const;

    // Where the widgets that move with the window's size are, interface pixels.
    struct Geometry {
        Rect path_field, recent_button;
        Rect text_field, sizes_field, colours_field, colours_button, compare_button, zoom_button;
        Rect light_panel, dark_panel, light_strip, dark_strip;
        float contrast_y = 0.0f;
        Rect mode_button, reset_button;
        Rect rendered_view;
        Rect status_bar;
    };
    Rect contrast_field(int parameter) const;
    Rect preview_area() const;  // the panels and strips
    Rect recent_row(size_t i) const;
    Rect prompt_box() const;
    Rect prompt_button(size_t i) const;  // 0 Save, 1 Discard, 2 Cancel
    // Zoomed: the panel the magnified preview covers, and the area of the other side it shows.
    bool zoom_target(Rect& target, Rect& source) const;
    // The rendered pixels the magnified view shows: columns and rows.
    int crop_columns() const;
    int crop_rows() const;
    void clamp_crop();

    LayoutModel& model_;
    Geometry geometry_;
    uint32_t window_width_ = kWindowWidth, window_height_ = kWindowHeight;
    float width_ = static_cast<float>(kWindowWidth), height_ = static_cast<float>(kWindowHeight);
    float scale_ = 1.0f;
    float content_scale_ = 1.0f;
    std::string path_;
    std::vector<Message> messages_;
    int active_field_ = -2;   // index into fields(); -2: none
    TextEdit edit_;           // the active field's text
    size_t edit_scroll_ = 0;  // its first byte shown (kept by draw())
    MeasureText measure_ = estimated_text_width;
    std::filesystem::path recent_file_;
    std::vector<std::string> recent_;
    bool write_recent_ = false;
    bool recent_open_ = false;
    bool prompting_ = false;
    bool prompt_on_quit_ = true;
    std::string preview_text_ = kDefaultPreviewText;
    std::vector<float> preview_sizes_ = {9.0f, 11.0f, 13.0f, 16.0f, 20.0f};
    PreviewColours colours_;
    int zoom_ = 1;
    bool comparing_ = false;
    std::vector<Candidate> candidates_;
    float drag_x_ = 0.0f, drag_y_ = 0.0f;
    // Top-left of the preview area shown magnified, interface pixels.
    float crop_x_ = 0.0f, crop_y_ = 0.0f;
    bool crop_chosen_ = false;  // by a click; else it follows the strip as the window is resized
    bool quit_ = false;
};

}  // namespace crisp::editor
