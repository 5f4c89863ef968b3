#include "png_writer.hpp"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

namespace engine {
namespace {

// libpng reports errors by longjmp; nothing with a destructor may live between setjmp and the
// calls that can jump, so the rows are prepared by the caller.
bool encode(std::FILE* file, uint32_t width, uint32_t height, png_bytepp rows) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_set_rows(png, info, rows);
    png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

crisp::Status write_png(const std::string& path, uint32_t width, uint32_t height, std::span<const uint8_t> rgb) {
    if (width == 0 || height == 0 || rgb.size() != size_t{width} * height * 3) {
        return crisp::Error{crisp::ErrorCode::invalid_argument, path + ": no image to write"};
    }
    std::vector<png_bytep> rows(height);
    for (uint32_t y = 0; y < height; ++y) rows[y] = const_cast<png_bytep>(rgb.data() + size_t{y} * width * 3);
    const std::string temporary = path + ".partial";
    std::FILE* file = std::fopen(temporary.c_str(), "wb");
    if (!file)
        return crisp::Error{crisp::ErrorCode::io, path + ": cannot create " + temporary + ": " + std::strerror(errno)};
    const bool encoded = encode(file, width, height, rows.data());
    const bool closed = std::fclose(file) == 0;
    std::error_code error;
    if (encoded && closed) std::filesystem::rename(temporary, path, error);
    if (!encoded || !closed || error) {
        std::filesystem::remove(temporary, error);
        return crisp::Error{crisp::ErrorCode::io, path + ": the PNG could not be written"};
    }
    return {};
}

}  // namespace engine
