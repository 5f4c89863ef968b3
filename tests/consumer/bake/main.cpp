// Bakes a few glyphs of a font given on the command line and loads the asset back, through the
// installed headers and libraries only.
#include <crisp/asset.hpp>
#include <crisp/bake.hpp>

#include <cstdio>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: bake_consumer FONT\n");
        return 2;
    }
    crisp::BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = {'c', 'r', 'i', 's', 'p'};
    auto baked = crisp::bake_font_file(argv[1], options);
    if (!baked) {
        std::fprintf(stderr, "bake failed: %s\n", baked.error().message.c_str());
        return 1;
    }
    auto loaded = crisp::load_asset(crisp::serialize_asset(baked->asset));
    if (!loaded || !(*loaded == baked->asset)) {
        std::fprintf(stderr, "round trip failed\n");
        return 1;
    }
    std::printf("bake_consumer: baked %u glyphs of %s\n", baked->report.baked_glyphs, loaded->info.family.c_str());
    return 0;
}
