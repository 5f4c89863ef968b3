// Text effects (docs/effects.md) on lavapipe with validation on: every outline placement and join
// and both weights converge, texel by texel, on the exact stroked area (support/stroke_reference);
// shadows are the glyph (with its outline) moved; blurred shadows and glows converge on the exact
// blurred coverage (support/blur_reference); the layers stack under and over their glyph;
// bad parameters are refused with their names; the atlas cost is counted.
#include "blur_reference.hpp"
#include "headless_context.hpp"
#include "shape_support.hpp"
#include "stroke_reference.hpp"
#include "test_support.hpp"

#include "text/blur_kernel.hpp"
#include "text/effect_code.hpp"
#include "text/stroke.hpp"

#include <crisp/bake.hpp>
#include <crisp/effects.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace crisp {
namespace {

HeadlessContext* context() {
    static test::GpuFixture fixture = test::make_gpu_fixture({}, false, "");
    return fixture.context.get();
}

#define REQUIRE_GPU() \
    if (!context()) GTEST_FAIL() << "no Vulkan device (lavapipe is installed by scripts/setup.sh)"

using test::Texel;

// Three hairlines 1/200 em wide.
std::vector<Contour> hairlines() {
    return {test::polygon({{0.1, 0}, {0.105, 0}, {0.105, 0.7}, {0.1, 0.7}}),
            test::polygon({{0, 0.4}, {0.6, 0.4}, {0.6, 0.405}, {0, 0.405}}),
            test::polygon({{0.2, 0.0}, {0.605, 0.7}, {0.6, 0.7}, {0.195, 0.0}})};
}

struct Worst {
    double max = 0.0;   // the largest error of any texel channel of an effect layer
    double mean = 0.0;  // over channels with coverage
    uint64_t channels = 0;
    uint32_t layers = 0;                   // effect layers compared
    std::map<uint32_t, double> by_effect;  // the largest error of the layers of each GlyphKey::effect
};

std::unique_ptr<Renderer> make_renderer(const char* layout, uint32_t samples, SampleKind kind = SampleKind::rows) {
    RendererCreateInfo info = renderer_create_info(*context());
    info.sample_kind = kind;
    info.atlas.width = info.atlas.height = 1024;
    info.atlas.max_samples = samples;
    info.atlas.frame_budget = uint64_t{1} << 40;
    info.layout = *subpixel_preset(layout);
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << renderer.error().message;
    return renderer ? std::make_unique<Renderer>(std::move(*renderer)) : nullptr;
}

// A layer's exact coverage of texel (tx, ty) of its glyph rect, per channel.
using TexelReference = std::function<std::array<double, 3>(uint32_t tx, uint32_t ty)>;
// The reference of a drawn layer; an empty one leaves the layer uncompared.
using LayerReference = std::function<TexelReference(const DrawnGlyph&, const SubpixelLayout&)>;

// Draws `glyphs` with `effects` until converged and holds the texels of every layer that
// `reference_of` gives a reference to that reference.
// Several effects are several draws of the glyphs on one renderer (lavapipe compiles its pipelines
// anew for every renderer: a few seconds each).
Worst converge_and_hold(const Font& font, std::span<const GlyphInstance> glyphs, std::span<const TextEffects> effects,
                        uint32_t samples, const char* layout, const LayerReference& reference_of,
                        SampleKind kind = SampleKind::rows, std::optional<TextTransform> transform = {}) {
    Worst worst;
    auto renderer = make_renderer(layout, samples, kind);
    if (!renderer) return worst;
    EXPECT_TRUE(renderer->add_font(font));
    DrawOptions options;
    options.transform = transform;
    const Result<uint32_t> frames = test::render_until_converged(*context(), *renderer, 4000, [&] {
        for (const TextEffects& e : effects) {
            options.effects = e;
            renderer->draw(glyphs, options);
        }
    });
    EXPECT_TRUE(frames) << frames.error().message;
    EXPECT_TRUE(renderer->converged());
    EXPECT_EQ(renderer->stats().failed_effects, 0u);
    Result<std::vector<Texel>> texels = test::read_atlas(*context(), *renderer);
    EXPECT_TRUE(texels) << texels.error().message;
    if (!texels) return worst;
    const uint32_t atlas_width = renderer->atlas().config().width;
    const SubpixelLayout& sub = *subpixel_preset(layout);
    double sum = 0.0;
    for (const DrawnGlyph& d : renderer->drawn()) {
        const TexelReference reference = reference_of(d, sub);
        if (!reference) continue;
        ++worst.layers;
        for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                const Texel& t = (*texels)[size_t{d.atlas_y + ty} * atlas_width + d.atlas_x + tx];
                EXPECT_EQ(t.count, samples);
                const std::array<double, 3> want = reference(tx + d.part_x, ty + d.part_y);
                const uint16_t sums[3] = {t.r, t.g, t.b};
                for (size_t c = 0; c < 3; ++c) {
                    const double got = static_cast<double>(sums[c]) / (kCoverageOne * std::max<uint32_t>(t.count, 1));
                    if (got == 0.0 && want[c] == 0.0) continue;
                    const double error = std::abs(got - want[c]);
                    worst.max = std::max(worst.max, error);
                    double& mine = worst.by_effect[d.instance.key.effect];
                    mine = std::max(mine, error);
                    sum += error;
                    ++worst.channels;
                }
            }
        }
    }
    if (worst.channels) worst.mean = sum / static_cast<double>(worst.channels);
    const ValidationMessages messages = context()->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
    for (const std::string& text : messages.recent) ADD_FAILURE() << text;
    return worst;
}

