// crisp support (not installed): a headless Vulkan context for tools and tests, the buffers and
// images it creates, and the renderer's and compositor's create infos for it.
//
// A renderer is created from the caller's Vulkan objects (instance, physical device, device, queue
// family, queue); an engine already owns those. Tools and tests have no engine, so HeadlessContext
// makes them: an instance (with the Khronos validation layer on request), a device that meets a
// Vulkan version floor and the features and extensions the caller requires, one queue that does
// graphics, compute and transfer, and a few helpers to move bytes in and out of the GPU.
//
// Nothing here is global: each context owns its objects and its validation log, so two contexts
// on two devices (or on one) live side by side. A context and the resources it creates are
// move-only; resources must be destroyed before the context that made them.
#pragma once

#include "vulkan_device.hpp"

#include <crisp/compositor.hpp>
#include <crisp/device_features.hpp>
#include <crisp/renderer.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace crisp {

// How a buffer's memory is used; picks the memory type (one VkDeviceMemory per resource).
enum class MemoryUsage {
    device_local,  // GPU only; filled by transfers (upload) or shaders
    upload,        // host writes, GPU reads: HOST_VISIBLE | HOST_COHERENT, persistently mapped
    readback,      // GPU writes, host reads: as upload, HOST_CACHED preferred so reads are fast
};

// A VkBuffer with its own VkDeviceMemory and, for host-visible usages, a persistent mapping.
// Move-only; the destructor frees both. It must not outlive the context that created it, and must
// not be destroyed while the GPU still uses it.
class Buffer {
public:
    Buffer() = default;
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&& other) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    ~Buffer();

    VkBuffer handle() const { return buffer_; }
    VkDeviceMemory memory() const { return memory_; }
    VkDeviceSize size() const { return size_; }
    VkBufferUsageFlags usage() const { return usage_; }
    // The mapped bytes of an upload or readback buffer (coherent: no flush or invalidate needed);
    // empty for a device_local buffer.
    std::span<std::byte> mapped() const { return mapped_; }

private:
    friend class HeadlessContext;
    void destroy();

    const vk::Functions* fn_ = nullptr;
    VkDevice device_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    VkBufferUsageFlags usage_ = 0;
    std::span<std::byte> mapped_;
};

// What create_image makes: a 2D colour image with one mip level and one layer, in device-local
// memory, with optimal tiling.
struct ImageDesc {
    VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
    uint32_t width = 0;
    uint32_t height = 0;
    // Add TRANSFER_DST to upload into it and TRANSFER_SRC to read it back.
    VkImageUsageFlags usage = 0;
    // The view's format when it differs (R8G8B8A8_UNORM over B8G8R8A8_UNORM, say); the image is
    // then made with MUTABLE_FORMAT and EXTENDED_USAGE, so `usage` need only suit the view's
    // format. VK_FORMAT_UNDEFINED: the view has `format`.
    VkFormat view_format = VK_FORMAT_UNDEFINED;
};

// A VkImage with its own VkDeviceMemory and a 2D colour view (the view is VK_NULL_HANDLE when
// the usage allows no view: transfer-only images). Move-only; same lifetime rules as Buffer.
class Image {
public:
    Image() = default;
    Image(Image&& other) noexcept;
    Image& operator=(Image&& other) noexcept;
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;
    ~Image();

    VkImage handle() const { return image_; }
    VkImageView view() const { return view_; }
    VkDeviceMemory memory() const { return memory_; }
    VkFormat format() const { return format_; }
    VkExtent2D extent() const { return extent_; }
    VkImageUsageFlags usage() const { return usage_; }

private:
    friend class HeadlessContext;
    void destroy();

    const vk::Functions* fn_ = nullptr;
    VkDevice device_ = VK_NULL_HANDLE;
    VkImage image_ = VK_NULL_HANDLE;
    VkImageView view_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkExtent2D extent_ = {0, 0};
    VkImageUsageFlags usage_ = 0;
};

