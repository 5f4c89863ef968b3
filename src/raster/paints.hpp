// Private to raster/: a frame's colour layers resolved into what the compositor fills them with
// (DrawnFrame::paints and stops): each layer's Paint of its asset for the draw's palette and
// colour, mapped from its glyph's em space to the target's pixels. CPU only, tested without a
// device (tests/test_raster_logic.cpp).
#pragma once

#include "raster/held_fonts.hpp"

#include <crisp/renderer.hpp>

#include <optional>
#include <span>
#include <vector>

namespace crisp::raster {

// Where a bitmap glyph's image is for this frame's draws: the layer of DrawnFrame::images and the
// part of it the image fills.
struct ImagePlace {
    uint32_t layer = 0;
    float extent_u = 1.0f;
    float extent_v = 1.0f;
};

// Finds or makes room for the images a frame draws (the renderer's BitmapLayers).
class ImagePlaces {
public:
    // Image `image` of `font`'s asset this frame; nullopt where it has no room or cannot be decoded.
    virtual std::optional<ImagePlace> place(FontId font, const FontAsset& asset, uint32_t image) = 0;

protected:
    ~ImagePlaces() = default;
};

class FramePaints {
public:
    // Resolves the colour layers among `drawn` (GlyphInstance::paint): a solid fill without a clip
    // box becomes the instance's colour; any other gets a FramePaint (DrawnGlyph::paint). A layer
    // of an unknown font or paint keeps its colour; an image layer without a place (`images` null,
    // or place() gave none) draws nothing. Counts go to `stats`.
    void resolve(std::span<DrawnGlyph> drawn, const HeldFonts& fonts, ImagePlaces* images, RendererStats& stats);

    std::span<const FramePaint> paints() const { return paints_; }
    std::span<const FrameStop> stops() const { return stops_; }

private:
    std::vector<FramePaint> paints_;
    std::vector<FrameStop> stops_;
};

}  // namespace crisp::raster
