#include "raster/raster.hpp"

#include "text/blur_kernel.hpp"
#include "vk/barriers.hpp"
#include "vk/bindings.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstring>
#include <utility>

namespace crisp::raster {

namespace {

// The bindings raster.comp declares: the atlas, the work items, each font page's curve points and
// band words (unused pages bound to an empty buffer), and each workgroup's item.
constexpr vk::Binding kBindings[] = {
    {gpu::kRasterBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kRasterBindItems, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kRasterBindPoints, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRendererFontPages},
    {gpu::kRasterBindBands, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRendererFontPages},
    {gpu::kRasterBindWorkgroupItems, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kRasterBindTransforms, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
};
constexpr vk::BindingTable kTable{kBindings, VK_SHADER_STAGE_COMPUTE_BIT};

}  // namespace

static_assert(kCoverageOne == gpu::kRasterCoverageOne);
static_assert(static_cast<uint32_t>(SampleKind::rows) == gpu::kRasterSampleRows);
static_assert(static_cast<uint32_t>(SampleKind::points) == gpu::kRasterSamplePoints);
static_assert(kRendererFontPages == gpu::kRasterFontPages);

namespace {

gpu::vec4 row_of(const Projective& map, int row) {
    const double* m = map.m + 3 * row;
    return {static_cast<float>(m[0]), static_cast<float>(m[1]), static_cast<float>(m[2]), 0.0f};
}

// A transformed glyph walks two lines a row sample where its em y axis lies within 15 degrees of
// the rows (tan 75 degrees = 3.732): there its stems run along the rows and eight lines leave the
// animated screen's mean error at 0.010-0.015 (H200, docs/transforms.md); further from vertical
// one line keeps it under 0.008 at half the cost.
constexpr double kTwoLineSlope = 3.7320508075688772;

// +1 where the map keeps the orientation of em (y up) in texels (y down), -1 where it reverses it
// (every unmirrored glyph: y flips): the sign of its determinant, W being positive.
float orientation(const Projective& map) {
    const double* m = map.m;
    const double det =
        m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
    return det > 0.0 ? 1.0f : -1.0f;
}

// The truth table raster.comp covers by for a derived glyph of `op`.
uint32_t cover_rule(StrokeOp op) {
    switch (op) {
        case StrokeOp::a:
            return gpu::kRasterCoverA;
        case StrokeOp::a_not_b:
            return gpu::kRasterCoverAOutsideB;
        case StrokeOp::a_and_b:
            return gpu::kRasterCoverAInsideB;
        case StrokeOp::a_or_b:
            return gpu::kRasterCoverAOrB;
        case StrokeOp::b_not_a:
            return gpu::kRasterCoverBOutsideA;
    }
    return gpu::kRasterCoverA;
}

}  // namespace

uint32_t item_kind(const GlyphKey& key) {
    if (!is_transformed(key)) return 0;
    // Stems along the rows: the em y axis's image within 15 degrees of horizontal.
    return std::abs(static_cast<double>(key.linear[1])) > kTwoLineSlope * std::abs(static_cast<double>(key.linear[3]))
               ? gpu::kRasterTwoLineItems
               : 1;
}

uint32_t build_work_items(std::span<const RasterWork> work, const HeldFonts& fonts, std::vector<gpu::RasterItem>& items,
                          std::vector<gpu::RasterTransform>& transforms, std::vector<uint32_t>& workgroup_items,
                          std::array<uint32_t, kRasterItemKinds>& kind_workgroups) {
    items.clear();
    transforms.clear();
    workgroup_items.clear();
    uint32_t workgroups = 0;
    // The axis-aligned items first, then the transformed ones of one line a sample, then those of
    // two: each set is one dispatch of its own pipeline (RasterPass::record_dispatch).
    for (uint32_t kind = 0; kind < kRasterItemKinds; ++kind) {
        const uint32_t first_workgroup = workgroups;
        for (const RasterWork& w : work) {
            if (w.sample_count == 0 || item_kind(w.key) != kind % kRasterGeometryKinds) continue;
            if ((kind >= kRasterBlurKindBase) != (w.key.blur != 0)) continue;
            const HeldGlyph held = fonts.glyph(w.key);
            if (!held.font || (kind % kRasterBlurKindBase >= kRasterGeometryKinds) != held.derived) continue;
            const HeldFont* font = held.font;
            const GlyphRecord& glyph = *held.record;
            const GlyphRect rect = glyph_rect(glyph, w.key);
            gpu::RasterItem item{};
            item.transform = gpu::kRasterNoTransform;
            item.flat_row = gpu::kRasterNoTransform;
            item.set_b_first = held.derived ? held.set_b_first : gpu::kRasterNoTransform;
            item.cover_rule = held.derived ? cover_rule(held.op) : gpu::kRasterCoverA;
            item.blur_w = static_cast<float>(blur_box_width(w.key.blur * kBlurUnit));
            if (is_transformed(w.key)) {
                const uint32_t row = held.flat_row;
                if (row != kNoFlatRow) item.flat_row = static_cast<uint32_t>(font->bands_at / sizeof(uint32_t)) + row;
                const Projective to_texel = em_to_texel(rect, w.key);
                const Projective to_em = inverse(to_texel);
                item.transform = static_cast<uint32_t>(transforms.size());
                gpu::RasterTransform t{{row_of(to_texel, 0), row_of(to_texel, 1), row_of(to_texel, 2)},
                                       {row_of(to_em, 0), row_of(to_em, 1), row_of(to_em, 2)}};
                t.to_texel[0].w = orientation(to_texel);
                t.to_texel[1].w = glyph.bbox_min_x;
                t.to_texel[2].w = glyph.bbox_max_x;
                transforms.push_back(t);
            }
            const TexelToEm map = is_transformed(w.key) ? TexelToEm{} : texel_to_em(rect, w.key);
            item.atlas_x = w.x;
            item.atlas_y = w.y;
            item.width = w.width;
            item.height = w.height;
            item.offset_x = map.offset_x;
            item.offset_y = map.offset_y;
            item.scale_x = map.scale_x;
            item.scale_y = map.scale_y;
            item.bbox_min_y = glyph.bbox_min_y;
            item.bbox_max_y = glyph.bbox_max_y;
            item.point_offset = static_cast<uint32_t>(font->points_at / sizeof(Point)) + glyph.point_offset;
            item.band_offset = static_cast<uint32_t>(font->bands_at / sizeof(uint32_t)) + glyph.band_offset;
            item.band_count = glyph.band_count;
            item.band_words = glyph.band_words;
            item.font = font->page;
            item.first_sample = w.first_sample;
            item.sample_count = w.sample_count;
            item.part_x = w.part_x;
            item.part_y = w.part_y;
            item.first_texel = w.first_texel;
            item.texel_count = w.texel_count;
            item.first_workgroup = workgroups;
            const uint32_t own = (w.texel_count + gpu::kRasterWorkgroupSize - 1) / gpu::kRasterWorkgroupSize;
            workgroups += own;
            workgroup_items.insert(workgroup_items.end(), own, static_cast<uint32_t>(items.size()));
            items.push_back(item);
        }
        kind_workgroups[kind] = workgroups - first_workgroup;
    }
    return workgroups;
}

RasterPass::RasterPass(const vk::DeviceRef& ref, const RasterOptions& options) : ref_(ref), options_(options) {}

Status RasterPass::make_item_buffers(uint32_t capacity, uint64_t atlas_texels, uint64_t retire_at,
                                     RetireLists& retired) {
    // Items cover disjoint parts of the atlas, so a dispatch has at most a workgroup per 64 atlas
    // texels plus one partial workgroup per item.
    const uint64_t workgroups = atlas_texels / gpu::kRasterWorkgroupSize + capacity;
    if (workgroups > UINT32_MAX) return Error{ErrorCode::invalid_argument, "renderer: the atlas is too large"};
    // The transforms and the table start at offsets every device accepts for a storage buffer (at
    // most 256).
    const auto aligned = [](VkDeviceSize bytes) { return (bytes + 255) / 256 * 256; };
    const VkDeviceSize transform_offset = aligned(VkDeviceSize{capacity} * sizeof(gpu::RasterItem));
    const VkDeviceSize offset = transform_offset + aligned(VkDeviceSize{capacity} * sizeof(gpu::RasterTransform));
    const VkDeviceSize bytes = offset + workgroups * sizeof(uint32_t);
    vk::DeviceBuffer device_items;
    if (Status s = vk::create_buffer(ref_, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                     false, "work items", device_items);
        !s) {
        return s;
    }
    std::vector<vk::DeviceBuffer> staging(options_.frames_in_flight);
    for (vk::DeviceBuffer& slot : staging) {
        if (Status s =
                vk::create_buffer(ref_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "work item staging", slot);
            !s) {
            return s;
        }
    }
    if (items_.buffer) retired.buffers.push_back({std::move(items_), retire_at});
    for (vk::DeviceBuffer& old : item_staging_) retired.buffers.push_back({std::move(old), retire_at});
    items_ = std::move(device_items);
    item_staging_ = std::move(staging);
    item_capacity_ = capacity;
    workgroup_capacity_ = static_cast<uint32_t>(workgroups);
    transform_offset_ = transform_offset;
    table_offset_ = offset;
    return {};
}

Status RasterPass::create(uint32_t cells, uint64_t atlas_texels, RetireLists& retired) {
    // Work items: an entry takes at least one cell, so a frame never has more items than cells.
    if (Status s = make_item_buffers(cells, atlas_texels, 0, retired); !s) return s;
    if (Status s = vk::create_buffer(ref_, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "empty font slot", dummy_);
        !s) {
        return s;
    }

    // The pipeline.
    Result<VkShaderModule> module = vk::create_embedded_shader(ref_, "raster.comp");
    if (!module) return module.error();
    shader_ = objects_.keep(ref_, *module);
    // One descriptor set per frame in flight: a set is rewritten only when its last use is done.
    if (Status s = vk::create_descriptor_sets(ref_, kTable, sizeof(gpu::RasterPushConstants), options_.frames_in_flight,
                                              "renderer", descriptors_);
        !s) {
        return s;
    }
    // Three pipelines of one shader (kTransformedItems, item_kind()): axis-aligned items,
    // transformed ones, and transformed ones that walk two lines a sample. Derived glyphs' three
    // wait for the first frame that draws one (prepare_pipelines()).
    for (uint32_t kind = 0; kind < kRasterGeometryKinds; ++kind) {
        if (Status s = make_pipeline(kind); !s) return s;
    }
    return {};
}

Status RasterPass::make_pipeline(uint32_t kind) {
    static constexpr const char* kNames[kRasterItemKinds] = {"raster.comp",
                                                             "raster.comp (transformed)",
                                                             "raster.comp (transformed, two lines)",
                                                             "raster.comp (two sets)",
                                                             "raster.comp (transformed, two sets)",
                                                             "raster.comp (transformed, two lines, two sets)",
                                                             "raster.comp (blurred)",
                                                             "raster.comp (transformed, blurred)",
                                                             "raster.comp (transformed, two lines, blurred)",
                                                             "raster.comp (two sets, blurred)",
                                                             "raster.comp (transformed, two sets, blurred)",
                                                             "raster.comp (transformed, two lines, two sets, blurred)"};
    const uint32_t constants[3] = {kind % kRasterGeometryKinds,
                                   kind % kRasterBlurKindBase >= kRasterGeometryKinds ? 1u : 0u,
                                   kind >= kRasterBlurKindBase ? 1u : 0u};
    const VkSpecializationMapEntry entries[3] = {
        {0, 0, sizeof(uint32_t)}, {1, sizeof(uint32_t), sizeof(uint32_t)}, {2, 2 * sizeof(uint32_t), sizeof(uint32_t)}};
    const VkSpecializationInfo specialization{3, entries, sizeof constants, constants};
    Result<VkPipeline> made =
        vk::create_compute_pipeline(ref_, shader_, descriptors_.pipeline_layout, &specialization, kNames[kind]);
    if (!made) return made.error();
    pipelines_[kind] = objects_.keep(ref_, *made);
    return {};
}

Status RasterPass::prepare_pipelines() {
    for (uint32_t kind = 0; kind < kRasterItemKinds; ++kind) {
        if (kind_workgroups_[kind] == 0 || pipelines_[kind] != VK_NULL_HANDLE) continue;
        if (Status s = make_pipeline(kind); !s) return s;
    }
    return {};
}

void RasterPass::write_descriptors(VkDescriptorSet set, VkImageView atlas, std::span<const FontPage> pages) {
    std::array<VkDescriptorBufferInfo, kRendererFontPages> point_infos{}, band_infos{};
    for (uint32_t page = 0; page < kRendererFontPages; ++page) {
        const bool used = page < pages.size() && pages[page].points.buffer != VK_NULL_HANDLE;
        point_infos[page] = {used ? pages[page].points.buffer : dummy_.buffer, 0, VK_WHOLE_SIZE};
        band_infos[page] = {used ? pages[page].bands.buffer : dummy_.buffer, 0, VK_WHOLE_SIZE};
    }
    vk::DescriptorWrites(kTable, set)
        .storage_image(gpu::kRasterBindAtlas, atlas)
        .storage_buffer(gpu::kRasterBindItems, items_.buffer, 0, transform_offset_)
        .storage_buffer(gpu::kRasterBindTransforms, items_.buffer, transform_offset_, table_offset_ - transform_offset_)
        .storage_buffers(gpu::kRasterBindPoints, point_infos)
        .storage_buffers(gpu::kRasterBindBands, band_infos)
        .storage_buffer(gpu::kRasterBindWorkgroupItems, items_.buffer, table_offset_)
        .update(ref_);
}

Status RasterPass::fit(uint32_t cells, uint64_t atlas_texels, uint64_t this_frame, RetireLists& retired) {
    if (cells > item_capacity_ || atlas_texels / gpu::kRasterWorkgroupSize + cells > workgroup_capacity_) {
        return make_item_buffers(cells, atlas_texels, this_frame, retired);
    }
    return {};
}

uint32_t RasterPass::build(std::span<const RasterWork> work, const HeldFonts& fonts, const GlyphAtlas& atlas,
                           RendererStats& stats) {
    const uint32_t workgroups =
        build_work_items(work, fonts, item_data_, transform_data_, workgroup_items_, kind_workgroups_);
    stats.work_items = static_cast<uint32_t>(item_data_.size());
    stats.workgroups = workgroups;
    stats.samples = atlas.stats().frame.samples;
    stats.curve_tests = atlas.stats().frame.curve_tests;
    return workgroups;
}

// The work list into the items buffer: written into this frame's staging buffer (the frame that
// last used it is done: the caller waits for frame N - frames_in_flight before recording frame N)
// and copied. vkCmdUpdateBuffer, which carries the bytes in the command buffer, took 0.1-0.2 ms
// of every frame on an H200 for the 1.1 MB of a new 4K screen; with the copy, a frame whose shader
// does nothing takes 0.03 ms (docs/results/h200-row-kernel.md). A barrier first keeps last frame's reads before the
// copy, one after makes it (and the fonts' copies) visible to the rasterizer.
void RasterPass::record_upload(VkCommandBuffer command_buffer, uint64_t this_frame, bool fonts_uploaded,
                               RendererStats& stats) {
    const vk::Functions& fn = *ref_.fn;
    if (!item_data_.empty()) {
        vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_TRANSFER_WRITE_BIT);
        // Items are parts of disjoint atlas entries: make_item_buffers() sized both for every atlas texel.
        assert(item_data_.size() <= item_capacity_ && workgroup_items_.size() <= workgroup_capacity_);
        const vk::DeviceBuffer& staging = item_staging_[this_frame % options_.frames_in_flight];
        const VkDeviceSize item_bytes = item_data_.size() * sizeof(gpu::RasterItem);
        const VkDeviceSize transform_bytes = transform_data_.size() * sizeof(gpu::RasterTransform);
        const VkDeviceSize table_bytes = workgroup_items_.size() * sizeof(uint32_t);
        auto* bytes = static_cast<std::byte*>(staging.mapped);
        std::memcpy(bytes, item_data_.data(), item_bytes);
        if (transform_bytes != 0) std::memcpy(bytes + transform_offset_, transform_data_.data(), transform_bytes);
        std::memcpy(bytes + table_offset_, workgroup_items_.data(), table_bytes);
        const VkBufferCopy copies[3] = {{0, 0, item_bytes},
                                        {table_offset_, table_offset_, table_bytes},
                                        {transform_offset_, transform_offset_, transform_bytes}};
        fn.vkCmdCopyBuffer(command_buffer, staging.buffer, items_.buffer, transform_bytes != 0 ? 3 : 2, copies);
        stats.upload_bytes += item_bytes + transform_bytes + table_bytes;
    }
    if (fonts_uploaded || !item_data_.empty()) {
        vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    }
}

// The rasterizer's dispatches over this frame's workgroups, between barriers against last frame's readers of
// the atlas (composite shaders, copies) and for this frame's.
void RasterPass::record_dispatch(VkCommandBuffer command_buffer, uint64_t this_frame, VkImageView atlas,
                                 std::span<const FontPage> pages, const SubpixelLayout& subpixel) {
    const vk::Functions& fn = *ref_.fn;
    constexpr VkPipelineStageFlags kReaders =
        VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vk::memory_barrier(fn, command_buffer, kReaders, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
    const VkDescriptorSet set = descriptors_.sets[this_frame % options_.frames_in_flight];
    write_descriptors(set, atlas, pages);
    fn.vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, descriptors_.pipeline_layout, 0, 1, &set,
                               0, nullptr);
    gpu::RasterPushConstants push{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = subpixel.channels[c];
        push.channel_rects[c] = {r.x0, r.y0, r.x1, r.y1};
    }
    push.shared_rows = options_.shared_row_roots && shares_sample_rows(subpixel) ? 1u : 0u;
    push.sample_kind = options_.sample_kind == SampleKind::points ? gpu::kRasterSamplePoints : gpu::kRasterSampleRows;
    // The items come kind after kind (build_work_items): a dispatch each, no barrier between
    // (their atlas texels are disjoint).
    uint32_t base = 0;
    for (uint32_t kind = 0; kind < kRasterItemKinds; ++kind) {
        const uint32_t count = kind_workgroups_[kind];
        push.workgroup_base = base;
        base += count;
        if (count == 0) continue;
        fn.vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[kind]);
        push.workgroup_count = count;
        fn.vkCmdPushConstants(command_buffer, descriptors_.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push,
                              &push);
        const uint32_t width = std::min(count, gpu::kRasterDispatchWidth);
        const uint32_t height = (count + gpu::kRasterDispatchWidth - 1) / gpu::kRasterDispatchWidth;
        fn.vkCmdDispatch(command_buffer, width, height, 1);
    }
    vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, kReaders,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
}

}  // namespace crisp::raster
