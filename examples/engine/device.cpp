#include "device.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <crisp/device_features.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace engine {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    static_cast<std::atomic<uint32_t>*>(user)->fetch_add(1);
    const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    std::fprintf(stderr, "crisp-engine-example: validation %s: %s\n", level,
                 data && data->pMessage ? data->pMessage : "");
    return VK_FALSE;  // the spec reserves VK_TRUE for layer development
}

bool has_layer(const char* name) {
    uint32_t count = 0;
    if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
    std::vector<VkLayerProperties> layers(count);
    if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
    for (const VkLayerProperties& layer : layers) {
        if (std::strcmp(layer.layerName, name) == 0) return true;
    }
    return false;
}

bool has_device_extension(VkPhysicalDevice device, const char* name) {
    uint32_t count = 0;
    if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) return false;
    std::vector<VkExtensionProperties> extensions(count);
    if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data()) != VK_SUCCESS) return false;
    for (const VkExtensionProperties& extension : extensions) {
        if (std::strcmp(extension.extensionName, name) == 0) return true;
    }
    return false;
}

// The first queue family that draws, computes and presents to `surface`.
std::optional<uint32_t> find_queue_family(VkPhysicalDevice device, VkSurfaceKHR surface) {
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    for (uint32_t family = 0; family < count; ++family) {
        const VkQueueFlags needed = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        VkBool32 presents = VK_FALSE;
        vkGetPhysicalDeviceSurfaceSupportKHR(device, family, surface, &presents);
        if ((families[family].queueFlags & needed) == needed && presents) return family;
    }
    return std::nullopt;
}

// Why `device` cannot run the example; empty when it can.
std::string unsuitability(VkInstance instance, VkPhysicalDevice device, VkSurfaceKHR surface) {
    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(device, &properties);
    if (properties.apiVersion < VK_API_VERSION_1_3) return "below Vulkan 1.3";
    if (!has_device_extension(device, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) return "no VK_KHR_swapchain";
    if (!find_queue_family(device, surface)) return "no queue family that draws, computes and presents";
    VkPhysicalDeviceVulkan13Features vulkan13{};
    vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    VkPhysicalDeviceFeatures2 offered{};
    offered.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    offered.pNext = &vulkan13;
    vkGetPhysicalDeviceFeatures2(device, &offered);
    if (!vulkan13.dynamicRendering) return "no dynamicRendering";
    // crisp's own check, on a scratch chain: it names the feature the GPU lacks.
    VkPhysicalDeviceFeatures2 scratch{};
    scratch.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    if (crisp::Status s = crisp::add_crisp_features(instance, device, scratch, {}, vkGetInstanceProcAddr); !s)
        return s.error().message;
    return {};
}

}  // namespace

crisp::Result<std::unique_ptr<Device>> Device::create(const DeviceOptions& options) {
    std::unique_ptr<Device> self(new Device());
    if (!glfwInit()) {
        return crisp::Error{crisp::ErrorCode::vulkan, "GLFW could not start (no display? set DISPLAY or use xvfb-run)"};
    }
    self->glfw_started_ = true;
    // The engine loads Vulkan itself; crisp is handed the same entry point (vkGetInstanceProcAddr).
    if (VkResult r = volkInitialize(); r != VK_SUCCESS) {
        return crisp::Error{crisp::ErrorCode::vulkan, "volk finds no Vulkan loader (Debian: libvulkan1)"};
    }
    if (!glfwVulkanSupported()) {
        return crisp::Error{crisp::ErrorCode::vulkan, "GLFW finds no Vulkan loader with surface support"};
    }
    crisp::Status status = self->create_instance(options.validation, options.message_count);
    if (status) status = self->create_window(options);
    if (status) status = self->pick_physical_device();
    if (status) status = self->create_device();
    if (!status) return status.error();
    return self;
}

