// The CPU reference of transformed glyphs (docs/transforms.md): the exact area of a glyph's
// outline under its key's transform, per rectangle of its rect's texels. An affine key maps each
// quadratic to a quadratic exactly; a key with perspective maps lines to lines, so its curves are
// cut into chords within kProjectiveChordError px of the curve first and their ends mapped.
#pragma once

#include "coverage.hpp"

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>

#include <vector>

namespace crisp {

// The farthest a chord of a curve under perspective lies from the projected curve, in pixels.
inline constexpr double kProjectiveChordError = 1.0e-4;

class TransformedCoverage {
public:
    // The glyph's listed curves (ExactCoverage's) at `key`, in texels of glyph_rect(glyph, key).
    TransformedCoverage(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key);

    // The covered fraction of [x0, x1] x [y0, y1], texels of the rect (y down); 0 for an empty one.
    double coverage(double x0, double y0, double x1, double y1) const { return exact_.coverage(x0, y0, x1, y1); }
    // Each channel's exact coverage of texel (tx, ty) under `layout`.
    std::array<double, 3> texel(const SubpixelLayout& layout, uint32_t tx, uint32_t ty) const;

    const GlyphRect& rect() const { return rect_; }
    // The curves in texels, as ExactCoverage holds them.
    const std::vector<Quad>& curves() const { return curves_; }

private:
    GlyphRect rect_;
    std::vector<Quad> curves_;
    ExactCoverage exact_;
};

}  // namespace crisp
