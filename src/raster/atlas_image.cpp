#include "raster/atlas_image.hpp"

#include "vk/barriers.hpp"

#include <optional>
#include <utility>

namespace crisp::raster {

AtlasImage::AtlasImage(const vk::DeviceRef& ref) : ref_(ref) {}

Status AtlasImage::create(const AtlasConfig& config) {
    if (Status s = make(config, image_); !s) return s;
    width_ = config.width;
    height_ = config.height;
    return {};
}

Status AtlasImage::make(const AtlasConfig& config, vk::DeviceImage& out) const {
    return vk::create_image(ref_, kAtlasFormat, config.width, config.height,
                            VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                            "atlas", out);
}

void AtlasImage::begin_record() {
    was_initialized_ = initialized_;
    grew_image_ = false;
}

void AtlasImage::record_growth(VkCommandBuffer command_buffer, vk::DeviceImage grown, const AtlasConfig& config,
                               uint64_t this_frame, RetireLists& retired) {
    const vk::Functions& fn = *ref_.fn;
    if (initialized_) {
        // Earlier frames' writes (and the compositor's reads) before the copy; the copy before
        // this frame's dispatch and every later read.
        vk::image_barrier(fn, command_buffer, image_.image, VK_IMAGE_LAYOUT_GENERAL,
                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                          VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        vk::image_barrier(fn, command_buffer, grown.image, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        VkImageCopy region{};
        region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.dstSubresource = region.srcSubresource;
        region.extent = {width_, height_, 1};
        fn.vkCmdCopyImage(command_buffer, image_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, grown.image,
                          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        vk::image_barrier(fn, command_buffer, grown.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
    }
    grew_image_ = true;
    old_image_ = image_.image;
    old_width_ = width_;
    old_height_ = height_;
    retired.images.push_back({std::move(image_), this_frame});
    image_ = std::move(grown);
    width_ = config.width;
    height_ = config.height;
}

void AtlasImage::record_first_layout(VkCommandBuffer command_buffer) {
    if (initialized_) return;
    vk::image_barrier(*ref_.fn, command_buffer, image_.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                      VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, vk::kShaderAccess);
    initialized_ = true;
}

void AtlasImage::abandon_frame(RetireLists& retired) {
    if (grew_image_) {
        // The copy into the larger image never ran: the old image comes back, and the next
        // record() grows it again. (The larger image was only in the dropped commands.)
        if (std::optional<vk::DeviceImage> old = retired.take_back(old_image_)) {
            image_ = std::move(*old);  // frees the larger image
        }
        width_ = old_width_;
        height_ = old_height_;
        grew_image_ = false;
    }
    initialized_ = was_initialized_;
}

void AtlasImage::record_readback(VkCommandBuffer command_buffer, VkBuffer buffer, const AtlasConfig& config) const {
    const vk::Functions& fn = *ref_.fn;
    const VkImage image = image_.image;
    vk::image_barrier(fn, command_buffer, image, initialized_ ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {config.width, config.height, 1};
    fn.vkCmdCopyImageToBuffer(command_buffer, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &copy);
    vk::image_barrier(fn, command_buffer, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      vk::kShaderAccess);
    vk::memory_barrier(fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

}  // namespace crisp::raster
