#include <crisp/glyph.hpp>

#include "text/blur_kernel.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <tuple>
#include <vector>

namespace crisp {

namespace {

uint64_t mix(uint64_t x) {
    // splitmix64's finalizer: every input bit reaches every output bit.
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

}  // namespace

int compare_keys(const GlyphKey& a, const GlyphKey& b) {
    const auto fields = [](const GlyphKey& k) {
        return std::tie(k.font, k.glyph, k.size_x, k.size_y, k.subpixel_x, k.subpixel_y, k.blur, k.linear[0],
                        k.linear[1], k.linear[2], k.linear[3], k.perspective[0], k.perspective[1], k.effect);
    };
    return fields(a) < fields(b) ? -1 : fields(b) < fields(a) ? 1 : 0;
}

size_t GlyphKeyHash::operator()(const GlyphKey& key) const {
    const uint64_t a = (uint64_t{key.font} << 32) | key.glyph;
    const uint64_t b =
        (uint64_t{key.size_x} << 40) ^ (uint64_t{key.size_y} << 16) ^ (uint64_t{key.subpixel_x} << 8) ^ key.subpixel_y;
    uint64_t h = mix(a ^ mix(b ^ (uint64_t{key.blur} << 48)) ^ (uint64_t{key.effect} * 0x9E3779B97F4A7C15ull));
    if (is_transformed(key) || key.perspective[0] != 0 || key.perspective[1] != 0) {
        const auto word = [](int32_t v) { return static_cast<uint64_t>(static_cast<uint32_t>(v)); };
        h = mix(h ^ ((word(key.linear[0]) << 32) | word(key.linear[1])));
        h = mix(h ^ ((word(key.linear[2]) << 32) | word(key.linear[3])));
        h = mix(h ^ ((word(key.perspective[0]) << 32) | word(key.perspective[1])));
    }
    return static_cast<size_t>(h);
}

namespace {

// A transformed key's em-to-pixel map relative to the pen's whole pixel: q = sub + (L e) / w,
// w = 1 + p . e.
struct KeyMap {
    double l[4] = {};
    double p[2] = {};
    double sub_x = 0.0, sub_y = 0.0;

