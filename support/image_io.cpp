#include "image_io.hpp"

#include "core/file_io.hpp"
#include "core/limits.hpp"

#include <png.h>

#include <bit>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <string_view>

namespace crisp {

namespace {

Status check_image(uint32_t width, uint32_t height, uint32_t channels, size_t floats) {
    if (width == 0 || height == 0 || width > kMaxImageDimension || height > kMaxImageDimension) {
        return Error{ErrorCode::invalid_argument, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                                      " is outside 1.." + std::to_string(kMaxImageDimension)};
    }
    const size_t expected = size_t{width} * height * channels;
    if (floats != expected) {
        return Error{ErrorCode::invalid_argument, "image of " + std::to_string(width) + "x" + std::to_string(height) +
                                                      "x" + std::to_string(channels) + " needs " +
                                                      std::to_string(expected) + " floats, got " +
                                                      std::to_string(floats)};
    }
    return {};
}

// ---- PNG

struct PngSink {
    std::vector<std::byte>* bytes = nullptr;
    bool out_of_memory = false;
};

struct PngErrorText {
    char text[256] = {};
};

void png_write_bytes(png_structp png, png_bytep data, size_t length) {
    auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
    if (sink->out_of_memory) return;
    // An exception must not unwind through libpng (C code): remember the failure instead.
    try {
        const auto* first = reinterpret_cast<const std::byte*>(data);
        sink->bytes->insert(sink->bytes->end(), first, first + length);
    } catch (const std::bad_alloc&) {
        sink->out_of_memory = true;
    }
}

void png_flush_bytes(png_structp) {}

[[noreturn]] void png_on_error(png_structp png, png_const_charp message) {
    auto* error = static_cast<PngErrorText*>(png_get_error_ptr(png));
    std::snprintf(error->text, sizeof error->text, "%s", message);
    png_longjmp(png, 1);
}

void png_on_warning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp to here. Only trivially destructible objects live in this frame
// and in libpng's, so jumping over them skips no destructor.
bool png_write_rows(png_structp png, png_infop info, uint32_t width, uint32_t height, int color_type, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, width, height, 8, color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, info);
    return true;
}

uint8_t unit_to_byte(double value) {
    if (!(value > 0.0)) return 0;  // NaN too
    if (value >= 1.0) return 255;
    return static_cast<uint8_t>(std::lround(value * 255.0));
}

// ---- PFM

void append_text(std::vector<std::byte>& out, std::string_view text) {
    for (const char c : text) out.push_back(static_cast<std::byte>(c));
}

void append_float_le(std::vector<std::byte>& out, float value) {
    const auto bits = std::bit_cast<uint32_t>(value);
    for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<std::byte>((bits >> shift) & 0xFFu));
}

float read_float(const std::byte* p, bool little_endian) {
    uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) {
        const auto byte = static_cast<uint32_t>(p[little_endian ? i : 3 - i]);
        bits |= byte << (8 * i);
    }
    return std::bit_cast<float>(bits);
}

bool is_pfm_space(std::byte b) {
    const auto c = static_cast<char>(b);
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// A header field: skips whitespace, then takes non-whitespace bytes (at most 64).
bool next_field(std::span<const std::byte> bytes, size_t& at, std::string& field) {
    while (at < bytes.size() && is_pfm_space(bytes[at])) ++at;
    field.clear();
    while (at < bytes.size() && !is_pfm_space(bytes[at])) {
        if (field.size() >= 64) return false;
        field += static_cast<char>(bytes[at++]);
    }
    return !field.empty();
}

bool parse_dimension(const std::string& field, uint32_t& value) {
    if (field.empty() || field.size() > 9) return false;
    uint32_t v = 0;
    for (const char c : field) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + static_cast<uint32_t>(c - '0');
    }
    value = v;
    return true;
}

Error pfm_error(const std::string& message) {
    return Error{ErrorCode::invalid_argument, "not a valid PFM image: " + message};
}

}  // namespace

double linear_to_srgb(double linear) {
    if (!(linear > 0.0)) return 0.0;
    if (linear >= 1.0) return 1.0;
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

uint8_t linear_to_srgb8(float linear) {
    return unit_to_byte(linear_to_srgb(static_cast<double>(linear)));
}

Result<std::vector<std::byte>> encode_png_srgb8(uint32_t width, uint32_t height, uint32_t channels,
                                                std::span<const float> pixels) {
    if (channels != 3 && channels != 4) {
        return Error{ErrorCode::invalid_argument, "a PNG needs 3 or 4 channels, not " + std::to_string(channels)};
    }
    if (Status status = check_image(width, height, channels, pixels.size()); !status) return status.error();

    const size_t row_bytes = size_t{width} * channels;
    std::vector<png_byte> texels(row_bytes * height);
    for (size_t i = 0; i < texels.size(); ++i) {
        const bool alpha = channels == 4 && i % 4 == 3;
        texels[i] = alpha ? unit_to_byte(static_cast<double>(pixels[i])) : linear_to_srgb8(pixels[i]);
    }
    std::vector<png_bytep> rows(height);
    for (size_t y = 0; y < height; ++y) rows[y] = texels.data() + y * row_bytes;

    std::vector<std::byte> bytes;
    PngSink sink{&bytes};
    PngErrorText error;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_on_error, png_on_warning);
    if (png == nullptr) return Error{ErrorCode::io, "libpng: cannot create a PNG writer"};
    png_infop info = png_create_info_struct(png);
    if (info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        return Error{ErrorCode::io, "libpng: cannot create a PNG writer"};
    }
    png_set_write_fn(png, &sink, png_write_bytes, png_flush_bytes);
    const bool written = png_write_rows(png, info, width, height,
                                        channels == 4 ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB, rows.data());
    png_destroy_write_struct(&png, &info);
    if (!written) return Error{ErrorCode::io, std::string("libpng: ") + error.text};
    if (sink.out_of_memory) return Error{ErrorCode::io, "libpng: out of memory while encoding"};
    return bytes;
}

