// crisp support (not installed): the steps a Vulkan device is made in, one path for the headless
// context and crisp-layout-editor's window. As vk-bootstrap splits them: an instance (with the
// Khronos validation layer and a messenger that logs it where asked for), the choice of a physical
// device and queue family that meet the caller's requirements, and the device made with exactly
// the features and extensions that choice settled. The headless context adds its submissions and
// resources; the window its surface, swapchain and presentation.
#pragma once

#include <crisp/device_features.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace crisp {

namespace vk {
struct Functions;       // the Vulkan functions crisp calls through (private)
struct DeviceFeatures;  // one of each core feature structure (private)
}  // namespace vk

// What the validation layer has said so far (warnings and errors only; info and verbose messages
// are not requested).
struct ValidationMessages {
    uint32_t warnings = 0;
    uint32_t errors = 0;
    // The last few message texts, oldest first, each prefixed "error: " or "warning: ".
    std::vector<std::string> recent;
};

// Counts what the validation layer reports. Its address is the messenger's user data, so it must
// not move while the instance that logs into it exists. Safe to use from any thread.
class ValidationLog {
public:
    // With an echo prefix, each message also goes to stderr as it arrives, as
    // "<prefix>validation error: <text>" (or warning).
    explicit ValidationLog(std::string echo_prefix = {}) : echo_prefix_(std::move(echo_prefix)) {}
    ValidationLog(const ValidationLog&) = delete;
    ValidationLog& operator=(const ValidationLog&) = delete;

    void add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* text);
    ValidationMessages snapshot() const;

private:
    mutable std::mutex mutex_;  // the layer may call back from any thread that calls Vulkan
    std::string echo_prefix_;
    ValidationMessages messages_;
    std::deque<std::string> recent_;
};

struct InstanceOptions {
    const char* application_name = "crisp";
    // VkApplicationInfo::apiVersion: the newest Vulkan the caller programs against.
    uint32_t api_version = VK_API_VERSION_1_2;
    // The oldest loader accepted: create() fails, saying so, below it.
    uint32_t minimum_version = VK_API_VERSION_1_2;
    // Instance extensions beyond the validation layer's (a window system's surface extensions).
    std::vector<const char*> extensions;
    // Turn on VK_LAYER_KHRONOS_validation with a messenger that adds its messages to
    // `validation_log` (which must then be set, and outlive the instance). create() fails, saying
    // so, when the layer is not installed.
    bool validation = false;
    // With validation: also the layer's synchronization validation (missing or wrong barriers),
    // which costs more CPU time.
    bool synchronization_validation = false;
    ValidationLog* validation_log = nullptr;
    // The loader entry point to make the instance through; null: the system loader's.
    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
};

// A VkInstance, the global and instance functions loaded for it, and its validation messenger.
// Move-only; the destructor destroys the messenger and the instance, which must outlive every
// device made from it. A default-constructed or moved-from one is empty.
class VulkanInstance {
public:
    // Fails with ErrorCode::vulkan when there is no Vulkan loader or driver, the loader is below
    // minimum_version, or validation was asked for and the layer or its extensions are absent.
    static Result<VulkanInstance> create(const InstanceOptions& options);

    VulkanInstance();
    VulkanInstance(VulkanInstance&& other) noexcept;
    VulkanInstance& operator=(VulkanInstance&& other) noexcept;
    VulkanInstance(const VulkanInstance&) = delete;
    VulkanInstance& operator=(const VulkanInstance&) = delete;
    ~VulkanInstance();

