// The tile compositor's binning, one invocation per quad (docs/compositing.md). Specialization
// constant 0 picks the pass:
//   0, count: add 1 to the count of every tile the quad reaches;
//   1, scatter: write the quad's entry (TileBinEntry) into each such tile's list, at the tile's cursor;
//   2, occluders (classified frames, before the others, over all the frame's quads): per tile the
//      nearest quad that hides what lies behind it there.
// The scatter order inside a list depends on arrival; the tile pass sorts each list. A frame whose
// pairs pass the bins' budget is binned in batches: quads [pc.quad_first, + pc.quad_count). In a
// classified frame count and scatter leave out the pairs whose texels under the tile are empty and
// those behind the tile's occluder.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "tiles_common.glsl"

layout(local_size_x = kTileBinInvocations) in;
layout(constant_id = 0) const uint kScatter = 0u;

void main() {
    const uint local = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * kTileBinInvocations +
                       gl_LocalInvocationIndex;
    if (local >= pc.quad_count) return;
    const uint quad = pc.quad_first + local;  // its index in the frame: its key
    const CompositeQuad q = quads[quad];
    uvec2 first, last;
    if (!quad_tile_range(q, first, last)) return;
    const uint tiles = tile_total();
    for (uint y = first.y; y <= last.y; ++y) {
        for (uint x = first.x; x <= last.x; ++x) {
            const uint tile = y * pc.tiles_x + x;
            const ivec2 corner = ivec2(x, y) * int(kTileSide);
            if (kScatter == 2u) {
                if (quad_hides_tile(quad, q, corner)) atomicMin(tile_words[occluder_word(tile)], quad);
                continue;
            }
            if (!quad_covers_tile(quad, q, corner)) {
                if (kScatter == 0u) atomicAdd(header[kHeaderEmptyPairs], 1u);
                continue;
            }
            if (pc.block_count != 0u && quad > tile_words[occluder_word(tile)]) {
                if (kScatter == 0u) atomicAdd(header[kHeaderHiddenPairs], 1u);
                continue;
            }
            if (kScatter == 0u) {
                atomicAdd(tile_words[tile], 1u);
            } else {
                const uint at = atomicAdd(tile_words[2u * tiles + tile], 1u);
                if (at < pc.bin_capacity) {
                    bins[at] = tile_bin_entry(quad, q, ivec2(x, y) * int(kTileSide));
                } else {
                    atomicAdd(header[kHeaderLostPairs], 1u);
                }
            }
        }
    }
}
