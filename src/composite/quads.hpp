// Private: the compositor's glyph quads, built on the CPU from the renderer's drawn glyphs.
#pragma once

#include "shared.h"

#include <crisp/renderer.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace crisp::composite {

// Clamps into [0, 1]; NaN becomes 0.
float clamp01(float value);

// A key's depth bits: floor(clamp01(depth) * 2^bits), saturated below the largest value so that no
// key equals an empty slot (oit::pack_layer_key).
uint32_t depth_bits(float depth, int bits);

// One quad per drawn glyph with a non-empty rect, its colour and depth clamped into [0, 1], its
// paint kept where it is one of the frame's `paint_count` paints.
gpu::CompositeQuad make_quad(const DrawnGlyph& glyph, size_t paint_count);

// The glyphs whose rects reach [0, width) x [0, height), as quads sorted front to back: depth
// ascending, then paint order descending (later in front), then stack descending (DrawnGlyph::stack: an
// effect layer under its glyph behind it), then by content (rect, atlas position,
// colour, paint), so that the order, and with it a quad's index, depends only on the set of glyphs and
// never on their submission order. A quad's index in `out` is then its compositing key. Rects
// wider or taller than 65535 are left out (the renderer's are at most a few thousand).
void sort_front_to_back(std::span<const DrawnGlyph> glyphs, size_t paint_count, uint32_t width, uint32_t height,
                        std::vector<gpu::CompositeQuad>& out);

// How many (quad, tile) pairs the tile compositor's binning makes for one quad in a rect of
// width x height pixels: the tiles of the rect it reaches.
uint64_t quad_tile_pairs(const gpu::CompositeQuad& quad, uint32_t width, uint32_t height);

// The reference modes' quads, in submission order, with the exact mode's key: paint orders become
// dense ranks of (paint order, stack) per depth plane.
void rank_quads(std::span<const DrawnGlyph> glyphs, size_t paint_count, std::vector<gpu::CompositeQuad>& out);

}  // namespace crisp::composite
