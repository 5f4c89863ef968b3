// PNG output of screenshots, with libpng.
#pragma once

#include <crisp/result.hpp>

#include <cstdint>
#include <span>
#include <string>

namespace engine {

// Writes 8-bit sRGB RGB pixels (rows top first) as a PNG, through a temporary file renamed into
// place, so a failed write leaves no partial file. Errors: crisp::ErrorCode::io naming the path.
crisp::Status write_png(const std::string& path, uint32_t width, uint32_t height, std::span<const uint8_t> rgb);

}  // namespace engine
