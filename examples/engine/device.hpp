// The example engine's window and Vulkan device: a GLFW window, an instance (with the validation
// layer and synchronization validation when asked), a surface, and a device created with what the
// engine needs plus what crisp needs (crisp::add_crisp_features), one queue that draws, computes
// and presents.
#pragma once

#include "vk_objects.hpp"

#include <crisp/result.hpp>

#include <volk.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

struct GLFWwindow;

namespace engine {

struct DeviceOptions {
    uint32_t width = 960;
    uint32_t height = 540;
    bool validation = false;  // VK_LAYER_KHRONOS_validation with synchronization validation
    // Counts the layer's warnings and errors, those of the device's and instance's destruction
    // included: it must outlive the Device. Required with validation.
    std::atomic<uint32_t>* message_count = nullptr;
};

// Not movable: the validation callback, GLFW and the feature chain point into it.
class Device {
public:
    // Errors (crisp::ErrorCode::vulkan): no display, no Vulkan loader or device that can present
    // to the window, the validation layer asked for and missing, no device with Vulkan 1.3,
    // dynamicRendering and what crisp needs (the message names each device and what it lacks).
    static crisp::Result<std::unique_ptr<Device>> create(const DeviceOptions& options);
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;
    // Waits for the device to go idle, then destroys the device, surface, window and instance.
    // Every object made from the device must be gone by then.
    ~Device();

    GLFWwindow* window() const { return window_; }
    VkInstance instance() const { return instance_; }
    // The VkApplicationInfo::apiVersion the instance is created with: crisp checks it.
    static constexpr uint32_t kInstanceApiVersion = VK_API_VERSION_1_3;
    VkPhysicalDevice physical_device() const { return physical_device_; }
    VkDevice device() const { return device_; }
    VkSurfaceKHR surface() const { return surface_; }
    uint32_t queue_family() const { return queue_family_; }
    VkQueue queue() const { return queue_; }
    MemoryContext memory() const { return {physical_device_, device_}; }
    // The feature chain vkCreateDevice was given: crisp checks its needs against it.
    const VkPhysicalDeviceFeatures2* enabled_features() const { return &features_; }

private:
    Device() = default;
    crisp::Status create_instance(bool validation, std::atomic<uint32_t>* message_count);
    crisp::Status create_window(const DeviceOptions& options);
    crisp::Status pick_physical_device();
    crisp::Status create_device();

    GLFWwindow* window_ = nullptr;
    bool glfw_started_ = false;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
    uint32_t queue_family_ = 0;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkPhysicalDeviceVulkan13Features vulkan13_{};
    VkPhysicalDeviceFeatures2 features_{};
};

}  // namespace engine
