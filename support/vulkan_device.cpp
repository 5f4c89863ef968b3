// The instance (validation layer and messenger), the choice of a physical device and queue family,
// and the device: the steps HeadlessContext and crisp-layout-editor's window both make theirs by.
#include "vulkan_device.hpp"

#include "vk/features.hpp"
#include "vk/resources.hpp"

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <cstring>
#include <utility>

namespace crisp {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// Enough recent messages to see what went wrong without keeping an unbounded log.
constexpr size_t kKeptValidationMessages = 16;

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

// The first queue family of `device` that does graphics and compute and passes the caller's check;
// fills the candidate's family. False when there is none.
bool choose_queue_family(const vk::Functions& fn, const DeviceRequirements& requirements, PhysicalDevice& candidate) {
    uint32_t family_count = 0;
    fn.vkGetPhysicalDeviceQueueFamilyProperties(candidate.handle, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    fn.vkGetPhysicalDeviceQueueFamilyProperties(candidate.handle, &family_count, families.data());
    families.resize(family_count);
    // Graphics and compute together imply transfer; one queue keeps ownership transfers away.
    const VkQueueFlags wanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    for (uint32_t family = 0; family < family_count; ++family) {
        const VkQueueFamilyProperties& f = families[family];
        if ((f.queueFlags & wanted) != wanted || f.queueCount == 0) continue;
        if (requirements.queue_family_check && !requirements.queue_family_check(candidate.handle, family)) continue;
        candidate.queue_family = family;
        candidate.queue_family_properties = f;
        return true;
    }
    return false;
}

// The extensions the device is made with: the required ones, each once (listing one twice is
// harmless to the caller but invalid for vkCreateDevice), then the statistics one where offered.
std::vector<std::string> device_extensions(const DeviceRequirements& requirements, bool pipeline_statistics) {
    std::vector<std::string> wanted = requirements.required_extensions;
    if (pipeline_statistics) wanted.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    std::vector<std::string> extensions;
    for (const std::string& name : wanted) {
        if (std::find(extensions.begin(), extensions.end(), name) == extensions.end()) extensions.push_back(name);
    }
    return extensions;
}

// Empty when `candidate` meets every requirement; otherwise what it lacks. Fills the candidate's
// properties, queue family and features (`required`, plus what requirements.crisp_needs adds).
std::vector<std::string> check_device(const vk::Functions& fn, VkInstance instance, PhysicalDevice& candidate,
                                      const DeviceRequirements& requirements, const vk::DeviceFeatures& required) {
    std::vector<std::string> lacks;
    const uint32_t device_version = candidate.properties.apiVersion;
    if (!meets_version(device_version, requirements.api_version)) {
        lacks.push_back("the device supports Vulkan " + vk::version_string(device_version) + " only, below " +
                        vk::version_string(requirements.api_version));
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

    if (!choose_queue_family(fn, requirements, candidate)) {
        std::string no_family = "the device has no queue family with both graphics and compute";
        if (requirements.queue_family_check) no_family += " that " + requirements.queue_family_check_name;
        lacks.push_back(no_family);
    }

    uint32_t extension_count = 0;
    fn.vkEnumerateDeviceExtensionProperties(candidate.handle, nullptr, &extension_count, nullptr);
    std::vector<VkExtensionProperties> extensions(extension_count);
    fn.vkEnumerateDeviceExtensionProperties(candidate.handle, nullptr, &extension_count, extensions.data());
    extensions.resize(extension_count);
    for (const std::string& name : requirements.required_extensions) {
        if (!has_extension(extensions, name.c_str())) lacks.push_back("the device lacks extension " + name);
    }
    if (requirements.shader_statistics &&
        has_extension(extensions, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME)) {
        VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable{};
        executable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
        VkPhysicalDeviceFeatures2 features{};
        features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        features.pNext = &executable;
        fn.vkGetPhysicalDeviceFeatures2(candidate.handle, &features);
        candidate.pipeline_statistics = executable.pipelineExecutableInfo == VK_TRUE;
    }

    auto features = std::make_shared<vk::DeviceFeatures>(required);
    candidate.features = features;
    if (requirements.crisp_needs) {
        VkPhysicalDeviceFeatures2* chain = features->link(true);
        if (Status s = add_crisp_features(instance, candidate.handle, *chain, *requirements.crisp_needs,
                                          fn.vkGetInstanceProcAddr);
            !s) {
            lacks.push_back(s.error().message);
            return lacks;
        }
    }
    const bool vulkan13 = meets_version(device_version, VK_API_VERSION_1_3) &&
                          meets_version(requirements.api_version, VK_API_VERSION_1_3);
    const std::vector<std::string> missing =
        vk::missing_features(*features, vk::query_features(fn, candidate.handle, vulkan13));
    if (!missing.empty()) lacks.push_back("the device lacks " + join(missing, ", "));

    const VkSubgroupFeatureFlags wanted_operations = requirements.required_compute_subgroup_operations;
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

void ValidationLog::add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* text) {
    const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
    std::lock_guard lock(mutex_);
    (error ? messages_.errors : messages_.warnings)++;
    recent_.push_back(std::string(error ? "error: " : "warning: ") + (text != nullptr ? text : "(no text)"));
    if (recent_.size() > kKeptValidationMessages) recent_.pop_front();
    if (!echo_prefix_.empty()) {
        std::fprintf(stderr, "%svalidation %s: %s\n", echo_prefix_.c_str(), error ? "error" : "warning",
                     text != nullptr ? text : "");
    }
}

ValidationMessages ValidationLog::snapshot() const {
    std::lock_guard lock(mutex_);
    ValidationMessages copy = messages_;
    copy.recent.assign(recent_.begin(), recent_.end());
    return copy;
}

struct VulkanInstance::State {
    vk::Functions fn;
    VkInstance instance = VK_NULL_HANDLE;
    uint32_t api_version = 0;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    // An instance whose functions failed to load cannot be destroyed; it is leaked.
    ~State() {
        if (messenger != VK_NULL_HANDLE) destroy_messenger(instance, messenger, nullptr);
        if (instance != VK_NULL_HANDLE && fn.vkDestroyInstance != nullptr) fn.vkDestroyInstance(instance, nullptr);
    }

    Status create_messenger(const VkDebugUtilsMessengerCreateInfoEXT& info);
};

// The messenger that logs the validation layer's messages after instance creation.
Status VulkanInstance::State::create_messenger(const VkDebugUtilsMessengerCreateInfoEXT& info) {
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

// The instance (with the validation layer and its messenger where asked for), after checking the
// loader's version.
Result<VulkanInstance> VulkanInstance::create(const InstanceOptions& options) {
    assert((!options.validation || options.validation_log != nullptr) && "validation needs a log");
    VulkanInstance created;
    created.state_ = std::make_unique<State>();
    State& s = *created.state_;
    vk::Functions& fn = s.fn;
    if (Status status = vk::load_functions(options.get_instance_proc_addr, VK_NULL_HANDLE, VK_NULL_HANDLE, fn);
        !status) {
        return status.error();
    }
    uint32_t loader_version = VK_API_VERSION_1_0;
    if (fn.vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS ||
        !meets_version(loader_version, options.minimum_version)) {
        return Error{ErrorCode::vulkan, "the Vulkan loader supports Vulkan " + vk::version_string(loader_version) +
                                            ", below the " + vk::version_string(options.minimum_version) +
                                            " crisp needs"};
    }

    std::vector<const char*> layers;
    std::vector<const char*> extensions = options.extensions;
    VkDebugUtilsMessengerCreateInfoEXT messenger_create = messenger_info(options.validation_log);
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
    application.pApplicationName = options.application_name;
    application.pEngineName = "crisp";
    application.apiVersion = options.api_version;
    s.api_version = options.api_version;
    VkInstanceCreateInfo instance_info{};
    instance_info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    // Chained here too so that messages from vkCreateInstance and vkDestroyInstance are counted.
    instance_info.pNext = options.validation ? &messenger_create : nullptr;
    instance_info.pApplicationInfo = &application;
    instance_info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    instance_info.ppEnabledLayerNames = layers.data();
    instance_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    instance_info.ppEnabledExtensionNames = extensions.data();
    if (VkResult result = fn.vkCreateInstance(&instance_info, nullptr, &s.instance); result != VK_SUCCESS) {
        if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
            return Error{ErrorCode::vulkan,
                         "no Vulkan driver supports Vulkan " + vk::version_string(options.api_version) +
                             " (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER)",
                         result};
        }
        return vk::vulkan_error("vkCreateInstance", result);
    }
    if (Status status = vk::load_functions(fn.vkGetInstanceProcAddr, s.instance, VK_NULL_HANDLE, fn); !status) {
        return status.error();
    }
    if (options.validation) {
        messenger_create.pNext = nullptr;  // the validation features belong to the instance only
        if (Status status = s.create_messenger(messenger_create); !status) return status.error();
    }
    return created;
}

VulkanInstance::VulkanInstance() = default;
VulkanInstance::VulkanInstance(VulkanInstance&& other) noexcept = default;
VulkanInstance& VulkanInstance::operator=(VulkanInstance&& other) noexcept = default;
VulkanInstance::~VulkanInstance() = default;

VkInstance VulkanInstance::handle() const {
    return state_ ? state_->instance : VK_NULL_HANDLE;
}
uint32_t VulkanInstance::api_version() const {
    return state_ ? state_->api_version : 0;
}
const vk::Functions& VulkanInstance::functions() const {
    return state_->fn;
}

void add_crisp_needs(DeviceRequirements& requirements) {
    if (!requirements.crisp_needs) return;
    if (requirements.crisp_needs->draw_path) {
        requirements.api_version = std::max(requirements.api_version, VK_API_VERSION_1_3);
    }
    requirements.required_compute_subgroup_operations |=
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
}

namespace {

// The features `requirements` (with crisp's needs added) asks for, or why they are malformed.
Result<vk::DeviceFeatures> copy_required_features(const DeviceRequirements& requirements) {
    if (!meets_version(requirements.api_version, VK_API_VERSION_1_2)) {
        return Error{ErrorCode::invalid_argument,
                     "api_version " + vk::version_string(requirements.api_version) + " is below crisp's floor of 1.2"};
    }
    return vk::copy_required_features(requirements.required_features, requirements.api_version);
}

}  // namespace

Status check_requirements(const DeviceRequirements& given) {
    DeviceRequirements requirements = given;
    add_crisp_needs(requirements);
    if (Result<vk::DeviceFeatures> required = copy_required_features(requirements); !required) {
        return required.error();
    }
    return {};
}

// The best device that meets every requirement (discrete > integrated > virtual > CPU), or an
// error naming each device and what it lacks.
Result<PhysicalDevice> choose_physical_device(const VulkanInstance& instance, const DeviceRequirements& given) {
    DeviceRequirements requirements = given;
    add_crisp_needs(requirements);
    Result<vk::DeviceFeatures> required = copy_required_features(requirements);
    if (!required) return required.error();
    const vk::Functions& fn = instance.functions();
    uint32_t device_count = 0;
    if (VkResult result = fn.vkEnumeratePhysicalDevices(instance.handle(), &device_count, nullptr);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkEnumeratePhysicalDevices", result);
    }
    std::vector<VkPhysicalDevice> devices(device_count);
    if (VkResult result = fn.vkEnumeratePhysicalDevices(instance.handle(), &device_count, devices.data());
        result != VK_SUCCESS && result != VK_INCOMPLETE) {
        return vk::vulkan_error("vkEnumeratePhysicalDevices", result);
    }
    devices.resize(device_count);
    if (devices.empty()) return Error{ErrorCode::vulkan, "no Vulkan device found"};

    std::vector<std::string> names;
    std::vector<std::string> rejections;
    std::optional<PhysicalDevice> chosen;
    for (VkPhysicalDevice handle : devices) {
        PhysicalDevice candidate;
        candidate.handle = handle;
        fn.vkGetPhysicalDeviceProperties(handle, &candidate.properties);
        const std::string name = candidate.properties.deviceName;
        names.push_back(name);
        if (name.find(requirements.device_name_contains) == std::string::npos) continue;
        const std::vector<std::string> lacks = check_device(fn, instance.handle(), candidate, requirements, *required);
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
            return Error{ErrorCode::vulkan, "no Vulkan device name contains \"" + requirements.device_name_contains +
                                                "\"; the devices are: " + join(names, ", ")};
        }
        return Error{ErrorCode::vulkan, "no suitable Vulkan device: " + join(rejections, " | ")};
    }
    chosen->api_version = std::min(requirements.api_version, chosen->properties.apiVersion);
    fn.vkGetPhysicalDeviceMemoryProperties(chosen->handle, &chosen->memory_properties);
    chosen->extensions = device_extensions(requirements, chosen->pipeline_statistics);
    return *chosen;
}

struct VulkanDevice::State {
    vk::Functions fn;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    vk::DeviceFeatures enabled;  // what the device was created with
    // Linked after `enabled`'s structures where shader_statistics found it offered.
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable_features{};
    VkPhysicalDeviceFeatures2* enabled_chain = nullptr;
    std::vector<std::string> enabled_extensions;

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    // A device whose functions failed to load cannot be destroyed; it is leaked.
    ~State() {
        if (device != VK_NULL_HANDLE && fn.vkDestroyDevice != nullptr) fn.vkDestroyDevice(device, nullptr);
    }
};

// The device from `chosen`, with exactly its features (the required ones and crisp's) and
// extensions, and its queue.
Result<VulkanDevice> VulkanDevice::create(const VulkanInstance& instance, const PhysicalDevice& chosen) {
    VulkanDevice created;
    created.state_ = std::make_unique<State>();
    State& s = *created.state_;
    const vk::Functions& instance_fn = instance.functions();
    vk::DeviceFeatures required = *chosen.features;
    s.enabled_extensions = chosen.extensions;
    s.executable_features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
    s.executable_features.pipelineExecutableInfo = chosen.pipeline_statistics ? VK_TRUE : VK_FALSE;
    // Puts executable_features right after `chain`'s head where it is enabled.
    const auto with_statistics = [&](VkPhysicalDeviceFeatures2* chain) {
        if (chosen.pipeline_statistics) {
            s.executable_features.pNext = chain->pNext;
            chain->pNext = &s.executable_features;
        }
        return chain;
    };

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = chosen.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    std::vector<const char*> extensions;
    for (const std::string& name : s.enabled_extensions) extensions.push_back(name.c_str());
    VkDeviceCreateInfo device_info{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    // Exactly what the caller required; the 1.3 structure only when it asks for something, since
    // a 1.2 device must not see it.
    device_info.pNext = with_statistics(required.link(required.any_vulkan13()));
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    device_info.ppEnabledExtensionNames = extensions.data();
    if (VkResult result = instance_fn.vkCreateDevice(chosen.handle, &device_info, nullptr, &s.device);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateDevice", result);
    }
    if (Status status = vk::load_functions(instance_fn.vkGetInstanceProcAddr, instance.handle(), s.device, s.fn);
        !status) {
        return status.error();
    }
    s.enabled = required;
    s.enabled_chain = with_statistics(s.enabled.link(true));
    s.fn.vkGetDeviceQueue(s.device, chosen.queue_family, 0, &s.queue);
    return created;
}

VulkanDevice::VulkanDevice() = default;
VulkanDevice::VulkanDevice(VulkanDevice&& other) noexcept = default;
VulkanDevice& VulkanDevice::operator=(VulkanDevice&& other) noexcept = default;
VulkanDevice::~VulkanDevice() = default;

VkDevice VulkanDevice::handle() const {
    return state_ ? state_->device : VK_NULL_HANDLE;
}
VkQueue VulkanDevice::queue() const {
    return state_->queue;
}
const vk::Functions& VulkanDevice::functions() const {
    return state_->fn;
}
const VkPhysicalDeviceFeatures2* VulkanDevice::enabled_features() const {
    return state_->enabled_chain;
}
const std::vector<std::string>& VulkanDevice::enabled_extensions() const {
    return state_->enabled_extensions;
}

}  // namespace crisp
