// The tile pass: one workgroup per non-empty screen tile, one invocation per pixel, compositing
// the tile's glyph quads into the caller's image (docs/compositing.md). The quads arrive sorted
// front to back on the CPU, so a quad's index is its key: (depth, paint order, content).
//
// - The exact way, when the tile's list fits in workgroup memory (kCapacity quads): the list is
//   loaded, sorted by index (a rank sort: each entry goes to the count of smaller keys), and each
//   pixel walks it front to back, per channel light += T * L, T *= 1 - o, stopping once T is below
//   kTileOpaque in every channel.
// - The layered way, when it does not (a second, indirect dispatch over the tiles the first handed
//   on): each pixel keeps its kLayers nearest fragments (the smallest quad indices) in registers
//   while reading the list unsorted; what falls off the K goes to a tail of absorbance sums,
//   estimated as docs/oit.md's absorbance_share. Where a pixel has at most K fragments the result
//   is the exact way's, bit for bit.
//
// Then, where the pixel had a fragment: out.rgb = light + T * dst.rgb, and alpha is "over" with each
// fragment's largest channel opacity, out.a = 1 - (1 - dst.a) * prod(1 - max o), as the draw path's
// blend does; in linear colour; 8-bit targets are decoded from and encoded to sRGB here.
// Included by tiles_pass_*.comp with CRISP_TARGET_FORMAT set to a GLSL image format qualifier,
// or undefined for a format-less image (B8G8R8A8, which has no qualifier).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "tiles_common.glsl"

layout(local_size_x = kTileInvocations) in;

layout(constant_id = 0) const uint kLayers = 8u;  // the layered way's K, 1..kCompositeMaxLayers
layout(constant_id = 1) const uint kEncode = kTileEncodeLinear;
layout(constant_id = 2) const uint kCapacity = kTileDefaultCapacity;  // a power of two
// 1: the view is R8G8B8A8 over a B8G8R8A8 image (made with MUTABLE_FORMAT): red and blue swap.
layout(constant_id = 3) const uint kSwapRedBlue = 0u;
// 0: the exact pass over the busy tiles; 1: the layered pass over the tiles it could not take.
// Separate pipelines, so that each is compiled with only its own registers.
layout(constant_id = 4) const uint kLayeredPass = 0u;
// 1: some quad's coverage is corrected (contrast.glsl) against the luminance of the caller's pixel.
// Linear frames use the pipelines made with 0, which carry none of its registers.
layout(constant_id = 5) const uint kContrast = 0u;
// 1: some quad is a colour layer with a fill of its own (paint.glsl). Frames of plain text use the
// pipelines made with 0.
layout(constant_id = 6) const uint kPaints = 0u;

layout(set = 0, binding = kTileBindAtlas, rgba16ui) uniform readonly uimage2D atlas;
#ifdef CRISP_TARGET_FORMAT
layout(set = 0, binding = kTileBindTarget, CRISP_TARGET_FORMAT) uniform image2D target;
#else
layout(set = 0, binding = kTileBindTarget) uniform image2D target;
#endif

#include "atlas/atlas_texel.glsl"
#include "contrast.glsl"
#define CRISP_BIND_PAINTS kTileBindPaints
#define CRISP_BIND_STOPS kTileBindStops
#define CRISP_BIND_IMAGES kTileBindImages
#include "paint.glsl"

shared uint unsorted[kCapacity];  // the keys of the tile's list as the scatter left it
shared uint list[kCapacity];      // ... sorted, as positions in that list
// A chunk of the sorted list, staged for the walk: per quad its rect in tile pixels (x0, y0, x1, y1
// in bytes, clamped to the tile), its atlas texel minus its position, and its colour.
shared uint chunk_rect[kTileChunk];
shared ivec2 chunk_texel[kTileChunk];
shared vec4 chunk_colour[kTileChunk];
// With kContrast: per staged quad its gamma, contrast and darkening, and its colour's luminance.
shared vec4 chunk_contrast[kTileChunk];
// With kPaints: per staged quad its fill (kNoQuadPaint: its colour).
shared uint chunk_paint[kTileChunk];
shared uint tile_overlap;
shared uint tile_tail_pixels;
shared uint tile_busy_pixels;  // pixels of the tile still walking

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}
vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// Stages a list entry at `slot` of the chunk for the walk.
void stage_entry(uint slot, TileBinEntry e) {
    chunk_rect[slot] = e.rect;
    chunk_texel[slot] = ivec2(e.texel_x, e.texel_y);
    chunk_colour[slot] = e.color;
    if (kContrast != 0u) {
        const CompositeQuad q = quads[e.quad];
        chunk_contrast[slot] =
            vec4(q.contrast_gamma, q.contrast_k, q.contrast_darkening, contrast_luminance(e.color.rgb));
    }
    if (kPaints != 0u) chunk_paint[slot] = quads[e.quad].paint;
}