Status write_png_srgb8(const std::filesystem::path& path, uint32_t width, uint32_t height, uint32_t channels,
                       std::span<const float> pixels) {
    Result<std::vector<std::byte>> bytes = encode_png_srgb8(width, height, channels, pixels);
    if (!bytes) return Error{bytes.error().code, path.string() + ": " + bytes.error().message};
    return write_file_atomically(path, *bytes);
}

Result<std::vector<std::byte>> encode_pfm(uint32_t width, uint32_t height, std::span<const float> rgb) {
    if (Status status = check_image(width, height, 3, rgb.size()); !status) return status.error();
    std::vector<std::byte> bytes;
    const std::string header = "PF\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
    bytes.reserve(header.size() + rgb.size() * 4);
    append_text(bytes, header);
    const size_t row_floats = size_t{width} * 3;
    for (size_t row = height; row-- > 0;) {
        for (const float value : rgb.subspan(row * row_floats, row_floats)) append_float_le(bytes, value);
    }
    return bytes;
}

Status write_pfm(const std::filesystem::path& path, uint32_t width, uint32_t height, std::span<const float> rgb) {
    Result<std::vector<std::byte>> bytes = encode_pfm(width, height, rgb);
    if (!bytes) return Error{bytes.error().code, path.string() + ": " + bytes.error().message};
    return write_file_atomically(path, *bytes);
}

Result<PfmImage> parse_pfm(std::span<const std::byte> bytes) {
    size_t at = 0;
    std::string field;
    if (!next_field(bytes, at, field) || (field != "PF" && field != "Pf")) {
        return pfm_error("it does not start with PF or Pf");
    }
    const uint32_t channels = field == "PF" ? 3 : 1;
    PfmImage image;
    if (!next_field(bytes, at, field) || !parse_dimension(field, image.width)) return pfm_error("bad width");
    if (!next_field(bytes, at, field) || !parse_dimension(field, image.height)) return pfm_error("bad height");
    if (image.width == 0 || image.height == 0 || image.width > kMaxImageDimension ||
        image.height > kMaxImageDimension) {
        return pfm_error("size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                         " is outside 1.." + std::to_string(kMaxImageDimension));
    }
    if (!next_field(bytes, at, field)) return pfm_error("no scale");
    char* end = nullptr;
    const double scale = std::strtod(field.c_str(), &end);
    if (end != field.c_str() + field.size() || !std::isfinite(scale) || scale == 0.0) {
        return pfm_error("bad scale '" + field + "'");
    }
    if (at >= bytes.size()) return pfm_error("the header has no end");
    ++at;  // the single whitespace character that ends the header
    const bool little_endian = scale < 0.0;

    const size_t pixels = size_t{image.width} * image.height;
    const size_t data_bytes = pixels * channels * 4;
    if (bytes.size() - at != data_bytes) {
        return pfm_error("a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " image holds " +
                         std::to_string(data_bytes) + " bytes of data, the file " + std::to_string(bytes.size() - at));
    }
    image.rgb.resize(pixels * 3);
    const std::byte* data = bytes.data() + at;
    for (size_t file_row = 0; file_row < image.height; ++file_row) {
        const size_t row = image.height - 1 - file_row;  // the file's first row is the bottom one
        for (size_t x = 0; x < image.width; ++x) {
            float* out = &image.rgb[(row * image.width + x) * 3];
            const std::byte* in = data + (file_row * image.width + x) * channels * 4;
            for (uint32_t c = 0; c < 3; ++c) out[c] = read_float(in + (channels == 3 ? c : 0) * 4, little_endian);
        }
    }
    return image;
}

Result<PfmImage> read_pfm(const std::filesystem::path& path) {
    Result<std::vector<std::byte>> bytes = read_file(path, limits::kImageFileBytes);
    if (!bytes) return bytes.error();
    Result<PfmImage> image = parse_pfm(*bytes);
    if (!image) return Error{image.error().code, path.string() + ": " + image.error().message};
    return image;
}

}  // namespace crisp