// converge_and_hold() of every derived layer to the exact stroked area of its shape.
Worst converge_and_compare(const Font& font, std::span<const GlyphInstance> glyphs,
                           std::span<const TextEffects> effects, uint32_t samples, const char* layout = "gray") {
    return converge_and_hold(
        font, glyphs, effects, samples, layout, [&](const DrawnGlyph& d, const SubpixelLayout& sub) -> TexelReference {
            const GlyphKey& key = d.instance.key;
            if (key.effect == 0) return {};
            const GlyphRecord& own = font.asset().glyphs[key.glyph];
            const Result<DerivedGlyph> derived =
                derive_effect_glyph(font.asset(), own, key.effect, effect_tolerance(effect_octave(key)));
            EXPECT_TRUE(derived);
            if (!derived) return {};
            const EffectShape shape = decode_effect(key.effect);
            auto reference = std::make_shared<StrokeReference>(glyph_contours(font.asset(), own), shape.join,
                                                               shape.half_width, shape.miter_limit, shape.op);
            const TexelToEm map = texel_to_em(glyph_rect(derived->record, key), key);
            return [reference, map, &sub](uint32_t tx, uint32_t ty) { return reference->texel(map, sub, tx, ty); };
        });
}

// converge_and_hold() of every blurred layer to the exact blurred coverage of its source (the
// glyph, or the derived glyph with its op).
Worst converge_and_compare_blur(const Font& font, std::span<const GlyphInstance> glyphs, const TextEffects& effects,
                                uint32_t samples, const char* layout, SampleKind kind = SampleKind::rows,
                                std::optional<TextTransform> transform = {}) {
    const TextEffects one[] = {effects};
    return converge_and_hold(
        font, glyphs, one, samples, layout,
        [&](const DrawnGlyph& d, const SubpixelLayout& sub) -> TexelReference {
            const GlyphKey& key = d.instance.key;
            if (key.blur == 0) return {};
            const GlyphRecord& own = font.asset().glyphs[key.glyph];
            std::shared_ptr<BlurReference> reference;
            GlyphRecord record = own;
            if (key.effect == 0) {
                reference = std::make_shared<BlurReference>(BlurReference::of_glyph(font.asset(), own));
            } else {
                const Result<DerivedGlyph> derived =
                    derive_effect_glyph(font.asset(), own, key.effect, effect_tolerance(effect_octave(key)));
                EXPECT_TRUE(derived);
                if (!derived) return {};
                reference =
                    std::make_shared<BlurReference>(BlurReference::of_derived(*derived, decode_effect(key.effect).op));
                record = derived->record;
            }
            // The rect's map: a transformed key's em_to_texel(), affine in these tests.
            const Projective map = em_to_texel(glyph_rect(record, key), key);
            const double w = blur_box_width(key.blur * kBlurUnit);
            return [reference, map, &sub, w](uint32_t tx, uint32_t ty) {
                const std::array<double, 3> want = reference->texel(map, sub, tx, ty, w);
                EXPECT_LE(reference->error(), 1e-5);
                return want;
            };
        },
        kind, transform);
}

std::vector<GlyphInstance> lay_out(const Font& font, std::string_view text, float size, float x, float y) {
    const Font* fonts[] = {&font};
    LayoutOptions options;
    options.origin_x = x;
    options.origin_y = y;
    auto layout = layout_text(fonts, text, {.size = size}, options);
    EXPECT_TRUE(layout);
    return layout ? layout->glyphs : std::vector<GlyphInstance>{};
}

TextEffects outline(float width, OutlinePlacement placement, LineJoin join, float weight = 0.0f) {
    TextEffects e;
    e.weight = weight;
    e.outline = TextOutline{width, placement, join, 4.0f, {0.0f, 0.0f, 0.0f, 1.0f}};
    return e;
}

// The converged coverage's target: 1/128 per texel channel of the exact stroked area.
constexpr double kTarget = 1.0 / 128.0;

TEST(Effects, OutlinesOfEveryPlacementAndJoinMatchTheExactStroke) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "MW4");
    ASSERT_TRUE(font);
    for (const float size : {8.0f, 16.0f, 48.0f}) {
        const std::vector<GlyphInstance> glyphs = lay_out(*font, "MW4", size, 3.3f, 4.0f + size);
        const float width = std::max(1.0f, size / 16.0f);
        std::vector<TextEffects> all;
        for (const OutlinePlacement placement :
             {OutlinePlacement::outside, OutlinePlacement::inside, OutlinePlacement::centred}) {
            for (const LineJoin join : {LineJoin::round, LineJoin::miter, LineJoin::bevel}) {
                all.push_back(outline(width, placement, join));
            }
        }
        const Worst w = converge_and_compare(*font, glyphs, all, 256);
        EXPECT_EQ(w.layers, 3u * all.size());
        EXPECT_EQ(w.by_effect.size(), all.size());
        for (const auto& [code, max] : w.by_effect) {
            const EffectShape shape = decode_effect(code);
            std::printf("[ effects ] MW4 %2.0f px, op %d, %s join, outline %.1f px: max %.4f\n",
                        static_cast<double>(size), static_cast<int>(shape.op),
                        line_join_name(static_cast<LineJoin>(shape.join)), static_cast<double>(width), max);
            EXPECT_LE(max, kTarget) << size << " px, op " << static_cast<int>(shape.op) << " "
                                    << line_join_name(static_cast<LineJoin>(shape.join));
        }
    }
}

