// Image files for tools and tests: 8-bit sRGB PNG (through libpng) and float PFM.
//
// Both writers encode in memory and then write with write_file_atomically(): a failed write leaves
// an existing file untouched and no temporary file behind. Pixels are passed top row first, tightly
// packed, as floats in linear light.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace crisp {

// Largest width or height either writer accepts: PNG's limit is 2^31 - 1, but a bound this far
// below it keeps width * height * channels * 4 bytes within size_t on every host crisp builds on.
inline constexpr uint32_t kMaxImageDimension = 1u << 20;

// Linear light (0..1) to the sRGB-encoded value (0..1) with the exact piecewise sRGB transfer
// function: 12.92 x up to 0.0031308, 1.055 x^(1/2.4) - 0.055 above. Clamps to [0, 1]; NaN gives 0.
double linear_to_srgb(double linear);

// The 8-bit sRGB code of a linear value: round(255 * linear_to_srgb(linear)).
uint8_t linear_to_srgb8(float linear);

// An 8-bit PNG of `width` x `height` pixels with `channels` = 3 (RGB) or 4 (RGBA) from `pixels`
// (width * height * channels floats, top row first). Colour components are linear light, encoded
// with linear_to_srgb8(); alpha is straight (not premultiplied) and stored linearly, as PNG
// defines it (round(255 * a), clamped to [0, 1]; NaN gives 0). The file carries an sRGB chunk
// (perceptual intent) with the matching gAMA and cHRM chunks for readers that ignore sRGB.
// Errors: ErrorCode::invalid_argument when channels is not 3 or 4, width or height is 0 or above
// kMaxImageDimension, or pixels has the wrong size; ErrorCode::io when libpng fails.
Result<std::vector<std::byte>> encode_png_srgb8(uint32_t width, uint32_t height, uint32_t channels,
                                                std::span<const float> pixels);

// The same PNG as encode_png_srgb8(), encoded a few rows at a time, so that a large image is never
// held whole: only its compressed bytes are (crisp-render composites its canvas in bands).
class PngRowEncoder {
public:
    // Errors as encode_png_srgb8()'s for the size and channels.
    static Result<PngRowEncoder> create(uint32_t width, uint32_t height, uint32_t channels);

    PngRowEncoder(PngRowEncoder&&) noexcept;
    PngRowEncoder& operator=(PngRowEncoder&&) noexcept;
    ~PngRowEncoder();

    // Encodes the next rows: whole rows of width * channels floats, top row first, as
    // encode_png_srgb8() takes them. Errors: ErrorCode::invalid_argument for floats that are not
    // whole rows or more rows than are left (nothing encoded); ErrorCode::io when libpng fails,
    // after which every call fails.
    Status add_rows(std::span<const float> pixels);

    // The file's bytes, once all rows are added. Errors: ErrorCode::invalid_argument while rows are
    // missing (the encoder stays usable) or after a failure or an earlier finish(); ErrorCode::io
    // when libpng fails.
    Result<std::vector<std::byte>> finish();

private:
    struct State;
    explicit PngRowEncoder(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

// encode_png_srgb8(), then write_file_atomically(path). Same errors; writing errors are
// ErrorCode::io naming the path.
Status write_png_srgb8(const std::filesystem::path& path, uint32_t width, uint32_t height, uint32_t channels,
                       std::span<const float> pixels);

// A PFM colour image in memory: width * height RGB float triples, TOP row first (the file stores
// the bottom row first; the reader and writer convert).
struct PfmImage {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgb;
};

// The PFM colour form of `rgb` (width * height * 3 floats, top row first): the header
// "PF\n<width> <height>\n-1.0\n" (a negative scale means little-endian), then the rows from the
// BOTTOM to the top, each pixel 3 little-endian IEEE-754 float32. Values are written as they are
// (NaN and infinities included). Errors as encode_png_srgb8().
Result<std::vector<std::byte>> encode_pfm(uint32_t width, uint32_t height, std::span<const float> rgb);
// For a writer that streams a PFM too large to hold: the header encode_pfm() writes, and `rgb`'s
// rows (whole rows of width * 3 floats, top row first) as the file stores them, bottom row first.
// The rows of the whole image then follow the header from the bottom band up.
std::string pfm_header(uint32_t width, uint32_t height);
void append_pfm_rows(std::vector<std::byte>& out, uint32_t width, std::span<const float> rgb);
Status write_pfm(const std::filesystem::path& path, uint32_t width, uint32_t height, std::span<const float> rgb);

// Reads a PFM file: "PF" (colour) or "Pf" (grey, expanded to equal RGB), either byte order (the
// sign of the scale), whitespace between header fields as the format allows, exactly one
// whitespace character after the scale. Safe for untrusted input. Errors: ErrorCode::io when the
// file cannot be read; ErrorCode::invalid_argument naming the fault for a malformed header, a
// dimension of 0 or above kMaxImageDimension, or a size that disagrees with the header.
Result<PfmImage> read_pfm(const std::filesystem::path& path);
Result<PfmImage> parse_pfm(std::span<const std::byte> bytes);

}  // namespace crisp
