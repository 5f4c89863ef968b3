// Fuzzes the asset loader. The checksum would reject almost every mutation before the structure
// is looked at, so the target re-seals it: what is fuzzed is every check behind it, and the
// decoding of the bitmap images of every asset that loads.
#include "asset/crc32c.hpp"
#include "raster/bitmap_pixels.hpp"

#include <crisp/asset.hpp>

#include <cstdint>
#include <cstring>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<std::byte> bytes(size);
    if (size > 0) std::memcpy(bytes.data(), data, size);
    if (size >= 32) {
        uint32_t crc = crisp::crc32c(std::span(bytes).first(24));
        crc = crisp::crc32c(std::span(bytes).subspan(28), crc);
        std::memcpy(bytes.data() + 24, &crc, 4);
    }
    auto asset = crisp::load_asset(bytes);
    if (asset) {
        // Whatever loads must serialize back to something that loads to the same asset.
        auto again = crisp::load_asset(crisp::serialize_asset(*asset));
        if (!again || !(*again == *asset)) __builtin_trap();
        // Bitmap glyphs' pixels are inflated only when drawn: each must decode or be refused.
        for (uint32_t i = 0; i < asset->images.size(); ++i) (void)crisp::raster::decode_bitmap(*asset, i);
    }
    return 0;
}
