// crisp: text layout on the CPU: UTF-8 text and a style become positioned glyph instances, each
// with the GlyphKey the atlas caches it under and the whole-pixel rect it covers on the target.
//
// The steps (docs/layout.md has the details and the measurements):
// 1. UTF-8 is decoded; invalid sequences become U+FFFD. Hard line breaks (LF, CR, CR LF, VT, FF,
//    NEL, U+2028, U+2029) split the text into paragraphs; each starts a new line.
// 2. Each paragraph gets bidi embedding levels (UAX #9, FriBidi), a script per character
//    (Common and Inherited characters take the script of their neighbours) and a font per
//    character: the first font of the list that has the character's glyph baked; combining marks
//    stay with their base's font when it has them; a character no font has is shaped with the
//    first font and comes out as its .notdef (glyph 0), counted in missing_glyphs. Emoji (Unicode
//    TR51): a character of Emoji_Presentation, or an emoji with U+FE0F after it, takes the first
//    font with a colour glyph for it (Font::has_colour_glyph_for), else the rule above; U+FE0E after
//    an emoji, or an emoji of text presentation by default, the first with a plain one. An emoji
//    sequence (ZWJ sequences, skin tone modifiers, flags, keycaps, tag sequences) stays whole in the
//    font chosen for its first character, in one run.
// 3. Runs of equal level, script and font are shaped with HarfBuzz (kerning, ligatures, marks,
//    joining, mirroring).
// 4. With a wrap width, lines break greedily at word boundaries (a subset of UAX #14: after
//    spaces, after hyphens, around CJK ideographs and kana); spaces at the end of a line hang past
//    it and do not count toward its width. A line is re-shaped where it cuts a run at a point
//    HarfBuzz marks unsafe to break.
// 5. Each line is reordered into visual order (UAX #9 L1, L2), aligned, and placed on its
//    baseline; pen positions are fractional pixels unless snapping is asked for.
// 6. Each glyph's pen position is split into a whole pixel and a subpixel offset quantized to
//    `subpixel_steps`; its GlyphKey and glyph_rect() give the rect on the target. A colour glyph
//    becomes one instance per layer, back to front, all at the glyph's pen.
#pragma once

#include <crisp/export.hpp>

#include <crisp/font.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace crisp {

// Largest size accepted, in pixels per em.
inline constexpr float kMaxTextSize = 4096.0f;
// Glyphs whose pen lands farther than this from the canvas origin (in pixels, either axis) are
// not emitted (TextLayout::out_of_range_glyphs counts them), so every emitted rect fits int32.
inline constexpr double kMaxCoordinate = 1 << 30;
// Longest text accepted, in bytes: 16 MiB, a few long books, whose glyph instances, itemization and
// shaping buffers stay within a few GiB (docs/limits.md). (FriBidi and HarfBuzz index text with
// int; this is far below.)
inline constexpr size_t kMaxTextBytes = size_t{16} << 20;
// Combining marks (joiners, variation selectors and the characters that continue an emoji sequence
// count too) shaped with one base character: past this many a new shaping run starts, and the
// further marks are drawn after the base rather than attached to it (TextLayout::mark_splits counts
// the cuts). HarfBuzz reorders a cluster's marks in time quadratic in their number: 'a' and 100,000
// marks took 21 s. Real text stacks a handful (Vietnamese, Tibetan, Indic up to about 10; the
// longest emoji sequences, families with skin tones, 10); "Zalgo" text dozens.
inline constexpr uint32_t kMaxMarksPerCluster = 64;
// Default-ignorable characters in a row (bidi controls, zero-width spaces, soft hyphens, ...) in one
// shaping run: past this many a new run starts. HarfBuzz removes them in time quadratic in a row of
// them at a run's start: 300,000 RLI and as many PDI took 99 s. The run's neighbours are passed to
// HarfBuzz as context, and what is cut is invisible, so the text looks the same
// (TextLayout::ignorable_splits counts the cuts).
inline constexpr uint32_t kMaxIgnorablesPerRun = 64;
// Glyphs one layout call shapes (HarfBuzz's output, before colour layers are expanded): past
// this many the call fails (invalid_argument, naming this limit). A font's substitutions (GSUB)
// can make a thousand glyphs of one character, so that 1 MiB of text would ask for 10^9; this
// bounds the glyph arrays and shaping buffers to a few hundred MiB. Real text is about one glyph
// a character: 4 Mi characters of it lay out.
inline constexpr size_t kMaxLayoutGlyphs = size_t{1} << 22;
// Characters HarfBuzz shapes in one call: a longer run of one font, script and direction is cut
// (after a space where one lies within the last 256 characters, never before a mark), so that
// HarfBuzz's buffer, which grows to 64 glyphs a character before it gives up, stays a few MiB.
// Kerning or a ligature across a cut is lost: one place in 4096 characters of an unbroken line.
// A run whose output HarfBuzz's buffer cannot hold (more than 64 glyphs a character) is shaped
// again in halves, down to pieces of 16 characters, whose buffer holds 16,384 glyphs.
inline constexpr uint32_t kMaxShapingRunCharacters = 4096;
// Layer instances one layout expands colour glyphs into: past this many, further colour glyphs
// are drawn as their plain outline (as with LayoutOptions::colour_glyphs off), so that a long text
// in a font of many-layered glyphs (up to kMaxColourLayers each) stays within memory.
inline constexpr uint32_t kMaxColourLayerInstances = 1u << 24;
// GlyphInstance::paint and ::colour_glyph of an instance that is not a colour glyph's layer.
inline constexpr uint32_t kNoPaint = 0xFFFFFFFF;
inline constexpr uint32_t kNoColourGlyph = 0xFFFFFFFF;

