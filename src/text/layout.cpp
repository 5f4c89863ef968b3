// Layout: shaping runs with HarfBuzz, breaking lines, reordering them visually, placing glyphs
// and turning pen positions into glyph keys and rects. Itemization lives in text/itemize.cpp.
#include <crisp/layout.hpp>

#include "text/itemize.hpp"

#include <hb.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <utility>

namespace crisp {

using namespace detail;

namespace {

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
    bool is_baked(uint32_t glyph) const {
        return glyph < glyph_count && (glyphs[glyph].flags & (kGlyphBaked | kGlyphFailed)) == kGlyphBaked;
    }
};

struct LineRecord {
    uint32_t begin = 0, end = 0;  // code points, hanging spaces included, hard break excluded
    double width = 0.0;
    bool rtl = false;
};

Error invalid(std::string message) {
    return Error{ErrorCode::invalid_argument, std::move(message)};
}

std::string show(double value) {
    if (std::isnan(value)) return "NaN";
    if (std::isinf(value)) return value > 0 ? "infinity" : "-infinity";
    std::string text = std::to_string(value);
    while (text.size() > 1 && text.back() == '0') text.pop_back();
    if (!text.empty() && text.back() == '.') text.pop_back();
    return text;
}

Status check_size(const char* name, float size) {
    if (!std::isfinite(size) || !(size > 0.0f) || size > kMaxTextSize)
        return invalid(std::string("layout: ") + name + " is " + show(static_cast<double>(size)) +
                       "; it must be a finite number of pixels per em in (0, 4096]");
    if (std::lround(static_cast<double>(size) * kSizeOne) == 0)
        return invalid(std::string("layout: ") + name + " is " + show(static_cast<double>(size)) +
                       " pixels per em, below the 1/256 px that glyph keys resolve");
    return {};
}

Status check_finite(const char* name, float value) {
    if (!std::isfinite(value))
        return invalid(std::string("layout: ") + name + " is " + show(static_cast<double>(value)) +
                       "; it must be finite");
    return {};
}

Status validate(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                const LayoutOptions& options) {
    if (fonts.empty()) return invalid("layout: the font list is empty; pass at least one font");
    if (fonts.size() > 65535)
        return invalid("layout: " + std::to_string(fonts.size()) + " fonts, at most 65535 are supported");
    for (size_t i = 0; i < fonts.size(); ++i) {
        if (fonts[i] == nullptr) return invalid("layout: fonts[" + std::to_string(i) + "] is null");
        for (size_t j = 0; j < i; ++j) {
            if (fonts[j] != fonts[i] && fonts[j]->id() == fonts[i]->id())
                return invalid("layout: fonts[" + std::to_string(j) + "] and fonts[" + std::to_string(i) +
                               "] are different fonts with the same FontId " + std::to_string(fonts[i]->id()) +
                               "; their glyph keys would collide");
        }
    }
    if (Status status = check_size("style.size", style.size); !status) return status;
    if (style.size_y != 0.0f) {
        if (Status status = check_size("style.size_y", style.size_y); !status) return status;
    }
    const std::pair<const char*, float> finite[] = {
        {"style.color[0]", style.color[0]},     {"style.color[1]", style.color[1]},
        {"style.color[2]", style.color[2]},     {"style.color[3]", style.color[3]},
        {"style.depth", style.depth},           {"options.origin_x", options.origin_x},
        {"options.origin_y", options.origin_y}, {"options.wrap_width", options.wrap_width},
    };
    for (const auto& [name, value] : finite) {
        if (Status status = check_finite(name, value); !status) return status;
    }
    if (options.wrap_width < 0.0f)
        return invalid("layout: options.wrap_width is " + show(static_cast<double>(options.wrap_width)) +
                       "; it must be 0 (no wrapping) or positive");
    const uint32_t steps = options.subpixel_steps;
    if (steps == 0 || steps > kSubpixelSteps || (steps & (steps - 1)) != 0)
        return invalid("layout: options.subpixel_steps is " + std::to_string(steps) +
                       "; it must be a power of two from 1 to 256");
    if (utf8.size() > kMaxTextBytes)
        return invalid("layout: the text is " + std::to_string(utf8.size()) + " bytes, more than the " +
                       std::to_string(kMaxTextBytes) + " supported");
    return {};
}

// Splits a pen coordinate into its whole pixel and a subpixel offset on a grid of `steps` per
// pixel, in u0.8. An offset that rounds up to a whole pixel carries into it.
void quantize(double pen, uint32_t steps, int32_t& whole, uint8_t& subpixel) {
    double base = std::floor(pen);
    double step = std::round((pen - base) * steps);
    if (step >= steps) {
        base += 1.0;
        step = 0.0;
    }
    whole = static_cast<int32_t>(base);
    subpixel = static_cast<uint8_t>(static_cast<uint32_t>(step) * (kSubpixelSteps / steps));
}

// Empties a layout, keeping its vectors' memory.
void reset(TextLayout& out, uint32_t first_paint_order) {
    out.glyphs.clear();
    out.lines.clear();
    out.x = out.y = out.width = out.height = out.line_height = 0.0f;
    out.shaped_glyphs = out.missing_glyphs = out.blank_glyphs = out.out_of_range_glyphs = out.mark_splits = 0;
    out.next_paint_order = first_paint_order;
}

}  // namespace

