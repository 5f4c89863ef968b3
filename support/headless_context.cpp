// HeadlessContext: instance, validation messenger, device choice and creation, one-off submissions,
// and the renderer's and compositor's create infos for it. Its buffers and images live in
// headless_resources.cpp.
#include "headless_context.hpp"

#include "vk/features.hpp"
#include "vk/resources.hpp"

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace crisp {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// Enough recent messages to see what went wrong without keeping an unbounded log.
constexpr size_t kKeptValidationMessages = 16;

// Counts what the validation layer reports. One per context, on the heap inside its State: its
// address is the messenger's user data, so it must not move while the instance exists.
class ValidationLog {
public:
    void add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* text) {
        const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
        std::lock_guard lock(mutex_);
        (error ? messages_.errors : messages_.warnings)++;
        recent_.push_back(std::string(error ? "error: " : "warning: ") + (text != nullptr ? text : "(no text)"));
        if (recent_.size() > kKeptValidationMessages) recent_.pop_front();
    }

    ValidationMessages snapshot() const {
        std::lock_guard lock(mutex_);
        ValidationMessages copy = messages_;
        copy.recent.assign(recent_.begin(), recent_.end());
        return copy;
    }

private:
    mutable std::mutex mutex_;  // the layer may call back from any thread that calls Vulkan
    ValidationMessages messages_;
    std::deque<std::string> recent_;
};

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                     void* user_data) {
    // No exception may cross back into the layer's C code; losing one message beats terminating.
    try {
        static_cast<ValidationLog*>(user_data)->add(severity, data != nullptr ? data->pMessage : nullptr);
    } catch (...) {
    }
    return VK_FALSE;  // the spec reserves VK_TRUE for layer development
}

VkDebugUtilsMessengerCreateInfoEXT messenger_info(ValidationLog* log) {
    VkDebugUtilsMessengerCreateInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    // Info and verbose messages are chatter (loader and layer status), not faults.
    info.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = on_validation_message;
    info.pUserData = log;
    return info;
}

bool has_extension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> instance_extensions(const vk::Functions& fn, const char* layer) {
    uint32_t count = 0;
    if (fn.vkEnumerateInstanceExtensionProperties(layer, &count, nullptr) != VK_SUCCESS) return {};
    std::vector<VkExtensionProperties> extensions(count);
    if (fn.vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data()) != VK_SUCCESS) return {};
    extensions.resize(count);
    return extensions;
}

bool has_layer(const vk::Functions& fn, const char* name) {
    uint32_t count = 0;
    if (fn.vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
    std::vector<VkLayerProperties> layers(count);
    if (fn.vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
    layers.resize(count);
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

// Ignores the patch number: a 1.2.0 floor accepts a 1.2.x device.
bool meets_version(uint32_t version, uint32_t floor) {
    return VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(version), VK_API_VERSION_MINOR(version), 0) >=
           VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(floor), VK_API_VERSION_MINOR(floor), 0);
}

std::string join(const std::vector<std::string>& parts, const char* separator) {
    std::string joined;
    for (const std::string& part : parts) {
        if (!joined.empty()) joined += separator;
        joined += part;
    }
    return joined;
}

// Lower is better: discrete > integrated > virtual > CPU > other.
int device_type_rank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 3;
        default:
            return 4;
    }
}

std::string subgroup_operation_names(VkSubgroupFeatureFlags operations) {
    static constexpr std::pair<VkSubgroupFeatureFlags, const char*> kNames[] = {
        {VK_SUBGROUP_FEATURE_BASIC_BIT, "basic"},
        {VK_SUBGROUP_FEATURE_VOTE_BIT, "vote"},
        {VK_SUBGROUP_FEATURE_ARITHMETIC_BIT, "arithmetic"},
        {VK_SUBGROUP_FEATURE_BALLOT_BIT, "ballot"},
        {VK_SUBGROUP_FEATURE_SHUFFLE_BIT, "shuffle"},
        {VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT, "shuffle_relative"},
        {VK_SUBGROUP_FEATURE_CLUSTERED_BIT, "clustered"},
        {VK_SUBGROUP_FEATURE_QUAD_BIT, "quad"},
    };
    std::vector<std::string> names;
    for (const auto& [bit, name] : kNames) {
        if (operations & bit) names.emplace_back(name);
    }
    if (names.empty()) names.emplace_back("(unknown bits)");
    return join(names, ", ");
}

