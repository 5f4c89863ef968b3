// crisp: contrast and gamma, so that dark text on light and light text on dark look alike.
//
// The atlas holds linear coverage, and blending that coverage in linear light is physically right,
// yet it makes dark text on a light background look thin beside light text on dark (docs/contrast.md
// has the measurements). The correction is applied where text meets what is behind it, in the
// compositor, per subpixel channel: the atlas, temporal accumulation and every accuracy figure stay
// linear. For one channel's coverage k of a glyph with linear text luminance Lt over a background
// of linear luminance Lb:
//
//     k1 = k * (1 + contrast) / (1 + contrast * k)             enhanced contrast (DirectWrite's form)
//     k2 = min(1, k1 * darkening(size))                         stem darkening, off by default
//     k' = (((1 - k2) * Lb^(1/g) + k2 * Lt^(1/g))^g - Lb) / (Lt - Lb)   blending in a space of gamma g
//
// k' is the linear coverage that blends (linearly, as before) to the colour that blending k2 in the
// gamma-g space would give; where Lt and Lb are (almost) equal it is k2. One function of the
// luminances serves all three channels, so a subpixel edge keeps its channel order, and each step
// is monotonic in k, so an edge stays monotonic. The tile path reads Lb from the caller's image at
// the pixel; the draw path and the reference modes cannot read it and take the far end of the
// range from the text (Lb = 1 for text darker than mid grey, else 0), as DirectWrite and Skia do.
#pragma once

#include <crisp/export.hpp>

#include <crisp/result.hpp>

#include <cstdint>

namespace crisp {

enum class ContrastMode : uint32_t {
    linear = 0,     // coverage blended as it is: today's images, bit for bit
    corrected = 1,  // the model above
};

struct TextContrast {
    ContrastMode mode = ContrastMode::corrected;
    // The blend space's gamma, in [1, 4]: 1 is linear light (then only contrast and darkening act);
    // the default 2.2 puts dark-on-light and light-on-dark ink within 2 % of each other
    // (docs/contrast.md).
    float gamma = 2.2f;
    // Enhanced contrast, in [0, 4]: 0 keeps each stem's ink equal to its coverage; larger values
    // make all text heavier, light and dark alike.
    float contrast = 0.0f;
    // Stem darkening, in [0, 4]: 0 is off; 1 darkens as FreeType's CFF engine does by default,
    // for a stem kStemDarkeningStem em wide (thin stems at small sizes gain most; nothing past
    // 2.333 px stems).
    float stem_darkening = 0.0f;
    friend bool operator==(const TextContrast&, const TextContrast&) = default;
};

// The stem width, in em, that stem darkening assumes (a regular weight's vertical stem).
inline constexpr float kStemDarkeningStem = 0.09f;

// Success when every field is finite and in its range and the mode is known; otherwise
// invalid_argument naming the field and its value ("contrast: gamma nan is not in [1, 4]").
CRISP_API Status validate_text_contrast(const TextContrast& contrast);

// What a drawn glyph carries to the compositor: the settings resolved for its size. Identity
// (gamma 1, contrast 0, darkening 1) is linear: the compositor then blends its coverage as is.
struct GlyphContrast {
    float gamma = 1.0f;
    float contrast = 0.0f;
    float darkening = 1.0f;  // the coverage factor of stem darkening at the glyph's size
    bool linear() const { return gamma == 1.0f && contrast == 0.0f && darkening == 1.0f; }
    friend bool operator==(const GlyphContrast&, const GlyphContrast&) = default;
};

// `contrast` (valid) resolved for a glyph of `size_px` pixels per em; linear mode gives identity.
CRISP_API GlyphContrast resolve_contrast(const TextContrast& contrast, float size_px);

// The largest factor stem_darkening_factor() gives: strength 4 on stems of a quarter pixel or less
// (narrower stems are darkened as a quarter-pixel one, so that tiny text is not blown up).
inline constexpr float kMaxStemDarkeningFactor = 1.0f + 4.0f * 0.4f / 0.25f;

// The coverage factor of stem darkening at `strength` for `size_px` pixels per em: 1 + strength *
// d(w) / w, with w the stem's width in pixels and d FreeType's default darkening curve.
CRISP_API float stem_darkening_factor(float strength, float size_px);

// The model above for one channel, in double precision: the CPU reference of the compositor's.
CRISP_API double corrected_coverage(double coverage, const GlyphContrast& contrast, double text_luminance,
                                    double background_luminance);

// Rec. 709 luminance of a linear colour.
inline double luminance(double r, double g, double b) {
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
}

// The background luminance the draw path and the reference modes assume for text of luminance
// `text_luminance`: the far end of the range.
inline double assumed_background_luminance(double text_luminance) {
    return text_luminance < 0.5 ? 1.0 : 0.0;
}

}  // namespace crisp
