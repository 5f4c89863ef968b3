// Bitmap glyphs: CBDT colour bitmaps baked from Noto Color Emoji (their images, rectangles, paints
// and advances against FreeType and HarfBuzz; a truncated CBDT), and the core's decoding and
// filtering of their pixels for the GPU.
#include "test_support.hpp"
#include "bake/bitmap.hpp"
#include "raster/bitmap_pixels.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>
#include <crisp/layout.hpp>

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H
#include <hb.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

namespace crisp {
namespace {

// fonts-noto-color-emoji (scripts/setup.sh): one CBDT strike of 109 pixels per em, no outlines.
const std::string kNotoColorEmoji = "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf";

#define SKIP_WITHOUT_NOTO_COLOR_EMOJI()            \
    if (!std::filesystem::exists(kNotoColorEmoji)) \
    GTEST_SKIP() << kNotoColorEmoji << " is missing (Debian: apt install fonts-noto-color-emoji; scripts/setup.sh)"

// 👨‍👩‍👧‍👦: four people joined by ZWJ, one ligature glyph in Noto Color Emoji.
const std::vector<uint32_t> kFamily = {0x1F468, 0x200D, 0x1F469, 0x200D, 0x1F467, 0x200D, 0x1F466};

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

// ---- The baker on Noto Color Emoji

struct FreeTypeFace {
    FT_Library library = nullptr;
    FT_Face face = nullptr;
    explicit FreeTypeFace(const std::vector<std::byte>& bytes) {
        FT_Init_FreeType(&library);
        FT_New_Memory_Face(library, reinterpret_cast<const FT_Byte*>(bytes.data()), static_cast<FT_Long>(bytes.size()),
                           0, &face);
        FT_Select_Size(face, face->num_fixed_sizes - 1);
    }
    FreeTypeFace(const FreeTypeFace&) = delete;
    FreeTypeFace& operator=(const FreeTypeFace&) = delete;
    ~FreeTypeFace() {
        FT_Done_Face(face);
        FT_Done_FreeType(library);
    }
};

struct HarfBuzzFont {
    hb_blob_t* blob = nullptr;
    hb_face_t* face = nullptr;
    hb_font_t* font = nullptr;
    explicit HarfBuzzFont(const std::vector<std::byte>& bytes) {
        blob = hb_blob_create(reinterpret_cast<const char*>(bytes.data()), static_cast<unsigned>(bytes.size()),
                              HB_MEMORY_MODE_READONLY, nullptr, nullptr);
        face = hb_face_create(blob, 0);
        font = hb_font_create(face);  // scaled to units per em
    }
    HarfBuzzFont(const HarfBuzzFont&) = delete;
    HarfBuzzFont& operator=(const HarfBuzzFont&) = delete;
    ~HarfBuzzFont() {
        hb_font_destroy(font);
        hb_face_destroy(face);
        hb_blob_destroy(blob);
    }
    uint32_t glyph(uint32_t codepoint) const {
        hb_codepoint_t glyph = 0;
        hb_font_get_nominal_glyph(font, codepoint, &glyph);
        return glyph;
    }
    std::vector<uint32_t> shape(const std::vector<uint32_t>& codepoints) const {
        hb_buffer_t* buffer = hb_buffer_create();
        hb_buffer_add_utf32(buffer, codepoints.data(), static_cast<int>(codepoints.size()), 0, -1);
        hb_buffer_guess_segment_properties(buffer);
        hb_shape(font, buffer, nullptr, 0);
        unsigned count = 0;
        const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &count);
        std::vector<uint32_t> glyphs;
        for (unsigned i = 0; i < count; ++i) glyphs.push_back(infos[i].codepoint);
        hb_buffer_destroy(buffer);
        return glyphs;
    }
};

BakeOptions emoji_options(std::vector<uint32_t> codepoints) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = std::move(codepoints);
    std::sort(options.codepoints.begin(), options.codepoints.end());
    options.codepoints.erase(std::unique(options.codepoints.begin(), options.codepoints.end()),
                             options.codepoints.end());
    return options;
}

std::vector<uint32_t> emoji_codepoints() {
    std::vector<uint32_t> codepoints = {0x1F600, 0x1F44D, 0x1F3FD};
    codepoints.insert(codepoints.end(), kFamily.begin(), kFamily.end());
    return codepoints;
}

