// The private Vulkan layer's objects, their owners and the errors they make (vk/resources.hpp).
#include "vk/resources.hpp"

#include "vk/barriers.hpp"
#include "vk/memory.hpp"

#include "embedded_shaders.hpp"

#include <crisp/device_features.hpp>

#include <algorithm>

#include <cassert>
#include <cstring>
#include <utility>

namespace crisp {

namespace vk {

Error vulkan_error(std::string_view call, VkResult result) {
    const ErrorCode code = result == VK_ERROR_DEVICE_LOST ? ErrorCode::device_lost : ErrorCode::vulkan;
    return Error{code, std::string(call) + " failed: " + vk_result_name(result), result};
}

std::optional<uint32_t> find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, uint32_t type_bits,
                                         VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
    std::optional<uint32_t> fallback;
    for (uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
        if ((type_bits & (1u << i)) == 0) continue;
        const VkMemoryPropertyFlags flags = properties.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (!fallback) fallback = i;
    }
    return fallback;
}

bool has_compute_subgroup_arithmetic(const Functions& fn, VkPhysicalDevice physical_device) {
    VkPhysicalDeviceSubgroupProperties subgroup{};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    VkPhysicalDeviceProperties2 properties{};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &subgroup;
    fn.vkGetPhysicalDeviceProperties2(physical_device, &properties);
    return (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
           (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0;
}

std::string version_string(uint32_t version) {
    return std::to_string(VK_API_VERSION_MAJOR(version)) + "." + std::to_string(VK_API_VERSION_MINOR(version)) + "." +
           std::to_string(VK_API_VERSION_PATCH(version));
}

DeviceRef make_device_ref(const Functions& fn, VkPhysicalDevice physical_device, VkDevice device,
                          const VkAllocationCallbacks* allocator, VkPipelineCache pipeline_cache) {
    DeviceRef ref;
    ref.fn = &fn;
    ref.physical_device = physical_device;
    ref.device = device;
    ref.allocator = allocator;
    ref.pipeline_cache = pipeline_cache;
    fn.vkGetPhysicalDeviceMemoryProperties(physical_device, &ref.memory_properties);
    return ref;
}

void name_object(const DeviceRef& device, VkObjectType type, uint64_t handle, std::string_view what) {
    if (!device.fn->vkSetDebugUtilsObjectNameEXT || handle == 0) return;
    const std::string name = "crisp " + std::string(what);
    VkDebugUtilsObjectNameInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT;
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    device.fn->vkSetDebugUtilsObjectNameEXT(device.device, &info);  // a failed name changes nothing crisp does
}

namespace {

// A VkDeviceMemory of its own for one resource, into `memory` and its size into `size`; `suffix`
// (" (what)") ends the error message.
Status allocate_own_memory(const DeviceRef& device, const VkMemoryRequirements& requirements, uint32_t type,
                           const std::string& suffix, VkDeviceMemory& memory, VkDeviceSize& size) {
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    if (VkResult r = device.fn->vkAllocateMemory(device.device, &allocate, device.allocator, &memory);
        r != VK_SUCCESS) {
        return vulkan_error("vkAllocateMemory" + suffix, r);
    }
    size = requirements.size;
    return {};
}

}  // namespace

Status create_buffer(const DeviceRef& device, VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible,
                     const char* what, DeviceBuffer& out) {
    out.reset();
    out.adopt(device);  // what is made below is given back by out.reset() on failure
    const std::string suffix = std::string(" (") + what + ")";
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = std::max<VkDeviceSize>(size, 16);
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (VkResult r = device.fn->vkCreateBuffer(device.device, &info, device.allocator, &out.buffer); r != VK_SUCCESS) {
        return vulkan_error("vkCreateBuffer" + suffix, r);
    }
    out.size = info.size;
    VkMemoryRequirements requirements{};
    device.fn->vkGetBufferMemoryRequirements(device.device, out.buffer, &requirements);
    const VkMemoryPropertyFlags required =
        host_visible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                     : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    // Host-visible buffers carry per-frame uploads the GPU reads: device-local memory the host can
    // map (resizable BAR) saves the GPU reading them across the bus, where there is such memory.
    const VkMemoryPropertyFlags preferred = host_visible ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : 0;
    const auto type = find_memory_type(device.memory_properties, requirements.memoryTypeBits, required, preferred);
    if (!type) {
        out.reset();
        return Error{ErrorCode::vulkan, "no memory type for a buffer of " + std::to_string(size) + " bytes" + suffix};
    }
    if (device.arena != nullptr) {
        Result<MemoryArena::Range> range = device.arena->allocate(requirements, *type, what);
        if (!range) {
            out.reset();
            return range.error();
        }
        out.memory = range->memory;
        out.memory_offset = range->offset;
        out.memory_size = range->size;
        out.mapped = range->mapped;
        out.suballocated = true;
    } else {
        if (Status s = allocate_own_memory(device, requirements, *type, suffix, out.memory, out.memory_size); !s) {
            out.reset();
            return s;
        }
        if (host_visible) {
            if (VkResult r = device.fn->vkMapMemory(device.device, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
                r != VK_SUCCESS) {
                out.reset();
                return vulkan_error("vkMapMemory" + suffix, r);
            }
        }
        name_object(device, VK_OBJECT_TYPE_DEVICE_MEMORY, out.memory, what);
    }
    if (VkResult r = device.fn->vkBindBufferMemory(device.device, out.buffer, out.memory, out.memory_offset);
        r != VK_SUCCESS) {
        out.reset();
        return vulkan_error("vkBindBufferMemory" + suffix, r);
    }
    name_object(device, VK_OBJECT_TYPE_BUFFER, out.buffer, what);
    return {};
}

void free_buffer(const DeviceRef& device, BufferFields& buffer) {
    if (buffer.buffer) device.fn->vkDestroyBuffer(device.device, buffer.buffer, device.allocator);
    if (buffer.suballocated) {
        device.arena->free({buffer.memory, buffer.memory_offset, buffer.memory_size, nullptr});
    } else if (buffer.memory) {
        device.fn->vkFreeMemory(device.device, buffer.memory, device.allocator);
    }
}

Status create_image(const DeviceRef& device, VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage,
                    const char* what, DeviceImage& out, uint32_t array_layers, uint32_t mip_levels) {
    out.reset();
    out.adopt(device);  // what is made below is given back by out.reset() on failure
    VkImageCreateInfo image{};
    image.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    image.imageType = VK_IMAGE_TYPE_2D;
    image.format = format;
    image.extent = {width, height, 1};
    image.mipLevels = mip_levels;
    image.arrayLayers = std::max(array_layers, 1u);
    image.samples = VK_SAMPLE_COUNT_1_BIT;
    image.tiling = VK_IMAGE_TILING_OPTIMAL;
    image.usage = usage;
    image.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    image.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    const std::string suffix = std::string(" (") + what + ")";
    if (VkResult r = device.fn->vkCreateImage(device.device, &image, device.allocator, &out.image); r != VK_SUCCESS) {
        return vulkan_error("vkCreateImage" + suffix, r);
    }
    VkMemoryRequirements requirements{};
    device.fn->vkGetImageMemoryRequirements(device.device, out.image, &requirements);
    const auto type =
        find_memory_type(device.memory_properties, requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (!type) {
        out.reset();
        return Error{ErrorCode::vulkan, std::string("no device-local memory type for the ") + what + " image"};
    }
    if (Status s = allocate_own_memory(device, requirements, *type, suffix, out.memory, out.memory_size); !s) {
        out.reset();
        return s;
    }
    device.fn->vkBindImageMemory(device.device, out.image, out.memory, 0);
    VkImageViewCreateInfo view{};
    view.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    view.image = out.image;
    view.viewType = array_layers > 0 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mip_levels, 0, image.arrayLayers};
    if (VkResult r = device.fn->vkCreateImageView(device.device, &view, device.allocator, &out.view); r != VK_SUCCESS) {
        out.reset();
        return vulkan_error("vkCreateImageView" + suffix, r);
    }
    name_object(device, VK_OBJECT_TYPE_IMAGE, out.image, what);
    name_object(device, VK_OBJECT_TYPE_DEVICE_MEMORY, out.memory, what);
    name_object(device, VK_OBJECT_TYPE_IMAGE_VIEW, out.view, what);
    return {};
}

void free_image(const DeviceRef& device, ImageFields& image) {
    if (image.view) device.fn->vkDestroyImageView(device.device, image.view, device.allocator);
    if (image.image) device.fn->vkDestroyImage(device.device, image.image, device.allocator);
    if (image.memory) device.fn->vkFreeMemory(device.device, image.memory, device.allocator);
}

Status create_descriptor_sets(const DeviceRef& device, std::span<const VkDescriptorSetLayoutBinding> bindings,
                              VkShaderStageFlags push_stages, uint32_t push_bytes, uint32_t set_count, const char* what,
                              DescriptorSets& out) {
    out.reset();
    out.adopt(device);  // what is made below is given back by out.reset() on failure
    const std::string suffix = std::string(" (") + what + ")";
    auto failed = [&](const char* call, VkResult r) {
        out.reset();
        return vulkan_error(call + suffix, r);
    };
    VkDescriptorSetLayoutCreateInfo set_info{};
    set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    set_info.bindingCount = static_cast<uint32_t>(bindings.size());
    set_info.pBindings = bindings.data();
    if (VkResult r =
            device.fn->vkCreateDescriptorSetLayout(device.device, &set_info, device.allocator, &out.set_layout);
        r != VK_SUCCESS) {
        return failed("vkCreateDescriptorSetLayout", r);
    }
    const VkPushConstantRange push{push_stages, 0, push_bytes};
    VkPipelineLayoutCreateInfo layout_info{};
    layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &out.set_layout;
    layout_info.pushConstantRangeCount = push_bytes > 0 ? 1 : 0;
    layout_info.pPushConstantRanges = &push;
    if (VkResult r =
            device.fn->vkCreatePipelineLayout(device.device, &layout_info, device.allocator, &out.pipeline_layout);
        r != VK_SUCCESS) {
        return failed("vkCreatePipelineLayout", r);
    }
    // The pool holds exactly the descriptors of set_count sets.
    std::vector<VkDescriptorPoolSize> sizes;
    for (const VkDescriptorSetLayoutBinding& binding : bindings) {
        auto it = std::find_if(sizes.begin(), sizes.end(),
                               [&](const VkDescriptorPoolSize& size) { return size.type == binding.descriptorType; });
        if (it == sizes.end()) it = sizes.insert(sizes.end(), {binding.descriptorType, 0});
        it->descriptorCount += binding.descriptorCount * set_count;
    }
    VkDescriptorPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    pool_info.maxSets = set_count;
    pool_info.poolSizeCount = static_cast<uint32_t>(sizes.size());
    pool_info.pPoolSizes = sizes.data();
    if (VkResult r = device.fn->vkCreateDescriptorPool(device.device, &pool_info, device.allocator, &out.pool);
        r != VK_SUCCESS) {
        return failed("vkCreateDescriptorPool", r);
    }
    const std::vector<VkDescriptorSetLayout> layouts(set_count, out.set_layout);
    out.sets.resize(set_count);
    VkDescriptorSetAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    allocate.descriptorPool = out.pool;
    allocate.descriptorSetCount = set_count;
    allocate.pSetLayouts = layouts.data();
    if (VkResult r = device.fn->vkAllocateDescriptorSets(device.device, &allocate, out.sets.data()); r != VK_SUCCESS) {
        return failed("vkAllocateDescriptorSets", r);
    }
    name_object(device, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, out.set_layout, what);
    name_object(device, VK_OBJECT_TYPE_PIPELINE_LAYOUT, out.pipeline_layout, what);
    name_object(device, VK_OBJECT_TYPE_DESCRIPTOR_POOL, out.pool, what);
    for (VkDescriptorSet set : out.sets) name_object(device, VK_OBJECT_TYPE_DESCRIPTOR_SET, set, what);
    return {};
}

void free_descriptor_sets(const DeviceRef& device, DescriptorSetsFields& sets) {
    if (sets.pool) device.fn->vkDestroyDescriptorPool(device.device, sets.pool, device.allocator);  // frees the sets
    if (sets.pipeline_layout) device.fn->vkDestroyPipelineLayout(device.device, sets.pipeline_layout, device.allocator);
    if (sets.set_layout) device.fn->vkDestroyDescriptorSetLayout(device.device, sets.set_layout, device.allocator);
}

DeviceObjects::DeviceObjects(DeviceObjects&& other) noexcept
    : device_(std::exchange(other.device_, nullptr)), objects_(std::exchange(other.objects_, {})) {}

DeviceObjects& DeviceObjects::operator=(DeviceObjects&& other) noexcept {
    if (this != &other) {
        reset();
        device_ = std::exchange(other.device_, nullptr);
        objects_ = std::exchange(other.objects_, {});
    }
    return *this;
}

void DeviceObjects::keep(const DeviceRef& device, VkObjectType type, uint64_t handle) {
    assert((device_ == nullptr || device_ == &device) && "one DeviceObjects per device reference");
    device_ = &device;
    if (handle != 0) objects_.emplace_back(type, handle);
}
void DeviceObjects::reset() {
    for (auto it = objects_.rbegin(); it != objects_.rend(); ++it) {
        const DeviceRef& d = *device_;
        switch (it->first) {
            case VK_OBJECT_TYPE_PIPELINE:
                d.fn->vkDestroyPipeline(d.device, reinterpret_cast<VkPipeline>(it->second), d.allocator);
                break;
            case VK_OBJECT_TYPE_SHADER_MODULE:
                d.fn->vkDestroyShaderModule(d.device, reinterpret_cast<VkShaderModule>(it->second), d.allocator);
                break;
            case VK_OBJECT_TYPE_RENDER_PASS:
                d.fn->vkDestroyRenderPass(d.device, reinterpret_cast<VkRenderPass>(it->second), d.allocator);
                break;
            case VK_OBJECT_TYPE_FRAMEBUFFER:
                d.fn->vkDestroyFramebuffer(d.device, reinterpret_cast<VkFramebuffer>(it->second), d.allocator);
                break;
            case VK_OBJECT_TYPE_SAMPLER:
                d.fn->vkDestroySampler(d.device, reinterpret_cast<VkSampler>(it->second), d.allocator);
                break;
            default:
                assert(false && "DeviceObjects keeps no other type");
        }
    }
    objects_.clear();
}

Result<VkPipeline> create_compute_pipeline(const DeviceRef& device, VkShaderModule module, VkPipelineLayout layout,
                                           const VkSpecializationInfo* specialization, const char* what) {
    VkComputePipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = specialization;
    info.layout = layout;
    info.flags = pipeline_create_flags(device);
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (VkResult r = device.fn->vkCreateComputePipelines(device.device, device.pipeline_cache, 1, &info,
                                                         device.allocator, &pipeline);
        r != VK_SUCCESS) {
        return vulkan_error(std::string("vkCreateComputePipelines (") + what + ")", r);
    }
    name_object(device, VK_OBJECT_TYPE_PIPELINE, pipeline, what);
    collect_statistics(device, pipeline, what);
    return pipeline;
}

VkPipelineCreateFlags pipeline_create_flags(const DeviceRef& device) {
    return device.statistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
}

namespace {

double statistic_value(const VkPipelineExecutableStatisticKHR& s) {
    switch (s.format) {
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
            return s.value.b32 ? 1.0 : 0.0;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
            return static_cast<double>(s.value.i64);
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
            return static_cast<double>(s.value.u64);
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR:
            return s.value.f64;
        default:
            return 0.0;
    }
}

}  // namespace

void collect_statistics(const DeviceRef& device, VkPipeline pipeline, std::string_view what) {
    const Functions& fn = *device.fn;
    if (!device.statistics || !fn.vkGetPipelineExecutablePropertiesKHR || !fn.vkGetPipelineExecutableStatisticsKHR) {
        return;
    }
    VkPipelineInfoKHR pipeline_info{};
    pipeline_info.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR;
    pipeline_info.pipeline = pipeline;
    uint32_t count = 0;
    if (fn.vkGetPipelineExecutablePropertiesKHR(device.device, &pipeline_info, &count, nullptr) != VK_SUCCESS) return;
    std::vector<VkPipelineExecutablePropertiesKHR> executables(count);
    for (auto& e : executables) e.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR;
    if (fn.vkGetPipelineExecutablePropertiesKHR(device.device, &pipeline_info, &count, executables.data()) !=
        VK_SUCCESS) {
        return;
    }
    executables.resize(count);
    for (uint32_t index = 0; index < count; ++index) {
        VkPipelineExecutableInfoKHR executable_info{};
        executable_info.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR;
        executable_info.pipeline = pipeline;
        executable_info.executableIndex = index;
        uint32_t stat_count = 0;
        if (fn.vkGetPipelineExecutableStatisticsKHR(device.device, &executable_info, &stat_count, nullptr) !=
            VK_SUCCESS) {
            continue;
        }
        std::vector<VkPipelineExecutableStatisticKHR> stats(stat_count);
        for (auto& s : stats) s.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
        if (fn.vkGetPipelineExecutableStatisticsKHR(device.device, &executable_info, &stat_count, stats.data()) !=
            VK_SUCCESS) {
            continue;
        }
        stats.resize(stat_count);
        for (const auto& s : stats) {
            device.statistics->push_back(
                ShaderStatistic{std::string(what), executables[index].name, s.name, s.description, statistic_value(s)});
        }
    }
}

Result<VkShaderModule> create_embedded_shader(const DeviceRef& device, std::string_view name) {
    const shaders::EmbeddedShader* code = shaders::find_embedded_shader(name);
    if (!code) return Error{ErrorCode::vulkan, "the shader " + std::string(name) + " is not embedded in this build"};
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = code->size;
    info.pCode = code->code;
    VkShaderModule module = VK_NULL_HANDLE;
    if (VkResult r = device.fn->vkCreateShaderModule(device.device, &info, device.allocator, &module);
        r != VK_SUCCESS) {
        return vulkan_error("vkCreateShaderModule (" + std::string(name) + ")", r);
    }
    name_object(device, VK_OBJECT_TYPE_SHADER_MODULE, module, name);
    return module;
}

}  // namespace vk

std::string vk_result_name(VkResult result) {
#define CRISP_VK_RESULT_CASE(name) \
    case name:                     \
        return #name;
    switch (result) {
        CRISP_VK_RESULT_CASE(VK_SUCCESS)
        CRISP_VK_RESULT_CASE(VK_NOT_READY)
        CRISP_VK_RESULT_CASE(VK_TIMEOUT)
        CRISP_VK_RESULT_CASE(VK_EVENT_SET)
        CRISP_VK_RESULT_CASE(VK_EVENT_RESET)
        CRISP_VK_RESULT_CASE(VK_INCOMPLETE)
        CRISP_VK_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        CRISP_VK_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        CRISP_VK_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
        CRISP_VK_RESULT_CASE(VK_ERROR_DEVICE_LOST)
        CRISP_VK_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
        CRISP_VK_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        CRISP_VK_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        CRISP_VK_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        CRISP_VK_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        CRISP_VK_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        CRISP_VK_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        CRISP_VK_RESULT_CASE(VK_ERROR_FRAGMENTED_POOL)
        CRISP_VK_RESULT_CASE(VK_ERROR_UNKNOWN)
        CRISP_VK_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        CRISP_VK_RESULT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        CRISP_VK_RESULT_CASE(VK_ERROR_FRAGMENTATION)
        CRISP_VK_RESULT_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        CRISP_VK_RESULT_CASE(VK_PIPELINE_COMPILE_REQUIRED)
        CRISP_VK_RESULT_CASE(VK_ERROR_SURFACE_LOST_KHR)
        CRISP_VK_RESULT_CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
        CRISP_VK_RESULT_CASE(VK_SUBOPTIMAL_KHR)
        CRISP_VK_RESULT_CASE(VK_ERROR_OUT_OF_DATE_KHR)
        CRISP_VK_RESULT_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
        default:
            break;
    }
#undef CRISP_VK_RESULT_CASE
    return "VkResult " + std::to_string(static_cast<int>(result));
}

}  // namespace crisp