TEST(Effects, SharpCornersStaySharpOnAStarAndHairlinesAt200Pixels) {
    REQUIRE_GPU();
    struct Shape {
        const char* name;
        std::vector<Contour> contours;
    };
    for (const Shape& shape : {Shape{"star", test::star()}, Shape{"hairlines", hairlines()}}) {
        uint32_t index = 0;
        auto font = test::with_shape(shape.contours, index);
        ASSERT_TRUE(font);
        for (const float size : {8.0f, 16.0f, 48.0f, 200.0f}) {
            const GlyphInstance glyph = test::place(*font, index, size, 2.25f, 2.0f + size);
            // From 48 px (lavapipe's time) miter joins only, at 200 px with fewer samples.
            std::vector<TextEffects> joins = {outline(size / 24.0f, OutlinePlacement::outside, LineJoin::miter)};
            if (size < 40.0f) joins.push_back(outline(size / 24.0f, OutlinePlacement::outside, LineJoin::round));
            const Worst w = converge_and_compare(*font, {&glyph, 1}, joins, size > 100.0f ? 128 : 256);
            for (const auto& [code, max] : w.by_effect) {
                std::printf("[ effects ] %s %3.0f px, %s outline %.2f px: max %.4f\n", shape.name,
                            static_cast<double>(size), line_join_name(static_cast<LineJoin>(decode_effect(code).join)),
                            static_cast<double>(size / 24.0f), max);
            }
            EXPECT_EQ(w.layers, joins.size());
            EXPECT_LE(w.max, kTarget) << shape.name << " " << size << " px";
        }
    }
}

TEST(Effects, OverlappingContoursAreOutlinedAlongTheFillsEdge) {
    REQUIRE_GPU();
    // A plus drawn as two overlapping bars: its inside and centred outlines and its thinning follow
    // the plus's edge (the twelve-sided polygon the reference is given), not the bars' edges inside it.
    uint32_t index = 0;
    auto font = test::with_shape({test::polygon({{0.1, 0.3}, {0.1, 0.5}, {0.7, 0.5}, {0.7, 0.3}}),
                                  test::polygon({{0.3, 0.1}, {0.3, 0.7}, {0.5, 0.7}, {0.5, 0.1}})},
                                 index);
    ASSERT_TRUE(font);
    const std::vector<Contour> plus = {test::polygon({{0.1, 0.3},
                                                      {0.1, 0.5},
                                                      {0.3, 0.5},
                                                      {0.3, 0.7},
                                                      {0.5, 0.7},
                                                      {0.5, 0.5},
                                                      {0.7, 0.5},
                                                      {0.7, 0.3},
                                                      {0.5, 0.3},
                                                      {0.5, 0.1},
                                                      {0.3, 0.1},
                                                      {0.3, 0.3}})};
    auto renderer = make_renderer("gray", 256);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*font));
    const GlyphInstance glyph = test::place(*font, index, 40.0f, 2.5f, 42.0f);
    for (const OutlinePlacement placement : {OutlinePlacement::inside, OutlinePlacement::centred}) {
        DrawOptions options;
        options.effects = outline(3.0f, placement, LineJoin::miter);
        const Result<uint32_t> frames = test::render_until_converged(*context(), *renderer, 4000, [&] {
            renderer->draw({&glyph, 1}, options);
        });
        ASSERT_TRUE(frames) << frames.error().message;
        Result<std::vector<Texel>> texels = test::read_atlas(*context(), *renderer);
        ASSERT_TRUE(texels);
        double worst = 0.0;
        uint32_t layers = 0;
        for (const DrawnGlyph& d : renderer->drawn()) {
            if (d.instance.key.effect == 0) continue;
            ++layers;
            const EffectShape shape = decode_effect(d.instance.key.effect);
            const StrokeReference reference(plus, shape.join, shape.half_width, shape.miter_limit, shape.op);
            const Result<DerivedGlyph> derived =
                derive_effect_glyph(font->asset(), font->asset().glyphs[index], d.instance.key.effect,
                                    effect_tolerance(effect_octave(d.instance.key)));
            ASSERT_TRUE(derived);
            const TexelToEm map = texel_to_em(glyph_rect(derived->record, d.instance.key), d.instance.key);
            const uint32_t side = renderer->atlas().config().width;
            for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
                for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                    const Texel& t = (*texels)[size_t{d.atlas_y + ty} * side + d.atlas_x + tx];
                    const double got = static_cast<double>(t.r) / (kCoverageOne * std::max<uint32_t>(t.count, 1));
                    worst = std::max(worst, std::abs(got - reference.texel(map, *subpixel_preset("gray"), tx, ty)[0]));
                }
            }
        }
        std::printf("[ effects ] plus of two bars, %s outline 3 px at 40 px: max %.4f\n",
                    outline_placement_name(placement), worst);
        EXPECT_EQ(layers, 1u);
        EXPECT_LE(worst, kTarget) << outline_placement_name(placement);
    }
}

TEST(Effects, WeightGrowsAndShrinksTheFaceExactly) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "MW4");
    ASSERT_TRUE(font);
    for (const float weight : {0.75f, -0.5f}) {
        for (const char* layout : {"gray", "rgb"}) {
            const std::vector<GlyphInstance> glyphs = lay_out(*font, "MW4", 16.0f, 2.6f, 20.0f);
            TextEffects e;
            e.weight = weight;
            const Worst w = converge_and_compare(*font, glyphs, {&e, 1}, 256, layout);
            std::printf("[ effects ] MW4 16 px %s, weight %+.2f px: max %.4f, mean %.5f\n", layout,
                        static_cast<double>(weight), w.max, w.mean);
            EXPECT_EQ(w.layers, 3u);
            EXPECT_LE(w.max, kTarget) << weight;
        }
    }
}

// Runs one frame of `draw` and returns the drawn glyphs (each with samples after one frame).
std::vector<DrawnGlyph> one_frame(Renderer& renderer, const std::function<void()>& draw) {
    const Result<uint32_t> frames = test::render_until_converged(*context(), renderer, 1, draw);
    EXPECT_TRUE(frames) << frames.error().message;
    const auto drawn = renderer.drawn();
    return {drawn.begin(), drawn.end()};
}

