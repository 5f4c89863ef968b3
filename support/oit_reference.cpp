#include "oit_reference.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <numeric>
#include <tuple>
#include <vector>

namespace crisp::oit {
namespace {

// A total order on a fragment's content: sums taken in this order do not depend on submission order.
bool content_less(const Fragment& a, const Fragment& b) {
    auto bits = [](const Fragment& f) {
        return std::tuple(std::bit_cast<uint32_t>(f.depth), f.paint_order, std::bit_cast<uint32_t>(f.transmittance[0]),
                          std::bit_cast<uint32_t>(f.transmittance[1]), std::bit_cast<uint32_t>(f.transmittance[2]),
                          std::bit_cast<uint32_t>(f.light[0]), std::bit_cast<uint32_t>(f.light[1]),
                          std::bit_cast<uint32_t>(f.light[2]));
    };
    return bits(a) < bits(b);
}

float clamp01(float v) {
    return std::clamp(v, 0.0f, 1.0f);
}

// (1 - P) / A, with its limit 1 as A -> 0.
float spread_factor(float product, float absorbance_sum) {
    return absorbance_sum > 1e-6f ? (1.0f - product) / absorbance_sum : 1.0f;
}

}  // namespace

LinearRgb composite_exact(std::span<const Fragment> fragments, const LinearRgb& background) {
    std::vector<size_t> order(fragments.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const Fragment& fa = fragments[a];
        const Fragment& fb = fragments[b];
        if (fa.depth != fb.depth) return fa.depth < fb.depth;
        if (fa.paint_order != fb.paint_order) return fa.paint_order > fb.paint_order;
        return a > b;
    });
    LinearRgb result{};
    for (int c = 0; c < 3; ++c) {
        double in_front = 1.0;
        double sum = 0.0;
        for (size_t i : order) {
            sum += in_front * static_cast<double>(fragments[i].light[c]);
            in_front *= static_cast<double>(fragments[i].transmittance[c]);
        }
        sum += in_front * static_cast<double>(background[static_cast<size_t>(c)]);
        result[static_cast<size_t>(c)] = static_cast<float>(sum);
    }
    return result;
}

LinearRgb composite_unsorted(std::span<const Fragment> fragments, const LinearRgb& background) {
    LinearRgb dst = background;
    for (const Fragment& f : fragments) {
        for (size_t c = 0; c < 3; ++c) dst[c] = f.light[c] + f.transmittance[c] * dst[c];
    }
    return dst;
}

float wboit_weight(WeightFunction function, float depth, float opacity) {
    switch (function) {
        case WeightFunction::mcguire_bavoil_eq10: {
            const float far = 1.0f - clamp01(depth);
            return opacity * std::max(1e-2f, 3e3f * far * far * far);
        }
        case WeightFunction::constant:
            return opacity;
    }
    return opacity;
}

LinearRgb composite_wboit(std::span<const Fragment> fragments, const LinearRgb& background, WeightFunction function) {
    std::vector<Fragment> sorted(fragments.begin(), fragments.end());
    std::sort(sorted.begin(), sorted.end(), content_less);
    LinearRgb result{};
    for (size_t c = 0; c < 3; ++c) {
        float accum_light = 0.0f;
        float accum_opacity = 0.0f;
        float revealage = 1.0f;
        for (const Fragment& f : sorted) {
            const float opacity = 1.0f - f.transmittance[c];
            const float w = wboit_weight(function, f.depth, opacity);
            accum_light += w * f.light[c];
            accum_opacity += w * opacity;
            revealage *= f.transmittance[c];
        }
        result[c] =
            accum_light / std::clamp(accum_opacity, 1e-4f, 5e4f) * (1.0f - revealage) + background[c] * revealage;
    }
    return result;
}

uint8_t quantize_transmittance(float transmittance) {
    // The GPU evaluates uint(T * 255.0 + 0.5) in float; so does this.
    return static_cast<uint8_t>(clamp01(transmittance) * 255.0f + 0.5f);
}

float transmittance_from_code(uint8_t code) {
    return static_cast<float>(code) / 255.0f;
}

float absorbance_from_code(uint8_t code) {
    const float t = code == 0 ? 0.5f / 255.0f : transmittance_from_code(code);
    return -std::log(t);
}

