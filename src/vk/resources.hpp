// The private Vulkan layer's objects: the DeviceRef everything is made from, move-only owners of
// buffers, images, descriptor sets and pipelines with the functions that make them, and the error
// values, memory-type choice and device checks they share.
#pragma once

#include "vk/functions.hpp"

#include <crisp/device_features.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

namespace crisp::vk {

// ErrorCode::vulkan (ErrorCode::device_lost for VK_ERROR_DEVICE_LOST) with "`call` failed:
// VK_ERROR_..." as the message and `result` as its vk_result.
Error vulkan_error(std::string_view call, VkResult result);

// The index of a memory type allowed by `type_bits` (VkMemoryRequirements::memoryTypeBits) that
// has every `required` flag, preferring one that also has every `preferred` flag; nullopt if none.
std::optional<uint32_t> find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, uint32_t type_bits,
                                         VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred);

// True when compute shaders on the device may use subgroup arithmetic (subgroupAdd, subgroupMax,
// ...): the rasterizer and the tile compositor both do.
bool has_compute_subgroup_arithmetic(const Functions& fn, VkPhysicalDevice physical_device);

// "1.3.230".
std::string version_string(uint32_t version);

class MemoryArena;
struct DeviceRef;

// Move-only ownership of `Fields` (plain handles) made on a device: reset() and the destructor
// give them back through Free with the DeviceRef they were made with, so that the objects that
// hold them need no hand-written destructor. The DeviceRef must outlive the owner (it is the
// member of the renderer's or compositor's state that every part is made from).
template <class Fields, void (*Free)(const DeviceRef&, Fields&)>
class Owner : public Fields {
public:
    Owner() = default;
    Owner(Owner&& other) noexcept
        : Fields(std::exchange(static_cast<Fields&>(other), Fields{})), owner_(std::exchange(other.owner_, nullptr)) {}
    Owner& operator=(Owner&& other) noexcept {
        if (this != &other) {
            reset();
            static_cast<Fields&>(*this) = std::exchange(static_cast<Fields&>(other), Fields{});
            owner_ = std::exchange(other.owner_, nullptr);
        }
        return *this;
    }
    Owner(const Owner&) = delete;
    Owner& operator=(const Owner&) = delete;
    ~Owner() { reset(); }

    // Gives everything back (nothing for an empty owner).
    void reset() {
        if (owner_ != nullptr) Free(*owner_, *this);
        static_cast<Fields&>(*this) = Fields{};
        owner_ = nullptr;
    }
    // Makes the owner responsible for what its fields now hold, made on `device`.
    void adopt(const DeviceRef& device) { owner_ = &device; }

private:
    const DeviceRef* owner_ = nullptr;
};

// A buffer and its memory: a range of an arena's block (DeviceRef::arena), or memory of its own.
// Host-visible ones stay mapped (coherent).
struct BufferFields {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;  // the block's, when suballocated
    void* mapped = nullptr;
    VkDeviceSize size = 0;
    VkDeviceSize memory_offset = 0;  // where in `memory` the buffer lies
    VkDeviceSize memory_size = 0;    // bytes of `memory` it takes
    bool suballocated = false;
};
void free_buffer(const DeviceRef& device, BufferFields& buffer);
using DeviceBuffer = Owner<BufferFields, free_buffer>;

// The device objects buffers and pipelines are made with, and the functions they are made through.
struct DeviceRef {
    const Functions* fn = nullptr;  // owned by whoever made the DeviceRef; outlives it
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    const VkAllocationCallbacks* allocator = nullptr;
    VkPhysicalDeviceMemoryProperties memory_properties{};
    VkPipelineCache pipeline_cache = VK_NULL_HANDLE;  // the caller's, or none
    // Where buffers take their memory (create_buffer); null: each buffer its own allocation.
    MemoryArena* arena = nullptr;
    // Where pipelines made from this ref report the driver's statistics of their shaders (made with
    // VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR); null: not captured. Set only where the device
    // enabled pipelineExecutableInfo (DeviceFeatures::pipeline_executable_info).
    std::vector<ShaderStatistic>* statistics = nullptr;
};

// The pipeline creation flags of `device`: capture statistics where it collects them.
VkPipelineCreateFlags pipeline_create_flags(const DeviceRef& device);
// Appends the statistics of every executable of `pipeline`, named `what`, to *device.statistics
// (nothing where it is null). A driver that fails to report leaves them out: statistics are a
// diagnostic, never a reason for a pipeline to fail.
void collect_statistics(const DeviceRef& device, VkPipeline pipeline, std::string_view what);

// A DeviceRef for `device`, calling through `fn` (which must outlive it): its memory properties
// and the caller's pipeline cache.
DeviceRef make_device_ref(const Functions& fn, VkPhysicalDevice physical_device, VkDevice device,
                          const VkAllocationCallbacks* allocator, VkPipelineCache pipeline_cache);

