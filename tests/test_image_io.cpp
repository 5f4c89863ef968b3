// The image writers crisp-render uses: sRGB PNG (read back with libpng) and PFM (byte layout and
// round trip), and their atomic writes.
#include "image_io.hpp"

#include <crisp/layout.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace crisp {
namespace {

namespace fs = std::filesystem;

using test::TemporaryDirectory;

std::vector<std::byte> file_bytes(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    std::vector<char> chars((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::vector<std::byte> bytes(chars.size());
    std::memcpy(bytes.data(), chars.data(), chars.size());
    return bytes;
}

void write_bytes(const fs::path& path, const std::string& bytes) {
    std::ofstream file(path, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string float_bytes(float value, bool little_endian) {
    const auto bits = std::bit_cast<uint32_t>(value);
    std::string out(4, '\0');
    for (size_t i = 0; i < 4; ++i) {
        const auto byte = static_cast<char>((bits >> (8 * i)) & 0xFFu);
        out[little_endian ? i : 3 - i] = byte;
    }
    return out;
}

// ---- A PNG reader on libpng's own API, independent of the writer under test.

struct PngFile {
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int bit_depth = 0;
    int color_type = 0;
    int interlace = 0;
    bool has_srgb = false;
    int srgb_intent = -1;
    bool has_gama = false;
    bool has_chrm = false;
    std::vector<png_byte> pixels;  // rows top to bottom
};

struct MemoryStream {
    const std::byte* data = nullptr;
    size_t size = 0;
    size_t at = 0;
};

void read_from_memory(png_structp png, png_bytep out, size_t length) {
    auto* stream = static_cast<MemoryStream*>(png_get_io_ptr(png));
    if (stream->size - stream->at < length) png_error(png, "truncated PNG");
    std::memcpy(out, stream->data + stream->at, length);
    stream->at += length;
}

// Both phases keep only trivially destructible objects in their frames (libpng longjmps here).
bool read_png_header(png_structp png, png_infop info, PngFile* file) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_info(png, info);
    png_get_IHDR(png, info, &file->width, &file->height, &file->bit_depth, &file->color_type, &file->interlace, nullptr,
                 nullptr);
    file->has_srgb = png_get_sRGB(png, info, &file->srgb_intent) != 0;
    file->has_gama = png_get_valid(png, info, PNG_INFO_gAMA) != 0;
    file->has_chrm = png_get_valid(png, info, PNG_INFO_cHRM) != 0;
    return true;
}

bool read_png_rows(png_structp png, png_infop info, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    png_read_end(png, info);
    return true;
}

bool decode_png(const std::vector<std::byte>& bytes, PngFile& file) {
    if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0) return false;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (info == nullptr) {
        png_destroy_read_struct(&png, nullptr, nullptr);
        return false;
    }
    MemoryStream stream{bytes.data(), bytes.size(), 0};
    png_set_read_fn(png, &stream, read_from_memory);
    bool ok = read_png_header(png, info, &file);
    if (ok) {
        const size_t row_bytes = png_get_rowbytes(png, info);
        file.pixels.resize(row_bytes * file.height);
        std::vector<png_bytep> rows(file.height);
        for (size_t y = 0; y < file.height; ++y) rows[y] = file.pixels.data() + y * row_bytes;
        ok = read_png_rows(png, info, rows.data());
    }
    png_destroy_read_struct(&png, &info, nullptr);
    return ok;
}

// A test image whose every pixel differs: linear values spread over [0, 1].
std::vector<float> gradient(uint32_t width, uint32_t height, uint32_t channels) {
    std::vector<float> pixels(size_t{width} * height * channels);
    for (size_t i = 0; i < pixels.size(); ++i) {
        pixels[i] = static_cast<float>(i) / static_cast<float>(pixels.size() - 1);
    }
    return pixels;
}

// ---- sRGB encoding

TEST(ImageIo, SrgbTransferFunctionIsTheExactPiecewiseOne) {
    EXPECT_EQ(linear_to_srgb(0.0), 0.0);
    EXPECT_EQ(linear_to_srgb(1.0), 1.0);
    EXPECT_DOUBLE_EQ(linear_to_srgb(0.002), 12.92 * 0.002);  // the linear segment
    EXPECT_NEAR(linear_to_srgb(0.5), 0.735356983, 1e-9);     // 1.055 * 0.5^(1/2.4) - 0.055
    EXPECT_NEAR(linear_to_srgb(0.0031308), 0.04045, 1e-6);   // the segments meet
    EXPECT_EQ(linear_to_srgb(-1.0), 0.0);
    EXPECT_EQ(linear_to_srgb(2.0), 1.0);
    EXPECT_EQ(linear_to_srgb(std::numeric_limits<double>::quiet_NaN()), 0.0);
    EXPECT_EQ(linear_to_srgb(std::numeric_limits<double>::infinity()), 1.0);
}

TEST(ImageIo, EverySrgbCodeSurvivesARoundTripThroughLinear) {
    for (int code = 0; code <= 255; ++code) {
        const float linear = srgb_to_linear(static_cast<float>(code) / 255.0f);
        EXPECT_EQ(linear_to_srgb8(linear), code) << "code " << code << " -> linear " << linear;
    }
}

// ---- PNG

TEST(ImageIo, PngRgbReadsBackAsSrgbWithItsChunks) {
    constexpr uint32_t kWidth = 7, kHeight = 5;
    const std::vector<float> pixels = gradient(kWidth, kHeight, 3);
    Result<std::vector<std::byte>> bytes = encode_png_srgb8(kWidth, kHeight, 3, pixels);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;

    PngFile file;
    ASSERT_TRUE(decode_png(*bytes, file));
    EXPECT_EQ(file.width, kWidth);
    EXPECT_EQ(file.height, kHeight);
    EXPECT_EQ(file.bit_depth, 8);
    EXPECT_EQ(file.color_type, PNG_COLOR_TYPE_RGB);
    EXPECT_EQ(file.interlace, PNG_INTERLACE_NONE);
    EXPECT_TRUE(file.has_srgb);
    EXPECT_EQ(file.srgb_intent, PNG_sRGB_INTENT_PERCEPTUAL);
    EXPECT_TRUE(file.has_gama) << "gAMA for readers that ignore sRGB";
    EXPECT_TRUE(file.has_chrm);
    ASSERT_EQ(file.pixels.size(), pixels.size());
    for (size_t i = 0; i < pixels.size(); ++i) {
        ASSERT_EQ(file.pixels[i], linear_to_srgb8(pixels[i])) << "byte " << i;
    }
    // The top row comes first: the first pixel is the darkest, the last the brightest.
    EXPECT_EQ(file.pixels.front(), 0);
    EXPECT_EQ(file.pixels.back(), 255);
}

// Rows added a few at a time make the file encode_png_srgb8() makes from all of them; whole rows
// only, no more than the image has, and finish() only once all are in.
TEST(ImageIo, PngRowsInPiecesMakeTheSameFile) {
    constexpr uint32_t kWidth = 7, kHeight = 5;
    const std::vector<float> pixels = gradient(kWidth, kHeight, 4);
    Result<std::vector<std::byte>> whole = encode_png_srgb8(kWidth, kHeight, 4, pixels);
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    Result<PngRowEncoder> encoder = PngRowEncoder::create(kWidth, kHeight, 4);
    ASSERT_TRUE(encoder.ok()) << encoder.error().message;
    const size_t row = size_t{kWidth} * 4;
    EXPECT_FALSE(encoder->add_rows(std::span(pixels).first(row + 1))) << "not whole rows";
    ASSERT_TRUE(encoder->add_rows(std::span(pixels).first(2 * row)));
    EXPECT_FALSE(encoder->finish()) << "three rows missing";
    EXPECT_FALSE(encoder->add_rows(pixels)) << "more rows than are left";
    ASSERT_TRUE(encoder->add_rows(std::span(pixels).subspan(2 * row)));
    Result<std::vector<std::byte>> pieces = encoder->finish();
    ASSERT_TRUE(pieces.ok()) << pieces.error().message;
    EXPECT_EQ(*pieces, *whole);
    EXPECT_FALSE(encoder->finish()) << "finished once";
    EXPECT_FALSE(PngRowEncoder::create(kWidth, kHeight, 2)) << "2 channels";
    EXPECT_FALSE(PngRowEncoder::create(0, kHeight, 3)) << "no width";
}

TEST(ImageIo, PngRgbaStoresStraightAlphaLinearly) {
    // One pixel: linear 0.5 grey at alpha 0.5; then opaque black; then transparent.
    const std::vector<float> pixels = {0.5f, 0.5f, 0.5f, 0.5f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f, 0.0f};
    Result<std::vector<std::byte>> bytes = encode_png_srgb8(3, 1, 4, pixels);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    PngFile file;
    ASSERT_TRUE(decode_png(*bytes, file));
    EXPECT_EQ(file.color_type, PNG_COLOR_TYPE_RGB_ALPHA);
    ASSERT_EQ(file.pixels.size(), 12u);
    EXPECT_EQ(file.pixels[0], 188);  // round(255 * 0.735357): sRGB-encoded colour
    EXPECT_EQ(file.pixels[3], 128);  // round(255 * 0.5): alpha is not encoded
    EXPECT_EQ(file.pixels[7], 255);
    EXPECT_EQ(file.pixels[8], 255);
    EXPECT_EQ(file.pixels[11], 0);
}

TEST(ImageIo, PngOutOfRangeValuesAreClamped) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> pixels = {-1.0f, 2.0f, nan};
    Result<std::vector<std::byte>> bytes = encode_png_srgb8(1, 1, 3, pixels);
    ASSERT_TRUE(bytes.ok());
    PngFile file;
    ASSERT_TRUE(decode_png(*bytes, file));
    EXPECT_EQ(file.pixels, (std::vector<png_byte>{0, 255, 0}));
}

TEST(ImageIo, PngRefusesBadArguments) {
    const std::vector<float> pixels(12, 0.5f);
    auto code = [](const Result<std::vector<std::byte>>& r) { return r.ok() ? -1 : static_cast<int>(r.error().code); };
    const int invalid = static_cast<int>(ErrorCode::invalid_argument);
    EXPECT_EQ(code(encode_png_srgb8(2, 2, 2, pixels)), invalid) << "2 channels";
    EXPECT_EQ(code(encode_png_srgb8(0, 4, 3, pixels)), invalid) << "zero width";
    EXPECT_EQ(code(encode_png_srgb8(4, 0, 3, pixels)), invalid) << "zero height";
    EXPECT_EQ(code(encode_png_srgb8(2, 2, 4, pixels)), invalid) << "too few floats";
    EXPECT_EQ(code(encode_png_srgb8(kMaxImageDimension + 1, 1, 3, pixels)), invalid) << "too wide";
    EXPECT_EQ(code(encode_png_srgb8(2, 2, 3, pixels)), -1);
}

// ---- PFM

TEST(ImageIo, PfmIsLittleEndianWithRowsFromTheBottom) {
    // 2x2: top row (1, 2), bottom row (3, 4), each pixel (v, v + 0.25, v + 0.5).
    std::vector<float> rgb;
    for (const float v : {1.0f, 2.0f, 3.0f, 4.0f}) rgb.insert(rgb.end(), {v, v + 0.25f, v + 0.5f});
    Result<std::vector<std::byte>> bytes = encode_pfm(2, 2, rgb);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;

    const std::string header = "PF\n2 2\n-1.0\n";
    ASSERT_EQ(bytes->size(), header.size() + 2 * 2 * 3 * 4);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes->data()), header.size()), header);
    const std::string data(reinterpret_cast<const char*>(bytes->data()) + header.size(), 2 * 2 * 3 * 4);
    std::string expected;
    for (const float v : {3.0f, 4.0f, 1.0f, 2.0f}) {  // the bottom row first
        for (const float c : {v, v + 0.25f, v + 0.5f}) expected += float_bytes(c, true);
    }
    EXPECT_EQ(data, expected);
    EXPECT_EQ(data.substr(0, 4), std::string("\x00\x00\x40\x40", 4)) << "3.0f, little-endian";
}

