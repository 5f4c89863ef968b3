// Bitmap glyphs' images on the GPU: one layer each, uploaded once.
#include "raster/bitmaps.hpp"

#include "vk/barriers.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace crisp::raster {

namespace {

constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_SRGB;
constexpr VkImageUsageFlags kUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

uint64_t image_key(FontId font, uint32_t image) {
    return uint64_t{font} << 32 | image;
}

}  // namespace

BitmapLayers::BitmapLayers(const vk::DeviceRef& device, uint32_t layers, uint32_t side, uint32_t frames_in_flight)
    : ref_(device),
      layer_count_(layers),
      side_(side),
      levels_(static_cast<uint32_t>(std::bit_width(side))),
      layers_(layers),
      staging_(frames_in_flight) {}

Status BitmapLayers::create() {
    return vk::create_image(ref_, kFormat, 1, 1, kUsage, "bitmap glyph images (blank)", image_, 1);
}

std::optional<ImagePlace> BitmapLayers::place(FontId font, const FontAsset& asset, uint32_t image) {
    const uint64_t key = image_key(font, image);
    if (const auto found = places_.find(key); found != places_.end()) {
        Layer& layer = layers_[found->second];
        layer.last_frame = frame_;
        return ImagePlace{found->second, layer.extent_u, layer.extent_v};
    }
    if (failed_.contains(key)) return std::nullopt;
    // A free layer, else the one drawn longest ago, if no draw of this frame uses it.
    uint32_t chosen = layer_count_;
    for (uint32_t i = 0; i < layer_count_; ++i) {
        const Layer& layer = layers_[i];
        if (layer.key == kNone) {
            chosen = i;
            break;
        }
        if (layer.last_frame < frame_ && (chosen == layer_count_ || layer.last_frame < layers_[chosen].last_frame))
            chosen = i;
    }
    if (chosen == layer_count_) return std::nullopt;
    Result<std::vector<uint8_t>> pixels = decode_bitmap(asset, image);
    Result<BitmapLayer> texels =
        pixels ? make_bitmap_layer(*pixels, asset.images[image].width, asset.images[image].height, side_)
               : Result<BitmapLayer>(pixels.error());
    if (!texels) {
        failed_.insert(key);
        return std::nullopt;
    }
    Layer& layer = layers_[chosen];
    if (layer.key != kNone) places_.erase(layer.key);
    layer = Layer{key, frame_, texels->u_extent, texels->v_extent};
    places_[key] = chosen;
    uploads_.push_back({chosen, std::move(*texels)});
    return ImagePlace{chosen, layer.extent_u, layer.extent_v};
}

void BitmapLayers::forget_font(FontId font) {
    for (Layer& layer : layers_) {
        if (layer.key != kNone && layer.key >> 32 == font) {
            places_.erase(layer.key);
            layer = Layer{};
        }
    }
    std::erase_if(failed_, [&](uint64_t key) { return key >> 32 == font; });
    std::erase_if(uploads_, [&](const Upload& upload) { return layers_[upload.layer].key == kNone; });
}

Status BitmapLayers::record(VkCommandBuffer command_buffer, uint64_t frame, RetireLists& retired,
                            RendererStats& stats) {
    made_last_ = false;
    uploaded_last_.clear();
    if (!uploads_.empty() && !full_) {
        vk::DeviceImage full;
        if (Status s = vk::create_image(ref_, kFormat, side_, side_, kUsage, "bitmap glyph images", full, layer_count_,
                                        levels_);
            !s) {
            return s;
        }
        retired.images.push_back({std::move(image_), frame});
        image_ = std::move(full);
        full_ = true;
        initialized_ = false;
        made_last_ = true;
    }
    const vk::Functions& fn = *ref_.fn;
    if (uploads_.empty()) {
        if (!initialized_) {
            vk::image_barrier(fn, command_buffer, image_.image, VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                              vk::kShaderStages, VK_ACCESS_SHADER_READ_BIT);
            initialized_ = made_last_ = true;
        }
        return {};
    }

    VkDeviceSize bytes = 0;
    for (const Upload& upload : uploads_) bytes += upload.texels.texels.size();
    vk::DeviceBuffer& staging = staging_[frame % staging_.size()];
    if (!staging.buffer || staging.size < bytes) {
        // The slot's last use is done (the frames-in-flight contract), so its buffer can go.
        staging.reset();
        if (Status s = vk::create_buffer(ref_, std::bit_ceil(bytes), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true,
                                         "bitmap glyph staging", staging);
            !s) {
            return s;
        }
    }
    std::vector<VkBufferImageCopy> regions;
    VkDeviceSize at = 0;
    for (const Upload& upload : uploads_) {
        const BitmapLayer& texels = upload.texels;
        std::memcpy(static_cast<std::byte*>(staging.mapped) + at, texels.texels.data(), texels.texels.size());
        for (uint32_t level = 0; level < texels.levels && level < levels_; ++level) {
            VkBufferImageCopy region{};
            region.bufferOffset = at + texels.level_offset(level);
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, upload.layer, 1};
            const uint32_t level_side = std::max(side_ >> level, 1u);
            region.imageExtent = {level_side, level_side, 1};
            regions.push_back(region);
        }
        at += texels.texels.size();
        uploaded_last_.push_back(upload.layer);
    }
    // Earlier frames' reads of the layers come first in the queue: the barrier orders the copies
    // after them, and keeps what the other layers hold (except at the first use).
    vk::image_barrier(fn, command_buffer, image_.image,
                      initialized_ ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, vk::kShaderStages, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT);
    fn.vkCmdCopyBufferToImage(command_buffer, staging.buffer, image_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                              static_cast<uint32_t>(regions.size()), regions.data());
    vk::image_barrier(fn, command_buffer, image_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                      VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT, vk::kShaderStages, VK_ACCESS_SHADER_READ_BIT);
    if (!initialized_) made_last_ = true;
    initialized_ = true;
    stats.bitmap_uploads += static_cast<uint32_t>(uploads_.size());
    stats.upload_bytes += bytes;
    uploads_.clear();
    return {};
}

void BitmapLayers::abandon_frame() {
    for (uint32_t layer : uploaded_last_) {
        places_.erase(layers_[layer].key);
        layers_[layer] = Layer{};
    }
    uploaded_last_.clear();
    uploads_.clear();
    if (made_last_) initialized_ = false;
    made_last_ = false;
}

DeviceMemoryUse BitmapLayers::memory() const {
    DeviceMemoryUse use;
    if (image_.memory != VK_NULL_HANDLE) {
        use.allocations = 1;
        use.bytes = image_.memory_size;
    }
    return use;
}

}  // namespace crisp::raster
