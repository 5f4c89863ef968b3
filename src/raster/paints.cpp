// A frame's colour layers resolved for the compositor (docs/colour.md, "At run time").
#include "raster/paints.hpp"

#include <crisp/glyph.hpp>

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

// Where a layer's em space lands in the target's pixels: its pen (the whole pixel plus the key's
// subpixel offset) and its pixels per em.
struct PenPlace {
    double x = 0.0, y = 0.0;    // pixels, y down
    double sx = 1.0, sy = 1.0;  // pixels per em
};

PenPlace pen_place(const DrawnGlyph& glyph, const GlyphRecord& record) {
    const GlyphInstance& instance = glyph.instance;
    const GlyphRect rect = glyph_rect(record, instance.key);
    PenPlace pen;
    pen.x = static_cast<double>(instance.x) - glyph.part_x - rect.x +
            static_cast<double>(subpixel_to_float(instance.key.subpixel_x));
    pen.y = static_cast<double>(instance.y) - glyph.part_y - rect.y +
            static_cast<double>(subpixel_to_float(instance.key.subpixel_y));
    pen.sx = static_cast<double>(size_to_float(instance.key.size_x));
    pen.sy = static_cast<double>(size_to_float(instance.key.size_y));
    return pen;
}

// to_paint (from em, y up) after the pixels-to-em map X -> ((X - pen.x) / sx, -(Y - pen.y) / sy).
void pixel_to_paint(const Affine& m, const PenPlace& pen, float out[6]) {
    const auto wide = [](float value) { return static_cast<double>(value); };
    const double xx = wide(m.xx), xy = wide(m.xy), yx = wide(m.yx), yy = wide(m.yy), dx = wide(m.dx), dy = wide(m.dy);
    const double ax = xx / pen.sx, bx = -xy / pen.sy;
    const double ay = yx / pen.sx, by = -yy / pen.sy;
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
            fill.clip[0] = static_cast<float>(pen.x + static_cast<double>(colour->clip_min_x) * pen.sx);
            fill.clip[1] = static_cast<float>(pen.y - static_cast<double>(colour->clip_max_y) * pen.sy);
            fill.clip[2] = static_cast<float>(pen.x + static_cast<double>(colour->clip_max_x) * pen.sx);
            fill.clip[3] = static_cast<float>(pen.y - static_cast<double>(colour->clip_min_y) * pen.sy);
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
