// Private: what the renderer and the compositor each make of the caller's device before any of
// their parts: the function table, the memory arena, the DeviceRef every part is made from, the
// features the device was created with and the physical device's properties.
#pragma once

#include "vk/features.hpp"
#include "vk/functions.hpp"
#include "vk/memory.hpp"
#include "vk/resources.hpp"

#include <crisp/device_features.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace crisp::vk {

// The caller's objects (RendererCreateInfo, CompositorCreateInfo) and who asks.
struct ContextCreateInfo {
    VkInstance instance = VK_NULL_HANDLE;
    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;  // null: the system loader's
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    const VkAllocationCallbacks* allocator = nullptr;
    VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
    const VkPhysicalDeviceFeatures2* enabled_features = nullptr;  // the chain the device was created with
    uint32_t min_api_version = 0;  // the device must offer at least this Vulkan version; 0: any
    const char* who = "";          // "renderer", "compositor": what every message starts with
};

// invalid_argument, from `who`, unless `instance_api_version` (what the caller's instance was
// created with) is at least Vulkan 1.2, the version crisp's SPIR-V is built for.
Status check_instance_version(uint32_t instance_api_version, const char* who);

// Heap-held and never moved: `ref` points at `fn` and `arena`, and every part made from `ref`
// points at it. Declared first in its owner's state, so that it is destroyed last.
class Context {
public:
    // Loads the functions, reads the device's properties (below min_api_version: error vulkan) and
    // the features it was created with (read_enabled_features), in that order; the first failure
    // is returned, its message starting with `who`.
    static Result<std::unique_ptr<Context>> create(const ContextCreateInfo& info);

    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    ~Context();

    const Functions fn;  // the caller's Vulkan entry points (get_instance_proc_addr)
    const VkPhysicalDeviceProperties properties;
    const DeviceFeatures enabled;                    // what the device was created with
    std::vector<ShaderStatistic> shader_statistics;  // the driver's, where the device enabled them
    DeviceRef ref;      // device, allocator, memory properties, pipeline cache, debug names, arena, statistics
    MemoryArena arena;  // every buffer's memory

private:
    Context(const Functions& functions, const VkPhysicalDeviceProperties& device_properties,
            const DeviceFeatures& features, const ContextCreateInfo& info);
};

}  // namespace crisp::vk
