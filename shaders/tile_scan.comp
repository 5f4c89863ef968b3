// The tile compositor's prefix sum: one workgroup turns the tiles' quad counts into the starts of
// their lists in the bins (and the scatter pass's cursors), lists the non-empty tiles in order,
// and writes the tile pass's indirect dispatch. Each invocation sums a run of tiles, the runs'
// sums are scanned in workgroup memory, then each invocation writes its run.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "tile_common.glsl"

layout(local_size_x = kTileScanInvocations) in;

// Per invocation: (quads, non-empty tiles) of its run, scanned in place (inclusive).
shared uvec2 partial[kTileScanInvocations];

void main() {
    const uint tiles = tile_total();
    const uint run = (tiles + kTileScanInvocations - 1u) / kTileScanInvocations;
    const uint begin = min(gl_LocalInvocationIndex * run, tiles);
    const uint end = min(begin + run, tiles);
    uvec2 sum = uvec2(0u);
    for (uint t = begin; t < end; ++t) {
        const uint count = tile_words[t];
        sum += uvec2(count, count > 0u ? 1u : 0u);
    }
    partial[gl_LocalInvocationIndex] = sum;
    barrier();
    for (uint offset = 1u; offset < kTileScanInvocations; offset *= 2u) {
        const uvec2 before =
            gl_LocalInvocationIndex >= offset ? partial[gl_LocalInvocationIndex - offset] : uvec2(0u);
        barrier();
        partial[gl_LocalInvocationIndex] += before;
        barrier();
    }
    uvec2 running = partial[gl_LocalInvocationIndex] - sum;
    for (uint t = begin; t < end; ++t) {
        const uint count = tile_words[t];
        tile_words[tiles + t] = running.x;
        tile_words[2u * tiles + t] = running.x;
        if (count > 0u) header[kTileHeaderWords + running.y] = t;
        running += uvec2(count, count > 0u ? 1u : 0u);
    }
    if (gl_LocalInvocationIndex == kTileScanInvocations - 1u) {
        const uint busy = running.y;
        const uint width = min(busy, kRasterDispatchWidth);
        header[kHeaderDispatchX] = width;
        header[kHeaderDispatchY] = width == 0u ? 0u : (busy + width - 1u) / width;
        header[kHeaderDispatchZ] = 1u;
        header[kHeaderBusyTiles] = busy;
        header[kHeaderPairs] = running.x;
    }
}
