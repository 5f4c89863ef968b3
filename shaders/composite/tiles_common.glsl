// What the tile compositor's passes share: push constants and the descriptor set
// (shared.h names the bindings and says what each holds).
#include "shared.h"

layout(push_constant) uniform PushConstants {
    TilePushConstants pc;
};

layout(std430, set = 0, binding = kTileBindQuads) readonly buffer Quads {
    CompositeQuad quads[];
};
// Three planes of pc.tiles_x * pc.tiles_y words: each tile's quad count, the start of its list in
// the bins, and the cursor the scatter pass advances.
layout(std430, set = 0, binding = kTileBindTiles) buffer Tiles {
    uint tile_words[];
};
layout(std430, set = 0, binding = kTileBindBins) buffer Bins {
    TileBinEntry bins[];
};
// TileHeader's words, then the non-empty tiles' entries (kTileBusyEntryWords each), then the
// indices of the tiles the exact pass hands to the layered pass.
layout(std430, set = 0, binding = kTileBindHeader) buffer Header {
    uint header[];
};

// Word offsets of TileHeader's fields.
const uint kHeaderDispatchX = 0u;
const uint kHeaderDispatchY = 1u;
const uint kHeaderDispatchZ = 2u;
const uint kHeaderBusyTiles = 3u;
const uint kHeaderPairs = 4u;
const uint kHeaderLostPairs = 5u;
const uint kHeaderLayeredTiles = 6u;
const uint kHeaderMaxOverlap = 7u;
const uint kHeaderTailPixels = 8u;
const uint kHeaderLayeredDispatchX = 10u;
const uint kHeaderLayeredDispatchY = 11u;
const uint kHeaderLayeredDispatchZ = 12u;

uint tile_total() {
    return pc.tiles_x * pc.tiles_y;
}

// The tiles a quad's rect reaches inside the caller's rect, as [first, last] in tile coordinates;
// false when it reaches none.
bool quad_tile_range(CompositeQuad q, out uvec2 first, out uvec2 last) {
    const ivec2 low = max(ivec2(q.x, q.y), ivec2(0));
    const ivec2 high = min(ivec2(q.x, q.y) + ivec2(q.width, q.height), ivec2(pc.width, pc.height));
    if (any(greaterThanEqual(low, high))) return false;
    first = uvec2(low) / kTileSide;
    last = uvec2(high - 1) / kTileSide;
    return true;
}

// Quad `index`'s entry in the list of the tile whose top-left pixel is `corner`.
TileBinEntry tile_bin_entry(uint index, CompositeQuad q, ivec2 corner) {
    const ivec2 low = clamp(ivec2(q.x, q.y) - corner, ivec2(0), ivec2(kTileSide));
    const ivec2 high = clamp(ivec2(q.x, q.y) + ivec2(q.width, q.height) - corner, ivec2(0), ivec2(kTileSide));
    const uint rect = uint(low.x) | (uint(low.y) << 8) | (uint(high.x) << 16) | (uint(high.y) << 24);
    const ivec2 texel = ivec2(q.atlas_x, q.atlas_y) - ivec2(q.x, q.y);
    return TileBinEntry(index, rect, texel.x, texel.y, q.color);
}