// What create() learns about one device while deciding whether it qualifies.
struct DeviceCandidate {
    VkPhysicalDevice handle = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceVulkan11Properties vulkan11{};
    VkPhysicalDeviceVulkan12Properties vulkan12{};
    uint32_t queue_family = 0;
    vk::DeviceFeatures features;  // what its device is created with (unlinked)
    bool pipeline_statistics = false;  // VK_KHR_pipeline_executable_properties and its feature offered
};

// Empty when `candidate` meets every requirement; otherwise what it lacks. Fills the candidate's
// properties, queue family and features (`required`, plus what options.crisp_needs adds for it).
std::vector<std::string> check_device(const vk::Functions& fn, VkInstance instance, DeviceCandidate& candidate,
                                      const HeadlessContextOptions& options, const vk::DeviceFeatures& required) {
    std::vector<std::string> lacks;
    const uint32_t device_version = candidate.properties.apiVersion;
    if (!meets_version(device_version, options.api_version)) {
        lacks.push_back("the device supports Vulkan " + vk::version_string(device_version) + " only, below " +
                        vk::version_string(options.api_version));
        return lacks;  // the 1.2 property and feature structures below may not be queried
    }

    VkPhysicalDeviceProperties2 properties2{};
    properties2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    candidate.vulkan11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES;
    candidate.vulkan12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES;
    properties2.pNext = &candidate.vulkan11;
    candidate.vulkan11.pNext = &candidate.vulkan12;
    fn.vkGetPhysicalDeviceProperties2(candidate.handle, &properties2);
    candidate.vulkan11.pNext = nullptr;

    uint32_t family_count = 0;
    fn.vkGetPhysicalDeviceQueueFamilyProperties(candidate.handle, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    fn.vkGetPhysicalDeviceQueueFamilyProperties(candidate.handle, &family_count, families.data());
    // Graphics and compute together imply transfer; one queue keeps ownership transfers away.
    const VkQueueFlags wanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    auto family = std::find_if(families.begin(), families.end(), [&](const VkQueueFamilyProperties& f) {
        return (f.queueFlags & wanted) == wanted && f.queueCount > 0;
    });
    if (family == families.end()) {
        lacks.push_back("the device has no queue family with both graphics and compute");
    } else {
        candidate.queue_family = static_cast<uint32_t>(family - families.begin());
    }

    uint32_t extension_count = 0;
    fn.vkEnumerateDeviceExtensionProperties(candidate.handle, nullptr, &extension_count, nullptr);
    std::vector<VkExtensionProperties> extensions(extension_count);
    fn.vkEnumerateDeviceExtensionProperties(candidate.handle, nullptr, &extension_count, extensions.data());
    extensions.resize(extension_count);
    for (const std::string& name : options.required_extensions) {
        if (!has_extension(extensions, name.c_str())) lacks.push_back("the device lacks extension " + name);
    }
    if (options.shader_statistics && has_extension(extensions, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME)) {
        VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable{};
        executable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
        VkPhysicalDeviceFeatures2 features{};
        features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        features.pNext = &executable;
        fn.vkGetPhysicalDeviceFeatures2(candidate.handle, &features);
        candidate.pipeline_statistics = executable.pipelineExecutableInfo == VK_TRUE;
    }

    candidate.features = required;
    if (options.crisp_needs) {
        VkPhysicalDeviceFeatures2* chain = candidate.features.link(true);
        if (Status s =
                add_crisp_features(instance, candidate.handle, *chain, *options.crisp_needs, fn.vkGetInstanceProcAddr);
            !s) {
            lacks.push_back(s.error().message);
            return lacks;
        }
    }
    const bool vulkan13 =
        meets_version(device_version, VK_API_VERSION_1_3) && meets_version(options.api_version, VK_API_VERSION_1_3);
    const std::vector<std::string> missing =
        vk::missing_features(candidate.features, vk::query_features(fn, candidate.handle, vulkan13));
    if (!missing.empty()) lacks.push_back("the device lacks " + join(missing, ", "));

    const VkSubgroupFeatureFlags wanted_operations = options.required_compute_subgroup_operations;
    if (wanted_operations != 0) {
        if ((candidate.vulkan11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) == 0) {
            lacks.push_back("the device offers no subgroup operations in compute shaders");
        } else if (VkSubgroupFeatureFlags absent =
                       wanted_operations & ~candidate.vulkan11.subgroupSupportedOperations) {
            lacks.push_back("the device lacks subgroup operations in compute shaders: " +
                            subgroup_operation_names(absent));
        }
    }
    return lacks;
}

}  // namespace

