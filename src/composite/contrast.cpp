// The contrast model's settings, checks and CPU reference (include/crisp/contrast.hpp); its GPU twin
// is shaders/composite/contrast.glsl.
#include <crisp/contrast.hpp>

#include "shared.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace crisp {

namespace {

Status out_of_range(const char* field, float value, const char* range) {
    return Error{ErrorCode::invalid_argument,
                 std::string("contrast: ") + field + " " + std::to_string(value) + " is not in " + range};
}

bool within(float value, float low, float high) {
    return std::isfinite(value) && value >= low && value <= high;
}

// FreeType's default CFF darkening curve (its darkening-parameters 500, 400, 1000, 275, 1667, 275,
// 2333, 0): the darkening, in pixels, of a stem `width` pixels wide, linear between the points,
// flat before the first and zero past the last.
double freetype_darkening(double width) {
    constexpr std::array<std::array<double, 2>, 4> kCurve = {{{0.5, 0.4}, {1.0, 0.275}, {1.667, 0.275}, {2.333, 0.0}}};
    if (width <= kCurve[0][0]) return kCurve[0][1];
    for (size_t i = 1; i < kCurve.size(); ++i) {
        if (width <= kCurve[i][0]) {
            const double t = (width - kCurve[i - 1][0]) / (kCurve[i][0] - kCurve[i - 1][0]);
            return kCurve[i - 1][1] + t * (kCurve[i][1] - kCurve[i - 1][1]);
        }
    }
    return 0.0;
}

}  // namespace

Status validate_text_contrast(const TextContrast& contrast) {
    if (contrast.mode != ContrastMode::linear && contrast.mode != ContrastMode::corrected) {
        return Error{ErrorCode::invalid_argument, "contrast: mode " +
                                                      std::to_string(static_cast<uint32_t>(contrast.mode)) +
                                                      " is neither linear (0) nor corrected (1)"};
    }
    if (!within(contrast.gamma, 1.0f, 4.0f)) return out_of_range("gamma", contrast.gamma, "[1, 4]");
    if (!within(contrast.contrast, 0.0f, 4.0f)) return out_of_range("contrast", contrast.contrast, "[0, 4]");
    if (!within(contrast.stem_darkening, 0.0f, 4.0f)) {
        return out_of_range("stem_darkening", contrast.stem_darkening, "[0, 4]");
    }
    return {};
}

float stem_darkening_factor(float strength, float size_px) {
    if (!(strength > 0.0f) || !(size_px > 0.0f)) return 1.0f;
    const double width = std::max(0.25, static_cast<double>(kStemDarkeningStem) * static_cast<double>(size_px));
    return static_cast<float>(1.0 + static_cast<double>(strength) * freetype_darkening(width) / width);
}

GlyphContrast resolve_contrast(const TextContrast& contrast, float size_px) {
    if (contrast.mode == ContrastMode::linear) return {};
    return {contrast.gamma, contrast.contrast, stem_darkening_factor(contrast.stem_darkening, size_px)};
}

double corrected_coverage(double coverage, const GlyphContrast& contrast, double text_luminance,
                          double background_luminance) {
    if (contrast.linear()) return coverage;
    const double k = static_cast<double>(contrast.contrast);
    double c = coverage * (1.0 + k) / (1.0 + k * coverage);
    c = std::min(1.0, c * static_cast<double>(contrast.darkening));
    const double lt = text_luminance, lb = background_luminance;
    // No coverage and full coverage stay exact: the round trip through the gamma space would
    // leave a trace of opacity where nothing is covered.
    if (c <= 0.0 || c >= 1.0 || std::abs(lt - lb) < static_cast<double>(gpu::kContrastSameLuminance)) return c;
    const double g = static_cast<double>(contrast.gamma);
    const double blended = (1.0 - c) * std::pow(lb, 1.0 / g) + c * std::pow(lt, 1.0 / g);
    return std::clamp((std::pow(blended, g) - lb) / (lt - lb), 0.0, 1.0);
}

}  // namespace crisp
