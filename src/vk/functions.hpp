// Private: every Vulkan function crisp calls, loaded through the caller's vkGetInstanceProcAddr.
//
// crisp is compiled with VK_NO_PROTOTYPES and references no Vulkan symbol: it calls Vulkan only
// through a Functions table that the renderer, the compositor or the headless context fills from a
// vkGetInstanceProcAddr. An engine that loads Vulkan itself (volk, a dynamic dispatcher, a layer
// of its own) hands crisp its own entry point, and crisp then calls exactly what the engine
// calls; without one, crisp opens the system's loader (libvulkan.so.1) on first use.
#pragma once

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

namespace crisp::vk {

// Global commands: callable before an instance exists.
#define CRISP_VK_GLOBAL_FUNCTIONS(X)      \
    X(vkCreateInstance)                   \
    X(vkEnumerateInstanceVersion)         \
    X(vkEnumerateInstanceLayerProperties) \
    X(vkEnumerateInstanceExtensionProperties)

// Instance and physical-device commands.
#define CRISP_VK_INSTANCE_FUNCTIONS(X)          \
    X(vkDestroyInstance)                        \
    X(vkEnumeratePhysicalDevices)               \
    X(vkGetPhysicalDeviceProperties)            \
    X(vkGetPhysicalDeviceProperties2)           \
    X(vkGetPhysicalDeviceFeatures2)             \
    X(vkGetPhysicalDeviceFormatProperties)      \
    X(vkGetPhysicalDeviceImageFormatProperties) \
    X(vkGetPhysicalDeviceMemoryProperties)      \
    X(vkGetPhysicalDeviceQueueFamilyProperties) \
    X(vkEnumerateDeviceExtensionProperties)     \
    X(vkCreateDevice)                           \
    X(vkGetDeviceProcAddr)

// Device commands, loaded through vkGetDeviceProcAddr so that they skip the loader's trampolines.
#define CRISP_VK_DEVICE_FUNCTIONS(X) \
    X(vkDestroyDevice)               \
    X(vkDeviceWaitIdle)              \
    X(vkGetDeviceQueue)              \
    X(vkQueueSubmit)                 \
    X(vkCreateFence)                 \
    X(vkDestroyFence)                \
    X(vkWaitForFences)               \
    X(vkResetFences)                 \
    X(vkCreateCommandPool)           \
    X(vkDestroyCommandPool)          \
    X(vkAllocateCommandBuffers)      \
    X(vkBeginCommandBuffer)          \
    X(vkEndCommandBuffer)            \
    X(vkResetCommandBuffer)          \
    X(vkCreateBuffer)                \
    X(vkDestroyBuffer)               \
    X(vkCreateImage)                 \
    X(vkDestroyImage)                \
    X(vkCreateImageView)             \
    X(vkDestroyImageView)            \
    X(vkGetBufferMemoryRequirements) \
    X(vkGetImageMemoryRequirements)  \
    X(vkAllocateMemory)              \
    X(vkFreeMemory)                  \
    X(vkMapMemory)                   \
    X(vkBindBufferMemory)            \
    X(vkBindImageMemory)             \
    X(vkCreateShaderModule)          \
    X(vkDestroyShaderModule)         \
    X(vkCreateComputePipelines)      \
    X(vkCreateGraphicsPipelines)     \
    X(vkDestroyPipeline)             \
    X(vkCreatePipelineLayout)        \
    X(vkDestroyPipelineLayout)       \
    X(vkCreateDescriptorSetLayout)   \
    X(vkDestroyDescriptorSetLayout)  \
    X(vkCreateDescriptorPool)        \
    X(vkDestroyDescriptorPool)       \
    X(vkAllocateDescriptorSets)      \
    X(vkUpdateDescriptorSets)        \
    X(vkCreateRenderPass)            \
    X(vkDestroyRenderPass)           \
    X(vkCreateFramebuffer)           \
    X(vkDestroyFramebuffer)          \
    X(vkCreateSampler)               \
    X(vkDestroySampler)              \
    X(vkCmdPipelineBarrier)          \
    X(vkCmdBindPipeline)             \
    X(vkCmdBindDescriptorSets)       \
    X(vkCmdPushConstants)            \
    X(vkCmdDispatch)                 \
    X(vkCmdDispatchIndirect)         \
    X(vkCmdDraw)                     \
    X(vkCmdSetViewport)              \
    X(vkCmdSetScissor)               \
    X(vkCmdBeginRenderPass)          \
    X(vkCmdEndRenderPass)            \
    X(vkCmdFillBuffer)               \
    X(vkCmdClearColorImage)          \
    X(vkCmdUpdateBuffer)             \
    X(vkCmdCopyBuffer)               \
    X(vkCmdCopyImage)                \
    X(vkCmdCopyBufferToImage)        \
    X(vkCmdCopyImageToBuffer)

// The table. Members are named as the commands, so that a call reads fn.vkCmdDispatch(...).
struct Functions {
#define CRISP_VK_MEMBER(name) PFN_##name name = nullptr;
    CRISP_VK_GLOBAL_FUNCTIONS(CRISP_VK_MEMBER)
    CRISP_VK_INSTANCE_FUNCTIONS(CRISP_VK_MEMBER)
    CRISP_VK_DEVICE_FUNCTIONS(CRISP_VK_MEMBER)
#undef CRISP_VK_MEMBER
    PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
    // VK_EXT_debug_utils, where the instance enabled it; null otherwise.
    PFN_vkSetDebugUtilsObjectNameEXT vkSetDebugUtilsObjectNameEXT = nullptr;
    // VK_KHR_pipeline_executable_properties, where the device enabled it; null otherwise.
    PFN_vkGetPipelineExecutablePropertiesKHR vkGetPipelineExecutablePropertiesKHR = nullptr;
    PFN_vkGetPipelineExecutableStatisticsKHR vkGetPipelineExecutableStatisticsKHR = nullptr;
};

// The system loader's vkGetInstanceProcAddr (libvulkan.so.1, opened once and kept open); null when
// there is no loader to open.
PFN_vkGetInstanceProcAddr system_get_instance_proc_addr();

// Fills `out` from `get_instance_proc_addr` (null: the system loader's): the global commands
// always, the instance commands where `instance` is not null, the device commands (through
// vkGetDeviceProcAddr) where `device` is not null too. Error vulkan, naming the first command the
// loader does not give, when one is missing, or when there is no loader at all.
Status load_functions(PFN_vkGetInstanceProcAddr get_instance_proc_addr, VkInstance instance, VkDevice device,
                      Functions& out);

}  // namespace crisp::vk