TEST(Effects, LayersStackShadowOutlineFaceInThatOrder) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "MW4");
    ASSERT_TRUE(font);
    auto renderer = make_renderer("rgb", 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*font));
    std::vector<GlyphInstance> glyphs = lay_out(*font, "MW4", 16.0f, 3.0f, 20.0f);
    for (GlyphInstance& g : glyphs) g.paint_order += 10;  // 10, 11, 12
    DrawOptions options;
    options.effects = outline(1.5f, OutlinePlacement::outside, LineJoin::round);
    options.effects->shadow = TextShadow{2.0f, 3.0f, {0.0f, 0.0f, 0.0f, 0.5f}};
    const std::vector<DrawnGlyph> drawn = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    ASSERT_EQ(drawn.size(), 9u);
    std::map<uint32_t, uint32_t> per_stack;
    for (const DrawnGlyph& d : drawn) {
        ++per_stack[d.stack];
        if (d.stack == kStackGlyph) {
            EXPECT_EQ(d.instance.key.effect, 0u);
            EXPECT_GE(d.instance.paint_order, 10u);
        } else {
            // Under every glyph of the draw: its first paint order, a smaller stack.
            EXPECT_EQ(d.instance.paint_order, 10u);
            EXPECT_NE(d.instance.key.effect, 0u);  // the shadow is the glyph with its outline
        }
        if (d.stack == kStackShadow) {
            // Moved by (2, 3) px: the same subpixel offset as its glyph, 2 and 3 px further.
            const auto glyph = std::find_if(drawn.begin(), drawn.end(), [&](const DrawnGlyph& g) {
                return g.stack == kStackGlyph && g.instance.cluster == d.instance.cluster;
            });
            ASSERT_NE(glyph, drawn.end());
            EXPECT_EQ(d.instance.key.subpixel_x, glyph->instance.key.subpixel_x);
            EXPECT_FLOAT_EQ(d.instance.pen_x, glyph->instance.pen_x + 2.0f);
            EXPECT_FLOAT_EQ(d.instance.pen_y, glyph->instance.pen_y + 3.0f);
            EXPECT_FLOAT_EQ(d.instance.color[3], 0.5f);
        }
    }
    EXPECT_EQ(per_stack[kStackShadow], 3u);
    EXPECT_EQ(per_stack[kStackOutlineUnder], 3u);
    EXPECT_EQ(per_stack[kStackGlyph], 3u);
    const RendererStats& stats = renderer->stats();
    EXPECT_EQ(stats.effect_layers, 6u);
    EXPECT_GT(stats.effect_texels, 0u);
    EXPECT_EQ(stats.derived_glyphs, 6u);  // per glyph: the outline, the shadow's outlined glyph
    EXPECT_EQ(stats.derived_made, 6u);
    EXPECT_GT(stats.derived_bytes, 0u);
    // Centred and inside outlines lie over the glyph, at the draw's last paint order.
    options.effects = outline(1.0f, OutlinePlacement::centred, LineJoin::bevel);
    const std::vector<DrawnGlyph> over = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    ASSERT_EQ(over.size(), 6u);
    for (const DrawnGlyph& d : over) {
        if (d.stack != kStackGlyph) {
            EXPECT_EQ(d.stack, kStackOutlineOver);
            EXPECT_EQ(d.instance.paint_order, 12u);
        }
    }
    // The derived glyphs leave with their font.
    ASSERT_TRUE(renderer->remove_font(font->id()));
    one_frame(*renderer, [] {});
    EXPECT_EQ(renderer->stats().derived_glyphs, 0u);
    const ValidationMessages messages = context()->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
}

TEST(Effects, BlurredShadowsConvergeOnTheExactBlur) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "M");
    ASSERT_TRUE(font);
    struct Case {
        float size, blur;
        const char* layout;
    };
    for (const Case& c : {Case{16.0f, 1.5f, "gray"}, Case{16.0f, 1.5f, "rgb"}, Case{16.0f, 6.0f, "gray"},
                          Case{16.0f, 6.0f, "rgb"}, Case{48.0f, 1.5f, "rgb"}, Case{48.0f, 6.0f, "gray"}}) {
        const std::vector<GlyphInstance> glyphs = lay_out(*font, "M", c.size, 3.3f, 4.0f + c.size);
        TextEffects e;
        e.shadow = TextShadow{1.5f, 2.25f, {0.0f, 0.0f, 0.0f, 0.5f}, c.blur};
        const Worst w = converge_and_compare_blur(*font, glyphs, e, 256, c.layout);
        std::printf("[ effects ] M %2.0f px %s, shadow blurred %.1f px: max %.4f, mean %.5f over %llu channels\n",
                    static_cast<double>(c.size), c.layout, static_cast<double>(c.blur), w.max, w.mean,
                    static_cast<unsigned long long>(w.channels));
        EXPECT_EQ(w.layers, 1u);
        EXPECT_LE(w.max, kTarget) << c.size << " px " << c.layout << " blur " << c.blur;
    }
}

