// Bitmap glyphs: the core's decoding and filtering of their pixels for the GPU.
#include "test_support.hpp"
#include "raster/bitmap_pixels.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>
#include <crisp/layout.hpp>

#include <gtest/gtest.h>

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

namespace crisp {
namespace {

std::vector<std::byte> zlib_compress(std::span<const uint8_t> bytes) {
    uLongf size = compressBound(static_cast<uLong>(bytes.size()));
    std::vector<std::byte> out(size);
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size, bytes.data(), static_cast<uLong>(bytes.size()), 9),
              Z_OK);
    out.resize(size);
    return out;
}

// An asset holding one image of width x height whose stream is `stream`.
FontAsset asset_with_image(uint32_t width, uint32_t height, std::vector<std::byte> stream) {
    FontAsset asset;
    asset.images.push_back({width, height, 0, static_cast<uint32_t>(stream.size())});
    asset.image_bytes = std::move(stream);
    return asset;
}

std::vector<uint8_t> random_pixels(uint32_t width, uint32_t height, bool opaque, uint32_t seed) {
    std::mt19937 random(seed);
    std::vector<uint8_t> pixels(size_t{width} * height * 4);
    for (size_t i = 0; i < pixels.size(); i += 4) {
        const auto alpha = static_cast<uint8_t>(opaque ? 255 : random() % 256);
        // Premultiplied: no channel above alpha.
        for (size_t c = 0; c < 3; ++c) pixels[i + c] = static_cast<uint8_t>(random() % (alpha + 1u));
        pixels[i + 3] = alpha;
    }
    return pixels;
}

// A layer texel as linear premultiplied light (rgb decoded from sRGB, alpha linear).
std::array<double, 4> texel_light(const uint8_t* texel) {
    std::array<double, 4> light{};
    for (size_t c = 0; c < 3; ++c) light[c] = static_cast<double>(srgb_to_linear(texel[c] / 255.0f));
    light[3] = texel[3] / 255.0;
    return light;
}

std::array<double, 4> mean_light(const raster::BitmapLayer& layer, uint32_t level) {
    const uint32_t side = layer.side >> level;
    const uint8_t* texels = layer.texels.data() + layer.level_offset(level);
    std::array<double, 4> sum{};
    for (size_t t = 0; t < size_t{side} * side; ++t) {
        const auto light = texel_light(texels + 4 * t);
        for (size_t c = 0; c < 4; ++c) sum[c] += light[c];
    }
    for (double& value : sum) value /= static_cast<double>(side) * side;
    return sum;
}

// ---- decode_bitmap

TEST(BitmapPixels, DecodeReturnsTheImagesPixels) {
    const std::vector<uint8_t> pixels = random_pixels(37, 21, false, 1);
    const FontAsset asset = asset_with_image(37, 21, zlib_compress(pixels));
    auto decoded = raster::decode_bitmap(asset, 0);
    ASSERT_TRUE(decoded) << decoded.error().message;
    EXPECT_EQ(*decoded, pixels);
}

void expect_image_fault(const FontAsset& asset, uint32_t image, const std::string& says) {
    auto decoded = raster::decode_bitmap(asset, image);
    ASSERT_FALSE(decoded);
    EXPECT_EQ(decoded.error().code, ErrorCode::asset_invalid);
    EXPECT_NE(decoded.error().message.find("image " + std::to_string(image) + ": " + says), std::string::npos)
        << decoded.error().message;
}

TEST(BitmapPixels, DecodeRefusesBadImagesNamingThem) {
    const std::vector<uint8_t> pixels = random_pixels(8, 4, false, 2);
    const std::vector<std::byte> stream = zlib_compress(pixels);
    expect_image_fault(asset_with_image(8, 4, stream), 1, "past the 1 images");
    expect_image_fault(asset_with_image(0, 4, stream), 0, "0 x 4 pixels, outside 1 to 1024 a side");
    expect_image_fault(asset_with_image(1025, 1, stream), 0, "1025 x 1 pixels, outside 1 to 1024 a side");
    FontAsset past = asset_with_image(8, 4, stream);
    past.images[0].byte_offset = 3;
    expect_image_fault(past, 0, "bytes [3, +" + std::to_string(stream.size()) + ") past the");
    // The stream of 8 x 4 pixels, declared smaller and larger.
    expect_image_fault(asset_with_image(4, 4, stream), 0, "inflates to more than 4 x 4 x 4 = 64 bytes");
    expect_image_fault(asset_with_image(8, 8, stream), 0, "inflates to 128 bytes, not 8 x 8 x 4 = 256 bytes");
    std::vector<std::byte> cut(stream.begin(), stream.end() - 6);
    expect_image_fault(asset_with_image(8, 4, cut), 0, "its zlib stream is cut short");
    std::vector<std::byte> trailing = stream;
    trailing.push_back(std::byte{0});
    expect_image_fault(asset_with_image(8, 4, trailing), 0, "1 bytes after the end of its zlib stream");
    std::vector<std::byte> garbage(stream.size(), std::byte{0x5A});
    expect_image_fault(asset_with_image(8, 4, garbage), 0, "not a zlib stream");
}