TEST(ImageIo, PfmRoundTripsEveryFloatBitForBit) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    constexpr uint32_t kWidth = 5, kHeight = 3;
    std::vector<float> rgb = gradient(kWidth, kHeight, 3);
    rgb[0] = -0.0f;
    rgb[1] = std::numeric_limits<float>::infinity();
    rgb[2] = std::numeric_limits<float>::denorm_min();
    rgb[44] = 1e30f;
    const fs::path path = directory.path() / "image.pfm";
    ASSERT_TRUE(write_pfm(path, kWidth, kHeight, rgb).ok());

    Result<PfmImage> image = read_pfm(path);
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image->width, kWidth);
    EXPECT_EQ(image->height, kHeight);
    ASSERT_EQ(image->rgb.size(), rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) {
        EXPECT_EQ(std::bit_cast<uint32_t>(image->rgb[i]), std::bit_cast<uint32_t>(rgb[i])) << "float " << i;
    }
}

TEST(ImageIo, PfmReaderTakesBigEndianAndGrey) {
    TemporaryDirectory directory;
    const fs::path path = directory.path() / "big.pfm";
    // Big-endian (positive scale), 1x2, whitespace as the format allows it.
    write_bytes(path, "PF  1\t2\n1.0\n" + float_bytes(0.5f, false) + float_bytes(0.25f, false) +
                          float_bytes(2.0f, false) + float_bytes(7.0f, false) + float_bytes(8.0f, false) +
                          float_bytes(9.0f, false));
    Result<PfmImage> big = read_pfm(path);
    ASSERT_TRUE(big.ok()) << big.error().message;
    EXPECT_EQ(big->rgb, (std::vector<float>{7.0f, 8.0f, 9.0f, 0.5f, 0.25f, 2.0f})) << "bottom row first in the file";

    write_bytes(path, "Pf\n2 1\n-1\n" + float_bytes(0.5f, true) + float_bytes(0.75f, true));
    Result<PfmImage> grey = read_pfm(path);
    ASSERT_TRUE(grey.ok()) << grey.error().message;
    EXPECT_EQ(grey->rgb, (std::vector<float>{0.5f, 0.5f, 0.5f, 0.75f, 0.75f, 0.75f}));
}