TEST(Effects, GlowsOfOutlinedGlyphsConvergeOnTheExactBlurAndStackUnderTheOutline) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "o");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "o", 16.0f, 2.6f, 20.0f);
    for (const char* layout : {"gray", "rgb"}) {
        TextEffects e = outline(1.0f, OutlinePlacement::outside, LineJoin::round);
        e.glow = TextGlow{4.0f, {1.0f, 0.8f, 0.2f, 0.75f}};
        const Worst w = converge_and_compare_blur(*font, glyphs, e, 256, layout);
        std::printf("[ effects ] o 16 px %s, outline 1 px, glow 4 px: max %.4f, mean %.5f over %llu channels\n", layout,
                    w.max, w.mean, static_cast<unsigned long long>(w.channels));
        EXPECT_EQ(w.layers, 1u);
        EXPECT_LE(w.max, kTarget) << layout;
    }
    // Without an outline the glow is the glyph's own outline blurred.
    TextEffects plain;
    plain.glow = TextGlow{1.5f, {1.0f, 1.0f, 1.0f, 0.75f}};
    const Worst w = converge_and_compare_blur(*font, glyphs, plain, 256, "gray");
    std::printf("[ effects ] o 16 px gray, glow 1.5 px: max %.4f, mean %.5f\n", w.max, w.mean);
    EXPECT_EQ(w.layers, 1u);
    EXPECT_LE(w.max, kTarget);
    // The layers: shadow, glow, outline, face, back to front; the glow unmoved, at the first paint order.
    auto renderer = make_renderer("gray", 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*font));
    DrawOptions options;
    options.effects = outline(1.0f, OutlinePlacement::outside, LineJoin::round);
    options.effects->shadow = TextShadow{2.0f, 2.0f, {0.0f, 0.0f, 0.0f, 0.5f}, 3.0f};
    options.effects->glow = TextGlow{4.0f, {1.0f, 1.0f, 1.0f, 0.5f}};
    const std::vector<DrawnGlyph> drawn = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    ASSERT_EQ(drawn.size(), 4u);
    std::map<uint32_t, const DrawnGlyph*> by_stack;
    for (const DrawnGlyph& d : drawn) by_stack[d.stack] = &d;
    ASSERT_EQ(by_stack.size(), 4u);
    const DrawnGlyph& face = *by_stack[kStackGlyph];
    const DrawnGlyph& glow = *by_stack[kStackGlow];
    const DrawnGlyph& shadow = *by_stack[kStackShadow];
    EXPECT_EQ(glow.instance.key.blur, 4 * 64);
    EXPECT_EQ(shadow.instance.key.blur, 3 * 64);
    EXPECT_EQ(glow.instance.key.effect, shadow.instance.key.effect);  // the glyph with its outline
    EXPECT_NE(glow.instance.key.effect, 0u);
    EXPECT_EQ(by_stack[kStackOutlineUnder]->instance.key.blur, 0);
    EXPECT_EQ(face.instance.key.blur, 0);
    EXPECT_FLOAT_EQ(glow.instance.pen_x, face.instance.pen_x);
    EXPECT_FLOAT_EQ(glow.instance.pen_y, face.instance.pen_y);
    EXPECT_FLOAT_EQ(glow.instance.color[3], 0.5f);
    // The blurred rect reaches ceil(R + 1) texels further on each side than the unblurred source.
    EXPECT_EQ(glow.instance.width, by_stack[kStackOutlineUnder]->instance.width + 2u * 5u);
    const ValidationMessages messages = context()->validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u);
}

TEST(Effects, BlurredPointSamplesAndTransformedGlyphsConvergeOnTheExactBlur) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "M");
    ASSERT_TRUE(font);
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "M", 16.0f, 3.3f, 20.0f);
    // Point samples: each point's x and y the inverse CDFs of its channel's filters at its R2
    // offset, converging as points do (a coverage step per sample, not a covered length).
    TextEffects e;
    e.shadow = TextShadow{1.0f, 1.0f, {0.0f, 0.0f, 0.0f, 0.5f}, 3.0f};
    const Worst points = converge_and_compare_blur(*font, glyphs, e, 1023, "gray", SampleKind::points);
    std::printf("[ effects ] M 16 px gray, points, shadow blurred 3 px: max %.4f, mean %.5f over %llu channels\n",
                points.max, points.mean, static_cast<unsigned long long>(points.channels));
    EXPECT_EQ(points.layers, 1u);
    EXPECT_LE(points.max, 2.0 * kTarget);
    // Transformed glyphs are blurred in the target's pixels: rotated by 37 degrees (one line a
    // sample) and by 80 (two lines, stems along the rows), a blurred shadow and a glow each.
    e.glow = TextGlow{2.0f, {1.0f, 1.0f, 1.0f, 0.75f}};
    // Outlined, the two-set source is blurred.
    struct Case {
        const char* name;
        TextTransform transform;
        const char* layout;
        bool outlined;
    };
    for (const Case& c : {Case{"37 degrees", {0.8f, -0.6f, 0.6f, 0.8f, 3.0f, 20.0f}, "gray", false},
                          Case{"37 degrees", {0.8f, -0.6f, 0.6f, 0.8f, 3.0f, 20.0f}, "rgb", false},
                          Case{"80 degrees", {0.173648f, -0.984808f, 0.984808f, 0.173648f, 3.0f, 20.0f}, "gray", false},
                          Case{"37 degrees", {0.8f, -0.6f, 0.6f, 0.8f, 3.0f, 20.0f}, "gray", true}}) {
        TextEffects fx = e;
        if (c.outlined) fx.outline = TextOutline{1.0f, OutlinePlacement::outside, LineJoin::round, 4.0f, {0, 0, 0, 1}};
        const Worst w = converge_and_compare_blur(*font, glyphs, fx, 256, c.layout, SampleKind::rows, c.transform);
        std::printf("[ effects ] M 16 px %s, rotated %s%s, shadow blurred 3 px, glow 2 px: max %.4f, mean %.5f\n",
                    c.layout, c.name, c.outlined ? ", outlined 1 px" : "", w.max, w.mean);
        EXPECT_EQ(w.layers, 2u);
        EXPECT_LE(w.max, kTarget) << c.name << " " << c.layout;
    }
}

// Colour glyphs of crisp's COLRv0 test font (tests/fonts/colour/README.md): four_layers (U+E002)
// is the square, the circle, the ring and the bar, whose union is the square.
constexpr uint32_t kSquare = 1, kRing = 3, kBar = 4, kFourLayers = 16;

