#include "vk/context.hpp"

#include <string>

namespace crisp::vk {

Status check_instance_version(uint32_t instance_api_version, const char* who) {
    if (instance_api_version >= VK_API_VERSION_1_2) return {};
    const std::string given =
        instance_api_version == 0 ? "not given (0)" : "Vulkan " + version_string(instance_api_version);
    return Error{ErrorCode::invalid_argument,
                 std::string(who) + ": instance_api_version is " + given +
                     ": crisp's shaders are SPIR-V for Vulkan 1.2, so the instance must be created with apiVersion "
                     "VK_API_VERSION_1_2 or later, and instance_api_version set to it"};
}

Context::Context(const Functions& functions, const VkPhysicalDeviceProperties& device_properties,
                 const DeviceFeatures& features, const ContextCreateInfo& info)
    : fn(functions),
      properties(device_properties),
      enabled(features),
      ref(make_device_ref(fn, info.physical_device, info.device, info.allocator, info.pipeline_cache)),
      arena(fn, info.device, info.allocator, ref.memory_properties) {
    ref.arena = &arena;
    if (enabled.pipeline_executable_info) ref.statistics = &shader_statistics;
}

Context::~Context() = default;

Result<std::unique_ptr<Context>> Context::create(const ContextCreateInfo& info) {
    Functions fn;
    if (Status s = load_functions(info.get_instance_proc_addr, info.instance, info.device, fn); !s) {
        return Error{s.error().code, std::string(info.who) + ": " + s.error().message, s.error().vk_result};
    }
    VkPhysicalDeviceProperties properties{};
    fn.vkGetPhysicalDeviceProperties(info.physical_device, &properties);
    if (properties.apiVersion < info.min_api_version) {
        return Error{ErrorCode::vulkan, std::string(info.who) + ": " + properties.deviceName + " offers Vulkan " +
                                            version_string(properties.apiVersion) + "; crisp needs " +
                                            std::to_string(VK_API_VERSION_MAJOR(info.min_api_version)) + "." +
                                            std::to_string(VK_API_VERSION_MINOR(info.min_api_version))};
    }
    Result<DeviceFeatures> enabled = read_enabled_features(info.enabled_features, info.who);
    if (!enabled) return enabled.error();
    return std::unique_ptr<Context>(new Context(fn, properties, *enabled, info));
}

}  // namespace crisp::vk
