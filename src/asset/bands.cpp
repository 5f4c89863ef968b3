#include "asset/bands.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace crisp {

namespace {

Point to_point(Vec2 v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y)};
}

struct SlotRange {
    uint32_t slot;
    float min_y, max_y;
};

// Band index range [first, last] that [min_y, max_y] touches with `count` widened bands.
void band_range(float glyph_min_y, float band_height, uint32_t count, float overlap, float min_y, float max_y,
                uint32_t& first, uint32_t& last) {
    const float widen = overlap * band_height;
    const float lo = std::floor((min_y - widen - glyph_min_y) / band_height);
    const float hi = std::floor((max_y + widen - glyph_min_y) / band_height);
    const float top = static_cast<float>(count - 1);
    first = static_cast<uint32_t>(std::clamp(lo, 0.0f, top));
    last = static_cast<uint32_t>(std::clamp(hi, 0.0f, top));
}

}  // namespace

PackedGlyph pack_contours(const std::vector<Contour>& contours) {
    PackedGlyph glyph;
    for (const Contour& contour : contours) {
        if (contour.empty()) continue;
        if (!glyph.points.empty()) {
            glyph.points.push_back(glyph.points.back());  // the pad's control point
            glyph.is_curve.push_back(0);
            glyph.points.push_back(to_point(contour.front().p0));
        } else {
            glyph.points.push_back(to_point(contour.front().p0));
        }
        for (const Quad& q : contour) {
            glyph.points.push_back(to_point(q.p1));
            glyph.points.push_back(to_point(q.p2));
            glyph.is_curve.push_back(1);
            ++glyph.real_curves;
        }
    }
    update_extent(glyph);
    return glyph;
}

void update_extent(PackedGlyph& glyph) {
    glyph.curve_count = static_cast<uint32_t>(glyph.is_curve.size());
    assert(glyph.points.empty() || glyph.points.size() == 2 * glyph.curve_count + 1);
    if (!glyph.points.empty()) {
        glyph.min_x = glyph.max_x = glyph.points[0].x;
        glyph.min_y = glyph.max_y = glyph.points[0].y;
        for (const Point& p : glyph.points) {
            glyph.min_x = std::min(glyph.min_x, p.x);
            glyph.max_x = std::max(glyph.max_x, p.x);
            glyph.min_y = std::min(glyph.min_y, p.y);
            glyph.max_y = std::max(glyph.max_y, p.y);
        }
    }
}

void curve_y_extent(std::span<const Point> points, uint32_t slot, float& min_y, float& max_y) {
    const auto y0 = static_cast<double>(points[2 * slot].y), y1 = static_cast<double>(points[2 * slot + 1].y),
               y2 = static_cast<double>(points[2 * slot + 2].y);
    double lo = std::min(y0, y2), hi = std::max(y0, y2);
    const double denominator = y0 - 2.0 * y1 + y2;
    if (denominator != 0.0) {
        const double t = (y0 - y1) / denominator;
        if (t > 0.0 && t < 1.0) {
            const double s = 1.0 - t;
            const double y = s * s * y0 + 2.0 * s * t * y1 + t * t * y2;
            lo = std::min(lo, y);
            hi = std::max(hi, y);
        }
    }
    // Round outwards so the float extent contains the exact one.
    min_y = std::nextafter(static_cast<float>(lo), -INFINITY);
    max_y = std::nextafter(static_cast<float>(hi), INFINITY);
}

GlyphBands build_bands(const PackedGlyph& glyph, uint32_t target_per_band, uint32_t max_bands, float overlap) {
    GlyphBands bands;
    if (glyph.curve_count == 0) return bands;
    assert(max_bands >= 1 && max_bands <= 0xFFFF);

    std::vector<SlotRange> ranges;
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        if (!glyph.is_curve[slot]) continue;
        const Point* p = &glyph.points[2 * slot];
        if (p[0].y == p[1].y && p[1].y == p[2].y) continue;  // flat: never crossed by a horizontal ray
        SlotRange range{slot, 0.0f, 0.0f};
        curve_y_extent(glyph.points, slot, range.min_y, range.max_y);
        ranges.push_back(range);
    }

    const float height = glyph.max_y - glyph.min_y;
    uint32_t best_count = 1;
    uint32_t best_worst = UINT32_MAX;
    std::vector<int32_t> delta;
    for (uint32_t count = 1; count <= max_bands; ++count) {
        if (height <= 0.0f && count > 1) break;
        const float band_height = height > 0.0f ? height / static_cast<float>(count) : 1.0f;
        delta.assign(count + 1, 0);
        for (const SlotRange& range : ranges) {
            uint32_t first = 0, last = 0;
            band_range(glyph.min_y, band_height, count, overlap, range.min_y, range.max_y, first, last);
            ++delta[first];
            --delta[last + 1];
        }
        uint32_t worst = 0;
        int32_t running = 0;
        for (uint32_t band = 0; band < count; ++band) {
            running += delta[band];
            worst = std::max(worst, static_cast<uint32_t>(running));
        }
        if (worst < best_worst) {
            best_worst = worst;
            best_count = count;
        }
        if (worst <= target_per_band) break;
    }

    bands.band_count = static_cast<uint16_t>(best_count);
    bands.band_words = static_cast<uint16_t>((glyph.curve_count + 31) / 32);
    bands.words.assign(size_t{bands.band_count} * bands.band_words, 0u);
    const float band_height = height > 0.0f ? height / static_cast<float>(best_count) : 1.0f;
    for (const SlotRange& range : ranges) {
        uint32_t first = 0, last = 0;
        band_range(glyph.min_y, band_height, best_count, overlap, range.min_y, range.max_y, first, last);
        for (uint32_t band = first; band <= last; ++band) {
            bands.words[size_t{band} * bands.band_words + range.slot / 32] |= 1u << (range.slot % 32);
        }
        bands.entries += last - first + 1;
    }
    bands.max_curves_in_band = best_worst;
    bands.mean_tests_per_ray = static_cast<double>(bands.entries) / best_count;
    return bands;
}

void append_glyph(const PackedGlyph& glyph, const GlyphBands& bands, GlyphRecord& record, FontAsset& asset) {
    record.bbox_min_x = glyph.min_x;
    record.bbox_min_y = glyph.min_y;
    record.bbox_max_x = glyph.max_x;
    record.bbox_max_y = glyph.max_y;
    record.point_offset = static_cast<uint32_t>(asset.points.size());
    record.curve_count = glyph.curve_count;
    record.band_offset = static_cast<uint32_t>(asset.band_words.size());
    record.band_count = bands.band_count;
    record.band_words = bands.band_words;
    asset.points.insert(asset.points.end(), glyph.points.begin(), glyph.points.end());
    asset.band_words.insert(asset.band_words.end(), bands.words.begin(), bands.words.end());
}

}  // namespace crisp
