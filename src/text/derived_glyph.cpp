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

// Refuses contours of more than limits::kMaxStrokeCurves curves, naming them as `what`.
Status check_curves(const std::vector<Contour>& contours, const char* what) {
    uint64_t curves = 0;
    for (const Contour& contour : contours) curves += contour.size();
    if (curves > limits::kMaxStrokeCurves) {
        return Error{ErrorCode::invalid_argument, "derived glyph: " + std::to_string(curves) + " " + what +
                                                      ", more than " + std::to_string(limits::kMaxStrokeCurves) +
                                                      " (limits::kMaxStrokeCurves)"};
    }
    return {};
}

// Bands over the packed slots, and the record: `base`'s advance and flags, the bearings of the
// packed bbox.
void finish(PackedGlyph& packed, const GlyphRecord& base, DerivedGlyph& derived) {
    update_extent(packed);
    FontAsset out;
    derived.record = base;
    append_glyph(packed, build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap), derived.record, out);
    derived.record.bearing_x = packed.curve_count > 0 ? packed.min_x : 0.0f;
    derived.record.bearing_y = packed.curve_count > 0 ? packed.max_y : 0.0f;
    derived.points = std::move(out.points);
    derived.band_words = std::move(out.band_words);
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
    if (Status s = check_curves(pieces, "piece curves"); !s) return s.error();
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
    finish(packed, glyph, derived);
    return derived;
}

Result<DerivedGlyph> pack_derived_glyph(const std::vector<Contour>& pieces, const std::vector<Contour>& set_b,
                                        const GlyphRecord& base) {
    if (Status s = check_curves(pieces, "piece curves"); !s) return s.error();
    if (Status s = check_curves(set_b, "curves of set B"); !s) return s.error();
    // Set B's slots start on an even point after A's (pack_contours pads between contours).
    std::vector<Contour> all = pieces;
    all.insert(all.end(), set_b.begin(), set_b.end());
    PackedGlyph packed = pack_contours(all);
    DerivedGlyph derived;
    if (!pieces.empty()) {
        const uint32_t pad = set_b.empty() ? 0u : 1u;
        derived.set_b_first = static_cast<uint32_t>(pack_contours(pieces).is_curve.size()) + pad;
    }
    finish(packed, base, derived);
    return derived;
}

}  // namespace crisp