// What the device must have (DeviceRequirements, support/vulkan_device.hpp: its api_version is
// also what the instance asks for and the floor the loader must meet), and whether to validate.
struct HeadlessContextOptions : DeviceRequirements {
    // Turn on VK_LAYER_KHRONOS_validation and count its messages (validation_messages()).
    // create() fails, saying so, when the layer is not installed.
    bool validation = false;
    // With validation: also turn on the layer's synchronization validation (missing or wrong
    // barriers), which costs more CPU time.
    bool synchronization_validation = false;
};

// Owns a Vulkan instance, a device, one queue and a command pool for one-off submissions.
// Move-only; the destructor waits for the device to go idle and then destroys everything in
// reverse order of creation. The submission and resource helpers use one command buffer and are
// not thread-safe: call them from one thread at a time. A moved-from context is empty: only
// destruction and assignment are allowed.
class HeadlessContext {
public:
    // Fails with ErrorCode::vulkan when there is no Vulkan driver, the validation layer was asked
    // for and is absent, or no device meets the requirements; the message names each device and
    // what it lacks ("llvmpipe (LLVM 15.0.6, 256 bits): the device lacks descriptorIndexing").
    // Fails with ErrorCode::invalid_argument when the options themselves are malformed.
    static Result<HeadlessContext> create(const HeadlessContextOptions& options);

    HeadlessContext(HeadlessContext&& other) noexcept;
    HeadlessContext& operator=(HeadlessContext&& other) noexcept;
    HeadlessContext(const HeadlessContext&) = delete;
    HeadlessContext& operator=(const HeadlessContext&) = delete;
    ~HeadlessContext();

    // The objects a renderer is created from.
    VkInstance instance() const;
    uint32_t instance_api_version() const;  // the apiVersion the instance was created with
    VkPhysicalDevice physical_device() const;
    VkDevice device() const;
    uint32_t queue_family() const;
    // The feature chain the device was created with (exactly what required_features asked for),
    // for RendererCreateInfo::enabled_features and CompositorCreateInfo::enabled_features. Valid
    // while the context lives.
    const VkPhysicalDeviceFeatures2* enabled_features() const;
    VkQueue queue() const;
    // The loader entry point the context was made through, for
    // RendererCreateInfo::get_instance_proc_addr and CompositorCreateInfo::get_instance_proc_addr.
    PFN_vkGetInstanceProcAddr get_instance_proc_addr() const;
    // The functions the context calls through, for crisp's own tools and tests (the type is in
    // the private src/vk/functions.hpp).
    const vk::Functions& functions() const;
    // crisp uses the driver's allocator: always nullptr, passed wherever Vulkan takes one.
    const VkAllocationCallbacks* allocation_callbacks() const { return nullptr; }

    // What was picked.
    const std::string& device_name() const;
    const std::string& driver_name() const;  // "llvmpipe" (VkPhysicalDeviceDriverProperties)
    const std::string& driver_info() const;  // "Mesa 22.3.6 (LLVM 15.0.6)"
    VkDriverId driver_id() const;
    uint32_t driver_version() const;  // vendor-specific encoding, as the driver reports it
    // The version usable on this device: the lower of the requested api_version and the
    // device's own.
    uint32_t api_version() const;
    const VkPhysicalDeviceProperties& properties() const;
    const VkPhysicalDeviceMemoryProperties& memory_properties() const;
    // Subgroup size, stages and operations (pNext is null).
    const VkPhysicalDeviceSubgroupProperties& subgroup_properties() const;
    // True when compute shaders may use subgroupAdd/Min/Max/... (GL_KHR_shader_subgroup_arithmetic).
    bool supports_compute_subgroup_arithmetic() const;
    const std::vector<std::string>& enabled_extensions() const;

    // The validation layer's messages so far; all zero and empty without validation. Safe to
    // call from any thread.
    ValidationMessages validation_messages() const;