    explicit KeyMap(const GlyphKey& key) {
        for (int i = 0; i < 4; ++i) l[i] = static_cast<double>(key.linear[i]) / kLinearOne;
        for (int i = 0; i < 2; ++i) p[i] = static_cast<double>(key.perspective[i]) / kPerspectiveOne;
        sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
        sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    }
};

GlyphRect transformed_rect(const GlyphRecord& glyph, const GlyphKey& key) {
    const KeyMap map(key);
    double lo_x = HUGE_VAL, lo_y = HUGE_VAL, hi_x = -HUGE_VAL, hi_y = -HUGE_VAL;
    for (int corner = 0; corner < 4; ++corner) {
        const double ex = static_cast<double>((corner & 1) != 0 ? glyph.bbox_max_x : glyph.bbox_min_x);
        const double ey = static_cast<double>((corner & 2) != 0 ? glyph.bbox_max_y : glyph.bbox_min_y);
        const double w = 1.0 + map.p[0] * ex + map.p[1] * ey;
        if (!(w >= kMinPerspectiveW)) return {};
        const double qx = map.sub_x + (map.l[0] * ex + map.l[1] * ey) / w;
        const double qy = map.sub_y + (map.l[2] * ex + map.l[3] * ey) / w;
        if (!(std::abs(qx) <= kMaxTransformedExtent && std::abs(qy) <= kMaxTransformedExtent)) return {};
        lo_x = std::min(lo_x, qx);
        hi_x = std::max(hi_x, qx);
        lo_y = std::min(lo_y, qy);
        hi_y = std::max(hi_y, qy);
    }
    const double pad = kGlyphPadding + blur_reach(key);
    const double left = std::floor(lo_x) - pad, right = std::ceil(hi_x) + pad;
    const double top = std::floor(lo_y) - pad, bottom = std::ceil(hi_y) + pad;
    return {static_cast<int32_t>(left), static_cast<int32_t>(top), static_cast<uint32_t>(right - left),
            static_cast<uint32_t>(bottom - top)};
}

}  // namespace

int32_t blur_reach(const GlyphKey& key) {
    if (key.blur == 0) return 0;
    return static_cast<int32_t>(std::ceil(key.blur / 64.0 + 1.0));
}

GlyphRect glyph_rect(const GlyphRecord& glyph, const GlyphKey& key) {
    if (glyph.curve_count == 0) return {};
    if (is_transformed(key)) return transformed_rect(glyph, key);
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    const double pad = kGlyphPadding + blur_reach(key);
    const double left = std::floor(sub_x + static_cast<double>(glyph.bbox_min_x) * size_x) - pad;
    const double right = std::ceil(sub_x + static_cast<double>(glyph.bbox_max_x) * size_x) + pad;
    const double top = std::floor(sub_y - static_cast<double>(glyph.bbox_max_y) * size_y) - pad;
    const double bottom = std::ceil(sub_y - static_cast<double>(glyph.bbox_min_y) * size_y) + pad;
    return {static_cast<int32_t>(left), static_cast<int32_t>(top), static_cast<uint32_t>(right - left),
            static_cast<uint32_t>(bottom - top)};
}

TexelToEm texel_to_em(const GlyphRect& rect, const GlyphKey& key) {
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    TexelToEm mapping;
    mapping.scale_x = static_cast<float>(1.0 / size_x);
    mapping.scale_y = static_cast<float>(-1.0 / size_y);
    mapping.offset_x = static_cast<float>((rect.x - sub_x) / size_x);
    mapping.offset_y = static_cast<float>((sub_y - rect.y) / size_y);
    return mapping;
}

Projective em_to_texel(const GlyphRect& rect, const GlyphKey& key) {
    const KeyMap map(key);
    double l[4] = {static_cast<double>(key.size_x) / kSizeOne, 0.0, 0.0, -static_cast<double>(key.size_y) / kSizeOne};
    if (is_transformed(key)) std::copy(std::begin(map.l), std::end(map.l), std::begin(l));
    const double p[2] = {is_transformed(key) ? map.p[0] : 0.0, is_transformed(key) ? map.p[1] : 0.0};
    const double ox = map.sub_x - rect.x, oy = map.sub_y - rect.y;
    return {{l[0] + ox * p[0], l[1] + ox * p[1], ox, l[2] + oy * p[0], l[3] + oy * p[1], oy, p[0], p[1], 1.0}};
}

Projective inverse(const Projective& map) {
    const double* m = map.m;
    const double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8], c02 = m[3] * m[7] - m[4] * m[6];
    const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return {};
    const double r = 1.0 / det;
    return {{c00 * r, (m[2] * m[7] - m[1] * m[8]) * r, (m[1] * m[5] - m[2] * m[4]) * r, c01 * r,
             (m[0] * m[8] - m[2] * m[6]) * r, (m[2] * m[3] - m[0] * m[5]) * r, c02 * r, (m[1] * m[6] - m[0] * m[7]) * r,
             (m[0] * m[4] - m[1] * m[3]) * r}};
}

namespace {

// The curves a band range lists together (each counted once).
uint64_t curves_in_bands(const FontAsset& asset, const GlyphRecord& glyph, uint32_t lo, uint32_t hi) {
    uint64_t count = 0;
    for (size_t w = 0; w < glyph.band_words; ++w) {
        uint32_t bits = 0;
        for (uint32_t band = lo; band <= hi; ++band)
            bits |= asset.band_words[size_t{glyph.band_offset} + size_t{band} * glyph.band_words + w];
        count += static_cast<uint64_t>(std::popcount(bits));
    }
    return count;
}

// A transformed glyph's cost, estimated in O(bands): each texel's row walks the bands its em
// segment crosses (about 1 + the segment's height in em over a band's, a segment being up to
// kSegment texels long) and the start's band once more for its winding, plus the curves flat in em.
uint64_t transformed_curve_tests(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key) {
    const GlyphRect rect = glyph_rect(glyph, key);
    if (rect.width == 0 || rect.height == 0) return 0;
    const Projective to_em = inverse(em_to_texel(rect, key));
    const double* m = to_em.m;
    // d(em y)/d(texel x) at the rect's centre.
    const double cx = 0.5 * rect.width, cy = 0.5 * rect.height;
    const double w = m[6] * cx + m[7] * cy + m[8];
    const double ey = (m[3] * cx + m[4] * cy + m[5]) / w;
    const double slope = std::abs((m[3] - ey * m[6]) / w);
    constexpr double kSegment = 5.0 / 3.0;  // the widest channel union of the presets, texels
    const double band_height = static_cast<double>(glyph.bbox_max_y - glyph.bbox_min_y) / glyph.band_count;
    const double bands =
        1.0 +
        (band_height > 0.0 ? std::min(slope * kSegment / band_height, static_cast<double>(glyph.band_count)) : 0.0);
    uint64_t entries = 0;
    for (uint32_t band = 0; band < glyph.band_count; ++band) entries += curves_in_bands(asset, glyph, band, band);
    const double per_band = static_cast<double>(entries) / glyph.band_count;
    uint64_t flat = 0;
    for (uint32_t word : flat_curve_words(asset, glyph)) flat += static_cast<uint64_t>(std::popcount(word));
    const double per_texel = per_band * (bands + 1.0) + static_cast<double>(flat);
    return static_cast<uint64_t>(std::ceil(per_texel * rect.width * rect.height));
}

// The texel x (of `map`'s rect) of each crossing of the curves `band` lists with the height
// `y` em, sorted, into `xs`.
void row_crossings(const FontAsset& asset, const GlyphRecord& glyph, uint32_t band, double y, const TexelToEm& map,
                   std::vector<double>& xs) {
    xs.clear();
    const size_t first = size_t{glyph.band_offset} + size_t{band} * glyph.band_words;
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        if (!((asset.band_words[first + slot / 32] >> (slot % 32)) & 1u)) continue;
        const Point* p = &asset.points[size_t{glyph.point_offset} + 2 * size_t{slot}];
        const auto d = [](float v) { return static_cast<double>(v); };
        const double a = d(p[0].y) - 2.0 * d(p[1].y) + d(p[2].y), b = 2.0 * (d(p[1].y) - d(p[0].y));
        const double c = d(p[0].y) - y;
        double roots[2];
        int n = 0;
        if (std::abs(a) < 1e-12) {
            if (b != 0.0) roots[n++] = -c / b;
        } else if (const double disc = b * b - 4.0 * a * c; disc >= 0.0) {
            roots[n++] = (-b - std::sqrt(disc)) / (2.0 * a);
            roots[n++] = (-b + std::sqrt(disc)) / (2.0 * a);
        }
        for (int i = 0; i < n; ++i) {
            const double t = roots[i];
            if (!(t >= 0.0 && t < 1.0)) continue;
            const double x = (1.0 - t) * (1.0 - t) * d(p[0].x) + 2.0 * t * (1.0 - t) * d(p[1].x) + t * t * d(p[2].x);
            xs.push_back((x - d(map.offset_x)) / d(map.scale_x));
        }
    }
    std::sort(xs.begin(), xs.end());
}

// A blurred key's samples: each texel's row walks 3w/2 texels past the texel on either side (the
// x filter's support), a pass over its band's curves for every kRasterRowCrossings (8) crossings
// of that stretch, at least one (raster.comp).
uint64_t blurred_curve_tests(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key) {
    constexpr size_t kRowCrossings = 8;
    const GlyphRect rect = glyph_rect(glyph, key);
    const TexelToEm map = texel_to_em(rect, key);
    const double reach = 1.5 * blur_box_width(static_cast<double>(key.blur) * kBlurUnit);
    std::vector<double> xs;
    uint64_t tests = 0;
    for (uint32_t row = 0; row < rect.height; ++row) {
        const float y = map.offset_y + map.scale_y * (static_cast<float>(row) + 0.5f);
        const uint32_t band = FontAsset::band_of(glyph, y);
        const size_t first = size_t{glyph.band_offset} + size_t{band} * glyph.band_words;
        uint64_t curves = 0;
        for (size_t w = 0; w < glyph.band_words; ++w) {
            curves += static_cast<uint64_t>(std::popcount(asset.band_words[first + w]));
        }
        row_crossings(asset, glyph, band, static_cast<double>(y), map, xs);
        size_t lo = 0, hi = 0;  // the crossings in [tx - reach, tx + 1 + reach)
        for (uint32_t tx = 0; tx < rect.width; ++tx) {
            while (lo < xs.size() && xs[lo] < static_cast<double>(tx) - reach) ++lo;
            while (hi < xs.size() && xs[hi] < static_cast<double>(tx) + 1.0 + reach) ++hi;
            tests += curves * std::max<uint64_t>(1, (hi - lo + kRowCrossings - 1) / kRowCrossings);
        }
    }
    return tests;
}

}  // namespace

