// Vulkan 1.0-1.3 device features, field by field: copying a caller's required-feature chain,
// comparing it with what a device offers and naming what is missing.
#pragma once

#include "vk/functions.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

namespace crisp::vk {

// One of each core feature structure in fixed storage, so that a caller's pNext chain (in any
// order, with any subset of the structures) can be compared member by member with what a device
// offers, and turned back into a chain for vkCreateDevice.
struct DeviceFeatures {
    VkPhysicalDeviceFeatures2 features2;  // .features holds the Vulkan 1.0 features
    VkPhysicalDeviceVulkan11Features vulkan11;
    VkPhysicalDeviceVulkan12Features vulkan12;
    VkPhysicalDeviceVulkan13Features vulkan13;
    // VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR::pipelineExecutableInfo, read from an
    // enabled chain only (read_enabled_features); never linked.
    bool pipeline_executable_info = false;

    DeviceFeatures();  // all false, sTypes set, not linked

    // Chains features2 -> vulkan11 -> vulkan12 (-> vulkan13) and returns &features2. The pointers
    // point into this object, so a copy must be linked again before use.
    VkPhysicalDeviceFeatures2* link(bool with_vulkan13);
    bool any_vulkan13() const;
};

// Copies the structures of a required-feature chain (null: nothing required). invalid_argument
// for a structure other than the Vulkan 1.1/1.2/1.3 feature structures, a structure given twice,
// or Vulkan 1.3 features asked for with an api_version below 1.3.
Result<DeviceFeatures> copy_required_features(const VkPhysicalDeviceFeatures2* chain, uint32_t api_version);

// The features a device was created with, read from the chain its VkDeviceCreateInfo held (it
// starts with a VkPhysicalDeviceFeatures2): the Vulkan 1.1/1.2/1.3 feature structures and
// VkPhysicalDeviceDynamicRenderingFeatures are read, any other structure is skipped (an engine's
// chain holds extension structures too). invalid_argument for a null chain or one that does not
// start with a VkPhysicalDeviceFeatures2; `who` names the caller in the message.
Result<DeviceFeatures> read_enabled_features(const VkPhysicalDeviceFeatures2* chain, const char* who);

// The features `device` offers. Vulkan 1.3 features are queried only when with_vulkan13 (the
// instance and the device are both 1.3 or newer); otherwise they read as absent.
DeviceFeatures query_features(const Functions& fn, VkPhysicalDevice device, bool with_vulkan13);

// The names of the features `required` asks for and `offered` lacks ("shaderBufferInt64Atomics"),
// in declaration order.
std::vector<std::string> missing_features(const DeviceFeatures& required, const DeviceFeatures& offered);

}  // namespace crisp::vk
