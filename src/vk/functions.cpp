#include "vk/functions.hpp"

#include <string>

#if defined(_WIN32)
#include <windows.h>
#else
#include <dlfcn.h>
#endif

namespace crisp::vk {

PFN_vkGetInstanceProcAddr system_get_instance_proc_addr() {
    // Opened once for the life of the process: function pointers taken from it must stay valid
    // for every crisp object, and a loader is never worth unloading.
    static const PFN_vkGetInstanceProcAddr loader = [] {
#if defined(_WIN32)
        HMODULE library = LoadLibraryA("vulkan-1.dll");
        return library != nullptr ? reinterpret_cast<PFN_vkGetInstanceProcAddr>(
                                        reinterpret_cast<void*>(GetProcAddress(library, "vkGetInstanceProcAddr")))
                                  : nullptr;
#else
        void* library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
        if (library == nullptr) library = dlopen("libvulkan.so", RTLD_NOW | RTLD_LOCAL);
        return library != nullptr ? reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(library, "vkGetInstanceProcAddr"))
                                  : nullptr;
#endif
    }();
    return loader;
}

Status load_functions(PFN_vkGetInstanceProcAddr get_instance_proc_addr, VkInstance instance, VkDevice device,
                      Functions& out) {
    out = {};
    if (get_instance_proc_addr == nullptr) get_instance_proc_addr = system_get_instance_proc_addr();
    if (get_instance_proc_addr == nullptr) {
        return Error{ErrorCode::vulkan,
                     "no Vulkan loader: libvulkan.so.1 cannot be opened and no vkGetInstanceProcAddr was given "
                     "(Debian: apt install libvulkan1)"};
    }
    out.vkGetInstanceProcAddr = get_instance_proc_addr;
    const auto missing = [](const char* name) {
        return Error{ErrorCode::vulkan, std::string("the Vulkan loader gives no ") + name};
    };
#define CRISP_VK_LOAD(name, from, handle)                         \
    out.name = reinterpret_cast<PFN_##name>(from(handle, #name)); \
    if (out.name == nullptr) return missing(#name);
#define CRISP_VK_LOAD_GLOBAL(name) CRISP_VK_LOAD(name, get_instance_proc_addr, VK_NULL_HANDLE)
#define CRISP_VK_LOAD_INSTANCE(name) CRISP_VK_LOAD(name, get_instance_proc_addr, instance)
#define CRISP_VK_LOAD_DEVICE(name) CRISP_VK_LOAD(name, out.vkGetDeviceProcAddr, device)
    CRISP_VK_GLOBAL_FUNCTIONS(CRISP_VK_LOAD_GLOBAL)
    if (instance == VK_NULL_HANDLE) return {};
    CRISP_VK_INSTANCE_FUNCTIONS(CRISP_VK_LOAD_INSTANCE)
    if (device == VK_NULL_HANDLE) return {};
    CRISP_VK_DEVICE_FUNCTIONS(CRISP_VK_LOAD_DEVICE)
#undef CRISP_VK_LOAD_DEVICE
#undef CRISP_VK_LOAD_INSTANCE
#undef CRISP_VK_LOAD_GLOBAL
#undef CRISP_VK_LOAD
    out.vkSetDebugUtilsObjectNameEXT = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        out.vkGetDeviceProcAddr(device, "vkSetDebugUtilsObjectNameEXT"));
    out.vkGetPipelineExecutablePropertiesKHR = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
        out.vkGetDeviceProcAddr(device, "vkGetPipelineExecutablePropertiesKHR"));
    out.vkGetPipelineExecutableStatisticsKHR = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
        out.vkGetDeviceProcAddr(device, "vkGetPipelineExecutableStatisticsKHR"));
    return {};
}

}  // namespace crisp::vk
