// layered, last pass: the background attenuated by the K layers and the tail, plus the light the
// composite pass summed. Also records the pixel's overlap (layers filled + tail count).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "composite_resolve.glsl"

layout(constant_id = 0) const uint kLayers = 4u;
layout(constant_id = 2) const uint kKey64 = 1u;

// The keys as 32-bit words: a 64-bit key is two, low word first.
layout(std430, set = 0, binding = 2) readonly buffer Layers {
    uint words[];
} layers[kCompositeMaxLayerBuffers];

uint layer_word(uint layer, uint pixel, uint word) {
    const uint b = layer / pc.layers_per_buffer;
    const uint i = ((layer - b * pc.layers_per_buffer) * pc.pixels + pixel) * (kKey64 != 0u ? 2u : 1u) + word;
    switch (b) {
        case 0u: return layers[0].words[i];
        case 1u: return layers[1].words[i];
        case 2u: return layers[2].words[i];
        case 3u: return layers[3].words[i];
        case 4u: return layers[4].words[i];
        case 5u: return layers[5].words[i];
        case 6u: return layers[6].words[i];
        default: return layers[7].words[i];
    }
}

void main() {
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    const uint p = uint(pixel.y) * pc.width + uint(pixel.x);
    vec3 transmittance = vec3(1.0);
    uint filled = 0u;
    // The last filled slot's key (high word, low word; the high word is 0 for mono keys), and the
    // transmittance in front of the first slot that holds it.
    uvec2 last = uvec2(0xFFFFFFFFu);
    vec3 last_t = vec3(1.0), in_front_of_last = vec3(1.0);
    for (uint i = 0u; i < kLayers; ++i) {
        const uint low = layer_word(i, p, 0u);
        const uint high = kKey64 != 0u ? layer_word(i, p, 1u) : 0u;
        if (low == 0xFFFFFFFFu && (kKey64 == 0u || high == 0xFFFFFFFFu)) break;
        filled = i + 1u;
        const uvec3 codes = kKey64 != 0u ? uvec3((low >> 16) & 255u, (low >> 8) & 255u, low & 255u) : uvec3(low & 255u);
        if (uvec2(high, low) != last) {
            in_front_of_last = transmittance;
            last = uvec2(high, low);
            last_t = vec3(codes) / 255.0;
        }
        transmittance *= vec3(codes) / 255.0;
    }
    const uint count_word = words[kLayeredTailCount * pc.pixels + p];
    const uint tail_count = count_word & kCompositeTailCountMask;
    vec3 light;
    for (uint c = 0u; c < 3u; ++c) {
        light[c] = fixed_light(words[(kLayeredLight + c) * pc.pixels + p]);
        if (tail_count > 0u) {
            const bool opaque = (count_word & (1u << (kCompositeTailZeroShift + c))) != 0u;
            const float absorbance =
                float(words[(kLayeredTailAbsorbance + c) * pc.pixels + p]) / kCompositeAbsorbanceScale;
            transmittance[c] *= opaque ? 0.0 : exp(-absorbance);
        }
    }
    const uint group = tail_count > 0u ? words[kLayeredGroupCount * pc.pixels + p] : 0u;
    if (group > 0u) {
        // The copies of the last key: their mean light times (1 + T + ... + T^(M-1)).
        vec3 places = vec3(0.0), power = vec3(1.0);
        for (uint m = 0u; m < group; ++m) {
            places += power;
            power *= last_t;
        }
        for (uint c = 0u; c < 3u; ++c) {
            const float mean = fixed_light(words[(kLayeredGroupLight + c) * pc.pixels + p]) / float(group);
            light[c] += in_front_of_last[c] * mean * places[c];
        }
    }
    if (filled + tail_count > 0u) atomicMax(stats[kStatMaxOverlap], filled + tail_count);
    if (tail_count > 0u) atomicAdd(stats[kStatTailPixels], 1u);
    store_pixel(pixel, light, transmittance);
}