TEST(ImageIo, PfmReaderRefusesMalformedFiles) {
    TemporaryDirectory directory;
    const fs::path path = directory.path() / "bad.pfm";
    const std::string pixel = float_bytes(1.0f, true) + float_bytes(1.0f, true) + float_bytes(1.0f, true);
    const struct {
        std::string bytes;
        const char* fragment;
    } cases[] = {
        {"", "PF"},
        {"P6\n1 1\n255\n...", "PF"},
        {"PF\n1 1\n-1.0\n", "bytes of data"},
        {"PF\n1 1\n-1.0\n" + pixel + "x", "bytes of data"},
        {"PF\n1 2\n-1.0\n" + pixel, "bytes of data"},
        {"PF\n0 1\n-1.0\n", "size"},
        {"PF\n1 99999999\n-1.0\n" + pixel, "size"},
        {"PF\n-1 1\n-1.0\n" + pixel, "width"},
        {"PF\n1 x\n-1.0\n" + pixel, "height"},
        {"PF\n1 1\n0\n" + pixel, "scale"},
        {"PF\n1 1\nnan\n" + pixel, "scale"},
        {"PF\n1 1\n-1.0", "end"},
    };
    for (const auto& c : cases) {
        write_bytes(path, c.bytes);
        Result<PfmImage> image = read_pfm(path);
        ASSERT_FALSE(image.ok()) << "accepted: " << c.bytes.substr(0, 20);
        EXPECT_EQ(image.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(image.error().message.find(c.fragment), std::string::npos)
            << "\"" << image.error().message << "\" lacks \"" << c.fragment << "\"";
        EXPECT_NE(image.error().message.find("bad.pfm"), std::string::npos) << "the message names the file";
    }
}

TEST(ImageIo, PfmRefusesBadArguments) {
    const std::vector<float> rgb(6, 0.0f);
    EXPECT_EQ(encode_pfm(1, 1, rgb).error().code, ErrorCode::invalid_argument);
    EXPECT_EQ(encode_pfm(0, 2, rgb).error().code, ErrorCode::invalid_argument);
    EXPECT_TRUE(encode_pfm(2, 1, rgb).ok());
}

// ---- Files

TEST(ImageIo, WritesAreAtomicAndLeaveNoTemporaries) {
    TemporaryDirectory directory;
    const fs::path png = directory.path() / "out.png";
    const fs::path pfm = directory.path() / "out.pfm";
    const std::vector<float> rgb = gradient(4, 4, 3);
    ASSERT_TRUE(write_png_srgb8(png, 4, 4, 3, rgb).ok());
    ASSERT_TRUE(write_pfm(pfm, 4, 4, rgb).ok());
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"out.pfm", "out.png"}));
    EXPECT_EQ(file_bytes(png), *encode_png_srgb8(4, 4, 3, rgb));
    EXPECT_EQ(file_bytes(pfm), *encode_pfm(4, 4, rgb));

    // Overwriting replaces the file whole.
    const std::vector<float> black(3 * 2 * 2, 0.0f);
    ASSERT_TRUE(write_pfm(pfm, 2, 2, black).ok());
    EXPECT_EQ(file_bytes(pfm), *encode_pfm(2, 2, black));

    // A failed encode touches nothing.
    EXPECT_FALSE(write_png_srgb8(png, 5, 5, 3, rgb).ok());
    EXPECT_EQ(file_bytes(png), *encode_png_srgb8(4, 4, 3, rgb));
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"out.pfm", "out.png"}));
}

