#include "raster/coarsening.hpp"

#include <algorithm>

namespace crisp::raster {

GlyphInstance coarsened(const FontAsset* asset, const GlyphInstance& glyph, uint32_t steps) {
    if (steps >= kSubpixelSteps) return glyph;
    if (!asset) return glyph;
    if (glyph.key.glyph >= asset->glyphs.size()) return glyph;
    const GlyphRecord& record = asset->glyphs[glyph.key.glyph];
    const GlyphRect rect = glyph_rect(record, glyph.key);
    GlyphInstance out = glyph;
    int32_t carry[2] = {0, 0};
    uint8_t* offsets[2] = {&out.key.subpixel_x, &out.key.subpixel_y};
    for (int axis = 0; axis < 2; ++axis) {
        const uint32_t grid = kSubpixelSteps / steps;
        const uint32_t rounded = (*offsets[axis] + grid / 2) / grid * grid;
        carry[axis] = rounded >= kSubpixelSteps ? 1 : 0;
        *offsets[axis] = static_cast<uint8_t>(rounded % kSubpixelSteps);
    }
    if (out.key == glyph.key) return glyph;
    const GlyphRect moved = glyph_rect(record, out.key);
    out.x = glyph.x - rect.x + carry[0] + moved.x;
    out.y = glyph.y - rect.y + carry[1] + moved.y;
    out.width = moved.width;
    out.height = moved.height;
    return out;
}

bool AtlasLimits::can_grow(const AtlasConfig& config) const {
    const uint64_t width = uint64_t{config.width} * 2, height = uint64_t{config.height} * 2;
    return width <= std::min<uint64_t>(max_image_side, kAtlasMaxSize) &&
           height <= std::min<uint64_t>(max_image_side, kAtlasMaxSize) &&
           width * height * sizeof(uint16_t) * 4 <= budget;
}

bool Coarsening::coarsen() {
    if (level_ + 1 >= kLevelSteps.size()) return false;
    if (just_refined_) calm_needed_ = std::min(calm_needed_ * 2, kMaxCalmFrames);  // it did not fit
    just_refined_ = false;
    ++level_;
    calm_frames_ = 0;
    return true;
}

void Coarsening::end_frame(bool calm) {
    just_refined_ = false;
    if (level_ > 0 && calm && ++calm_frames_ >= calm_needed_) {
        --level_;  // from the next frame on
        calm_frames_ = 0;
        just_refined_ = true;
    }
}

}  // namespace crisp::raster