struct HeadlessContext::State {
    vk::Functions fn;  // from the system loader
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    uint32_t queue_family = 0;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool command_pool = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    bool recording = false;  // catches submit_and_wait called from inside its own record callback
    bool lost = false;       // a submission or wait returned VK_ERROR_DEVICE_LOST

    std::string device_name;
    std::string driver_name;
    std::string driver_info;
    VkDriverId driver_id = VK_DRIVER_ID_MAX_ENUM;
    uint32_t driver_version = 0;
    uint32_t api_version = 0;
    vk::DeviceFeatures enabled;  // what the device was created with
    // Linked after `enabled`'s structures where options.shader_statistics found it offered.
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable_features{};
    VkPhysicalDeviceFeatures2* enabled_chain = nullptr;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory_properties{};
    VkPhysicalDeviceSubgroupProperties subgroup{};
    std::vector<std::string> enabled_extensions;

    ValidationLog validation_log;

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;

    // create()'s steps, in order; each leaves what it made for the destructor on failure.
    Status create_instance(const HeadlessContextOptions& options);
    Status create_messenger(const VkDebugUtilsMessengerCreateInfoEXT& info);
    Result<DeviceCandidate> choose_device(const HeadlessContextOptions& options, const vk::DeviceFeatures& required);
    Status create_device(const DeviceCandidate& chosen, const HeadlessContextOptions& options);
    Status create_submission_objects();

    // Destroys in reverse order of creation; create() relies on this to clean up after a failure
    // part-way through.
    ~State() {
        const ValidationMessages before = validation_log.snapshot();
        // A device or instance whose functions failed to load cannot be destroyed; it is leaked.
        if (device != VK_NULL_HANDLE && fn.vkDestroyDevice != nullptr) {
            // Nothing may be destroyed while the GPU still uses it.
            fn.vkDeviceWaitIdle(device);
            if (fence != VK_NULL_HANDLE) fn.vkDestroyFence(device, fence, nullptr);
            if (command_pool != VK_NULL_HANDLE) fn.vkDestroyCommandPool(device, command_pool, nullptr);
            fn.vkDestroyDevice(device, nullptr);
        }
        if (messenger != VK_NULL_HANDLE) destroy_messenger(instance, messenger, nullptr);
        if (instance != VK_NULL_HANDLE && fn.vkDestroyInstance != nullptr) fn.vkDestroyInstance(instance, nullptr);
        // What the layer says during teardown (typically: a Buffer or Image outlived its context)
        // has no one left to read it, so it goes to stderr.
        const ValidationMessages after = validation_log.snapshot();
        const size_t added = (after.errors + after.warnings) - (before.errors + before.warnings);
        const size_t shown = std::min(added, after.recent.size());
        for (size_t i = after.recent.size() - shown; i < after.recent.size(); ++i) {
            std::fprintf(stderr, "crisp: validation during HeadlessContext teardown: %s\n", after.recent[i].c_str());
        }
    }
};