float srgb_to_linear(float encoded) {
    const double c = static_cast<double>(encoded);
    return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

struct CRISP_HIDDEN Layouter::State {
    hb_buffer_t* buffer = hb_buffer_create();

    // Per call.
    std::span<const Font* const> fonts;
    std::vector<FontView> font_views;
    const LayoutOptions* options = nullptr;
    double size_x = 0.0, size_y = 0.0;  // the key's quantized sizes, pixels per em
    double tab_width = 0.0;             // pixels; 0: tabs are spaces
    hb_language_t language = nullptr;
    bool failed = false;       // HarfBuzz ran out of memory
    uint32_t mark_splits = 0;  // clusters cut after kMaxMarksPerCluster attached characters

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

    // Until the end of the call.
    std::vector<PlacedGlyph> placed;
    std::vector<LineRecord> lines;
    std::vector<double> line_x, line_baseline;

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    ~State() { hb_buffer_destroy(buffer); }

    Status layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                  const LayoutOptions& options, TextLayout& out);
    void paragraph(uint32_t p0, uint32_t p1);
    bool shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
               uint16_t font);
    void break_lines(uint32_t p0, uint32_t p1);
    size_t cut_pieces(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                      size_t& run_cursor, size_t& glyph_cursor);
    void order_pieces(size_t content_pieces);
    double place_pieces(size_t content_pieces, uint8_t base_level);
    void place_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                    size_t& run_cursor, size_t& glyph_cursor);
    void align_lines(TextLayout& out);
    void emit_glyphs(const TextStyle& style, TextLayout& out);
    bool safe_to_break(uint32_t at) const {
        return (flags[at] & kCharClusterStart) != 0 && (flags[at] & kCharUnsafe) == 0;
    }
    void finish(const TextStyle& style, TextLayout& out);
};

