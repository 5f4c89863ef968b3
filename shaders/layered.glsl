// layered: the K nearest fragments per pixel, after the Diligent Engine's layered OIT tutorial,
// with 64-bit RGB keys (CRISP_KEY64) or 32-bit mono keys. The spec constant kPass picks the pass:
//   0, build: insert the fragment's key by the atomic-min chain; what falls off the K slots goes
//      to the tail (count, zero flags, absorbance sums), from the evicted key alone;
//   1, composite: add the fragment's light times its in-front transmittance to the pixel's
//      fixed-point light sums.
// docs/oit.md has the key layout, the equal-key rule and the tail estimate (absorbance_share).
#include "composite_fragment.glsl"

layout(constant_id = 0) const uint kLayers = 4u;
layout(constant_id = 1) const uint kPass = 0u;

#ifdef CRISP_KEY64
#define Key uint64_t
const Key kEmptyKey = 0xFFFFFFFFFFFFFFFFul;
#else
#define Key uint
const Key kEmptyKey = 0xFFFFFFFFu;
#endif

layout(std430, set = 0, binding = 2) buffer Layers {
    Key keys[];
} layers[kCompositeMaxLayerBuffers];

layout(std430, set = 0, binding = 3) buffer Accumulators {
    uint words[];
};

uint slot_index(uint layer, uint pixel, out uint buffer_index) {
    buffer_index = layer / pc.layers_per_buffer;
    return (layer - buffer_index * pc.layers_per_buffer) * pc.pixels + pixel;
}

// Each case indexes the buffer array with a constant, which needs no non-uniform indexing.
#define CRISP_LAYER_CASES(expression) \
    switch (b) {                      \
        case 0u: expression(0); break; \
        case 1u: expression(1); break; \
        case 2u: expression(2); break; \
        case 3u: expression(3); break; \
        case 4u: expression(4); break; \
        case 5u: expression(5); break; \
        case 6u: expression(6); break; \
        default: expression(7); break; \
    }

Key slot_atomic_min(uint layer, uint pixel, Key key) {
    uint b;
    const uint i = slot_index(layer, pixel, b);
    Key original = kEmptyKey;
#define CRISP_MIN(n) original = atomicMin(layers[n].keys[i], key)
    CRISP_LAYER_CASES(CRISP_MIN)
#undef CRISP_MIN
    return original;
}

Key slot_load(uint layer, uint pixel) {
    uint b;
    const uint i = slot_index(layer, pixel, b);
    Key value = kEmptyKey;
#define CRISP_LOAD(n) value = layers[n].keys[i]
    CRISP_LAYER_CASES(CRISP_LOAD)
#undef CRISP_LOAD
    return value;
}

uvec3 key_codes(Key key) {
#ifdef CRISP_KEY64
    const uint low = uint(key);
    return uvec3((low >> 16) & 255u, (low >> 8) & 255u, low & 255u);
#else
    return uvec3(key & 255u);
#endif
}

Key make_key(GlyphFragment f, out uvec3 codes) {
    codes = transmittance_codes(f.transmittance);
#ifdef CRISP_KEY64
    const uint low = (f.quad.key_order << 24) | (codes.r << 16) | (codes.g << 8) | codes.b;
    return (uint64_t(f.quad.key_depth) << 32) | uint64_t(low);
#else
    // Mono: one code for the three channels, from their mean transmittance.
    const uint code = transmittance_codes(vec3((f.transmittance.r + f.transmittance.g + f.transmittance.b) / 3.0)).r;
    codes = uvec3(code);
    return (f.quad.key_depth16 << 16) | (f.quad.key_order << 8) | code;
#endif
}

void build(GlyphFragment f, Key key) {
    for (uint i = 0u; i < kLayers; ++i) {
        const Key original = slot_atomic_min(i, f.pixel, key);
        if (original == kEmptyKey) return;
        // Unlike the seed, an equal key moves on to the next slot: identical fragments both count.
        key = max(key, original);
    }
    // The key left over (this fragment's or one it evicted) joins the tail.
    const uvec3 codes = key_codes(key);
    const uint count_word = kLayeredTailCount * pc.pixels + f.pixel;
    uint zero_flags = 0u;
    for (uint c = 0u; c < 3u; ++c) {
        if (codes[c] == 0u) zero_flags |= 1u << (kCompositeTailZeroShift + c);
        atomicAdd(words[(kLayeredTailAbsorbance + c) * pc.pixels + f.pixel],
                  uint(absorbance_from_code(codes[c]) * kCompositeAbsorbanceScale + 0.5));
    }
    atomicAdd(words[count_word], 1u);
    if (zero_flags != 0u) atomicOr(words[count_word], zero_flags);
}