    VkInstance handle() const;
    // The VkApplicationInfo::apiVersion it was created with (RendererCreateInfo::instance_api_version).
    uint32_t api_version() const;
    // The functions the instance was made and is used through (stable while it lives).
    const vk::Functions& functions() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

// What a device must have to be chosen.
struct DeviceRequirements {
    // Pick a device whose name contains this (case-sensitive); empty: any. Among the candidates
    // that meet every requirement, prefer discrete > integrated > virtual > CPU.
    std::string device_name_contains;
    // The Vulkan version the caller programs against, and the floor the device must meet (the
    // patch number aside). At least VK_API_VERSION_1_2.
    uint32_t api_version = VK_API_VERSION_1_2;
    // Features the device must offer; exactly these are enabled. Null: none. Its pNext chain may
    // hold VkPhysicalDeviceVulkan11Features, VkPhysicalDeviceVulkan12Features and (with
    // api_version >= 1.3) VkPhysicalDeviceVulkan13Features, each at most once; any other
    // structure is an invalid_argument error. Read only while the device is chosen.
    const VkPhysicalDeviceFeatures2* required_features = nullptr;
    // Device extensions the device must offer; exactly these are enabled ("VK_KHR_push_descriptor").
    std::vector<std::string> required_extensions;
    // Subgroup operations (VK_SUBGROUP_FEATURE_*_BIT) the device must offer in compute shaders.
    VkSubgroupFeatureFlags required_compute_subgroup_operations = 0;
    // Also what crisp's parts need, as an engine asks for it: for each candidate device,
    // add_crisp_features() adds to required_features what `crisp_needs` names (a device that lacks
    // something is passed over, its rejection saying what), and crisp's compute subgroup
    // operations (basic, arithmetic) are required. storage_without_format is turned on only where
    // the device offers it. With draw_path, api_version is raised to at least 1.3 (dynamic
    // rendering). nullopt: only what the fields above ask for.
    std::optional<CrispFeatureNeeds> crisp_needs;
    // Where the chosen device offers VK_KHR_pipeline_executable_properties and its
    // pipelineExecutableInfo feature, enable both (the enabled features then chain the feature
    // structure), so that renderers and compositors made on the device report their shaders'
    // statistics (Renderer::shader_statistics()). Never a reason to pass a device over.
    bool shader_statistics = false;
    // The queue family is the first that does graphics and compute and, where this is set, passes
    // it too (a window's: it presents to the window's surface). `queue_family_check_name` says
    // what it checks in a rejection ("presents to the window's surface").
    std::function<bool(VkPhysicalDevice device, uint32_t family)> queue_family_check;
    std::string queue_family_check_name;
};

// What crisp_needs implies, added to `requirements`: Vulkan 1.3 for the draw path, crisp's subgroup
// operations. choose_physical_device() adds it itself; a caller whose instance asks for the
// device's api_version adds it first.
void add_crisp_needs(DeviceRequirements& requirements);

// The device choose_physical_device() picked, what it learnt about it, and what its device is to
// be made with.
struct PhysicalDevice {
    VkPhysicalDevice handle = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceVulkan11Properties vulkan11{};  // pNext null
    VkPhysicalDeviceVulkan12Properties vulkan12{};  // pNext null
    VkPhysicalDeviceMemoryProperties memory_properties{};
    uint32_t queue_family = 0;
    VkQueueFamilyProperties queue_family_properties{};
    // The lower of the required api_version and the device's own.
    uint32_t api_version = 0;
    // What the device is made with: the required features with what crisp_needs added, and the
    // required extensions, each once, with VK_KHR_pipeline_executable_properties where
    // shader_statistics found it offered.
    std::shared_ptr<const vk::DeviceFeatures> features;
    std::vector<std::string> extensions;
    bool pipeline_statistics = false;  // VK_KHR_pipeline_executable_properties and its feature offered
};

// The invalid_argument errors choose_physical_device() gives for malformed requirements (an
// api_version below 1.2, a malformed required_features chain), for a caller that wants them before
// it makes an instance.
Status check_requirements(const DeviceRequirements& requirements);

// The best device of `instance` that meets every requirement (discrete > integrated > virtual >
// CPU). Fails with ErrorCode::vulkan when there is none; the message names each device and what
// it lacks ("llvmpipe (LLVM 15.0.6, 256 bits): the device lacks descriptorIndexing"). Fails with
// ErrorCode::invalid_argument as check_requirements().
Result<PhysicalDevice> choose_physical_device(const VulkanInstance& instance, const DeviceRequirements& requirements);

// A VkDevice with one queue, made from what choose_physical_device() settled, and its functions.
// Move-only; the destructor destroys the device, which its owner has let go idle first. A
// default-constructed or moved-from one is empty.
class VulkanDevice {
public:
    // Fails with ErrorCode::vulkan when vkCreateDevice fails or the loader gives a device function
    // crisp calls no address.
    static Result<VulkanDevice> create(const VulkanInstance& instance, const PhysicalDevice& chosen);

    VulkanDevice();
    VulkanDevice(VulkanDevice&& other) noexcept;
    VulkanDevice& operator=(VulkanDevice&& other) noexcept;
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;
    ~VulkanDevice();

    VkDevice handle() const;
    VkQueue queue() const;  // queue 0 of the chosen family
    // Every function crisp calls, instance and device ones (stable while the device lives).
    const vk::Functions& functions() const;
    // The feature chain the device was made with, for RendererCreateInfo::enabled_features and
    // CompositorCreateInfo::enabled_features. Valid while the device lives.
    const VkPhysicalDeviceFeatures2* enabled_features() const;
    const std::vector<std::string>& enabled_extensions() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace crisp