std::unique_ptr<Font> colour_font(bool ring_and_bar = false) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = {0xE002};
    Result<BakeResult> baked = bake_font_file(test::source_path("tests/fonts/colour/colrv0.ttf"), options);
    EXPECT_TRUE(baked) << (baked ? "" : baked.error().message);
    if (!baked) return nullptr;
    if (ring_and_bar) {
        // Two layers that cross: the bar through the ring's hole, out past its sides.
        FontAsset& asset = baked->asset;
        ColourGlyph& four = asset.colour_glyphs.front();
        EXPECT_EQ(four.glyph, kFourLayers);
        asset.layers[four.first_layer] = asset.layers[four.first_layer + 2];
        asset.layers[four.first_layer + 1] = asset.layers[four.first_layer + 3];
        EXPECT_EQ(asset.layers[four.first_layer].glyph, kRing);
        EXPECT_EQ(asset.layers[four.first_layer + 1].glyph, kBar);
        four.layer_count = 2;
        // The bar mirrored about its middle (x = 1/2 em): the same rectangle wound the other way,
        // as a CFF layer among TrueType ones would be.
        const GlyphRecord& bar = asset.glyphs[kBar];
        for (uint32_t i = 0; i < 2 * bar.curve_count + 1; ++i) {
            Point& point = asset.points[size_t{bar.point_offset} + i];
            point.x = 1.0f - point.x;
        }
    }
    Result<Font> font = Font::create(std::move(baked->asset), 1);
    EXPECT_TRUE(font) << (font ? "" : font.error().message);
    return font ? std::make_unique<Font>(std::move(*font)) : nullptr;
}

// converge_and_hold() of every layer around a colour glyph to the exact stroked area of its
// silhouette, the union of `fills` (StrokeReference's union: exact for every op where the fills
// are the silhouette's own boundary, for the outside ones otherwise), or blurred, to the exact
// blurred coverage of the silhouette's derived glyph.
Worst converge_and_compare_silhouette(const Font& font, std::span<const GlyphInstance> glyphs,
                                      std::span<const TextEffects> effects, uint32_t samples,
                                      const std::vector<std::vector<Contour>>& fills) {
    return converge_and_hold(
        font, glyphs, effects, samples, "gray", [&](const DrawnGlyph& d, const SubpixelLayout& sub) -> TexelReference {
            const GlyphKey& key = d.instance.key;
            if (!(key.glyph & kSilhouetteGlyph)) return {};
            EXPECT_NE(key.effect, 0u);
            EXPECT_EQ(d.instance.paint, kNoPaint);
            const ColourGlyph* colour = font.asset().colour_glyph(key.glyph & ~kSilhouetteGlyph);
            EXPECT_TRUE(colour);
            if (!colour) return {};
            const Result<DerivedGlyph> derived =
                derive_silhouette_glyph(font.asset(), *colour, key.effect, effect_tolerance(effect_octave(key)));
            EXPECT_TRUE(derived) << (derived ? "" : derived.error().message);
            if (!derived) return {};
            const EffectShape shape = decode_effect(key.effect);
            if (key.blur != 0) {
                auto reference = std::make_shared<BlurReference>(BlurReference::of_derived(*derived, shape.op));
                const Projective map = em_to_texel(glyph_rect(derived->record, key), key);
                const double w = blur_box_width(key.blur * kBlurUnit);
                return [reference, map, &sub, w](uint32_t tx, uint32_t ty) {
                    return reference->texel(map, sub, tx, ty, w);
                };
            }
            auto reference =
                std::make_shared<StrokeReference>(fills, shape.join, shape.half_width, shape.miter_limit, shape.op);
            const TexelToEm map = texel_to_em(glyph_rect(derived->record, key), key);
            return [reference, map, &sub](uint32_t tx, uint32_t ty) { return reference->texel(map, sub, tx, ty); };
        });
}

TEST(Effects, ColourGlyphsAreOutlinedAroundTheirSilhouette) {
    REQUIRE_GPU();
    auto font = colour_font();
    ASSERT_TRUE(font);
    const FontAsset& asset = font->asset();
    // The silhouette of four layers that touch, share edges and overlap is the square.
    const std::vector<std::vector<Contour>> square = {glyph_contours(asset, asset.glyphs[kSquare])};
    for (const float size : {16.0f, 48.0f}) {
        const std::vector<GlyphInstance> glyphs = lay_out(*font, "\uE002", size, 3.3f, 4.0f + size);
        ASSERT_EQ(glyphs.size(), 4u);
        const float width = std::max(1.5f, size / 16.0f);
        const TextEffects all[] = {outline(width, OutlinePlacement::outside, LineJoin::round),
                                   outline(width, OutlinePlacement::inside, LineJoin::miter),
                                   outline(width, OutlinePlacement::centred, LineJoin::bevel)};
        const Worst w = converge_and_compare_silhouette(*font, glyphs, all, 128, square);
        EXPECT_EQ(w.layers, 3u);  // one outline of each colour glyph, not one of each layer
        for (const auto& [code, max] : w.by_effect) {
            const EffectShape shape = decode_effect(code);
            std::printf("[ effects ] four_layers %2.0f px, op %d, %s join: max %.4f\n", static_cast<double>(size),
                        static_cast<int>(shape.op), line_join_name(static_cast<LineJoin>(shape.join)), max);
            EXPECT_LE(max, kTarget) << size << " px, op " << static_cast<int>(shape.op);
        }
    }
}

TEST(Effects, ColourGlyphsThatCrossHaveTheirUnionOutlinedAndShadowed) {
    REQUIRE_GPU();
    auto font = colour_font(true);
    ASSERT_TRUE(font);
    const FontAsset& asset = font->asset();
    const std::vector<std::vector<Contour>> ring_and_bar = {glyph_contours(asset, asset.glyphs[kRing]),
                                                            glyph_contours(asset, asset.glyphs[kBar])};
    // The bar is wound against the ring: a silhouette of the layers' curves added up would cancel
    // where the bar crosses the ring.
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "\uE002", 24.0f, 3.3f, 30.0f);
    ASSERT_EQ(glyphs.size(), 2u);
    TextEffects outlined = outline(2.0f, OutlinePlacement::outside, LineJoin::miter);
    TextEffects shadowed;
    shadowed.shadow = TextShadow{1.5f, 2.0f, {0.0f, 0.0f, 0.0f, 0.5f}, 2.0f};
    const TextEffects both[] = {outlined, shadowed};
    const Worst w = converge_and_compare_silhouette(*font, glyphs, both, 128, ring_and_bar);
    EXPECT_EQ(w.layers, 2u);
    std::printf("[ effects ] ring and bar 24 px, outline and blurred shadow: max %.4f, mean %.5f\n", w.max, w.mean);
    for (const auto& [code, max] : w.by_effect) std::printf("  code %x: %.4f\n", code, max);
    EXPECT_LE(w.max, kTarget);
}