bool Layouter::State::shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
                            uint16_t font) {
    const bool rtl = (level & 1) != 0;
    hb_buffer_clear_contents(buffer);
    hb_buffer_set_direction(buffer, rtl ? HB_DIRECTION_RTL : HB_DIRECTION_LTR);
    hb_buffer_set_script(buffer, script);
    if (language != nullptr) hb_buffer_set_language(buffer, language);
    // Beginning and end of text only at the paragraph's ends: elsewhere the neighbours are passed
    // as context, so Arabic joins across a change of font or level.
    unsigned buffer_flags = HB_BUFFER_FLAG_REMOVE_DEFAULT_IGNORABLES;
    if (begin == p0) buffer_flags |= HB_BUFFER_FLAG_BOT;
    if (end == p1) buffer_flags |= HB_BUFFER_FLAG_EOT;
    hb_buffer_set_flags(buffer, static_cast<hb_buffer_flags_t>(buffer_flags));
    hb_buffer_add_codepoints(buffer, codepoints.data() + p0, static_cast<int>(p1 - p0), begin - p0,
                             static_cast<int>(end - begin));
    hb_shape(fonts[font]->harfbuzz_font(), buffer, nullptr, 0);
    if (!hb_buffer_allocation_successful(buffer)) return false;

    unsigned count = 0;
    const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &count);
    const hb_glyph_position_t* positions = hb_buffer_get_glyph_positions(buffer, nullptr);
    const double per_unit = 1.0 / fonts[font]->units_per_em();
    const double scale_x = per_unit * size_x, scale_y = per_unit * size_y;
    const bool snap = options->snap_to_pixels;
    auto pixels = [snap](double value) { return static_cast<float>(snap ? std::round(value) : value); };
    // Grown geometrically: reserving exactly size + count here reallocated on every run (quadratic
    // in a paragraph of many runs).
    if (shaped.capacity() < shaped.size() + count)
        shaped.reserve(std::max(shaped.size() + count, 2 * shaped.capacity()));
    for (unsigned k = 0; k < count; ++k) {
        // HarfBuzz returns right-to-left runs in visual order; keep everything logical.
        const unsigned i = rtl ? count - 1 - k : k;
        ShapedGlyph glyph;
        glyph.glyph = infos[i].codepoint;
        glyph.cluster = p0 + infos[i].cluster;
        glyph.advance = pixels(positions[i].x_advance * scale_x);
        glyph.x_offset = pixels(positions[i].x_offset * scale_x);
        glyph.y_offset = pixels(positions[i].y_offset * scale_y);
        glyph.font = font;
        // What hb.h's hb_glyph_info_get_glyph_flags() macro reads, without its C casts.
        glyph.unsafe_to_break = (infos[i].mask & HB_GLYPH_FLAG_UNSAFE_TO_BREAK) != 0;
        shaped.push_back(glyph);
    }
    return true;
}

void Layouter::State::paragraph(uint32_t p0, uint32_t p1) {
    const LayoutOptions& o = *options;
    if (p0 == p1) {
        lines.push_back({p0, p1, 0.0, o.direction == Direction::rtl});
        return;
    }
    const size_t n = p1 - p0;
    std::span<const uint32_t> text(codepoints.data() + p0, n);
    std::span<uint8_t> paragraph_flags(flags.data() + p0, n);
    classify(text, paragraph_flags);
    const uint8_t base_level = resolve_levels(text, o.direction, bidi, std::span(levels.data() + p0, n));
    // Tabs are shaped as spaces (few fonts map U+0009) after bidi, which treats them as segment
    // separators; their width is set when the line is placed.
    for (size_t i = 0; i < n; ++i)
        if ((paragraph_flags[i] & kCharTab) != 0) codepoints[p0 + i] = ' ';
    resolve_scripts(text, paragraph_flags, std::span(scripts.data() + p0, n));
    choose_fonts(fonts, text, paragraph_flags, std::span(font_of.data() + p0, n));

    runs.clear();
    shaped.clear();
    uint32_t run_begin = p0;
    // Combining marks (and joiners, selectors) attached to one base: HarfBuzz reorders a cluster's
    // marks in time quadratic in their number, so past kMaxMarksPerCluster a new run starts.
    uint32_t attached = (flags[p0] & kCharAttached) != 0 ? 1 : 0;
    for (uint32_t i = p0 + 1; i <= p1; ++i) {
        bool split = false;
        if (i < p1) {
            attached = (flags[i] & kCharAttached) != 0 ? attached + 1 : 0;
            split = attached > kMaxMarksPerCluster;
        }
        if (i < p1 && !split && levels[i] == levels[i - 1] && scripts[i] == scripts[i - 1] &&
            font_of[i] == font_of[i - 1])
            continue;
        if (split) {
            ++mark_splits;
            attached = 1;  // the mark at i starts the next run
        }
        Run run;
        run.begin = run_begin;
        run.end = i;
        run.script = scripts[run_begin];
        run.font = font_of[run_begin];
        run.level = levels[run_begin];
        run.glyph_begin = shaped.size();
        if (!shape(p0, p1, run.begin, run.end, run.level, run.script, run.font)) {
            failed = true;
            return;
        }
        run.glyph_end = shaped.size();
        runs.push_back(run);
        run_begin = i;
    }
    for (const ShapedGlyph& glyph : shaped) {
        flags[glyph.cluster] |= kCharClusterStart;
        if (glyph.unsafe_to_break) flags[glyph.cluster] |= kCharUnsafe;
    }
    for (const Run& run : runs) flags[run.begin] |= kCharClusterStart;  // run boundaries were shaped apart

    if (o.wrap_width > 0.0f) {
        std::fill(cluster_advance.begin() + p0, cluster_advance.begin() + p1, 0.0f);
        for (const ShapedGlyph& glyph : shaped) {
            // A tab is at most a full tab stop wide: measuring it so keeps wrapped lines inside.
            const bool tab = (flags[glyph.cluster] & kCharTab) != 0 && tab_width > 0.0;
            cluster_advance[glyph.cluster] += tab ? static_cast<float>(tab_width) : glyph.advance;
        }
    }
    break_lines(p0, p1);
    size_t run_cursor = 0, glyph_cursor = 0;
    for (const auto& [line_begin, line_end] : line_ranges) {
        place_line(p0, p1, line_begin, line_end, base_level, run_cursor, glyph_cursor);
        if (failed) return;
    }
}