// The instance (with the validation layer and its messenger where asked for), after checking the
// loader's version.
Status HeadlessContext::State::create_instance(const HeadlessContextOptions& options) {
    if (Status s = vk::load_functions(nullptr, VK_NULL_HANDLE, VK_NULL_HANDLE, fn); !s) return s;
    uint32_t loader_version = VK_API_VERSION_1_0;
    if (fn.vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS ||
        !meets_version(loader_version, options.api_version)) {
        return Error{ErrorCode::vulkan, "the Vulkan loader supports Vulkan " + vk::version_string(loader_version) +
                                            ", below the " + vk::version_string(options.api_version) + " crisp needs"};
    }

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    VkDebugUtilsMessengerCreateInfoEXT messenger_create = messenger_info(&validation_log);
    VkValidationFeaturesEXT validation_features{};
    const VkValidationFeatureEnableEXT sync_validation = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    if (options.validation) {
        if (!has_layer(fn, kValidationLayer)) {
            return Error{ErrorCode::vulkan, std::string("validation was requested but ") + kValidationLayer +
                                                " is not available (Debian: apt install vulkan-validationlayers)"};
        }
        layers.push_back(kValidationLayer);
        std::vector<VkExtensionProperties> available = instance_extensions(fn, nullptr);
        const std::vector<VkExtensionProperties> from_layer = instance_extensions(fn, kValidationLayer);
        available.insert(available.end(), from_layer.begin(), from_layer.end());
        if (!has_extension(available, VK_EXT_DEBUG_UTILS_EXTENSION_NAME)) {
            return Error{ErrorCode::vulkan, "validation was requested but VK_EXT_debug_utils is not available"};
        }
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        if (options.synchronization_validation) {
            if (!has_extension(available, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME)) {
                return Error{
                    ErrorCode::vulkan,
                    "synchronization validation was requested but VK_EXT_validation_features is not available"};
            }
            extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
            validation_features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
            validation_features.enabledValidationFeatureCount = 1;
            validation_features.pEnabledValidationFeatures = &sync_validation;
            messenger_create.pNext = &validation_features;
        }
    }

    VkApplicationInfo application{};
    application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    application.pApplicationName = "crisp";
    application.pEngineName = "crisp";
    application.apiVersion = options.api_version;
    VkInstanceCreateInfo instance_info{};
    instance_info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    // Chained here too so that messages from vkCreateInstance and vkDestroyInstance are counted.
    instance_info.pNext = options.validation ? &messenger_create : nullptr;
    instance_info.pApplicationInfo = &application;
    instance_info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    instance_info.ppEnabledLayerNames = layers.data();
    instance_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    instance_info.ppEnabledExtensionNames = extensions.data();
    if (VkResult result = fn.vkCreateInstance(&instance_info, nullptr, &instance); result != VK_SUCCESS) {
        if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
            return Error{ErrorCode::vulkan,
                         "no Vulkan driver supports Vulkan " + vk::version_string(options.api_version) +
                             " (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER)",
                         result};
        }
        return vk::vulkan_error("vkCreateInstance", result);
    }
    if (Status s = vk::load_functions(fn.vkGetInstanceProcAddr, instance, VK_NULL_HANDLE, fn); !s) {
        return s.error();
    }
    if (!options.validation) return {};
    messenger_create.pNext = nullptr;  // the validation features belong to the instance only
    return create_messenger(messenger_create);
}

// The messenger that counts the validation layer's messages after instance creation.
Status HeadlessContext::State::create_messenger(const VkDebugUtilsMessengerCreateInfoEXT& info) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        fn.vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        fn.vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (create == nullptr || destroy_messenger == nullptr) {
        return Error{ErrorCode::vulkan, "VK_EXT_debug_utils is enabled but its functions are missing"};
    }
    if (VkResult result = create(instance, &info, nullptr, &messenger); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateDebugUtilsMessengerEXT", result);
    }
    return {};
}

