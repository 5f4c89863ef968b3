// Fuzzes the baker's font path: FreeType's parsers, the outline walk, cubic lowering, bands and
// the asset validation the baker applies to its own output.
#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <cstdint>
#include <cstring>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<std::byte> bytes(size);
    if (size > 0) std::memcpy(bytes.data(), data, size);
    crisp::BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = crisp::decode_utf8("Ag1 fi");
    options.max_curves_per_glyph = 4096;
    options.allow_failed = true;
    auto baked = crisp::bake_font(bytes, options);
    if (baked && !crisp::validate_asset(baked->asset)) __builtin_trap();
    return 0;
}
