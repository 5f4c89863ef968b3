#include "oit_reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace {

using crisp::oit::Fragment;
using crisp::oit::LinearRgb;
using crisp::oit::TailMode;

constexpr float kQuantum = 1.0f / 255.0f;

Fragment make(float depth, uint32_t paint_order, LinearRgb light, LinearRgb transmittance) {
    Fragment f;
    f.depth = depth;
    f.paint_order = paint_order;
    for (size_t c = 0; c < 3; ++c) {
        f.light[c] = light[c];
        f.transmittance[c] = transmittance[c];
    }
    return f;
}

// Subpixel-like fragments with distinct depths: colour and coverage per channel.
std::vector<Fragment> random_fragments(std::mt19937& rng, size_t count, float alpha) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<Fragment> fragments;
    for (size_t i = 0; i < count; ++i) {
        Fragment f;
        f.depth = unit(rng);
        f.paint_order = static_cast<uint32_t>(i);
        const bool opaque = unit(rng) < 0.25f;
        for (int c = 0; c < 3; ++c) {
            const float opacity = alpha * (opaque ? 1.0f : unit(rng));
            f.transmittance[c] = 1.0f - opacity;
            f.light[c] = unit(rng) * opacity;
        }
        fragments.push_back(f);
    }
    return fragments;
}

void expect_near(const LinearRgb& got, const LinearRgb& want, float tolerance) {
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tolerance) << "channel " << c;
}

TEST(OitExact, TwoFragmentsPerChannel) {
    const Fragment front = make(0.2f, 0, {0.4f, 0.3f, 0.0f}, {0.5f, 0.25f, 1.0f});
    const Fragment back = make(0.6f, 0, {0.1f, 0.2f, 0.3f}, {0.5f, 0.5f, 0.5f});
    const LinearRgb background = {1.0f, 1.0f, 1.0f};
    // r: 0.4 + 0.5 * 0.1 + 0.25 * 1; g: 0.3 + 0.25 * 0.2 + 0.125 * 1; b: 0 + 0.3 + 0.5 * 1.
    const LinearRgb want = {0.7f, 0.475f, 0.8f};
    const std::vector<Fragment> submitted_back_first = {back, front};
    const std::vector<Fragment> submitted_front_first = {front, back};
    expect_near(crisp::oit::composite_exact(submitted_back_first, background), want, 1e-6f);
    expect_near(crisp::oit::composite_exact(submitted_front_first, background), want, 1e-6f);
}

TEST(OitExact, ThreeFragmentsPerChannel) {
    const Fragment a = make(0.1f, 0, {0.2f, 0.0f, 0.1f}, {0.8f, 0.5f, 0.0f});
    const Fragment b = make(0.3f, 0, {0.3f, 0.4f, 0.5f}, {0.5f, 0.5f, 0.5f});
    const Fragment c = make(0.9f, 0, {0.0f, 0.6f, 0.2f}, {0.25f, 0.2f, 0.5f});
    const LinearRgb background = {0.5f, 1.0f, 0.0f};
    // r: 0.2 + 0.8 * 0.3 + 0.4 * 0 + 0.1 * 0.5; g: 0 + 0.5 * 0.4 + 0.25 * 0.6 + 0.05 * 1; b: 0.1 (opaque a).
    const LinearRgb want = {0.49f, 0.4f, 0.1f};
    const std::vector<Fragment> fragments = {c, a, b};
    expect_near(crisp::oit::composite_exact(fragments, background), want, 1e-6f);
}

TEST(OitExact, EqualDepthResolvesByPaintOrderLaterInFront) {
    const Fragment later = make(0.5f, 2, {0.25f, 0.25f, 0.25f}, {0.5f, 0.5f, 0.5f});
    const Fragment earlier = make(0.5f, 1, {0.8f, 0.8f, 0.8f}, {0.2f, 0.2f, 0.2f});
    const LinearRgb black = {0.0f, 0.0f, 0.0f};
    const std::vector<Fragment> fragments = {later, earlier};
    // later in front: 0.25 + 0.5 * 0.8.
    expect_near(crisp::oit::composite_exact(fragments, black), {0.65f, 0.65f, 0.65f}, 1e-6f);
    // The layered key agrees.
    for (uint32_t k : {1u, 2u, 4u}) {
        expect_near(crisp::oit::composite_layered(fragments, black, k), {0.65f, 0.65f, 0.65f}, kQuantum);
    }
}

