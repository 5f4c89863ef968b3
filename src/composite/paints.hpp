// What every compositing path reads for colour layers' fills (shaders/composite/paint.glsl): the
// frame's paints and stops in host-visible buffers of the frame slot, and the bitmap images with
// their sampler.
#pragma once

#include "vk/bindings.hpp"
#include "vk/resources.hpp"

#include <crisp/renderer.hpp>

#include "shared.h"

#include <vector>

namespace crisp::composite {

class PaintInputs {
public:
    // The sampler and one pair of buffers per frame in flight. Errors: vulkan.
    Status create(const vk::DeviceRef& device, uint32_t frames_in_flight);

    // Copies `frame`'s paints and stops into the next slot's buffers (one slot per record*() call
    // of the compositor); records no command. Errors: vulkan.
    Status upload(const DrawnFrame& frame);
    // Takes back the last upload(): its slot.
    void abandon_frame();

    // The last record()'s buffers and images as the three bindings of a pass's set.
    void write(vk::DescriptorWrites& writes, uint32_t paints_binding, uint32_t stops_binding,
               uint32_t images_binding) const;

private:
    struct Slot {
        vk::DeviceBuffer paints;  // host-visible gpu::QuadPaint[]
        vk::DeviceBuffer stops;   // host-visible gpu::PaintStop[]
    };
    Status fit(vk::DeviceBuffer& buffer, VkDeviceSize bytes, const char* what);

    vk::DeviceRef ref_;
    vk::DeviceObjects objects_;
    VkSampler sampler_ = VK_NULL_HANDLE;
    std::vector<Slot> slots_;
    uint64_t frame_ = 0;
    bool recorded_ = false;
    VkImageView images_ = VK_NULL_HANDLE;  // the last record()'s
    std::vector<gpu::QuadPaint> paint_data_;
    std::vector<gpu::PaintStop> stop_data_;
};

// The gpu form of a frame's paint.
gpu::QuadPaint quad_paint(const FramePaint& paint);

}  // namespace crisp::composite