// Names `handle` "crisp <what>" for debuggers and the validation layer; nothing without
// VK_EXT_debug_utils.
void name_object(const DeviceRef& device, VkObjectType type, uint64_t handle, std::string_view what);
template <typename Handle>
void name_object(const DeviceRef& device, VkObjectType type, Handle handle, std::string_view what) {
    name_object(device, type, reinterpret_cast<uint64_t>(handle), what);
}

// Makes `out` (at least 16 bytes): device-local, or host-visible and coherent and mapped, named
// `what`; its memory comes from the device's arena where it has one. On failure `out` is left
// empty and the error names the call and `what`.
Status create_buffer(const DeviceRef& device, VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible,
                     const char* what, DeviceBuffer& out);

// A 2D colour image (optimal tiling, `mip_levels` levels) in device-local memory, with a view of all
// of it: a 2D image and view, or with array_layers > 0 an array of that many layers and a 2D array view.
struct ImageFields {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;  // its own
    VkImageView view = VK_NULL_HANDLE;
    VkDeviceSize memory_size = 0;
};
void free_image(const DeviceRef& device, ImageFields& image);
using DeviceImage = Owner<ImageFields, free_image>;

// Makes `out` in VK_IMAGE_LAYOUT_UNDEFINED. On failure what was made is destroyed and the error
// names the call and `what` ("atlas").
Status create_image(const DeviceRef& device, VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage,
                    const char* what, DeviceImage& out, uint32_t array_layers = 0, uint32_t mip_levels = 1);

// One descriptor set layout, a pipeline layout over it with one push-constant range at offset 0,
// and a pool holding `sets.size()` sets of it (one per frame in flight, typically).
struct DescriptorSetsFields {
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    std::vector<VkDescriptorSet> sets;
};
void free_descriptor_sets(const DeviceRef& device, DescriptorSetsFields& sets);
using DescriptorSets = Owner<DescriptorSetsFields, free_descriptor_sets>;

// Makes `out`; on failure what was made is destroyed and the error names the call and `what`.
Status create_descriptor_sets(const DeviceRef& device, std::span<const VkDescriptorSetLayoutBinding> bindings,
                              VkShaderStageFlags push_stages, uint32_t push_bytes, uint32_t set_count, const char* what,
                              DescriptorSets& out);

// The pipelines, shader modules, render passes, framebuffers and samplers an object made, destroyed with it
// (newest first) through the DeviceRef they were made with, which must outlive it. keep() takes
// ownership of a handle and returns it, so that a part keeps using plain handles.
class DeviceObjects {
public:
    DeviceObjects() = default;
    DeviceObjects(DeviceObjects&& other) noexcept;
    DeviceObjects& operator=(DeviceObjects&& other) noexcept;
    DeviceObjects(const DeviceObjects&) = delete;
    DeviceObjects& operator=(const DeviceObjects&) = delete;
    ~DeviceObjects() { reset(); }

    template <class Handle>
    Handle keep(const DeviceRef& device, Handle handle) {
        static_assert(type_of<Handle>() != VK_OBJECT_TYPE_UNKNOWN, "DeviceObjects keeps no such type");
        keep(device, type_of<Handle>(), reinterpret_cast<uint64_t>(handle));
        return handle;
    }
    void reset();  // destroys everything kept

private:
    template <class Handle>
    static constexpr VkObjectType type_of() {
        if constexpr (std::is_same_v<Handle, VkPipeline>) return VK_OBJECT_TYPE_PIPELINE;
        if constexpr (std::is_same_v<Handle, VkShaderModule>) return VK_OBJECT_TYPE_SHADER_MODULE;
        if constexpr (std::is_same_v<Handle, VkRenderPass>) return VK_OBJECT_TYPE_RENDER_PASS;
        if constexpr (std::is_same_v<Handle, VkFramebuffer>) return VK_OBJECT_TYPE_FRAMEBUFFER;
        if constexpr (std::is_same_v<Handle, VkSampler>) return VK_OBJECT_TYPE_SAMPLER;
        return VK_OBJECT_TYPE_UNKNOWN;
    }
    void keep(const DeviceRef& device, VkObjectType type, uint64_t handle);

    const DeviceRef* device_ = nullptr;
    std::vector<std::pair<VkObjectType, uint64_t>> objects_;
};

// A compute pipeline of `module`'s "main" with `layout`.
Result<VkPipeline> create_compute_pipeline(const DeviceRef& device, VkShaderModule module, VkPipelineLayout layout,
                                           const VkSpecializationInfo* specialization, const char* what);

// A shader module from SPIR-V embedded in the library ("raster.comp"); `name` must be embedded.
Result<VkShaderModule> create_embedded_shader(const DeviceRef& device, std::string_view name);

}  // namespace crisp::vk