TEST(OitUnsorted, DiffersFromExactWhenOrderMatters) {
    const Fragment later = make(0.5f, 2, {0.25f, 0.25f, 0.25f}, {0.5f, 0.5f, 0.5f});
    const Fragment earlier = make(0.5f, 1, {0.8f, 0.8f, 0.8f}, {0.2f, 0.2f, 0.2f});
    const LinearRgb black = {0.0f, 0.0f, 0.0f};
    const std::vector<Fragment> wrong_order = {later, earlier};
    // "earlier" submitted last lands on top: 0.8 + 0.2 * 0.25.
    expect_near(crisp::oit::composite_unsorted(wrong_order, black), {0.85f, 0.85f, 0.85f}, 1e-6f);
    const std::vector<Fragment> right_order = {earlier, later};
    expect_near(crisp::oit::composite_unsorted(right_order, black), crisp::oit::composite_exact(right_order, black),
                1e-6f);
}

TEST(OitKey, OrdersNearerFirstThenLaterPaintFirst) {
    const LinearRgb half = {0.5f, 0.5f, 0.5f};
    const uint64_t near = crisp::oit::pack_layer_key(make(0.25f, 0, half, half));
    const uint64_t far = crisp::oit::pack_layer_key(make(0.75f, 9, half, half));
    const uint64_t tie_later = crisp::oit::pack_layer_key(make(0.75f, 10, half, half));
    EXPECT_LT(near, far);
    EXPECT_LT(tie_later, far);
    EXPECT_EQ(crisp::oit::key_depth(near), 0x40000000u);
    // Depth 1, last paint order byte and full transmittance must not collide with an empty slot.
    const uint64_t last = crisp::oit::pack_layer_key(make(1.0f, 0, {0, 0, 0}, {1, 1, 1}));
    EXPECT_NE(last, crisp::oit::kEmptyKey);
    // Transmittance rounds to nearest.
    EXPECT_EQ(crisp::oit::quantize_transmittance(0.5f / 255.0f - 1e-4f), 0);
    EXPECT_EQ(crisp::oit::quantize_transmittance(0.5f / 255.0f + 1e-4f), 1);
    EXPECT_EQ(crisp::oit::quantize_transmittance(1.0f), 255);
    const uint64_t rgb = crisp::oit::pack_layer_key(make(0.5f, 0, half, {1.0f, 0.0f, 0.5f}));
    EXPECT_EQ(crisp::oit::key_transmittance_code(rgb, 0), 255);
    EXPECT_EQ(crisp::oit::key_transmittance_code(rgb, 1), 0);
    EXPECT_EQ(crisp::oit::key_transmittance_code(rgb, 2), 128);
}

TEST(OitLayered, MatchesExactWhenEveryFragmentFits) {
    std::mt19937 rng(7);
    const LinearRgb background = {0.2f, 0.6f, 0.9f};
    for (uint32_t k = 1; k <= crisp::oit::kMaxLayers; ++k) {
        for (int trial = 0; trial < 200; ++trial) {
            const size_t count = 1 + rng() % k;
            const std::vector<Fragment> fragments = random_fragments(rng, count, trial % 2 ? 0.9f : 0.3f);
            // Each layer's T is off by at most half a code and scales what lies behind it (at most 1):
            // 1/255 up to two layers, half a code per layer beyond.
            const float tolerance = std::max(kQuantum, 0.5f * kQuantum * static_cast<float>(count)) + 1e-6f;
            for (TailMode mode : crisp::oit::kAllTailModes) {
                expect_near(crisp::oit::composite_layered(fragments, background, k, mode),
                            crisp::oit::composite_exact(fragments, background), tolerance);
            }
        }
    }
}

TEST(OitLayered, TailOfOneFragmentIsExactForEveryMode) {
    std::mt19937 rng(11);
    const LinearRgb background = {0.7f, 0.1f, 0.4f};
    for (uint32_t k : {1u, 2u, 4u, 8u}) {
        for (int trial = 0; trial < 100; ++trial) {
            const std::vector<Fragment> fragments = random_fragments(rng, k + 1, 0.6f);
            EXPECT_EQ(crisp::oit::build_layers(fragments, k).tail.count, 1u);
            const float tolerance = std::max(kQuantum, 0.5f * kQuantum * static_cast<float>(k + 1)) + 1e-6f;
            for (TailMode mode : crisp::oit::kAllTailModes) {
                expect_near(crisp::oit::composite_layered(fragments, background, k, mode),
                            crisp::oit::composite_exact(fragments, background), tolerance);
            }
        }
    }
}

TEST(OitOrderIndependence, BitIdenticalUnderShuffles) {
    std::mt19937 rng(3);
    const LinearRgb background = {0.3f, 0.3f, 0.8f};
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<Fragment> fragments = random_fragments(rng, 1 + rng() % 32, trial % 2 ? 0.9f : 0.3f);
        const LinearRgb exact = crisp::oit::composite_exact(fragments, background);
        const LinearRgb wboit = crisp::oit::composite_wboit(fragments, background);
        std::vector<LinearRgb> layered;
        for (uint32_t k : {1u, 2u, 4u, 8u}) {
            for (TailMode mode : crisp::oit::kAllTailModes) {
                layered.push_back(crisp::oit::composite_layered(fragments, background, k, mode));
            }
        }
        for (int shuffle = 0; shuffle < 10; ++shuffle) {
            std::shuffle(fragments.begin(), fragments.end(), rng);
            EXPECT_EQ(crisp::oit::composite_exact(fragments, background), exact);
            EXPECT_EQ(crisp::oit::composite_wboit(fragments, background), wboit);
            size_t i = 0;
            for (uint32_t k : {1u, 2u, 4u, 8u}) {
                for (TailMode mode : crisp::oit::kAllTailModes) {
                    EXPECT_EQ(crisp::oit::composite_layered(fragments, background, k, mode), layered[i++]);
                }
            }
        }
    }
}

