// Measures every compositing mode of support/oit_reference against composite_exact on random text-like
// pixels and prints a Markdown table (docs/oit.md). No GPU. Usage: crisp-oit-study [pixels] [seed]
#include "cli.hpp"
#include "oit_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using crisp::oit::Fragment;
using crisp::oit::LinearRgb;

double srgb_encode(double linear) {
    linear = std::clamp(linear, 0.0, 1.0);
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}
float srgb_decode(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

struct Scene {
    const char* name;
    float alpha;
    bool coplanar;  // depths drawn from 3 planes, paint orders resolving ties
};

// One glyph-like fragment: 30% opaque interiors, the rest edges whose three subpixel coverages
// follow one edge ramp shifted by a third of a pixel per channel.
Fragment make_fragment(std::mt19937& rng, const Scene& scene, uint32_t paint_order) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Fragment f;
    f.depth = scene.coplanar ? static_cast<float>(1 + rng() % 3) * 0.25f : unit(rng);
    f.paint_order = paint_order;
    float coverage[3];
    if (unit(rng) < 0.3f) {
        coverage[0] = coverage[1] = coverage[2] = 1.0f;
    } else {
        const float centre = unit(rng) * 1.6f - 0.3f;
        const float slope = (unit(rng) < 0.5f ? -1.0f : 1.0f) * (0.5f + unit(rng));
        for (int c = 0; c < 3; ++c) {
            coverage[c] = std::clamp(centre + slope * (static_cast<float>(c) - 1.0f) / 3.0f, 0.0f, 1.0f);
        }
    }
    for (int c = 0; c < 3; ++c) {
        const float colour = srgb_decode(unit(rng));
        const float opacity = scene.alpha * coverage[c];
        f.transmittance[c] = 1.0f - opacity;
        f.light[c] = colour * opacity;
    }
    return f;
}

struct Error {
    double sum_squares = 0.0;
    double max = 0.0;
    size_t samples = 0;
    void add(const LinearRgb& got, const LinearRgb& want) {
        for (size_t c = 0; c < 3; ++c) {
            const double e =
                255.0 * std::abs(srgb_encode(static_cast<double>(got[c])) - srgb_encode(static_cast<double>(want[c])));
            sum_squares += e * e;
            max = std::max(max, e);
            ++samples;
        }
    }
    double rmse() const { return samples ? std::sqrt(sum_squares / static_cast<double>(samples)) : 0.0; }
};

// [pixels] [seed], both optional; exits on --help or a usage error (2).
void parse(int argc, char** argv, size_t& pixels, unsigned& seed) {
    crisp::cli::CommandLine cli(
        "crisp-oit-study",
        "usage: crisp-oit-study [PIXELS [SEED]]\n"
        "Measures every compositing mode of the OIT references against the exact one on random\n"
        "text-like pixels (PIXELS per scene, default 20000; SEED, default 1) and prints a\n"
        "Markdown table. No GPU.\n\n");
    cli.on_usage_error(2, " (--help lists the options)");
    int given = 0;
    cli.positional([&](std::string_view text) -> crisp::Status {
        const char* name = given == 0 ? "PIXELS" : "SEED";
        crisp::Result<uint64_t> value = crisp::cli::CommandLine::checked_number<uint64_t>(
            name, text, crisp::cli::Range<uint64_t>{given == 0 ? 1u : 0u, given == 0 ? 100000000u : UINT32_MAX});
        if (!value) return value.error();
        if (given == 0)
            pixels = *value;
        else if (given == 1)
            seed = static_cast<unsigned>(*value);
        else
            return crisp::Error{crisp::ErrorCode::invalid_argument,
                                "unexpected argument '" + crisp::cli::printable(text) + "'"};
        ++given;
        return {};
    });
    cli.parse(argc, argv);
}

}  // namespace

int main(int argc, char** argv) {
    size_t pixels = 20000;
    unsigned seed = 1;
    parse(argc, argv, pixels, seed);
    const Scene scenes[] = {
        {"a=0.9", 0.9f, false}, {"a=0.3", 0.3f, false}, {"a=0.9 coplanar", 0.9f, true}, {"a=0.3 coplanar", 0.3f, true}};
    constexpr uint32_t kLayerCounts[] = {1, 2, 4, 8};
    constexpr size_t kScenes = std::size(scenes);

    std::vector<std::string> rows;
    std::vector<std::vector<Error>> errors;  // [row][scene]
    rows.push_back("unsorted");
    rows.push_back("wboit (eq. 10)");
    rows.push_back("wboit (w = o)");
    for (uint32_t k : kLayerCounts) {
        for (crisp::oit::TailMode mode : crisp::oit::kAllTailModes) {
            rows.push_back("layered K=" + std::to_string(k) + " " + crisp::oit::tail_mode_name(mode));
        }
    }
    errors.assign(rows.size(), std::vector<Error>(kScenes));

    for (size_t s = 0; s < kScenes; ++s) {
        std::mt19937 rng(seed + static_cast<unsigned>(s) * 7919u);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        std::vector<Fragment> fragments;
        for (size_t p = 0; p < pixels; ++p) {
            const size_t count = 1 + rng() % 32;
            fragments.clear();
            // Submission order is paint order; the pixel sees the glyphs in a shuffled arrival order.
            for (size_t i = 0; i < count; ++i) {
                fragments.push_back(make_fragment(rng, scenes[s], static_cast<uint32_t>(i)));
            }
            const LinearRgb background = {srgb_decode(unit(rng)), srgb_decode(unit(rng)), srgb_decode(unit(rng))};
            const LinearRgb exact = crisp::oit::composite_exact(fragments, background);
            size_t row = 0;
            errors[row++][s].add(crisp::oit::composite_unsorted(fragments, background), exact);
            errors[row++][s].add(crisp::oit::composite_wboit(fragments, background), exact);
            errors[row++][s].add(
                crisp::oit::composite_wboit(fragments, background, crisp::oit::WeightFunction::constant), exact);
            std::shuffle(fragments.begin(), fragments.end(), rng);
            for (uint32_t k : kLayerCounts) {
                const crisp::oit::LayeredPixel built = crisp::oit::build_layers(fragments, k);
                for (crisp::oit::TailMode mode : crisp::oit::kAllTailModes) {
                    errors[row++][s].add(crisp::oit::resolve_layers(built, fragments, background, mode), exact);
                }
            }
        }
    }

    std::printf(
        "%zu pixels per scene, 1..32 fragments each, seed %u; error in 8-bit sRGB units vs exact "
        "(RMSE / max)\n\n",
        pixels, seed);
    std::printf("| method |");
    for (const Scene& scene : scenes) std::printf(" %s |", scene.name);
    std::printf("\n|---|");
    for (size_t s = 0; s < kScenes; ++s) std::printf("---|");
    std::printf("\n");
    for (size_t r = 0; r < rows.size(); ++r) {
        std::printf("| %s |", rows[r].c_str());
        for (size_t s = 0; s < kScenes; ++s) std::printf(" %.2f / %.1f |", errors[r][s].rmse(), errors[r][s].max);
        std::printf("\n");
    }
    return 0;
}
