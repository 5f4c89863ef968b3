// crisp-editing-picture: the data of docs/images/layout-editing.png as JSON on stdout, for
// scripts/plot_editing.py: a mixed-direction line laid out with DejaVu Sans, its glyphs' outlines
// on the canvas, its clusters, a selection's rectangles and the carets of every grapheme boundary
// on both sides (docs/layout.md, "Editing").
//
//     crisp-editing-picture > editing.json && python3 scripts/plot_editing.py editing.json out.png
#include <crisp/bake.hpp>
#include <crisp/editing.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include "json_writer.hpp"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

// "office" (an ffi ligature), Hebrew with digits inside, Arabic: three direction boundaries.
constexpr const char* kText = "office \u05E9\u05DC\u05D5\u05DD 123 \u0645\u0631\u062D\u0628\u0627 end";
constexpr float kSize = 40.0f;

void write_rect(crisp::JsonWriter& json, const crisp::TextRect& rect) {
    json.begin_array().value(rect.x).value(rect.y).value(rect.width).value(rect.height).end_array();
}

}  // namespace

int main() {
    using namespace crisp;
    Result<BakeResult> baked = bake_font_file(std::string(CRISP_SOURCE_DIR) + "/fonts/DejaVuSans.ttf", {});
    if (!baked) {
        std::fprintf(stderr, "crisp-editing-picture: %s\n", baked.error().message.c_str());
        return 1;
    }
    Result<Font> font = Font::create(std::move(baked->asset), 1);
    if (!font) {
        std::fprintf(stderr, "crisp-editing-picture: %s\n", font.error().message.c_str());
        return 1;
    }
    const Font* fonts[] = {&*font};
    LayoutOptions options;
    options.origin_x = 10.0f;
    options.origin_y = 50.0f;
    Result<TextLayout> layout = layout_text(fonts, kText, {.size = kSize}, options);
    Result<TextBoundaries> boundaries = TextBoundaries::analyze(kText);
    if (!layout || !boundaries) {
        std::fprintf(stderr, "crisp-editing-picture: %s\n",
                     (!layout ? layout.error() : boundaries.error()).message.c_str());
        return 1;
    }

    JsonWriter json;
    json.begin_object().field("text", kText).field("size", kSize);
    json.key("box")
        .begin_array()
        .value(layout->x)
        .value(layout->y)
        .value(layout->width)
        .value(layout->height)
        .end_array();
    // Each glyph's contours on the canvas (y down): arrays of quadratic curves, six numbers each.
    // The asset chains a glyph's contours with pad curves (a pad's control point is its start).
    json.key("glyphs").begin_array();
    const FontAsset& asset = font->asset();
    for (const GlyphInstance& glyph : layout->glyphs) {
        const GlyphRecord* record = font->glyph_record(glyph.key.glyph);
        if (record == nullptr || record->curve_count == 0) continue;
        const auto pen_x = static_cast<double>(glyph.pen_x), pen_y = static_cast<double>(glyph.pen_y);
        const auto size = static_cast<double>(kSize);
        const Point* points = asset.points.data() + record->point_offset;
        json.begin_array().begin_array();
        for (uint32_t i = 0; i < record->curve_count; ++i) {
            const Point& p0 = points[2 * i];
            const Point& p1 = points[2 * i + 1];
            if (p1 == p0 && points[2 * i + 2] != p0) {
                json.end_array().begin_array();  // a pad: the next contour starts
                continue;
            }
            json.begin_array();
            for (uint32_t k = 0; k < 3; ++k) {
                const Point& point = points[2 * i + k];
                json.value(pen_x + static_cast<double>(point.x) * size)
                    .value(pen_y - static_cast<double>(point.y) * size);
            }
            json.end_array();
        }
        json.end_array().end_array();
    }
    json.end_array();
    json.key("clusters").begin_array();
    for (const TextCluster& cluster : layout->clusters) {
        json.begin_object()
            .field("begin", cluster.text_begin)
            .field("end", cluster.text_end)
            .field("x", cluster.x)
            .field("advance", cluster.advance)
            .field("level", cluster.level)
            .end_object();
    }
    json.end_array();
    // The selection: from inside the ligature to inside the Arabic, across both direction runs.
    const uint32_t selection_begin = 2, selection_end = 26;
    std::vector<TextRect> rects;
    selection_rects(*layout, *boundaries, selection_begin, selection_end, rects);
    json.key("selection").begin_object().field("begin", selection_begin).field("end", selection_end).key("rects");
    json.begin_array();
    for (const TextRect& rect : rects) write_rect(json, rect);
    json.end_array().end_object();
    json.key("carets").begin_array();
    for (uint32_t offset : boundaries->graphemes()) {
        json.begin_object().field("offset", offset).key("downstream");
        write_rect(json, caret_rect(*layout, *boundaries, {offset, false}, 2.0f));
        json.key("upstream");
        write_rect(json, caret_rect(*layout, *boundaries, {offset, true}, 2.0f));
        json.end_object();
    }
    json.end_array().end_object();
    std::puts(json.text().c_str());
    return 0;
}
