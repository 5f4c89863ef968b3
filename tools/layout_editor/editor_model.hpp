// crisp-layout-editor: the edited subpixel layout (with the monitor's contrast settings), the
// selected channel and the undo history.
// No window, no GPU: tests/test_layout_editor_model.cpp drives it directly.
#pragma once

#include "canvas.hpp"

#include <crisp/contrast.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
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

// How wide `text` is at `size` pixels, interface pixels. The window measures with crisp's layout
// of its font; tests and --print-geometry with estimated_text_width.
using MeasureText = std::function<float(std::string_view text, float size)>;

// One line of text being edited in a field: the text, the cursor (a byte offset, always at the
// start of a UTF-8 sequence) and the selection, between the anchor and the cursor. Every field
// (the file's path, the numbers, the preview's text, sizes and colours) edits through one.
class TextEdit {
public:
    TextEdit() = default;
    // The cursor at the end, nothing selected.
    explicit TextEdit(std::string text);

    const std::string& text() const { return text_; }
    size_t cursor() const { return cursor_; }
    // The selected bytes [first, second); first == second when nothing is selected.
    std::pair<size_t, size_t> selection() const { return std::minmax(anchor_, cursor_); }
    bool has_selection() const { return anchor_ != cursor_; }

    // Puts the cursor at `offset` (past the end: at the end; inside a UTF-8 sequence: at its
    // start). With `extend` the selection runs from the anchor to it, else nothing is selected.
    void move_to(size_t offset, bool extend = false);
    // One character left or right; without `extend`, a selection collapses to its start or end
    // instead. Home and End: the start and the end of the text.
    void left(bool extend = false);
    void right(bool extend = false);
    void home(bool extend = false) { move_to(0, extend); }
    void end(bool extend = false) { move_to(text_.size(), extend); }
    void select_all();

    // Inserts `utf8` at the cursor in place of the selection; the cursor ends after it. Control
    // characters (below U+0020, and U+007F) are left out: a field holds one line.
    void insert(std::string_view utf8);
    // The same for one code point; surrogates and values past U+10FFFF are ignored.
    void insert_codepoint(uint32_t codepoint);
    // Deletes the selection, else the character before (backspace) or at (erase) the cursor.
    void backspace();
    void erase();

    // The byte offset whose caret is nearest `x` interface pixels right of where the text from
    // byte `first` starts, at `size` (a click in a field scrolled to `first`).
    size_t offset_at(float x, float size, const MeasureText& measure, size_t first = 0) const;
    // What a field `room` pixels wide shows: the bytes [first, last) of the text, scrolled as
    // little as keeps the cursor in view from `first` (the field's previous scroll).
    std::pair<size_t, size_t> visible(float room, float size, const MeasureText& measure, size_t first) const;

private:
    size_t boundary_at_or_before(size_t offset) const;
    size_t next_boundary(size_t offset) const;
    size_t previous_boundary(size_t offset) const;

    std::string text_;
    size_t cursor_ = 0;
    size_t anchor_ = 0;
};

// The files saved or loaded lately, newest first, kept between runs in recent_files_path().
inline constexpr size_t kMaxRecentFiles = 8;
// $XDG_CONFIG_HOME/crisp/layout-editor-recent, or ~/.config/crisp/layout-editor-recent where
// XDG_CONFIG_HOME is unset, empty or relative (the XDG base directory rules); empty where HOME
// is not set either.
std::filesystem::path recent_files_path();
// Reads the list: one absolute path a line, newest first. A missing file is an empty list, not an
// error (the first run). Refused (ErrorCode::io or invalid_argument, naming the file and what is
// wrong) where it cannot be read, is over 64 KiB, holds a NUL byte or invalid UTF-8, a relative
// path or more than kMaxRecentFiles lines: the caller goes on without it.
Result<std::vector<std::string>> read_recent_files(const std::filesystem::path& file);
// `path` made absolute and put first in `recent`, once, the list cut to kMaxRecentFiles. A path
// that cannot be kept on one line (it holds a line break) or is empty leaves the list as it was.
std::vector<std::string> add_recent_file(std::vector<std::string> recent, const std::string& path);
// Writes the list atomically (write_file_atomically), making its directory first; crisp's errors.
Status write_recent_files(const std::filesystem::path& file, const std::vector<std::string>& recent);

// The preview's settings (issue 29, item 5): its text, the sizes it is shown at, its colours.
inline constexpr const char* kDefaultPreviewText =
    "Subpixel text fitted to your own monitor: sharp stems, no fringes. 0123456789 (fi fl)";
inline constexpr float kMinPreviewSize = 4.0f, kMaxPreviewSize = 72.0f;
inline constexpr size_t kMaxPreviewSizes = 8;
// Sizes in pixels, separated by spaces or commas ("9 11 13 16 20"): 1 to kMaxPreviewSizes of
// them, each kMinPreviewSize..kMaxPreviewSize. Anything else is nullopt with the reason in `why`
// ("'x' is not a number", "200 is past 72 pixels").
std::optional<std::vector<float>> parse_preview_sizes(std::string_view text, std::string* why = nullptr);
// The sizes as parse_preview_sizes reads them, separated by spaces.
std::string format_preview_sizes(const std::vector<float>& sizes);

// The first panel's text on its background; the second panel shows them swapped.
struct PreviewColours {
    Color foreground{20, 20, 24};
    Color background{250, 248, 240};
    friend bool operator==(const PreviewColours&, const PreviewColours&) = default;
};
// The presets, by name: dark-on-light (the default), light-on-dark, yellow-on-blue.
std::span<const std::pair<const char*, PreviewColours>> preview_colour_presets();
// A preset's name, or two colours as #RRGGBB (the '#' optional, any case) separated by spaces,
// a slash or " on " ("#141418 on #FAF8F0"). Anything else, and two equal colours (invisible
// text), is nullopt with the reason in `why`.
std::optional<PreviewColours> parse_preview_colours(std::string_view text, std::string* why = nullptr);
// "#141418 on #FAF8F0", which parse_preview_colours reads back.
std::string format_preview_colours(const PreviewColours& colours);

// Compare mode (issue 29, item 1): candidate layouts shown side by side, one picked.
inline constexpr size_t kMaxCandidates = 4;
// How far each side of every rectangle moves in the narrower and wider candidates: edit steps.
inline constexpr int kCandidateSteps = 4;
struct Candidate {
    std::string label;  // what its panel says: "Current", "Order reversed", "Narrower", "Wider"
    SubpixelLayout layout;
    friend bool operator==(const Candidate&, const Candidate&) = default;
};
// The candidates around `current`, first `current` itself, then those of: the order reversed
// (mirrored left to right, or top to bottom where that changes nothing), every rectangle
// narrower by kCandidateSteps edit steps each side (about its centre, never below kMinRectSize),
// every rectangle wider by as much (within the bounds). Each passes validate_subpixel_layout, is
// on the edit grid, keeps current's contrast and differs from the others in its rectangles; one
// that would not (gray is its own mirror) is left out. A candidate equal to a preset is named
// after it, any other "NAME-edited" (NAME current's, without a "-edited" it already has). An
// invalid `current` gives no candidates.
std::vector<Candidate> layout_candidates(const SubpixelLayout& current);

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
    // Makes a candidate's layout the edited one (replace(): validated, one undo step; nothing
    // when it is the current one already).
    Status pick(const Candidate& candidate) { return replace(candidate.layout); }

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
