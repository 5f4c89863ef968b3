// The buffers and images a HeadlessContext makes, each with its own memory, and the helpers that
// move bytes between them and the host.
#include "headless_context.hpp"

#include "vk/barriers.hpp"
#include "vk/resources.hpp"

#include <cassert>
#include <cstring>
#include <utility>

namespace crisp {

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
        return Error{ErrorCode::vulkan,
                     "create_image: the device does not support a " + std::to_string(desc.width) + "x" +
                         std::to_string(desc.height) + " image of VkFormat " +
                         std::to_string(static_cast<int>(desc.format)) + " with usage flags " +
                         std::to_string(desc.usage),
                     supported};
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
    const VkDeviceSize size = VkDeviceSize{source.extent().width} * source.extent().height * texel_size;
    const VkBufferImageCopy region = whole_image_copy(source.extent());
    return read_image_regions(source.handle(), layout, std::span(&region, 1), size);
}

Result<std::vector<std::byte>> HeadlessContext::read_image_regions(VkImage source, VkImageLayout layout,
                                                                   std::span<const VkBufferImageCopy> regions,
                                                                   VkDeviceSize buffer_bytes) {
    if (!is_real_layout(layout)) {
        return Error{ErrorCode::invalid_argument,
                     "read_image: an image in layout UNDEFINED or PREINITIALIZED has no contents to read"};
    }
    if (buffer_bytes == 0) return std::vector<std::byte>{};
    Result<Buffer> staging = create_buffer(buffer_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    if (!staging) return staging.error();
    Status copied = submit_and_wait([&](VkCommandBuffer commands) {
        image_barrier(functions(), commands, source, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        functions().vkCmdCopyImageToBuffer(commands, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging->handle(),
                                           static_cast<uint32_t>(regions.size()), regions.data());
        // Back to the caller's layout; later work must wait for the copy's reads.
        image_barrier(functions(), commands, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
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

}  // namespace crisp
