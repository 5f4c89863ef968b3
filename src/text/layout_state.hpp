// Private to text/: what Layouter's passes share, its state, and the pieces, runs and lines they
// hand each other. layout.cpp shapes and emits; lines.cpp breaks, orders, places and aligns lines.
#pragma once

#include <crisp/layout.hpp>

#include "text/itemize.hpp"

#include <hb.h>

#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace crisp {

namespace detail {

// Text that fits a wrap width up to float noise still fits.
constexpr double kFitTolerance = 1.0 / 1024.0;

struct Run {
    uint32_t begin = 0, end = 0;            // code points
    size_t glyph_begin = 0, glyph_end = 0;  // in State::shaped
    hb_script_t script = HB_SCRIPT_INVALID;
    uint32_t style = 0;  // of its first character: its size and features are the whole run's
    uint16_t font = 0;
    uint8_t level = 0;
};

// A glyph as HarfBuzz shaped it, in logical order, in pixels (whole when snapping).
struct ShapedGlyph {
    uint32_t glyph = 0;
    uint32_t cluster = 0;  // code point index
    float advance = 0.0f;
    float x_offset = 0.0f;
    float y_offset = 0.0f;  // up, as in the font
    uint16_t font = 0;
    bool unsafe_to_break = false;
    bool ellipsis = false;  // of the ellipsis a trimmed line shows (cluster: a shown character beside it)
};

// The part of a run on one line.
struct Piece {
    uint32_t begin = 0, end = 0;
    size_t glyph_begin = 0, glyph_end = 0;
    uint8_t level = 0;
};

// A glyph placed on its line, relative to the line's left edge and baseline.
struct PlacedGlyph {
    double x = 0.0;
    float y_offset = 0.0f;
    uint32_t glyph = 0;
    uint32_t cluster = 0;  // code point index
    uint32_t line = 0;
    uint16_t font = 0;
    float x_offset = 0.0f;  // HarfBuzz's, within `x`
    float advance = 0.0f;   // as placed (a tab's to its stop)
};

// A decorated glyph's stretch of a line, before merging (text/decorations.cpp).
struct DecorationStretch {
    double left = 0.0, right = 0.0;
    double top = 0.0, bottom = 0.0;  // canvas pixels, y down
    uint32_t style = 0;
    uint32_t glyph = 0;  // in State::placed
    DecorationKind kind = DecorationKind::underline;
};

// What the per-glyph loop needs of a Font, looked up once per call.
struct FontView {
    const GlyphRecord* glyphs = nullptr;
    size_t glyph_count = 0;
    FontId id = 0;
    const FontAsset* asset = nullptr;
    bool is_baked(uint32_t glyph) const {
        return glyph < glyph_count && (glyphs[glyph].flags & (kGlyphBaked | kGlyphFailed)) == kGlyphBaked;
    }
    // A layer draws something: its outline is a glyph of the asset with curves.
    bool is_drawn(const ColourLayer& layer) const {
        return layer.glyph < glyph_count && glyphs[layer.glyph].curve_count != 0;
    }
};

// A style (the layout's, 0, or span k's, k + 1) resolved once per call: pixel sizes, linear colour
// and its fonts in State::all_fonts.
struct StyleView {
    const TextStyle* style = nullptr;
    uint32_t font_map = 0;  // its fallback list: all_fonts indices at State::font_map[font_map, + font_count)
    uint16_t font_count = 0;
    uint32_t feature_begin = 0, feature_count = 0;  // in State::features
    double size_x = 0.0, size_y = 0.0;              // the key's quantized sizes, pixels per em
    uint32_t size_x_fixed = 0, size_y_fixed = 0;
    float color[4] = {};
    float letter_spacing = 0.0f, baseline_shift = 0.0f;  // pixels (whole when snapping)
    // Its first font's metrics at size_y, pixels: above and below the baseline, shift included,
    // and the gap below that.
    double above = 0.0, descent = 0.0, gap = 0.0;
};

// A cluster placed on its line (TextCluster before alignment): code points, x from the line's left
// edge.
struct ClusterRecord {
    uint32_t begin = 0, end = 0;
    uint32_t line = 0;
    double x = 0.0;
    double advance = 0.0;
    uint8_t level = 0;
};

struct LineRecord {
    uint32_t begin = 0, end = 0;  // code points, hanging spaces included, hard break excluded
    double width = 0.0;
    // The box: its tallest style's, the layout's style's (the strut) at least: above the baseline,
    // below it, and below it with the line gap.
    double above = 0.0, descent = 0.0, below = 0.0;
    bool tall = false;  // a style on it reaches past the strut
    bool rtl = false;
};

}  // namespace detail

using namespace detail;

struct CRISP_HIDDEN Layouter::State {
    hb_buffer_t* buffer = hb_buffer_create();

