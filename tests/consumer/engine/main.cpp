// Loads an asset baked offline (run.sh bakes it with the installed crisp-bake) and lays out text
// with it, through the installed headers and crisp::crisp only: what an engine does before it
// draws.
#include <crisp/asset.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include <cstdio>
#include <utility>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: engine_consumer ASSET.crisp\n");
        return 2;
    }
    crisp::Result<crisp::FontAsset> asset = crisp::load_asset_file(argv[1]);
    if (!asset) {
        std::fprintf(stderr, "load failed: %s\n", asset.error().message.c_str());
        return 1;
    }
    crisp::Result<crisp::Font> font = crisp::Font::create(std::move(*asset), 0);
    if (!font) {
        std::fprintf(stderr, "font failed: %s\n", font.error().message.c_str());
        return 1;
    }
    const crisp::Font* fonts[] = {&*font};
    crisp::TextStyle style;
    style.size = 32.0f;
    crisp::Result<crisp::TextLayout> layout = crisp::layout_text(fonts, "crisp", style, crisp::LayoutOptions{});
    if (!layout) {
        std::fprintf(stderr, "layout failed: %s\n", layout.error().message.c_str());
        return 1;
    }
    // Five letters, each baked: five glyphs with ink, none missing.
    if (layout->glyphs.size() != 5 || layout->missing_glyphs != 0 || layout->lines.size() != 1) {
        std::fprintf(stderr, "layout: %zu glyphs, %u missing, %zu lines; want 5, 0, 1\n", layout->glyphs.size(),
                     layout->missing_glyphs, layout->lines.size());
        return 1;
    }
    for (const crisp::GlyphInstance& glyph : layout->glyphs) {
        if (glyph.width == 0 || glyph.height == 0) {
            std::fprintf(stderr, "layout: glyph %u has an empty rect\n", glyph.key.glyph);
            return 1;
        }
    }
    std::printf("engine_consumer: laid out %zu glyphs of %s, %.1f px wide\n", layout->glyphs.size(),
                font->asset().info.family.c_str(), static_cast<double>(layout->lines[0].width));
    return 0;
}
