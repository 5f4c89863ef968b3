// What every compositing fragment shader starts from: its quad, its pixel and the glyph's
// coverage there. Included by the *.frag shaders after #version and the include extension.
#include "shared.h"

layout(early_fragment_tests) in;

layout(push_constant) uniform PushConstants {
    CompositePushConstants pc;
};

layout(set = 0, binding = 0, rgba16ui) uniform readonly uimage2D atlas;

layout(std430, set = 0, binding = 1) readonly buffer Quads {
    CompositeQuad quads[];
};

layout(location = 0) flat in uint v_quad;

// One glyph at one pixel, per channel: opacity o = a * coverage, T = 1 - o, L = c * o (linear).
struct GlyphFragment {
    CompositeQuad quad;
    uint pixel;  // y * width + x
    vec3 opacity;
    vec3 transmittance;
    vec3 light;
};

// False where the texel holds no samples: the glyph does not draw there yet.
bool load_fragment(out GlyphFragment f) {
    f.quad = quads[v_quad];
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    f.pixel = uint(pixel.y) * pc.width + uint(pixel.x);
    const ivec2 texel = ivec2(f.quad.atlas_x, f.quad.atlas_y) + pixel - ivec2(f.quad.x, f.quad.y);
    const uvec4 sums = imageLoad(atlas, texel);
    if (sums.a == 0u) return false;
    const vec3 coverage = min(vec3(sums.rgb) / (float(kRasterCoverageOne) * float(sums.a)), vec3(1.0));
    f.opacity = f.quad.color.a * coverage;
    f.transmittance = 1.0 - f.opacity;
    f.light = f.quad.color.rgb * f.opacity;
    return true;
}

// round(clamp(T) * 255) per channel, as the CPU reference (oit::quantize_transmittance).
uvec3 transmittance_codes(vec3 transmittance) {
    return uvec3(clamp(transmittance, 0.0, 1.0) * 255.0 + 0.5);
}

// -ln(code / 255), code 0 taken as the middle of its rounding bin (oit::absorbance_from_code).
float absorbance_from_code(uint code) {
    return -log(code == 0u ? 0.5 / 255.0 : float(code) / 255.0);
}

uint light_fixed(float light) {
    return uint(clamp(light, 0.0, 1.0) * kCompositeLightScale + 0.5);
}
