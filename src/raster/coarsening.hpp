// Private: the renderer's subpixel-step controller. Where the atlas has no room for a frame's
// glyphs and cannot grow, the frame starts over with every glyph at the next coarser subpixel
// steps (a quarter pixel, then a whole one); the steps stay coarse until the atlas has been mostly
// empty for a while. CPU only.
#pragma once

#include <crisp/atlas.hpp>
#include <crisp/glyph.hpp>
#include <crisp/layout.hpp>

#include <array>
#include <cstddef>
#include <cstdint>

namespace crisp::raster {

// Subpixel steps per pixel of each level of coarsening (kSubpixelSteps: the layout's own).
inline constexpr std::array<uint32_t, 3> kLevelSteps = {kSubpixelSteps, 4, 1};
// Frames whose glyphs take under a quarter of the atlas before the steps get finer again; the
// wait doubles each time finer steps did not fit after all (up to kMaxCalmFrames).
inline constexpr uint32_t kCalmFrames = 120;
inline constexpr uint32_t kMaxCalmFrames = 120u << 6;

// `glyph` with its pen moved to the nearest of `steps` subpixel positions per pixel: its key,
// rect and position follow, its pen moves by at most half a step. `asset` is its font's; null
// (a font not held) or a glyph the asset does not have: `glyph` as it is.
GlyphInstance coarsened(const FontAsset* asset, const GlyphInstance& glyph, uint32_t steps);

// How far the atlas may grow before a full frame takes coarser steps instead.
struct AtlasLimits {
    uint32_t max_image_side = 0;  // the device's maxImageDimension2D
    uint64_t budget = 0;          // bytes the atlas image may grow to
    // Whether the atlas may double within the budget and the device's image size.
    bool can_grow(const AtlasConfig& config) const;
};

// The level of coarsening from frame to frame. A value: abandon_frame() puts back the one
// begin_frame() saw.
class Coarsening {
public:
    uint32_t steps() const { return kLevelSteps[level_]; }
    // A frame's glyphs did not fit at steps(): the next coarser level, from this frame on. False
    // (nothing changes) at the coarsest.
    bool coarsen();
    // A frame settled: `calm` when every glyph fit and the frame's glyphs take under a quarter of
    // the atlas. The calm_needed-th calm frame since the level last changed makes it finer from
    // the next frame on.
    void end_frame(bool calm);

private:
    size_t level_ = 0;  // index into kLevelSteps
    uint32_t calm_frames_ = 0;
    uint32_t calm_needed_ = kCalmFrames;
    bool just_refined_ = false;  // the level went down at the end of the last frame
};

}  // namespace crisp::raster
