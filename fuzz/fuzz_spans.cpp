// Fuzzes styled spans and paragraph options: span ranges (overlapping, out of range, inside UTF-8
// sequences, empty), every span style member, maximum lines with each trimming, scale, line
// height and tab stops, over arbitrary text. The first bytes pick the paragraph, then spans are
// read in 8-byte records until a record starts with 0xFF; the rest is the text.
#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include "fuzz_fonts.hpp"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>
#include <vector>

namespace {

std::vector<std::unique_ptr<crisp::Font>> g_fonts;  // the fuzzer's fixture, made once
std::vector<const crisp::Font*> g_chain, g_other;

const crisp::FontFeature kFeatures[] = {
    {{'l', 'i', 'g', 'a'}, 0}, {{'k', 'e', 'r', 'n'}, 0}, {{'s', 's', '0', '1'}, 1}};
const float kStops[] = {12.0f, 40.0f, 41.0f, 200.0f};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    g_fonts.push_back(load_fuzz_font("fuzz/corpus/font/inter-cff-subset.otf", 1));  // a subset: most text falls back
    g_fonts.push_back(load_fuzz_font("fonts/DejaVuSans.ttf", 2));
    g_chain = {g_fonts[0].get(), g_fonts[1].get()};
    g_other = {g_fonts[1].get()};
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 4) return 0;
    crisp::TextStyle style;
    style.size = 4.0f + static_cast<float>(data[0] % 64);
    crisp::LayoutOptions options;
    options.wrap_width = (data[1] & 0x80) ? 0.0f : static_cast<float>(data[1]) * 4.0f;
    options.max_lines = data[2] % 4;
    options.trimming = static_cast<crisp::Trimming>((data[2] >> 2) % 4);
    options.direction = static_cast<crisp::Direction>((data[2] >> 4) % 3);
    options.snap_to_pixels = (data[2] >> 6) & 1;
    options.scale = 0.5f + static_cast<float>(data[3] % 8) * 0.25f;
    options.line_spacing = (data[3] & 0x80) ? 1.5f : 1.0f;
    options.line_height = (data[3] & 0x40) ? 10.0f : 0.0f;
    if (data[3] & 0x20) options.tab_stops = kStops;
    size_t at = 4;
    std::vector<crisp::TextSpan> spans;
    while (at + 8 <= size && data[at] != 0xFF && spans.size() < 64) {
        const uint8_t* r = data + at;
        crisp::TextSpan span;
        span.begin = r[0];
        span.end = r[0] + r[1] % 32u;
        if (r[7] & 0x80) span.end = r[1];  // sometimes before the begin
        span.style = style;
        span.style.size = r[2] & 1 ? 4.0f + static_cast<float>(r[2] % 48) : style.size;
        span.style.color[0] = static_cast<float>(r[3]) / 255.0f;
        span.style.letter_spacing = static_cast<float>(static_cast<int8_t>(r[4])) / 32.0f;
        span.style.baseline_shift = static_cast<float>(static_cast<int8_t>(r[5])) / 16.0f;
        span.style.underline = r[6] & 1;
        span.style.strikethrough = (r[6] >> 1) & 1;
        span.style.skip_ink = (r[6] >> 2) & 1;
        if ((r[6] >> 3) & 1) span.style.features = std::span(kFeatures).first((r[6] >> 4) % 4);
        if ((r[7] >> 6) & 1) span.style.fonts = g_other;
        spans.push_back(span);
        at += 8;
    }
    if (at < size && data[at] == 0xFF) ++at;
    const std::string_view text(reinterpret_cast<const char*>(data + at), size - at);
    crisp::Layouter layouter;
    crisp::TextLayout layout;
    const crisp::Status status = layouter.layout(g_chain, text, style, spans, options, layout);
    if (!status) {
        // Only the spans can be wrong: the message names one, and the layout is empty.
        if (status.error().message.find("spans[") == std::string::npos) __builtin_trap();
        if (!layout.glyphs.empty() || !layout.lines.empty()) __builtin_trap();
        return 0;
    }
    if (options.max_lines != 0 && layout.lines.size() > options.max_lines) __builtin_trap();
    for (const crisp::GlyphInstance& glyph : layout.glyphs) {
        if (glyph.cluster > text.size()) __builtin_trap();
    }
    for (const crisp::TextDecoration& decoration : layout.decorations) {
        if (!(decoration.width >= 0.0f) || !(decoration.height > 0.0f) || decoration.line >= layout.lines.size())
            __builtin_trap();
    }
    return 0;
}