std::vector<uint32_t> flat_curve_words(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<uint32_t> words;
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        const Point* p = &asset.points[size_t{glyph.point_offset} + 2 * size_t{slot}];
        if (p[0].y != p[1].y || p[1].y != p[2].y || (p[1].x == p[0].x && p[1].y == p[0].y)) continue;
        if (words.empty()) words.assign(glyph.band_words, 0u);
        words[slot / 32] |= 1u << (slot % 32);
    }
    return words;
}

uint64_t curve_tests_per_sample(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key) {
    if (glyph.curve_count == 0 || glyph.band_count == 0) return 0;
    if (is_transformed(key)) return transformed_curve_tests(asset, glyph, key);
    if (key.blur != 0) return blurred_curve_tests(asset, glyph, key);
    const GlyphRect rect = glyph_rect(glyph, key);
    const TexelToEm map = texel_to_em(rect, key);
    uint64_t tests = 0;
    uint32_t cached_band = UINT32_MAX;
    uint64_t cached_count = 0;
    for (uint32_t row = 0; row < rect.height; ++row) {
        const float y = map.offset_y + map.scale_y * (static_cast<float>(row) + 0.5f);
        const uint32_t band = FontAsset::band_of(glyph, y);
        if (band != cached_band) {
            cached_band = band;
            cached_count = 0;
            const size_t first = size_t{glyph.band_offset} + size_t{band} * glyph.band_words;
            for (size_t w = 0; w < glyph.band_words; ++w)
                cached_count += static_cast<uint64_t>(std::popcount(asset.band_words[first + w]));
        }
        tests += cached_count * rect.width;
    }
    return tests;
}

}  // namespace crisp