TEST(BitmapBake, NotoColorEmojiBakesItsBitmapsAsImageLayers) {
    SKIP_WITHOUT_NOTO_COLOR_EMOJI();
    const std::vector<std::byte> font = test::read_file(kNotoColorEmoji);
    auto baked = bake_font(font, emoji_options(emoji_codepoints()));
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    const HarfBuzzFont hb(font);
    // FreeType gives this face (no outlines) no units per em; head, and HarfBuzz, say 2048.
    EXPECT_EQ(asset.info.units_per_em, 2048u);
    EXPECT_EQ(asset.info.units_per_em, hb_face_get_upem(hb.face));
    EXPECT_EQ(asset.info.ascender, 1900);
    EXPECT_EQ(asset.info.descender, -500);
    EXPECT_EQ(asset.info.line_gap, 0);
    EXPECT_EQ(baked->report.failed_glyphs, 0u);
    auto loaded = load_asset(serialize_asset(asset));
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_TRUE(*loaded == asset);

    const std::vector<uint32_t> family = hb.shape(kFamily);
    ASSERT_EQ(family.size(), 1u) << "the ZWJ sequence shapes to one ligature";
    const std::vector<uint32_t> glyphs = {hb.glyph(0x1F600), hb.glyph(0x1F44D), hb.glyph(0x1F3FD), family[0]};
    // One rectangle for all: every image of the strike is 136 x 128 pixels at the same place.
    const uint32_t faces = static_cast<uint32_t>(hb_face_get_glyph_count(hb.face));
    EXPECT_EQ(asset.face_glyph_count(), faces);
    ASSERT_EQ(asset.glyphs.size(), faces + 1u);
    const GlyphRecord& rect = asset.glyphs[faces];
    EXPECT_EQ(rect.flags, kGlyphBaked | kGlyphSynthetic);
    EXPECT_FLOAT_EQ(rect.bbox_min_x, 0.0f);
    EXPECT_FLOAT_EQ(rect.bbox_max_x, 136.0f / 109.0f);
    EXPECT_FLOAT_EQ(rect.bbox_min_y, (101.0f - 128.0f) / 109.0f);
    EXPECT_FLOAT_EQ(rect.bbox_max_y, 101.0f / 109.0f);
    EXPECT_EQ(rect.curve_count, 4u);  // four lines, one contour

    EXPECT_EQ(asset.colour_glyphs.size(), asset.images.size());
    for (uint32_t glyph : glyphs) {
        SCOPED_TRACE("glyph " + std::to_string(glyph));
        const GlyphRecord& record = asset.glyphs[glyph];
        EXPECT_EQ(record.flags, kGlyphBaked);
        EXPECT_EQ(record.curve_count, 0u);
        // hmtx, as HarfBuzz advances: 2550 font units.
        EXPECT_EQ(record.advance, static_cast<float>(hb_font_get_glyph_h_advance(hb.font, glyph) / 2048.0));
        const ColourGlyph* colour = asset.colour_glyph(glyph);
        ASSERT_NE(colour, nullptr);
        ASSERT_EQ(colour->layer_count, 1u);
        const ColourLayer& layer = asset.layers[colour->first_layer];
        EXPECT_EQ(layer.glyph, faces);
        const Paint& paint = asset.paints[layer.paint];
        EXPECT_EQ(paint.kind, PaintKind::image);
        EXPECT_EQ(paint.stop_count, 0u);
        const BitmapImage& image = asset.images[paint.image];
        EXPECT_EQ(image.width, 136u);
        EXPECT_EQ(image.height, 128u);
        // The rectangle's top-left corner to (0, 0) of the image, its bottom-right to (1, 1).
        const Affine& m = paint.to_paint;
        EXPECT_NEAR(m.xx * rect.bbox_min_x + m.xy * rect.bbox_max_y + m.dx, 0.0f, 1e-6f);
        EXPECT_NEAR(m.yx * rect.bbox_min_x + m.yy * rect.bbox_max_y + m.dy, 0.0f, 1e-6f);
        EXPECT_NEAR(m.xx * rect.bbox_max_x + m.xy * rect.bbox_min_y + m.dx, 1.0f, 1e-6f);
        EXPECT_NEAR(m.yx * rect.bbox_max_x + m.yy * rect.bbox_min_y + m.dy, 1.0f, 1e-6f);
    }
}

