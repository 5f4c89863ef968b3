// The swapchain and the images sized like it: the engine's HDR scene target, which crisp composites
// text into, and the depth buffer. A resize recreates these and nothing else.
#pragma once

#include "device.hpp"
#include "vk_objects.hpp"

#include <crisp/result.hpp>

#include <volk.h>

#include <cstdint>
#include <vector>

namespace engine {

// The scene's colour target: linear HDR, a colour attachment for the engine's pass and a storage
// image for crisp's tile compositor (record()), which composites into it exactly, per channel.
inline constexpr VkFormat kSceneColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
// Frames the CPU may record while the GPU still works on earlier ones; crisp's renderer and
// compositor are created with the same number.
inline constexpr uint32_t kFramesInFlight = 2;

class Swapchain {
public:
    // A swapchain for the surface's current extent (or `wanted` where the surface leaves it to the
    // application), replacing `old` (may be VK_NULL_HANDLE). It takes an 8-bit _SRGB format, so
    // that the blit from the linear scene target encodes sRGB, and asks for TRANSFER_SRC where
    // offered (screenshots). Errors: no _SRGB surface format that can be a blit destination, a surface that
    // cannot take transfers, a failed Vulkan call.
    static crisp::Result<Swapchain> create(const Device& device, VkExtent2D wanted, VkSwapchainKHR old);

    VkSwapchainKHR handle() const { return swapchain_.get(); }
    VkFormat format() const { return format_; }
    VkExtent2D extent() const { return extent_; }
    bool can_copy_from() const { return can_copy_from_; }
    uint32_t image_count() const { return static_cast<uint32_t>(images_.size()); }
    VkImage image(uint32_t index) const { return images_[index]; }
    // Signalled by the frame that draws image `index`, waited on by its presentation: one per image,
    // since a frame slot's semaphore could still be waited on by an earlier presentation.
    VkSemaphore rendered(uint32_t index) const { return rendered_[index].get(); }
    // The fence of the frame that last drew image `index` (images in flight), or VK_NULL_HANDLE.
    VkFence& image_fence(uint32_t index) { return image_fences_[index]; }

private:
    OwnedSwapchain swapchain_;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkExtent2D extent_{};
    bool can_copy_from_ = false;
    std::vector<VkImage> images_;  // owned by the swapchain
    std::vector<OwnedSemaphore> rendered_;
    std::vector<VkFence> image_fences_;  // not owned: the frame slots' fences
};

// The images the engine renders a frame into, sized like the swapchain.
struct RenderTargets {
    Image color;  // kSceneColorFormat
    Image depth;
};

// The first depth format the device can attach: D32_SFLOAT, X8_D24, D16 (Vulkan guarantees one).
VkFormat choose_depth_format(VkPhysicalDevice physical_device);

// Errors: the device cannot use kSceneColorFormat as a colour attachment, storage image and blit
// source; a failed allocation.
crisp::Result<RenderTargets> create_render_targets(const MemoryContext& context, VkExtent2D extent,
                                                   VkFormat depth_format);

}  // namespace engine