// Entry i's place in the sorted list: the number of keys smaller than its own (a quad is in a
// tile's list once, so keys are distinct). count / kTileInvocations reads of workgroup memory.
uint sorted_place(uint i, uint count) {
    const uint key = unsorted[i];
    uint place = 0u;
    for (uint j = 0u; j < count; ++j) place += unsorted[j] < key ? 1u : 0u;
    return place;
}

// The tile's list sorted by key into `list` (positions in the bins' list), the first chunk staged.
// Each invocation's first entry is read whole before the barrier, so that staging it waits on no
// second load; with a capacity above kTileInvocations the further entries are read again.
void sort_list(uint start, uint count) {
    const uint mine = gl_LocalInvocationIndex;
    TileBinEntry entry;
    if (mine < count) {
        entry = bins[start + mine];
        unsorted[mine] = entry.quad;
    }
    for (uint i = mine + kTileInvocations; i < count; i += kTileInvocations) unsorted[i] = bins[start + i].quad;
    barrier();
    if (mine < count) {
        const uint place = sorted_place(mine, count);
        list[place] = mine;
        if (place < kTileChunk) stage_entry(place, entry);  // the first chunk, staged at once
    }
    for (uint i = mine + kTileInvocations; i < count; i += kTileInvocations) {
        const uint place = sorted_place(i, count);
        list[place] = i;
        if (place < kTileChunk) stage_entry(place, bins[start + i]);
    }
    barrier();
}

// Quad `index`'s opacity at the pixel; false where it draws nothing there (outside its rect, no
// samples, or no opacity in any channel: such a fragment would change nothing).
bool quad_opacity(uint index, ivec2 pixel, float background_luminance, out vec3 opacity, out vec3 colour) {
    const CompositeQuad q = quads[index];
    if (pixel.x < q.x || pixel.y < q.y || pixel.x - q.x >= int(q.width) || pixel.y - q.y >= int(q.height)) {
        return false;
    }
    if (kContrast == 0u && kPaints == 0u) {
        if (!glyph_texel_opacity(q, pixel, opacity)) return false;
        colour = q.color.rgb;
    } else {
        vec3 coverage;
        if (!glyph_texel_coverage(q, pixel, coverage)) return false;
        const vec4 fill = kPaints != 0u ? quad_fill(q, pixel) : q.color;
        if (kContrast != 0u) {
            coverage = corrected_coverage(coverage, q.contrast_gamma, q.contrast_k, q.contrast_darkening,
                                          contrast_luminance(fill.rgb), background_luminance);
        }
        opacity = fill.a * coverage;
        colour = fill.rgb;
    }
    return any(greaterThan(opacity, vec3(0.0)));
}

struct Blend {
    vec3 light;
    vec3 transmittance;
    float coverage_transmittance;  // alpha: the product of 1 - (the fragment's largest opacity)
    uint fragments;
};

void blend_over(inout Blend b, vec3 opacity, vec3 colour) {
    b.light += b.transmittance * colour * opacity;
    b.transmittance *= 1.0 - opacity;
    b.coverage_transmittance *= 1.0 - max(opacity.r, max(opacity.g, opacity.b));
}