TEST(BitmapPixels, DecodeSurvivesEveryTruncationAndFlippedByte) {
    const std::vector<uint8_t> pixels = random_pixels(16, 9, false, 3);
    const std::vector<std::byte> stream = zlib_compress(pixels);
    for (size_t size = 0; size < stream.size(); ++size) {
        FontAsset asset =
            asset_with_image(16, 9, std::vector<std::byte>(stream.begin(), stream.begin() + ptrdiff_t(size)));
        EXPECT_FALSE(raster::decode_bitmap(asset, 0)) << "cut to " << size << " bytes";
    }
    for (size_t i = 0; i < stream.size(); ++i) {
        FontAsset asset = asset_with_image(16, 9, stream);
        asset.image_bytes[i] ^= std::byte{0x41};
        auto decoded = raster::decode_bitmap(asset, 0);
        // The adler32 checksum catches a flip that still inflates: nothing but the original decodes.
        if (decoded)
            EXPECT_EQ(*decoded, pixels) << "byte " << i;
        else
            EXPECT_EQ(decoded.error().code, ErrorCode::asset_invalid);
    }
}

// ---- make_bitmap_layer

TEST(BitmapPixels, AnImageThatFitsIsCopied) {
    const std::vector<uint8_t> pixels = random_pixels(100, 60, true, 4);
    auto layer = raster::make_bitmap_layer(pixels, 100, 60, 128);
    ASSERT_TRUE(layer) << layer.error().message;
    EXPECT_EQ(layer->side, 128u);
    EXPECT_EQ(layer->levels, 8u);
    EXPECT_EQ(layer->texels.size(), layer->level_offset(8));
    EXPECT_EQ(layer->level_offset(1), 128u * 128 * 4);
    EXPECT_FLOAT_EQ(layer->u_extent, 100.0f / 128.0f);
    EXPECT_FLOAT_EQ(layer->v_extent, 60.0f / 128.0f);
    for (uint32_t y = 0; y < 128; ++y) {
        for (uint32_t x = 0; x < 128; ++x) {
            for (size_t c = 0; c < 4; ++c) {
                const uint8_t texel = layer->texels[(size_t{y} * 128 + x) * 4 + c];
                const uint8_t expected = x < 100 && y < 60 ? pixels[(size_t{y} * 100 + x) * 4 + c] : 0;
                ASSERT_EQ(texel, expected) << "texel " << x << ", " << y << " channel " << c;
            }
        }
    }
}

TEST(BitmapPixels, TranslucentTexelsHoldLinearPremultipliedLight) {
    // Half-transparent sRGB 50 % grey, premultiplied in sRGB as FreeType gives it: (64, 64, 64, 128).
    const std::vector<uint8_t> pixel = {64, 64, 64, 128};
    auto layer = raster::make_bitmap_layer(pixel, 1, 1, 1);
    ASSERT_TRUE(layer) << layer.error().message;
    const double light = 128.0 / 255.0 * static_cast<double>(srgb_to_linear(64.0f / 128.0f));
    const auto texel = texel_light(layer->texels.data());
    EXPECT_NEAR(texel[0], light, 0.002);
    EXPECT_NEAR(texel[3], 128.0 / 255.0, 1e-9);
}