void Layouter::State::break_lines(uint32_t p0, uint32_t p1) {
    line_ranges.clear();
    const double wrap = static_cast<double>(options->wrap_width);
    if (!(wrap > 0.0)) {
        line_ranges.emplace_back(p0, p1);
        return;
    }
    // Greedy, one pass: each segment (text between two break opportunities) is measured once,
    // so a paragraph costs O(n) however it breaks.
    const double limit = wrap + kFitTolerance;
    uint32_t line_begin = p0, segment_begin = p0;
    double committed = 0.0;  // width of [line_begin, segment_begin), inner spaces included
    for (uint32_t b = p0 + 1; b <= p1; ++b) {
        if (b < p1 && (flags[b] & kCharBreakBefore) == 0) continue;
        double total = 0.0;
        for (uint32_t k = segment_begin; k < b; ++k) total += static_cast<double>(cluster_advance[k]);
        uint32_t content_end = b;
        double trailing = 0.0;
        while (content_end > segment_begin && (flags[content_end - 1] & kCharSpace) != 0) {
            --content_end;
            trailing += static_cast<double>(cluster_advance[content_end]);
        }
        const double content = total - trailing;
        if (segment_begin > line_begin && committed + content > limit) {
            line_ranges.emplace_back(line_begin, segment_begin);
            line_begin = segment_begin;
            committed = 0.0;
        }
        if (options->break_long_words && segment_begin == line_begin && content > limit) {
            // The word alone overflows: break it between clusters.
            double width = 0.0;
            uint32_t k = segment_begin;
            while (k < content_end) {
                uint32_t next = k + 1;
                double cluster = static_cast<double>(cluster_advance[k]);
                while (next < content_end && (flags[next] & kCharClusterStart) == 0)
                    cluster += static_cast<double>(cluster_advance[next++]);
                if (k > line_begin && width + cluster > limit) {
                    line_ranges.emplace_back(line_begin, k);
                    line_begin = k;
                    width = 0.0;
                }
                width += cluster;
                k = next;
            }
            committed = width + trailing;
        } else {
            committed += total;
        }
        segment_begin = b;
    }
    line_ranges.emplace_back(line_begin, p1);
}