// The best device that meets every requirement (discrete > integrated > virtual > CPU), or an
// error naming each device and what it lacks.
Result<DeviceCandidate> HeadlessContext::State::choose_device(const HeadlessContextOptions& options,
                                                              const vk::DeviceFeatures& required) {
    uint32_t device_count = 0;
    if (VkResult result = fn.vkEnumeratePhysicalDevices(instance, &device_count, nullptr); result != VK_SUCCESS) {
        return vk::vulkan_error("vkEnumeratePhysicalDevices", result);
    }
    std::vector<VkPhysicalDevice> devices(device_count);
    if (VkResult result = fn.vkEnumeratePhysicalDevices(instance, &device_count, devices.data());
        result != VK_SUCCESS && result != VK_INCOMPLETE) {
        return vk::vulkan_error("vkEnumeratePhysicalDevices", result);
    }
    devices.resize(device_count);
    if (devices.empty()) return Error{ErrorCode::vulkan, "no Vulkan device found"};

    std::vector<std::string> names;
    std::vector<std::string> rejections;
    std::optional<DeviceCandidate> chosen;
    for (VkPhysicalDevice handle : devices) {
        DeviceCandidate candidate;
        candidate.handle = handle;
        fn.vkGetPhysicalDeviceProperties(handle, &candidate.properties);
        const std::string name = candidate.properties.deviceName;
        names.push_back(name);
        if (name.find(options.device_name_contains) == std::string::npos) continue;
        const std::vector<std::string> lacks = check_device(fn, instance, candidate, options, required);
        if (!lacks.empty()) {
            rejections.push_back(name + ": " + join(lacks, "; "));
            continue;
        }
        if (!chosen ||
            device_type_rank(candidate.properties.deviceType) < device_type_rank(chosen->properties.deviceType)) {
            chosen = candidate;
        }
    }
    if (!chosen) {
        if (rejections.empty()) {
            return Error{ErrorCode::vulkan, "no Vulkan device name contains \"" + options.device_name_contains +
                                                "\"; the devices are: " + join(names, ", ")};
        }
        return Error{ErrorCode::vulkan, "no suitable Vulkan device: " + join(rejections, " | ")};
    }

    return *chosen;
}