TEST(ImageIo, BadPathsAreIoErrorsNamingThePath) {
    TemporaryDirectory directory;
    const std::vector<float> rgb(3, 0.25f);
    const fs::path missing = directory.path() / "no" / "such" / "dir" / "out.png";
    Status png = write_png_srgb8(missing, 1, 1, 3, rgb);
    ASSERT_FALSE(png.ok());
    EXPECT_EQ(png.error().code, ErrorCode::io);
    EXPECT_NE(png.error().message.find("no/such/dir"), std::string::npos) << png.error().message;

    Status pfm = write_pfm(directory.path() / "no" / "out.pfm", 1, 1, rgb);
    ASSERT_FALSE(pfm.ok());
    EXPECT_EQ(pfm.error().code, ErrorCode::io);

    // The target is a directory: the rename fails; the directory stays and no temporary is left.
    fs::create_directory(directory.path() / "taken.png");
    Status taken = write_png_srgb8(directory.path() / "taken.png", 1, 1, 3, rgb);
    ASSERT_FALSE(taken.ok());
    EXPECT_EQ(taken.error().code, ErrorCode::io);
    EXPECT_TRUE(fs::is_directory(directory.path() / "taken.png"));
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"taken.png"}));

    Result<PfmImage> absent = read_pfm(directory.path() / "absent.pfm");
    ASSERT_FALSE(absent.ok());
    EXPECT_EQ(absent.error().code, ErrorCode::io);
    EXPECT_NE(absent.error().message.find("absent.pfm"), std::string::npos) << absent.error().message;
}

}  // namespace
}  // namespace crisp
