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
    const double wrap = wrap_width;
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
void Layouter::State::add_pieces(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, int level, size_t& run_cursor,
                                 size_t& glyph_cursor) {
    auto add_piece = [&](const Run& run, uint32_t piece_begin, uint32_t piece_end) {
        size_t g = std::max(glyph_cursor, run.glyph_begin);
        while (g < run.glyph_end && shaped[g].cluster < piece_begin) ++g;
        Piece piece{piece_begin, piece_end, g, g, level < 0 ? run.level : static_cast<uint8_t>(level)};
        while (g < run.glyph_end && shaped[g].cluster < piece_end) ++g;
        piece.glyph_end = g;
        glyph_cursor = g;
        // A line that cuts a run where HarfBuzz says the shaping depends on the other side
        // (a ligature or kerning pair across the cut, joining) gets its part re-shaped.
        const bool unsafe = (piece_begin != run.begin && !safe_to_break(piece_begin)) ||
                            (piece_end != run.end && !safe_to_break(piece_end));
        if (unsafe) {
            piece.glyph_begin = shaped.size();
            if (!shape(p0, p1, piece_begin, piece_end, run.level, run.script, run.font, run.style)) {
                failed = true;
                return;
            }
            piece.glyph_end = shaped.size();
        }
        pieces.push_back(piece);
    };
    if (begin >= end) return;
    while (run_cursor < runs.size() && runs[run_cursor].end <= begin) ++run_cursor;
    for (size_t r = run_cursor; r < runs.size() && runs[r].begin < end && !failed; ++r)
        add_piece(runs[r], std::max(begin, runs[r].begin), std::min(end, runs[r].end));
}

// The line's pieces: each run's part on the line, cut where trailing spaces begin (they hang: they
// take the paragraph's level, UAX #9 L1, and are placed past the content). Returns how many pieces
// are content, the rest are the hanging spaces; sets `failed` where re-shaping a cut run fails.
size_t Layouter::State::cut_pieces(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end, uint8_t base_level,
                                   size_t& run_cursor, size_t& glyph_cursor) {
    uint32_t content_end = line_end;
    while (content_end > line_begin && (flags[content_end - 1] & kCharSpace) != 0) --content_end;
    pieces.clear();
    add_pieces(p0, p1, line_begin, content_end, -1, run_cursor, glyph_cursor);
    const size_t content_pieces = pieces.size();
    if (!failed) add_pieces(p0, p1, content_end, line_end, base_level, run_cursor, glyph_cursor);
    return content_pieces;
}

double Layouter::State::shape_ellipsis(uint32_t style, uint32_t cluster) {
    const StyleView& view = styles[style];
    auto list_font = [&](uint16_t i) { return view.font_map == UINT32_MAX ? i : font_map[view.font_map + i]; };
    // U+2026 from the first font of the style's list that has it, else "..." from the first that
    // has '.', else U+2026 as the first font's .notdef.
    uint16_t font = list_font(0);
    uint32_t dots = 0x2026;
    int count = 1;
    auto first_with = [&](uint32_t cp, uint16_t& chosen) {
        for (uint16_t i = 0; i < view.font_count; ++i) {
            if (fonts[list_font(i)]->has_glyph_for(cp)) {
                chosen = list_font(i);
                return true;
            }
        }
        return false;
    };
    if (!first_with(0x2026, font) && first_with('.', font)) {
        dots = '.';
        count = 3;
    }
    const uint32_t text[3] = {dots, dots, dots};
    hb_buffer_clear_contents(buffer);
    hb_buffer_add_codepoints(buffer, text, count, 0, count);
    hb_buffer_guess_segment_properties(buffer);
    hb_buffer_set_direction(buffer, HB_DIRECTION_LTR);
    hb_shape(fonts[font]->harfbuzz_font(), buffer, nullptr, 0);
    unsigned glyphs = 0;
    const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &glyphs);
    const hb_glyph_position_t* positions = hb_buffer_get_glyph_positions(buffer, nullptr);
    const double per_unit = 1.0 / fonts[font]->units_per_em();
    const bool snap = options->snap_to_pixels;
    double width = 0.0;
    for (unsigned i = 0; i < glyphs && hb_buffer_allocation_successful(buffer); ++i) {
        ShapedGlyph glyph;
        glyph.glyph = infos[i].codepoint;
        glyph.cluster = cluster;
        const double advance = positions[i].x_advance * per_unit * view.size_x;
        glyph.advance = static_cast<float>(snap ? std::round(advance) : advance);
        glyph.y_offset = view.baseline_shift;
        glyph.font = font;
        glyph.ellipsis = true;
        shaped.push_back(glyph);
        width += static_cast<double>(glyph.advance);
    }
    return width;
}

