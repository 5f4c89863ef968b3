// crisp-layout-editor: the GLFW window, the Vulkan instance, device and swapchain behind it, and
// the window's input as an ordered list of events. The instance, the device's choice and the
// device are made as the headless context makes them (support/vulkan_device.hpp); the window adds
// its surface, a queue family that presents to it, and the swapchain.
#pragma once

#include "vulkan_device.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct GLFWwindow;

namespace crisp::editor {

// One input event, in the order the window system delivered it. Positions are window pixels.
struct InputEvent {
    enum class Kind : uint8_t { mouse_move, mouse_down, mouse_up, key, character };
    Kind kind = Kind::mouse_move;
    double x = 0.0, y = 0.0;  // the cursor, for every kind
    int button = 0;           // GLFW_MOUSE_BUTTON_*
    int key = 0;              // GLFW_KEY_* (key presses and repeats only)
    int mods = 0;             // GLFW_MOD_*
    uint32_t codepoint = 0;   // character
};

struct WindowOptions {
    // The starting size, window pixels; the person may resize the window from there.
    uint32_t width = 1280;
    uint32_t height = 800;
    // The size is in interface pixels instead: times the primary monitor's content scale, and
    // no larger than its work area.
    bool fit_to_monitor = false;
    std::string title = "crisp layout editor";
    // VK_LAYER_KHRONOS_validation with a messenger that counts its warnings and errors.
    bool validation = false;
};

// Owns the window and every Vulkan object the program makes outside crisp. Destroying it waits
// for the device to be idle. Not copyable or movable (GLFW keeps a pointer to it).
class VulkanWindow {
public:
    // Errors (ErrorCode::vulkan): no display, no Vulkan driver or surface support, the validation
    // layer asked for and missing, no device with what crisp's renderer needs and presentation.
    static Result<std::unique_ptr<VulkanWindow>> create(const WindowOptions& options);
    VulkanWindow(const VulkanWindow&) = delete;
    VulkanWindow& operator=(const VulkanWindow&) = delete;
    ~VulkanWindow();

    VkInstance instance() const { return instance_.handle(); }
    uint32_t instance_api_version() const { return instance_.api_version(); }
    VkPhysicalDevice physical_device() const { return physical_.handle; }
    VkDevice device() const { return device_.handle(); }
    uint32_t queue_family() const { return physical_.queue_family; }
    VkQueue queue() const { return device_.queue(); }
    const VkPhysicalDeviceProperties& properties() const { return physical_.properties; }
    const VkPhysicalDeviceMemoryProperties& memory_properties() const { return physical_.memory_properties; }
    // B8G8R8A8 storage views (shaderStorageImageWriteWithoutFormat), on where the GPU has them.
    bool storage_without_format() const {
        return device_.enabled_features()->features.shaderStorageImageWriteWithoutFormat == VK_TRUE;
    }
    // The feature chain the device was created with, for crisp's create infos.
    const VkPhysicalDeviceFeatures2* enabled_features() const { return device_.enabled_features(); }
    uint32_t timestamp_valid_bits() const { return physical_.queue_family_properties.timestampValidBits; }
    // The swapchain's size, window pixels: what a frame fills.
    uint32_t width() const { return extent_.width; }
    uint32_t height() const { return extent_.height; }
    // Window pixels per interface pixel the monitor asks for (glfwGetWindowContentScale; 1 where
    // the window system does not say).
    float content_scale() const;
    // Whether a frame can be shown: the window is not minimized and has an area.
    bool drawable() const;

    bool should_close() const;
    // Sets or clears the close request (glfwSetWindowShouldClose): cleared while the editor
    // asks whether to save, so that Cancel keeps the window.
    void set_should_close(bool close);
    // Polls the window system and returns the events since the last call, oldest first. With
    // `wait`, sleeps until the window system has something (input, a resize, an exposure).
    std::vector<InputEvent> poll_events(bool wait = false);

    // The swapchain image to draw into next, or nullopt-like (image == VK_NULL_HANDLE) when the
    // swapchain had to be rebuilt (out of date, or the window was resized: width() and height()
    // are then the new size) and the frame should be skipped. `ready` is signalled when the image
    // may be written.
    struct Acquired {
        VkImage image = VK_NULL_HANDLE;
        uint32_t index = 0;
        VkSemaphore ready = VK_NULL_HANDLE;     // wait on it before writing the image
        VkSemaphore rendered = VK_NULL_HANDLE;  // signal it when the image is done
    };
    Result<Acquired> acquire();
    // Presents an acquired image once `rendered` is signalled; rebuilds the swapchain when it is
    // out of date.
    Status present(const Acquired& acquired);
    VkFormat swapchain_format() const { return swapchain_format_; }

    // Warnings and errors the validation layer reported so far.
    uint32_t validation_messages() const {
        const ValidationMessages messages = validation_log_.snapshot();
        return messages.warnings + messages.errors;
    }

private:
    VulkanWindow() = default;
    // create()'s steps, in order; each leaves what it made for the destructor on failure.
    Status create_instance();
    Status create_window();
    Status choose_device();
    Status create_device();
    Status create_swapchain();
    void destroy_swapchain();
    friend struct WindowCallbacks;

    WindowOptions options_;
    // Each message goes to stderr as it arrives, and is counted.
    ValidationLog validation_log_{"crisp-layout-editor: "};
    GLFWwindow* window_ = nullptr;
    VulkanInstance instance_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    PhysicalDevice physical_;
    VulkanDevice device_;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    VkFormat swapchain_format_ = VK_FORMAT_UNDEFINED;
    std::vector<VkImage> swapchain_images_;
    std::vector<VkSemaphore> rendered_;  // one per swapchain image
    VkSemaphore image_ready_ = VK_NULL_HANDLE;
    VkExtent2D extent_{};
    bool resized_ = false;  // the framebuffer's size changed since the swapchain was made
    std::vector<InputEvent> events_;
    double cursor_x_ = 0.0, cursor_y_ = 0.0;
};

}  // namespace crisp::editor