uint64_t pack_layer_key(const Fragment& fragment) {
    const float depth = clamp01(fragment.depth);
    // depth * 2^32 is exact in float; values at or above 2^32 - 2 saturate so no key is kEmptyKey.
    const float scaled = depth * 4294967296.0f;
    const uint32_t depth_bits = scaled >= 4294967294.0f ? 0xFFFFFFFEu : static_cast<uint32_t>(scaled);
    const uint64_t paint = 255u - (fragment.paint_order & 255u);
    uint64_t key = (uint64_t{depth_bits} << 32) | (paint << 24);
    for (int c = 0; c < 3; ++c) {
        key |= uint64_t{quantize_transmittance(fragment.transmittance[c])} << (16 - 8 * c);
    }
    return key;
}

uint32_t key_depth(uint64_t key) {
    return static_cast<uint32_t>(key >> 32);
}

uint8_t key_transmittance_code(uint64_t key, int channel) {
    assert(channel >= 0 && channel < 3);
    return static_cast<uint8_t>(key >> (16 - 8 * channel));
}

bool is_neutral(const Fragment& fragment) {
    for (int c = 0; c < 3; ++c) {
        if (quantize_transmittance(fragment.transmittance[c]) != 255 || fragment.light[c] != 0.0f) return false;
    }
    return true;
}

LayeredPixel build_layers(std::span<const Fragment> fragments, uint32_t layers) {
    LayeredPixel pixel;
    pixel.layers = std::clamp(layers, 1u, kMaxLayers);
    pixel.slots.fill(kEmptyKey);
    std::vector<uint64_t> tail_keys;
    for (const Fragment& f : fragments) {
        if (is_neutral(f)) continue;
        uint64_t key = pack_layer_key(f);
        for (uint32_t i = 0; i < pixel.layers; ++i) {
            const uint64_t original = pixel.slots[i];  // atomicMin returns the previous value
            pixel.slots[i] = std::min(original, key);
            if (original == kEmptyKey) {
                key = kEmptyKey;
                break;
            }
            // Unlike the seed, an equal key does not stop here: it moves on to the next slot, so two
            // identical fragments both count (side by side in the slots, or one in the tail).
            key = std::max(key, original);
        }
        if (key != kEmptyKey) tail_keys.push_back(key);
    }
    pixel.layer_count = static_cast<uint32_t>(
        std::count_if(pixel.slots.begin(), pixel.slots.end(), [](uint64_t k) { return k != kEmptyKey; }));
    // Blending sums in whatever order fragments arrive; summing in key order makes this bit-exact.
    std::sort(tail_keys.begin(), tail_keys.end());
    TailAccumulators& tail = pixel.tail;
    for (uint64_t key : tail_keys) {
        ++tail.count;
        tail.depth_min = std::min(tail.depth_min, key_depth(key));
        tail.depth_max = std::max(tail.depth_max, key_depth(key));
        for (int c = 0; c < 3; ++c) {
            const uint8_t code = key_transmittance_code(key, c);
            tail.transmittance[c] *= transmittance_from_code(code);
            tail.absorbance[c] += absorbance_from_code(code);
            tail.opacity[c] += 1.0f - transmittance_from_code(code);
        }
    }
    return pixel;
}

const char* tail_mode_name(TailMode mode) {
    switch (mode) {
        case TailMode::seed:
            return "seed";
        case TailMode::absorbance_share:
            return "absorbance_share";
        case TailMode::opacity_share:
            return "opacity_share";
        case TailMode::depth_ramp:
            return "depth_ramp";
    }
    return "?";
}

namespace {

// The in-front transmittance of a tail fragment, per channel, beyond the K layers' product.
float tail_factor(TailMode mode, const TailAccumulators& tail, uint64_t key, int c) {
    const uint8_t code = key_transmittance_code(key, c);
    switch (mode) {
        case TailMode::seed:
            return 1.0f / static_cast<float>(std::max(tail.count, 1u));
        case TailMode::absorbance_share: {
            // a_i / o_i tends to 1 as T_i -> 1.
            const float opacity = 1.0f - transmittance_from_code(code);
            const float ratio = code == 255 ? 1.0f : absorbance_from_code(code) / opacity;
            return spread_factor(tail.transmittance[c], tail.absorbance[c]) * ratio;
        }
        case TailMode::opacity_share:
            return tail.opacity[c] > 1e-6f ? (1.0f - tail.transmittance[c]) / tail.opacity[c] : 1.0f;
        case TailMode::depth_ramp: {
            const uint32_t range = tail.depth_max - tail.depth_min;
            // A tail in one plane has no depth order to read: share absorbance instead.
            if (range == 0) return tail_factor(TailMode::absorbance_share, tail, key, c);
            const float place = static_cast<float>(key_depth(key) - tail.depth_min) / static_cast<float>(range);
            const float others = std::max(tail.absorbance[c] - absorbance_from_code(code), 0.0f);
            return std::exp(-others * place);
        }
    }
    return 1.0f;
}

}  // namespace

