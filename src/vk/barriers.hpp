// Private: the pipeline barriers crisp's passes record, in one place.
#pragma once

#include "vk/functions.hpp"

#include <vulkan/vulkan.h>

namespace crisp::vk {

inline constexpr VkPipelineStageFlags kShaderStages =
    VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
inline constexpr VkAccessFlags kShaderAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;

// A global memory barrier: `source_access` at `source` stages made visible to
// `destination_access` at `destination` stages.
inline void memory_barrier(const Functions& fn, VkCommandBuffer command_buffer, VkPipelineStageFlags source,
                           VkAccessFlags source_access, VkPipelineStageFlags destination,
                           VkAccessFlags destination_access) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = source_access;
    barrier.dstAccessMask = destination_access;
    fn.vkCmdPipelineBarrier(command_buffer, source, destination, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

// A layout change of a whole colour image (every level and layer), with the same access ordering as
// memory_barrier.
inline void image_barrier(const Functions& fn, VkCommandBuffer command_buffer, VkImage image, VkImageLayout from,
                          VkImageLayout to, VkPipelineStageFlags source, VkAccessFlags source_access,
                          VkPipelineStageFlags destination, VkAccessFlags destination_access) {
    VkImageMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    barrier.srcAccessMask = source_access;
    barrier.dstAccessMask = destination_access;
    barrier.oldLayout = from;
    barrier.newLayout = to;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    fn.vkCmdPipelineBarrier(command_buffer, source, destination, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

}  // namespace crisp::vk
