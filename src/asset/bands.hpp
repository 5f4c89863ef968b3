// A glyph's curves as the asset stores them (shared end points, pad slots between contours) and
// the horizontal bands that tell a sample ray which curves it must test.
#pragma once

#include "asset/curves.hpp"

#include <crisp/asset.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace crisp {

struct PackedGlyph {
    std::vector<Point> points;      // 2 * curve_count + 1 points, em, y up
    std::vector<uint8_t> is_curve;  // per slot: 1 for a curve, 0 for a pad between contours
    uint32_t curve_count = 0;       // slots, pads included
    uint32_t real_curves = 0;       // slots that are curves
    float min_x = 0.0f, min_y = 0.0f, max_x = 0.0f, max_y = 0.0f;  // bbox of every point
};

// Lays contours out as curve slots: curve i is (points[2i], points[2i+1], points[2i+2]). Each
// contour after the first starts on an even point index, so one pad slot (its control point a
// copy of the previous end) joins it to the contour before.
PackedGlyph pack_contours(const std::vector<Contour>& contours);

// Sets curve_count from is_curve and the bbox from every point, after slots are added by hand.
void update_extent(PackedGlyph& glyph);

struct GlyphBands {
    uint16_t band_count = 0;
    uint16_t band_words = 0;
    std::vector<uint32_t> words;  // band_count * band_words
    uint32_t max_curves_in_band = 0;
    uint64_t entries = 0;             // set bits over all bands
    double mean_tests_per_ray = 0.0;  // mean set bits per band (bands are of equal height)
};

// The y-extent of slot `slot` of a packed glyph, exact for the quadratic (not its control hull).
void curve_y_extent(std::span<const Point> points, uint32_t slot, float& min_y, float& max_y);

// Cuts the glyph's bbox into equal bands: the fewest bands (1 to max_bands) whose fullest band
// lists at most target_per_band curves, or, when no count gets there, the fewest bands that
// reach the lowest worst case. A curve is listed in every band its y-extent touches once each
// band is widened by `overlap` of its height on both sides. Curves that are flat in y are listed
// nowhere: a horizontal ray never crosses them, and the root classification decides rays through
// their end points from the neighbouring curves.
GlyphBands build_bands(const PackedGlyph& glyph, uint32_t target_per_band, uint32_t max_bands, float overlap);

// Appends the glyph's points and band words to the asset and points `record` at them: its bbox,
// offsets and counts. The glyph's other fields (advance, bearings, flags) are the caller's.
void append_glyph(const PackedGlyph& glyph, const GlyphBands& bands, GlyphRecord& record, FontAsset& asset);

}  // namespace crisp