LinearRgb resolve_layers(const LayeredPixel& pixel, std::span<const Fragment> fragments, const LinearRgb& background,
                         TailMode mode) {
    const uint32_t filled = pixel.layer_count;
    float layers_t[3] = {1.0f, 1.0f, 1.0f};
    for (uint32_t i = 0; i < filled; ++i) {
        for (int c = 0; c < 3; ++c) layers_t[c] *= transmittance_from_code(key_transmittance_code(pixel.slots[i], c));
    }
    const bool has_tail = pixel.tail.count > 0;
    const uint64_t last_key = filled > 0 ? pixel.slots[filled - 1] : kEmptyKey;

    struct Contribution {
        uint64_t key;
        float light[3];
    };
    std::vector<Contribution> contributions;
    contributions.reserve(fragments.size());
    // Equal keys straddling the K boundary (copies of the last slot's key, some in the slots and
    // some in the tail): a group of M fragments whose places are the M after the slots in front.
    uint32_t group_count = 0;
    double group_light[3] = {};
    for (const Fragment& f : fragments) {
        if (is_neutral(f)) continue;
        const uint64_t key = pack_layer_key(f);
        Contribution contribution{key, {}};
        if (has_tail && key == last_key) {
            ++group_count;
            for (int c = 0; c < 3; ++c) group_light[c] += static_cast<double>(f.light[c]);
            continue;
        }
        if (has_tail && key > last_key) {
            for (int c = 0; c < 3; ++c) {
                contribution.light[c] = f.light[c] * layers_t[c] * tail_factor(mode, pixel.tail, key, c);
            }
        } else {
            float in_front[3] = {1.0f, 1.0f, 1.0f};
            uint32_t equal = 0;
            for (uint32_t i = 0; i < filled; ++i) {
                if (pixel.slots[i] < key) {
                    for (int c = 0; c < 3; ++c) {
                        in_front[c] *= transmittance_from_code(key_transmittance_code(pixel.slots[i], c));
                    }
                } else if (pixel.slots[i] == key) {
                    ++equal;
                }
            }
            for (int c = 0; c < 3; ++c) {
                // The mean of the m places among equal keys: (1 + T + ... + T^(m-1)) / m.
                const float t = transmittance_from_code(key_transmittance_code(key, c));
                float power = 1.0f;
                float sum = 0.0f;
                for (uint32_t m = 0; m < std::max(equal, 1u); ++m) {
                    sum += power;
                    power *= t;
                }
                contribution.light[c] = f.light[c] * in_front[c] * (sum / static_cast<float>(std::max(equal, 1u)));
            }
        }
        contributions.push_back(contribution);
    }
    std::sort(contributions.begin(), contributions.end(), [](const Contribution& a, const Contribution& b) {
        return std::tuple(a.key, std::bit_cast<uint32_t>(a.light[0]), std::bit_cast<uint32_t>(a.light[1]),
                          std::bit_cast<uint32_t>(a.light[2])) < std::tuple(b.key, std::bit_cast<uint32_t>(b.light[0]),
                                                                            std::bit_cast<uint32_t>(b.light[1]),
                                                                            std::bit_cast<uint32_t>(b.light[2]));
    });
    LinearRgb result{};
    for (size_t c = 0; c < 3; ++c) {
        result[c] = background[c] * layers_t[c] * pixel.tail.transmittance[c];
        for (const Contribution& contribution : contributions) result[c] += contribution.light[c];
    }
    if (group_count > 0) {
        // Their mean light times (1 + T + ... + T^(M-1)), behind the slots with smaller keys.
        for (size_t c = 0; c < 3; ++c) {
            float in_front = 1.0f;
            for (uint32_t i = 0; i < filled && pixel.slots[i] < last_key; ++i) {
                in_front *= transmittance_from_code(key_transmittance_code(pixel.slots[i], static_cast<int>(c)));
            }
            const float t = transmittance_from_code(key_transmittance_code(last_key, static_cast<int>(c)));
            float places = 0.0f, power = 1.0f;
            for (uint32_t m = 0; m < group_count; ++m) {
                places += power;
                power *= t;
            }
            result[c] += static_cast<float>(group_light[c] / group_count) * in_front * places;
        }
    }
    return result;
}

LinearRgb composite_layered(std::span<const Fragment> fragments, const LinearRgb& background, uint32_t layers,
                            TailMode mode) {
    return resolve_layers(build_layers(fragments, layers), fragments, background, mode);
}

}  // namespace crisp::oit
