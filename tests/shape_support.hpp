// Shared by the GPU tests: glyphs of hand-made contours (shapes no font in the repository has) and
// glyphs placed by hand.
#pragma once

#include "asset/bands.hpp"
#include "asset/curves.hpp"
#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>

#include <cmath>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace crisp::test {

// The font at `path` baked with only the glyphs of `text`, as FontId 1; null when baking fails.
inline std::unique_ptr<Font> bake_subset(const std::string& path, std::string_view text) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = decode_utf8(text);
    auto baked = bake_font_file(path, options);
    if (!baked) return nullptr;
    auto font = Font::create(std::move(baked->asset), 1);
    return font ? std::make_unique<Font>(std::move(*font)) : nullptr;
}

// Replaces the last outlined glyph of a subset asset with hand-made contours, so the rasterizer
// meets shapes no font in the repository has.
inline std::unique_ptr<Font> with_shape(const std::vector<Contour>& contours, uint32_t& glyph_index) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = decode_utf8("o");
    auto baked = bake_font_file(test::kDejaVuSans, options);
    if (!baked) return nullptr;
    FontAsset asset = std::move(baked->asset);
    glyph_index = 0;
    for (uint32_t g = 0; g < asset.glyphs.size(); ++g) {
        if (asset.glyphs[g].curve_count > 0) glyph_index = g;
    }
    GlyphRecord& record = asset.glyphs[glyph_index];
    asset.points.resize(record.point_offset);
    asset.band_words.resize(record.band_offset);
    const PackedGlyph packed = pack_contours(contours);
    const GlyphBands bands = build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap);
    record.bbox_min_x = packed.min_x;
    record.bbox_min_y = packed.min_y;
    record.bbox_max_x = packed.max_x;
    record.bbox_max_y = packed.max_y;
    record.curve_count = packed.curve_count;
    record.band_count = bands.band_count;
    record.band_words = bands.band_words;
    asset.points.insert(asset.points.end(), packed.points.begin(), packed.points.end());
    asset.band_words.insert(asset.band_words.end(), bands.words.begin(), bands.words.end());
    if (!validate_asset(asset)) return nullptr;
    auto font = Font::create(std::move(asset), 1);
    return font ? std::make_unique<Font>(std::move(*font)) : nullptr;
}

inline Contour polygon(std::initializer_list<Vec2> corners) {
    Contour contour;
    const std::vector<Vec2> points(corners);
    for (size_t i = 0; i < points.size(); ++i)
        contour.push_back(line_to_quad(points[i], points[(i + 1) % points.size()]));
    return contour;
}

inline Contour circle(double cx, double cy, double r, bool clockwise) {
    // Eight quadratic arcs, control points on the tangents.
    Contour contour;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < 8; ++i) {
        const double a0 = (clockwise ? -1 : 1) * i * pi / 4, a1 = (clockwise ? -1 : 1) * (i + 1) * pi / 4;
        const double am = 0.5 * (a0 + a1), k = r / std::cos(pi / 8);
        contour.push_back({{cx + r * std::cos(a0), cy + r * std::sin(a0)},
                           {cx + k * std::cos(am), cy + k * std::sin(am)},
                           {cx + r * std::cos(a1), cy + r * std::sin(a1)}});
    }
    return contour;
}

// A five-pointed star, clockwise in y-up (TrueType's outer direction): sharp convex tips and
// concave notches.
inline std::vector<Contour> star() {
    std::vector<Vec2> corners;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < 10; ++i) {
        const double a = pi / 2 - i * pi / 5;
        const double radius = i % 2 == 0 ? 0.35 : 0.14;
        corners.push_back({0.4 + radius * std::cos(a), 0.37 + radius * std::sin(a)});
    }
    Contour contour;
    for (size_t i = 0; i < corners.size(); ++i)
        contour.push_back(line_to_quad(corners[i], corners[(i + 1) % corners.size()]));
    return {contour};
}

// A glyph of `font` laid out by hand at (x, y) at `size` px per em, its pen kept for transforms.
inline GlyphInstance place(const Font& font, uint32_t glyph_index, float size, float x, float y) {
    GlyphInstance g;
    g.key.font = font.id();
    g.key.glyph = glyph_index;
    g.key.size_x = g.key.size_y = static_cast<uint32_t>(std::lround(size * kSizeOne));
    const double xd = x, yd = y, fx = std::floor(xd), fy = std::floor(yd);
    g.key.subpixel_x = static_cast<uint8_t>(std::lround((xd - fx) * kSubpixelSteps) % kSubpixelSteps);
    g.key.subpixel_y = static_cast<uint8_t>(std::lround((yd - fy) * kSubpixelSteps) % kSubpixelSteps);
    const GlyphRect rect = glyph_rect(font.asset().glyphs[glyph_index], g.key);
    g.x = static_cast<int32_t>(fx) + rect.x;
    g.y = static_cast<int32_t>(fy) + rect.y;
    g.width = rect.width;
    g.height = rect.height;
    g.pen_x = x;
    g.pen_y = y;
    return g;
}

}  // namespace crisp::test
