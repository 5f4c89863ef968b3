// exact, last pass: gathers the pixel's list, sorts it (key depth ascending, rank descending,
// then content, so that the order does not depend on arrival) and composites front to back.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "reference_resolve.glsl"

layout(std430, set = 0, binding = kCompositeBindNodes) readonly buffer Nodes {
    uint nodes[];
};

// a in front of b.
bool in_front(uint a, uint b) {
    const uint ba = a * kCompositeNodeWords, bb = b * kCompositeNodeWords;
    if (nodes[ba + 1u] != nodes[bb + 1u]) return nodes[ba + 1u] < nodes[bb + 1u];
    if (nodes[ba + 2u] != nodes[bb + 2u]) return nodes[ba + 2u] > nodes[bb + 2u];
    for (uint w = 3u; w < kCompositeNodeWords; ++w) {
        if (nodes[ba + w] != nodes[bb + w]) return nodes[ba + w] < nodes[bb + w];
    }
    return false;
}

void main() {
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    const uint p = uint(pixel.y) * pc.width + uint(pixel.x);
    uint list[kCompositeExactMaxPerPixel];
    uint count = 0u, dropped = 0u;
    for (uint node = words[kExactHead * pc.pixels + p]; node != kCompositeNoNode;
         node = nodes[node * kCompositeNodeWords]) {
        if (count < kCompositeExactMaxPerPixel) {
            // Insertion sort as the list is read.
            uint j = count++;
            while (j > 0u && in_front(node, list[j - 1u])) {
                list[j] = list[j - 1u];
                --j;
            }
            list[j] = node;
        } else {
            ++dropped;
        }
    }
    if (count > 0u) atomicMax(stats[kStatMaxOverlap], count + dropped);
    if (dropped > 0u) atomicAdd(stats[kStatListOverflow], dropped);
    vec3 light = vec3(0.0), transmittance = vec3(1.0);
    for (uint i = 0u; i < count; ++i) {
        const uint base = list[i] * kCompositeNodeWords;
        for (uint c = 0u; c < 3u; ++c) {
            light[c] += transmittance[c] * uintBitsToFloat(nodes[base + 6u + c]);
            transmittance[c] *= uintBitsToFloat(nodes[base + 3u + c]);
        }
    }
    store_pixel(pixel, light, transmittance);
}