crisp::Status Device::create_instance(bool validation, std::atomic<uint32_t>* message_count) {
    uint32_t glfw_count = 0;
    const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
    if (!glfw_extensions) return crisp::Error{crisp::ErrorCode::vulkan, "GLFW knows no Vulkan surface extensions"};
    std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
    std::vector<const char*> layers;
    if (validation) {
        if (!message_count) return crisp::Error{crisp::ErrorCode::invalid_argument, "validation needs a message count"};
        if (!has_layer(kValidationLayer)) {
            return crisp::Error{
                crisp::ErrorCode::vulkan,
                "--validation: VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)"};
        }
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);  // the layer provides it
    }
    // Synchronization validation checks every barrier crisp and the engine record.
    const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    VkDebugUtilsMessengerCreateInfoEXT messenger{};
    messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger.pNext = &features;
    messenger.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger.pfnUserCallback = on_validation_message;
    messenger.pUserData = message_count;

    VkApplicationInfo application{};
    application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    application.pApplicationName = "crisp-engine-example";
    application.apiVersion = kInstanceApiVersion;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pNext = validation ? &messenger : nullptr;  // so that instance creation is reported too
    info.pApplicationInfo = &application;
    info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    if (crisp::Status s = check("vkCreateInstance", vkCreateInstance(&info, nullptr, &instance_)); !s) return s;
    volkLoadInstance(instance_);
    if (!validation) return {};
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!create_messenger) return crisp::Error{crisp::ErrorCode::vulkan, "vkCreateDebugUtilsMessengerEXT is missing"};
    messenger.pNext = nullptr;
    return check("vkCreateDebugUtilsMessengerEXT", create_messenger(instance_, &messenger, nullptr, &messenger_));
}

crisp::Status Device::create_window(const DeviceOptions& options) {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    window_ = glfwCreateWindow(static_cast<int>(options.width), static_cast<int>(options.height),
                               "crisp engine example", nullptr, nullptr);
    if (!window_) return crisp::Error{crisp::ErrorCode::vulkan, "glfwCreateWindow failed"};
    return check("glfwCreateWindowSurface", glfwCreateWindowSurface(instance_, window_, nullptr, &surface_));
}

crisp::Status Device::pick_physical_device() {
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
    // A GPU of its own first, then an integrated one, then the rest (lavapipe is a CPU).
    auto rank = [](VkPhysicalDevice device) {
        VkPhysicalDeviceProperties properties{};
        vkGetPhysicalDeviceProperties(device, &properties);
        switch (properties.deviceType) {
            case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
                return 0;
            case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
                return 1;
            default:
                return 2;
        }
    };
    std::stable_sort(devices.begin(), devices.end(), [&](auto a, auto b) { return rank(a) < rank(b); });
    std::string rejected;
    for (VkPhysicalDevice candidate : devices) {
        const std::string why = unsuitability(instance_, candidate, surface_);
        if (why.empty()) {
            physical_device_ = candidate;
            queue_family_ = *find_queue_family(candidate, surface_);
            return {};
        }
        VkPhysicalDeviceProperties properties{};
        vkGetPhysicalDeviceProperties(candidate, &properties);
        rejected += std::string(rejected.empty() ? "" : "; ") + properties.deviceName + ": " + why;
    }
    return crisp::Error{crisp::ErrorCode::vulkan, "no Vulkan device can run the example: " +
                                                      (rejected.empty() ? std::string("no devices") : rejected)};
}

crisp::Status Device::create_device() {
    // The engine's own needs first (dynamic rendering for its passes), then crisp's, in the same
    // chain; crisp reads this very chain back through enabled_features().
    vulkan13_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    vulkan13_.dynamicRendering = VK_TRUE;
    features_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features_.pNext = &vulkan13_;
    if (crisp::Status s = crisp::add_crisp_features(instance_, physical_device_, features_, {}, vkGetInstanceProcAddr);
        !s)
        return s;

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue{};
    queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue.queueFamilyIndex = queue_family_;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    const char* extensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    VkDeviceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    info.pNext = &features_;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
    if (crisp::Status s = check("vkCreateDevice", vkCreateDevice(physical_device_, &info, nullptr, &device_)); !s)
        return s;
    volkLoadDevice(device_);  // the device's functions, without the loader's dispatch
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
    return {};
}

Device::~Device() {
    if (device_) {
        vkDeviceWaitIdle(device_);  // a lost device returns an error here; destroying is still valid
        vkDestroyDevice(device_, nullptr);
    }
    if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
    if (window_) glfwDestroyWindow(window_);
    if (messenger_) {
        auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy_messenger) destroy_messenger(instance_, messenger_, nullptr);
    }
    if (instance_) vkDestroyInstance(instance_, nullptr);
    if (glfw_started_) glfwTerminate();
}

}  // namespace engine
