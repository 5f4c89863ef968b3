// crisp: CRC-32C (Castagnoli), the asset checksum.
//
// Slicing-by-8: eight 256-entry tables let the loop fold eight input bytes per step with eight
// independent lookups instead of eight dependent ones. The tables are built at compile time, so
// the library holds no mutable state and needs no initialisation. Portable C++ is fast enough
// here (a few GB/s); the checksum runs once per asset load.
#include "asset/crc32c.hpp"

#include <array>
#include <bit>
#include <cstring>

namespace crisp {

namespace {

static_assert(std::endian::native == std::endian::little, "crisp supports little-endian hosts only");

constexpr uint32_t kCastagnoliReflected = 0x82F63B78u;

using CrcTables = std::array<std::array<uint32_t, 256>, 8>;

constexpr CrcTables make_crc_tables() {
    CrcTables tables{};
    for (uint32_t byte = 0; byte < 256; ++byte) {
        uint32_t crc = byte;
        for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ ((crc & 1u) ? kCastagnoliReflected : 0u);
        tables[0][byte] = crc;
    }
    // tables[k][b] is the CRC of byte b followed by k zero bytes.
    for (size_t k = 1; k < 8; ++k)
        for (size_t byte = 0; byte < 256; ++byte) {
            uint32_t previous = tables[k - 1][byte];
            tables[k][byte] = (previous >> 8) ^ tables[0][previous & 0xFFu];
        }
    return tables;
}

constexpr CrcTables kCrcTables = make_crc_tables();

// The byte-at-a-time reference, used to check the tables at compile time.
constexpr uint32_t crc32c_bytewise(const char* text, size_t length) {
    uint32_t crc = ~0u;
    for (size_t i = 0; i < length; ++i)
        crc = (crc >> 8) ^ kCrcTables[0][(crc ^ static_cast<unsigned char>(text[i])) & 0xFFu];
    return ~crc;
}

static_assert(crc32c_bytewise("123456789", 9) == 0xE3069283u, "CRC-32C check value");

}  // namespace

uint32_t crc32c(std::span<const std::byte> bytes, uint32_t crc) {
    // The running value is kept inverted so that continuing from a returned crc equals one call
    // over the concatenation (the standard pre- and post-inversion).
    crc = ~crc;
    const std::byte* data = bytes.data();
    size_t left = bytes.size();

    while (left >= 8) {
        uint32_t low = 0;
        uint32_t high = 0;
        std::memcpy(&low, data, 4);  // little-endian host: the first input byte is the low byte
        std::memcpy(&high, data + 4, 4);
        low ^= crc;
        crc = kCrcTables[7][low & 0xFFu] ^ kCrcTables[6][(low >> 8) & 0xFFu] ^ kCrcTables[5][(low >> 16) & 0xFFu] ^
              kCrcTables[4][low >> 24] ^ kCrcTables[3][high & 0xFFu] ^ kCrcTables[2][(high >> 8) & 0xFFu] ^
              kCrcTables[1][(high >> 16) & 0xFFu] ^ kCrcTables[0][high >> 24];
        data += 8;
        left -= 8;
    }
    for (; left > 0; --left, ++data) crc = (crc >> 8) ^ kCrcTables[0][(crc ^ std::to_integer<uint32_t>(*data)) & 0xFFu];

    return ~crc;
}

}  // namespace crisp
