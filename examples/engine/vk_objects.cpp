#include "vk_objects.hpp"

#include <crisp/device_features.hpp>

namespace engine {
namespace {

crisp::Result<uint32_t> find_memory_type(VkPhysicalDevice physical_device, uint32_t type_bits,
                                         VkMemoryPropertyFlags properties) {
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(physical_device, &memory);
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        if ((type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & properties) == properties) return i;
    }
    return crisp::Error{crisp::ErrorCode::vulkan, "no memory type with the properties an allocation needs"};
}

crisp::Result<OwnedMemory> allocate(const MemoryContext& context, const VkMemoryRequirements& requirements,
                                    VkMemoryPropertyFlags properties) {
    crisp::Result<uint32_t> type = find_memory_type(context.physical_device, requirements.memoryTypeBits, properties);
    if (!type) return type.error();
    VkMemoryAllocateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    info.allocationSize = requirements.size;
    info.memoryTypeIndex = *type;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkAllocateMemory", vkAllocateMemory(context.device, &info, nullptr, &memory)); !s) {
        return s.error();
    }
    return OwnedMemory(context.device, memory);
}

}  // namespace

crisp::Error vulkan_error(const char* call, VkResult result) {
    const crisp::ErrorCode code =
        result == VK_ERROR_DEVICE_LOST ? crisp::ErrorCode::device_lost : crisp::ErrorCode::vulkan;
    return crisp::Error{code, std::string(call) + " failed: " + crisp::vk_result_name(result), result};
}

crisp::Status check(const char* call, VkResult result) {
    if (result == VK_SUCCESS) return {};
    return vulkan_error(call, result);
}

crisp::Result<Buffer> create_host_buffer(const MemoryContext& context, VkDeviceSize size, VkBufferUsageFlags usage) {
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    Buffer out;
    out.size = size;
    VkBuffer buffer = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreateBuffer", vkCreateBuffer(context.device, &info, nullptr, &buffer)); !s) {
        return s.error();
    }
    out.buffer = OwnedBuffer(context.device, buffer);
    VkMemoryRequirements requirements{};
    vkGetBufferMemoryRequirements(context.device, buffer, &requirements);
    crisp::Result<OwnedMemory> memory =
        allocate(context, requirements, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (!memory) return memory.error();
    out.memory = std::move(*memory);
    if (crisp::Status s = check("vkBindBufferMemory", vkBindBufferMemory(context.device, buffer, out.memory.get(), 0));
        !s) {
        return s.error();
    }
    if (crisp::Status s = check("vkMapMemory", vkMapMemory(context.device, out.memory.get(), 0, size, 0, &out.mapped));
        !s) {
        return s.error();
    }
    return out;
}

crisp::Result<Image> create_image(const MemoryContext& context, VkFormat format, VkExtent2D extent,
                                  VkImageUsageFlags usage, VkImageAspectFlags aspect) {
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {extent.width, extent.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    Image out;
    out.format = format;
    out.extent = extent;
    VkImage image = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreateImage", vkCreateImage(context.device, &info, nullptr, &image)); !s) {
        return s.error();
    }
    out.image = OwnedImage(context.device, image);
    VkMemoryRequirements requirements{};
    vkGetImageMemoryRequirements(context.device, image, &requirements);
    crisp::Result<OwnedMemory> memory = allocate(context, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (!memory) return memory.error();
    out.memory = std::move(*memory);
    if (crisp::Status s = check("vkBindImageMemory", vkBindImageMemory(context.device, image, out.memory.get(), 0));
        !s) {
        return s.error();
    }
    VkImageViewCreateInfo view_info{};
    view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    view_info.image = image;
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = format;
    view_info.subresourceRange = {aspect, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreateImageView", vkCreateImageView(context.device, &view_info, nullptr, &view));
        !s) {
        return s.error();
    }
    out.view = OwnedImageView(context.device, view);
    return out;
}

void record_barrier(VkCommandBuffer command_buffer, const ImageBarrier& b) {
    VkImageMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    barrier.srcAccessMask = b.source_access;
    barrier.dstAccessMask = b.destination_access;
    barrier.oldLayout = b.from;
    barrier.newLayout = b.to;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = b.image;
    barrier.subresourceRange = {b.aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(command_buffer, b.source, b.destination, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

}  // namespace engine
