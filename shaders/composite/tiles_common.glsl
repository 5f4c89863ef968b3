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
layout(std430, set = 0, binding = kTileBindBlocks) buffer Blocks {
    TileBlock blocks[];
};
layout(std430, set = 0, binding = kTileBindQuadBlocks) readonly buffer QuadBlocks {
    TileQuadBlocks quad_blocks[];
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
const uint kHeaderEmptyPairs = 9u;
const uint kHeaderHiddenPairs = 13u;
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

// Where the tiles buffer keeps, in a classified frame, the nearest quad that hides everything behind
// it in `tile` (kTileNoQuad: none): after the three planes and the scan's block sums.
uint occluder_word(uint tile) {
    return 3u * tile_total() + 2u * ((tile_total() + kTileScanBlock - 1u) / kTileScanBlock) + tile;
}

// Whether every block of quad `index`'s atlas entry under the tile whose top-left pixel is
// `corner` (within the caller's rect) carries `mark`: blocks start at the entry's corner, which is
// the quad's (q.x, q.y) on screen. False where the frame was not classified.
bool tile_blocks_marked(TileQuadBlocks b, CompositeQuad q, ivec2 corner, uint mark, bool any_block) {
    const ivec2 low = max(corner - ivec2(q.x, q.y), ivec2(0));
    const ivec2 high = min(min(corner + ivec2(kTileSide), ivec2(pc.width, pc.height)) - ivec2(q.x, q.y),
                           ivec2(q.width, q.height)) - 1;
    const uvec2 first = uvec2(low) / kTileBlockSide, last = uvec2(high) / kTileBlockSide;
    for (uint y = first.y; y <= last.y; ++y) {
        for (uint x = first.x; x <= last.x; ++x) {
            const bool marked = (blocks[b.first + y * b.across + x].marked & mark) != 0u;
            if (marked == any_block) return any_block;
        }
    }
    return !any_block;
}

// False where the frame was classified (pc.block_count) and no block of quad `index`'s entry under
// the tile holds coverage: the pair would draw nothing.
bool quad_covers_tile(uint index, CompositeQuad q, ivec2 corner) {
    if (pc.block_count == 0u) return true;
    const TileQuadBlocks b = quad_blocks[index];
    return b.first == kTileNoBlocks || tile_blocks_marked(b, q, corner, kTileBlockCovered, true);
}

// True where the frame was classified and quad `index` hides everything behind it in the tile: it
// reaches the whole tile (within the caller's rect), its every channel's opacity is exactly 1 there
// (full blocks, alpha 1, no fill of its own, no contrast correction that could thin it).
bool quad_hides_tile(uint index, CompositeQuad q, ivec2 corner) {
    if (pc.block_count == 0u) return false;
    const TileQuadBlocks b = quad_blocks[index];
    if (b.first == kTileNoBlocks || q.color.a != 1.0 || q.paint != kNoQuadPaint || q.contrast_darkening < 1.0) {
        return false;
    }
    const ivec2 far = min(corner + ivec2(kTileSide), ivec2(pc.width, pc.height));
    if (any(lessThan(corner, ivec2(q.x, q.y))) || any(greaterThan(far, ivec2(q.x, q.y) + ivec2(q.width, q.height)))) {
        return false;
    }
    return tile_blocks_marked(b, q, corner, kTileBlockFull, false);
}
