// Private: what the renderer's CPU parts (requests, coarsening, work items) read of the fonts it
// holds, so that they run, and are tested, without a device. FontStore holds them on the GPU.
#pragma once

#include "text/stroke.hpp"

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>

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

// What a key rasterizes: its font's glyph, or the derived glyph of an effect key (GlyphKey::effect),
// which the rasterizer walks as two sets of curves.
struct HeldGlyph {
    const HeldFont* font = nullptr;  // null: the font is not held, the glyph not in it, or not derived yet
    const GlyphRecord* record = nullptr;
    uint32_t flat_row = kNoFlatRow;      // as HeldFont::flat_rows
    uint32_t set_b_first = 0xFFFFFFFFu;  // a derived glyph's first slot of set B (RasterItem::set_b_first)
    StrokeOp op = StrokeOp::a;           // what a derived glyph covers of its two sets
    bool derived = false;
};

class HeldFonts {
public:
    // The font with `id`, or null where none is held.
    virtual const HeldFont* find(FontId id) const = 0;
    // The glyph `key` rasterizes. The default holds no derived glyphs.
    virtual HeldGlyph glyph(const GlyphKey& key) const {
        HeldGlyph held;
        const HeldFont* font = find(key.font);
        if (key.effect != 0 || !font || !font->asset || key.glyph >= font->asset->glyphs.size()) return held;
        held.font = font;
        held.record = &font->asset->glyphs[key.glyph];
        held.flat_row = key.glyph < font->flat_rows.size() ? font->flat_rows[key.glyph] : kNoFlatRow;
        return held;
    }
    // Makes the derived glyph of an effect key, where it is not held yet, and marks it used this
    // frame. Errors: the effect cannot be made (its stroke passes limits::kMaxStrokeCurves, the
    // derived glyphs' memory is spent). The default makes none.
    virtual Status derive(const GlyphKey& key) {
        (void)key;
        return Error{ErrorCode::invalid_argument, "renderer: these fonts hold no derived glyphs"};
    }

    // Its asset, or null.
    const FontAsset* asset(FontId id) const {
        const HeldFont* font = find(id);
        return font ? font->asset : nullptr;
    }

protected:
    ~HeldFonts() = default;
};

}  // namespace crisp::raster
