// crisp-layout-editor: the edited subpixel layout (with the monitor's contrast settings), the
// selected channel and the undo history.
// No window, no GPU: tests/test_layout_editor_model.cpp drives it directly.
#pragma once

#include <crisp/contrast.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace crisp::editor {

// One step of a nudge or a drag, in pixel units: one screen pixel of the magnified pixel view
// (kMagnifiedPixelScale screen pixels per pixel), so a drag and an arrow key move by the same grid.
inline constexpr float kEditStep = 1.0f / 96.0f;
// The smallest width or height a rectangle can be dragged or nudged to.
inline constexpr float kMinRectSize = kEditStep;

// One step of a contrast parameter, by key.
inline constexpr float kContrastStep = 0.1f;

// The contrast parameters the editor sets, by index.
enum class ContrastParameter : uint8_t { gamma, contrast, stem_darkening };

// A parameter's value, and its range (validate_text_contrast's).
float contrast_parameter(const TextContrast& contrast, ContrastParameter parameter);
std::pair<float, float> contrast_range(ContrastParameter parameter);

// What a drag grabs: one edge of a channel's rectangle, or the whole rectangle.
enum class Handle : uint8_t { left, top, right, bottom, body };

// The --layout argument: a preset by name, else a layout file (load_subpixel_layout_file's
// errors). Where no such file exists either, the error also lists the presets, since a mistyped
// preset name ends up here.
Result<SubpixelLayout> load_layout_argument(std::string_view preset_or_file);

// A number typed into a field: a decimal as cli::parse_number<float> reads it ("0.25", "-1e-3"),
// or a fraction of two such numbers ("1/3", "-2/3", spaces allowed around the slash), divided in
// double and rounded once to float. Anything else, a zero denominator and a quotient past float's
// range are nullopt, with the reason in `why` ("is not a number", "divides by zero").
std::optional<float> parse_typed_number(std::string_view text, std::string* why = nullptr);

// The four numbers of a SampleRect by index: 0 x0, 1 y0, 2 x1, 3 y1.
float rect_coordinate(const SampleRect& rect, int coordinate);

// A value within 1/1000 of a step of the kEditStep grid becomes the float nearest that grid
// value (k / 96 divided in double): sums of float steps drift off the grid (0.5 plus three steps
// is 0.53125006), the grid value itself is exact wherever it can be (0.53125). Others are kept.
float snap_to_grid_if_near(float value);

// A number as a field shows it and a file stores it: the shortest text that reads back as the
// same float ("0.95", "0.53125", "-0.083333336"), never an exponent for values the editor takes.
std::string format_number(float value);

// How wide `text` is at `size` pixels, at most, in DejaVu Sans (the default font): its advances
// per character class, rounded up (digits 0.64 em, lowercase 0.65, capitals 0.8, m, w, M, W and
// anything not ASCII 1). Fields and messages are fitted with it, so what they show stays inside their boxes.
float estimated_text_width(std::string_view text, float size);

// `value` as a field `width` pixels wide shows it at `size` pixels: format_number's form where it
// fits, else rounded to as many decimals as fit ("-0.08333" for -0.083333336 in 56 pixels at 12).
std::string fitted_number(float value, float width, float size);

// `text` in lines no wider than `width` at `size` (estimated_text_width), broken at spaces, a word
// too long for a line broken within it. Every character is kept: the lines joined with the spaces
// they were broken at give `text` back. No lines for an empty text.
std::vector<std::string> wrap_text(std::string_view text, float width, float size);

// The layout as a layout file holds it (the format of docs/subpixel.md, which
// load_subpixel_layout_file reads), every number in format_number's shortest form.
std::string layout_file_text(const SubpixelLayout& layout);
// Writes layout_file_text atomically. Refused (invalid_argument) when validate_subpixel_layout
// refuses the layout; the file's errors are crisp's (ErrorCode::io, naming the path).
Status save_layout_file(const SubpixelLayout& layout, const std::filesystem::path& path);

class LayoutModel {
public:
    explicit LayoutModel(SubpixelLayout initial);

    const SubpixelLayout& layout() const { return layout_; }
    // Counts every change of the layout (edits, contrast, undo, redo, presets, loads): the frame
    // loop hands the renderer what moved (a new layout restarts its sample schedule).
    uint64_t revision() const { return revision_; }

    int selected() const { return selected_; }
    void select(int channel);  // 0 red, 1 green, 2 blue; others are ignored

    // Sets one coordinate (see rect_coordinate) of a channel to a typed number. Refused
    // (invalid_argument, the layout unchanged) when the result fails validate_subpixel_layout;
    // the message is crisp's.
    Status set_coordinate(int channel, int coordinate, float value);

    // Moves the selected rectangle by (dx, dy) edit steps, stopping at the bounds
    // [-kGlyphPadding, 1 + kGlyphPadding]. One undo step.
    void nudge(int dx_steps, int dy_steps);

    // A drag: begin_drag() remembers the rectangle, drag_to() moves the grabbed edge (or the
    // whole rectangle) by (dx, dy) pixels from where it was at begin_drag(), snapped to
    // kEditStep, kept within the bounds and at least kMinRectSize wide and tall; end_drag() makes
    // the whole drag one undo step (none when nothing changed).
    void begin_drag(int channel, Handle handle);
    void drag_to(float dx, float dy);
    void end_drag();
    bool dragging() const { return drag_channel_ >= 0; }

    // The contrast the preview is drawn with: the layout's, else crisp's default.
    TextContrast contrast() const { return layout_.contrast.value_or(TextContrast{}); }
    // Sets the layout's contrast settings (nullopt: none, and the file saved carries none).
    // Refused (invalid_argument, the layout unchanged) when validate_text_contrast refuses them;
    // the message is crisp's. One undo step.
    Status set_contrast(const std::optional<TextContrast>& contrast);
    // Sets one parameter of contrast() (checked as set_contrast), or steps it by `steps`
    // kContrastStep, rounded to the step and stopping at its range; toggles linear and corrected.
    Status set_contrast_parameter(ContrastParameter parameter, float value);
    void step_contrast(ContrastParameter parameter, int steps);
    void toggle_contrast_mode();

    // Replaces the layout with a preset (subpixel_preset's error for an unknown name) or with a
    // loaded layout (validated first). One undo step each. A chosen preset is what modified()
    // compares with from then on: only an edit away from it is a modification.
    Status apply_preset(std::string_view name);
    Status replace(const SubpixelLayout& layout);

    bool can_undo() const { return !undo_.empty(); }
    bool can_redo() const { return !redo_.empty(); }
    bool undo();
    bool redo();

    // Whether the layout differs from the last one marked saved (at construction, mark_saved(),
    // or a preset chosen with apply_preset()).
    bool modified() const { return layout_ != saved_; }
    void mark_saved() { saved_ = layout_; }

private:
    void push_undo();
    void changed();
    // A preset's name no longer describes an edited copy of it: "rgb" becomes "rgb-edited".
    void rename_if_preset();

    SubpixelLayout layout_;
    SubpixelLayout saved_;
    std::vector<SubpixelLayout> undo_;
    std::vector<SubpixelLayout> redo_;
    uint64_t revision_ = 0;
    int selected_ = 0;
    int drag_channel_ = -1;
    Handle drag_handle_ = Handle::body;
    SampleRect drag_start_{};
    SubpixelLayout drag_before_;
};

}  // namespace crisp::editor
