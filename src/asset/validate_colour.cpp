// crisp: the rules on an asset's colour glyphs (docs/asset-format.md, "Colour glyphs"), part of
// validate_asset. Like the glyph rules they bound validation by the asset's size: every range is
// checked once, in order, and records that share ranges are refused.
#include "asset/asset_format.hpp"

#include <crisp/asset.hpp>

#include <cmath>

namespace crisp::asset_format {

namespace {

// Paint geometry and mappings stay in a range where the shaders' float arithmetic is meaningful.
constexpr float kMaxPaintValue = 1.0e6f;

bool is_sane(float value) {
    return std::isfinite(value) && std::fabs(value) <= kMaxPaintValue;
}

Status check_synthetic_glyphs(const FontAsset& asset) {
    const uint32_t face_glyphs = asset.face_glyph_count();
    if (face_glyphs == 0) return invalid("asset: glyph 0 is synthetic; the face's glyphs come first");
    if (asset.glyphs.size() - face_glyphs > kMaxSyntheticGlyphs)
        return invalid("asset: {} synthetic glyphs, at most {}", asset.glyphs.size() - face_glyphs,
                       kMaxSyntheticGlyphs);
    for (size_t i = face_glyphs; i < asset.glyphs.size(); ++i) {
        const GlyphRecord& glyph = asset.glyphs[i];
        if ((glyph.flags & kGlyphSynthetic) == 0)
            return invalid("asset: glyph {} follows the synthetic glyph {} but is not synthetic", i, face_glyphs);
        if ((glyph.flags & kGlyphBaked) == 0 || (glyph.flags & kGlyphFailed) != 0)
            return invalid("asset: synthetic glyph {}: flags {}, must be baked and not failed", i, Hex{glyph.flags});
    }
    return {};
}

Status check_palettes(const FontAsset& asset) {
    if (asset.palette_size == 0) {
        if (!asset.palette_colours.empty())
            return invalid("asset: {} palette colours but a palette size of 0", asset.palette_colours.size());
        return {};
    }
    if (asset.palette_size > kMaxPaletteSize)
        return invalid("asset: palettes of {} entries, at most {}", asset.palette_size, kMaxPaletteSize);
    if (asset.palette_colours.empty() || asset.palette_colours.size() % asset.palette_size != 0)
        return invalid("asset: {} palette colours are not whole palettes of {}", asset.palette_colours.size(),
                       asset.palette_size);
    if (asset.palette_colours.size() / asset.palette_size > kMaxPalettes)
        return invalid("asset: {} palettes, at most {}", asset.palette_colours.size() / asset.palette_size,
                       kMaxPalettes);
    return {};
}

Status check_stop(const FontAsset& asset, size_t paint, const ColourStop& stop, float previous_offset) {
    if (!is_sane(stop.offset))
        return invalid("asset: paint {}: stop offset {} is not a sane number", paint, stop.offset);
    if (stop.offset < previous_offset)
        return invalid("asset: paint {}: stop offset {} after {}: stops are sorted", paint, stop.offset,
                       previous_offset);
    if (!(stop.alpha >= 0.0f && stop.alpha <= 1.0f))
        return invalid("asset: paint {}: stop alpha {} outside [0, 1]", paint, stop.alpha);
    if (stop.palette_index != kForegroundPaletteIndex && stop.palette_index >= asset.palette_size)
        return invalid("asset: paint {}: palette index {} past the {} entries of a palette", paint, stop.palette_index,
                       asset.palette_size);
    return {};
}

Status check_paint(const FontAsset& asset, size_t index, uint64_t& stops_end) {
    const Paint& paint = asset.paints[index];
    if (paint.kind > PaintKind::image)
        return invalid("asset: paint {}: kind {} is unknown", index, static_cast<uint32_t>(paint.kind));
    if (paint.extend > PaintExtend::reflect)
        return invalid("asset: paint {}: extend {} is unknown", index, static_cast<uint32_t>(paint.extend));
    const Affine& m = paint.to_paint;
    for (float value : {m.xx, m.yx, m.xy, m.yy, m.dx, m.dy})
        if (!is_sane(value)) return invalid("asset: paint {}: mapping value {} is not a sane number", index, value);
    for (float value : paint.geometry)
        if (!is_sane(value)) return invalid("asset: paint {}: geometry value {} is not a sane number", index, value);
    if (paint.kind == PaintKind::radial && (paint.geometry[2] < 0.0f || paint.geometry[5] < 0.0f))
        return invalid("asset: paint {}: radius {} or {} is negative", index, paint.geometry[2], paint.geometry[5]);

    if (paint.kind == PaintKind::image) {
        if (paint.stop_count != 0)
            return invalid("asset: paint {}: an image paint has {} stops", index, paint.stop_count);
        if (paint.image >= asset.images.size())
            return invalid("asset: paint {}: image {} past the {} images", index, paint.image, asset.images.size());
        return {};
    }
    if (paint.image != 0)
        return invalid("asset: paint {}: image {} on a paint that is not an image", index, paint.image);
    const uint32_t wanted_min = 1, wanted_max = paint.kind == PaintKind::solid ? 1 : kMaxColourStops;
    if (paint.stop_count < wanted_min || paint.stop_count > wanted_max)
        return invalid("asset: paint {}: {} stops, {} wants {}..{}", index, paint.stop_count,
                       paint.kind == PaintKind::solid ? "a solid paint" : "a gradient", wanted_min, wanted_max);
    const uint64_t begin = paint.first_stop, end = begin + paint.stop_count;
    if (end > asset.stops.size())
        return invalid("asset: paint {}: stop range [{}, {}) past the {} stops", index, begin, end, asset.stops.size());
    if (begin < stops_end)
        return invalid("asset: paint {}: stop range starts at {}, inside an earlier paint's (ends at {})", index, begin,
                       stops_end);
    stops_end = end;
    float previous = -kMaxPaintValue;
    for (uint64_t i = begin; i < end; ++i) {
        const ColourStop& stop = asset.stops[static_cast<size_t>(i)];
        if (Status status = check_stop(asset, index, stop, previous); !status) return status;
        previous = stop.offset;
    }
    return {};
}

Status check_image(const FontAsset& asset, size_t index, uint64_t& bytes_end) {
    const BitmapImage& image = asset.images[index];
    if (image.width < 1 || image.width > kMaxBitmapSide || image.height < 1 || image.height > kMaxBitmapSide)
        return invalid("asset: image {}: {} x {} pixels, each side 1..{}", index, image.width, image.height,
                       kMaxBitmapSide);
    const uint64_t begin = image.byte_offset, end = begin + image.byte_count;
    if (image.byte_count == 0 || end > asset.image_bytes.size())
        return invalid("asset: image {}: byte range [{}, {}) empty or past the {} image bytes", index, begin, end,
                       asset.image_bytes.size());
    if (begin < bytes_end)
        return invalid("asset: image {}: byte range starts at {}, inside an earlier image's (ends at {})", index, begin,
                       bytes_end);
    bytes_end = end;
    return {};
}

Status check_colour_glyph(const FontAsset& asset, size_t index, uint64_t& layers_end) {
    const ColourGlyph& colour = asset.colour_glyphs[index];
    if (colour.glyph >= asset.face_glyph_count())
        return invalid("asset: colour glyph {}: glyph {} is not one of the face's {} glyphs", index, colour.glyph,
                       asset.face_glyph_count());
    if (index > 0 && asset.colour_glyphs[index - 1].glyph >= colour.glyph)
        return invalid("asset: colour glyph {}: glyph {} after glyph {}: sorted, each once", index, colour.glyph,
                       asset.colour_glyphs[index - 1].glyph);
    if ((colour.flags & ~kKnownColourGlyphFlags) != 0)
        return invalid("asset: colour glyph {}: flags {} hold unknown bits", index, Hex{colour.flags});
    for (float value : {colour.clip_min_x, colour.clip_min_y, colour.clip_max_x, colour.clip_max_y})
        if (!std::isfinite(value) || std::fabs(value) > kMaxCoordinateEm)
            return invalid("asset: colour glyph {}: clip box value {} outside [-64, 64] em", index, value);
    if (colour.clip_min_x > colour.clip_max_x || colour.clip_min_y > colour.clip_max_y)
        return invalid("asset: colour glyph {}: clip box [{}, {}] x [{}, {}] is inverted", index, colour.clip_min_x,
                       colour.clip_max_x, colour.clip_min_y, colour.clip_max_y);
    if (colour.layer_count < 1 || colour.layer_count > kMaxColourLayers)
        return invalid("asset: colour glyph {}: {} layers, 1..{} (docs/limits.md)", index, colour.layer_count,
                       kMaxColourLayers);
    const uint64_t begin = colour.first_layer, end = begin + colour.layer_count;
    if (end > asset.layers.size())
        return invalid("asset: colour glyph {}: layer range [{}, {}) past the {} layers", index, begin, end,
                       asset.layers.size());
    if (begin < layers_end)
        return invalid("asset: colour glyph {}: layer range starts at {}, inside an earlier glyph's (ends at {})",
                       index, begin, layers_end);
    layers_end = end;
    for (uint64_t i = begin; i < end; ++i) {
        const ColourLayer& layer = asset.layers[static_cast<size_t>(i)];
        if (layer.glyph >= asset.glyphs.size())
            return invalid("asset: colour glyph {}: layer {} names glyph {}, past the {} glyphs", index, i - begin,
                           layer.glyph, asset.glyphs.size());
        if ((asset.glyphs[layer.glyph].flags & kGlyphBaked) == 0)
            return invalid("asset: colour glyph {}: layer {} names glyph {}, which is not baked", index, i - begin,
                           layer.glyph);
        if (layer.paint >= asset.paints.size())
            return invalid("asset: colour glyph {}: layer {} names paint {}, past the {} paints", index, i - begin,
                           layer.paint, asset.paints.size());
    }
    return {};
}

}  // namespace

Status check_colour(const FontAsset& asset) {
    if (Status status = check_synthetic_glyphs(asset); !status) return status;
    if (Status status = check_palettes(asset); !status) return status;
    uint64_t bytes_end = 0;
    for (size_t i = 0; i < asset.images.size(); ++i)
        if (Status status = check_image(asset, i, bytes_end); !status) return status;
    uint64_t stops_end = 0;
    for (size_t i = 0; i < asset.paints.size(); ++i)
        if (Status status = check_paint(asset, i, stops_end); !status) return status;
    uint64_t layers_end = 0;
    for (size_t i = 0; i < asset.colour_glyphs.size(); ++i)
        if (Status status = check_colour_glyph(asset, i, layers_end); !status) return status;
    if (asset.colour_glyphs.empty() && !asset.layers.empty())
        return invalid("asset: {} layers but no colour glyph", asset.layers.size());
    return {};
}

}  // namespace crisp::asset_format
