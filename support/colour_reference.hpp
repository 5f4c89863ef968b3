// The CPU reference of colour glyphs (docs/colour.md), which the GPU is held to within 1/255 per
// channel:
//
// 1. Paints evaluated in double as the definition of a paint says: the gradient's parameter t at a
//    point (linear, radial as the two-point conical gradient, sweep), the colour line under its
//    extend mode, interpolated in premultiplied sRGB-encoded RGBA, then linearized and
//    premultiplied again and scaled by the text colour's alpha; image paints from their decoded
//    texels, the texel under the point or the exact mean over a footprint.
// 2. A colour glyph's image: per layer, per pixel, per channel, the exact area coverage of the
//    channel's sample rectangle over the layer's outline (coverage.hpp's ExactCoverage, on the
//    mapping of texel_to_em() in double), times the fraction of the pixel inside the clip box,
//    with the layer's paint at the pixel centre; layers composited src-over in paint order per
//    channel: light L = P * k, transmittance T = 1 - P_a * k, c = L + T * c.
//
// The text colour's alpha counts once: a stop of kForegroundPaletteIndex takes the text colour's
// rgb with alpha 1 (times the stop's alpha), and every paint is then scaled by the text alpha, so
// a colour glyph of one foreground layer draws as the monochrome glyph does.
//
// Functions taking a FontAsset expect a valid one (load_asset or validate_asset passed it) for its
// outlines; a paint's stop range, image index and palette entries are checked where they are used,
// so hand-made paints fail with invalid_argument rather than reading out of bounds.
#pragma once

#include "asset/curves.hpp"

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

namespace crisp::colour {

// Linear light, premultiplied by a.
struct LinearRgba {
    double r = 0.0, g = 0.0, b = 0.0, a = 0.0;
    friend bool operator==(const LinearRgba&, const LinearRgba&) = default;
};

// sRGB-encoded RGBA in [0, 1]: straight for the text colour, premultiplied on a colour line.
using Srgba = std::array<double, 4>;

// The exact piecewise sRGB transfer, encoded to linear: x / 12.92 up to 0.04045, ((x + 0.055) /
// 1.055)^2.4 above. Clamps to [0, 1]; NaN gives 0.
double srgb_to_linear(double encoded);

// Premultiplied sRGB-encoded RGBA to linear premultiplied: rgb unpremultiplied (clamped to [0, 1]),
// linearized, premultiplied again; 0 where alpha is 0.
LinearRgba linearize(const Srgba& premultiplied);

// Where the colour line is read for parameter t, on a line whose stops run from offset `first` to
// `last`: pad clamps to [first, last], repeat wraps into [first, last), reflect mirrors at each end;
// a line with first == last is pad. NaN reads as `first`.
double extend_t(PaintExtend extend, double first, double last, double t);

// An em point in the paint's own space (Paint::to_paint).
Vec2 to_paint_space(const Affine& to_paint, Vec2 em);

// The colour line's parameter of a gradient paint at em point `em`, before extend: linear
// t = dot(q - p0, p1 - p0) / |p1 - p0|^2; radial, the largest t with r(t) >= 0 whose circle passes
// through q; sweep, (angle(q) - start) / (end - start) with the angle in turns wrapped into [0, 1).
// None where the paint defines no colour there: no circle passes through q, or the gradient is
// degenerate (p1 == p0, start == end, one circle for every t), or the paint is not a gradient.
std::optional<double> gradient_t(const Paint& paint, Vec2 em);

// Paints of one asset under one palette and text colour. Image paints decode their image on first
// use and keep it: one Painter is not to be used from two threads at once.
class Painter {
public:
    // invalid_argument when `palette` is not below asset.palette_count() (palette 0 of an asset
    // without palettes is accepted: only the foreground entry is then usable) or a foreground
    // component is not in [0, 1]. The asset must outlive the Painter.
    static Result<Painter> create(const FontAsset& asset, uint32_t palette, const Srgba& foreground);

    // A stop's colour, premultiplied sRGB-encoded, before the text alpha. invalid_argument for a
    // palette index past the palette that is not kForegroundPaletteIndex.
    Result<Srgba> stop_colour(const ColourStop& stop) const;

