#include "raster/bitmap_pixels.hpp"

#include <crisp/layout.hpp>

#define ZLIB_CONST
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

namespace crisp::raster {

namespace {

Error image_fault(uint32_t image, const std::string& why) {
    return Error{ErrorCode::asset_invalid, "asset: image " + std::to_string(image) + ": " + why};
}

struct SrgbTables {
    float decoded[256];  // code k: srgb_to_linear(k / 255)
    // Code k + 1 from here on: srgb_to_linear((k + 0.5) / 255). Rounding the encoded value to the
    // nearest code is counting the bounds at or below the linear value, since the transfer is monotonic.
    float bounds[255];
};

const SrgbTables& srgb_tables() {
    static const SrgbTables tables = [] {
        SrgbTables made{};
        for (int k = 0; k < 256; ++k) made.decoded[k] = srgb_to_linear(static_cast<float>(k) / 255.0f);
        for (int k = 0; k < 255; ++k) made.bounds[k] = srgb_to_linear((static_cast<float>(k) + 0.5f) / 255.0f);
        return made;
    }();
    return tables;
}

uint8_t encode_srgb8(float linear) {
    const float* bounds = srgb_tables().bounds;
    return static_cast<uint8_t>(std::upper_bound(bounds, bounds + 255, linear) - bounds);
}

uint8_t encode_linear8(float value) {
    return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
}

// Premultiplied sRGB-encoded RGBA8 to linear premultiplied light: unpremultiplied, decoded, and
// premultiplied again (docs/colour.md), as the paint of an image layer is defined.
void to_linear(const uint8_t* rgba, float* out) {
    const SrgbTables& tables = srgb_tables();
    const uint8_t alpha = rgba[3];
    if (alpha == 0) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        return;
    }
    const float a = static_cast<float>(alpha) / 255.0f;
    for (int c = 0; c < 3; ++c) {
        // Opaque pixels, most of an emoji, skip the transfer function.
        out[c] = alpha == 255
                     ? tables.decoded[rgba[c]]
                     : a * srgb_to_linear(std::min(1.0f, static_cast<float>(rgba[c]) / static_cast<float>(alpha)));
    }
    out[3] = a;
}

// Source texels [lo, hi) of an axis, and how much of each lies in it.
template <class Visit>
void for_each_tap(double lo, double hi, Visit&& visit) {
    for (auto x = static_cast<uint32_t>(lo); static_cast<double>(x) < hi; ++x) {
        visit(x, std::min(hi, static_cast<double>(x) + 1.0) - std::max(lo, static_cast<double>(x)));
    }
}

// The image's linear light, box-filtered at `scale` into the top-left of a side x side level.
std::vector<float> filtered_level(std::span<const uint8_t> pixels, uint32_t width, uint32_t height, uint32_t side,
                                  double scale) {
    std::vector<float> linear(size_t{width} * height * 4);
    for (size_t i = 0; i < size_t{width} * height; ++i) to_linear(&pixels[4 * i], &linear[4 * i]);

    const auto covered = [&](uint32_t extent) {
        return std::min(side, static_cast<uint32_t>(std::ceil(static_cast<double>(extent) * scale)));
    };
    const uint32_t columns = covered(width), rows = covered(height);
    // Columns first: each row of the image into `columns` sums over a texel's width in source texels.
    std::vector<double> across(size_t{columns} * height * 4, 0.0);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t i = 0; i < columns; ++i) {
            double* sum = &across[(size_t{y} * columns + i) * 4];
            const double hi = std::min((i + 1) / scale, static_cast<double>(width));
            for_each_tap(i / scale, hi, [&](uint32_t x, double weight) {
                const float* texel = &linear[(size_t{y} * width + x) * 4];
                for (int c = 0; c < 4; ++c) sum[c] += weight * static_cast<double>(texel[c]);
            });
        }
    }
    // Then rows, and the mean over the texel's whole area (1 / scale^2 texels of the image), so that
    // the part of it the image does not reach counts as transparent.
    std::vector<float> level(size_t{side} * side * 4, 0.0f);
    for (uint32_t j = 0; j < rows; ++j) {
        const double hi = std::min((j + 1) / scale, static_cast<double>(height));
        for (uint32_t i = 0; i < columns; ++i) {
            double sum[4] = {};
            for_each_tap(j / scale, hi, [&](uint32_t y, double weight) {
                for (size_t c = 0; c < 4; ++c) sum[c] += weight * across[(size_t{y} * columns + i) * 4 + c];
            });
            for (size_t c = 0; c < 4; ++c)
                level[(size_t{j} * side + i) * 4 + c] = static_cast<float>(sum[c] * scale * scale);
        }
    }
    return level;
}

}  // namespace