    // Records commands with `record` into a one-time command buffer, submits it to the queue and
    // waits for it to finish. Work submitted earlier on this context has finished too when it
    // returns, but its writes are only visible to `record` after a barrier. Errors: vulkan for a
    // failed call; device_lost when the submission or the wait lost the device, and for every
    // later call (the context is then good only for destruction).
    Status submit_and_wait(const std::function<void(VkCommandBuffer)>& record);

    // A buffer of `size` bytes (> 0) with its own memory. For upload and readback buffers the
    // memory is mapped. Fails with ErrorCode::vulkan when no memory type fits or allocation fails.
    Result<Buffer> create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage memory);
    // A device-local buffer holding `bytes` (not empty), usage | TRANSFER_DST, filled through a
    // staging buffer; returns once the copy has finished.
    Result<Buffer> create_buffer_with_data(std::span<const std::byte> bytes, VkBufferUsageFlags usage);
    // Copies `bytes` into `destination` at `offset` through a staging buffer (or directly when the
    // buffer is mapped) and waits. Fails with invalid_argument when the range does not fit or a
    // device-local destination lacks TRANSFER_DST usage.
    Status upload(const Buffer& destination, std::span<const std::byte> bytes, VkDeviceSize offset = 0);
    // Copies `size` bytes at `offset` of `source` back to the host. Earlier GPU writes to the
    // buffer from this context's queue are made visible first.
    Result<std::vector<std::byte>> read_buffer(const Buffer& source, VkDeviceSize offset, VkDeviceSize size);

    // A 2D colour image with a view (see ImageDesc). Fails with invalid_argument for a zero
    // extent or a depth/stencil format, with vulkan when the device does not support the format
    // with that usage or allocation fails.
    Result<Image> create_image(const ImageDesc& desc);
    // Fills the whole image with tightly packed rows of texels (width * height * texel size bytes)
    // and leaves it in `final_layout`; the previous contents are discarded. Formats: see
    // format_texel_size().
    Status upload(const Image& destination, std::span<const std::byte> bytes, VkImageLayout final_layout);
    // Reads the whole image, which is in `layout` (not UNDEFINED), back as tightly packed rows and
    // leaves it in that layout. Earlier GPU writes from this context's queue are made visible.
    Result<std::vector<std::byte>> read_image(const Image& source, VkImageLayout layout);
    // Reads `regions` of a single-level colour image made elsewhere (a renderer's atlas), which is
    // in `layout` (not UNDEFINED) and was made with VK_IMAGE_USAGE_TRANSFER_SRC_BIT, into
    // `buffer_bytes` bytes laid out as the regions' buffer offsets say, and leaves it in that
    // layout. Earlier GPU writes from this context's queue are made visible.
    Result<std::vector<std::byte>> read_image_regions(VkImage source, VkImageLayout layout,
                                                      std::span<const VkBufferImageCopy> regions,
                                                      VkDeviceSize buffer_bytes);

private:
    struct State;
    explicit HeadlessContext(std::unique_ptr<State> state);

    std::unique_ptr<State> state_;
};

// Bytes per texel of the colour formats the image helpers move: R8, R8G8 and R8G8B8A8 in UNORM,
// SRGB and UINT; B8G8R8A8 in UNORM and SRGB; R16G16B16A16_SFLOAT; R32, R32G32 and R32G32B32A32 in
// UINT, SINT and SFLOAT. 0 for any other format.
uint32_t format_texel_size(VkFormat format);

// A RendererCreateInfo for the objects `context` made (instance, devices, queue family,
// allocator), the rest at its defaults. An engine fills in its own objects.
RendererCreateInfo renderer_create_info(const HeadlessContext& context);

// A CompositorCreateInfo for the objects `context` made (physical device, device, allocator,
// enabled features), the rest at its defaults.
CompositorCreateInfo compositor_create_info(const HeadlessContext& context);

}  // namespace crisp
