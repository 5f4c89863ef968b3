// What every per-pixel resolve pass shares: one invocation per target pixel, writing the final
// premultiplied linear colour. Included by the *_resolve.comp shaders.
#include "shared.h"

layout(local_size_x = kCompositeTile, local_size_y = kCompositeTile) in;

layout(push_constant) uniform PushConstants {
    CompositePushConstants pc;
};

layout(std430, set = 0, binding = kCompositeBindAccumulators) buffer Accumulators {
    uint words[];
};
layout(std430, set = 0, binding = kCompositeBindStats) buffer Stats {
    uint stats[];
};
layout(set = 0, binding = kCompositeBindTarget, rgba32f) uniform writeonly image2D target;

// The background seen through `transmittance`, plus `light`; alpha is the most opaque channel's.
void store_pixel(ivec2 pixel, vec3 light, vec3 transmittance) {
    const vec3 colour = light + pc.background.rgb * transmittance;
    const float seen = min(transmittance.r, min(transmittance.g, transmittance.b));
    imageStore(target, pixel, vec4(colour, 1.0 - (1.0 - pc.background.a) * seen));
}

float fixed_light(uint word) {
    return float(word) / kCompositeLightScale;
}
