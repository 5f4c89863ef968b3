// crisp: what a text field needs of a laid-out text: hit testing a point, the caret of a text
// position, the rectangles of a selection, and cursor motion by grapheme cluster, word and line,
// logical and visual (docs/layout.md, "Editing").
//
// Everything works on a TextLayout's clusters (TextLayout::clusters) and, where it needs the
// grapheme and word boundaries of the text, on a TextBoundaries made once per text with ICU. The
// functions keep no state and never fail: bad input is clamped or snapped as each says.
//
// Positions. A TextPosition is a byte offset on a grapheme boundary of the UTF-8 text, and the side
// it belongs to: downstream (the default) the character at the offset, upstream the character
// before it. The two differ on screen only where those two characters are apart: at the end of a
// wrapped line (upstream stays at the end of the line, downstream goes to the start of the next)
// and at a direction boundary.
//
// The caret rule: a position's caret is at the edge of the character it belongs to: downstream the
// leading edge of the character at the offset (its left edge if it is left-to-right, its right
// edge if right-to-left), upstream the trailing edge of the character before it. Where that
// character is not on the position's line (the offset starts or ends its line, or the line is
// empty) the caret takes the other side, and an empty line puts it at the line's x. So in "abc
// XYZ" with XYZ Hebrew in a left-to-right paragraph (drawn "abc ZYX"), offset 4 downstream is at
// the right end of the line (X's leading edge) and offset 4 upstream after the space (between the
// space and Z). The caret's rectangle lies inside the character it belongs to, beside that edge,
// so that hit testing its centre returns the position (hit_test; with the side the rule took, and
// where the character is wider than the caret).
//
// Ligatures: a cluster of several graphemes (an "ffi" ligature) is divided into equal parts, one a
// grapheme, in the cluster's direction; carets, hits and selections use those parts.
#pragma once

#include <crisp/export.hpp>

#include <crisp/layout.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

namespace crisp {

struct TextPosition {
    uint32_t offset = 0;    // bytes into the UTF-8 text, on a grapheme boundary
    bool upstream = false;  // the caret belongs to the character before `offset`
    friend bool operator==(const TextPosition&, const TextPosition&) = default;
};

// A rectangle on the canvas, pixels, y down.
struct TextRect {
    float x = 0.0f;
    float y = 0.0f;
    float width = 0.0f;
    float height = 0.0f;
};

struct HitTest {
    // The caret position nearest the point: the leading edge of the grapheme hit (downstream at its
    // start) when the point is in the half of it its reading starts from, else its trailing edge
    // (upstream at its end).
    TextPosition position;
    uint32_t line = 0;    // index into TextLayout::lines of the line hit (0 when there are none)
    bool inside = false;  // the point lies on a character: inside its advance and its line's box
};

// The grapheme cluster (UAX #29) and word boundaries of a UTF-8 text, found once with ICU's break
// iterators so that cursor motion over a long text costs a binary search. Immutable after it is
// made; copyable; safe to share between threads.
class CRISP_API TextBoundaries {
public:
    // The boundaries of the empty text: offset 0 only.
    TextBoundaries();

    // Finds the boundaries of `utf8`. Invalid UTF-8 is read as ICU reads it (each maximal
    // ill-formed subsequence is one U+FFFD). Returns ErrorCode::invalid_argument when the text is
    // longer than kMaxTextBytes or ICU fails (its error named).
    static Result<TextBoundaries> analyze(std::string_view utf8);

    uint32_t size() const { return size_; }  // the text's length in bytes
    // Every grapheme boundary in increasing order, 0 and size() included.
    std::span<const uint32_t> graphemes() const { return graphemes_; }
    // Every offset where a word (letters, digits, kana or ideographs, as ICU's word iterator says;
    // not spaces or punctuation) starts, in increasing order.
    std::span<const uint32_t> word_starts() const { return word_starts_; }

