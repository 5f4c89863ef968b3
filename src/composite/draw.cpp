// The compositor's draw path: sorted quads blended inside the caller's render pass.
#include "composite/draw.hpp"

#include "composite/quad_pipeline.hpp"
#include "vk/bindings.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace crisp::composite {

namespace {

constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
// The bindings quad_pipeline.glsl declares for a rasterized quad: the atlas, the quads and their
// fills.
constexpr vk::Binding kBindings[] = {
    {gpu::kCompositeBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kCompositeBindQuads, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindPaints, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindStops, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindImages, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
};
constexpr vk::BindingTable kTable{kBindings, kStages};

}  // namespace

DrawCompositor::~DrawCompositor() = default;

Status DrawCompositor::create(const vk::DeviceRef& device, VkPhysicalDevice physical_device, VkFormat format,
                              VkFormat depth_format, uint32_t frames_in_flight) {
    ref_ = device;
    VkFormatProperties properties{};
    ref_.fn->vkGetPhysicalDeviceFormatProperties(physical_device, format, &properties);
    if ((properties.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) == 0) {
        return Error{ErrorCode::vulkan, "compositor: draw_format (VkFormat " + std::to_string(format) +
                                            ") cannot be a blended colour attachment on this device"};
    }
    if (depth_format != VK_FORMAT_UNDEFINED) {
        VkFormatProperties depth{};
        ref_.fn->vkGetPhysicalDeviceFormatProperties(physical_device, depth_format, &depth);
        if ((depth.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) == 0) {
            return Error{ErrorCode::vulkan, "compositor: draw_depth_format (VkFormat " + std::to_string(depth_format) +
                                                ") cannot be a depth attachment on this device"};
        }
    }
    if (Status s = vk::create_descriptor_sets(ref_, kTable, sizeof(gpu::CompositePushConstants), frames_in_flight,
                                              "compositor draw path", descriptors_);
        !s) {
        return s;
    }
    slots_.resize(frames_in_flight);
    for (uint32_t i = 0; i < frames_in_flight; ++i) slots_[i].set = descriptors_.sets[i];
    Result<VkShaderModule> vertex = vk::create_embedded_shader(ref_, "quad_pipeline.vert");
    if (!vertex) return vertex.error();
    vertex_ = objects_.keep(ref_, *vertex);
    Result<VkShaderModule> fragment = vk::create_embedded_shader(ref_, "draw.frag");
    if (!fragment) return fragment.error();
    fragment_ = objects_.keep(ref_, *fragment);

    QuadPipeline desc;
    desc.vertex = vertex_;
    desc.fragment = fragment_;
    desc.layout = descriptors_.pipeline_layout;
    desc.blend_over = true;
    desc.color_format = format;
    desc.depth_format = depth_format;
    desc.what = "compositor draw path";
    Result<VkPipeline> pipeline = create_quad_pipeline(ref_, desc);
    if (!pipeline) return pipeline.error();
    pipeline_ = objects_.keep(ref_, *pipeline);
    return {};
}

Result<uint64_t> DrawCompositor::record(VkCommandBuffer command_buffer, std::span<const gpu::CompositeQuad> quads,
                                        VkImageView atlas_view, const PaintInputs& paints, const VkRect2D& rect) {
    Slot& slot = slots_[frame_ % slots_.size()];
    const VkDeviceSize bytes = quads.size_bytes();
    if (!slot.quads.buffer || slot.quads.size < bytes) {
        // The slot's last use is done (the frames-in-flight contract), so its buffer can go.
        slot.quads.reset();
        if (Status s = vk::create_buffer(ref_, std::max<VkDeviceSize>(256, std::bit_ceil(bytes)),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "draw quads", slot.quads);
            !s) {
            return s.error();
        }
    }
    if (bytes > 0) std::memcpy(slot.quads.mapped, quads.data(), bytes);
    vk::DescriptorWrites writes(kTable, slot.set);
    writes.storage_image(gpu::kCompositeBindAtlas, atlas_view)
        .storage_buffer(gpu::kCompositeBindQuads, slot.quads.buffer);
    paints.write(writes, gpu::kCompositeBindPaints, gpu::kCompositeBindStops, gpu::kCompositeBindImages);
    writes.update(ref_);
    ++frame_;
    recorded_ = true;
    if (quads.empty()) return uint64_t{0};

    gpu::CompositePushConstants push{};
    push.width = rect.extent.width;
    push.height = rect.extent.height;
    push.quad_count = static_cast<uint32_t>(quads.size());
    push.back_to_front = 1;
    push.origin_x = rect.offset.x;
    push.origin_y = rect.offset.y;
    ref_.fn->vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
    ref_.fn->vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, descriptors_.pipeline_layout, 0,
                                     1, &slot.set, 0, nullptr);
    ref_.fn->vkCmdPushConstants(command_buffer, descriptors_.pipeline_layout, kStages, 0, sizeof(push), &push);
    set_viewport(*ref_.fn, command_buffer, rect);
    ref_.fn->vkCmdDraw(command_buffer, 4, push.quad_count, 0, 0);
    return uint64_t{bytes};
}

}  // namespace crisp::composite