    // Per call.
    std::span<const Font* const> fonts;  // all_fonts: the layout's list first, then the spans' other fonts
    std::vector<const Font*> all_fonts;
    size_t base_font_count = 0;                            // the layout's list, all_fonts[0, base_font_count)
    std::unordered_map<const Font*, uint16_t> font_index;  // in all_fonts
    std::unordered_map<FontId, const Font*> font_by_id;
    std::vector<uint16_t> font_map;  // StyleView::font_map
    std::vector<FontView> font_views;
    std::vector<StyleView> styles;
    std::vector<hb_feature_t> features;
    std::vector<double> tab_stops;  // pixels from a line's left edge
    const LayoutOptions* options = nullptr;
    double wrap_width = 0.0;  // pixels; 0: no wrapping
    // The layout's style's box without its shift (LineRecord), and its line height.
    double strut_above = 0.0, strut_descent = 0.0, strut_below = 0.0, strut_height = 0.0;
    double tab_width = 0.0;    // pixels; 0: tabs are spaces
    double tab_measure = 0.0;  // the widest a tab can be, for line breaking
    hb_language_t language = nullptr;
    bool failed = false;   // shaping failed: `failure` says why
    bool stopped = false;  // max_lines reached: no further paragraphs
    bool dropped = false;  // max_lines dropped text
    std::string failure;
    size_t glyphs_shaped = 0;       // by HarfBuzz in this call, re-shaped line pieces too: at most kMaxLayoutGlyphs
    uint32_t mark_splits = 0;       // clusters cut after kMaxMarksPerCluster attached characters
    uint32_t ignorable_splits = 0;  // runs cut after kMaxIgnorablesPerRun default ignorables in a row

    // Whole text.
    std::vector<uint32_t> codepoints;
    std::vector<uint32_t> offsets;  // byte offset of each code point, and the text's size
    std::vector<uint8_t> flags;     // CharFlags
    std::vector<uint8_t> levels;
    std::vector<hb_script_t> scripts;
    std::vector<uint16_t> font_of;       // in all_fonts
    std::vector<uint32_t> style_of;      // in styles
    std::vector<float> cluster_advance;  // pixels, at each cluster's first code point
    BidiScratch bidi;

    // Per paragraph.
    std::vector<Run> runs;
    std::vector<ShapedGlyph> shaped;
    std::vector<std::pair<uint32_t, uint32_t>> line_ranges;
    std::vector<Piece> pieces;
    std::vector<uint32_t> order;
    std::vector<double> glyph_x;
    std::vector<double> glyph_advance;  // the pen's advance past each glyph (a tab's to its stop)

    // Until the end of the call.
    std::vector<PlacedGlyph> placed;
    std::vector<ClusterRecord> clusters;
    std::vector<LineRecord> lines;
    std::vector<double> line_x, line_baseline;
    std::vector<DecorationStretch> decoration_stretches;
    std::vector<TextDecoration> decoration_pieces;
    std::vector<std::pair<double, double>> gaps;

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    ~State() { hb_buffer_destroy(buffer); }

    Status layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                  std::span<const TextSpan> spans, const LayoutOptions& options, TextLayout& out);
    // The styles and fonts of the call; false (with `failure`) where a span is out of place.
    bool resolve_styles(std::span<const Font* const> fonts, const TextStyle& style, std::span<const TextSpan> spans);
    bool same_shaping(uint32_t a, uint32_t b) const;
    void choose_paragraph_fonts(uint32_t p0, uint32_t p1);
    void paragraph(uint32_t p0, uint32_t p1);
    // Shapes [begin, end) of the paragraph [p0, p1) with one HarfBuzz call, appending to `shaped`;
    // false when HarfBuzz's buffer could not hold the output.
    bool shape_once(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
                    uint16_t font, uint32_t style);
    // shape_once(), in pieces where HarfBuzz's buffer cannot hold a run's output; false (with
    // `failure`) past kMaxLayoutGlyphs or where a piece of a few characters still does not fit.
    bool shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script, uint16_t font,
               uint32_t style);
    void break_lines(uint32_t p0, uint32_t p1);
    // Appends the pieces of [begin, end), within one line, at their runs' levels (or `level`).
    void add_pieces(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, int level, size_t& run_cursor,
                    size_t& glyph_cursor);
    size_t cut_pieces(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                      size_t& run_cursor, size_t& glyph_cursor);
    // The ellipsis of a trimmed line in the fonts of `style`, appended to `shaped` with `cluster`;
    // returns its width.
    double shape_ellipsis(uint32_t style, uint32_t cluster);
    // The last line max_lines keeps, trimmed (LayoutOptions::trimming) with an ellipsis.
    void place_trimmed_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                            size_t& run_cursor, size_t& glyph_cursor);
    void finish_line(uint32_t line_begin, uint32_t line_end, size_t content_pieces, uint8_t base_level);
    void order_pieces(size_t content_pieces);
    double place_pieces(size_t content_pieces, uint8_t base_level);
    void place_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                    size_t& run_cursor, size_t& glyph_cursor);
    void record_clusters(uint32_t line);
    void align_lines(TextLayout& out);
    void emit_clusters(TextLayout& out) const;
    void emit_glyphs(TextLayout& out);
    void decorate(TextLayout& out);
    void skip_ink(size_t first, TextLayout& out);
    bool safe_to_break(uint32_t at) const {
        return (flags[at] & kCharClusterStart) != 0 && (flags[at] & kCharUnsafe) == 0;
    }
    void finish(TextLayout& out);
};

}  // namespace crisp