Result<std::vector<uint8_t>> decode_bitmap(const FontAsset& asset, uint32_t image) {
    if (image >= asset.images.size())
        return image_fault(image, "past the " + std::to_string(asset.images.size()) + " images");
    const BitmapImage& bitmap = asset.images[image];
    const std::string size_text = std::to_string(bitmap.width) + " x " + std::to_string(bitmap.height);
    if (bitmap.width == 0 || bitmap.height == 0 || bitmap.width > kMaxBitmapSide || bitmap.height > kMaxBitmapSide)
        return image_fault(image, size_text + " pixels, outside 1 to " + std::to_string(kMaxBitmapSide) + " a side");
    if (uint64_t{bitmap.byte_offset} + bitmap.byte_count > asset.image_bytes.size())
        return image_fault(image, "bytes [" + std::to_string(bitmap.byte_offset) + ", +" +
                                      std::to_string(bitmap.byte_count) + ") past the " +
                                      std::to_string(asset.image_bytes.size()) + " image bytes");

    const size_t expected = size_t{bitmap.width} * bitmap.height * 4;
    std::vector<uint8_t> pixels(expected);
    z_stream stream{};
    if (inflateInit(&stream) != Z_OK) return image_fault(image, "zlib cannot start");
    stream.next_in = reinterpret_cast<const Bytef*>(asset.image_bytes.data() + bitmap.byte_offset);
    stream.avail_in = bitmap.byte_count;
    stream.next_out = pixels.data();
    stream.avail_out = static_cast<uInt>(expected);
    const int status = inflate(&stream, Z_FINISH);
    const std::string zlib_message = stream.msg ? stream.msg : "";
    const uLong produced = stream.total_out;
    const uInt left_in = stream.avail_in, left_out = stream.avail_out;
    inflateEnd(&stream);

    const std::string expected_text = size_text + " x 4 = " + std::to_string(expected) + " bytes";
    if (status == Z_STREAM_END) {
        if (produced != expected)
            return image_fault(image, "inflates to " + std::to_string(produced) + " bytes, not " + expected_text);
        if (left_in != 0)
            return image_fault(image, std::to_string(left_in) + " bytes after the end of its zlib stream");
        return pixels;
    }
    if (status == Z_BUF_ERROR && left_out == 0) return image_fault(image, "inflates to more than " + expected_text);
    if (status == Z_BUF_ERROR) return image_fault(image, "its zlib stream is cut short");
    return image_fault(image, "not a zlib stream" + (zlib_message.empty() ? "" : " (" + zlib_message + ")"));
}

size_t BitmapLayer::level_offset(uint32_t level) const {
    size_t offset = 0;
    for (uint32_t k = 0; k < level; ++k) offset += size_t{side >> k} * (side >> k) * 4;
    return offset;
}

Result<BitmapLayer> make_bitmap_layer(std::span<const uint8_t> pixels, uint32_t width, uint32_t height,
                                      uint32_t layer_side) {
    if (!std::has_single_bit(layer_side) || layer_side > kMaxBitmapSide)
        return Error{ErrorCode::invalid_argument, "bitmap layer side " + std::to_string(layer_side) +
                                                      " is not a power of two from 1 to " +
                                                      std::to_string(kMaxBitmapSide)};
    if (width == 0 || height == 0 || width > kMaxBitmapSide || height > kMaxBitmapSide)
        return Error{ErrorCode::invalid_argument, "bitmap of " + std::to_string(width) + " x " +
                                                      std::to_string(height) + " pixels, outside 1 to " +
                                                      std::to_string(kMaxBitmapSide) + " a side"};
    if (pixels.size() != size_t{width} * height * 4)
        return Error{ErrorCode::invalid_argument, "bitmap of " + std::to_string(width) + " x " +
                                                      std::to_string(height) + " pixels given " +
                                                      std::to_string(pixels.size()) + " bytes"};

    BitmapLayer layer;
    layer.side = layer_side;
    layer.levels = static_cast<uint32_t>(std::countr_zero(layer_side)) + 1;
    const double scale = std::min(1.0, static_cast<double>(layer_side) / std::max(width, height));
    layer.u_extent = static_cast<float>(width * scale / layer_side);
    layer.v_extent = static_cast<float>(height * scale / layer_side);
    layer.texels.resize(layer.level_offset(layer.levels));

    std::vector<float> level = filtered_level(pixels, width, height, layer_side, scale);
    for (uint32_t k = 0; k < layer.levels; ++k) {
        const uint32_t side = layer_side >> k;
        if (k > 0) {
            // The mean of the 2 x 2 texels above, from the unrounded level, so that rounding never adds up.
            std::vector<float> next(size_t{side} * side * 4);
            const uint32_t above = side * 2;
            for (uint32_t j = 0; j < side; ++j) {
                for (uint32_t i = 0; i < side; ++i) {
                    for (size_t c = 0; c < 4; ++c) {
                        const auto at = [&](uint32_t x, uint32_t y) { return level[(size_t{y} * above + x) * 4 + c]; };
                        next[(size_t{j} * side + i) * 4 + c] =
                            0.25f *
                            (at(2 * i, 2 * j) + at(2 * i + 1, 2 * j) + at(2 * i, 2 * j + 1) + at(2 * i + 1, 2 * j + 1));
                    }
                }
            }
            level = std::move(next);
        }
        uint8_t* out = layer.texels.data() + layer.level_offset(k);
        for (size_t t = 0; t < size_t{side} * side; ++t) {
            for (size_t c = 0; c < 3; ++c) out[4 * t + c] = encode_srgb8(level[4 * t + c]);
            out[4 * t + 3] = encode_linear8(level[4 * t + 3]);
        }
    }
    return layer;
}

}  // namespace crisp::raster
