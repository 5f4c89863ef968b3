// Private: the compositor's draw path: the frame's quads, sorted front to back on the CPU, drawn
// back to front inside the caller's render pass (dynamic rendering) with dual-source blending per
// channel, dst = L + T * dst, for targets that cannot be storage images.
#pragma once

#include "composite/paints.hpp"

#include "shared.h"
#include "vk/resources.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <span>
#include <vector>

namespace crisp::composite {

class DrawCompositor {
public:
    DrawCompositor() = default;
    DrawCompositor(const DrawCompositor&) = delete;
    DrawCompositor& operator=(const DrawCompositor&) = delete;
    ~DrawCompositor();

    // The pipeline for colour attachments of `format`, depth-tested against a depth attachment
    // of `depth_format` unless it is VK_FORMAT_UNDEFINED. Errors: vulkan when the format cannot
    // be a blended colour attachment, the depth format a depth attachment, or a call fails.
    Status create(const vk::DeviceRef& device, VkPhysicalDevice physical_device, VkFormat format, VkFormat depth_format,
                  uint32_t frames_in_flight);

    // Records the draws into the active render pass; `quads` sorted front to back for rect's size.
    // Returns the bytes of quads uploaded.
    Result<uint64_t> record(VkCommandBuffer command_buffer, std::span<const gpu::CompositeQuad> quads,
                            VkImageView atlas_view, const PaintInputs& paints, const VkRect2D& rect);
    // Takes back the last record() (its command buffer will not be submitted): the frame does
    // not count towards frames in flight.
    void abandon_frame() {
        if (recorded_) --frame_;
        recorded_ = false;
    }

private:
    struct Slot {
        vk::DeviceBuffer quads;  // host-visible CompositeQuad[]
        VkDescriptorSet set = VK_NULL_HANDLE;
    };

    vk::DeviceRef ref_;
    vk::DescriptorSets descriptors_;
    vk::DeviceObjects objects_;  // the shader modules and the pipeline
    VkShaderModule vertex_ = VK_NULL_HANDLE, fragment_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    std::vector<Slot> slots_;
    uint64_t frame_ = 0;
    bool recorded_ = false;  // record() since the last abandon_frame()
};

}  // namespace crisp::composite
