// Private: the compositor's reference modes (unsorted, wboit, exact),
// into the compositor's own RGBA32F target over a flat background (docs/compositing.md).
#pragma once

#include "composite/paints.hpp"

#include "shared.h"
#include "vk/resources.hpp"

#include <crisp/compositor.hpp>

#include <array>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace crisp::composite {

class ReferenceCompositor {
public:
    ReferenceCompositor() = default;
    ReferenceCompositor(const ReferenceCompositor&) = delete;
    ReferenceCompositor& operator=(const ReferenceCompositor&) = delete;
    ~ReferenceCompositor();

    // The target, per-pixel buffers and fixed pipelines for `info` (already checked by
    // Compositor::create). Warnings go to `warnings`.
    Status create(const vk::DeviceRef& device, const CompositorCreateInfo& info, std::vector<std::string>& warnings);
    Status record(VkCommandBuffer command_buffer, const DrawnFrame& drawn, const PaintInputs& paints,
                  const CompositeParams& params, CompositorStats& stats);
    void record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const;
    const vk::DeviceImage& target() const { return target_; }
    // Takes back the last record() (its command buffer will not be submitted).
    void abandon_frame();

private:
    struct FrameSlot {
        vk::DeviceBuffer quads;  // host-visible CompositeQuad[]
        uint32_t quad_capacity = 0;
        vk::DeviceBuffer tiles;  // host-visible uvec2[]: the compute path's tiles
        uint32_t tile_capacity = 0;
        vk::DeviceBuffer stats;  // host-visible copy of the stats words
        VkDescriptorSet set = VK_NULL_HANDLE;
        bool pending = false;  // recorded, its stats not read yet
        uint64_t frame = 0;
        CompositeMode mode = CompositeMode::exact;
    };

    Status create_buffers(const CompositorCreateInfo& info, std::vector<std::string>& warnings);
    Status create_descriptors();
    Status create_passes();
    Status create_pipelines();
    Result<VkShaderModule> module(const char* name);
    Result<VkPipeline> graphics_pipeline(const char* fragment, const VkSpecializationInfo* specialization, bool blend);
    Result<VkPipeline> compute_pipeline(const char* shader, const VkSpecializationInfo* specialization);
    Status check(const CompositeParams& params) const;
    // Whether the frame's quad passes run as compute (making their pipeline on first use).
    Result<bool> compute_pass_for(const CompositeParams& params);
    void read_back_stats(FrameSlot& slot, CompositorStats& stats);
    void build_tiles();
    Status upload(vk::DeviceBuffer& buffer, uint32_t& capacity, const void* data, uint32_t count, size_t size);
    void write_descriptors(const FrameSlot& slot, VkImageView atlas_view, const PaintInputs& paints);
    gpu::CompositePushConstants push_constants(const CompositeParams& params) const;
    void record_target_init(VkCommandBuffer command_buffer);
    uint64_t record_clears(VkCommandBuffer command_buffer, CompositeMode mode);
    void record_passes(VkCommandBuffer command_buffer, const FrameSlot& slot, CompositeMode mode, bool compute,
                       const gpu::CompositePushConstants& push);
    void record_draw(VkCommandBuffer command_buffer, const FrameSlot& slot, VkPipeline pipeline, bool color,
                     const gpu::CompositePushConstants& push);
    void record_dispatch(VkCommandBuffer command_buffer, const FrameSlot& slot, VkPipeline pipeline, uint32_t x,
                         uint32_t y, const gpu::CompositePushConstants& push);

    vk::DeviceRef ref;
    uint32_t width = 0, height = 0, pixels = 0;
    uint32_t frames_in_flight = 2;
    uint32_t node_capacity = 0;

    vk::DeviceImage target_;
    bool target_initialized = false;
    bool target_was_initialized = false;  // before the last record()
    bool recorded = false;                // record() since the last abandon_frame()

    vk::DeviceBuffer accumulators;  // kWboitWords (the most either mode uses) words per pixel
    vk::DeviceBuffer nodes;         // exact mode's pool; a stand-in of 16 bytes when there is none
    vk::DeviceBuffer stats_words;   // device-local kStatWords

    vk::DeviceObjects objects;  // shader modules, pipelines, render passes, framebuffers
    std::map<std::string, VkShaderModule> modules;
    vk::DescriptorSets descriptors;            // one set per frame in flight
    VkRenderPass empty_pass = VK_NULL_HANDLE;  // no attachments: the storage-only passes
    VkRenderPass color_pass = VK_NULL_HANDLE;  // the target as colour attachment: unsorted
    VkFramebuffer empty_framebuffer = VK_NULL_HANDLE;
    VkFramebuffer color_framebuffer = VK_NULL_HANDLE;
    VkPipeline unsorted = VK_NULL_HANDLE, wboit = VK_NULL_HANDLE, exact = VK_NULL_HANDLE;
    VkPipeline wboit_resolve = VK_NULL_HANDLE, exact_resolve = VK_NULL_HANDLE;
    VkPipeline wboit_compute = VK_NULL_HANDLE, exact_compute = VK_NULL_HANDLE;  // made on first use

    std::vector<FrameSlot> slots;
    uint64_t frame = 0;
    std::vector<gpu::CompositeQuad> quad_data;
    std::vector<uint32_t> tile_data;  // pairs: quad index, tile origin in its rect (x | y << 16)
};

}  // namespace crisp::composite
