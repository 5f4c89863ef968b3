// The tile compositor's prefix sum over the tiles' quad counts, in three dispatches of blocks of
// kTileScanBlock tiles (specialization constant 0 picks the phase):
//   0, reduce: each workgroup sums its block's quads and non-empty tiles;
//   1, blocks: one workgroup scans the block sums (at most kTileScanBlock blocks), and writes the
//      totals and the tile pass's indirect dispatch;
//   2, down: each workgroup scans its block again from the block's offset, writing every tile's
//      list start and the scatter pass's cursor, and the non-empty tiles' entries into the
//      header's list (index and count, list start: kTileBusyEntryWords words).
// Each invocation takes kTileScanPerInvocation consecutive tiles (one 16-byte load); loads and
// stores are coalesced, and the scan inside a workgroup runs in workgroup memory.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "tiles_common.glsl"

layout(local_size_x = kTileScanInvocations) in;
layout(constant_id = 0) const uint kPhase = 0u;

const uint kPer = kTileScanPerInvocation;

// Per invocation: (quads, non-empty tiles) of its run, scanned in place (inclusive).
shared uvec2 partial[kTileScanInvocations];

// The block sums live after the three planes of tile words: (quads, non-empty tiles) per block,
// replaced by the blocks' exclusive offsets in phase 1.
uint block_word(uint block, uint component) {
    return 3u * tile_total() + 2u * block + component;
}

// Inclusive scan of `value` over the workgroup; returns this invocation's inclusive sum.
uvec2 workgroup_scan(uvec2 value) {
    partial[gl_LocalInvocationIndex] = value;
    barrier();
    for (uint offset = 1u; offset < kTileScanInvocations; offset *= 2u) {
        const uvec2 before =
            gl_LocalInvocationIndex >= offset ? partial[gl_LocalInvocationIndex - offset] : uvec2(0u);
        barrier();
        partial[gl_LocalInvocationIndex] += before;
        barrier();
    }
    return partial[gl_LocalInvocationIndex];
}

// This invocation's tiles' counts (0 past the last tile) and their (quads, non-empty) sum.
uvec2 load_run(uint first, out uint counts[kPer]) {
    const uint tiles = tile_total();
    uvec2 sum = uvec2(0u);
    for (uint k = 0u; k < kPer; ++k) {
        counts[k] = first + k < tiles ? tile_words[first + k] : 0u;
        sum += uvec2(counts[k], counts[k] > 0u ? 1u : 0u);
    }
    return sum;
}

void main() {
    const uint tiles = tile_total();
    const uint blocks = (tiles + kTileScanBlock - 1u) / kTileScanBlock;
    if (kPhase == 1u) {
        // One workgroup: kPer block sums per invocation.
        uvec2 sums[kPer];
        uvec2 run = uvec2(0u);
        for (uint k = 0u; k < kPer; ++k) {
            const uint b = gl_LocalInvocationIndex * kPer + k;
            sums[k] = b < blocks ? uvec2(tile_words[block_word(b, 0u)], tile_words[block_word(b, 1u)]) : uvec2(0u);
            run += sums[k];
        }
        const uvec2 inclusive = workgroup_scan(run);
        uvec2 offset = inclusive - run;
        for (uint k = 0u; k < kPer; ++k) {
            const uint b = gl_LocalInvocationIndex * kPer + k;
            if (b < blocks) {
                tile_words[block_word(b, 0u)] = offset.x;
                tile_words[block_word(b, 1u)] = offset.y;
            }
            offset += sums[k];
        }
        if (gl_LocalInvocationIndex == kTileScanInvocations - 1u) {
            const uint busy = inclusive.y;
            const uint width = min(busy, kRasterDispatchWidth);
            header[kHeaderDispatchX] = width;
            header[kHeaderDispatchY] = width == 0u ? 0u : (busy + width - 1u) / width;
            header[kHeaderDispatchZ] = 1u;
            header[kHeaderBusyTiles] = busy;
            header[kHeaderPairs] = inclusive.x;
            header[kHeaderLayeredDispatchY] = 1u;  // x: the exact pass counts the tiles it hands on
            header[kHeaderLayeredDispatchZ] = 1u;
        }
        return;
    }
    const uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (block >= blocks) return;  // uniform over the workgroup
    const uint first = block * kTileScanBlock + gl_LocalInvocationIndex * kPer;
    uint counts[kPer];
    const uvec2 run = load_run(first, counts);
    const uvec2 inclusive = workgroup_scan(run);
    if (kPhase == 0u) {
        if (gl_LocalInvocationIndex == kTileScanInvocations - 1u) {
            tile_words[block_word(block, 0u)] = inclusive.x;
            tile_words[block_word(block, 1u)] = inclusive.y;
        }
        return;
    }
    uvec2 running = inclusive - run + uvec2(tile_words[block_word(block, 0u)], tile_words[block_word(block, 1u)]);
    for (uint k = 0u; k < kPer; ++k) {
        const uint t = first + k;
        if (t >= tiles) break;
        tile_words[tiles + t] = running.x;
        tile_words[2u * tiles + t] = running.x;
        if (counts[k] > 0u) {
            const uint entry = kTileHeaderWords + kTileBusyEntryWords * running.y;
            header[entry] = t | (min(counts[k], kTileBusyCountMax) << kTileBusyIndexBits);
            header[entry + 1u] = running.x;
        }
        running += uvec2(counts[k], counts[k] > 0u ? 1u : 0u);
    }
}
