// Fuzzes text layout: UTF-8 decoding, bidi, itemization, fallback, shaping, line breaking and
// placement, and editing over the result (boundaries, carets, hit tests, selections, motion). The
// first bytes pick the options, the rest is the text.
#include <crisp/bake.hpp>
#include <crisp/editing.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>
#include <vector>

namespace {

std::vector<std::unique_ptr<crisp::Font>> g_fonts;  // the fuzzer's fixture, made once
std::vector<const crisp::Font*> g_chain;

std::unique_ptr<crisp::Font> load(const char* relative, crisp::FontId id) {
    auto baked = crisp::bake_font_file(std::string(CRISP_SOURCE_DIR) + "/" + relative, crisp::BakeOptions{});
    if (!baked) std::abort();
    auto font = crisp::Font::create(std::move(baked->asset), id);
    if (!font) std::abort();
    return std::make_unique<crisp::Font>(std::move(font).value());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    g_fonts.push_back(load("fuzz/corpus/font/inter-cff-subset.otf", 1));  // a subset: most text falls back
    g_fonts.push_back(load("fonts/DejaVuSans.ttf", 2));
    for (const auto& font : g_fonts) g_chain.push_back(font.get());
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 4) return 0;
    crisp::TextStyle style;
    style.size = 4.0f + static_cast<float>(data[0]);  // 4 to 259 px
    crisp::LayoutOptions options;
    options.wrap_width = (data[1] & 0x80) ? 0.0f : static_cast<float>(data[1]) * 8.0f;
    options.align = static_cast<crisp::Align>(data[2] % 5);
    options.direction = static_cast<crisp::Direction>((data[2] >> 3) % 3);
    options.snap_to_pixels = (data[2] >> 5) & 1;
    options.break_long_words = (data[2] >> 6) & 1;
    options.keep_blank_glyphs = (data[2] >> 7) & 1;
    options.subpixel_steps = 1u << (data[3] % 9);
    options.origin_x = static_cast<float>(data[3]) * 0.37f;
    const std::string_view text(reinterpret_cast<const char*>(data + 4), size - 4);
    auto layout = crisp::layout_text(g_chain, text, style, options);
    if (!layout) __builtin_trap();  // every option above is valid: only bugs fail
    for (const crisp::GlyphInstance& glyph : layout->glyphs) {
        if (glyph.cluster > text.size()) __builtin_trap();
    }

    auto bounds = crisp::TextBoundaries::analyze(text);
    if (!bounds) __builtin_trap();  // the text is within kMaxTextBytes: only bugs fail
    auto on_boundary = [&](crisp::TextPosition position) {
        return position.offset <= text.size() && bounds->is_grapheme_boundary(position.offset);
    };
    // A few hundred positions at most, so that a long input still runs fast: each looks at one line.
    const auto graphemes = bounds->graphemes();
    const size_t stride = graphemes.size() / 256 + 1;
    std::vector<crisp::TextRect> rects;
    for (size_t i = 0; i < graphemes.size(); i += stride) {
        const crisp::TextPosition position{graphemes[i], (i & 1) != 0};
        const crisp::TextRect caret = crisp::caret_rect(*layout, *bounds, position);
        if (!std::isfinite(caret.x) || !std::isfinite(caret.y)) __builtin_trap();
        const crisp::HitTest hit = crisp::hit_test(*layout, *bounds, caret.x + 0.5f, caret.y + caret.height * 0.5f);
        if (!on_boundary(hit.position)) __builtin_trap();
        for (uint8_t motion = 0; motion <= static_cast<uint8_t>(crisp::CaretMotion::down); ++motion) {
            const crisp::Caret moved = crisp::move_caret(*layout, *bounds, {position}, crisp::CaretMotion{motion});
            if (!on_boundary(moved.position)) __builtin_trap();
        }
    }
    crisp::selection_rects(*layout, *bounds, 0, static_cast<uint32_t>(text.size()), rects);
    for (const crisp::TextRect& rect : rects) {
        if (!(rect.width >= 0.0f) || !std::isfinite(rect.x)) __builtin_trap();
    }
    return 0;
}