TEST(BitmapBake, ImagesHoldFreeTypesPixelsByteForByte) {
    SKIP_WITHOUT_NOTO_COLOR_EMOJI();
    const std::vector<std::byte> font = test::read_file(kNotoColorEmoji);
    auto baked = bake_font(font, emoji_options({0x1F600, 0x1F3FD}));
    ASSERT_TRUE(baked) << baked.error().message;
    const FreeTypeFace ft(font);
    for (uint32_t codepoint : {0x1F600u, 0x1F3FDu}) {
        const uint32_t glyph = FT_Get_Char_Index(ft.face, codepoint);
        ASSERT_EQ(FT_Load_Glyph(ft.face, glyph, FT_LOAD_COLOR), 0);
        const FT_Bitmap& bitmap = ft.face->glyph->bitmap;
        ASSERT_EQ(bitmap.pixel_mode, FT_PIXEL_MODE_BGRA);
        const ColourGlyph* colour = baked->asset.colour_glyph(glyph);
        ASSERT_NE(colour, nullptr);
        const uint32_t image = baked->asset.paints[baked->asset.layers[colour->first_layer].paint].image;
        auto pixels = raster::decode_bitmap(baked->asset, image);
        ASSERT_TRUE(pixels) << pixels.error().message;
        ASSERT_EQ(pixels->size(), size_t{bitmap.width} * bitmap.rows * 4);
        size_t differing = 0, translucent = 0;
        for (uint32_t y = 0; y < bitmap.rows; ++y) {
            for (uint32_t x = 0; x < bitmap.width; ++x) {
                const uint8_t* bgra = bitmap.buffer + ptrdiff_t(y) * bitmap.pitch + x * 4;
                const uint8_t* rgba = pixels->data() + (size_t{y} * bitmap.width + x) * 4;
                differing += rgba[0] != bgra[2] || rgba[1] != bgra[1] || rgba[2] != bgra[0] || rgba[3] != bgra[3];
                translucent += bgra[3] != 0 && bgra[3] != 255;
            }
        }
        EXPECT_EQ(differing, 0u) << "U+" << std::hex << codepoint;
        EXPECT_GT(translucent, 0u);  // antialiased edges: premultiplied pixels were compared
    }
}

// The font with its CBDT table cut to its first half, the tables after it moved up to follow.
std::vector<std::byte> with_cbdt_halved(const std::vector<std::byte>& font) {
    const auto u16 = [&](size_t at) { return uint32_t(font[at]) << 8 | uint32_t(font[at + 1]); };
    const auto u32 = [&](size_t at) { return u16(at) << 16 | u16(at + 2); };
    const auto put32 = [](std::vector<std::byte>& out, size_t at, uint32_t value) {
        for (size_t i = 0; i < 4; ++i) out[at + i] = std::byte(value >> (24 - 8 * i));
    };
    const uint32_t tables = u16(4);
    std::vector<size_t> order(tables);
    for (size_t i = 0; i < tables; ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return u32(12 + 16 * a + 8) < u32(12 + 16 * b + 8); });
    std::vector<std::byte> out(font.begin(), font.begin() + 12 + 16 * ptrdiff_t(tables));
    for (size_t i : order) {
        const size_t entry = 12 + 16 * i;
        const uint32_t offset = u32(entry + 8);
        uint32_t length = u32(entry + 12);
        if (u32(entry) == make_tag("CBDT")) length /= 2;
        out.resize((out.size() + 3) & ~size_t{3});
        put32(out, entry + 8, static_cast<uint32_t>(out.size()));
        put32(out, entry + 12, length);
        out.insert(out.end(), font.begin() + offset, font.begin() + offset + length);
    }
    return out;
}

