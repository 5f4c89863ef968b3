// Layout's line passes: breaking a paragraph into lines, ordering each line's pieces visually,
// placing them and aligning the lines (Layouter::State, text/layout_state.hpp).
#include "text/layout_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace crisp {

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
    glyph_advance.resize(shaped.size());
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
            glyph_advance[g] = advance;
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
    record_clusters(line);
    lines.push_back({line_begin, line_end, width, (base_level & 1) != 0});
}

// The clusters of the placed pieces, in logical order: each run of glyphs of one HarfBuzz cluster
// value, reaching to the next cluster's first character (the piece's ends at its ends), from its
// leftmost pen over its glyphs' advances.
void Layouter::State::record_clusters(uint32_t line) {
    for (const Piece& piece : pieces) {
        for (size_t g = piece.glyph_begin; g < piece.glyph_end;) {
            ClusterRecord cluster{g == piece.glyph_begin ? piece.begin : shaped[g].cluster,
                                  piece.end,
                                  line,
                                  std::numeric_limits<double>::infinity(),
                                  0.0,
                                  piece.level};
            const uint32_t value = shaped[g].cluster;
            for (; g < piece.glyph_end && shaped[g].cluster <= value; ++g) {
                cluster.x = std::min(cluster.x, glyph_x[g] - static_cast<double>(shaped[g].x_offset));
                cluster.advance += glyph_advance[g];
            }
            if (g < piece.glyph_end) cluster.end = shaped[g].cluster;
            clusters.push_back(cluster);
        }
    }
}

void Layouter::State::emit_clusters(TextLayout& out) const {
    out.clusters.resize(clusters.size());
    for (size_t i = 0; i < clusters.size(); ++i) {
        const ClusterRecord& cluster = clusters[i];
        out.clusters[i] = {offsets[cluster.begin],
                           offsets[cluster.end],
                           cluster.line,
                           static_cast<float>(line_x[cluster.line] + cluster.x),
                           static_cast<float>(cluster.advance),
                           cluster.level};
    }
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
    const auto ascent = static_cast<float>(static_cast<double>(fonts[0]->ascender()) * size_y);
    const auto descent = static_cast<float>(-static_cast<double>(fonts[0]->descender()) * size_y);
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
        record.ascent = ascent;
        record.descent = descent;
        record.rtl = line.rtl;
    }
    // Empty text: the box where its first line's would start, of no size (where its caret goes).
    out.x = static_cast<float>(origin_x);
    out.y = static_cast<float>(origin_y - static_cast<double>(fonts[0]->ascender()) * size_y);
    if (!lines.empty()) {
        out.x = static_cast<float>(left);
        out.width = static_cast<float>(right - left);
        out.height = static_cast<float>(line_height * static_cast<double>(lines.size()));
    }
}

}  // namespace crisp