TEST(Effects, ColourGlyphLayersAreEachWeightedAndBitmapsAreLeftAsTheyAre) {
    REQUIRE_GPU();
    auto font = colour_font();
    ASSERT_TRUE(font);
    auto renderer = make_renderer("gray", 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*font));
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "\uE002\uE002", 20.0f, 3.0f, 24.0f);
    ASSERT_EQ(glyphs.size(), 8u);
    DrawOptions options;
    options.effects = outline(1.0f, OutlinePlacement::outside, LineJoin::round, 0.5f);
    options.effects->shadow = TextShadow{1.0f, 1.0f, {0.0f, 0.0f, 0.0f, 1.0f}, 0.0f};
    const std::vector<DrawnGlyph> drawn = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    EXPECT_EQ(renderer->stats().failed_effects, 0u);
    // Each of the two glyphs: a shadow and an outline of its silhouette under its four layers,
    // each layer emboldened and keeping its paint.
    ASSERT_EQ(drawn.size(), 12u);
    uint32_t silhouettes = 0, faces = 0;
    for (const DrawnGlyph& d : drawn) {
        if (d.instance.key.glyph & kSilhouetteGlyph) {
            ++silhouettes;
            EXPECT_EQ(d.instance.paint, kNoPaint);
            EXPECT_LT(d.stack, kStackGlyph);
            EXPECT_EQ(d.instance.key.glyph & ~kSilhouetteGlyph, kFourLayers);
        } else {
            ++faces;
            EXPECT_NE(d.instance.paint, kNoPaint);
            EXPECT_NE(d.instance.key.effect, 0u);  // weighted
            EXPECT_EQ(d.stack, kStackGlyph);
        }
    }
    EXPECT_EQ(silhouettes, 4u);
    EXPECT_EQ(faces, 8u);

    // A bitmap glyph has no outline: drawn as it is, counted once.
    const std::string noto = "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf";
    if (!std::filesystem::exists(noto)) GTEST_SKIP() << noto << " is missing (scripts/setup.sh installs it)";
    BakeOptions bitmap;
    bitmap.all_glyphs = false;
    bitmap.codepoints = {0x1F600};
    Result<BakeResult> baked = bake_font_file(noto, bitmap);
    ASSERT_TRUE(baked) << baked.error().message;
    Result<Font> emoji = Font::create(std::move(baked->asset), 2);
    ASSERT_TRUE(emoji);
    ASSERT_TRUE(renderer->add_font(*emoji));
    const std::vector<GlyphInstance> smile = lay_out(*emoji, "\U0001F600", 20.0f, 3.0f, 24.0f);
    ASSERT_EQ(smile.size(), 1u);
    const std::vector<DrawnGlyph> as_is = one_frame(*renderer, [&] { renderer->draw(smile, options); });
    EXPECT_EQ(as_is.size(), 1u);
    EXPECT_EQ(renderer->stats().failed_effects, 1u);
}

TEST(Effects, ABlurredKeysCostCountsThePassesOfItsWiderRows) {
    // 24 bars 1/100 em wide, 1/50 em apart, full height: 48 crossings on every row, the same
    // curves in every band (their vertical sides; the flat tops and bottoms are in none).
    std::vector<Contour> bars;
    for (int i = 0; i < 24; ++i) {
        const double x = 0.05 + 0.02 * i;
        bars.push_back(test::polygon({{x, 0.0}, {x, 0.7}, {x + 0.01, 0.7}, {x + 0.01, 0.0}}));
    }
    uint32_t index = 0;
    auto font = test::with_shape(bars, index);
    ASSERT_TRUE(font);
    const GlyphRecord& record = font->asset().glyphs[index];
    GlyphKey key;
    key.font = 1;
    key.glyph = index;
    key.size_x = key.size_y = 32 * kSizeOne;
    const auto texels = [&](const GlyphKey& k) {
        const GlyphRect rect = glyph_rect(record, k);
        return uint64_t{rect.width} * rect.height;
    };
    const uint64_t plain = curve_tests_per_sample(font->asset(), record, key);
    ASSERT_EQ(plain % texels(key), 0u);
    const uint64_t per_texel = plain / texels(key);  // the curves of a band
    EXPECT_GE(per_texel, 48u);
    // A blur of 1/64 px reaches no further crossing: one pass a texel, over its wider rect.
    key.blur = 1;
    EXPECT_EQ(curve_tests_per_sample(font->asset(), record, key), per_texel * texels(key));
    // 8 px: a texel's row reaches 8 texels either side, over 20 texels of bars' 32: up to 30
    // crossings, four passes; more than two on average over the rect and its margins.
    key.blur = 8 * 64;
    const uint64_t blurred = curve_tests_per_sample(font->asset(), record, key);
    EXPECT_GT(blurred, 2 * per_texel * texels(key));
    EXPECT_LE(blurred, 6 * per_texel * texels(key));
}