// The device from `chosen`, with exactly its features (the required ones and crisp's) and the
// required extensions, and its queue.
Status HeadlessContext::State::create_device(const DeviceCandidate& chosen, const HeadlessContextOptions& options) {
    vk::DeviceFeatures required = chosen.features;
    physical_device = chosen.handle;
    queue_family = chosen.queue_family;
    properties = chosen.properties;
    device_name = chosen.properties.deviceName;
    driver_name = chosen.vulkan12.driverName;
    driver_info = chosen.vulkan12.driverInfo;
    driver_id = chosen.vulkan12.driverID;
    driver_version = chosen.properties.driverVersion;
    api_version = std::min(options.api_version, chosen.properties.apiVersion);
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    subgroup.subgroupSize = chosen.vulkan11.subgroupSize;
    subgroup.supportedStages = chosen.vulkan11.subgroupSupportedStages;
    subgroup.supportedOperations = chosen.vulkan11.subgroupSupportedOperations;
    subgroup.quadOperationsInAllStages = chosen.vulkan11.subgroupQuadOperationsInAllStages;
    fn.vkGetPhysicalDeviceMemoryProperties(physical_device, &memory_properties);
    std::vector<std::string> wanted_extensions = options.required_extensions;
    if (chosen.pipeline_statistics) wanted_extensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    for (const std::string& name : wanted_extensions) {
        // Listing an extension twice is harmless to the caller but invalid for vkCreateDevice.
        if (std::find(enabled_extensions.begin(), enabled_extensions.end(), name) == enabled_extensions.end()) {
            enabled_extensions.push_back(name);
        }
    }
    executable_features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
    executable_features.pipelineExecutableInfo = chosen.pipeline_statistics ? VK_TRUE : VK_FALSE;
    // Puts executable_features right after `chain`'s head where it is enabled.
    const auto with_statistics = [&](VkPhysicalDeviceFeatures2* chain) {
        if (chosen.pipeline_statistics) {
            executable_features.pNext = chain->pNext;
            chain->pNext = &executable_features;
        }
        return chain;
    };

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    std::vector<const char*> device_extensions;
    for (const std::string& name : enabled_extensions) device_extensions.push_back(name.c_str());
    VkDeviceCreateInfo device_info{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    // Exactly what the caller required; the 1.3 structure only when it asks for something, since
    // a 1.2 device must not see it.
    device_info.pNext = with_statistics(required.link(required.any_vulkan13()));
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.enabledExtensionCount = static_cast<uint32_t>(device_extensions.size());
    device_info.ppEnabledExtensionNames = device_extensions.data();
    if (VkResult result = fn.vkCreateDevice(physical_device, &device_info, nullptr, &device); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateDevice", result);
    }
    if (Status s = vk::load_functions(fn.vkGetInstanceProcAddr, instance, device, fn); !s) {
        return s.error();
    }
    enabled = required;
    enabled_chain = with_statistics(enabled.link(true));
    fn.vkGetDeviceQueue(device, queue_family, 0, &queue);

    return {};
}

// The command pool, command buffer and fence submit_and_wait() uses.
Status HeadlessContext::State::create_submission_objects() {
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    // One command buffer, re-recorded for every submission.
    pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = queue_family;
    if (VkResult result = fn.vkCreateCommandPool(device, &pool_info, nullptr, &command_pool); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateCommandPool", result);
    }
    VkCommandBufferAllocateInfo buffer_info{};
    buffer_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    buffer_info.commandPool = command_pool;
    buffer_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    buffer_info.commandBufferCount = 1;
    if (VkResult result = fn.vkAllocateCommandBuffers(device, &buffer_info, &command_buffer); result != VK_SUCCESS) {
        return vk::vulkan_error("vkAllocateCommandBuffers", result);
    }
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if (VkResult result = fn.vkCreateFence(device, &fence_info, nullptr, &fence); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFence", result);
    }
    return {};
}

namespace {

// `given` with what crisp_needs implies: Vulkan 1.3 for the draw path, crisp's subgroup operations.
HeadlessContextOptions with_crisp_needs(const HeadlessContextOptions& given) {
    HeadlessContextOptions options = given;
    if (!options.crisp_needs) return options;
    if (options.crisp_needs->draw_path) options.api_version = std::max(options.api_version, VK_API_VERSION_1_3);
    options.required_compute_subgroup_operations |= VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    return options;
}

}  // namespace

Result<HeadlessContext> HeadlessContext::create(const HeadlessContextOptions& given) {
    const HeadlessContextOptions options = with_crisp_needs(given);
    if (!meets_version(options.api_version, VK_API_VERSION_1_2)) {
        return Error{ErrorCode::invalid_argument,
                     "api_version " + vk::version_string(options.api_version) + " is below crisp's floor of 1.2"};
    }
    Result<vk::DeviceFeatures> required = vk::copy_required_features(options.required_features, options.api_version);
    if (!required) return required.error();
    auto state = std::make_unique<State>();
    if (Status s = state->create_instance(options); !s) return s.error();
    Result<DeviceCandidate> chosen = state->choose_device(options, *required);
    if (!chosen) return chosen.error();
    if (Status s = state->create_device(*chosen, options); !s) return s.error();
    if (Status s = state->create_submission_objects(); !s) return s.error();
    return HeadlessContext(std::move(state));
}

HeadlessContext::HeadlessContext(std::unique_ptr<State> state) : state_(std::move(state)) {}
HeadlessContext::HeadlessContext(HeadlessContext&& other) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&& other) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

const vk::Functions& HeadlessContext::functions() const {
    return state_->fn;
}
PFN_vkGetInstanceProcAddr HeadlessContext::get_instance_proc_addr() const {
    return state_->fn.vkGetInstanceProcAddr;
}
VkInstance HeadlessContext::instance() const {
    return state_->instance;
}
VkPhysicalDevice HeadlessContext::physical_device() const {
    return state_->physical_device;
}
VkDevice HeadlessContext::device() const {
    return state_->device;
}
uint32_t HeadlessContext::queue_family() const {
    return state_->queue_family;
}