TEST(OitLayered, EqualKeysAreNotLost) {
    // Two overlapping glyphs of one run: same depth, paint order, coverage and colour.
    const Fragment glyph = make(0.5f, 3, {0.3f, 0.2f, 0.1f}, {0.4f, 0.6f, 0.8f});
    const std::vector<Fragment> twice = {glyph, glyph};
    const LinearRgb background = {1.0f, 1.0f, 1.0f};
    const LinearRgb exact = crisp::oit::composite_exact(twice, background);
    const LinearRgb once = crisp::oit::composite_exact(std::vector<Fragment>{glyph}, background);
    ASSERT_GT(std::abs(exact[0] - once[0]), 0.05f);  // dropping one would show
    for (uint32_t k : {2u, 4u}) {
        const crisp::oit::LayeredPixel pixel = crisp::oit::build_layers(twice, k);
        EXPECT_EQ(pixel.layer_count, 2u);
        EXPECT_EQ(pixel.slots[0], pixel.slots[1]);
        expect_near(crisp::oit::composite_layered(twice, background, k), exact, kQuantum);
    }
    // With one slot, the second copy goes to the tail rather than away.
    const crisp::oit::LayeredPixel one_slot = crisp::oit::build_layers(twice, 1);
    EXPECT_EQ(one_slot.layer_count, 1u);
    EXPECT_EQ(one_slot.tail.count, 1u);
    // ... and the copies straddling the boundary are placed as a group: still exact.
    expect_near(crisp::oit::composite_layered(twice, background, 1), exact, kQuantum);
    // Three copies beside a distinct fragment, in every slot count.
    std::vector<Fragment> many = {glyph, make(0.2f, 0, {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}), glyph, glyph};
    for (uint32_t k : {1u, 2u, 3u, 4u, 8u}) {
        expect_near(crisp::oit::composite_layered(many, background, k), crisp::oit::composite_exact(many, background),
                    kQuantum);
    }
}

TEST(OitOpaque, FrontFragmentHidesEverythingBehind) {
    std::mt19937 rng(5);
    const LinearRgb background = {1.0f, 1.0f, 1.0f};
    const Fragment opaque = make(0.05f, 0, {0.2f, 0.4f, 0.6f}, {0.0f, 0.0f, 0.0f});
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<Fragment> fragments = random_fragments(rng, 1 + rng() % 20, 0.7f);
        for (Fragment& f : fragments) f.depth = 0.1f + 0.9f * f.depth;
        fragments.push_back(opaque);
        // Behind it at equal depth: drawn earlier.
        Fragment coplanar_behind = opaque;
        coplanar_behind.paint_order = 0;
        coplanar_behind.light[0] = 0.9f;
        fragments.front() = coplanar_behind;
        fragments.back().paint_order = 1;
        std::shuffle(fragments.begin(), fragments.end(), rng);
        const LinearRgb want = {0.2f, 0.4f, 0.6f};
        EXPECT_EQ(crisp::oit::composite_exact(fragments, background), want);
        for (uint32_t k : {1u, 2u, 4u, 8u}) {
            for (TailMode mode : crisp::oit::kAllTailModes) {
                EXPECT_EQ(crisp::oit::composite_layered(fragments, background, k, mode), want);
            }
        }
    }
}

TEST(OitWboit, SingleFragmentIsExactAndWeightIsEquation10) {
    const Fragment f = make(0.4f, 0, {0.3f, 0.1f, 0.0f}, {0.5f, 0.8f, 1.0f});
    const LinearRgb background = {0.2f, 0.2f, 0.2f};
    const std::vector<Fragment> one = {f};
    expect_near(crisp::oit::composite_wboit(one, background), crisp::oit::composite_exact(one, background), 1e-6f);
    // 3e3 * 0.6^3 = 648, times alpha.
    EXPECT_NEAR(crisp::oit::wboit_weight(crisp::oit::WeightFunction::mcguire_bavoil_eq10, 0.4f, 0.5f), 324.0f, 1e-3f);
    EXPECT_NEAR(crisp::oit::wboit_weight(crisp::oit::WeightFunction::mcguire_bavoil_eq10, 1.0f, 0.5f), 0.005f, 1e-6f);
}

}  // namespace
