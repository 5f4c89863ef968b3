// Private to raster/: bitmap glyphs' images on the GPU (docs/colour.md, "Bitmap glyphs"). Each
// image a frame draws is box-filtered into one layer of an R8G8B8A8_SRGB array image with its mips
// (raster/bitmap_pixels) and uploaded once; a layer is reused for another image once no draw of the
// current frame uses it. Until the first bitmap glyph the array is one blank layer, so that the
// compositor always has an image to bind.
#pragma once

#include "raster/bitmap_pixels.hpp"
#include "raster/paints.hpp"
#include "raster/retired.hpp"
#include "vk/resources.hpp"

#include <crisp/renderer.hpp>

#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace crisp::raster {

class BitmapLayers final : public ImagePlaces {
public:
    BitmapLayers(const vk::DeviceRef& device, uint32_t layers, uint32_t side, uint32_t frames_in_flight);

    // The blank one-layer image. Errors: vulkan.
    Status create();

    // The frame whose draws place() serves from now on.
    void begin_frame(uint64_t frame) { frame_ = frame; }
    std::optional<ImagePlace> place(FontId font, const FontAsset& asset, uint32_t image) override;
    // Forgets every image of a font being removed (its ids may come back with another font).
    void forget_font(FontId font);

    // Makes the full array at the first frame that placed an image (the blank one retired), uploads
    // the frame's new layers and leaves the image in SHADER_READ_ONLY_OPTIMAL. Errors: vulkan.
    Status record(VkCommandBuffer command_buffer, uint64_t frame, RetireLists& retired, RendererStats& stats);
    // Takes back the last record(): the images it uploaded are placed again when next drawn.
    void abandon_frame();

    VkImageView view() const { return image_.view; }
    DeviceMemoryUse memory() const;

private:
    struct Layer {
        uint64_t key = kNone;  // font << 32 | image
        uint64_t last_frame = 0;
        float extent_u = 0.0f, extent_v = 0.0f;
    };
    struct Upload {
        uint32_t layer = 0;
        BitmapLayer texels;
    };
    static constexpr uint64_t kNone = ~uint64_t{0};

    vk::DeviceRef ref_;
    uint32_t layer_count_ = 0;
    uint32_t side_ = 0;
    uint32_t levels_ = 0;
    vk::DeviceImage image_;
    bool full_ = false;         // image_ has layer_count_ layers (else the blank one)
    bool initialized_ = false;  // image_'s first layout change is recorded
    bool made_last_ = false;    // the last record() made image_
    uint64_t frame_ = 0;
    std::vector<Layer> layers_;
    std::unordered_map<uint64_t, uint32_t> places_;
    std::unordered_set<uint64_t> failed_;    // images that did not decode: not tried again
    std::vector<Upload> uploads_;            // placed this frame, uploaded by record()
    std::vector<uint32_t> uploaded_last_;    // the layers the last record() uploaded
    std::vector<vk::DeviceBuffer> staging_;  // one per frame in flight
};

}  // namespace crisp::raster