TEST(BitmapPixels, AConstantImageStaysConstantAtEveryLevel) {
    // 512 x 512 of one translucent colour onto 128: a quarter of the size, every texel of every level covered.
    std::vector<uint8_t> pixels(512 * 512 * 4);
    for (size_t i = 0; i < pixels.size(); i += 4) {
        pixels[i + 0] = 150, pixels[i + 1] = 40, pixels[i + 2] = 90, pixels[i + 3] = 200;
    }
    auto layer = raster::make_bitmap_layer(pixels, 512, 512, 128);
    ASSERT_TRUE(layer) << layer.error().message;
    EXPECT_FLOAT_EQ(layer->u_extent, 1.0f);
    const uint8_t* first = layer->texels.data();
    EXPECT_EQ(first[3], 200);
    for (size_t t = 0; t < layer->texels.size(); t += 4) {
        ASSERT_TRUE(std::equal(first, first + 4, layer->texels.data() + t)) << "texel byte " << t;
    }
    // An opaque constant keeps its very bytes, down to the 1 x 1 mip, across a scale that cuts texels.
    std::vector<uint8_t> opaque(136 * 136 * 4);
    for (size_t i = 0; i < opaque.size(); i += 4) {
        opaque[i + 0] = 255, opaque[i + 1] = 128, opaque[i + 2] = 7, opaque[i + 3] = 255;
    }
    auto scaled = raster::make_bitmap_layer(opaque, 136, 136, 128);
    ASSERT_TRUE(scaled) << scaled.error().message;
    for (uint32_t level = 0; level < scaled->levels; ++level) {
        const uint8_t* texel = scaled->texels.data() + scaled->level_offset(level);
        EXPECT_EQ(std::vector<uint8_t>(texel, texel + 4), std::vector<uint8_t>(opaque.begin(), opaque.begin() + 4))
            << "level " << level;
    }
}

TEST(BitmapPixels, OnePixelKeepsItsLightWhenScaled) {
    // Noto Color Emoji's 136 x 128 onto 64: a scale of 0.47 spreads the pixel over 2 x 2 texels.
    const uint32_t width = 136, height = 128, side = 64;
    std::vector<uint8_t> pixels(size_t{width} * height * 4, 0);
    const size_t at = (size_t{38} * width + 19) * 4;
    pixels[at + 0] = 255, pixels[at + 1] = 128, pixels[at + 3] = 255;
    auto layer = raster::make_bitmap_layer(pixels, width, height, side);
    ASSERT_TRUE(layer) << layer.error().message;
    EXPECT_FLOAT_EQ(layer->u_extent, 1.0f);
    EXPECT_FLOAT_EQ(layer->v_extent, 128.0f / 136.0f);
    const double scale = 64.0 / 136.0;
    std::array<double, 4> total{};
    uint32_t lit = 0;
    for (size_t t = 0; t < size_t{side} * side; ++t) {
        const auto light = texel_light(layer->texels.data() + 4 * t);
        if (light[3] > 0.0) ++lit;
        for (size_t c = 0; c < 4; ++c) total[c] += light[c] / (scale * scale);  // a texel is 1 / scale^2 pixels
    }
    EXPECT_EQ(lit, 4u);
    EXPECT_NEAR(total[0], 1.0, 0.03);
    EXPECT_NEAR(total[1], static_cast<double>(srgb_to_linear(128.0f / 255.0f)), 0.03);
    EXPECT_NEAR(total[2], 0.0, 1e-12);
    EXPECT_NEAR(total[3], 1.0, 0.04);
}

TEST(BitmapPixels, EachMipHoldsTheMeanLightOfTheLevelAbove) {
    const std::vector<uint8_t> pixels = random_pixels(136, 128, false, 5);
    auto layer = raster::make_bitmap_layer(pixels, 136, 128, 128);
    ASSERT_TRUE(layer) << layer.error().message;
    for (uint32_t level = 1; level < layer->levels; ++level) {
        const auto above = mean_light(*layer, level - 1), here = mean_light(*layer, level);
        for (size_t c = 0; c < 4; ++c) EXPECT_NEAR(here[c], above[c], 2e-3) << "level " << level << " channel " << c;
    }
    // The 1 x 1 mip: the mean light of the whole layer, which the image fills but for its last 7.5 rows.
    EXPECT_GT(mean_light(*layer, 7)[3], 0.3);
}

TEST(BitmapPixels, LayerRefusesBadArguments) {
    const std::vector<uint8_t> pixels(16 * 4);
    EXPECT_EQ(raster::make_bitmap_layer(pixels, 4, 4, 100).error().code, ErrorCode::invalid_argument);
    EXPECT_EQ(raster::make_bitmap_layer(pixels, 4, 4, 2048).error().code, ErrorCode::invalid_argument);
    EXPECT_EQ(raster::make_bitmap_layer(pixels, 4, 0, 64).error().code, ErrorCode::invalid_argument);
    auto short_pixels = raster::make_bitmap_layer(pixels, 4, 5, 64);
    ASSERT_FALSE(short_pixels);
    EXPECT_NE(short_pixels.error().message.find("4 x 5 pixels given 64 bytes"), std::string::npos);
}

}  // namespace
}  // namespace crisp
