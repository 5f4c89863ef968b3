// exact: every fragment goes into its pixel's linked list, taken from a node pool. A node past
// the pool's end is lost and counted (kStatNodesUsed exceeds the capacity). Included by
// reference_exact.frag and reference_exact_quads.comp.
#include "quad_pipeline.glsl"

layout(std430, set = 0, binding = kCompositeBindAccumulators) buffer Accumulators {
    uint words[];
};
layout(std430, set = 0, binding = kCompositeBindNodes) buffer Nodes {
    uint nodes[];
};
layout(std430, set = 0, binding = kCompositeBindStats) buffer Stats {
    uint stats[];
};

void main() {
    GlyphFragment f;
    if (!load_fragment(f)) return;
    if (all(equal(f.opacity, vec3(0.0)))) return;
    const uint node = atomicAdd(stats[kStatNodesUsed], 1u);
    if (node >= pc.node_capacity) return;
    const uint base = node * kCompositeNodeWords;
    nodes[base + 1u] = f.quad.key_depth;
    nodes[base + 2u] = f.quad.rank;
    for (uint c = 0u; c < 3u; ++c) {
        nodes[base + 3u + c] = floatBitsToUint(f.transmittance[c]);
        nodes[base + 6u + c] = floatBitsToUint(f.light[c]);
    }
    nodes[base] = atomicExchange(words[kExactHead * pc.pixels + f.pixel], node);
}
