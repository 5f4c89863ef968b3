// The example engine's Vulkan ownership and the few helpers every part uses. An engine has its own
// version of this file; crisp does not need it and does not provide it.
#pragma once

#include <crisp/result.hpp>

#include <volk.h>

#include <string>
#include <utility>

namespace engine {

// A failed Vulkan call as crisp's error type, so that the engine and crisp report alike:
// crisp::ErrorCode::device_lost for VK_ERROR_DEVICE_LOST, and `result` as its vk_result, as
// crisp's own calls report it.
crisp::Error vulkan_error(const char* call, VkResult result);
// Success, or vulkan_error(call, result).
crisp::Status check(const char* call, VkResult result);

// One object of a device, destroyed with it by `*Destroy` unless moved from (a pointer to volk's
// function pointer, which is loaded at run time). Members of this type are destroyed in reverse
// order of declaration, so declaration order is destruction order.
template <class Handle, void (**Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
class Owned {
public:
    Owned() = default;
    Owned(VkDevice device, Handle handle) : device_(device), handle_(handle) {}
    Owned(Owned&& other) noexcept
        : device_(std::exchange(other.device_, VK_NULL_HANDLE)),
          handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
    Owned& operator=(Owned&& other) noexcept {
        if (this != &other) {
            reset();
            device_ = std::exchange(other.device_, VK_NULL_HANDLE);
            handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }
    Owned(const Owned&) = delete;
    Owned& operator=(const Owned&) = delete;
    ~Owned() { reset(); }

    void reset() {
        if (handle_ != VK_NULL_HANDLE) (*Destroy)(device_, handle_, nullptr);
        handle_ = VK_NULL_HANDLE;
    }
    Handle get() const { return handle_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    Handle handle_ = VK_NULL_HANDLE;
};

using OwnedMemory = Owned<VkDeviceMemory, &vkFreeMemory>;
using OwnedBuffer = Owned<VkBuffer, &vkDestroyBuffer>;
using OwnedImage = Owned<VkImage, &vkDestroyImage>;
using OwnedImageView = Owned<VkImageView, &vkDestroyImageView>;
using OwnedSemaphore = Owned<VkSemaphore, &vkDestroySemaphore>;
using OwnedFence = Owned<VkFence, &vkDestroyFence>;
using OwnedCommandPool = Owned<VkCommandPool, &vkDestroyCommandPool>;
using OwnedShaderModule = Owned<VkShaderModule, &vkDestroyShaderModule>;
using OwnedPipelineLayout = Owned<VkPipelineLayout, &vkDestroyPipelineLayout>;
using OwnedPipeline = Owned<VkPipeline, &vkDestroyPipeline>;
using OwnedSwapchain = Owned<VkSwapchainKHR, &vkDestroySwapchainKHR>;

// A buffer and its memory; `mapped` is its host address when made host-visible.
struct Buffer {
    OwnedMemory memory;  // declared first: freed after the buffer
    OwnedBuffer buffer;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
};

// A 2D image of one level and layer, its memory and a view of all of it.
struct Image {
    OwnedMemory memory;
    OwnedImage image;
    OwnedImageView view;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkExtent2D extent{};
};

// What buffers and images are made from.
struct MemoryContext {
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
};

// A host-visible, coherent, persistently mapped buffer (vertex data, readbacks: small and few).
crisp::Result<Buffer> create_host_buffer(const MemoryContext& context, VkDeviceSize size, VkBufferUsageFlags usage);
// A device-local image with a view of `aspect`.
crisp::Result<Image> create_image(const MemoryContext& context, VkFormat format, VkExtent2D extent,
                                  VkImageUsageFlags usage, VkImageAspectFlags aspect);

// A layout change of a whole single-level, single-layer image, ordering `source_access` at
// `source` stages before `destination_access` at `destination` stages.
struct ImageBarrier {
    VkImage image = VK_NULL_HANDLE;
    VkImageLayout from = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImageLayout to = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags source = VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT;
    VkAccessFlags source_access = 0;
    VkPipelineStageFlags destination = VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT;
    VkAccessFlags destination_access = 0;
    VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
};
void record_barrier(VkCommandBuffer command_buffer, const ImageBarrier& barrier);

}  // namespace engine
