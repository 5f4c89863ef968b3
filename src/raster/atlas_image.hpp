// Private: the renderer's atlas image: made at the atlas's size, grown with it (the old texels
// copied to the larger image's top-left), moved to GENERAL once, and read back for tools and
// tests. What a frame did to it, abandon_frame() takes back.
#pragma once

#include "raster/retired.hpp"
#include "vk/resources.hpp"

#include <crisp/atlas.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>

namespace crisp::raster {

inline constexpr VkFormat kAtlasFormat = VK_FORMAT_R16G16B16A16_UINT;

class AtlasImage {
public:
    explicit AtlasImage(const vk::DeviceRef& ref);  // `ref` outlives it

    // The first image, of `config`'s size.
    Status create(const AtlasConfig& config);
    // An image of `config`'s size, in VK_IMAGE_LAYOUT_UNDEFINED.
    Status make(const AtlasConfig& config, vk::DeviceImage& out) const;
    bool holds(const AtlasConfig& config) const { return config.width == width_ && config.height == height_; }

    // Notes what record() may change, for abandon_frame().
    void begin_record();
    // `grown` (of `config`'s size) takes the place of the image, which is retired at `this_frame`;
    // once the first layout change was recorded, the old image's texels are copied into it.
    void record_growth(VkCommandBuffer command_buffer, vk::DeviceImage grown, const AtlasConfig& config,
                       uint64_t this_frame, RetireLists& retired);
    // UNDEFINED to GENERAL, the first time only.
    void record_first_layout(VkCommandBuffer command_buffer);
    // The image as it was at begin_record(): a larger image made this frame is freed.
    void abandon_frame(RetireLists& retired);
    // Renderer::record_atlas_readback() of an atlas of `config`.
    void record_readback(VkCommandBuffer command_buffer, VkBuffer buffer, const AtlasConfig& config) const;

    const vk::DeviceImage& image() const { return image_; }

private:
    const vk::DeviceRef& ref_;
    vk::DeviceImage image_;
    uint32_t width_ = 0, height_ = 0;  // image_'s size (the atlas's, once grown)
    bool initialized_ = false;
    // What the frame committed, so that abandon_frame() can take it back.
    bool was_initialized_ = false;
    // The atlas image this frame replaced by a larger one (its copy is in the dropped commands).
    bool grew_image_ = false;
    VkImage old_image_ = VK_NULL_HANDLE;  // in retired images until the frame is known submitted
    uint32_t old_width_ = 0, old_height_ = 0;
};

}  // namespace crisp::raster
