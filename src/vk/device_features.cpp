#include <crisp/device_features.hpp>

#include "vk/functions.hpp"

#include <string>

namespace crisp {

namespace {

// The dynamicRendering member of whichever structure of the chain holds one, or null.
VkBool32* find_dynamic_rendering(VkPhysicalDeviceFeatures2& features) {
    for (auto* next = static_cast<VkBaseOutStructure*>(features.pNext); next != nullptr; next = next->pNext) {
        if (next->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES)
            return &reinterpret_cast<VkPhysicalDeviceVulkan13Features*>(next)->dynamicRendering;
        if (next->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES)
            return &reinterpret_cast<VkPhysicalDeviceDynamicRenderingFeatures*>(next)->dynamicRendering;
    }
    return nullptr;
}

}  // namespace

Status add_crisp_features(VkInstance instance, VkPhysicalDevice physical_device, VkPhysicalDeviceFeatures2& features,
                          const CrispFeatureNeeds& needs, PFN_vkGetInstanceProcAddr get_instance_proc_addr) {
    if (instance == VK_NULL_HANDLE || physical_device == VK_NULL_HANDLE) {
        return Error{ErrorCode::invalid_argument, "add_crisp_features: an instance and a physical device are required"};
    }
    if (features.sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
        return Error{ErrorCode::invalid_argument, "add_crisp_features: `features` is not a VkPhysicalDeviceFeatures2"};
    }
    VkBool32* dynamic_rendering = find_dynamic_rendering(features);
    if (needs.draw_path && dynamic_rendering == nullptr) {
        return Error{
            ErrorCode::invalid_argument,
            "add_crisp_features: the draw path needs dynamicRendering; link a VkPhysicalDeviceVulkan13Features "
            "(or VkPhysicalDeviceDynamicRenderingFeatures) into the chain"};
    }

    vk::Functions fn;
    if (Status s = vk::load_functions(get_instance_proc_addr, instance, VK_NULL_HANDLE, fn); !s) {
        return Error{s.error().code, "add_crisp_features: " + s.error().message};
    }

    // What the GPU offers, to refuse before changing anything.
    VkPhysicalDeviceVulkan13Features offered13{};
    offered13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    VkPhysicalDeviceFeatures2 offered{};
    offered.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    VkPhysicalDeviceProperties properties{};
    fn.vkGetPhysicalDeviceProperties(physical_device, &properties);
    if (needs.draw_path && properties.apiVersion >= VK_API_VERSION_1_3) offered.pNext = &offered13;
    fn.vkGetPhysicalDeviceFeatures2(physical_device, &offered);
    const VkPhysicalDeviceFeatures& has = offered.features;
    const auto lacks = [&](const char* feature) {
        return Error{ErrorCode::vulkan,
                     std::string("add_crisp_features: ") + properties.deviceName + " lacks " + feature};
    };
    if (!has.shaderStorageBufferArrayDynamicIndexing) return lacks("shaderStorageBufferArrayDynamicIndexing");
    if ((needs.draw_path || needs.reference_modes) && !has.dualSrcBlend) return lacks("dualSrcBlend");
    if (needs.reference_modes && !has.fragmentStoresAndAtomics) return lacks("fragmentStoresAndAtomics");
    if (needs.draw_path && !offered13.dynamicRendering) return lacks("dynamicRendering (Vulkan 1.3)");

    VkPhysicalDeviceFeatures& wanted = features.features;
    wanted.shaderStorageBufferArrayDynamicIndexing = VK_TRUE;
    if (needs.draw_path || needs.reference_modes) wanted.dualSrcBlend = VK_TRUE;
    if (needs.reference_modes) wanted.fragmentStoresAndAtomics = VK_TRUE;
    if (needs.draw_path) *dynamic_rendering = VK_TRUE;
    if (needs.storage_without_format && has.shaderStorageImageReadWithoutFormat &&
        has.shaderStorageImageWriteWithoutFormat) {
        wanted.shaderStorageImageReadWithoutFormat = VK_TRUE;
        wanted.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    }
    return {};
}

}  // namespace crisp
