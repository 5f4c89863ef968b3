// Fuzzes crisp's COLR reader: the input is a COLR table, read beside a fixed CPAL of one palette of
// eight colours for a face of 128 glyphs; every base glyph is flattened and assembled, and what the
// reader hands over must keep the rules the asset's loader applies.
#include "bake/colr.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr uint32_t kGlyphs = 128;
constexpr uint32_t kEntries = 8;

std::vector<std::byte> fixed_cpal() {
    std::vector<std::byte> cpal;
    const auto put16 = [&](uint32_t v) {
        cpal.push_back(static_cast<std::byte>(v >> 8));
        cpal.push_back(static_cast<std::byte>(v & 0xFF));
    };
    put16(0);         // version
    put16(kEntries);  // entries per palette
    put16(1);         // palettes
    put16(kEntries);  // colour records
    put16(0);
    put16(14);  // the records, after the one palette start
    put16(0);
    for (uint32_t i = 0; i < kEntries * 4; ++i) cpal.push_back(static_cast<std::byte>(i * 37));
    return cpal;
}

bool keeps_the_rules(const crisp::ColrGlyph& glyph) {
    if (glyph.layers.size() > crisp::kMaxColourLayers) return false;
    for (const crisp::ColrLayer& layer : glyph.layers) {
        if (layer.glyph >= kGlyphs || layer.stops.empty() || layer.stops.size() > crisp::kMaxColourStops) return false;
        float previous = -INFINITY;
        for (const crisp::ColourStop& stop : layer.stops) {
            if (stop.palette_index >= kEntries && stop.palette_index != crisp::kForegroundPaletteIndex) return false;
            if (!(stop.alpha >= 0.0f && stop.alpha <= 1.0f) || stop.offset < previous) return false;
            previous = stop.offset;
        }
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::vector<std::byte> cpal = fixed_cpal();
    std::vector<std::byte> colr(size);
    if (size > 0) std::memcpy(colr.data(), data, size);
    auto reader = crisp::ColrReader::open(colr, cpal, kGlyphs, 1000);
    if (!reader) return 0;
    crisp::ColourAssembler assembler(kGlyphs);
    for (const uint32_t glyph : reader->base_glyphs()) {
        const crisp::ColrOutcome outcome = reader->flatten(glyph);
        if (!outcome.colour) continue;
        if (!keeps_the_rules(outcome.glyph)) __builtin_trap();
        std::string reason;
        (void)assembler.add(glyph, outcome.glyph, reason);
    }
    return 0;
}
