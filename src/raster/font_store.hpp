// Private: the renderer's fonts on the GPU. Each font's curve points and band words take a range
// of a font page's two buffers; a font's bytes wait in a staging buffer until record() copies
// them. Removed fonts leave at the next begin_frame(), their ranges once the GPU is done.
#pragma once

#include "core/range_allocator.hpp"
#include "raster/held_fonts.hpp"
#include "raster/retired.hpp"
#include "vk/functions.hpp"
#include "vk/resources.hpp"

#include <crisp/atlas.hpp>
#include <crisp/font.hpp>
#include <crisp/renderer.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

namespace crisp::raster {

// Two device-local buffers (curve points, band words) that hold the ranges of several fonts:
// fonts are suballocated from at most kRendererFontPages pages, so their number is not bound to
// the shader's descriptor arrays, and removing a font frees its ranges for the next.
struct FontPage {
    vk::DeviceBuffer points;
    vk::DeviceBuffer bands;
    RangeAllocator point_ranges;  // of `points`
    RangeAllocator band_ranges;   // of `bands`
};

struct GpuFont : HeldFont {
    // A derived glyph (an effect layer's outline): its one-glyph asset, what it is derived from and
    // the frame it was last drawn.
    std::unique_ptr<FontAsset> derived;
    FontId source = 0;
    uint32_t set_b_first = 0;
    StrokeOp op = StrokeOp::a;
    uint64_t last_used = 0;
    std::vector<uint32_t> flat_row_of;  // HeldFont::flat_rows
    std::vector<uint32_t> flat_words;   // the rows, uploaded after the asset's band words
    VkDeviceSize points_bytes = 0;
    VkDeviceSize bands_bytes = 0;
    vk::DeviceBuffer staging;  // host-visible, points then bands; freed once copied and done
    bool uploaded = false;
    VkBuffer retired_staging = VK_NULL_HANDLE;  // the staging buffer the last upload retired
};

// Smallest capacities of a new font page; a page holds at least twice the font that makes it.
inline constexpr VkDeviceSize kMinPagePoints = VkDeviceSize{4} << 20;
inline constexpr VkDeviceSize kMinPageBands = VkDeviceSize{1} << 20;

class FontStore final : public HeldFonts {
public:
    // Buffers are made from `ref`, which outlives the store; no range passes `max_range` bytes
    // (maxStorageBufferRange).
    FontStore(const vk::DeviceRef& ref, VkDeviceSize max_range);

    const HeldFont* find(FontId id) const override;
    HeldGlyph glyph(const GlyphKey& key) const override;
    // Strokes and packs the derived glyph of an effect key (text/effect_code.hpp) and stages it
    // like a font, where it is not held yet; marks it used this frame. Where the derived glyphs
    // would pass kMaxDerivedBytes or kMaxDerivedGlyphs, those not drawn this frame go first, oldest
    // first. Errors: the key's font is not held, the stroke is refused, or there is no room.
    Status derive(const GlyphKey& key) override;
    // Renderer::add_font() and remove_font(), with their errors.
    Status add(const Font& font);
    Status remove(FontId id);
    // The fonts remove() named leave: their atlas entries go, their staging buffers and page
    // ranges are freed once the frames that may read them are done, and their ids are free.
    // The fonts the next apply_removals() removes.
    const std::vector<FontId>& pending_removals() const { return removals_; }
    void apply_removals(GlyphAtlas& atlas, RetireLists& retired, uint64_t frame);
    // At begin_frame(), after apply_removals(): `frame` is the one now drawn; derived glyphs not
    // drawn for kForgetDerivedFrames frames go (their atlas entries stay, and are derived again
    // when drawn).
    void begin_frame(RetireLists& retired, uint64_t frame);
    // The derived glyphs held, made this frame, and their bytes on the GPU.
    uint32_t derived_glyphs() const { return static_cast<uint32_t>(derived_slot_.size()); }
    uint32_t derived_made() const { return derived_made_; }
    uint64_t derived_bytes() const { return derived_bytes_; }
    // Copies every font added since the last frame from its staging buffer into its page; the
    // staging buffer is retired. True when something was copied.
    bool record_uploads(VkCommandBuffer command_buffer, uint64_t this_frame, RetireLists& retired,
                        RendererStats& stats);
    // The uploads of the last record_uploads() (at `frame`), which never ran, go back to waiting.
    void abandon_uploads(RetireLists& retired, uint64_t frame);
    // A removed font's ranges, free for the next.
    void give_back(const RetiredRanges& ranges);

    const std::vector<FontPage>& pages() const { return pages_; }  // at most kRendererFontPages

    // Bounds of the derived glyphs held at once.
    static constexpr uint64_t kMaxDerivedBytes = uint64_t{64} << 20;
    static constexpr uint32_t kMaxDerivedGlyphs = 16384;
    static constexpr uint64_t kForgetDerivedFrames = 600;

private:
    struct DerivedKey {
        FontId font = 0;
        uint32_t glyph = 0;
        uint32_t effect = 0;
        uint32_t octave = 0;  // effect_octave(): the pieces' tolerance
        friend bool operator==(const DerivedKey&, const DerivedKey&) = default;
    };
    struct DerivedKeyHash {
        size_t operator()(const DerivedKey& k) const {
            return std::hash<uint64_t>{}((uint64_t{k.font} << 32 | k.glyph) ^
                                         ((uint64_t{k.effect} << 5 | k.octave) * 0x9E3779B97F4A7C15ull));
        }
    };

    Status place(GpuFont& font);
    // Places `gpu` (its asset set) in a page and copies its bytes into a new staging buffer; on
    // failure nothing is held.
    Status stage(GpuFont& gpu);
    // Into a free place of fonts_; returns its index.
    uint32_t keep(GpuFont&& gpu);
    // Lets the font or derived glyph at `slot` go: its staging buffer and ranges retire at `frame`.
    void release(uint32_t slot, RetireLists& retired, uint64_t frame);
    void forget_derived(uint32_t slot, RetireLists& retired, uint64_t frame);

    const vk::DeviceRef& ref_;
    VkDeviceSize max_range_ = 0;
    std::vector<GpuFont> fonts_;                      // index order; removed ones have no font
    std::unordered_map<FontId, uint32_t> font_slot_;  // FontId -> index in fonts_
    std::vector<FontPage> pages_;
    std::vector<FontId> removals_;    // remove()s, applied at begin_frame()
    std::vector<uint32_t> uploaded_;  // slots whose staging went to `retired` at the last record_uploads()
    std::unordered_map<DerivedKey, uint32_t, DerivedKeyHash> derived_slot_;  // -> index in fonts_
    uint64_t derived_bytes_ = 0;
    uint32_t derived_made_ = 0;
    uint64_t frame_ = 0;              // the frame begin_frame() began
    RetireLists* retired_ = nullptr;  // the renderer's, from begin_frame()
};

}  // namespace crisp::raster
