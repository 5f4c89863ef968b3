// wboit: weighted blended OIT (McGuire and Bavoil 2013), per channel with alpha := that channel's
// opacity, weight from the paper's equation (10) divided by its 3e3 ceiling:
//     w = o * max(1e-2 / 3e3, (1 - d)^3)
// The sums are fixed point and added with atomics instead of blending, so the result does not
// depend on the order fragments arrive in (docs/compositing.md). Included by reference_wboit.frag and
// reference_wboit_quads.comp.
#include "quad_pipeline.glsl"

layout(std430, set = 0, binding = kCompositeBindAccumulators) buffer Accumulators {
    uint words[];
};

void main() {
    GlyphFragment f;
    if (!load_fragment(f)) return;
    if (all(equal(f.opacity, vec3(0.0)))) return;
    const float far = 1.0 - clamp(f.quad.depth, 0.0, 1.0);
    const float weight = max(1e-2 / 3e3, far * far * far);
    for (uint c = 0u; c < 3u; ++c) {
        const float w = f.opacity[c] * weight;
        atomicAdd(words[(kWboitLight + c) * pc.pixels + f.pixel], light_fixed(w * f.light[c]));
        atomicAdd(words[(kWboitOpacity + c) * pc.pixels + f.pixel], light_fixed(w * f.opacity[c]));
        const float absorbance = f.transmittance[c] > 0.0 ? min(-log(f.transmittance[c]), kCompositeMaxAbsorbance)
                                                          : kCompositeMaxAbsorbance;
        atomicAdd(words[(kWboitAbsorbance + c) * pc.pixels + f.pixel],
                  uint(absorbance * kCompositeAbsorbanceScale + 0.5));
    }
}
