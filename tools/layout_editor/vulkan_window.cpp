#include "vulkan_window.hpp"

#include "vk/resources.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <crisp/device_features.hpp>

#include <algorithm>
#include <utility>
#include <vector>

namespace crisp::editor {

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
    static void framebuffer_size(GLFWwindow* window, int, int) { owner(window).resized_ = true; }
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
// logs its messages (which also covers instance creation).
Status VulkanWindow::create_instance() {
    uint32_t glfw_count = 0;
    const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
    InstanceOptions instance_options;
    instance_options.application_name = "crisp-layout-editor";
    instance_options.api_version = VK_API_VERSION_1_3;
    instance_options.minimum_version = VK_API_VERSION_1_2;  // the renderer's floor
    instance_options.extensions.assign(glfw_extensions, glfw_extensions + glfw_count);
    instance_options.validation = options_.validation;
    instance_options.validation_log = &validation_log_;
    // The loader GLFW and the editor's own calls use.
    instance_options.get_instance_proc_addr = vkGetInstanceProcAddr;
    Result<VulkanInstance> created = VulkanInstance::create(instance_options);
    if (!created) return created.error();
    instance_ = std::move(*created);
    return {};
}

// The window (resizable: the editor lays its widgets out for the size), its input callbacks and
// its surface.
Status VulkanWindow::create_window() {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    int width = static_cast<int>(options_.width), height = static_cast<int>(options_.height);
    if (GLFWmonitor* monitor = glfwGetPrimaryMonitor(); options_.fit_to_monitor && monitor) {
        float scale_x = 1.0f, scale_y = 1.0f;
        glfwGetMonitorContentScale(monitor, &scale_x, &scale_y);
        int area_x = 0, area_y = 0, area_width = 0, area_height = 0;
        glfwGetMonitorWorkarea(monitor, &area_x, &area_y, &area_width, &area_height);
        width = static_cast<int>(static_cast<float>(width) * std::max(scale_x, 1.0f));
        height = static_cast<int>(static_cast<float>(height) * std::max(scale_y, 1.0f));
        if (area_width > 0) width = std::min(width, area_width);
        if (area_height > 0) height = std::min(height, area_height);
    }
    window_ = glfwCreateWindow(width, height, options_.title.c_str(), nullptr, nullptr);
    if (!window_) return Error{ErrorCode::vulkan, "glfwCreateWindow failed"};
    glfwSetWindowPos(window_, 0, 0);
    glfwSetWindowUserPointer(window_, this);
    glfwSetCursorPosCallback(window_, WindowCallbacks::cursor);
    glfwSetMouseButtonCallback(window_, WindowCallbacks::button);
    glfwSetKeyCallback(window_, WindowCallbacks::key);
    glfwSetCharCallback(window_, WindowCallbacks::character);
    glfwSetFramebufferSizeCallback(window_, WindowCallbacks::framebuffer_size);
    if (VkResult r = glfwCreateWindowSurface(instance(), window_, nullptr, &surface_); r != VK_SUCCESS) {
        return vk::vulkan_error("glfwCreateWindowSurface", r);
    }
    return {};
}

// The device: one at Vulkan 1.2 or later (the renderer's floor) with the swapchain extension, what
// crisp's renderer and tile path need (and B8G8R8A8 storage views where the GPU has them: crisp is
// then told what it was created with), and a queue family that computes, draws and presents.
Status VulkanWindow::choose_device() {
    DeviceRequirements requirements;
    requirements.required_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    requirements.crisp_needs = CrispFeatureNeeds{.storage_without_format = true};
    requirements.queue_family_check = [this](VkPhysicalDevice candidate, uint32_t family) {
        VkBool32 presents = VK_FALSE;
        vkGetPhysicalDeviceSurfaceSupportKHR(candidate, family, surface_, &presents);
        return presents == VK_TRUE;
    };
    requirements.queue_family_check_name = "presents to the window's surface";
    Result<PhysicalDevice> chosen = choose_physical_device(instance_, requirements);
    if (!chosen) return chosen.error();
    physical_ = std::move(*chosen);
    return {};
}

// The device, its queue, and the semaphore that orders rendering after image acquisition.
Status VulkanWindow::create_device() {
    Result<VulkanDevice> created = VulkanDevice::create(instance_, physical_);
    if (!created) return created.error();
    device_ = std::move(*created);
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    if (VkResult r = vkCreateSemaphore(device(), &semaphore_info, nullptr, &image_ready_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateSemaphore", r);
    }
    return {};
}

Status VulkanWindow::create_swapchain() {
    VkSurfaceCapabilitiesKHR capabilities{};
    vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_.handle, surface_, &capabilities);
    resized_ = false;
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;  // the canvas is blitted in
    if ((capabilities.supportedUsageFlags & usage) != usage) {
        return Error{ErrorCode::vulkan, "the surface's images cannot be transfer destinations"};
    }
    uint32_t format_count = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_.handle, surface_, &format_count, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(format_count);
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical_.handle, surface_, &format_count, formats.data());
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
    vkGetPhysicalDeviceFormatProperties(physical_.handle, chosen.format, &format_properties);
    if (!(format_properties.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
        return Error{ErrorCode::vulkan, "the swapchain format cannot be a blit destination"};
    }
    swapchain_format_ = chosen.format;
    VkExtent2D extent = capabilities.currentExtent;
    if (extent.width == UINT32_MAX) {
        // The surface takes the swapchain's size: the framebuffer's, within the surface's limits.
        int width = 0, height = 0;
        glfwGetFramebufferSize(window_, &width, &height);
        extent.width = std::clamp(static_cast<uint32_t>(std::max(width, 1)), capabilities.minImageExtent.width,
                                  capabilities.maxImageExtent.width);
        extent.height = std::clamp(static_cast<uint32_t>(std::max(height, 1)), capabilities.minImageExtent.height,
                                   capabilities.maxImageExtent.height);
    }
    // A minimized window has no area: the swapchain stays as it is until it has one again.
    if (extent.width == 0 || extent.height == 0) {
        resized_ = true;
        return {};
    }
    extent_ = extent;
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
    if (VkResult r = vkCreateSwapchainKHR(device(), &info, nullptr, &created); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateSwapchainKHR", r);
    }
    destroy_swapchain();
    swapchain_ = created;
    uint32_t count = 0;
    vkGetSwapchainImagesKHR(device(), swapchain_, &count, nullptr);
    swapchain_images_.resize(count);
    vkGetSwapchainImagesKHR(device(), swapchain_, &count, swapchain_images_.data());
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    rendered_.assign(count, VK_NULL_HANDLE);
    for (VkSemaphore& semaphore : rendered_) {
        if (VkResult r = vkCreateSemaphore(device(), &semaphore_info, nullptr, &semaphore); r != VK_SUCCESS) {
            return vk::vulkan_error("vkCreateSemaphore", r);
        }
    }
    return {};
}

void VulkanWindow::destroy_swapchain() {
    if (!device()) return;
    vkDeviceWaitIdle(device());
    for (VkSemaphore semaphore : rendered_) {
        if (semaphore) vkDestroySemaphore(device(), semaphore, nullptr);
    }
    rendered_.clear();
    swapchain_images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(device(), swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
}

VulkanWindow::~VulkanWindow() {
    destroy_swapchain();
    if (image_ready_) vkDestroySemaphore(device(), image_ready_, nullptr);
    device_ = {};
    if (surface_) vkDestroySurfaceKHR(instance(), surface_, nullptr);
    if (window_) glfwDestroyWindow(window_);
    instance_ = {};
    glfwTerminate();
}

bool VulkanWindow::should_close() const {
    return glfwWindowShouldClose(window_) != 0;
}

void VulkanWindow::set_should_close(bool close) {
    glfwSetWindowShouldClose(window_, close ? GLFW_TRUE : GLFW_FALSE);
}

float VulkanWindow::content_scale() const {
    float x = 1.0f, y = 1.0f;
    glfwGetWindowContentScale(window_, &x, &y);
    return x > 0.0f ? x : 1.0f;
}

bool VulkanWindow::drawable() const {
    int width = 0, height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    return width > 0 && height > 0 && glfwGetWindowAttrib(window_, GLFW_ICONIFIED) == GLFW_FALSE;
}

std::vector<InputEvent> VulkanWindow::poll_events(bool wait) {
    wait ? glfwWaitEvents() : glfwPollEvents();
    return std::exchange(events_, {});
}

Result<VulkanWindow::Acquired> VulkanWindow::acquire() {
    Acquired acquired;
    if (resized_ || swapchain_ == VK_NULL_HANDLE) {
        if (Status status = create_swapchain(); !status) return status.error();
        return acquired;
    }
    const VkResult r =
        vkAcquireNextImageKHR(device(), swapchain_, UINT64_MAX, image_ready_, VK_NULL_HANDLE, &acquired.index);
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
    const VkResult r = vkQueuePresentKHR(queue(), &info);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return create_swapchain();
    if (r != VK_SUCCESS) return vk::vulkan_error("vkQueuePresentKHR", r);
    return {};
}

}  // namespace crisp::editor
