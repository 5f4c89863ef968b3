// Private: what the renderer's CPU parts (requests, coarsening, work items) read of the fonts it
// holds, so that they run, and are tested, without a device. FontStore holds them on the GPU.
#pragma once

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>

#include <cstdint>
#include <span>

namespace crisp::raster {

struct HeldFont {
    const FontAsset* asset = nullptr;  // null: a removed font's place, free for the next
    uint32_t page = 0;                 // the font page that holds its ranges
    uint64_t points_at = 0;            // byte offsets of its ranges in the page's buffers
    uint64_t bands_at = 0;
    // Per glyph, where its flat curves' row (flat_curve_words()) starts, in words from bands_at
    // (after the asset's band words), or kNoFlatRow: what a transformed glyph's rows add.
    std::span<const uint32_t> flat_rows;
};

inline constexpr uint32_t kNoFlatRow = 0xFFFFFFFFu;

class HeldFonts {
public:
    // The font with `id`, or null where none is held.
    virtual const HeldFont* find(FontId id) const = 0;

    // Its asset, or null.
    const FontAsset* asset(FontId id) const {
        const HeldFont* font = find(id);
        return font ? font->asset : nullptr;
    }

protected:
    ~HeldFonts() = default;
};

}  // namespace crisp::raster
