// The colour layers' fills every compositing path reads.
#include "composite/paints.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

namespace crisp::composite {

namespace {

float finite_or(float value, float fallback) {
    return std::isfinite(value) ? value : fallback;
}

}  // namespace

gpu::QuadPaint quad_paint(const FramePaint& paint) {
    gpu::QuadPaint q{};
    q.kind = static_cast<uint32_t>(paint.kind);
    q.extend = static_cast<uint32_t>(paint.extend);
    q.first_stop = paint.first_stop;
    q.stop_count = paint.stop_count;
    q.to_paint_x = {finite_or(paint.to_paint[0], 0.0f), finite_or(paint.to_paint[1], 0.0f),
                    finite_or(paint.to_paint[2], 0.0f), 0.0f};
    q.to_paint_y = {finite_or(paint.to_paint[3], 0.0f), finite_or(paint.to_paint[4], 0.0f),
                    finite_or(paint.to_paint[5], 0.0f), 0.0f};
    q.geometry0 = {paint.geometry[0], paint.geometry[1], paint.geometry[2], paint.geometry[3]};
    q.geometry1 = {paint.geometry[4], paint.geometry[5], 0.0f, 0.0f};
    q.clip = {paint.clip[0], paint.clip[1], paint.clip[2], paint.clip[3]};
    q.image_layer = paint.image_layer;
    q.image_u = std::clamp(finite_or(paint.image_extent[0], 0.0f), 0.0f, 1.0f);
    q.image_v = std::clamp(finite_or(paint.image_extent[1], 0.0f), 0.0f, 1.0f);
    q.opacity = std::clamp(finite_or(paint.opacity, 0.0f), 0.0f, 1.0f);
    return q;
}

Status PaintInputs::create(const vk::DeviceRef& device, uint32_t frames_in_flight) {
    ref_ = device;
    VkSamplerCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    // Trilinear over the images' box-filtered mips: a bitmap drawn smaller than its layer does not
    // alias, one drawn larger is interpolated.
    info.magFilter = VK_FILTER_LINEAR;
    info.minFilter = VK_FILTER_LINEAR;
    info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    info.addressModeU = info.addressModeV = info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    info.maxLod = VK_LOD_CLAMP_NONE;
    if (VkResult r = ref_.fn->vkCreateSampler(ref_.device, &info, ref_.allocator, &sampler_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateSampler (compositor bitmap images)", r);
    }
    objects_.keep(ref_, sampler_);
    slots_.resize(frames_in_flight);
    return {};
}

Status PaintInputs::fit(vk::DeviceBuffer& buffer, VkDeviceSize bytes, const char* what) {
    if (buffer.buffer && buffer.size >= bytes) return {};
    // The slot's last use is done (the frames-in-flight contract), so its buffer can go.
    buffer.reset();
    return vk::create_buffer(ref_, std::max<VkDeviceSize>(256, std::bit_ceil(bytes)),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, what, buffer);
}

Status PaintInputs::upload(const DrawnFrame& frame) {
    Slot& slot = slots_[frame_ % slots_.size()];
    paint_data_.clear();
    for (const FramePaint& paint : frame.paints) {
        gpu::QuadPaint q = quad_paint(paint);
        // A paint whose stops are not in the frame's, or of no known kind, fills nothing.
        const bool stops_ok = q.kind == gpu::kPaintSolid || q.kind == gpu::kPaintImage ||
                              (q.stop_count > 0 && uint64_t{q.first_stop} + q.stop_count <= frame.stops.size());
        if (!stops_ok || q.kind > gpu::kPaintImage) {
            q.kind = gpu::kPaintSolid;
            q.clip = {0.0f, 0.0f, 0.0f, 0.0f};
        }
        paint_data_.push_back(q);
    }
    stop_data_.clear();
    for (const FrameStop& stop : frame.stops) {
        gpu::PaintStop s{};
        s.colour = {std::clamp(finite_or(stop.colour[0], 0.0f), 0.0f, 1.0f),
                    std::clamp(finite_or(stop.colour[1], 0.0f), 0.0f, 1.0f),
                    std::clamp(finite_or(stop.colour[2], 0.0f), 0.0f, 1.0f),
                    std::clamp(finite_or(stop.colour[3], 0.0f), 0.0f, 1.0f)};
        s.offset = finite_or(stop.offset, 0.0f);
        stop_data_.push_back(s);
    }
    const VkDeviceSize paint_bytes = paint_data_.size() * sizeof(gpu::QuadPaint);
    const VkDeviceSize stop_bytes = stop_data_.size() * sizeof(gpu::PaintStop);
    if (Status s = fit(slot.paints, paint_bytes, "compositor paints"); !s) return s;
    if (Status s = fit(slot.stops, stop_bytes, "compositor paint stops"); !s) return s;
    if (paint_bytes > 0) std::memcpy(slot.paints.mapped, paint_data_.data(), paint_bytes);
    if (stop_bytes > 0) std::memcpy(slot.stops.mapped, stop_data_.data(), stop_bytes);

    images_ = frame.images;
    ++frame_;
    recorded_ = true;
    return {};
}

void PaintInputs::abandon_frame() {
    if (!recorded_) return;
    recorded_ = false;
    --frame_;
}

void PaintInputs::write(vk::DescriptorWrites& writes, uint32_t paints_binding, uint32_t stops_binding,
                        uint32_t images_binding) const {
    const Slot& slot = slots_[(frame_ + slots_.size() - 1) % slots_.size()];
    writes.storage_buffer(paints_binding, slot.paints.buffer)
        .storage_buffer(stops_binding, slot.stops.buffer)
        .sampled_image(images_binding, images_, sampler_);
}

}  // namespace crisp::composite
