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
    // Renderer::add_font() and remove_font(), with their errors.
    Status add(const Font& font);
    Status remove(FontId id);
    // The fonts remove() named leave: their atlas entries go, their staging buffers and page
    // ranges are freed once the frames that may read them are done, and their ids are free.
    // The fonts the next apply_removals() removes.
    const std::vector<FontId>& pending_removals() const { return removals_; }
    void apply_removals(GlyphAtlas& atlas, RetireLists& retired, uint64_t frame);
    // Copies every font added since the last frame from its staging buffer into its page; the
    // staging buffer is retired. True when something was copied.
    bool record_uploads(VkCommandBuffer command_buffer, uint64_t this_frame, RetireLists& retired,
                        RendererStats& stats);
    // The uploads of the last record_uploads() (at `frame`), which never ran, go back to waiting.
    void abandon_uploads(RetireLists& retired, uint64_t frame);
    // A removed font's ranges, free for the next.
    void give_back(const RetiredRanges& ranges);

    const std::vector<FontPage>& pages() const { return pages_; }  // at most kRendererFontPages

private:
    Status place(GpuFont& font);

    const vk::DeviceRef& ref_;
    VkDeviceSize max_range_ = 0;
    std::vector<GpuFont> fonts_;                      // index order; removed ones have no font
    std::unordered_map<FontId, uint32_t> font_slot_;  // FontId -> index in fonts_
    std::vector<FontPage> pages_;
    std::vector<FontId> removals_;    // remove()s, applied at begin_frame()
    std::vector<uint32_t> uploaded_;  // slots whose staging went to `retired` at the last record_uploads()
};

}  // namespace crisp::raster