void Layouter::State::place_trimmed_line(uint32_t p0, uint32_t p1, uint32_t line_begin, uint32_t line_end,
                                         uint8_t base_level, size_t& run_cursor, size_t& glyph_cursor) {
    const Trimming trimming = wrap_width > 0.0 ? options->trimming : Trimming::end;
    // What the line would show: its own text (end), or the rest of its paragraph (start, middle),
    // without spaces at its end.
    uint32_t end = trimming == Trimming::end ? line_end : p1;
    while (end > line_begin && (flags[end - 1] & kCharSpace) != 0) --end;
    const auto space = [&](uint32_t i) { return (flags[i] & kCharSpace) != 0; };
    const auto next_cluster = [&](uint32_t i) {
        do ++i;
        while (i < end && (flags[i] & kCharClusterStart) == 0);
        return i;
    };
    const auto previous_cluster = [&](uint32_t i) {
        do --i;
        while (i > line_begin && (flags[i] & kCharClusterStart) == 0);
        return i;
    };
    const auto width_of = [&](uint32_t a, uint32_t b) {
        double width = 0.0;
        for (uint32_t k = a; k < b; ++k) width += static_cast<double>(cluster_advance[k]);
        return width;
    };
    // Whole clusters from the start of the line that fit `budget`; from the end, down to `floor`.
    const auto head_fitting = [&](double budget) {
        uint32_t cut = line_begin;
        double width = 0.0;
        while (cut < end) {
            const uint32_t next = next_cluster(cut);
            const double w = width_of(cut, next);
            if (width + w > budget + kFitTolerance) break;
            width += w;
            cut = next;
        }
        while (cut > line_begin && space(cut - 1)) --cut;
        return cut;
    };
    const auto tail_fitting = [&](double budget, uint32_t floor) {
        uint32_t cut = end;
        double width = 0.0;
        while (cut > floor) {
            const uint32_t before = previous_cluster(cut);
            const double w = width_of(before, cut);
            if (before < floor || width + w > budget + kFitTolerance) break;
            width += w;
            cut = before;
        }
        while (cut < end && space(cut)) ++cut;
        return cut;
    };
    // The ellipsis takes the style of the text it follows (it precedes, with start trimming).
    const uint32_t anchor = trimming == Trimming::start || end == line_begin ? line_begin : end - 1;
    const size_t ellipsis_begin = shaped.size();
    const double ellipsis = shape_ellipsis(style_of[anchor], anchor);
    const Piece ellipsis_piece{anchor, anchor, ellipsis_begin, shaped.size(), base_level};
    const double available = std::max(0.0, wrap_width - ellipsis);
    uint32_t head_end = end, tail_begin = end;
    if (wrap_width > 0.0) {
        if (trimming == Trimming::end) {
            head_end = head_fitting(available);
        } else if (trimming == Trimming::start) {
            head_end = line_begin;
            tail_begin = tail_fitting(available, line_begin);
        } else {
            head_end = head_fitting(available * 0.5);
            tail_begin = tail_fitting(available - width_of(line_begin, head_end), head_end);
        }
    }
    pieces.clear();
    add_pieces(p0, p1, line_begin, head_end, -1, run_cursor, glyph_cursor);
    pieces.push_back(ellipsis_piece);
    if (!failed) add_pieces(p0, p1, tail_begin, end, -1, run_cursor, glyph_cursor);
    if (failed) return;
    order_pieces(pieces.size());
    finish_line(line_begin, trimming == Trimming::end ? line_end : p1, pieces.size(), base_level);
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
            if (tabs && tab_measure > 0.0 && (flags[glyph.cluster] & kCharTab) != 0) {
                // To the next tab stop from the line's left edge: the first of tab_stops past the
                // pen, then the tab width's (a stop closer than 1/1000 of a tab is skipped, as a
                // tab never has no width).
                const auto next = std::upper_bound(tab_stops.begin(), tab_stops.end(), x + 1e-3 * tab_measure);
                if (next != tab_stops.end())
                    advance = *next - x;
                else if (tab_width > 0.0)
                    advance = (std::floor(x / tab_width + 1e-3) + 1.0) * tab_width - x;
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
    finish_line(line_begin, line_end, content_pieces, base_level);
}

// Places the ordered pieces and records the line.
void Layouter::State::finish_line(uint32_t line_begin, uint32_t line_end, size_t content_pieces, uint8_t base_level) {
    const double width = place_pieces(content_pieces, base_level);
    const auto line = static_cast<uint32_t>(lines.size());
    LineRecord record{line_begin,    line_end,    width, strut_above,
                      strut_descent, strut_below, false, (base_level & 1) != 0};
    for (const Piece& piece : pieces) {
        for (size_t g = piece.glyph_begin; g < piece.glyph_end; ++g) {
            const ShapedGlyph& glyph = shaped[g];
            placed.push_back({glyph_x[g], glyph.y_offset, glyph.glyph, glyph.cluster, line, glyph.font, glyph.x_offset,
                              static_cast<float>(glyph_advance[g])});
            const StyleView& view = styles[style_of[glyph.cluster]];
            record.above = std::max(record.above, view.above);
            record.descent = std::max(record.descent, view.descent);
            record.below = std::max(record.below, view.descent + view.gap);
        }
    }
    record.tall = record.above > strut_above || record.below > strut_below;
    record_clusters(line);
    lines.push_back(record);
}

// The clusters of the placed pieces, in logical order: each run of glyphs of one HarfBuzz cluster
// value, reaching to the next cluster's first character (the piece's ends at its ends), from its
// leftmost pen over its glyphs' advances.
void Layouter::State::record_clusters(uint32_t line) {
    for (const Piece& piece : pieces) {
        // A trimmed line's ellipsis stands for hidden text: no caret goes into it.
        if (piece.begin == piece.end) continue;
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
    const double spacing = static_cast<double>(o.line_spacing);
    // Baseline to baseline: a fixed height where one is asked for; else the layout's style's line
    // height where neither line has a taller style, the lower box of the line before and the
    // upper box of this one where one has; times line_spacing.
    auto step = [&](const LineRecord& before, const LineRecord& line) {
        const double height = o.line_height > 0.0f ? static_cast<double>(o.line_height) * static_cast<double>(o.scale)
                              : !before.tall && !line.tall ? strut_height * spacing
                                                           : (before.below + line.above) * spacing;
        return snap ? std::round(height) : height;
    };
    const LineRecord strut{0, 0, 0.0, strut_above, strut_descent, strut_below, false, false};
    out.line_height = static_cast<float>(step(strut, strut));

    double align_width = wrap_width;
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
    double baseline = origin_y;
    for (size_t i = 0; i < lines.size(); ++i) {
        const LineRecord& line = lines[i];
        Align align = o.align;
        if (align == Align::start) align = line.rtl ? Align::right : Align::left;
        if (align == Align::end) align = line.rtl ? Align::left : Align::right;
        const double slack = align_width - line.width;
        double x = origin_x + (align == Align::right ? slack : align == Align::center ? slack * 0.5 : 0.0);
        if (snap) x = std::round(x);
        line_x[i] = x;
        if (i > 0) baseline += step(lines[i - 1], line);
        line_baseline[i] = baseline;
        left = std::min(left, x);
        right = std::max(right, x + line.width);
        TextLine& record = out.lines[i];
        record.text_begin = offsets[line.begin];
        record.text_end = offsets[line.end];
        record.x = static_cast<float>(x);
        record.baseline_y = static_cast<float>(baseline);
        record.width = static_cast<float>(line.width);
        record.ascent = static_cast<float>(line.above);
        record.descent = static_cast<float>(line.descent);
        record.rtl = line.rtl;
    }
    // Empty text: the box where its first line's would start, of no size (where its caret goes).
    out.x = static_cast<float>(origin_x);
    out.y = static_cast<float>(origin_y - strut_above);
    if (!lines.empty()) {
        // From the first line's top down to where a line after the last would start.
        out.x = static_cast<float>(left);
        out.width = static_cast<float>(right - left);
        const double top = origin_y - lines.front().above;
        out.y = static_cast<float>(top);
        out.height = static_cast<float>(baseline + step(lines.back(), strut) - strut_above - top);
    }
}

}  // namespace crisp