    // The colour line of `paint` at parameter t (extend applied here), premultiplied sRGB-encoded:
    // the stop at t exactly (the later of equal offsets), else the interpolation of the two stops
    // around it. invalid_argument when the paint's stops are not in the asset or it has none.
    Result<Srgba> colour_line(const Paint& paint, double t) const;

    // The paint's final colour at em point `em`: linear premultiplied, times the text alpha; image
    // paints give the texel under the point (transparent outside the image's unit square).
    // invalid_argument for stops or an image the asset does not hold, asset_invalid naming the
    // image when its bytes do not decode.
    Result<LinearRgba> evaluate(const Paint& paint, Vec2 em) const;

    // How a colour glyph reads an image layer, whose outline is the image's rectangle: the edges
    // are the coverage's, so what lies outside the image is not read. Both give the final colour
    // as evaluate() does, and its errors, and invalid_argument for a paint that is not an image.
    //
    // The texel under em point `em`, the point first clamped into the image (its edge texel where
    // it lies outside, as a pixel centre just past the outline's edge does).
    Result<LinearRgba> image_nearest(const Paint& paint, Vec2 em) const;
    // The exact mean over the part inside the image of the em-space quadrilateral `footprint`
    // (convex, its corners in order; a pixel's square maps to one): each texel weighted by the
    // area of the footprint it holds in the paint's space. Transparent when no part of the
    // footprint of any area lies inside.
    Result<LinearRgba> image_mean(const Paint& paint, const std::array<Vec2, 4>& footprint) const;

private:
    Painter(const FontAsset& asset, uint32_t palette, const Srgba& foreground)
        : asset_(&asset), palette_(palette), foreground_(foreground) {}
    Result<const std::vector<uint8_t>*> image_pixels(const Paint& paint) const;
    LinearRgba finish(const LinearRgba& colour) const;

    const FontAsset* asset_;
    uint32_t palette_;
    Srgba foreground_;
    mutable std::map<uint32_t, std::vector<uint8_t>> images_;  // decoded on first use
};

// Painter::create(asset, palette, foreground), then evaluate(paint, em).
Result<LinearRgba> evaluate_paint(const FontAsset& asset, const Paint& paint, uint32_t palette, const Srgba& foreground,
                                  Vec2 em);

// How the colour glyph reference reads image paints at a pixel.
enum class ImageSampling {
    nearest,  // the texel under the pixel centre (Painter::image_nearest)
    box,      // the exact mean over the pixel's square (Painter::image_mean)
};

// The most pixels render_colour_reference draws: a glyph of 4096 x 4096 px.
inline constexpr uint64_t kMaxReferencePixels = uint64_t{1} << 24;

// A colour glyph's reference image over the union of its layers' rects.
struct ColourImage {
    // Texel (i, j) is pixel (rect.x + i, rect.y + j) relative to the pen's whole pixel (x right, y
    // down), as a GlyphRect places its texels. Empty when no layer has an outline.
    GlyphRect rect;
    std::vector<double> rgb;    // linear light over the background: (j * width + i) * 3 + channel
    std::vector<double> alpha;  // 1 - the layers' transmittance, per channel, laid out as rgb

    double at(uint32_t column, uint32_t row, uint32_t channel) const {
        return rgb[(size_t{row} * rect.width + column) * 3 + channel];
    }
    double alpha_at(uint32_t column, uint32_t row, uint32_t channel) const {
        return alpha[(size_t{row} * rect.width + column) * 3 + channel];
    }
};

// The reference image of asset.colour_glyphs[colour_glyph] at key's size and subpixel offset
// (key.glyph is not read) with `layout`'s channel rectangles, palette `palette` and the text
// colour `foreground`, over `background` (linear rgb): see the file comment. invalid_argument for
// a colour glyph, layer or paint the asset does not hold, a key of size 0, an invalid layout or
// palette, a rect past kMaxReferencePixels; errors of evaluate() otherwise.
Result<ColourImage> render_colour_reference(const FontAsset& asset, uint32_t colour_glyph, const GlyphKey& key,
                                            const SubpixelLayout& layout, uint32_t palette, const Srgba& foreground,
                                            const std::array<double, 3>& background,
                                            ImageSampling sampling = ImageSampling::nearest);

}  // namespace crisp::colour