// The exact way: the sorted list, staged a chunk at a time into workgroup memory (the first
// chunk by the sort itself), walked front to back by every pixel; the workgroup stops after a
// chunk once every pixel's transmittance is spent. Inside a chunk the walk carries no early exit,
// so that the texel loads of successive quads do not wait on each other.
Blend exact_way(uint start, uint count, ivec2 corner, ivec2 pixel, bool inside, float background_luminance) {
    if (gl_LocalInvocationIndex == 0u) tile_busy_pixels = 0u;
    sort_list(start, count);  // its barriers also order tile_busy_pixels' reset before the adds
    Blend b = Blend(vec3(0.0), vec3(1.0), 1.0, 0u);
    bool walking = inside;
    const uint walkers = subgroupAdd(walking ? 1u : 0u);
    if (subgroupElect() && walkers > 0u) atomicAdd(tile_busy_pixels, walkers);
    const ivec2 local = pixel - corner;
    const ivec2 atlas_size = imageSize(atlas);
    for (uint base = 0u; base < count; base += kTileChunk) {
        if (base > 0u) {
            // The barrier that ended the last chunk's walk lets its staged quads be replaced.
            const uint i = base + gl_LocalInvocationIndex;
            if (gl_LocalInvocationIndex < kTileChunk && i < count) stage_entry(gl_LocalInvocationIndex, bins[start + list[i]]);
            barrier();
        }
        const uint staged = min(kTileChunk, count - base);
        if (walking) {
            for (uint j = 0u; j < staged; ++j) {
                const uint rect = chunk_rect[j];
                if (local.x < int(rect & 255u) || local.y < int((rect >> 8) & 255u) ||
                    local.x >= int((rect >> 16) & 255u) || local.y >= int(rect >> 24)) {
                    continue;
                }
                const ivec2 texel = pixel + chunk_texel[j];
                if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, atlas_size))) continue;
                const uvec4 sums = imageLoad(atlas, texel);
                if (sums.a == 0u) continue;
                vec4 colour = chunk_colour[j];
                float luminance = 0.0;
                if (kContrast != 0u) luminance = chunk_contrast[j].w;
                if (kPaints != 0u && chunk_paint[j] != kNoQuadPaint) {
                    colour = paint_fill(chunk_paint[j], colour, pixel);
                    if (kContrast != 0u) luminance = contrast_luminance(colour.rgb);
                }
                vec3 coverage = min(vec3(sums.rgb) / (float(kRasterCoverageOne) * float(sums.a)), vec3(1.0));
                if (kContrast != 0u) {
                    const vec4 c = chunk_contrast[j];
                    coverage = corrected_coverage(coverage, c.x, c.y, c.z, luminance, background_luminance);
                }
                const vec3 opacity = colour.a * coverage;
                if (!any(greaterThan(opacity, vec3(0.0)))) continue;
                blend_over(b, opacity, colour.rgb);
                ++b.fragments;
            }
            if (all(lessThan(b.transmittance, vec3(kTileOpaque)))) {
                walking = false;
                atomicAdd(tile_busy_pixels, 0xFFFFFFFFu);  // minus one
            }
        }
        if (base + kTileChunk < count) {
            barrier();
            if (tile_busy_pixels == 0u) break;  // read between two barriers: uniform
        }
    }
    return b;
}

Blend layered_way(uint start, uint count, ivec2 pixel, bool inside, float background_luminance, out bool tail) {
    Blend b = Blend(vec3(0.0), vec3(1.0), 1.0, 0u);
    tail = false;
    if (!inside) return b;
    uint slots[kCompositeMaxLayers];
    for (uint s = 0u; s < kLayers; ++s) slots[s] = kTileNoQuad;
    // The tail, per channel: absorbance sum A, colour weighted by absorbance, and whether some
    // tail fragment was opaque there.
    vec3 absorbance = vec3(0.0), weighted = vec3(0.0);
    bvec3 opaque = bvec3(false);
    float tail_coverage = 1.0;
    for (uint i = 0u; i < count; ++i) {
        uint candidate = bins[start + i].quad;
        vec3 opacity, colour;
        if (!quad_opacity(candidate, pixel, background_luminance, opacity, colour)) continue;
        ++b.fragments;
        // The compare-and-swap chain keeps the K smallest indices sorted; what is left falls off.
        for (uint s = 0u; s < kLayers; ++s) {
            if (candidate < slots[s]) {
                const uint kept = slots[s];
                slots[s] = candidate;
                candidate = kept;
            }
        }
        if (candidate == kTileNoQuad) continue;
        tail = true;
        quad_opacity(candidate, pixel, background_luminance, opacity, colour);
        const vec3 transmittance = 1.0 - opacity;
        opaque = bvec3(uvec3(opaque) | uvec3(equal(transmittance, vec3(0.0))));
        const vec3 a = min(-log(max(transmittance, vec3(1e-30))), vec3(kCompositeMaxAbsorbance));
        absorbance += a;
        weighted += colour * a;
        tail_coverage *= 1.0 - max(opacity.r, max(opacity.g, opacity.b));
    }
    for (uint s = 0u; s < kLayers; ++s) {
        vec3 opacity, colour;
        if (slots[s] != kTileNoQuad && quad_opacity(slots[s], pixel, background_luminance, opacity, colour)) blend_over(b, opacity, colour);
    }
    if (tail) {
        // absorbance_share: the tail absorbs 1 - P of what reaches it, P = exp(-A) (0 where a tail
        // fragment was opaque), and gives back light in proportion to each fragment's absorbance.
        const vec3 passed = mix(exp(-absorbance), vec3(0.0), opaque);
        const vec3 share = mix(vec3(0.0), weighted / max(absorbance, vec3(1e-30)), greaterThan(absorbance, vec3(0.0)));
        b.light += b.transmittance * (1.0 - passed) * share;
        b.transmittance *= passed;
        b.coverage_transmittance *= tail_coverage;
    }
    return b;
}

// The caller's pixel, in linear colour.
vec4 load_destination(ivec2 at) {
    vec4 destination = imageLoad(target, at);
    if (kSwapRedBlue != 0u) destination = destination.bgra;
    if (kEncode == kTileEncodeSrgb) destination.rgb = srgb_to_linear(destination.rgb);
    return destination;
}

