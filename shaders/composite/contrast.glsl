// The contrast model (include/crisp/contrast.hpp) on the GPU; its CPU twin is
// src/composite/contrast.cpp. Needs shared.h.

// Rec. 709 luminance of a linear colour.
float contrast_luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// The corrected coverage of each channel of a glyph (its settings, its colour's luminance `lt`) over
// a background of luminance `lb`; coverage as it is where the settings are linear.
vec3 corrected_coverage(vec3 coverage, float gamma, float k, float darkening, float lt, float lb) {
    if (gamma == 1.0 && k == 0.0 && darkening == 1.0) return coverage;
    vec3 c = coverage * (1.0 + k) / (1.0 + k * coverage);
    c = min(c * darkening, vec3(1.0));
    if (abs(lt - lb) < kContrastSameLuminance) return c;
    const float blended_lb = pow(lb, 1.0 / gamma), blended_lt = pow(lt, 1.0 / gamma);
    const vec3 blended = mix(vec3(blended_lb), vec3(blended_lt), c);
    const vec3 corrected = clamp((pow(blended, vec3(gamma)) - lb) / (lt - lb), 0.0, 1.0);
    // No coverage and full coverage stay exact (c is 0 or 1 exactly where |c - 0.5| is 0.5): the
    // round trip through the gamma space would leave a trace of opacity where nothing is covered.
    return mix(corrected, c, greaterThanEqual(abs(c - 0.5), vec3(0.5)));
}

// The background luminance the draw path and the reference modes assume: the far end of the range.
float assumed_background_luminance(float lt) {
    return lt < 0.5 ? 1.0 : 0.0;
}
