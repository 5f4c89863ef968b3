// crisp: structs and constants shared by the C++ sources and the GLSL shaders, declared once.
//
// GLSL sees plain GLSL; C++ sees the same declarations inside namespace crisp::gpu, with GLSL's
// scalar type names, plus static_asserts that its layout matches the shaders' (std430 for storage
// buffers, and push constants).
#ifndef CRISP_SHADERS_SHARED_H
#define CRISP_SHADERS_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>

namespace crisp::gpu {

using uint = std::uint32_t;
struct vec4 {
    float x, y, z, w;
};

#define CRISP_CONSTANT(type, name, value) inline constexpr type name = value
#else
#define CRISP_CONSTANT(type, name, value) const type name = value
#endif

// ---- selftest.comp: checks the context, push constants, storage buffers and subgroup arithmetic.

// Invocations per workgroup: whole subgroups on common GPUs (8 to 64 wide), eight of them on
// lavapipe's 8-wide subgroups.
CRISP_CONSTANT(uint, kSelftestWorkgroupSize, 64u);

struct SelftestPushConstants {
    uint element_count;  // invocations at or past this index write nothing
    uint seed;           // mixed into every value, so results left from an earlier run cannot pass
};

// One per invocation, in a std430 storage buffer.
struct SelftestResult {
    uint value;          // lowbias32(index ^ seed)
    uint subgroup_min;   // subgroupMin(value) over the active invocations of its subgroup
    uint subgroup_max;   // subgroupMax(value), likewise
    uint subgroup_key;   // gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID: which subgroup ran it
    uint active_count;   // subgroupAdd(1u): how many invocations of that subgroup were active
    uint subgroup_size;  // gl_SubgroupSize
};

// ---- raster.comp: adds row (or point) samples of glyph outlines into the atlas accumulators.

// Invocations per workgroup; a workgroup rasterizes 64 texels of one glyph, row-major, so the
// bands a subgroup touches stay few.
CRISP_CONSTANT(uint, kRasterWorkgroupSize, 64u);
// One covered sample adds this to its channel's accumulator (fixed point: a row sample adds its
// covered fraction, dithered to a whole unit); alpha counts samples. 1023 samples fill 16 bits.
CRISP_CONSTANT(uint, kRasterCoverageOne, 64u);
// Sample kinds (RasterPushConstants::sample_kind).
CRISP_CONSTANT(uint, kRasterSampleRows, 0u);    // a segment across the channel's rect, its covered length exact
CRISP_CONSTANT(uint, kRasterSamplePoints, 1u);  // a point, covered or not
// Crossings inside one row segment a channel keeps in registers, sorted by x; a segment with more
// is finished by further passes over the curves, each from the last crossing kept (exact).
CRISP_CONSTANT(uint, kRasterRowCrossings, 8u);
// Row sample n sits at height frac(radical_inverse_2(n) + kRasterRowOffset) of the channel's rect:
// 1/16 + 1/128 + 1/1024 puts the first 64 and the first 512 samples within 1/1024 of their strata's
// centres and the first 8 within 9/1024 (docs/rasterizer.md, "Row samples", says why not 8 too).
CRISP_CONSTANT(float, kRasterRowOffset, 0.0712890625f);
// The R2 sequence's steps 1/g, 1/g^2 (g the plastic number): frac(0.5 + n * step) fills any run of n evenly.
CRISP_CONSTANT(float, kRasterR2StepX, 0.7548776662466927f);
CRISP_CONSTANT(float, kRasterR2StepY, 0.5698402909980532f);
// Storage buffers of curve points and of band bitsets, one each per font: with the work items
// 18 storage buffers, within the 32 per stage that lavapipe and desktop drivers offer.
CRISP_CONSTANT(uint, kRasterFontPages, 8u);  // font pages, each several fonts' points and bands
// Workgroups per row of the 2D dispatch (maxComputeWorkGroupCount[0] is at least 65535).
CRISP_CONSTANT(uint, kRasterDispatchWidth, 65535u);
// The rasterizer's descriptor set.
CRISP_CONSTANT(uint, kRasterBindAtlas, 0u);           // the atlas, storage image
CRISP_CONSTANT(uint, kRasterBindItems, 1u);           // RasterItem[]
CRISP_CONSTANT(uint, kRasterBindPoints, 2u);          // kRasterFontPages buffers of curve points
CRISP_CONSTANT(uint, kRasterBindBands, 3u);           // kRasterFontPages buffers of band words
CRISP_CONSTANT(uint, kRasterBindWorkgroupItems, 4u);  // uint[]: the item of each workgroup
CRISP_CONSTANT(uint, kRasterBindTransforms, 5u);      // RasterTransform[]: transformed glyphs' maps
// RasterItem::transform of a glyph that is not transformed (texel_to_em's offset and scale serve it).
CRISP_CONSTANT(uint, kRasterNoTransform, 0xFFFFFFFFu);
// RasterItem::cover_rule of the effect layers (docs/effects.md): with A the first set of curves
// and B the second (the glyph's own), bit (a + 2 b) says whether a point inside A (a) and B (b)
// is covered. A plain glyph is kRasterCoverA over one set.
CRISP_CONSTANT(uint, kRasterCoverA, 0xAu);          // A
CRISP_CONSTANT(uint, kRasterCoverAOutsideB, 0x2u);  // A and not B
CRISP_CONSTANT(uint, kRasterCoverAInsideB, 0x8u);   // A and B
CRISP_CONSTANT(uint, kRasterCoverAOrB, 0xEu);       // A or B
CRISP_CONSTANT(uint, kRasterCoverBOutsideA, 0x4u);  // B and not A
// raster.comp's kTransformedItems of the pipeline for transformed items that walk two lines a row
// sample (0 serves axis-aligned items, 1 the other transformed ones).
CRISP_CONSTANT(uint, kRasterTwoLineItems, 2u);

// One glyph's work this frame, in a std430 storage buffer.
struct RasterItem {
    uint atlas_x;  // texel of the glyph rect's top-left corner in the atlas
    uint atlas_y;
    uint width;  // the rect, texels
    uint height;
    float offset_x;  // texel_to_em: em = offset + scale * (texel position in the rect)
    float offset_y;
    float scale_x;
    float scale_y;
    float bbox_min_y;  // the glyph's em bbox in y, for its bands
    float bbox_max_y;
    uint point_offset;  // first point of the glyph in its font's point buffer
    uint band_offset;   // first word of its bands in its font's band buffer
    uint band_count;
    uint band_words;    // words per band
    uint font;          // index into the per-font buffer arrays
    uint first_sample;  // index of the first sample to add; 0: start from empty accumulators
    uint sample_count;  // samples to add
    uint part_x;        // texel (0, 0) of the work is texel (part_x, part_y) of the glyph rect
    uint part_y;
    uint first_texel;  // the work's texels, row-major over width x height
    uint texel_count;
    uint first_workgroup;  // this item's first workgroup; the items' ranges tile the dispatch, in order
    uint transform;        // index into RasterTransform[], or kRasterNoTransform
    uint flat_row;         // transformed: first word of its flat curves' row in the band buffer, or kRasterNoTransform
    uint set_b_first;      // two-set items (effect layers): the first curve slot of the second set
    uint cover_rule;       // two-set items: covered where bit (wa != 0) + 2 (wb != 0) is set (kRasterCover*)
    float blur_w;          // blurred items (kBlurItems): the blur's box width w = 2 R / 3, texels; 0 otherwise
};

// A transformed glyph's maps (include/crisp/glyph.hpp, em_to_texel): rows of 3x3 projective
// matrices, em (y up) to the rect's texels and back. W is 1 without perspective. to_texel[0].w is
// the map's orientation, +1 or -1 (the sign of its determinant); to_texel[1].w and [2].w the
// glyph's em bbox in x; the other w are unused.
struct RasterTransform {
    vec4 to_texel[3];
    vec4 to_em[3];
};

struct RasterPushConstants {
    vec4 channel_rects[3];  // subpixel layout: x0, y0, x1, y1 of red, green, blue, pixel units, y down
    uint workgroup_base;    // the dispatch's first workgroup in the table (transformed items follow the others)
    uint workgroup_count;   // workgroups that have work (the dispatch may round up)
    uint shared_rows;       // 1: the three rects share their rows: one set of roots, one row list, serves all
    uint sample_kind;       // kRasterSampleRows or kRasterSamplePoints
};

// ---- The compositor (quad_pipeline.vert and the *.frag / *_resolve.comp of each mode).

// The descriptor set every quad pass shares (the draw path binds the first two).
CRISP_CONSTANT(uint, kCompositeBindAtlas, 0u);         // the atlas, storage image
CRISP_CONSTANT(uint, kCompositeBindQuads, 1u);         // CompositeQuad[]
CRISP_CONSTANT(uint, kCompositeBindAccumulators, 3u);  // per-pixel sums (wboit, exact heads)
CRISP_CONSTANT(uint, kCompositeBindNodes, 4u);         // exact: the node pool
CRISP_CONSTANT(uint, kCompositeBindStats, 5u);         // counters read back after the frame
CRISP_CONSTANT(uint, kCompositeBindTarget, 6u);        // the reference target, storage image
CRISP_CONSTANT(uint, kCompositeBindTiles, 7u);         // the compute quad passes' tile list
CRISP_CONSTANT(uint, kCompositeBindPaints, 8u);        // QuadPaint[]: colour layers' fills
CRISP_CONSTANT(uint, kCompositeBindStops, 9u);         // PaintStop[]: their colour lines
CRISP_CONSTANT(uint, kCompositeBindImages, 10u);       // bitmap glyphs' images, sampled 2D array

// The tile path's layered way keeps at most this many layers per pixel.
CRISP_CONSTANT(uint, kCompositeMaxLayers, 8u);
// Threads per workgroup of the per-pixel resolve passes, and of the compute quad passes (one
// 8 x 8 tile of a quad each): 8 x 8 pixels.
CRISP_CONSTANT(uint, kCompositeTile, 8u);
// Light sums are u8.24 fixed point: integer addition is associative, so the sum of a pixel's
// fragments is bit-identical whatever order they arrive in.
CRISP_CONSTANT(float, kCompositeLightScale, 16777216.0f);
// Absorbance (-ln T) sums (wboit) are u16.16 fixed point; one fragment adds at most
// kCompositeMaxAbsorbance (so does one in the tile path's layered tail, in float).
CRISP_CONSTANT(float, kCompositeAbsorbanceScale, 65536.0f);
CRISP_CONSTANT(float, kCompositeMaxAbsorbance, 24.0f);
// The exact mode sorts at most this many fragments per pixel; the rest are counted and dropped.
CRISP_CONSTANT(uint, kCompositeExactMaxPerPixel, 64u);
// uint words per exact-mode list node: next, key depth, rank, T rgb, L rgb (floats as bits).
CRISP_CONSTANT(uint, kCompositeNodeWords, 9u);
CRISP_CONSTANT(uint, kCompositeNoNode, 0xFFFFFFFFu);

// Per-pixel words of each reference mode in the accumulator buffer (sized for the larger,
// kWboitWords), plane-major (word w of pixel p at w * pixels + p).
CRISP_CONSTANT(uint, kWboitLight, 0u);       // 3 words: sum w * L
CRISP_CONSTANT(uint, kWboitOpacity, 3u);     // 3 words: sum w * o
CRISP_CONSTANT(uint, kWboitAbsorbance, 6u);  // 3 words: sum -ln T
CRISP_CONSTANT(uint, kWboitWords, 9u);
CRISP_CONSTANT(uint, kExactHead, 0u);
CRISP_CONSTANT(uint, kExactWords, 1u);

// The stats buffer, uint words, cleared every frame and copied back for the host.
CRISP_CONSTANT(uint, kStatNodesUsed, 0u);     // exact: nodes asked for (past capacity: lost)
CRISP_CONSTANT(uint, kStatListOverflow, 1u);  // exact: fragments past kCompositeExactMaxPerPixel
CRISP_CONSTANT(uint, kStatMaxOverlap, 2u);    // exact: most fragments in one pixel
CRISP_CONSTANT(uint, kStatWords, 3u);

// One glyph quad, in a std430 storage buffer: its rect on the target and in the atlas, and what
// the compositor derived from its depth and paint order.
struct CompositeQuad {
    int x;  // target pixel of the rect's top-left corner
    int y;
    uint width;
    uint height;
    uint atlas_x;  // the rect's top-left texel in the atlas
    uint atlas_y;
    uint key_depth;  // exact mode: depth fixed point, one step nearer per 256 paint-order ranks
    uint rank;       // exact mode: dense rank of the paint order among the quads of its depth plane
    float depth;     // [0, 1], for the WBOIT weight
    // Its contrast settings (include/crisp/contrast.hpp, GlyphContrast): gamma 1, contrast 0 and
    // darkening 1 blend its coverage as is.
    float contrast_gamma;
    float contrast_k;
    float contrast_darkening;
    vec4 color;  // linear, straight alpha
    uint paint;  // a colour layer's fill: an index in the QuadPaint buffer; kNoQuadPaint: `color`
    uint stack;  // DrawnGlyph::stack: its place among the layers of its depth and paint order
    uint padding1;
    uint padding2;
};

// ---- Colour layers' fills (paint.glsl; include/crisp/renderer.hpp, FramePaint, says what each
// field means; docs/colour.md the paints).
CRISP_CONSTANT(uint, kNoQuadPaint, 0xFFFFFFFFu);
CRISP_CONSTANT(uint, kPaintSolid, 0u);
CRISP_CONSTANT(uint, kPaintLinear, 1u);
CRISP_CONSTANT(uint, kPaintRadial, 2u);
CRISP_CONSTANT(uint, kPaintSweep, 3u);
CRISP_CONSTANT(uint, kPaintImage, 4u);
CRISP_CONSTANT(uint, kExtendPad, 0u);
CRISP_CONSTANT(uint, kExtendRepeat, 1u);
CRISP_CONSTANT(uint, kExtendReflect, 2u);

struct QuadPaint {
    uint kind;  // kPaint*
    uint extend;
    uint first_stop;
    uint stop_count;
    vec4 to_paint_x;  // paint x = dot(xyz, (pixel.x, pixel.y, 1)); w unused
    vec4 to_paint_y;
    vec4 geometry0;  // Paint::geometry[0..3]
    vec4 geometry1;  // [4..5], unused, unused
    vec4 clip;       // pixels: x0, y0, x1, y1
    uint image_layer;
    float image_u;  // the part of the layer the image fills
    float image_v;
    float opacity;
};

struct PaintStop {
    vec4 colour;  // premultiplied, sRGB-encoded
    float offset;
    float padding0;
    float padding1;
    float padding2;
};

// Text and background luminances closer than this blend the corrected coverage as it is (the
// gamma-space blend's quotient would divide rounding errors by their difference).
CRISP_CONSTANT(float, kContrastSameLuminance, 1.0e-3f);

struct CompositePushConstants {
    vec4 background;  // linear, premultiplied
    uint width;       // the target
    uint height;
    uint pixels;  // width * height
    uint padding3;
    uint node_capacity;  // exact: nodes in the pool
    uint tile_count;     // compute quad passes: tiles in the frame's tile list
    uint quad_count;     // quads in the quad buffer
    uint back_to_front;  // 1: instance i draws quad quad_count - 1 - i (the draw path)
    int origin_x;        // the draw path: the caller's rect, whose corner is glyph pixel (0, 0)
    int origin_y;
    uint padding0;
    uint padding1;
};

// ---- The tile compositor (tiles_bin.comp, tiles_scan.comp, tiles_pass_*.comp): the frame's quads,
// sorted front to back on the CPU (so a quad's index is its key), binned into screen tiles on the
// GPU and composited per tile into the caller's image (docs/compositing.md).

// A screen tile is kTileSide x kTileSide pixels; one workgroup of kTileSide^2 invocations
// composites one tile, an invocation per pixel.
CRISP_CONSTANT(uint, kTileSide, 16u);
CRISP_CONSTANT(uint, kTileInvocations, 256u);
// The scan of the tile counts: workgroups of kTileScanInvocations, each invocation taking
// kTileScanPerInvocation consecutive tiles, so a block of kTileScanBlock tiles per workgroup; the
// block sums are scanned by one workgroup, so at most kTileScanBlock blocks: 2^20 tiles, a
// 16384 x 16384 target.
CRISP_CONSTANT(uint, kTileScanInvocations, 256u);
CRISP_CONSTANT(uint, kTileScanPerInvocation, 4u);
CRISP_CONSTANT(uint, kTileScanBlock, 1024u);
// Invocations per workgroup of the binning passes (one quad each).
CRISP_CONSTANT(uint, kTileBinInvocations, 64u);
// (quad, tile) pairs a frame bins at once by default (32 bytes each: 128 MiB, the
// maxStorageBufferRange every device has); a frame with more is binned and composited in batches of
// consecutive quads, back to front (CompositorCreateInfo::tile_bin_pairs).
CRISP_CONSTANT(uint, kTileDefaultBinPairs, 1u << 22);
// Quad indices a tile's list holds in workgroup memory by default (8 bytes each: the list as
// scattered and sorted); a longer list takes the layered way (the K nearest per pixel, the rest
// estimated). Workgroup memory is kept small: it bounds how many tiles an SM composites at once.
CRISP_CONSTANT(uint, kTileDefaultCapacity, 256u);
// Quads staged in workgroup memory at a time for the exact way's walk (28 bytes each).
CRISP_CONSTANT(uint, kTileChunk, 64u);
CRISP_CONSTANT(uint, kTileMaxCapacity,
               1024u);  // about 10 KiB of workgroup memory in all, of the 16 KiB every device offers
CRISP_CONSTANT(uint, kTileNoQuad, 0xFFFFFFFFu);
// Below this in every channel the transmittance left hides whatever lies behind (less than a
// 16-bit code): a pixel's walk stops there.
CRISP_CONSTANT(float, kTileOpaque, 1.0f / 65536.0f);
// Deep stacks (tiles_classify.comp): in a frame whose (quad, tile) pairs average more than
// kTileCullDepth a tile of the rect (or that is batched), each atlas entry its quads show is cut
// into blocks of kTileBlockSide^2 texels from its corner, a block marked where some texel holds
// coverage, and a pair whose blocks under its tile are all unmarked is not binned: it would draw
// nothing, yet every pixel of its tile that no glyph makes opaque would read its texel. Hundreds of
// copies of a large glyph otherwise cost every pixel of their gaps a read per copy. A block whose
// texels all hold full coverage is marked full too: an opaque quad (alpha 1, no fill of its own)
// full over a whole tile hides what lies behind it there, and those pairs are not binned either.
CRISP_CONSTANT(uint, kTileCullDepth, 64u);
CRISP_CONSTANT(uint, kTileBlockCovered, 1u);  // TileBlock::marked: some texel holds coverage
CRISP_CONSTANT(uint, kTileBlockFull, 2u);     // ... every texel holds full coverage in every channel
CRISP_CONSTANT(uint, kTileBlockSide, 16u);
CRISP_CONSTANT(uint, kTileNoBlocks, 0xFFFFFFFFu);  // a quad whose entry was not classified

// Bindings of the tile compositor's descriptor set (tiles_common.glsl declares the same).
CRISP_CONSTANT(uint, kTileBindAtlas, 0u);        // the atlas, storage image
CRISP_CONSTANT(uint, kTileBindQuads, 1u);        // CompositeQuad[], front to back
CRISP_CONSTANT(uint, kTileBindTiles, 2u);        // per tile: count, start, cursor (plane-major); block sums
CRISP_CONSTANT(uint, kTileBindBins, 3u);         // TileBinEntry[], each tile's at its start
CRISP_CONSTANT(uint, kTileBindHeader, 4u);       // TileHeader, then the non-empty tiles' indices
CRISP_CONSTANT(uint, kTileBindTarget, 5u);       // the caller's image, storage image
CRISP_CONSTANT(uint, kTileBindPaints, 6u);       // QuadPaint[]
CRISP_CONSTANT(uint, kTileBindStops, 7u);        // PaintStop[]
CRISP_CONSTANT(uint, kTileBindImages, 8u);       // bitmap images, sampled 2D array
CRISP_CONSTANT(uint, kTileBindBlocks, 9u);       // TileBlock[]: the frame's atlas blocks, classified
CRISP_CONSTANT(uint, kTileBindQuadBlocks, 10u);  // TileQuadBlocks[], per quad
CRISP_CONSTANT(uint, kTileBindingCount, 11u);

// Target encodings of the tile pass (specialization constant 1).
CRISP_CONSTANT(uint, kTileEncodeLinear, 0u);  // float formats: the image holds linear colour
CRISP_CONSTANT(uint, kTileEncodeSrgb, 1u);    // 8-bit UNORM formats: sRGB-encoded in the shader

// The start of the header buffer; the list of busy tiles follows it (kTileBusyEntryWords words a
// tile), then the list of the tiles handed to the layered pass (a word a tile).
struct TileHeader {
    uint dispatch_x;  // VkDispatchIndirectCommand of the exact pass
    uint dispatch_y;
    uint dispatch_z;
    uint busy_tiles;          // tiles with at least one quad
    uint pairs;               // (quad, tile) pairs binned
    uint lost_pairs;          // pairs past the bins' capacity (never, when the CPU sized them)
    uint layered_tiles;       // tiles that took the layered way (the exact ones: busy - layered)
    uint max_overlap;         // most fragments one pixel had
    uint tail_pixels;         // layered tiles: pixels with fragments past K
    uint empty_pairs;         // pairs not binned: the quad's texels under the tile hold no coverage
    uint layered_dispatch_x;  // VkDispatchIndirectCommand of the layered pass (at byte 40)
    uint layered_dispatch_y;
    uint layered_dispatch_z;
    uint hidden_pairs;  // pairs not binned: an opaque quad in front covers the whole tile
    uint padding2;
    uint padding3;
};
CRISP_CONSTANT(uint, kTileHeaderWords, 16u);
// A busy tile's entry: the tile's index in the low kTileBusyIndexBits bits (the scan takes at most
// 2^20 tiles) and its quad count above them, saturated at kTileBusyCountMax (above any capacity);
// then the start of its list in the bins. So the tile pass learns what it needs of its tile from
// one 8-byte load, rather than from the tile's index and then the tile's words.
CRISP_CONSTANT(uint, kTileBusyEntryWords, 2u);
CRISP_CONSTANT(uint, kTileBusyIndexBits, 20u);
CRISP_CONSTANT(uint, kTileBusyCountMax, 4095u);
CRISP_CONSTANT(uint, kTileLayeredDispatchOffset, 40u);  // bytes

// An entry of a tile's list in the bins, written by the scatter: what the tile pass's walk needs of
// the quad, so that the pass reads no quad between its list and the atlas.
struct TileBinEntry {
    uint quad;    // the quad's index: its key
    uint rect;    // its rect in the tile's pixels, clamped to the tile: x0, y0, x1, y1, a byte each
    int texel_x;  // its atlas texel minus its position
    int texel_y;
    vec4 color;
};

struct TilePushConstants {
    int origin_x;  // the caller's rect: its top-left pixel in the image, and its size
    int origin_y;
    uint width;
    uint height;
    uint tiles_x;  // tiles across and down the rect
    uint tiles_y;
    uint quad_count;    // the batch's quads (binning): quads [quad_first, quad_first + quad_count)
    uint bin_capacity;  // entries the bins buffer holds
    uint quad_first;    // the batch's first quad, in front-to-back order
    uint block_count;   // atlas blocks classified this frame; 0: no pair is culled
};

// An atlas block to classify (tiles_classify.comp): its first texel, its size (up to
// kTileBlockSide each way), and the marks the pass writes (kTileBlockCovered, kTileBlockFull).
struct TileBlock {
    uint x;
    uint y;
    uint size;  // width | height << 16
    uint marked;
};

// Per quad of a classified frame: its entry's first block and blocks per row (kTileNoBlocks: none).
struct TileQuadBlocks {
    uint first;
    uint across;
};

#ifdef __cplusplus
static_assert(sizeof(RasterItem) == 108);
static_assert(offsetof(RasterItem, blur_w) == 104);
static_assert(sizeof(RasterTransform) == 96);
static_assert(sizeof(TileHeader) == kTileHeaderWords * 4);
static_assert(sizeof(TileBinEntry) == 32);
static_assert(offsetof(TileHeader, layered_dispatch_x) == kTileLayeredDispatchOffset);
static_assert(kTileScanBlock == kTileScanInvocations * kTileScanPerInvocation);
static_assert(kTileScanBlock * kTileScanBlock <= 1u << kTileBusyIndexBits);
static_assert(kTileMaxCapacity < kTileBusyCountMax && kTileBusyCountMax < 1u << (32 - kTileBusyIndexBits));
static_assert(kTileScanBlock * kTileScanBlock * kTileSide * kTileSide >= 16384u * 16384u);
static_assert(sizeof(TilePushConstants) == 40);
static_assert(sizeof(TileBlock) == 16);
static_assert(sizeof(TileQuadBlocks) == 8);
static_assert(sizeof(CompositeQuad) == 80);
static_assert(offsetof(CompositeQuad, color) == 48);
static_assert(offsetof(CompositeQuad, paint) == 64);
static_assert(sizeof(QuadPaint) == 112);
static_assert(offsetof(QuadPaint, clip) == 80);
static_assert(sizeof(PaintStop) == 32);
static_assert(sizeof(CompositePushConstants) == 64);
static_assert(offsetof(CompositePushConstants, width) == 16);
static_assert(offsetof(RasterItem, first_workgroup) == 84);
static_assert(sizeof(RasterPushConstants) == 64);
static_assert(offsetof(RasterPushConstants, workgroup_base) == 48);
static_assert(sizeof(SelftestPushConstants) == 8);
static_assert(offsetof(SelftestPushConstants, seed) == 4);
static_assert(sizeof(SelftestResult) == 24);  // std430 array stride: 6 uints, 4-byte aligned
static_assert(offsetof(SelftestResult, subgroup_key) == 12);
static_assert(offsetof(SelftestResult, subgroup_size) == 20);

}  // namespace crisp::gpu
#endif

#undef CRISP_CONSTANT

#endif  // CRISP_SHADERS_SHARED_H
