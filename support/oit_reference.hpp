// CPU references for every way crisp composites overlapping glyph fragments (docs/oit.md). The GPU
// compositor is tested against these; composite_exact() is the ground truth.
//
// A fragment is one glyph quad's contribution to one pixel, per channel (subpixel text has RGB
// transmittance): with linear text colour c, alpha a and atlas coverage k, opacity o = a * k,
// transmittance T = 1 - o and premultiplied light L = c * o. Smaller depth is nearer; at equal depth
// the larger paint order (drawn later) is in front. Every function returns linear RGB and never
// fails: inputs outside [0, 1] are clamped where a key is packed and used as given elsewhere.
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace crisp::oit {

using LinearRgb = std::array<float, 3>;

struct Fragment {
    float depth = 0.0f;           // [0, 1], smaller is nearer
    uint32_t paint_order = 0;     // at equal depth, larger is in front
    float light[3] = {};          // premultiplied linear light c * o per channel
    float transmittance[3] = {};  // 1 - o per channel
};

// Ground truth: fragments sorted by (depth ascending, paint order descending, submission index
// descending: among exact ties the later-submitted is in front), composited front to back per
// channel in double precision.
LinearRgb composite_exact(std::span<const Fragment> fragments, const LinearRgb& background);

// Premultiplied "over" in submission order: the last fragment is on top. Order-dependent by design.
LinearRgb composite_unsorted(std::span<const Fragment> fragments, const LinearRgb& background);

// Weighted blended OIT (McGuire and Bavoil 2013), applied independently per channel with alpha :=
// opacity of that channel: w_c = o_c * max(1e-2, 3e3 * (1 - depth)^3), the paper's equation (10)
// with d(z) = depth. Result_c = (sum w_c L_c) / clamp(sum w_c o_c, 1e-4, 5e4) * (1 - R_c) + B_c * R_c,
// R_c = prod T_c. Sums run in a canonical (content) order, so the result is order-independent.
enum class WeightFunction {
    mcguire_bavoil_eq10,  // the paper's (10): depth-buffer based, needs no view-space z
    constant,             // w_c = o_c: plain weighted average, for comparison
};
float wboit_weight(WeightFunction function, float depth, float opacity);
LinearRgb composite_wboit(std::span<const Fragment> fragments, const LinearRgb& background,
                          WeightFunction function = WeightFunction::mcguire_bavoil_eq10);

// ---- Layered OIT -----------------------------------------------------------------------------

inline constexpr uint32_t kMaxLayers = 8;
inline constexpr uint64_t kEmptyKey = ~uint64_t{0};  // the value a cleared slot holds

// Key layout, most significant first: [63:32] depth fixed point, [31:24] 255 - (paint_order & 255),
// [23:16] T red, [15:8] T green, [7:0] T blue. Depth is floor(clamp(depth, 0, 1) * 2^32) saturated
// to 2^32 - 2 (so no key equals kEmptyKey); the float multiply by 2^32 is exact on a GPU too.
// Transmittance is round(clamp(T, 0, 1) * 255) per channel.
uint64_t pack_layer_key(const Fragment& fragment);
uint32_t key_depth(uint64_t key);
uint8_t key_transmittance_code(uint64_t key, int channel);  // 0..255
float transmittance_from_code(uint8_t code);                // code / 255
uint8_t quantize_transmittance(float transmittance);        // round(clamp(T) * 255)

// A fragment that absorbs and emits nothing (every T code 255 and no light) is discarded before
// insertion, as a GPU shader would, so that it does not inflate the tail count.
bool is_neutral(const Fragment& fragment);

// What pass 1 leaves per pixel: the K smallest keys (a multiset: equal keys are kept side by side)
// and, per channel, the tail's sums over the keys that did not fit. Every field is a sum, product,
// min or max, so a GPU can build it with blending or atomics in any order.
struct TailAccumulators {
    uint32_t count = 0;                           // additive blend or atomicAdd
    float transmittance[3] = {1.0f, 1.0f, 1.0f};  // product of code / 255: multiplicative blend
    float absorbance[3] = {};                     // sum of absorbance_from_code(code): additive blend
    float opacity[3] = {};                        // sum of 1 - code / 255: additive blend
    uint32_t depth_min = 0xFFFFFFFFu;             // atomicMin of key_depth
    uint32_t depth_max = 0;                       // atomicMax of key_depth
};
struct LayeredPixel {
    std::array<uint64_t, kMaxLayers> slots{};  // sorted ascending; kEmptyKey past layer_count
    uint32_t layers = 1;                       // K
    uint32_t layer_count = 0;                  // filled slots
    TailAccumulators tail;
};

// -ln(code / 255), with code 0 (opaque) taken as -ln(0.5 / 255), the middle of its rounding bin.
float absorbance_from_code(uint8_t code);

// Pass 1: insert every non-neutral fragment, in the given arrival order, by the atomic-min chain of
// the seed without its "equal key: drop" exit, and merge what falls off the K slots into the tail.
// The slots end up holding the K smallest keys whatever the arrival order. layers is clamped to
// [1, kMaxLayers].
LayeredPixel build_layers(std::span<const Fragment> fragments, uint32_t layers);

// How a tail fragment's in-front transmittance is estimated in pass 2 (docs/oit.md has the
// formulas). T_K is the product of the K layers' T; n, P, A, S the tail's count, transmittance
// product, absorbance sum and opacity sum; o_i, a_i the fragment's own quantized opacity/absorbance.
enum class TailMode {
    seed,              // T_K / max(n, 1): the Diligent tutorial's shader
    absorbance_share,  // T_K * (1 - P) * (a_i / A) / o_i: light spread by share of absorbance
    opacity_share,     // T_K * (1 - P) / S: the tail as one uniform slab of its mean colour
    depth_ramp,        // T_K * exp(-(A - a_i) * t_i), t_i the fragment's place in the tail depth range
                       // (absorbance_share when the tail lies in one plane)
};
inline constexpr TailMode kAllTailModes[] = {TailMode::seed, TailMode::absorbance_share, TailMode::opacity_share,
                                             TailMode::depth_ramp};
const char* tail_mode_name(TailMode mode);

// The chosen default (docs/oit.md, "Decision").
inline constexpr TailMode kDefaultTailMode = TailMode::absorbance_share;

// Pass 2 plus the background pass: background * T_K * P, plus each fragment's light times its
// in-front transmittance. A kept fragment takes the product of the slots with smaller keys; when m
// slots hold its very key (equal keys), it takes the mean of its m possible places,
// (1 + T + ... + T^(m-1)) / m, which is exact when the equal fragments' lights are equal. A
// fragment whose key is above the last filled slot of a full buffer is in the tail and takes the
// TailMode estimate. Contributions are summed in key order, so the result is bit-identical for any
// arrival order of the same fragments.
LinearRgb resolve_layers(const LayeredPixel& pixel, std::span<const Fragment> fragments, const LinearRgb& background,
                         TailMode mode);

// build_layers then resolve_layers.
LinearRgb composite_layered(std::span<const Fragment> fragments, const LinearRgb& background, uint32_t layers,
                            TailMode mode = kDefaultTailMode);

}  // namespace crisp::oit
