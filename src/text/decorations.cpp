// Layout's decorations: underlines and strikethroughs (TextStyle::underline, ::strikethrough) as
// rectangles, at the positions and thicknesses of the font's post and OS/2 tables, merged along a
// line and broken around descenders where the style skips ink.
#include "text/layout_state.hpp"

#include <hb-ot.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace crisp {

namespace {

// Where the glyph's outline lies within the heights [low, high] (em, y up), as [left, right] in em
// relative to the pen; false where it does not reach them. The curves come from the glyph's bands
// that overlap those heights (a pad between contours is in none), each sampled at 16 points and
// clipped to the heights.
bool ink_between(const FontAsset& asset, const GlyphRecord& glyph, double low, double high, double& left,
                 double& right) {
    if (glyph.curve_count == 0 || glyph.band_count == 0 || high < static_cast<double>(glyph.bbox_min_y) ||
        low > static_cast<double>(glyph.bbox_max_y))
        return false;
    const double band_height = static_cast<double>(glyph.bbox_max_y - glyph.bbox_min_y) / glyph.band_count;
    const auto band_of = [&](double y) {
        const double band =
            band_height > 0.0 ? std::floor((y - static_cast<double>(glyph.bbox_min_y)) / band_height) : 0.0;
        return static_cast<uint32_t>(std::clamp(band, 0.0, static_cast<double>(glyph.band_count - 1)));
    };
    const uint32_t first_band = band_of(low), last_band = band_of(high);
    left = std::numeric_limits<double>::infinity();
    right = -left;
    const Point* points = asset.points.data() + glyph.point_offset;
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        bool listed = false;
        for (uint32_t band = first_band; band <= last_band && !listed; ++band) {
            const size_t word = size_t{glyph.band_offset} + size_t{band} * glyph.band_words + slot / 32;
            listed = ((asset.band_words[word] >> (slot % 32)) & 1u) != 0;
        }
        if (!listed) continue;
        const double ax = static_cast<double>(points[2 * slot].x), ay = static_cast<double>(points[2 * slot].y);
        const double bx = static_cast<double>(points[2 * slot + 1].x), by = static_cast<double>(points[2 * slot + 1].y);
        const double cx = static_cast<double>(points[2 * slot + 2].x), cy = static_cast<double>(points[2 * slot + 2].y);
        constexpr int kSamples = 16;
        auto at = [&](int k, double& x, double& y) {
            const double t = static_cast<double>(k) / kSamples, u = 1.0 - t;
            x = u * u * ax + 2.0 * u * t * bx + t * t * cx;
            y = u * u * ay + 2.0 * u * t * by + t * t * cy;
        };
        double x0 = 0.0, y0 = 0.0;
        at(0, x0, y0);
        for (int k = 1; k <= kSamples; ++k) {
            double x1 = 0.0, y1 = 0.0;
            at(k, x1, y1);
            // The segment's part within [low, high].
            const double ya = std::min(y0, y1), yb = std::max(y0, y1);
            if (yb >= low && ya <= high) {
                const auto x_at = [&](double y) { return y1 == y0 ? x0 : x0 + (x1 - x0) * (y - y0) / (y1 - y0); };
                const double from = x_at(std::clamp(y0, low, high)), to = x_at(std::clamp(y1, low, high));
                left = std::min({left, from, to});
                right = std::max({right, from, to});
            }
            x0 = x1;
            y0 = y1;
        }
    }
    return left <= right;
}

}  // namespace