const VkPhysicalDeviceFeatures2* HeadlessContext::enabled_features() const {
    return state_->enabled_chain;
}
VkQueue HeadlessContext::queue() const {
    return state_->queue;
}
const std::string& HeadlessContext::device_name() const {
    return state_->device_name;
}
const std::string& HeadlessContext::driver_name() const {
    return state_->driver_name;
}
const std::string& HeadlessContext::driver_info() const {
    return state_->driver_info;
}
VkDriverId HeadlessContext::driver_id() const {
    return state_->driver_id;
}
uint32_t HeadlessContext::driver_version() const {
    return state_->driver_version;
}
uint32_t HeadlessContext::api_version() const {
    return state_->api_version;
}
const VkPhysicalDeviceProperties& HeadlessContext::properties() const {
    return state_->properties;
}
const VkPhysicalDeviceMemoryProperties& HeadlessContext::memory_properties() const {
    return state_->memory_properties;
}
const VkPhysicalDeviceSubgroupProperties& HeadlessContext::subgroup_properties() const {
    return state_->subgroup;
}
const std::vector<std::string>& HeadlessContext::enabled_extensions() const {
    return state_->enabled_extensions;
}

bool HeadlessContext::supports_compute_subgroup_arithmetic() const {
    return (state_->subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
           (state_->subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0;
}

ValidationMessages HeadlessContext::validation_messages() const {
    return state_->validation_log.snapshot();
}

Status HeadlessContext::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
    State& s = *state_;
    const vk::Functions& fn = s.fn;
    assert(!s.recording && "submit_and_wait called from inside its own record callback");
    if (s.lost) {
        return Error{ErrorCode::device_lost, "the device was lost earlier: make a new context", VK_ERROR_DEVICE_LOST};
    }
    // Leaves the command buffer reusable even if `record` throws.
    struct RecordingGuard {
        State& s;
        bool ended = false;
        explicit RecordingGuard(State& state) : s(state) { s.recording = true; }
        ~RecordingGuard() {
            if (!ended) s.fn.vkResetCommandBuffer(s.command_buffer, 0);
            s.recording = false;
        }
    } guard(s);

    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (VkResult result = fn.vkBeginCommandBuffer(s.command_buffer, &begin); result != VK_SUCCESS) {
        return vk::vulkan_error("vkBeginCommandBuffer", result);
    }
    record(s.command_buffer);
    VkResult ended = fn.vkEndCommandBuffer(s.command_buffer);
    guard.ended = ended == VK_SUCCESS;
    if (ended != VK_SUCCESS) return vk::vulkan_error("vkEndCommandBuffer", ended);

    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &s.command_buffer;
    if (VkResult result = fn.vkQueueSubmit(s.queue, 1, &submit, s.fence); result != VK_SUCCESS) {
        s.lost = result == VK_ERROR_DEVICE_LOST;
        return vk::vulkan_error("vkQueueSubmit", result);
    }
    if (VkResult result = fn.vkWaitForFences(s.device, 1, &s.fence, VK_TRUE, UINT64_MAX); result != VK_SUCCESS) {
        s.lost = result == VK_ERROR_DEVICE_LOST;
        return vk::vulkan_error("vkWaitForFences", result);
    }
    if (VkResult result = fn.vkResetFences(s.device, 1, &s.fence); result != VK_SUCCESS) {
        return vk::vulkan_error("vkResetFences", result);
    }
    return {};
}

RendererCreateInfo renderer_create_info(const HeadlessContext& context) {
    RendererCreateInfo info;
    info.instance = context.instance();
    info.get_instance_proc_addr = context.get_instance_proc_addr();
    info.physical_device = context.physical_device();
    info.device = context.device();
    info.queue_family = context.queue_family();
    info.enabled_features = context.enabled_features();
    info.allocator = context.allocation_callbacks();
    return info;
}

CompositorCreateInfo compositor_create_info(const HeadlessContext& context) {
    CompositorCreateInfo info;
    info.instance = context.instance();
    info.get_instance_proc_addr = context.get_instance_proc_addr();
    info.physical_device = context.physical_device();
    info.device = context.device();
    info.allocator = context.allocation_callbacks();
    info.enabled_features = context.enabled_features();
    return info;
}

}  // namespace crisp
