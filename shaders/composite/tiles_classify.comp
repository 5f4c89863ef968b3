// The tile compositor's classification of a deep frame's atlas blocks (shared.h, kTileCullDepth):
// one workgroup per TileBlock, an invocation per texel; the block is marked covered where some texel
// holds coverage in some channel (a texel without samples holds none), and full where every texel
// holds full coverage in every channel (its coverage is then exactly 1: atlas_texel.glsl). Binning
// then leaves out the pairs whose blocks hold no coverage, which would draw nothing, and those behind
// an opaque quad full over their tile, which add exactly nothing: the image is the same bit for bit.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "tiles_common.glsl"

layout(local_size_x = kTileBlockSide, local_size_y = kTileBlockSide) in;

layout(set = 0, binding = kTileBindAtlas, rgba16ui) uniform readonly uimage2D atlas;

shared uint covered;
shared uint short_of_full;

void main() {
    const uint index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (index >= pc.block_count) return;  // uniform over the workgroup
    if (gl_LocalInvocationIndex == 0u) {
        covered = 0u;
        short_of_full = 0u;
    }
    barrier();
    const TileBlock block = blocks[index];
    const uvec2 size = uvec2(block.size & 0xFFFFu, block.size >> 16);
    if (all(lessThan(gl_LocalInvocationID.xy, size))) {
        const ivec2 texel = ivec2(block.x, block.y) + ivec2(gl_LocalInvocationID.xy);
        if (all(lessThan(texel, imageSize(atlas)))) {
            const uvec4 sums = imageLoad(atlas, texel);
            if (any(notEqual(sums.rgb, uvec3(0u)))) atomicOr(covered, 1u);
            if (sums.a == 0u || any(lessThan(sums.rgb, uvec3(kRasterCoverageOne * sums.a)))) atomicOr(short_of_full, 1u);
        } else {
            atomicOr(short_of_full, 1u);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        blocks[index].marked = (covered != 0u ? kTileBlockCovered : 0u) | (short_of_full == 0u ? kTileBlockFull : 0u);
    }
}
