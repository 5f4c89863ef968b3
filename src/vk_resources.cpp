// Buffers and images with their own memory, and the HeadlessContext helpers that move bytes
// between them and the host.
#include "vk_resources.hpp"

#include "vk_barriers.hpp"
#include "vk_memory.hpp"

#include "embedded_shaders.hpp"

#include <crisp/vulkan_context.hpp>

#include <algorithm>

#include <cassert>
#include <cstring>
#include <utility>

namespace crisp {

namespace vk {

Error vulkan_error(std::string_view call, VkResult result) {
    const ErrorCode code = result == VK_ERROR_DEVICE_LOST ? ErrorCode::device_lost : ErrorCode::vulkan;
    return Error{code, std::string(call) + " failed: " + vk_result_name(result)};
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
                    const char* what, DeviceImage& out) {
    out.reset();
    out.adopt(device);  // what is made below is given back by out.reset() on failure
    VkImageCreateInfo image{};
    image.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    image.imageType = VK_IMAGE_TYPE_2D;
    image.format = format;
    image.extent = {width, height, 1};
    image.mipLevels = 1;
    image.arrayLayers = 1;
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
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
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
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (VkResult r = device.fn->vkCreateComputePipelines(device.device, device.pipeline_cache, 1, &info,
                                                         device.allocator, &pipeline);
        r != VK_SUCCESS) {
        return vulkan_error(std::string("vkCreateComputePipelines (") + what + ")", r);
    }
    name_object(device, VK_OBJECT_TYPE_PIPELINE, pipeline, what);
    return pipeline;
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

namespace {

using vk::image_barrier;
using vk::memory_barrier;

bool is_depth_or_stencil(VkFormat format) {
    switch (format) {
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_S8_UINT:
        case VK_FORMAT_D16_UNORM_S8_UINT:
        case VK_FORMAT_D24_UNORM_S8_UINT:
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
            return true;
        default:
            return false;
    }
}

// Image views are only allowed for images with at least one of these usages.
constexpr VkImageUsageFlags kViewUsages = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;

// True when [offset, offset + size) lies inside a resource of `capacity` bytes, without overflow.
bool range_fits(VkDeviceSize offset, VkDeviceSize size, VkDeviceSize capacity) {
    return offset <= capacity && size <= capacity - offset;
}

VkImageSubresourceRange color_range() {
    VkImageSubresourceRange range{};
    range.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    range.levelCount = 1;
    range.layerCount = 1;
    return range;
}

VkBufferImageCopy whole_image_copy(VkExtent2D extent) {
    VkBufferImageCopy region{};
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    region.imageSubresource.layerCount = 1;
    region.imageExtent = {extent.width, extent.height, 1};
    return region;  // bufferRowLength 0: rows are tightly packed
}

bool is_real_layout(VkImageLayout layout) {
    return layout != VK_IMAGE_LAYOUT_UNDEFINED && layout != VK_IMAGE_LAYOUT_PREINITIALIZED;
}

}  // namespace

// --- Buffer ---------------------------------------------------------------------------------------

Buffer::Buffer(Buffer&& other) noexcept
    : fn_(std::exchange(other.fn_, nullptr)),
      device_(std::exchange(other.device_, VK_NULL_HANDLE)),
      buffer_(std::exchange(other.buffer_, VK_NULL_HANDLE)),
      memory_(std::exchange(other.memory_, VK_NULL_HANDLE)),
      size_(std::exchange(other.size_, 0)),
      usage_(std::exchange(other.usage_, 0)),
      mapped_(std::exchange(other.mapped_, {})) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
    if (this != &other) {
        destroy();
        fn_ = std::exchange(other.fn_, nullptr);
        device_ = std::exchange(other.device_, VK_NULL_HANDLE);
        buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
        size_ = std::exchange(other.size_, 0);
        usage_ = std::exchange(other.usage_, 0);
        mapped_ = std::exchange(other.mapped_, {});
    }
    return *this;
}

Buffer::~Buffer() {
    destroy();
}

void Buffer::destroy() {
    if (device_ == VK_NULL_HANDLE) return;
    // The buffer goes before the memory bound to it.
    if (buffer_ != VK_NULL_HANDLE) fn_->vkDestroyBuffer(device_, buffer_, nullptr);
    if (memory_ != VK_NULL_HANDLE) fn_->vkFreeMemory(device_, memory_, nullptr);  // also unmaps
    device_ = VK_NULL_HANDLE;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    size_ = 0;
    usage_ = 0;
    mapped_ = {};
}

// --- Image ----------------------------------------------------------------------------------------

Image::Image(Image&& other) noexcept
    : fn_(std::exchange(other.fn_, nullptr)),
      device_(std::exchange(other.device_, VK_NULL_HANDLE)),
      image_(std::exchange(other.image_, VK_NULL_HANDLE)),
      view_(std::exchange(other.view_, VK_NULL_HANDLE)),
      memory_(std::exchange(other.memory_, VK_NULL_HANDLE)),
      format_(std::exchange(other.format_, VK_FORMAT_UNDEFINED)),
      extent_(std::exchange(other.extent_, {0, 0})),
      usage_(std::exchange(other.usage_, 0)) {}

Image& Image::operator=(Image&& other) noexcept {
    if (this != &other) {
        destroy();
        fn_ = std::exchange(other.fn_, nullptr);
        device_ = std::exchange(other.device_, VK_NULL_HANDLE);
        image_ = std::exchange(other.image_, VK_NULL_HANDLE);
        view_ = std::exchange(other.view_, VK_NULL_HANDLE);
        memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
        format_ = std::exchange(other.format_, VK_FORMAT_UNDEFINED);
        extent_ = std::exchange(other.extent_, {0, 0});
        usage_ = std::exchange(other.usage_, 0);
    }
    return *this;
}

Image::~Image() {
    destroy();
}

void Image::destroy() {
    if (device_ == VK_NULL_HANDLE) return;
    // View, then image, then the memory bound to it.
    if (view_ != VK_NULL_HANDLE) fn_->vkDestroyImageView(device_, view_, nullptr);
    if (image_ != VK_NULL_HANDLE) fn_->vkDestroyImage(device_, image_, nullptr);
    if (memory_ != VK_NULL_HANDLE) fn_->vkFreeMemory(device_, memory_, nullptr);
    device_ = VK_NULL_HANDLE;
    image_ = VK_NULL_HANDLE;
    view_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    format_ = VK_FORMAT_UNDEFINED;
    extent_ = {0, 0};
    usage_ = 0;
}

// --- HeadlessContext: buffers -----------------------------------------------------------------------

Result<Buffer> HeadlessContext::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage memory) {
    if (size == 0) return Error{ErrorCode::invalid_argument, "create_buffer: the size is 0"};
    VkMemoryPropertyFlags required = 0;
    VkMemoryPropertyFlags preferred = 0;
    switch (memory) {
        case MemoryUsage::device_local:
            required = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
            break;
        case MemoryUsage::upload:
            // Coherent memory needs no flush; every implementation has a HOST_VISIBLE |
            // HOST_COHERENT type.
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            break;
        case MemoryUsage::readback:
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;  // uncached reads crawl on discrete GPUs
            break;
    }

    const VkDevice vk_device = device();
    Buffer buffer;  // owns whatever exists so far, so every early return cleans up
    buffer.fn_ = &functions();
    buffer.device_ = vk_device;
    buffer.size_ = size;
    buffer.usage_ = usage;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (VkResult result = functions().vkCreateBuffer(vk_device, &info, nullptr, &buffer.buffer_);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateBuffer", result);
    }
    VkMemoryRequirements requirements{};
    functions().vkGetBufferMemoryRequirements(vk_device, buffer.buffer_, &requirements);
    const std::optional<uint32_t> type =
        vk::find_memory_type(memory_properties(), requirements.memoryTypeBits, required, preferred);
    if (!type) {
        return Error{ErrorCode::vulkan, "create_buffer: no memory type with property flags " +
                                            std::to_string(required) + " suits this buffer"};
    }
    VkMemoryAllocateInfo allocation{};
    allocation.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocation.allocationSize = requirements.size;
    allocation.memoryTypeIndex = *type;
    if (VkResult result = functions().vkAllocateMemory(vk_device, &allocation, nullptr, &buffer.memory_);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkAllocateMemory", result);
    }
    if (VkResult result = functions().vkBindBufferMemory(vk_device, buffer.buffer_, buffer.memory_, 0);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkBindBufferMemory", result);
    }
    if (memory != MemoryUsage::device_local) {
        void* mapped = nullptr;
        if (VkResult result = functions().vkMapMemory(vk_device, buffer.memory_, 0, VK_WHOLE_SIZE, 0, &mapped);
            result != VK_SUCCESS) {
            return vk::vulkan_error("vkMapMemory", result);
        }
        buffer.mapped_ = std::span<std::byte>(static_cast<std::byte*>(mapped), static_cast<size_t>(size));
    }
    return buffer;
}

Result<Buffer> HeadlessContext::create_buffer_with_data(std::span<const std::byte> bytes, VkBufferUsageFlags usage) {
    if (bytes.empty()) return Error{ErrorCode::invalid_argument, "create_buffer_with_data: no bytes"};
    Result<Buffer> buffer =
        create_buffer(bytes.size(), usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::device_local);
    if (!buffer) return buffer;
    if (Status uploaded = upload(*buffer, bytes); !uploaded) return uploaded.error();
    return buffer;
}

Status HeadlessContext::upload(const Buffer& destination, std::span<const std::byte> bytes, VkDeviceSize offset) {
    if (!range_fits(offset, bytes.size(), destination.size())) {
        return Error{ErrorCode::invalid_argument, "upload: " + std::to_string(bytes.size()) + " bytes at offset " +
                                                      std::to_string(offset) + " do not fit a buffer of " +
                                                      std::to_string(destination.size()) + " bytes"};
    }
    if (bytes.empty()) return {};
    if (!destination.mapped().empty()) {
        // Host writes before a submission are visible to it without a barrier.
        std::memcpy(destination.mapped().data() + offset, bytes.data(), bytes.size());
        return {};
    }
    if ((destination.usage() & VK_BUFFER_USAGE_TRANSFER_DST_BIT) == 0) {
        return Error{ErrorCode::invalid_argument, "upload: the buffer lacks VK_BUFFER_USAGE_TRANSFER_DST_BIT"};
    }
    Result<Buffer> staging = create_buffer(bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::upload);
    if (!staging) return staging.error();
    std::memcpy(staging->mapped().data(), bytes.data(), bytes.size());
    return submit_and_wait([&](VkCommandBuffer commands) {
        // Earlier GPU work may still read or write the range being overwritten.
        memory_barrier(functions(), commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        VkBufferCopy region{};
        region.dstOffset = offset;
        region.size = bytes.size();
        functions().vkCmdCopyBuffer(commands, staging->handle(), destination.handle(), 1, &region);
        // So that later submissions may use the data without a barrier of their own.
        memory_barrier(functions(), commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    });
}

Result<std::vector<std::byte>> HeadlessContext::read_buffer(const Buffer& source, VkDeviceSize offset,
                                                            VkDeviceSize size) {
    if (!range_fits(offset, size, source.size())) {
        return Error{ErrorCode::invalid_argument, "read_buffer: " + std::to_string(size) + " bytes at offset " +
                                                      std::to_string(offset) + " do not fit a buffer of " +
                                                      std::to_string(source.size()) + " bytes"};
    }
    std::vector<std::byte> bytes(static_cast<size_t>(size));
    if (size == 0) return bytes;
    if (!source.mapped().empty()) {
        // GPU writes reach the host only through a barrier to the host stage.
        Status made_visible = submit_and_wait([&](VkCommandBuffer commands) {
            memory_barrier(functions(), commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
                           VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        });
        if (!made_visible) return made_visible.error();
        std::memcpy(bytes.data(), source.mapped().data() + offset, bytes.size());
        return bytes;
    }
    if ((source.usage() & VK_BUFFER_USAGE_TRANSFER_SRC_BIT) == 0) {
        return Error{ErrorCode::invalid_argument, "read_buffer: the buffer lacks VK_BUFFER_USAGE_TRANSFER_SRC_BIT"};
    }
    Result<Buffer> staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    if (!staging) return staging.error();
    Status copied = submit_and_wait([&](VkCommandBuffer commands) {
        memory_barrier(functions(), commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        VkBufferCopy region{};
        region.srcOffset = offset;
        region.size = size;
        functions().vkCmdCopyBuffer(commands, source.handle(), staging->handle(), 1, &region);
        memory_barrier(functions(), commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    });
    if (!copied) return copied.error();
    std::memcpy(bytes.data(), staging->mapped().data(), bytes.size());
    return bytes;
}

// --- HeadlessContext: images ------------------------------------------------------------------------

Result<Image> HeadlessContext::create_image(const ImageDesc& desc) {
    if (desc.width == 0 || desc.height == 0) {
        return Error{ErrorCode::invalid_argument, "create_image: the extent " + std::to_string(desc.width) + "x" +
                                                      std::to_string(desc.height) + " is empty"};
    }
    if (is_depth_or_stencil(desc.format)) {
        return Error{ErrorCode::invalid_argument, "create_image: depth and stencil formats are not supported"};
    }
    const VkFormat view_format = desc.view_format != VK_FORMAT_UNDEFINED ? desc.view_format : desc.format;
    const VkImageCreateFlags flags =
        view_format != desc.format ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_EXTENDED_USAGE_BIT : 0;
    VkImageFormatProperties limits{};
    VkResult supported = functions().vkGetPhysicalDeviceImageFormatProperties(
        physical_device(), desc.format, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL, desc.usage, flags, &limits);
    if (supported == VK_ERROR_FORMAT_NOT_SUPPORTED ||
        (supported == VK_SUCCESS && (desc.width > limits.maxExtent.width || desc.height > limits.maxExtent.height))) {
        return Error{ErrorCode::vulkan, "create_image: the device does not support a " + std::to_string(desc.width) +
                                            "x" + std::to_string(desc.height) + " image of VkFormat " +
                                            std::to_string(static_cast<int>(desc.format)) + " with usage flags " +
                                            std::to_string(desc.usage)};
    }
    if (supported != VK_SUCCESS) return vk::vulkan_error("vkGetPhysicalDeviceImageFormatProperties", supported);

    const VkDevice vk_device = device();
    Image image;  // owns whatever exists so far, so every early return cleans up
    image.fn_ = &functions();
    image.device_ = vk_device;
    image.format_ = desc.format;
    image.extent_ = {desc.width, desc.height};
    image.usage_ = desc.usage;
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.flags = flags;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = desc.format;
    info.extent = {desc.width, desc.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = desc.usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (VkResult result = functions().vkCreateImage(vk_device, &info, nullptr, &image.image_); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateImage", result);
    }
    VkMemoryRequirements requirements{};
    functions().vkGetImageMemoryRequirements(vk_device, image.image_, &requirements);
    const std::optional<uint32_t> type =
        vk::find_memory_type(memory_properties(), requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (!type) return Error{ErrorCode::vulkan, "create_image: no device-local memory type suits this image"};
    VkMemoryAllocateInfo allocation{};
    allocation.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocation.allocationSize = requirements.size;
    allocation.memoryTypeIndex = *type;
    if (VkResult result = functions().vkAllocateMemory(vk_device, &allocation, nullptr, &image.memory_);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkAllocateMemory", result);
    }
    if (VkResult result = functions().vkBindImageMemory(vk_device, image.image_, image.memory_, 0);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkBindImageMemory", result);
    }
    if ((desc.usage & kViewUsages) != 0) {
        VkImageViewCreateInfo view_info{};
        view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
        view_info.image = image.image_;
        view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view_info.format = view_format;
        view_info.subresourceRange = color_range();
        if (VkResult result = functions().vkCreateImageView(vk_device, &view_info, nullptr, &image.view_);
            result != VK_SUCCESS) {
            return vk::vulkan_error("vkCreateImageView", result);
        }
    }
    return image;
}

Status HeadlessContext::upload(const Image& destination, std::span<const std::byte> bytes, VkImageLayout final_layout) {
    const uint32_t texel_size = format_texel_size(destination.format());
    if (texel_size == 0) {
        return Error{ErrorCode::invalid_argument, "upload: VkFormat " +
                                                      std::to_string(static_cast<int>(destination.format())) +
                                                      " is not one the image helpers move"};
    }
    const VkDeviceSize expected = VkDeviceSize{destination.extent().width} * destination.extent().height * texel_size;
    if (bytes.size() != expected) {
        return Error{ErrorCode::invalid_argument, "upload: " + std::to_string(bytes.size()) + " bytes given, the " +
                                                      std::to_string(destination.extent().width) + "x" +
                                                      std::to_string(destination.extent().height) + " image holds " +
                                                      std::to_string(expected)};
    }
    if ((destination.usage() & VK_IMAGE_USAGE_TRANSFER_DST_BIT) == 0) {
        return Error{ErrorCode::invalid_argument, "upload: the image lacks VK_IMAGE_USAGE_TRANSFER_DST_BIT"};
    }
    if (!is_real_layout(final_layout)) {
        return Error{ErrorCode::invalid_argument, "upload: the final layout must not be UNDEFINED or PREINITIALIZED"};
    }
    Result<Buffer> staging = create_buffer(expected, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::upload);
    if (!staging) return staging.error();
    std::memcpy(staging->mapped().data(), bytes.data(), bytes.size());
    return submit_and_wait([&](VkCommandBuffer commands) {
        // From UNDEFINED: the old contents are discarded, but earlier work on the image must finish.
        image_barrier(functions(), commands, destination.handle(), VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                      VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        const VkBufferImageCopy region = whole_image_copy(destination.extent());
        functions().vkCmdCopyBufferToImage(commands, staging->handle(), destination.handle(),
                                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        image_barrier(functions(), commands, destination.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, final_layout,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                      VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    });
}

Result<std::vector<std::byte>> HeadlessContext::read_image(const Image& source, VkImageLayout layout) {
    const uint32_t texel_size = format_texel_size(source.format());
    if (texel_size == 0) {
        return Error{ErrorCode::invalid_argument, "read_image: VkFormat " +
                                                      std::to_string(static_cast<int>(source.format())) +
                                                      " is not one the image helpers move"};
    }
    if ((source.usage() & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) == 0) {
        return Error{ErrorCode::invalid_argument, "read_image: the image lacks VK_IMAGE_USAGE_TRANSFER_SRC_BIT"};
    }
    if (!is_real_layout(layout)) {
        return Error{ErrorCode::invalid_argument,
                     "read_image: an image in layout UNDEFINED or PREINITIALIZED has no "
                     "contents to read"};
    }
    const VkDeviceSize size = VkDeviceSize{source.extent().width} * source.extent().height * texel_size;
    Result<Buffer> staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    if (!staging) return staging.error();
    Status copied = submit_and_wait([&](VkCommandBuffer commands) {
        image_barrier(functions(), commands, source.handle(), layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        const VkBufferImageCopy region = whole_image_copy(source.extent());
        functions().vkCmdCopyImageToBuffer(commands, source.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                           staging->handle(), 1, &region);
        // Back to the caller's layout; later work must wait for the copy's reads.
        image_barrier(functions(), commands, source.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                      VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
        memory_barrier(functions(), commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    });
    if (!copied) return copied.error();
    return std::vector<std::byte>(staging->mapped().begin(), staging->mapped().end());
}

// --- Free functions -------------------------------------------------------------------------------

uint32_t format_texel_size(VkFormat format) {
    switch (format) {
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R8_SRGB:
        case VK_FORMAT_R8_UINT:
            return 1;
        case VK_FORMAT_R8G8_UNORM:
        case VK_FORMAT_R8G8_SRGB:
        case VK_FORMAT_R8G8_UINT:
            return 2;
        case VK_FORMAT_R8G8B8A8_UNORM:
        case VK_FORMAT_R8G8B8A8_SRGB:
        case VK_FORMAT_R8G8B8A8_UINT:
        case VK_FORMAT_B8G8R8A8_UNORM:
        case VK_FORMAT_B8G8R8A8_SRGB:
        case VK_FORMAT_R32_UINT:
        case VK_FORMAT_R32_SINT:
        case VK_FORMAT_R32_SFLOAT:
            return 4;
        case VK_FORMAT_R16G16B16A16_SFLOAT:
        case VK_FORMAT_R32G32_UINT:
        case VK_FORMAT_R32G32_SINT:
        case VK_FORMAT_R32G32_SFLOAT:
            return 8;
        case VK_FORMAT_R32G32B32A32_UINT:
        case VK_FORMAT_R32G32B32A32_SINT:
        case VK_FORMAT_R32G32B32A32_SFLOAT:
            return 16;
        default:
            return 0;
    }
}

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
