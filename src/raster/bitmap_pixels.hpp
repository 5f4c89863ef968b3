// Private: a bitmap glyph's pixels on their way to the GPU. The asset holds each image zlib-compressed
// (BitmapImage); decode_bitmap inflates one, and make_bitmap_layer scales it into one square layer of
// an R8G8B8A8_SRGB array image with its whole mip chain. CPU only.
#pragma once

#include <crisp/asset.hpp>
#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp::raster {

// The pixels of asset.images[image]: width * height premultiplied RGBA8, sRGB-encoded, rows top to
// bottom. Safe on untrusted assets: an image index past the images, a byte range past image_bytes,
// a side of 0 or past kMaxBitmapSide, and a stream that is not zlib, is cut short, inflates to more
// or fewer than width * height * 4 bytes or has bytes after its end all return
// ErrorCode::asset_invalid naming the image; at most width * height * 4 bytes are allocated.
Result<std::vector<uint8_t>> decode_bitmap(const FontAsset& asset, uint32_t image);

// One layer of the bitmap atlas: level 0 of side `side`, then its mips down to 1 x 1, each level
// side_k * side_k RGBA8 texels, rows top to bottom. rgb hold the sRGB encoding of LINEAR
// premultiplied light and a its linear alpha: an _SRGB format's sampler decodes each texel before it
// filters, so its bilinear and trilinear filtering average light, as the layers were made.
struct BitmapLayer {
    uint32_t side = 0;
    uint32_t levels = 0;  // log2(side) + 1
    std::vector<uint8_t> texels;
    // The image covers [0, u_extent] x [0, v_extent] of the layer's unit square (top-left corner at
    // (0, 0), v down); the rest is transparent.
    float u_extent = 0.0f;
    float v_extent = 0.0f;

    // Where level `level` starts in `texels`, in bytes.
    size_t level_offset(uint32_t level) const;
};

// The image of `width` x `height` pixels (as decode_bitmap gives them) in a layer of side
// `layer_side`: scaled by min(1, layer_side / max(width, height)) (aspect kept; never magnified, which
// is the sampler's job) and placed at the top-left, with an exact box (area) filter in linear
// premultiplied light: each texel is the mean light of the part of the image under it, transparent
// where the image does not reach. Each mip is the 2 x 2 mean of the level above, in the same light,
// before rounding. An image that fits is copied texel for texel (opaque texels keep their bytes).
// invalid_argument when layer_side is not a power of two in [1, kMaxBitmapSide], a side of the image
// is 0 or past kMaxBitmapSide, or `pixels` does not hold width * height * 4 bytes.
Result<BitmapLayer> make_bitmap_layer(std::span<const uint8_t> pixels, uint32_t width, uint32_t height,
                                      uint32_t layer_side);

}  // namespace crisp::raster
