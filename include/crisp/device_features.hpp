// crisp: the Vulkan device features crisp's parts need, for an engine that creates its own device.
//
// crisp checks what the device was created with (RendererCreateInfo::enabled_features,
// CompositorCreateInfo::enabled_features), never what the GPU merely offers. Before vkCreateDevice,
// add_crisp_features() turns on what the parts an engine uses need in the chain it passes:
//
//     VkPhysicalDeviceVulkan13Features vulkan13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
//     VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &vulkan13};
//     ... the engine's own features ...
//     crisp::add_crisp_features(instance, physical_device, features, {.draw_path = true});
//     device_info.pNext = &features;                    // then vkCreateDevice
//     renderer_info.enabled_features = &features;       // and the same chain for crisp
#pragma once

#include <crisp/export.hpp>

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <string>

namespace crisp {

// The parts of crisp a device is made for. The renderer and the compositor's tile path are always
// counted in.
struct CrispFeatureNeeds {
    bool draw_path = false;        // Compositor::record_draw: dynamicRendering, dualSrcBlend
    bool reference_modes = false;  // Compositor::record_reference: fragmentStoresAndAtomics, dualSrcBlend
    // B8G8R8A8_UNORM storage views for the tile path: shaderStorageImageRead/WriteWithoutFormat,
    // turned on only where the GPU offers both (they are optional: the tile path works without).
    bool storage_without_format = false;
};

// Sets, in `features` and in the VkPhysicalDeviceVulkan13Features or
// VkPhysicalDeviceDynamicRenderingFeatures of its pNext chain, every feature `needs` asks for,
// leaving whatever else the chain enables as it is; it never allocates into the chain. Errors:
// invalid_argument when `features` is not a VkPhysicalDeviceFeatures2, or the draw path is asked
// for and the chain holds no structure with dynamicRendering (link a
// VkPhysicalDeviceVulkan13Features), or `instance` or `physical_device` is null; vulkan when the
// GPU lacks a required feature (named), or the loader gives no function crisp queries with, in
// which case `features` is unchanged. The GPU is queried through `get_instance_proc_addr` (null:
// the system loader's), as RendererCreateInfo::get_instance_proc_addr.
CRISP_API Status add_crisp_features(VkInstance instance, VkPhysicalDevice physical_device,
                                    VkPhysicalDeviceFeatures2& features, const CrispFeatureNeeds& needs = {},
                                    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr);

// One statistic of one of crisp's compiled shaders as the driver reports it through
// VK_KHR_pipeline_executable_properties: registers, spills, shared memory, instruction counts,
// whatever the driver names. Renderer::shader_statistics() and Compositor::shader_statistics()
// return them when the device was created with that extension and its pipelineExecutableInfo
// feature, and RendererCreateInfo::enabled_features / CompositorCreateInfo::enabled_features
// chain the VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR that enabled it; otherwise
// none (nothing else changes: the pipelines are the same).
struct ShaderStatistic {
    std::string shader;       // crisp's name for the pipeline, "raster.comp"
    std::string executable;   // the driver's name for one compiled stage of it
    std::string name;         // the driver's name for the statistic, "Register Count"
    std::string description;  // the driver's description of it
    double value = 0.0;       // booleans as 0 and 1, integers exactly up to 2^53
};

// "VK_ERROR_DEVICE_LOST", for messages; "VkResult -13" for a code this build does not know.
CRISP_API std::string vk_result_name(VkResult result);

}  // namespace crisp
