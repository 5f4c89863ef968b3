// CRC-32C (Castagnoli): the asset checksum (docs/asset-format.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace crisp {

// CRC-32C of `bytes`, continuing from `crc` (0 to start).
uint32_t crc32c(std::span<const std::byte> bytes, uint32_t crc = 0);

}  // namespace crisp
