// A frame's colour layers resolved for the compositor (docs/colour.md, "At run time").
#include "raster/paints.hpp"

#include <crisp/glyph.hpp>

#include <algorithm>
#include <cmath>

namespace crisp::raster {

namespace {

float linear_to_srgb(float linear) {
    const float c = linear >= 0.0f ? std::fmin(linear, 1.0f) : 0.0f;
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// A stop's colour: sRGB-encoded straight RGBA (the palette entry, or the text's colour with alpha 1
// for the foreground index) with its alpha times the stop's.
std::array<float, 4> stop_colour(const FontAsset& asset, uint32_t palette, const ColourStop& stop,
                                 const GlyphInstance& instance) {
    std::array<float, 4> c{};
    if (stop.palette_index == kForegroundPaletteIndex || stop.palette_index >= asset.palette_size) {
        for (int i = 0; i < 3; ++i) c[static_cast<size_t>(i)] = linear_to_srgb(instance.color[i]);
        c[3] = 1.0f;
    } else {
        const uint32_t rgba = asset.palette_colours[size_t{palette} * asset.palette_size + stop.palette_index];
        for (size_t i = 0; i < 4; ++i) c[i] = static_cast<float>((rgba >> (8 * i)) & 0xFFu) / 255.0f;
    }
    c[3] *= stop.alpha;
    return c;
}

// Where a layer's em space lands in the target's pixels: pixel = (x, y) + A e, e in em (y up),
// pixels y down. A transformed glyph's map is its key's linear part (with perspective, its local
// affine map at the bbox centre: paints are affine).
struct PenPlace {
    double x = 0.0, y = 0.0;              // pixels, y down
    double a[4] = {1.0, 0.0, 0.0, -1.0};  // pixels per em
    double px(double ex, double ey) const { return x + a[0] * ex + a[1] * ey; }
    double py(double ex, double ey) const { return y + a[2] * ex + a[3] * ey; }
};

PenPlace pen_place(const DrawnGlyph& glyph, const GlyphRecord& record) {
    const GlyphInstance& instance = glyph.instance;
    const GlyphKey& key = instance.key;
    const GlyphRect rect = glyph_rect(record, key);
    PenPlace pen;
    pen.x = static_cast<double>(instance.x) - glyph.part_x - rect.x +
            static_cast<double>(subpixel_to_float(key.subpixel_x));
    pen.y = static_cast<double>(instance.y) - glyph.part_y - rect.y +
            static_cast<double>(subpixel_to_float(key.subpixel_y));
    if (!is_transformed(key)) {
        pen.a[0] = static_cast<double>(size_to_float(key.size_x));
        pen.a[3] = -static_cast<double>(size_to_float(key.size_y));
        return pen;
    }
    double l[4], p[2];
    for (int i = 0; i < 4; ++i) l[i] = static_cast<double>(key.linear[i]) / kLinearOne;
    for (int i = 0; i < 2; ++i) p[i] = static_cast<double>(key.perspective[i]) / kPerspectiveOne;
    // q(e) = L e / w(e), w = 1 + p . e; at the centre c: J = (L - q(c) p^T) / w(c).
    const double cx = 0.5 * static_cast<double>(record.bbox_min_x + record.bbox_max_x);
    const double cy = 0.5 * static_cast<double>(record.bbox_min_y + record.bbox_max_y);
    const double w = 1.0 + p[0] * cx + p[1] * cy;
    const double qx = (l[0] * cx + l[1] * cy) / w, qy = (l[2] * cx + l[3] * cy) / w;
    pen.a[0] = (l[0] - qx * p[0]) / w;
    pen.a[1] = (l[1] - qx * p[1]) / w;
    pen.a[2] = (l[2] - qy * p[0]) / w;
    pen.a[3] = (l[3] - qy * p[1]) / w;
    pen.x += qx - pen.a[0] * cx - pen.a[1] * cy;
    pen.y += qy - pen.a[2] * cx - pen.a[3] * cy;
    return pen;
}

// to_paint (from em, y up) after the pixels-to-em map, the inverse of the pen's.
void pixel_to_paint(const Affine& m, const PenPlace& pen, float out[6]) {
    const auto wide = [](float value) { return static_cast<double>(value); };
    const double xx = wide(m.xx), xy = wide(m.xy), yx = wide(m.yx), yy = wide(m.yy), dx = wide(m.dx), dy = wide(m.dy);
    const double det = pen.a[0] * pen.a[3] - pen.a[1] * pen.a[2];
    const double i00 = pen.a[3] / det, i01 = -pen.a[1] / det, i10 = -pen.a[2] / det, i11 = pen.a[0] / det;
    const double ax = xx * i00 + xy * i10, bx = xx * i01 + xy * i11;
    const double ay = yx * i00 + yy * i10, by = yx * i01 + yy * i11;
    out[0] = static_cast<float>(ax);
    out[1] = static_cast<float>(bx);
    out[2] = static_cast<float>(dx - ax * pen.x - bx * pen.y);
    out[3] = static_cast<float>(ay);
    out[4] = static_cast<float>(by);
    out[5] = static_cast<float>(dy - ay * pen.x - by * pen.y);
}

}  // namespace

void FramePaints::resolve(std::span<DrawnGlyph> drawn, const HeldFonts& fonts, ImagePlaces* images,
                          RendererStats& stats) {
    paints_.clear();
    stops_.clear();
    for (DrawnGlyph& glyph : drawn) {
        GlyphInstance& instance = glyph.instance;
        glyph.paint = kNoPaint;
        if (instance.paint == kNoPaint) continue;
        const FontAsset* asset = fonts.asset(instance.key.font);
        if (!asset || instance.paint >= asset->paints.size() || instance.key.glyph >= asset->glyphs.size()) continue;
        ++stats.colour_layers;
        const Paint& paint = asset->paints[instance.paint];
        const uint32_t palette = instance.palette < asset->palette_count() ? instance.palette : 0;
        const PenPlace pen = pen_place(glyph, asset->glyphs[instance.key.glyph]);
        const float text_alpha = instance.color[3];

        FramePaint fill;
        fill.kind = paint.kind;
        fill.extend = paint.extend;
        fill.opacity = text_alpha;
        const ColourGlyph* colour = instance.colour_glyph < asset->colour_glyphs.size()
                                        ? &asset->colour_glyphs[instance.colour_glyph]
                                        : nullptr;
        const bool clipped = colour && (colour->flags & kColourClipped) != 0;
        if (clipped) {
            // The clip box's pixel bounds (a transformed glyph's box is not axis-aligned: its bounds).
            const double ex[2] = {static_cast<double>(colour->clip_min_x), static_cast<double>(colour->clip_max_x)};
            const double ey[2] = {static_cast<double>(colour->clip_min_y), static_cast<double>(colour->clip_max_y)};
            double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
            for (double u : ex) {
                for (double v : ey) {
                    x0 = std::min(x0, pen.px(u, v));
                    x1 = std::max(x1, pen.px(u, v));
                    y0 = std::min(y0, pen.py(u, v));
                    y1 = std::max(y1, pen.py(u, v));
                }
            }
            fill.clip[0] = static_cast<float>(x0);
            fill.clip[1] = static_cast<float>(y0);
            fill.clip[2] = static_cast<float>(x1);
            fill.clip[3] = static_cast<float>(y1);
        }
        if (paint.kind == PaintKind::solid) {
            // One colour: the instance's, linear and straight, with the text's alpha.
            const std::array<float, 4> c = stop_colour(*asset, palette, asset->stops[paint.first_stop], instance);
            for (int i = 0; i < 3; ++i) instance.color[i] = srgb_to_linear(c[static_cast<size_t>(i)]);
            instance.color[3] = c[3] * text_alpha;
            if (!clipped) continue;
        } else if (paint.kind == PaintKind::image) {
            const std::optional<ImagePlace> place =
                images ? images->place(instance.key.font, *asset, paint.image) : std::nullopt;
            if (!place) {
                ++stats.bitmap_misses;
                instance.color[3] = 0.0f;  // drawn without its image: nothing
                continue;
            }
            fill.image_layer = place->layer;
            fill.image_extent[0] = place->extent_u;
            fill.image_extent[1] = place->extent_v;
        } else {
            fill.first_stop = static_cast<uint32_t>(stops_.size());
            fill.stop_count = paint.stop_count;
            for (uint32_t i = 0; i < paint.stop_count; ++i) {
                const ColourStop& stop = asset->stops[paint.first_stop + i];
                const std::array<float, 4> c = stop_colour(*asset, palette, stop, instance);
                stops_.push_back(FrameStop{{c[0] * c[3], c[1] * c[3], c[2] * c[3], c[3]}, stop.offset});
            }
        }
        pixel_to_paint(paint.to_paint, pen, fill.to_paint);
        std::copy(std::begin(paint.geometry), std::end(paint.geometry), std::begin(fill.geometry));
        glyph.paint = static_cast<uint32_t>(paints_.size());
        paints_.push_back(fill);
    }
    stats.frame_paints = static_cast<uint32_t>(paints_.size());
}

}  // namespace crisp::raster