TEST(Effects, EffectsPastTheGlyphsLimitsAreLeftOutAndCounted) {
    REQUIRE_GPU();
    auto font = test::bake_subset(test::kDejaVuSans, "MW4");
    ASSERT_TRUE(font);
    auto renderer = make_renderer("gray", 8);
    ASSERT_TRUE(renderer);
    ASSERT_TRUE(renderer->add_font(*font));
    const std::vector<GlyphInstance> glyphs = lay_out(*font, "M", 4.0f, 3.0f, 20.0f);
    DrawOptions options;
    options.effects = outline(17.0f, OutlinePlacement::outside, LineJoin::round);  // 4.25 em at 4 px
    const std::vector<DrawnGlyph> drawn = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    EXPECT_EQ(drawn.size(), 1u);  // the glyph, without its outline
    EXPECT_EQ(renderer->stats().failed_effects, 1u);
    EXPECT_FALSE(validate_text_effects(*options.effects, 4.0f));
    EXPECT_TRUE(validate_text_effects(*options.effects, 8.0f));
    // Effects validate_text_effects() refuses draw nothing.
    options.effects->outline->width = -1.0f;
    const std::vector<DrawnGlyph> none = one_frame(*renderer, [&] { renderer->draw(glyphs, options); });
    EXPECT_TRUE(none.empty());
    EXPECT_EQ(renderer->stats().skipped_glyphs, 1u);
}

TEST(Effects, BadParametersAreRefusedByName) {
    const auto message = [](const TextEffects& e) {
        const Status s = validate_text_effects(e);
        return s ? std::string() : s.error().message;
    };
    TextEffects e;
    EXPECT_EQ(message(e), "");
    e.weight = std::nanf("");
    EXPECT_NE(message(e).find("weight nan"), std::string::npos) << message(e);
    e.weight = 1e6f;
    EXPECT_NE(message(e).find("weight"), std::string::npos) << message(e);
    e = outline(-2.0f, OutlinePlacement::outside, LineJoin::round);
    EXPECT_NE(message(e).find("outline width -2 is negative"), std::string::npos) << message(e);
    e.outline->width = std::numeric_limits<float>::infinity();
    EXPECT_NE(message(e).find("outline width inf is not finite"), std::string::npos) << message(e);
    e.outline->width = 1.0f;
    e.outline->miter_limit = 0.5f;
    EXPECT_NE(message(e).find("miter_limit 0.5"), std::string::npos) << message(e);
    e.outline->miter_limit = 4.0f;
    e.outline->color[1] = 2.0f;
    EXPECT_NE(message(e).find("outline color"), std::string::npos) << message(e);
    e.outline->color[1] = 0.0f;
    e.outline->join = static_cast<LineJoin>(7);
    EXPECT_NE(message(e).find("outline join 7"), std::string::npos) << message(e);
    e.outline->join = LineJoin::round;
    e.outline->placement = static_cast<OutlinePlacement>(9);
    EXPECT_NE(message(e).find("outline placement 9"), std::string::npos) << message(e);
    e.outline->placement = OutlinePlacement::centred;
    e.shadow = TextShadow{std::nanf(""), 0.0f, {0.0f, 0.0f, 0.0f, 1.0f}};
    EXPECT_NE(message(e).find("shadow offset nan"), std::string::npos) << message(e);
    e.shadow->offset_x = 5000.0f;
    EXPECT_NE(message(e).find("shadow offset 5000"), std::string::npos) << message(e);
    e.shadow->offset_x = 1.0f;
    EXPECT_EQ(message(e), "");
    e.shadow->blur = -1.0f;
    EXPECT_NE(message(e).find("shadow blur -1"), std::string::npos) << message(e);
    e.shadow->blur = 200.0f;
    EXPECT_NE(message(e).find("shadow blur 200"), std::string::npos) << message(e);
    e.shadow->blur = 6.0f;
    EXPECT_EQ(message(e), "");
    e.glow = TextGlow{0.0f, {1.0f, 1.0f, 1.0f, 1.0f}};
    EXPECT_NE(message(e).find("glow radius 0"), std::string::npos) << message(e);
    e.glow->radius = std::nanf("");
    EXPECT_NE(message(e).find("glow radius nan"), std::string::npos) << message(e);
    e.glow->radius = 4.0f;
    e.glow->color[3] = -0.5f;
    EXPECT_NE(message(e).find("glow color"), std::string::npos) << message(e);
    e.glow->color[3] = 1.0f;
    EXPECT_EQ(message(e), "");
    e.glow.reset();
    // Per size: the reach in em.
    e.outline->width = 100.0f;  // centred: 50 px either side
    EXPECT_TRUE(validate_text_effects(e, 12.5f));
    EXPECT_FALSE(validate_text_effects(e, 12.0f));
    EXPECT_FALSE(validate_text_effects(e, 0.0f));
    EXPECT_NE(validate_text_effects(e, 12.0f).error().message.find("outline width 100 px reaches past 4 em"),
              std::string::npos);
}

TEST(Effects, CodesKeepTheShapeToTheirSteps) {
    for (const StrokeOp op : {StrokeOp::a, StrokeOp::a_not_b, StrokeOp::a_and_b, StrokeOp::a_or_b, StrokeOp::b_not_a}) {
        for (const StrokeJoin join : {StrokeJoin::round, StrokeJoin::miter, StrokeJoin::bevel}) {
            for (const double r : {1.0 / 262144.0, 0.0625, 1.0 / 3.0, 3.99}) {
                const EffectShape shape{op, join, r, 4.0};
                const uint32_t code = encode_effect(shape);
                EXPECT_NE(code, 0u);
                const EffectShape back = decode_effect(code);
                EXPECT_EQ(back.op, op);
                EXPECT_EQ(back.join, join);
                EXPECT_NEAR(back.half_width, r, kEffectWidthUnit / 2);
                if (join == StrokeJoin::miter) {
                    EXPECT_NEAR(back.miter_limit, 4.0, 1e-12);
                }
            }
        }
    }
    // Miter limits keep to 2^(1/16) steps.
    const EffectShape ten{StrokeOp::a, StrokeJoin::miter, 0.1, 10.0};
    EXPECT_NEAR(decode_effect(encode_effect(ten)).miter_limit, 10.0, 10.0 * (std::exp2(1.0 / 32.0) - 1.0));
}

}  // namespace
}  // namespace crisp