// The line's pieces: each run's part on the line, cut where trailing spaces begin (they hang: they
// take the paragraph's level, UAX #9 L1, and are placed past the content). Returns how many pieces
// are content, the rest are the hanging spaces; sets `failed` where re-shaping a cut run fails.
size_t Layouter::State::cut_pieces(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                                   size_t& run_cursor, size_t& glyph_cursor) {
    uint32_t content_end = line_end;
    while (content_end > line_begin && (flags[content_end - 1] & kCharSpace) != 0) --content_end;

    pieces.clear();
    size_t content_pieces = 0;
    auto add_piece = [&](const Run& run, uint32_t begin, uint32_t end, uint8_t level) {
        size_t g = std::max(glyph_cursor, run.glyph_begin);
        while (g < run.glyph_end && shaped[g].cluster < begin) ++g;
        Piece piece{begin, end, g, g, level};
        while (g < run.glyph_end && shaped[g].cluster < end) ++g;
        piece.glyph_end = g;
        glyph_cursor = g;
        // A line that cuts a run where HarfBuzz says the shaping depends on the other side
        // (a ligature or kerning pair across the cut, joining) gets its part re-shaped.
        const bool unsafe = (begin != run.begin && !safe_to_break(begin)) || (end != run.end && !safe_to_break(end));
        if (unsafe) {
            piece.glyph_begin = shaped.size();
            if (!shape(p0, p1, begin, end, run.level, run.script, run.font)) {
                failed = true;
                return;
            }
            piece.glyph_end = shaped.size();
        }
        pieces.push_back(piece);
    };
    while (run_cursor < runs.size() && runs[run_cursor].end <= line_begin) ++run_cursor;
    for (size_t r = run_cursor; r < runs.size() && runs[r].begin < line_end; ++r) {
        const Run& run = runs[r];
        const uint32_t begin = std::max(line_begin, run.begin), end = std::min(line_end, run.end);
        if (begin < content_end) {
            add_piece(run, begin, std::min(end, content_end), run.level);
            ++content_pieces;
        }
        if (end > content_end) add_piece(run, std::max(begin, content_end), end, base_level);
        if (failed) break;
    }
    return content_pieces;
}

// Visual order of the content pieces into `order` (UAX #9 L2): from the highest level down to the
// lowest odd level, every maximal sequence of pieces at that level or higher is reversed.
void Layouter::State::order_pieces(size_t content_pieces) {
    order.resize(content_pieces);
    uint8_t highest = 0, lowest_odd = 255;
    for (size_t i = 0; i < content_pieces; ++i) {
        order[i] = static_cast<uint32_t>(i);
        highest = std::max(highest, pieces[i].level);
        if ((pieces[i].level & 1) != 0) lowest_odd = std::min(lowest_odd, pieces[i].level);
    }
    for (int level = highest; level >= lowest_odd; --level) {
        for (size_t i = 0; i < content_pieces;) {
            if (pieces[order[i]].level < level) {
                ++i;
                continue;
            }
            size_t j = i;
            while (j < content_pieces && pieces[order[j]].level >= level) ++j;
            std::reverse(order.begin() + static_cast<ptrdiff_t>(i), order.begin() + static_cast<ptrdiff_t>(j));
            i = j;
        }
    }
}