void composite(GlyphFragment f, Key key, uvec3 codes) {
    Key slots[kCompositeMaxLayers];
    uint filled = 0u;
    for (uint i = 0u; i < kLayers; ++i) {
        slots[i] = slot_load(i, f.pixel);
        if (slots[i] != kEmptyKey) filled = i + 1u;
    }
    const uint count_word = words[kLayeredTailCount * pc.pixels + f.pixel];
    const uint tail_count = count_word & kCompositeTailCountMask;
    const Key last = filled > 0u ? slots[filled - 1u] : kEmptyKey;
    if (tail_count > 0u && key == last) {
        // A copy of the last slot's key with copies in the tail too: the resolve pass places the
        // group (light summed, copies counted).
        for (uint c = 0u; c < 3u; ++c) {
            atomicAdd(words[(kLayeredGroupLight + c) * pc.pixels + f.pixel], light_fixed(f.light[c]));
        }
        atomicAdd(words[kLayeredGroupCount * pc.pixels + f.pixel], 1u);
        return;
    }
    vec3 contribution;
    if (tail_count > 0u && key > last) {
        // A tail fragment: behind all K layers, and its share of the tail's absorbed light
        // (absorbance_share): (1 - P) * (a_i / A) / o_i, P = exp(-A), 0 where a tail key is opaque.
        vec3 layers_t = vec3(1.0);
        for (uint i = 0u; i < filled; ++i) layers_t *= vec3(key_codes(slots[i])) / 255.0;
        for (uint c = 0u; c < 3u; ++c) {
            const float absorbance =
                float(words[(kLayeredTailAbsorbance + c) * pc.pixels + f.pixel]) / kCompositeAbsorbanceScale;
            const bool opaque = (count_word & (1u << (kCompositeTailZeroShift + c))) != 0u;
            const float tail_t = opaque ? 0.0 : exp(-absorbance);
            const float spread = absorbance > 1e-6 ? (1.0 - tail_t) / absorbance : 1.0;
            const float own_opacity = 1.0 - float(codes[c]) / 255.0;
            const float ratio = codes[c] == 255u ? 1.0 : absorbance_from_code(codes[c]) / own_opacity;
            contribution[c] = f.light[c] * layers_t[c] * spread * ratio;
        }
    } else {
        vec3 in_front = vec3(1.0);
        uint equal = 0u;
        for (uint i = 0u; i < filled; ++i) {
            if (slots[i] < key) {
                in_front *= vec3(key_codes(slots[i])) / 255.0;
            } else if (slots[i] == key) {
                ++equal;
            }
        }
        // m slots hold this very key: the mean of its m places, (1 + T + ... + T^(m-1)) / m.
        const vec3 t = vec3(codes) / 255.0;
        vec3 power = vec3(1.0), sum = vec3(0.0);
        const uint places = max(equal, 1u);
        for (uint m = 0u; m < places; ++m) {
            sum += power;
            power *= t;
        }
        contribution = f.light * in_front * (sum / float(places));
    }
    for (uint c = 0u; c < 3u; ++c) {
        const uint add = light_fixed(contribution[c]);
        if (add != 0u) atomicAdd(words[(kLayeredLight + c) * pc.pixels + f.pixel], add);
    }
}

void main() {
    GlyphFragment f;
    if (!load_fragment(f)) return;
    uvec3 codes;
    const Key key = make_key(f, codes);
    // A fragment that absorbs and emits nothing changes nothing; it would only inflate the tail.
    if (all(equal(codes, uvec3(255u))) && all(equal(f.light, vec3(0.0)))) return;
    if (kPass == 0u) {
        build(f, key);
    } else {
        composite(f, key, codes);
    }
}
