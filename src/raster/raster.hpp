// Private: the host twin of shaders/raster/raster.comp. A frame's work items, built from the
// atlas's RasterWork (build_work_items, CPU only), go through this frame's staging buffer into the
// item buffer; one dispatch, its descriptor set and push constants, adds their samples.
#pragma once

#include "raster/font_store.hpp"
#include "raster/held_fonts.hpp"
#include "raster/retired.hpp"
#include "shared.h"
#include "vk/resources.hpp"

#include <crisp/atlas.hpp>
#include <crisp/renderer.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp::raster {

// The kinds of work item, each rasterized by its own pipeline: item_kind() (raster.comp's
// kTransformedItems) for a glyph's own outline, plus kRasterGeometryKinds for a derived glyph's
// (an effect layer's: two sets of curves, kTwoSetItems), and all of these again plus
// kRasterBlurKindBase for a blurred key's (kBlurItems: a blurred shadow or glow).
inline constexpr uint32_t kRasterGeometryKinds = 3;
inline constexpr uint32_t kRasterBlurKindBase = 2 * kRasterGeometryKinds;
inline constexpr uint32_t kRasterItemKinds = 2 * kRasterBlurKindBase;

// The kind of a glyph's items: 0 for an axis-aligned key, gpu::kRasterTwoLineItems for a
// transformed one whose em y axis lies within 15 degrees of the rows (its stems run along them,
// and it walks two lines a row sample), 1 for other transformed keys.
uint32_t item_kind(const GlyphKey& key);

// The rasterizer's work items for `work` into `items`, and into `workgroup_items` the item of
// each workgroup; returns the workgroups they take. Work of a font not held, or without samples,
// makes none. Items come kind after kind (item_kind()), and `kind_workgroups` gets the
// workgroups of each kind. Transformed glyphs' items point into `transforms`, one per such item.
uint32_t build_work_items(std::span<const RasterWork> work, const HeldFonts& fonts, std::vector<gpu::RasterItem>& items,
                          std::vector<gpu::RasterTransform>& transforms, std::vector<uint32_t>& workgroup_items,
                          std::array<uint32_t, kRasterItemKinds>& kind_workgroups);

// What the rasterizer samples (RendererCreateInfo), fixed at create().
struct RasterOptions {
    uint32_t frames_in_flight = 2;
    bool shared_row_roots = true;
    SampleKind sample_kind = SampleKind::rows;
};

class RasterPass {
public:
    RasterPass(const vk::DeviceRef& ref, const RasterOptions& options);  // `ref` outlives it

    // The item buffers for an atlas of `cells` and `atlas_texels`, the empty font slot's buffer,
    // the descriptor sets and the pipeline.
    Status create(uint32_t cells, uint64_t atlas_texels, RetireLists& retired);
    // The item buffers grown, where they are short, for an atlas grown to `cells` and
    // `atlas_texels`; the ones they replace are retired at `this_frame`. On failure nothing changes.
    Status fit(uint32_t cells, uint64_t atlas_texels, uint64_t this_frame, RetireLists& retired);

    // This frame's work items (build_work_items) and their stats; returns their workgroups.
    uint32_t build(std::span<const RasterWork> work, const HeldFonts& fonts, const GlyphAtlas& atlas,
                   RendererStats& stats);
    bool has_items() const { return !item_data_.empty(); }
    // Makes the pipelines of the kinds this frame's items need that are not made yet (derived
    // glyphs' pipelines are made at the first frame that draws one).
    Status prepare_pipelines();
    void record_upload(VkCommandBuffer command_buffer, uint64_t this_frame, bool fonts_uploaded, RendererStats& stats);
    void record_dispatch(VkCommandBuffer command_buffer, uint64_t this_frame, VkImageView atlas,
                         std::span<const FontPage> pages, const SubpixelLayout& subpixel);

private:
    // `items` and its staging buffers for `capacity` items and the workgroups of an atlas of
    // `atlas_texels`; the ones they replace are retired at frame `retire_at`. On failure nothing
    // changes.
    Status make_item_buffers(uint32_t capacity, uint64_t atlas_texels, uint64_t retire_at, RetireLists& retired);
    void write_descriptors(VkDescriptorSet set, VkImageView atlas, std::span<const FontPage> pages);
    Status make_pipeline(uint32_t kind);

    const vk::DeviceRef& ref_;
    RasterOptions options_;
    // Device-local: RasterItem[item_capacity], at transform_offset RasterTransform[item_capacity],
    // then at table_offset the item of each workgroup, uint[workgroup_capacity].
    vk::DeviceBuffer items_;
    // Host-visible and mapped, one per frame in flight, laid out as `items`: a frame's items and
    // table are written here and copied into `items` by its command buffer.
    std::vector<vk::DeviceBuffer> item_staging_;
    uint32_t item_capacity_ = 0;
    uint32_t workgroup_capacity_ = 0;
    VkDeviceSize transform_offset_ = 0;
    VkDeviceSize table_offset_ = 0;
    vk::DeviceBuffer dummy_;  // bound to the font slots no font uses
    std::vector<gpu::RasterItem> item_data_;
    std::vector<gpu::RasterTransform> transform_data_;
    std::vector<uint32_t> workgroup_items_;  // this frame's table

    vk::DeviceObjects objects_;  // the shader module and the pipeline
    VkShaderModule shader_ = VK_NULL_HANDLE;
    vk::DescriptorSets descriptors_;  // one set per frame in flight
    // By kind: axis-aligned items, transformed ones, transformed ones of two lines a sample; then
    // the same of derived glyphs; then all six blurred.
    std::array<VkPipeline, kRasterItemKinds> pipelines_{};
    std::array<uint32_t, kRasterItemKinds> kind_workgroups_{};  // this frame's workgroups of each kind
};

}  // namespace crisp::raster
