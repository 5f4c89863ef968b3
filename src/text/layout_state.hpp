// Private to text/: what Layouter's passes share, its state, and the pieces, runs and lines they
// hand each other. layout.cpp shapes and emits; lines.cpp breaks, orders, places and aligns lines.
#pragma once

#include <crisp/layout.hpp>

#include "text/itemize.hpp"

#include <hb.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace crisp {

namespace detail {

// Text that fits a wrap width up to float noise still fits.
constexpr double kFitTolerance = 1.0 / 1024.0;

struct Run {
    uint32_t begin = 0, end = 0;            // code points
    size_t glyph_begin = 0, glyph_end = 0;  // in State::shaped
    hb_script_t script = HB_SCRIPT_INVALID;
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
};

// What the per-glyph loop needs of a Font, looked up once per call.
struct FontView {
    const GlyphRecord* glyphs = nullptr;
    size_t glyph_count = 0;
    FontId id = 0;
    const FontAsset* asset = nullptr;
    uint32_t palette = 0;  // TextStyle::palette, or 0 past the font's palettes
    bool is_baked(uint32_t glyph) const {
        return glyph < glyph_count && (glyphs[glyph].flags & (kGlyphBaked | kGlyphFailed)) == kGlyphBaked;
    }
    // A layer draws something: its outline is a glyph of the asset with curves.
    bool is_drawn(const ColourLayer& layer) const {
        return layer.glyph < glyph_count && glyphs[layer.glyph].curve_count != 0;
    }
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
    bool rtl = false;
};

}  // namespace detail

using namespace detail;

struct CRISP_HIDDEN Layouter::State {
    hb_buffer_t* buffer = hb_buffer_create();

    // Per call.
    std::span<const Font* const> fonts;
    std::vector<FontView> font_views;
    const LayoutOptions* options = nullptr;
    double size_x = 0.0, size_y = 0.0;  // the key's quantized sizes, pixels per em
    double tab_width = 0.0;             // pixels; 0: tabs are spaces
    hb_language_t language = nullptr;
    bool failed = false;  // shaping failed: `failure` says why
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
    std::vector<uint16_t> font_of;
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

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    ~State() { hb_buffer_destroy(buffer); }

    Status layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                  const LayoutOptions& options, TextLayout& out);
    void paragraph(uint32_t p0, uint32_t p1);
    // Shapes [begin, end) of the paragraph [p0, p1) with one HarfBuzz call, appending to `shaped`;
    // false when HarfBuzz's buffer could not hold the output.
    bool shape_once(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
                    uint16_t font);
    // shape_once(), in pieces where HarfBuzz's buffer cannot hold a run's output; false (with
    // `failure`) past kMaxLayoutGlyphs or where a piece of a few characters still does not fit.
    bool shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
               uint16_t font);
    void break_lines(uint32_t p0, uint32_t p1);
    size_t cut_pieces(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                      size_t& run_cursor, size_t& glyph_cursor);
    void order_pieces(size_t content_pieces);
    double place_pieces(size_t content_pieces, uint8_t base_level);
    void place_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                    size_t& run_cursor, size_t& glyph_cursor);
    void record_clusters(uint32_t line);
    void align_lines(TextLayout& out);
    void emit_clusters(TextLayout& out) const;
    void emit_glyphs(const TextStyle& style, TextLayout& out);
    bool safe_to_break(uint32_t at) const {
        return (flags[at] & kCharClusterStart) != 0 && (flags[at] & kCharUnsafe) == 0;
    }
    void finish(const TextStyle& style, TextLayout& out);
};

}  // namespace crisp
