#include "vulkan_window.hpp"
#include "headless_context.hpp"

#include "vk/resources.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <crisp/device_features.hpp>

#include <cstdio>
#include <cstring>
#include <utility>

namespace crisp::editor {
namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* count = static_cast<std::atomic<uint32_t>*>(user);
    count->fetch_add(1);
    const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    std::fprintf(stderr, "crisp-layout-editor: validation %s: %s\n", level, data->pMessage ? data->pMessage : "");
    return VK_FALSE;
}

bool has_layer(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const VkLayerProperties& layer : layers) {
        if (std::strcmp(layer.layerName, name) == 0) return true;
    }
    return false;
}

}  // namespace

// GLFW's callbacks, turning each into an InputEvent in delivery order.
struct WindowCallbacks {
    static VulkanWindow& owner(GLFWwindow* window) {
        return *static_cast<VulkanWindow*>(glfwGetWindowUserPointer(window));
    }
    static void cursor(GLFWwindow* window, double x, double y) {
        VulkanWindow& self = owner(window);
        self.cursor_x_ = x;
        self.cursor_y_ = y;
        InputEvent event;
        event.kind = InputEvent::Kind::mouse_move;
        event.x = x;
        event.y = y;
        self.events_.push_back(event);
    }
    static void button(GLFWwindow* window, int button, int action, int mods) {
        VulkanWindow& self = owner(window);
        InputEvent event;
        event.kind = action == GLFW_PRESS ? InputEvent::Kind::mouse_down : InputEvent::Kind::mouse_up;
        event.x = self.cursor_x_;
        event.y = self.cursor_y_;
        event.button = button;
        event.mods = mods;
        self.events_.push_back(event);
    }
    static void key(GLFWwindow* window, int key, int, int action, int mods) {
        if (action == GLFW_RELEASE) return;
        VulkanWindow& self = owner(window);
        InputEvent event;
        event.kind = InputEvent::Kind::key;
        event.x = self.cursor_x_;
        event.y = self.cursor_y_;
        event.key = key;
        event.mods = mods;
        self.events_.push_back(event);
    }
    static void character(GLFWwindow* window, unsigned int codepoint) {
        VulkanWindow& self = owner(window);
        InputEvent event;
        event.kind = InputEvent::Kind::character;
        event.x = self.cursor_x_;
        event.y = self.cursor_y_;
        event.codepoint = codepoint;
        self.events_.push_back(event);
    }
};

Result<std::unique_ptr<VulkanWindow>> VulkanWindow::create(const WindowOptions& options) {
    if (!glfwInit())
        return Error{ErrorCode::vulkan, "GLFW could not start (no display? set DISPLAY or run under xvfb-run)"};
    if (!glfwVulkanSupported()) {
        glfwTerminate();
        return Error{ErrorCode::vulkan, "GLFW finds no Vulkan loader with surface support"};
    }
    std::unique_ptr<VulkanWindow> self(new VulkanWindow());
    self->options_ = options;
    if (Status s = self->create_instance(); !s) return s.error();
    if (Status s = self->create_window(); !s) return s.error();
    if (Status s = self->choose_device(); !s) return s.error();
    if (Status s = self->create_device(); !s) return s.error();
    if (Status s = self->create_swapchain(); !s) return s.error();
    return self;
}