// Every piece's glyphs' x into glyph_x: the content in visual order from 0 (tabs to the next
// stop), then the hanging spaces past it in the paragraph's direction. Returns the content's width.
double Layouter::State::place_pieces(size_t content_pieces, uint8_t base_level) {
    glyph_x.resize(shaped.size());
    double x = 0.0;
    auto place = [&](const Piece& piece, bool tabs) {
        // Right-to-left pieces go through their glyphs backwards: HarfBuzz's offsets are relative
        // to a pen that moves in visual order.
        const bool rtl = (piece.level & 1) != 0;
        for (size_t k = 0; k < piece.glyph_end - piece.glyph_begin; ++k) {
            const size_t g = rtl ? piece.glyph_end - 1 - k : piece.glyph_begin + k;
            const ShapedGlyph& glyph = shaped[g];
            glyph_x[g] = x + static_cast<double>(glyph.x_offset);
            double advance = static_cast<double>(glyph.advance);
            if (tabs && tab_width > 0.0 && (flags[glyph.cluster] & kCharTab) != 0) {
                // To the next tab stop from the line's left edge (a stop closer than 1/1000 of
                // a tab is skipped, as a tab never has no width).
                const double stop = (std::floor(x / tab_width + 1e-3) + 1.0) * tab_width;
                advance = stop - x;
            }
            x += advance;
        }
    };
    for (uint32_t index : order) place(pieces[index], true);
    const double width = x;
    if (pieces.size() > content_pieces) {
        double hanging = 0.0;
        for (size_t i = content_pieces; i < pieces.size(); ++i)
            for (size_t g = pieces[i].glyph_begin; g < pieces[i].glyph_end; ++g)
                hanging += static_cast<double>(shaped[g].advance);
        const bool rtl = (base_level & 1) != 0;
        x = rtl ? -hanging : width;
        for (size_t k = content_pieces; k < pieces.size(); ++k) {
            const size_t i = rtl ? pieces.size() - 1 - (k - content_pieces) : k;
            place(pieces[i], false);
        }
    }
    return width;
}

void Layouter::State::place_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                                 size_t& run_cursor, size_t& glyph_cursor) {
    const size_t content_pieces = cut_pieces(p0, p1, line_begin, line_end, base_level, run_cursor, glyph_cursor);
    if (failed) return;
    order_pieces(content_pieces);
    const double width = place_pieces(content_pieces, base_level);
    const auto line = static_cast<uint32_t>(lines.size());
    for (const Piece& piece : pieces) {
        for (size_t g = piece.glyph_begin; g < piece.glyph_end; ++g) {
            const ShapedGlyph& glyph = shaped[g];
            placed.push_back({glyph_x[g], glyph.y_offset, glyph.glyph, glyph.cluster, line, glyph.font});
        }
    }
    lines.push_back({line_begin, line_end, width, (base_level & 1) != 0});
}

// Each line's x (aligned within the wrap width, or the widest line) and baseline into line_x and
// line_baseline, the lines' records and the layout's box into `out`.
void Layouter::State::align_lines(TextLayout& out) {
    const LayoutOptions& o = *options;
    const bool snap = o.snap_to_pixels;
    double line_height = static_cast<double>(fonts[0]->line_height()) * size_y;
    if (snap) line_height = std::round(line_height);
    out.line_height = static_cast<float>(line_height);

    double align_width = static_cast<double>(o.wrap_width);
    if (!(align_width > 0.0)) {
        align_width = 0.0;
        for (const LineRecord& line : lines) align_width = std::max(align_width, line.width);
    }
    const double origin_x = static_cast<double>(o.origin_x);
    const double origin_y = snap ? std::round(static_cast<double>(o.origin_y)) : static_cast<double>(o.origin_y);
    line_x.resize(lines.size());
    line_baseline.resize(lines.size());
    out.lines.resize(lines.size());
    double left = std::numeric_limits<double>::infinity(), right = -left;
    for (size_t i = 0; i < lines.size(); ++i) {
        const LineRecord& line = lines[i];
        Align align = o.align;
        if (align == Align::start) align = line.rtl ? Align::right : Align::left;
        if (align == Align::end) align = line.rtl ? Align::left : Align::right;
        const double slack = align_width - line.width;
        double x = origin_x + (align == Align::right ? slack : align == Align::center ? slack * 0.5 : 0.0);
        if (snap) x = std::round(x);
        line_x[i] = x;
        line_baseline[i] = origin_y + static_cast<double>(i) * line_height;
        left = std::min(left, x);
        right = std::max(right, x + line.width);
        TextLine& record = out.lines[i];
        record.text_begin = offsets[line.begin];
        record.text_end = offsets[line.end];
        record.x = static_cast<float>(x);
        record.baseline_y = static_cast<float>(line_baseline[i]);
        record.width = static_cast<float>(line.width);
        record.rtl = line.rtl;
    }
    if (!lines.empty()) {
        out.x = static_cast<float>(left);
        out.width = static_cast<float>(right - left);
        out.y = static_cast<float>(origin_y - static_cast<double>(fonts[0]->ascender()) * size_y);
        out.height = static_cast<float>(line_height * static_cast<double>(lines.size()));
    }
}