enum class Align : uint8_t {
    left,
    center,
    right,
    start,  // left in a left-to-right paragraph, right in a right-to-left one
    end,    // the opposite of start
};

enum class Direction : uint8_t {
    auto_detect,  // each paragraph takes the direction of its first strong character (UAX #9 P2, P3); LTR if none
    ltr,
    rtl,
};

struct TextStyle {
    float size = 16.0f;                         // pixels per em, horizontally; (0, kMaxTextSize]
    float size_y = 0.0f;                        // pixels per em, vertically; 0: same as size
    float color[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // sRGB, straight (not premultiplied) alpha; clamped to [0, 1]
    float depth = 0.0f;                         // copied to every instance, for the compositor
    // CPAL palette of colour glyphs; past a font's palettes (or in a font without any), palette 0.
    uint32_t palette = 0;
};

struct LayoutOptions {
    float origin_x = 0.0f;  // pen of the first line on its baseline, canvas pixels, y down
    float origin_y = 0.0f;
    float wrap_width = 0.0f;    // pixels; 0: no wrapping
    Align align = Align::left;  // within wrap_width, or within the widest line when there is none
    Direction direction = Direction::auto_detect;
    // Rounds every advance and offset and the start of every line to whole pixels, and every
    // baseline (line height included) too: all subpixel offsets are 0, so equal glyphs share one
    // atlas entry wherever they are (the monospaced-editor case).
    bool snap_to_pixels = false;
    // Subpixel offsets are quantized to this many positions per pixel: 1, 2, 4, ..., 256.
    uint32_t subpixel_steps = kSubpixelSteps;
    uint32_t first_paint_order = 0;  // paint order of the first glyph; glyphs count up in logical order
    // Long words: false lets a word wider than wrap_width overflow on a line of its own; true
    // breaks it between grapheme clusters (like CSS overflow-wrap: anywhere).
    bool break_long_words = false;
    // Tab (U+0009) advances to the next multiple of this many space advances (of the first font)
    // from the line's left edge; 0 makes a tab an ordinary space.
    uint32_t tab_spaces = 4;
    // Glyphs without outlines (spaces) are dropped unless this is set; they are always counted.
    bool keep_blank_glyphs = false;
    // BCP 47 language for shaping ("tr", "sr", "ar", ...), or nullptr for the OpenType default
    // language system. Read during the call only.
    const char* language = nullptr;
    // Colour glyphs (FontAsset::colour_glyphs) become their layers; false draws each as its plain
    // outline, one instance with kNoPaint. Fonts are chosen the same either way.
    bool colour_glyphs = true;
};

struct GlyphInstance {
    GlyphKey key;        // font id, glyph index, size (u24.8), subpixel offset (u0.8)
    int32_t x = 0;       // top-left of the glyph's atlas rect on the target, whole pixels:
    int32_t y = 0;       // pen's whole pixel + glyph_rect(record, key).x / .y
    uint32_t width = 0;  // rect size in texels; 0 x 0 only for kept blank glyphs
    uint32_t height = 0;
    float pen_x = 0.0f;   // the glyph's pen position before quantization, canvas pixels (a float:
    float pen_y = 0.0f;   // finer than 1/256 px within 32768 px of the canvas origin; keys use doubles)
    float color[4] = {};  // LINEAR RGB (exact sRGB transfer function) and alpha, NOT premultiplied
    float depth = 0.0f;
    uint32_t paint_order = 0;  // consecutive from first_paint_order, in logical order
    uint32_t cluster = 0;      // byte offset in the UTF-8 text of the first character it shows
    uint32_t line = 0;         // index into TextLayout::lines
    // A colour glyph's layer: key.glyph is the layer's outline (a face glyph or a synthetic one) and
    // the rect is that outline's at the colour glyph's pen. A glyph's layers follow each other, back
    // to front, in consecutive paint orders, with its cluster, line, depth and colour.
    uint32_t paint = kNoPaint;               // index in the font's FontAsset::paints; kNoPaint: `color`
    uint32_t colour_glyph = kNoColourGlyph;  // index in FontAsset::colour_glyphs of the glyph it is a layer of
    uint32_t palette = 0;                    // CPAL palette: TextStyle::palette where the font has it, else 0
};

struct TextLine {
    uint32_t text_begin = 0;  // byte range of the line's characters, without its hard break
    uint32_t text_end = 0;
    uint32_t glyph_begin = 0;  // range in TextLayout::glyphs
    uint32_t glyph_count = 0;
    float x = 0.0f;  // left edge of the line's content (its visual start), canvas pixels
    float baseline_y = 0.0f;
    float width = 0.0f;  // advance width of the content, spaces hanging at its end excluded
    // The line's box: pixels above and below its baseline (positive both), where carets and
    // selections are drawn: fonts[0]'s ascender and descender times the vertical size.
    float ascent = 0.0f;
    float descent = 0.0f;
    bool rtl = false;  // the paragraph's direction
};

// One shaped cluster: a base character with its marks, or all the characters of a ligature, as
// HarfBuzz clusters them; what carets, hit tests and selections (crisp/editing.hpp) work on.
struct TextCluster {
    uint32_t text_begin = 0;  // byte range of its characters in the UTF-8 text
    uint32_t text_end = 0;
    uint32_t line = 0;     // index into TextLayout::lines
    float x = 0.0f;        // left edge on the canvas, pixels, after alignment
    float advance = 0.0f;  // width: the sum of its glyphs' advances (a tab's to its stop)
    uint8_t level = 0;     // bidi embedding level: odd is right-to-left
};

struct TextLayout {
    std::vector<GlyphInstance> glyphs;  // in logical order
    std::vector<TextLine> lines;        // one per line, hard or wrapped; empty for empty text
    // Every shaped cluster in logical order (so in increasing text_begin, and line by line),
    // blank ones (spaces, tabs, hanging spaces) included whatever keep_blank_glyphs says.
    // Characters HarfBuzz shapes into no glyph (default ignorables) join a neighbouring cluster of
    // their run; a run of nothing else (a bidi control between runs) and hard line breaks are in
    // none.
    std::vector<TextCluster> clusters;
    // The box of the line boxes: from the leftmost line start to the rightmost line end, from
    // the first line's ascender down `lines.size()` line heights. Empty text: x and y are where
    // its first line's box would start (its caret's place), width and height 0.
    float x = 0.0f;
    float y = 0.0f;
    float width = 0.0f;
    float height = 0.0f;
    float line_height = 0.0f;          // pixels between baselines (whole when snapping)
    uint32_t shaped_glyphs = 0;        // glyphs HarfBuzz produced, blank and dropped ones included
    uint32_t missing_glyphs = 0;       // .notdef glyphs (characters no font has); they are emitted
    uint32_t blank_glyphs = 0;         // glyphs without an outline (dropped unless keep_blank_glyphs)
    uint32_t out_of_range_glyphs = 0;  // not emitted: pen beyond kMaxCoordinate
    uint32_t mark_splits = 0;          // clusters cut after kMaxMarksPerCluster combining marks
    uint32_t ignorable_splits = 0;     // runs cut after kMaxIgnorablesPerRun default ignorables in a row
    uint32_t colour_glyphs = 0;        // shaped glyphs drawn in colour (as layers)
    uint32_t colour_layers = 0;        // the instances they became
    uint32_t next_paint_order = 0;     // first_paint_order + glyphs.size()
};

// Lays out text, keeping HarfBuzz buffers and scratch memory between calls so that an engine
// laying out every frame allocates (almost) nothing once warm. Move-only; not thread-safe: use
// one per thread (Fonts may be shared).
class CRISP_API Layouter {
public:
    Layouter();
    Layouter(Layouter&& other) noexcept;
    Layouter& operator=(Layouter&& other) noexcept;
    Layouter(const Layouter&) = delete;
    Layouter& operator=(const Layouter&) = delete;
    ~Layouter();