// The instance: GLFW's surface extensions, and with validation the layer and a messenger that
// counts its messages (chained into the instance info too, so that instance creation is covered).
Status VulkanWindow::create_instance() {
    uint32_t glfw_count = 0;
    const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
    std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
    std::vector<const char*> layers;
    if (options_.validation) {
        if (!has_layer("VK_LAYER_KHRONOS_validation")) {
            return Error{
                ErrorCode::vulkan,
                "--validation: VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)"};
        }
        layers.push_back("VK_LAYER_KHRONOS_validation");
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "crisp-layout-editor";
    app.apiVersion = VK_API_VERSION_1_3;
    VkDebugUtilsMessengerCreateInfoEXT messenger{};
    messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger.pfnUserCallback = on_validation_message;
    messenger.pUserData = &validation_messages_;
    VkInstanceCreateInfo instance_info{};
    instance_info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    instance_info.pNext = options_.validation ? &messenger : nullptr;
    instance_info.pApplicationInfo = &app;
    instance_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    instance_info.ppEnabledExtensionNames = extensions.data();
    instance_info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    instance_info.ppEnabledLayerNames = layers.data();
    if (VkResult r = vkCreateInstance(&instance_info, nullptr, &instance_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateInstance", r);
    }
    if (!options_.validation) return {};
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!create_messenger) return Error{ErrorCode::vulkan, "vkCreateDebugUtilsMessengerEXT is missing"};
    if (VkResult r = create_messenger(instance_, &messenger, nullptr, &messenger_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateDebugUtilsMessengerEXT", r);
    }
    return {};
}

// The window (fixed size: the editor's widgets sit at fixed positions), its input callbacks and
// its surface.
Status VulkanWindow::create_window() {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    window_ = glfwCreateWindow(static_cast<int>(options_.width), static_cast<int>(options_.height),
                               options_.title.c_str(), nullptr, nullptr);
    if (!window_) return Error{ErrorCode::vulkan, "glfwCreateWindow failed"};
    glfwSetWindowPos(window_, 0, 0);
    glfwSetWindowUserPointer(window_, this);
    glfwSetCursorPosCallback(window_, WindowCallbacks::cursor);
    glfwSetMouseButtonCallback(window_, WindowCallbacks::button);
    glfwSetKeyCallback(window_, WindowCallbacks::key);
    glfwSetCharCallback(window_, WindowCallbacks::character);
    if (VkResult r = glfwCreateWindowSurface(instance_, window_, nullptr, &surface_); r != VK_SUCCESS) {
        return vk::vulkan_error("glfwCreateWindowSurface", r);
    }
    return {};
}

// The device: the first with a queue family that computes, draws and presents, at Vulkan 1.2 or
// later (the renderer's floor).
Status VulkanWindow::choose_device() {
    uint32_t device_count = 0;
    vkEnumeratePhysicalDevices(instance_, &device_count, nullptr);
    std::vector<VkPhysicalDevice> devices(device_count);
    vkEnumeratePhysicalDevices(instance_, &device_count, devices.data());
    std::string rejected;
    for (VkPhysicalDevice candidate : devices) {
        VkPhysicalDeviceProperties properties{};
        vkGetPhysicalDeviceProperties(candidate, &properties);
        if (properties.apiVersion < VK_API_VERSION_1_2) {
            rejected += std::string(properties.deviceName) + ": below Vulkan 1.2; ";
            continue;
        }
        uint32_t family_count = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, nullptr);
        std::vector<VkQueueFamilyProperties> families(family_count);
        vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, families.data());
        for (uint32_t family = 0; family < family_count; ++family) {
            const VkQueueFlags needed = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
            VkBool32 presents = VK_FALSE;
            vkGetPhysicalDeviceSurfaceSupportKHR(candidate, family, surface_, &presents);
            if ((families[family].queueFlags & needed) == needed && presents) {
                physical_device_ = candidate;
                queue_family_ = family;
                timestamp_valid_bits_ = families[family].timestampValidBits;
                break;
            }
        }
        if (physical_device_) break;
        rejected += std::string(properties.deviceName) + ": no queue that computes, draws and presents; ";
    }
    if (!physical_device_) {
        return Error{ErrorCode::vulkan, "no Vulkan device can show the editor: " +
                                            (rejected.empty() ? std::string("no devices") : rejected)};
    }
    vkGetPhysicalDeviceProperties(physical_device_, &properties_);
    vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
    return {};
}

