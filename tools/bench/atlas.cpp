// crisp-bench --suite atlas: reuse against subpixel quantization. A page of real text at 16 px,
// wrapped at 900 px: how many distinct atlas entries (and cells) it needs at each quantization of
// the pen's subpixel offset, and the coverage error the quantization costs: each glyph's exact
// coverage (FreeType's area coverage, support/freetype_reference.hpp) at its pen quantized to
// 1/256 px, the finest a key holds, against the same at the quantized pen, on the same target
// pixels. No GPU: the errors are the reference's, so they are what any exact rasterizer pays.
#include "bench.hpp"
#include "freetype_reference.hpp"

#include <crisp/atlas.hpp>
#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "atlas";

const char* const kPageText =
    "It was the best of times, it was the worst of times, it was the age of wisdom, it was the age of "
    "foolishness, it was the epoch of belief, it was the epoch of incredulity, it was the season of Light, "
    "it was the season of Darkness, it was the spring of hope, it was the winter of despair, we had "
    "everything before us, we had nothing before us, we were all going direct to Heaven, we were all going "
    "direct the other way - in short, the period was so far like the present period, that some of its "
    "noisiest authorities insisted on its being received, for good or for evil, in the superlative degree "
    "of comparison only.\n";

// The coverage error of one quantization over the glyphs measured.
struct QuantizationError {
    double mean = 0.0;   // mean absolute error per texel channel, averaged over the glyphs
    double worst = 0.0;  // the worst texel channel
    uint32_t glyphs = 0;
};

struct Row {
    uint32_t steps = 0;
    size_t glyphs = 0;
    uint32_t entries = 0;
    uint32_t cells = 0;
    QuantizationError gray, rgb;
};

std::vector<GlyphInstance> lay_out_page(const Font& font, float size, uint32_t steps, const std::string& page) {
    const Font* fonts[] = {&font};
    LayoutOptions options;
    options.origin_x = 10.25f;
    options.origin_y = 20.0f;
    options.wrap_width = 900.0f;
    options.subpixel_steps = steps;
    TextStyle style;
    style.size = size;
    auto laid = layout_text(fonts, page, style, options);
    if (!laid) fail(kSuite, laid.error().message);
    return laid->glyphs;
}

// Distinct atlas entries and cells the page needs: every glyph acquired in one frame of a fresh atlas.
void count_entries(const Font& font, const std::vector<GlyphInstance>& glyphs, Row& row) {
    auto atlas = GlyphAtlas::create();
    if (!atlas) fail(kSuite, atlas.error().message);
    atlas->begin_frame();
    for (const GlyphInstance& glyph : glyphs) {
        uint64_t cost = 0;
        if (atlas->find(glyph.key) == kNoAtlasEntry) {
            cost = curve_tests_per_sample(font.asset(), font.asset().glyphs[glyph.key.glyph], glyph.key);
        }
        atlas->acquire(glyph.key, glyph.width, glyph.height, cost);
    }
    atlas->schedule();
    row.glyphs = glyphs.size();
    row.entries = atlas->stats().resident_glyphs;
    row.cells = atlas->stats().used_cells;
}

// The error of quantized pens against the finest ones, over the first `count` outlined glyphs:
// per glyph, both references on the same target pixels (the finest glyph's rect widened by a
// texel on each side), mean absolute error per texel channel averaged over the glyphs, and the
// worst channel.
QuantizationError quantization_error(freetype::Face& face, const Font& font, const std::vector<GlyphInstance>& finest,
                                     const std::vector<GlyphInstance>& quantized, size_t count,
                                     const SubpixelLayout& layout, uint32_t cells) {
    QuantizationError point;
    size_t measured = 0;
    for (size_t i = 0; i < finest.size() && i < quantized.size() && measured < count; ++i) {
        const GlyphInstance& a = finest[i];
        const GlyphInstance& b = quantized[i];
        if (a.width == 0 || !(a.key.glyph == b.key.glyph)) continue;
        const GlyphRecord& record = font.asset().glyphs[a.key.glyph];
        const GlyphRect rect_a = glyph_rect(record, a.key), rect_b = glyph_rect(record, b.key);
        const int32_t pen_ax = a.x - rect_a.x, pen_ay = a.y - rect_a.y;
        const int32_t pen_bx = b.x - rect_b.x, pen_by = b.y - rect_b.y;
        const GlyphRect wide_a{rect_a.x - 1, rect_a.y - 1, rect_a.width + 2, rect_a.height + 2};
        const GlyphRect wide_b{wide_a.x + pen_ax - pen_bx, wide_a.y + pen_ay - pen_by, wide_a.width, wide_a.height};
        auto image_a = freetype::reference_coverage(face, a.key, wide_a, layout, cells);
        auto image_b = freetype::reference_coverage(face, b.key, wide_b, layout, cells);
        if (!image_a) fail(kSuite, image_a.error().message);
        if (!image_b) fail(kSuite, image_b.error().message);
        auto error = freetype::compare_coverage(*image_a, *image_b);
        if (!error) fail(kSuite, error.error().message);
        point.mean += error->mean;
        point.worst = std::max(point.worst, error->worst);
        ++measured;
    }
    if (measured > 0) point.mean /= static_cast<double>(measured);
    point.glyphs = static_cast<uint32_t>(measured);
    return point;
}

}  // namespace