    // Lays out `utf8` with `fonts` (fallback order; fonts[0] gives the line metrics, the tab
    // width and .notdef) into `out`, whose vectors are cleared and reused.
    //
    // Bad input: invalid UTF-8 becomes U+FFFD, shaped as such; empty text gives an empty layout
    // (no lines, no glyphs) and success. Returns ErrorCode::invalid_argument, with `out` emptied,
    // when: `fonts` is empty, holds a null pointer, more than 65535 fonts, or two different Fonts
    // with one FontId; a size or size_y is NaN, infinite, <= 0 (size_y: < 0) or above kMaxTextSize
    // (a size below the 1/256 px glyph keys resolve is laid out and drawn at 1/256 px per em); an
    // origin, wrap width, color or depth is not finite, or the wrap width is negative;
    // subpixel_steps is not a power of two in [1, 256]; the text is longer than kMaxTextBytes; or
    // HarfBuzz runs out of memory. Hostile text never crashes; it is O(n) in time and memory.
    Status layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                  const LayoutOptions& options, TextLayout& out);

private:
    struct State;
    std::unique_ptr<State> state_;
};

// One-shot convenience: a temporary Layouter. Same behaviour and errors as Layouter::layout.
CRISP_API Result<TextLayout> layout_text(std::span<const Font* const> fonts, std::string_view utf8,
                                         const TextStyle& style, const LayoutOptions& options);

// sRGB-encoded component (0..1) to linear light, with the exact piecewise sRGB transfer function.
CRISP_API float srgb_to_linear(float encoded);

}  // namespace crisp
