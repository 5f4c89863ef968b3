// The fonts the layout fuzz targets lay out with, baked once when the fuzzer starts.
#pragma once

#include <crisp/bake.hpp>
#include <crisp/font.hpp>

#include <cstdlib>
#include <memory>
#include <string>

// The font at `relative` (to the source tree) baked whole as FontId `id`; aborts where it cannot
// be (the fixture, not the input, is wrong).
inline std::unique_ptr<crisp::Font> load_fuzz_font(const char* relative, crisp::FontId id) {
    auto baked = crisp::bake_font_file(std::string(CRISP_SOURCE_DIR) + "/" + relative, crisp::BakeOptions{});
    if (!baked) std::abort();
    auto font = crisp::Font::create(std::move(baked->asset), id);
    if (!font) std::abort();
    return std::make_unique<crisp::Font>(std::move(font).value());
}