void run_atlas(Session& session) {
    const Options& o = session.options;
    const std::string font_path = o.fonts.empty() ? data_file("fonts/DejaVuSans.ttf") : o.fonts.front();
    const float size = o.size.value_or(16.0f);
    const size_t error_glyphs = o.quick ? 12 : 200;
    std::vector<uint32_t> steps = o.steps;
    if (o.quick && !o.steps_given) steps = {256, 4, 1};
    if (std::find(steps.begin(), steps.end(), 256u) == steps.end()) steps.insert(steps.begin(), 256u);

    auto baked = bake_font_file(font_path, BakeOptions{});
    if (!baked) fail(kSuite, baked.error().message);
    auto font = Font::create(std::move(baked->asset), 1);
    if (!font) fail(kSuite, font.error().message);
    auto face = freetype::Face::open_file(font_path);
    if (!face) fail(kSuite, font_path + ": FreeType: " + face.error().message);
    std::string page;
    for (int i = 0; i < (o.quick ? 1 : 6); ++i) page += kPageText;

    const SubpixelLayout gray = *subpixel_preset("gray"), rgb = *subpixel_preset("rgb");
    const std::vector<GlyphInstance> finest = lay_out_page(*font, size, 256, page);
    std::vector<Row> rows;
    for (const uint32_t s : steps) {
        progress(kSuite, std::to_string(s) + " subpixel steps per pixel");
        Row row;
        row.steps = s;
        const std::vector<GlyphInstance> glyphs = lay_out_page(*font, size, s, page);
        count_entries(*font, glyphs, row);
        row.gray = quantization_error(*face, *font, finest, glyphs, error_glyphs, gray, o.cells_gray);
        row.rgb = quantization_error(*face, *font, finest, glyphs, error_glyphs, rgb, o.cells_gray);
        rows.push_back(row);
    }

    std::fprintf(session.md,
                 "A page of prose (%s at %g px, wrapped at 900 px, %zu glyphs): the distinct atlas entries it needs "
                 "at each quantization of the pen's subpixel offset (x and y), and what the quantization costs: "
                 "for the first %u outlined glyphs, the exact coverage (FreeType area coverage, %ux%u cells per "
                 "texel) at the quantized pen against the same at the pen to 1/256 px, on the same pixels. Mean: "
                 "absolute error per texel channel averaged over the glyphs; worst: one texel channel.\n\n"
                 "| subpixel steps per pixel | distinct atlas entries | glyphs per entry | atlas cells used | gray: "
                 "mean | worst | rgb: mean | worst |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                 font_path.c_str(), static_cast<double>(size), finest.size(),
                 rows.empty() ? 0u : rows.front().gray.glyphs, o.cells_gray, o.cells_gray);
    session.json.begin_object()
        .field("font", font_path)
        .field("size", size)
        .field("page_glyphs", finest.size())
        .field("error_glyphs", rows.empty() ? 0u : rows.front().gray.glyphs)
        .field("cells", o.cells_gray)
        .key("rows")
        .begin_array();
    for (const Row& r : rows) {
        std::fprintf(session.md, "| %u | %u | %.2f | %u | %.4f | %.4f | %.4f | %.4f |\n", r.steps, r.entries,
                     static_cast<double>(r.glyphs) / std::max(1u, r.entries), r.cells, r.gray.mean, r.gray.worst,
                     r.rgb.mean, r.rgb.worst);
        session.json.begin_object()
            .field("steps", r.steps)
            .field("glyphs", r.glyphs)
            .field("entries", r.entries)
            .field("cells", r.cells)
            .field("gray_mean", r.gray.mean)
            .field("gray_worst", r.gray.worst)
            .field("rgb_mean", r.rgb.mean)
            .field("rgb_worst", r.rgb.worst)
            .end_object();
    }
    session.json.end_array().end_object();
}

}  // namespace crisp::bench
