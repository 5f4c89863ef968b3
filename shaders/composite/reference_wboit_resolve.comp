// wboit, last pass: accum / clamp(accumA) * (1 - R) + background * R per channel, R = exp(-sum of
// absorbance), the paper's clamp (1e-4, 5e4) divided by the weight's 3e3 scale.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "reference_resolve.glsl"

void main() {
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    const uint p = uint(pixel.y) * pc.width + uint(pixel.x);
    vec3 light, transmittance;
    for (uint c = 0u; c < 3u; ++c) {
        const float accum = fixed_light(words[(kWboitLight + c) * pc.pixels + p]);
        const float accum_opacity = fixed_light(words[(kWboitOpacity + c) * pc.pixels + p]);
        const float absorbance = float(words[(kWboitAbsorbance + c) * pc.pixels + p]) / kCompositeAbsorbanceScale;
        const float revealage = exp(-absorbance);
        transmittance[c] = revealage;
        light[c] = accum / clamp(accum_opacity, 1e-4 / 3e3, 5e4 / 3e3) * (1.0 - revealage);
    }
    store_pixel(pixel, light, transmittance);
}