// The placed glyphs as instances into `out`, line by line: .notdef for glyphs the asset lacks,
// blank glyphs kept only when asked, pens beyond kMaxCoordinate counted and dropped.
void Layouter::State::emit_glyphs(const TextStyle& style, TextLayout& out) {
    const LayoutOptions& o = *options;
    float color[4];
    for (int c = 0; c < 3; ++c) color[c] = srgb_to_linear(std::clamp(style.color[c], 0.0f, 1.0f));
    color[3] = std::clamp(style.color[3], 0.0f, 1.0f);
    const auto size_x_fixed = static_cast<uint32_t>(std::lround(size_x * kSizeOne));
    const auto size_y_fixed = static_cast<uint32_t>(std::lround(size_y * kSizeOne));

    out.glyphs.reserve(placed.size());
    out.shaped_glyphs = static_cast<uint32_t>(std::min<size_t>(placed.size(), UINT32_MAX));
    out.mark_splits = mark_splits;
    size_t p = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
        TextLine& record = out.lines[i];
        record.glyph_begin = static_cast<uint32_t>(out.glyphs.size());
        for (; p < placed.size() && placed[p].line == i; ++p) {
            const PlacedGlyph& placed_glyph = placed[p];
            const FontView& font = font_views[placed_glyph.font];
            uint32_t glyph = placed_glyph.glyph;
            if (glyph == 0 || !font.is_baked(glyph)) {
                // .notdef, or (only with an inconsistent asset) a glyph the asset lacks: show
                // the font's .notdef when it has one.
                ++out.missing_glyphs;
                glyph = 0;
                if (!font.is_baked(0)) continue;
            }
            const GlyphRecord& glyph_record = font.glyphs[glyph];
            if (glyph_record.curve_count == 0) {
                ++out.blank_glyphs;
                if (!o.keep_blank_glyphs) continue;
            }
            const double pen_x = line_x[i] + placed_glyph.x;
            const double pen_y = line_baseline[i] - static_cast<double>(placed_glyph.y_offset);
            if (!(std::abs(pen_x) <= kMaxCoordinate) || !(std::abs(pen_y) <= kMaxCoordinate)) {
                ++out.out_of_range_glyphs;
                continue;
            }
            GlyphInstance instance;
            int32_t whole_x = 0, whole_y = 0;
            quantize(pen_x, o.subpixel_steps, whole_x, instance.key.subpixel_x);
            quantize(pen_y, o.subpixel_steps, whole_y, instance.key.subpixel_y);
            instance.key.font = font.id;
            instance.key.glyph = glyph;
            instance.key.size_x = size_x_fixed;
            instance.key.size_y = size_y_fixed;
            const GlyphRect rect = glyph_rect(glyph_record, instance.key);
            instance.x = whole_x + rect.x;
            instance.y = whole_y + rect.y;
            instance.width = rect.width;
            instance.height = rect.height;
            instance.pen_x = static_cast<float>(pen_x);
            instance.pen_y = static_cast<float>(pen_y);
            std::copy(std::begin(color), std::end(color), std::begin(instance.color));
            instance.depth = style.depth;
            instance.paint_order = o.first_paint_order + static_cast<uint32_t>(out.glyphs.size());
            instance.cluster = offsets[placed_glyph.cluster];
            instance.line = static_cast<uint32_t>(i);
            out.glyphs.push_back(instance);
        }
        record.glyph_count = static_cast<uint32_t>(out.glyphs.size()) - record.glyph_begin;
    }
    out.next_paint_order = o.first_paint_order + static_cast<uint32_t>(out.glyphs.size());
}

