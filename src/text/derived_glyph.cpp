#include "asset/bands.hpp"
#include "text/stroke.hpp"

#include <crisp/bake.hpp>
#include <crisp/glyph.hpp>

#include <algorithm>
#include <string>

namespace crisp {

namespace {

// Per slot of the glyph: 1 for a real curve (listed in a band, or flat in y), 0 for a pad.
std::vector<uint8_t> real_slots(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<uint8_t> real(glyph.curve_count, 0);
    for (uint32_t band = 0; band < glyph.band_count; ++band) {
        const size_t first = size_t{glyph.band_offset} + size_t{band} * glyph.band_words;
        for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
            if ((asset.band_words[first + slot / 32] >> (slot % 32)) & 1u) real[slot] = 1;
        }
    }
    const std::vector<uint32_t> flat = flat_curve_words(asset, glyph);
    for (uint32_t slot = 0; slot < glyph.curve_count && !flat.empty(); ++slot) {
        if ((flat[slot / 32] >> (slot % 32)) & 1u) real[slot] = 1;
    }
    return real;
}

Vec2 to_vec(const Point& p) {
    return {static_cast<double>(p.x), static_cast<double>(p.y)};
}

}  // namespace

std::vector<Contour> glyph_contours(const FontAsset& asset, const GlyphRecord& glyph) {
    std::vector<Contour> contours;
    const std::vector<uint8_t> real = real_slots(asset, glyph);
    bool open = false;
    for (uint32_t slot = 0; slot < glyph.curve_count; ++slot) {
        if (!real[slot]) {
            open = false;
            continue;
        }
        if (!open) contours.emplace_back();
        open = true;
        const Point* p = &asset.points[size_t{glyph.point_offset} + 2 * size_t{slot}];
        contours.back().push_back({to_vec(p[0]), to_vec(p[1]), to_vec(p[2])});
    }
    return contours;
}

Result<DerivedGlyph> pack_derived_glyph(const std::vector<Contour>& pieces, const FontAsset& asset,
                                        const GlyphRecord& glyph) {
    uint64_t piece_curves = 0;
    for (const Contour& contour : pieces) piece_curves += contour.size();
    if (piece_curves > limits::kMaxStrokeCurves) {
        return Error{ErrorCode::invalid_argument,
                     "derived glyph: " + std::to_string(piece_curves) + " piece curves, more than " +
                         std::to_string(limits::kMaxStrokeCurves) + " (limits::kMaxStrokeCurves)"};
    }
    PackedGlyph packed = pack_contours(pieces);
    DerivedGlyph derived;
    if (glyph.curve_count > 0) {
        const Point* first = &asset.points[glyph.point_offset];
        if (!packed.points.empty()) {
            packed.points.push_back(packed.points.back());  // the pad's control point
            packed.is_curve.push_back(0);
            packed.points.push_back(first[0]);
        } else {
            packed.points.push_back(first[0]);
        }
        derived.set_b_first = static_cast<uint32_t>(packed.is_curve.size());
        packed.points.insert(packed.points.end(), first + 1, first + 2 * size_t{glyph.curve_count} + 1);
        const std::vector<uint8_t> real = real_slots(asset, glyph);
        packed.is_curve.insert(packed.is_curve.end(), real.begin(), real.end());
        for (uint8_t r : real) packed.real_curves += r;
    } else {
        derived.set_b_first = static_cast<uint32_t>(packed.is_curve.size());
    }
    update_extent(packed);
    FontAsset out;
    derived.record = glyph;
    append_glyph(packed, build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap), derived.record, out);
    derived.record.bearing_x = packed.curve_count > 0 ? packed.min_x : 0.0f;
    derived.record.bearing_y = packed.curve_count > 0 ? packed.max_y : 0.0f;
    derived.points = std::move(out.points);
    derived.band_words = std::move(out.band_words);
    return derived;
}

}  // namespace crisp