void Layouter::State::decorate(TextLayout& out) {
    bool any = false;
    for (const StyleView& view : styles) any = any || view.style->underline || view.style->strikethrough;
    if (!any) return;
    const bool snap = options->snap_to_pixels;
    std::vector<DecorationStretch>& stretches = decoration_stretches;
    size_t p = 0;
    for (size_t line = 0; line < lines.size(); ++line) {
        stretches.clear();
        for (; p < placed.size() && placed[p].line == line; ++p) {
            const PlacedGlyph& glyph = placed[p];
            const uint32_t style = style_of[glyph.cluster];
            const StyleView& view = styles[style];
            if (!view.style->underline && !view.style->strikethrough) continue;
            // The line's position and thickness from the style's first font, so a span draws one
            // straight line whatever its fallback fonts.
            const Font& font = *fonts[view.font_map == UINT32_MAX ? 0 : font_map[view.font_map]];
            const double per_unit = view.size_y / font.units_per_em();
            const double left = line_x[line] + glyph.x - static_cast<double>(glyph.x_offset);
            const double baseline = line_baseline[line] - static_cast<double>(view.baseline_shift);
            auto add = [&](hb_ot_metrics_tag_t offset_tag, hb_ot_metrics_tag_t size_tag, DecorationKind kind) {
                hb_position_t offset = 0, size = 0;
                hb_ot_metrics_get_position_with_fallback(font.harfbuzz_font(), offset_tag, &offset);
                hb_ot_metrics_get_position_with_fallback(font.harfbuzz_font(), size_tag, &size);
                double thickness = std::max(1.0, static_cast<double>(size)) * per_unit;
                double top = baseline - static_cast<double>(offset) * per_unit;  // the tables give the top
                if (snap) {
                    thickness = std::max(1.0, std::round(thickness));
                    top = std::round(top);
                }
                // A negative letter spacing can make an advance negative: the stretch still runs
                // left to right.
                const double right = left + static_cast<double>(glyph.advance);
                stretches.push_back({std::min(left, right), std::max(left, right), top, top + thickness, style,
                                     static_cast<uint32_t>(p), kind});
            };
            if (view.style->underline)
                add(HB_OT_METRICS_TAG_UNDERLINE_OFFSET, HB_OT_METRICS_TAG_UNDERLINE_SIZE, DecorationKind::underline);
            if (view.style->strikethrough)
                add(HB_OT_METRICS_TAG_STRIKEOUT_OFFSET, HB_OT_METRICS_TAG_STRIKEOUT_SIZE,
                    DecorationKind::strikethrough);
        }
        if (stretches.empty()) continue;
        std::stable_sort(stretches.begin(), stretches.end(),
                         [](const DecorationStretch& a, const DecorationStretch& b) {
                             return a.kind != b.kind ? a.kind < b.kind : a.left < b.left;
                         });
        const size_t first = out.decorations.size();
        for (const DecorationStretch& stretch : stretches) {
            const StyleView& view = styles[stretch.style];
            const PlacedGlyph& glyph = placed[stretch.glyph];
            const uint32_t begin = offsets[glyph.cluster];
            uint32_t end = glyph.cluster + 1 < offsets.size() ? offsets[glyph.cluster + 1] : begin;
            end = std::max(end, begin);
            if (out.decorations.size() > first) {
                TextDecoration& last = out.decorations.back();
                const bool same = last.kind == stretch.kind && std::equal(last.color, last.color + 4, view.color) &&
                                  last.depth == view.style->depth && last.y == static_cast<float>(stretch.top) &&
                                  last.height == static_cast<float>(stretch.bottom - stretch.top);
                const double last_right = static_cast<double>(last.x) + static_cast<double>(last.width);
                // Touching or (with negative letter spacing) overlapping: one rectangle, so that
                // no pixel is painted twice.
                if (same && stretch.left <= last_right + 1e-3) {
                    last.width = static_cast<float>(std::max(last_right, stretch.right) - static_cast<double>(last.x));
                    last.text_begin = std::min(last.text_begin, begin);
                    last.text_end = std::max(last.text_end, end);
                    continue;
                }
            }
            TextDecoration decoration;
            decoration.x = static_cast<float>(stretch.left);
            decoration.y = static_cast<float>(stretch.top);
            decoration.width = static_cast<float>(stretch.right - stretch.left);
            decoration.height = static_cast<float>(stretch.bottom - stretch.top);
            std::copy(view.color, view.color + 4, decoration.color);
            decoration.depth = view.style->depth;
            decoration.line = static_cast<uint32_t>(line);
            decoration.text_begin = begin;
            decoration.text_end = end;
            decoration.kind = stretch.kind;
            out.decorations.push_back(decoration);
        }
        skip_ink(first, out);
    }
}

// Breaks the underlines from `first` on (one line's) where a glyph's ink crosses them, with a gap
// of one thickness either side, for the styles that skip ink.
void Layouter::State::skip_ink(size_t first, TextLayout& out) {
    std::vector<TextDecoration>& kept = decoration_pieces;
    kept.clear();
    const uint32_t line = out.decorations.empty() ? 0 : out.decorations.back().line;
    size_t p = 0;
    while (p < placed.size() && placed[p].line < line) ++p;
    const size_t line_glyphs = p;
    for (size_t d = first; d < out.decorations.size(); ++d) {
        const TextDecoration decoration = out.decorations[d];
        if (decoration.kind != DecorationKind::underline) {
            kept.push_back(decoration);
            continue;
        }
        // Gaps of the glyphs on the line whose style skips ink and whose outline crosses it.
        gaps.clear();
        const double pad = static_cast<double>(decoration.height);
        for (size_t g = line_glyphs; g < placed.size() && placed[g].line == line; ++g) {
            const PlacedGlyph& glyph = placed[g];
            const StyleView& view = styles[style_of[glyph.cluster]];
            if (!view.style->skip_ink || !view.style->underline) continue;
            const FontView& font = font_views[glyph.font];
            if (!font.is_baked(glyph.glyph)) continue;
            const double pen_x = line_x[line] + glyph.x;
            const double pen_y = line_baseline[line] - static_cast<double>(glyph.y_offset);
            // The underline's heights in the glyph's em, y up.
            const double low = (pen_y - static_cast<double>(decoration.y + decoration.height)) / view.size_y;
            const double high = (pen_y - static_cast<double>(decoration.y)) / view.size_y;
            double left = 0.0, right = 0.0;
            if (!ink_between(*font.asset, font.glyphs[glyph.glyph], low, high, left, right)) continue;
            gaps.emplace_back(pen_x + left * view.size_x - pad, pen_x + right * view.size_x + pad);
        }
        std::sort(gaps.begin(), gaps.end());
        double x = static_cast<double>(decoration.x);
        const double end = x + static_cast<double>(decoration.width);
        for (const auto& [gap_left, gap_right] : gaps) {
            if (gap_right <= x || gap_left >= end) continue;
            if (gap_left > x) {
                TextDecoration piece = decoration;
                piece.x = static_cast<float>(x);
                piece.width = static_cast<float>(gap_left - x);
                kept.push_back(piece);
            }
            x = std::max(x, gap_right);
        }
        if (end > x) {
            TextDecoration piece = decoration;
            piece.x = static_cast<float>(x);
            piece.width = static_cast<float>(end - x);
            kept.push_back(piece);
        }
    }
    out.decorations.resize(first);
    out.decorations.insert(out.decorations.end(), kept.begin(), kept.end());
}

}  // namespace crisp
