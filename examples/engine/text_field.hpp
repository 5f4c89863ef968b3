// A one-line text field drawn with crisp: a panel behind it, a highlight panel per selection
// rectangle, a thin panel as its caret, and its text, clipped to the field and scrolled to keep the
// caret in view. Hit testing, carets, selection rectangles and cursor motion are crisp's
// (crisp/editing.hpp); the field keeps the text, the caret and the selection's anchor, and lays the
// text out again only when it changes.
//
// Input (App forwards GLFW's callbacks): a click in the field focuses it and places the caret,
// a drag selects, Shift+click extends the selection, a click outside takes the focus away. While
// it has the focus: typed characters replace the selection, Backspace and Delete remove a grapheme
// (or the selection), Left and Right move by grapheme on screen (Ctrl: by word), Home and End go to
// the line's ends, Shift with any motion extends the selection, Ctrl+A selects all, Escape gives
// the focus back.
#pragma once

#include "scene.hpp"

#include <crisp/editing.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace engine {

// The field's text at start: Latin around Arabic, one line of mixed directions.
inline constexpr const char* kFieldText =
    "Type here: \xD9\x85\xD8\xB1\xD8\xAD\xD8\xA8\xD8\xA7 \xD8\xA8\xD8\xA7\xD9\x84\xD8\xB9\xD8\xA7\xD9\x84\xD9\x85 and "
    "more";
// Longest text the field holds, in bytes: typing past it is ignored.
inline constexpr size_t kFieldMaxBytes = 1024;

// Where a rectangle of the field is, in window pixels.
struct FieldRect {
    float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
};

// The field as the last draw() drew it, for --report.
struct FieldReport {
    std::string text;  // UTF-8
    bool focused = false;
    uint32_t caret = 0;  // byte offset
    bool caret_upstream = false;
    uint32_t anchor = 0;  // the selection is [min(anchor, caret), max(anchor, caret))
    bool caret_visible = false;
    FieldRect box;                           // the field's panel
    FieldRect caret_rect;                    // as drawn when visible; where it would be otherwise
    std::vector<FieldRect> selection_rects;  // as drawn, clipped to the field
    float text_x = 0.0f;                     // where the text's first line starts, scroll included
    float baseline_y = 0.0f;
};

class TextField {
public:
    // `fonts` and `layouter` must outlive the field (TextOverlay owns all three). `blink_ms` 0: a
    // caret that never blinks.
    TextField(std::span<const crisp::Font* const> fonts, crisp::Layouter& layouter, uint32_t blink_ms);

    // Lays out `text` (clamped to kFieldMaxBytes at a character boundary; invalid UTF-8 is laid
    // out as U+FFFD, as crisp does) and puts the caret at its end. Errors: the layouter's.
    crisp::Status set_text(std::string_view text);
    // Where the field's panel is, in window pixels: the text's baseline is centred in it.
    void place(FieldRect box);
    const FieldRect& box() const { return box_; }
    bool focused() const { return focused_; }

    // GLFW's character callback: a Unicode code point, inserted at the caret in place of the
    // selection. Ignored without the focus, for control characters, surrogates and values past
    // U+10FFFF, and when the text would pass kFieldMaxBytes.
    void type(uint32_t codepoint);
    // GLFW's key callback for a press or a repeat (GLFW_KEY_*, GLFW_MOD_* bits). True when the
    // field used the key (it has the focus and the key is one of the field's).
    bool key(int key, int mods);
    // The left mouse button went down at (x, y), window pixels. Inside the field: focus, caret at
    // the hit position (Shift: the anchor stays, extending the selection), and a drag begins.
    // Outside: the focus goes. Returns whether the point was inside.
    bool press(float x, float y, bool shift);
    // The pointer moved to (x, y) while the button is held: a drag begun in the field moves the
    // caret there, the anchor staying where the press put it.
    void drag(float x, float y);
    void release() { dragging_ = false; }

    // Draws the text (named `id`, at `paint_order` and up) and appends the field's panels (its
    // background, the selection's highlights, the caret when it is in its visible half of the blink)
    // to `panels`, in that order.
    void draw(crisp::Renderer& renderer, std::vector<Panel>& panels, uint64_t id);
    const FieldReport& report() const { return report_; }

private:
    crisp::Status lay_out();
    uint32_t selection_begin() const;
    uint32_t selection_end() const;
    // Replaces the selection with `utf8` (which may be empty) and lays the text out again.
    void replace_selection(std::string_view utf8);
    // The caret goes to `position`, or where crisp's `motion` takes it; the anchor follows unless
    // `extend`.
    void move_caret(crisp::TextPosition position, bool extend);
    void move_caret(crisp::CaretMotion motion, bool extend);
    // Something happened: the caret shows at once, and the scroll follows it.
    void touched();
    void scroll_to_caret();
    // Window pixels to the layout's canvas and back (the layout is made at the origin).
    float origin_x() const;
    float origin_y() const;
    crisp::TextPosition hit(float x, float y) const;
    bool caret_shown() const;

    std::span<const crisp::Font* const> fonts_;
    crisp::Layouter& layouter_;
    std::chrono::milliseconds blink_;
    std::string text_;
    crisp::TextLayout layout_;
    crisp::TextBoundaries boundaries_;
    crisp::TextPosition caret_;
    uint32_t anchor_ = 0;
    float scroll_ = 0.0f;  // whole pixels of text scrolled out at the left
    FieldRect box_;
    bool focused_ = false;
    bool dragging_ = false;
    std::chrono::steady_clock::time_point touched_at_;
    FieldReport report_;
};

}  // namespace engine