// The device with the swapchain extension and what crisp's renderer and tile path need (and
// B8G8R8A8 storage views where the GPU has them: crisp is then told what it was created with), its
// queue, and the semaphore that orders rendering after image acquisition.
Status VulkanWindow::create_device() {
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = queue_family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    features_ = VkPhysicalDeviceFeatures2{};
    features_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    if (Status s = add_crisp_features(instance_, physical_device_, features_, {.storage_without_format = true}); !s) {
        return s.error();
    }
    storage_without_format_ = features_.features.shaderStorageImageWriteWithoutFormat == VK_TRUE;
    const char* device_extensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    VkDeviceCreateInfo device_info{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.pNext = &features_;
    device_info.enabledExtensionCount = 1;
    device_info.ppEnabledExtensionNames = device_extensions;
    if (VkResult r = vkCreateDevice(physical_device_, &device_info, nullptr, &device_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateDevice", r);
    }
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    if (VkResult r = vkCreateSemaphore(device_, &semaphore_info, nullptr, &image_ready_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateSemaphore", r);
    }
    return {};
}

Status VulkanWindow::create_swapchain() {
    VkSurfaceCapabilitiesKHR capabilities{};
    vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_device_, surface_, &capabilities);
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;  // the canvas is blitted in
    if ((capabilities.supportedUsageFlags & usage) != usage) {
        return Error{ErrorCode::vulkan, "the surface's images cannot be transfer destinations"};
    }
    uint32_t format_count = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_device_, surface_, &format_count, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(format_count);
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_device_, surface_, &format_count, formats.data());
    // The canvas holds sRGB-encoded bytes: a UNORM swapchain shows them as they are.
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (const VkSurfaceFormatKHR& format : formats) {
        if ((format.format == VK_FORMAT_B8G8R8A8_UNORM || format.format == VK_FORMAT_R8G8B8A8_UNORM) &&
            format.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) {
            chosen = format;
            break;
        }
    }
    if (chosen.format == VK_FORMAT_UNDEFINED)
        return Error{ErrorCode::vulkan, "the surface offers no 8-bit UNORM format"};
    VkFormatProperties format_properties{};
    vkGetPhysicalDeviceFormatProperties(physical_device_, chosen.format, &format_properties);
    if (!(format_properties.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
        return Error{ErrorCode::vulkan, "the swapchain format cannot be a blit destination"};
    }
    swapchain_format_ = chosen.format;
    VkExtent2D extent = capabilities.currentExtent;
    if (extent.width == UINT32_MAX) extent = {options_.width, options_.height};
    uint32_t image_count = capabilities.minImageCount + 1;
    if (capabilities.maxImageCount != 0 && image_count > capabilities.maxImageCount)
        image_count = capabilities.maxImageCount;

    VkSwapchainCreateInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
    info.surface = surface_;
    info.minImageCount = image_count;
    info.imageFormat = chosen.format;
    info.imageColorSpace = chosen.colorSpace;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = usage;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = capabilities.currentTransform;
    info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always offered
    info.clipped = VK_TRUE;
    info.oldSwapchain = swapchain_;
    VkSwapchainKHR created = VK_NULL_HANDLE;
    if (VkResult r = vkCreateSwapchainKHR(device_, &info, nullptr, &created); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateSwapchainKHR", r);
    }
    destroy_swapchain();
    swapchain_ = created;
    uint32_t count = 0;
    vkGetSwapchainImagesKHR(device_, swapchain_, &count, nullptr);
    swapchain_images_.resize(count);
    vkGetSwapchainImagesKHR(device_, swapchain_, &count, swapchain_images_.data());
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    rendered_.assign(count, VK_NULL_HANDLE);
    for (VkSemaphore& semaphore : rendered_) {
        if (VkResult r = vkCreateSemaphore(device_, &semaphore_info, nullptr, &semaphore); r != VK_SUCCESS) {
            return vk::vulkan_error("vkCreateSemaphore", r);
        }
    }
    return {};
}

void VulkanWindow::destroy_swapchain() {
    if (!device_) return;
    vkDeviceWaitIdle(device_);
    for (VkSemaphore semaphore : rendered_) {
        if (semaphore) vkDestroySemaphore(device_, semaphore, nullptr);
    }
    rendered_.clear();
    swapchain_images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(device_, swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
}

VulkanWindow::~VulkanWindow() {
    destroy_swapchain();
    if (device_) {
        if (image_ready_) vkDestroySemaphore(device_, image_ready_, nullptr);
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
    glfwTerminate();
}

bool VulkanWindow::should_close() const {
    return glfwWindowShouldClose(window_) != 0;
}

std::vector<InputEvent> VulkanWindow::poll_events() {
    glfwPollEvents();
    return std::exchange(events_, {});
}

Result<VulkanWindow::Acquired> VulkanWindow::acquire() {
    Acquired acquired;
    const VkResult r =
        vkAcquireNextImageKHR(device_, swapchain_, UINT64_MAX, image_ready_, VK_NULL_HANDLE, &acquired.index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
        if (Status status = create_swapchain(); !status) return status.error();
        return acquired;
    }
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) return vk::vulkan_error("vkAcquireNextImageKHR", r);
    acquired.image = swapchain_images_[acquired.index];
    acquired.ready = image_ready_;
    acquired.rendered = rendered_[acquired.index];
    return acquired;
}

Status VulkanWindow::present(const Acquired& acquired) {
    VkPresentInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
    info.waitSemaphoreCount = 1;
    info.pWaitSemaphores = &acquired.rendered;
    info.swapchainCount = 1;
    info.pSwapchains = &swapchain_;
    info.pImageIndices = &acquired.index;
    const VkResult r = vkQueuePresentKHR(queue_, &info);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return create_swapchain();
    if (r != VK_SUCCESS) return vk::vulkan_error("vkQueuePresentKHR", r);
    return {};
}

}  // namespace crisp::editor
