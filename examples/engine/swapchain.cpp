#include "swapchain.hpp"

#include <algorithm>

namespace engine {
namespace {

bool has_features(VkPhysicalDevice physical_device, VkFormat format, VkFormatFeatureFlags features) {
    VkFormatProperties properties{};
    vkGetPhysicalDeviceFormatProperties(physical_device, format, &properties);
    return (properties.optimalTilingFeatures & features) == features;
}

// An _SRGB format in the sRGB colour space that the blit can write; UNDEFINED when there is none.
VkSurfaceFormatKHR choose_surface_format(const Device& device) {
    uint32_t count = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(count);
    vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count, formats.data());
    for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_A8B8G8R8_SRGB_PACK32}) {
        for (const VkSurfaceFormatKHR& format : formats) {
            if (format.format == wanted && format.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR &&
                has_features(device.physical_device(), wanted, VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
                return format;
            }
        }
    }
    return {VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
}

VkExtent2D choose_extent(const VkSurfaceCapabilitiesKHR& capabilities, VkExtent2D wanted) {
    if (capabilities.currentExtent.width != UINT32_MAX) return capabilities.currentExtent;
    return {std::clamp(wanted.width, capabilities.minImageExtent.width, capabilities.maxImageExtent.width),
            std::clamp(wanted.height, capabilities.minImageExtent.height, capabilities.maxImageExtent.height)};
}

}  // namespace

crisp::Result<Swapchain> Swapchain::create(const Device& device, VkExtent2D wanted, VkSwapchainKHR old) {
    VkSurfaceCapabilitiesKHR capabilities{};
    if (crisp::Status s =
            check("vkGetPhysicalDeviceSurfaceCapabilitiesKHR",
                  vkGetPhysicalDeviceSurfaceCapabilitiesKHR(device.physical_device(), device.surface(), &capabilities));
        !s) {
        return s.error();
    }
    if (!(capabilities.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        return crisp::Error{crisp::ErrorCode::vulkan, "the surface's images cannot be transfer destinations"};
    }
    const VkSurfaceFormatKHR format = choose_surface_format(device);
    if (format.format == VK_FORMAT_UNDEFINED) {
        return crisp::Error{
            crisp::ErrorCode::vulkan,
            "the surface offers no 8-bit _SRGB format (sRGB colour space) that can be a blit destination"};
    }
    Swapchain out;
    out.format_ = format.format;
    out.extent_ = choose_extent(capabilities, wanted);
    out.can_copy_from_ = (capabilities.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
    uint32_t image_count = capabilities.minImageCount + 1;
    if (capabilities.maxImageCount != 0) image_count = std::min(image_count, capabilities.maxImageCount);

    VkSwapchainCreateInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
    info.surface = device.surface();
    info.minImageCount = image_count;
    info.imageFormat = format.format;
    info.imageColorSpace = format.colorSpace;
    info.imageExtent = out.extent_;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    if (out.can_copy_from_) info.imageUsage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = capabilities.currentTransform;
    info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // the one mode every surface offers
    info.clipped = VK_TRUE;
    info.oldSwapchain = old;
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    if (crisp::Status s =
            check("vkCreateSwapchainKHR", vkCreateSwapchainKHR(device.device(), &info, nullptr, &swapchain));
        !s) {
        return s.error();
    }
    out.swapchain_ = OwnedSwapchain(device.device(), swapchain);
    uint32_t count = 0;
    vkGetSwapchainImagesKHR(device.device(), swapchain, &count, nullptr);
    out.images_.resize(count);
    vkGetSwapchainImagesKHR(device.device(), swapchain, &count, out.images_.data());
    out.image_fences_.assign(count, VK_NULL_HANDLE);
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    for (uint32_t i = 0; i < count; ++i) {
        VkSemaphore semaphore = VK_NULL_HANDLE;
        if (crisp::Status s =
                check("vkCreateSemaphore", vkCreateSemaphore(device.device(), &semaphore_info, nullptr, &semaphore));
            !s) {
            return s.error();
        }
        out.rendered_.emplace_back(device.device(), semaphore);
    }
    return out;
}

VkFormat choose_depth_format(VkPhysicalDevice physical_device) {
    for (VkFormat format : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D16_UNORM}) {
        if (has_features(physical_device, format, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)) return format;
    }
    return VK_FORMAT_D16_UNORM;  // required by the specification as a depth attachment
}

crisp::Result<RenderTargets> create_render_targets(const MemoryContext& context, VkExtent2D extent,
                                                   VkFormat depth_format) {
    const VkFormatFeatureFlags color_features = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                                VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT;
    if (!has_features(context.physical_device, kSceneColorFormat, color_features)) {
        return crisp::Error{crisp::ErrorCode::vulkan,
                            "R16G16B16A16_SFLOAT cannot be a blended colour attachment, storage image and blit source"};
    }
    RenderTargets out;
    crisp::Result<Image> color =
        create_image(context, kSceneColorFormat, extent,
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     VK_IMAGE_ASPECT_COLOR_BIT);
    if (!color) return color.error();
    out.color = std::move(*color);
    crisp::Result<Image> depth = create_image(context, depth_format, extent,
                                              VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
    if (!depth) return depth.error();
    out.depth = std::move(*depth);
    return out;
}

}  // namespace engine