void Layouter::State::finish(const TextStyle& style, TextLayout& out) {
    align_lines(out);
    emit_glyphs(style, out);
}

Status Layouter::State::layout(std::span<const Font* const> font_list, std::string_view utf8, const TextStyle& style,
                               const LayoutOptions& layout_options, TextLayout& out) {
    reset(out, layout_options.first_paint_order);
    if (Status status = validate(font_list, utf8, style, layout_options); !status) return status;

    fonts = font_list;
    font_views.clear();
    for (const Font* font : fonts)
        font_views.push_back({font->asset().glyphs.data(), font->asset().glyphs.size(), font->id()});
    options = &layout_options;
    failed = false;
    mark_splits = 0;
    size_x = static_cast<double>(std::lround(static_cast<double>(style.size) * kSizeOne)) / kSizeOne;
    const float size_y_asked = style.size_y == 0.0f ? style.size : style.size_y;
    size_y = static_cast<double>(std::lround(static_cast<double>(size_y_asked) * kSizeOne)) / kSizeOne;
    language = layout_options.language != nullptr && layout_options.language[0] != '\0'
                   ? hb_language_from_string(layout_options.language, -1)
                   : nullptr;
    tab_width = 0.0;
    if (layout_options.tab_spaces > 0 && utf8.find('\t') != std::string_view::npos) {
        const Font& first = *fonts[0];
        hb_position_t space = 0;
        const uint32_t space_glyph = first.nominal_glyph(' ');
        if (first.has_glyph_for(' ')) space = hb_font_get_glyph_h_advance(first.harfbuzz_font(), space_glyph);
        double space_width = space / static_cast<double>(first.units_per_em()) * size_x;
        if (!(space_width > 0.0)) space_width = 0.25 * size_x;  // no space glyph: a quarter em
        if (layout_options.snap_to_pixels) space_width = std::max(1.0, std::round(space_width));
        tab_width = space_width * layout_options.tab_spaces;
    }
    placed.clear();
    lines.clear();
    if (utf8.empty()) {
        finish(style, out);
        return {};
    }

    decode_utf8_with_offsets(utf8, codepoints, offsets);
    const size_t n = codepoints.size();
    flags.resize(n);
    levels.resize(n);
    scripts.resize(n);
    font_of.resize(n);
    if (layout_options.wrap_width > 0.0f) cluster_advance.resize(n);

    uint32_t begin = 0;
    for (;;) {
        uint32_t end = begin;
        while (end < n && !is_hard_break(codepoints[end])) ++end;
        paragraph(begin, end);
        if (failed) {
            reset(out, layout_options.first_paint_order);
            return invalid("layout: HarfBuzz could not allocate memory for the text");
        }
        if (end == n) break;
        begin = end + (codepoints[end] == '\r' && end + 1 < n && codepoints[end + 1] == '\n' ? 2 : 1);
    }
    finish(style, out);
    return {};
}

Layouter::Layouter() : state_(std::make_unique<State>()) {}
Layouter::Layouter(Layouter&& other) noexcept = default;
Layouter& Layouter::operator=(Layouter&& other) noexcept = default;
Layouter::~Layouter() = default;

Status Layouter::layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                        const LayoutOptions& options, TextLayout& out) {
    assert(state_ && "a moved-from Layouter may only be destroyed or assigned to");
    try {
        return state_->layout(fonts, utf8, style, options, out);
    } catch (const std::exception& error) {
        // Only allocation can throw here (a text too large for memory): no exception crosses the API.
        reset(out, options.first_paint_order);
        return invalid(std::string("layout: out of memory: ") + error.what());
    }
}

Result<TextLayout> layout_text(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                               const LayoutOptions& options) {
    Layouter layouter;
    TextLayout layout;
    if (Status status = layouter.layout(fonts, utf8, style, options, layout); !status) return status.error();
    return layout;
}

}  // namespace crisp