    bool is_grapheme_boundary(uint32_t offset) const;
    // The grapheme boundary at or before `offset`; offsets past the text give size().
    uint32_t snap(uint32_t offset) const;
    // The first grapheme boundary after `offset`, or size() at or past the end.
    uint32_t next_grapheme(uint32_t offset) const;
    // The last grapheme boundary before `offset`, or 0 at the start.
    uint32_t previous_grapheme(uint32_t offset) const;
    // The first word start after `offset`, or size() where no word starts after it.
    uint32_t next_word_start(uint32_t offset) const;
    // The last word start before `offset`, or 0 where none does.
    uint32_t previous_word_start(uint32_t offset) const;

private:
    std::vector<uint32_t> graphemes_;
    std::vector<uint32_t> word_starts_;
    uint32_t size_ = 0;
};

// The position whose caret is nearest the point (x, y), canvas pixels: the line whose box
// (TextLine::ascent above its baseline to ::descent below) is nearest in y, then on it the cluster
// nearest in x, and within it the grapheme and its half as HitTest says. A point left or right of a
// line takes its nearest grapheme's edge; above the first line or below the last, that line.
//
// The position is on a grapheme boundary of `boundaries`: where HarfBuzz's clusters cut a grapheme
// (past kMaxMarksPerCluster marks; a line broken inside one), that grapheme's edge. `boundaries`
// must be of the text `layout` was made of (it divides ligatures into graphemes); with another
// text the result is still a position of `layout`'s lines, never a crash. Bad input: a NaN
// coordinate is treated as 0; infinite ones are nearest the far side. A layout without lines (empty
// text) gives offset 0, line 0, not inside.
CRISP_API HitTest hit_test(const TextLayout& layout, const TextBoundaries& boundaries, float x, float y);

// The caret rectangle of `position` by the caret rule above: `width` pixels wide, inside the
// character the position belongs to and beside its edge, from the line's ascent above its
// baseline to its descent below. An empty line's caret starts at its x (ends there in a
// right-to-left paragraph).
//
// Bad input: an offset past the text, inside a UTF-8 sequence or inside a grapheme is first moved
// to the grapheme boundary before it (TextBoundaries::snap); upstream at the start of a line is
// downstream and downstream at its end upstream (the caret rule); a width that is NaN, infinite or
// negative is 1. A layout without lines (empty text) gives a caret at its origin (TextLayout::x and
// ::y: the first line's box would start there), TextLayout::line_height tall.
CRISP_API TextRect caret_rect(const TextLayout& layout, const TextBoundaries& boundaries, TextPosition position,
                              float width = 1.0f);

// The rectangles that cover the characters of the byte range [begin, end) into `out` (cleared
// first): on each line, one per visually contiguous part of the range of one direction, in
// increasing x, lines in order; each covers exactly its characters' advances (a ligature's part
// for a part of it), from the line's ascent to its descent. Hard line breaks are not drawn.
//
// Bad input: begin and end are swapped when begin > end, and each is snapped like a caret's offset
// (past the text to its end, inside a grapheme to its start); an empty range gives no rectangles.
CRISP_API void selection_rects(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t begin, uint32_t end,
                               std::vector<TextRect>& out);

enum class CaretMotion : uint8_t {
    // Logical: through the text in reading order, whatever its direction on screen.
    next_grapheme,      // to the next grapheme boundary (downstream)
    previous_grapheme,  // to the previous grapheme boundary (downstream)
    next_word,          // to the next word start, or the end of the text (Ctrl+Right in LTR text)
    previous_word,      // to the previous word start, or the start of the text
    line_start,         // to the start of the caret's line, downstream (Home)
    line_end,           // to the end of the caret's line, upstream: past its hanging spaces (End)
    text_start,         // to offset 0 (Ctrl+Home)
    text_end,           // to the end of the text, upstream (Ctrl+End)
    // Visual: on screen.
    left,        // one grapheme edge to the left; past the line's left end to the line before (LTR
                 // paragraph) or after (RTL) it, at that line's right end
    right,       // one grapheme edge to the right; past the right end to the line after (LTR) or
                 // before (RTL), at its left end
    word_left,   // left grapheme edge by grapheme edge to the first word start (Ctrl+Left), or
                 // as far as `left` goes: in right-to-left text that is the next word, logically
    word_right,  // the same to the right (Ctrl+Right)
    up,          // to the line above, nearest the goal x; on the first line, to the start of the text
    down,        // to the line below, nearest the goal x; on the last line, to the end of the text
};

struct Caret {
    TextPosition position;
    // Where up and down aim: the x the caret had when the first of a series of them was pressed,
    // so that going through a short line does not lose the column. NaN: none yet (up and down take
    // the caret's x); every other motion resets it to NaN.
    float goal_x = std::numeric_limits<float>::quiet_NaN();
};

// Moves `caret` by `motion` over `layout` and the `boundaries` of its text. Visual motion through
// mixed-direction text moves the caret on screen in the pressed direction, one grapheme edge at a
// time (at a direction boundary, two positions can share an edge: the one that belongs to the
// character passed over is taken).
//
// The result is on a grapheme boundary (a line start inside a grapheme is moved to the grapheme's
// start). Bad input: the caret's position is first snapped as caret_rect does; a NaN or infinite
// goal_x is none. On a layout without lines every motion gives offset 0. At the ends of the text
// the motions that would leave it stay.
CRISP_API Caret move_caret(const TextLayout& layout, const TextBoundaries& boundaries, Caret caret, CaretMotion motion);

}  // namespace crisp