TEST(BitmapBake, ATruncatedCbdtFailsItsGlyphsByName) {
    SKIP_WITHOUT_NOTO_COLOR_EMOJI();
    const std::vector<std::byte> font = with_cbdt_halved(test::read_file(kNotoColorEmoji));
    // The strike's first half holds the bitmaps of the code points' own glyphs, the second most
    // ligatures': that of 👩🏽‍💻 (woman, skin tone, ZWJ, laptop) is cut off, U+1F600's is whole.
    const std::vector<uint32_t> coder = {0x1F469, 0x1F3FD, 0x200D, 0x1F4BB};
    const FreeTypeFace ft(font);
    const HarfBuzzFont hb(font);
    const uint32_t smile = hb.glyph(0x1F600), ligature = hb.shape(coder).at(0);
    ASSERT_EQ(FT_Load_Glyph(ft.face, smile, FT_LOAD_COLOR), 0);
    ASSERT_NE(FT_Load_Glyph(ft.face, ligature, FT_LOAD_COLOR), 0);
    std::vector<uint32_t> codepoints = coder;
    codepoints.push_back(0x1F600);

    BakeOptions options = emoji_options(codepoints);
    options.allow_failed = true;
    auto baked = bake_font(font, options);
    ASSERT_TRUE(baked) << baked.error().message;
    const BakeReport& report = baked->report;
    EXPECT_GE(report.failed_glyphs, 1u);
    EXPECT_EQ(baked->asset.glyphs[ligature].flags, kGlyphBaked | kGlyphFailed);
    EXPECT_EQ(report.first_failure.find("glyph " + std::to_string(report.failed_glyph_ids[0]) +
                                        ": its bitmap: FreeType error 6"),
              0u)
        << report.first_failure;
    EXPECT_EQ(baked->asset.colour_glyph(ligature), nullptr);
    EXPECT_NE(baked->asset.colour_glyph(smile), nullptr);
    // Every glyph that baked and has a bitmap has its colour glyph; no other does.
    for (uint32_t glyph = 0; glyph < baked->asset.face_glyph_count(); ++glyph) {
        const bool has_bitmap = baked->asset.glyphs[glyph].flags == kGlyphBaked &&
                                FT_Load_Glyph(ft.face, glyph, FT_LOAD_COLOR) == 0 && ft.face->glyph->bitmap.width > 0;
        EXPECT_EQ(baked->asset.colour_glyph(glyph) != nullptr, has_bitmap) << "glyph " << glyph;
    }
    EXPECT_TRUE(validate_asset(baked->asset));

    auto refused = bake_font(font, emoji_options(codepoints));
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::glyph_failed);
    EXPECT_NE(refused.error().message.find("glyphs failed; first: " + report.first_failure), std::string::npos)
        << refused.error().message;
}

TEST(BitmapBake, AColrGlyphKeepsItsLayersAndBitmapsFallIntoOrder) {
    SKIP_WITHOUT_NOTO_COLOR_EMOJI();
    const std::vector<std::byte> font = test::read_file(kNotoColorEmoji);
    const FreeTypeFace ft(font);
    const HarfBuzzFont hb(font);
    const uint32_t thumbs = hb.glyph(0x1F44D), smile = hb.glyph(0x1F600), family = hb.shape(kFamily).at(0);
    ASSERT_LT(thumbs, smile);
    ASSERT_LT(smile, family);
    // As the COLR reader leaves them: the smile has a colour glyph of two layers already.
    FontAsset asset;
    asset.glyphs.assign(static_cast<size_t>(ft.face->num_glyphs), GlyphRecord{});
    asset.paints.resize(1);
    asset.layers = {{1, 0}, {2, 0}};
    ColourGlyph colr;
    colr.glyph = smile;
    colr.layer_count = 2;
    asset.colour_glyphs.push_back(colr);

    auto bitmaps = BitmapGlyphs::open(ft.face, 2048);
    ASSERT_TRUE(bitmaps) << bitmaps.error().message;
    EXPECT_TRUE(bitmaps->bitmap_only());
    BakeReport report;
    for (uint32_t glyph : {thumbs, smile, family}) EXPECT_FALSE(bitmaps->bake(glyph, asset, report));
    ASSERT_TRUE(bitmaps->finish(asset));

    ASSERT_EQ(asset.colour_glyphs.size(), 3u);
    EXPECT_EQ(asset.images.size(), 2u);  // the smile's bitmap is not used
    const uint32_t glyphs[] = {thumbs, smile, family}, counts[] = {1, 2, 1}, firsts[] = {0, 1, 3};
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(asset.colour_glyphs[i].glyph, glyphs[i]);
        EXPECT_EQ(asset.colour_glyphs[i].layer_count, counts[i]);
        EXPECT_EQ(asset.colour_glyphs[i].first_layer, firsts[i]);
    }
    EXPECT_EQ(asset.layers[1].glyph, 1u);
    EXPECT_EQ(asset.layers[2].glyph, 2u);
    EXPECT_EQ(asset.paints[asset.layers[3].paint].kind, PaintKind::image);
    EXPECT_EQ(asset.paints[asset.layers[3].paint].image, 1u);
    EXPECT_EQ(asset.layers[0].glyph, asset.layers[3].glyph);  // one rectangle for both
}

TEST(BitmapBake, AFontWithoutColourHasNoColourGlyphs) {
    auto baked = bake_font_file(test::kDejaVuSans, emoji_options({'A', 0x263A}));
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_TRUE(baked->asset.colour_glyphs.empty());
    EXPECT_TRUE(baked->asset.images.empty());
    EXPECT_EQ(baked->asset.face_glyph_count(), baked->asset.glyphs.size());
}

}  // namespace
}  // namespace crisp
