// crisp-layout-editor: what the window shows and how input edits the layout. Every widget sits
// at a fixed position in a 1280 x 800 window (geometry_json() lists them, for scripted input).
// The view draws the panels and widgets on the CPU canvas and lists the text crisp draws on top.
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

inline constexpr uint32_t kWindowWidth = 1280;
inline constexpr uint32_t kWindowHeight = 800;
// The magnified pixel: screen pixels per pixel, and where the centre pixel's top-left corner is.
inline constexpr float kMagnifiedPixelScale = 96.0f;
inline constexpr float kPixelOriginX = 136.0f;
inline constexpr float kPixelOriginY = 160.0f;
// The magnified view of rendered pixels: screen pixels per rendered pixel.
inline constexpr uint32_t kRenderedScale = 8;

// A run of text for crisp to draw: a baseline origin in window pixels, sRGB colour.
struct TextItem {
    std::string text;
    float x = 0.0f, y = 0.0f;
    float size = 13.0f;
    Color color{};
    float wrap_width = 0.0f;
    bool preview = false;  // drawn with the edited layout (else with the interface's gray one)
    bool moving = false;   // moves every frame, so it never converges
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
};

struct Message {
    std::string text;
    bool error = false;
};

class EditorView {
public:
    EditorView(LayoutModel& model, std::filesystem::path path);

    // Applies one input event to the model and the view's own state (fields, file, crop).
    void handle(const InputEvent& event);

    // Draws the frame's CPU part into `canvas` and lists its text into `text`. `previous` is the
    // last composited frame (kWindowWidth x kWindowHeight RGBA8, sRGB), for the magnified view of
    // rendered pixels; empty before the first frame has completed.
    void draw(Canvas& canvas, std::span<const uint8_t> previous, const FrameStats& stats, std::vector<TextItem>& text);

    // Saves to / loads from the file field's path, reporting in the message list.
    bool save();
    bool load();
    void report(std::string text, bool error);

    // Ctrl+Q was pressed.
    bool quit_requested() const { return quit_; }

    // The widgets' positions, as JSON, for scripts that drive the window.
    static std::string geometry_json();

private:
    struct Field {
        Rect rect;
        int channel = -1;  // -1: the file path field; 3: a contrast parameter (ContrastParameter)
        int coordinate = 0;
    };
    std::vector<Field> fields() const;
    std::string field_value(const Field& field) const;  // a number field's value, formatted
    void begin_field_edit(int index);
    void commit_field_edit();
    void handle_key(const InputEvent& event);
    void handle_mouse_down(const InputEvent& event);
    bool start_drag(float x, float y);

    void draw_toolbar(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_magnified_pixel(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_fields(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_contrast(Canvas& canvas, std::vector<TextItem>& text) const;
    void draw_side_text(std::vector<TextItem>& text) const;
    void draw_preview(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const;
    void draw_rendered_pixels(Canvas& canvas, std::span<const uint8_t> previous, std::vector<TextItem>& text) const;
    void draw_status(Canvas& canvas, const FrameStats& stats, std::vector<TextItem>& text) const;

    LayoutModel& model_;
    std::string path_;
    std::vector<Message> messages_;
    int active_field_ = -2;  // index into fields(); -2: none
    std::string field_text_;
    bool field_fresh_ = false;  // nothing typed since the field was clicked
    float drag_x_ = 0.0f, drag_y_ = 0.0f;
    // Top-left of the preview area shown magnified, window pixels.
    int crop_x_ = 0, crop_y_ = 0;
    bool quit_ = false;
};

}  // namespace crisp::editor