// The luminance the contrast model corrects against: the caller's pixel before any glyph, read
// only by the contrast passes (0 otherwise, unused).
float background_luminance(ivec2 pixel, bool inside) {
    if (kContrast == 0u || !inside) return 0.0;
    return contrast_luminance(load_destination(pixel + ivec2(pc.origin_x, pc.origin_y)).rgb);
}

// The pixel's result into the caller's image, and the tile's statistics: one workgroup-memory
// atomic per subgroup, then few global ones (the overlap only where it passes the largest seen so
// far). Reached by every invocation of the workgroup.
void finish_tile(ivec2 pixel, Blend b, bool tail) {
    if (gl_LocalInvocationIndex == 0u) {
        tile_overlap = 0u;
        tile_tail_pixels = 0u;
    }
    barrier();
    const uint most = subgroupMax(b.fragments);
    const uint tails = subgroupAdd(tail ? 1u : 0u);
    if (subgroupElect()) {
        if (most > 0u) atomicMax(tile_overlap, most);
        if (tails > 0u) atomicAdd(tile_tail_pixels, tails);
    }
    if (b.fragments > 0u) {
        const ivec2 at = pixel + ivec2(pc.origin_x, pc.origin_y);
        const vec4 destination = load_destination(at);
        vec3 colour = b.light + b.transmittance * destination.rgb;
        const float alpha = 1.0 - (1.0 - destination.a) * b.coverage_transmittance;
        if (kEncode == kTileEncodeSrgb) colour = linear_to_srgb(colour);
        imageStore(target, at, kSwapRedBlue != 0u ? vec4(colour.bgr, alpha) : vec4(colour, alpha));
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        if (tile_overlap > header[kHeaderMaxOverlap]) atomicMax(header[kHeaderMaxOverlap], tile_overlap);
        if (tile_tail_pixels > 0u) atomicAdd(header[kHeaderTailPixels], tile_tail_pixels);
    }
}

// Where the header buffer's list of the tiles handed to the layered pass starts.
uint layered_list() {
    return kTileHeaderWords + kTileBusyEntryWords * tile_total();
}

// This invocation's pixel of `tile`, in the caller's rect; false past its right or bottom edge.
bool tile_pixel(uint tile, out ivec2 corner, out ivec2 pixel) {
    corner = ivec2(uvec2(tile % pc.tiles_x, tile / pc.tiles_x) * kTileSide);
    pixel = corner + ivec2(gl_LocalInvocationIndex % kTileSide, gl_LocalInvocationIndex / kTileSide);
    return pixel.x < int(pc.width) && pixel.y < int(pc.height);
}

// The exact pass: one workgroup per busy tile. A tile whose list does not fit is handed to the
// layered pass: its index goes onto the overflow list, and the layered dispatch grows.
void exact_pass() {
    const uint busy = gl_WorkGroupID.y * kRasterDispatchWidth + gl_WorkGroupID.x;
    if (busy >= header[kHeaderBusyTiles]) return;  // uniform over the workgroup
    const uint entry = kTileHeaderWords + kTileBusyEntryWords * busy;
    const uint tile_and_count = header[entry];
    const uint start = header[entry + 1u];
    const uint tile = tile_and_count & ((1u << kTileBusyIndexBits) - 1u);
    const uint count = tile_and_count >> kTileBusyIndexBits;  // saturated: above kCapacity
    if (count > kCapacity) {
        if (gl_LocalInvocationIndex == 0u) {
            const uint slot = atomicAdd(header[kHeaderLayeredTiles], 1u);
            header[layered_list() + slot] = tile;
            if (slot < kRasterDispatchWidth) atomicAdd(header[kHeaderLayeredDispatchX], 1u);
        }
        return;
    }
    ivec2 corner, pixel;
    const bool inside = tile_pixel(tile, corner, pixel);
    const float lb = background_luminance(pixel, inside);
    finish_tile(pixel, exact_way(start, count, corner, pixel, inside, lb), false);
}

// The layered pass: the overflow list's tiles, workgroup i taking i, i + kRasterDispatchWidth, ...
void layered_pass() {
    const uint overflowing = header[kHeaderLayeredTiles];
    for (uint i = gl_WorkGroupID.x; i < overflowing; i += kRasterDispatchWidth) {
        const uint tile = header[layered_list() + i];
        ivec2 corner, pixel;
        const bool inside = tile_pixel(tile, corner, pixel);
        bool tail = false;
        const float lb = background_luminance(pixel, inside);
        const Blend b = layered_way(tile_words[tile_total() + tile], tile_words[tile], pixel, inside, lb, tail);
        finish_tile(pixel, b, tail);
    }
}

void main() {
    if (kLayeredPass == 0u) {
        exact_pass();
    } else {
        layered_pass();
    }
}
