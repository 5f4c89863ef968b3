#include "asset/bands.hpp"
#include "bake/bitmap.hpp"
#include "bake/colr.hpp"
#include "asset/asset_format.hpp"
#include "bake/composite.hpp"
#include "bake/font_file.hpp"
#include "core/file_io.hpp"
#include "core/limits.hpp"
#include "core/utf8.hpp"
#include "bake/outline.hpp"

#include <crisp/bake.hpp>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_MULTIPLE_MASTERS_H
#include FT_OUTLINE_H
#include <hb-ot.h>
#include <hb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace crisp {

namespace {

// Coordinates past this many em are refused (the loader refuses them too): no real glyph reaches
// it, and it keeps every em-space computation far from float overflow.
constexpr float kMaxEmCoordinate = 64.0f;
constexpr size_t kReportedFailures = 16;

struct LibraryDeleter {
    void operator()(FT_Library library) const { FT_Done_FreeType(library); }
};
struct FaceDeleter {
    void operator()(FT_Face face) const { FT_Done_Face(face); }
};
using LibraryHandle = std::unique_ptr<FT_LibraryRec_, LibraryDeleter>;
using FaceHandle = std::unique_ptr<FT_FaceRec_, FaceDeleter>;

double fixed_to_double(FT_Fixed value) {
    return static_cast<double>(value) / 65536.0;
}

// The glyphs to bake: every glyph the code points map to, every glyph GSUB can substitute for
// them (ligatures, alternates, contextual forms), and .notdef.
std::vector<uint8_t> requested_glyphs(std::span<const std::byte> font_bytes, uint32_t face_index,
                                      const std::vector<uint32_t>& codepoints, uint32_t glyph_count) {
    std::vector<uint8_t> wanted(glyph_count, 0);
    hb_blob_t* blob =
        hb_blob_create(reinterpret_cast<const char*>(font_bytes.data()), static_cast<unsigned>(font_bytes.size()),
                       HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    hb_face_t* face = hb_face_create(blob, face_index);
    hb_font_t* font = hb_font_create(face);
    hb_set_t* glyphs = hb_set_create();
    hb_set_add(glyphs, 0);
    for (uint32_t cp : codepoints) {
        hb_codepoint_t glyph = 0;
        if (hb_font_get_nominal_glyph(font, cp, &glyph)) hb_set_add(glyphs, glyph);
    }
    hb_set_t* lookups = hb_set_create();
    hb_ot_layout_collect_lookups(face, make_tag("GSUB"), nullptr, nullptr, nullptr, lookups);
    hb_ot_layout_lookups_substitute_closure(face, lookups, glyphs);
    hb_codepoint_t glyph = UINT32_MAX;  // HB_SET_VALUE_INVALID: start of the walk
    while (hb_set_next(glyphs, &glyph)) {
        if (glyph < glyph_count) wanted[glyph] = 1;
    }
    hb_set_destroy(lookups);
    hb_set_destroy(glyphs);
    hb_font_destroy(font);
    hb_face_destroy(face);
    hb_blob_destroy(blob);
    return wanted;
}

Status apply_variations(FT_Library library, FT_Face face, const BakeOptions& options, FontInfo& info) {
    if (!FT_HAS_MULTIPLE_MASTERS(face)) {
        if (!options.variations.empty()) {
            return Error{ErrorCode::font_unsupported,
                         "--var given but the face has no variation axes (it is not a variable font)"};
        }
        return {};
    }
    FT_MM_Var* mm = nullptr;
    if (const FT_Error error = FT_Get_MM_Var(face, &mm); error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot read the variation axes: " + freetype_error(error)};
    }
    std::vector<FT_Fixed> coords(mm->num_axis);
    std::string axis_names;
    for (FT_UInt i = 0; i < mm->num_axis; ++i) {
        const FT_Var_Axis& axis = mm->axis[i];
        coords[i] = axis.def;
        axis_names += (i ? ", " : "") + printable(tag_to_string(static_cast<uint32_t>(axis.tag)));
    }
    Status status;
    for (const Variation& variation : options.variations) {
        FT_UInt i = 0;
        while (i < mm->num_axis && static_cast<uint32_t>(mm->axis[i].tag) != variation.tag) ++i;
        if (i == mm->num_axis) {
            status =
                Error{ErrorCode::font_unsupported, "the face has no axis '" + printable(tag_to_string(variation.tag)) +
                                                       "'; its axes are " + axis_names};
            break;
        }
        const FT_Var_Axis& axis = mm->axis[i];
        const double minimum = fixed_to_double(axis.minimum), maximum = fixed_to_double(axis.maximum);
        const auto value = static_cast<double>(variation.value);
        if (!std::isfinite(value) || value < minimum || value > maximum) {
            status =
                Error{ErrorCode::invalid_argument, "axis '" + printable(tag_to_string(variation.tag)) + "' value " +
                                                       std::to_string(variation.value) + " is outside [" +
                                                       std::to_string(minimum) + ", " + std::to_string(maximum) + "]"};
            break;
        }
        coords[i] = static_cast<FT_Fixed>(std::lround(value * 65536.0));
    }
    if (status.ok()) {
        if (const FT_Error error = FT_Set_Var_Design_Coordinates(face, mm->num_axis, coords.data()); error != 0) {
            status = Error{ErrorCode::font_unsupported, "cannot set the variation: " + freetype_error(error)};
        }
    }
    if (status.ok()) {
        info.flags |= kFontVariable;
        for (FT_UInt i = 0; i < mm->num_axis; ++i) {
            const FT_Var_Axis& axis = mm->axis[i];
            info.axes.push_back({static_cast<uint32_t>(axis.tag), static_cast<float>(fixed_to_double(coords[i])),
                                 static_cast<float>(fixed_to_double(axis.minimum)),
                                 static_cast<float>(fixed_to_double(axis.def)),
                                 static_cast<float>(fixed_to_double(axis.maximum))});
        }
    }
    FT_Done_MM_Var(library, mm);
    return status;
}

// Why a record's advance or bearings cannot be stored (not finite, or past kMaxEmCoordinate), or nullopt.
std::optional<std::string> metrics_out_of_range(const GlyphRecord& record) {
    const std::pair<const char*, float> metrics[] = {
        {"advance", record.advance}, {"bearing_x", record.bearing_x}, {"bearing_y", record.bearing_y}};
    for (const auto& [name, value] : metrics) {
        if (std::isfinite(value) && std::fabs(value) <= kMaxEmCoordinate) continue;
        char text[96];
        std::snprintf(text, sizeof text, "%s %.7g em, beyond the asset's +-64 em", name, static_cast<double>(value));
        return std::string(text);
    }
    return std::nullopt;
}

struct GlyphOutcome {
    bool failed = false;
    std::string reason;
    bool asset_full = false;  // the glyph would take the asset past a limit: the bake stops (reason says which)
};

// What one bake has spent of its limits (docs/limits.md), checked before each glyph is loaded
// and before it is added, so that a small font cannot grow the asset past what a renderer holds.
struct BakeBudget {
    CompositeBounds composites;
    uint64_t fixed_bytes = 0;     // the asset's font bytes and glyph records
    uint64_t flat_row_words = 0;  // the renderer's flat rows (FontStore::add): a glyph's band_words at most
};

// Why adding the glyph would pass a limit of the asset, or nullopt.
std::optional<std::string> asset_room(const FontAsset& asset, const PackedGlyph& packed, const GlyphBands& bands,
                                      BakeBudget& budget) {
    const uint64_t point_bytes = (asset.points.size() + packed.points.size()) * asset_format::kPointSize;
    const uint64_t band_bytes =
        (asset.band_words.size() + bands.words.size() + budget.flat_row_words + bands.band_words) *
        asset_format::kBandWordSize;
    const uint64_t file_bytes = budget.fixed_bytes + point_bytes + band_bytes + asset.image_bytes.size();
    const auto past = [](const char* what, uint64_t bytes, uint64_t limit) {
        return std::string("the asset's ") + what + " would reach " + std::to_string(bytes) +
               " bytes, more than the limit of " + std::to_string(limit);
    };
    if (point_bytes > kMaxAssetPointBytes) return past("curve points", point_bytes, kMaxAssetPointBytes);
    if (band_bytes > kMaxAssetBandBytes) return past("band words", band_bytes, kMaxAssetBandBytes);
    if (file_bytes > limits::kAssetFileBytes) return past("file", file_bytes, limits::kAssetFileBytes);
    budget.flat_row_words += bands.band_words;
    return std::nullopt;
}

// The bake's error for a glyph that asset_room() refused.
Error asset_full(uint32_t glyph, const std::string& reason) {
    return Error{ErrorCode::font_unsupported, "glyph " + std::to_string(glyph) + ": " + reason +
                                                  " (docs/limits.md); bake fewer glyphs (--text, --codepoints)"};
}

// The largest factor by which the linear part of `t` stretches a length (its largest singular value).
double stretch(const Affine& t) {
    const auto a = static_cast<double>(t.xx), b = static_cast<double>(t.xy);
    const auto c = static_cast<double>(t.yx), d = static_cast<double>(t.yy);
    const double sum = a * a + b * b + c * c + d * d, det = a * d - b * c;
    return std::sqrt((sum + std::sqrt(std::max(0.0, sum * sum - 4.0 * det * det))) / 2.0);
}

// A synthetic glyph's contours: the face glyph's under `t`, exact for quadratics (an affine map of
// a quadratic is the quadratic of the mapped points). The y-extrema move under a rotation or skew,
// so they are split here, after the map, rather than by the builder.
std::vector<Contour> transform_contours(const std::vector<Contour>& contours, const Affine& t, bool split_y_extrema,
                                        OutlineCounters& counters) {
    const auto xx = static_cast<double>(t.xx), yx = static_cast<double>(t.yx), xy = static_cast<double>(t.xy);
    const auto yy = static_cast<double>(t.yy), dx = static_cast<double>(t.dx), dy = static_cast<double>(t.dy);
    const auto map = [=](Vec2 p) { return Vec2{xx * p.x + xy * p.y + dx, yx * p.x + yy * p.y + dy}; };
    std::vector<Contour> mapped;
    for (const Contour& contour : contours) {
        Contour& out = mapped.emplace_back();
        for (const Quad& q : contour) {
            const Quad m{map(q.p0), map(q.p1), map(q.p2)};
            if (is_zero_length(m)) {
                ++counters.dropped_zero_length;
                continue;
            }
            if (!split_y_extrema) {
                out.push_back(m);
                continue;
            }
            Quad halves[2];
            const int count = split_at_y_extremum(m, halves);
            counters.y_splits += static_cast<uint64_t>(count - 1);
            out.insert(out.end(), halves, halves + count);
        }
        if (out.empty()) mapped.pop_back();
    }
    return mapped;
}

// Converts one glyph into record `record_index` of the asset: its own record, or with `transform`
// a synthetic record of its outline under that map (em to em).
GlyphOutcome bake_glyph(FT_Face face, uint32_t glyph_index, double units_per_em, const BakeOptions& options,
                        BakeBudget& budget, OutlineCounters& counters, FontAsset& asset, BakeReport& report,
                        uint32_t record_index, const Affine* transform = nullptr) {
    GlyphRecord& record = asset.glyphs[record_index];
    if (std::optional<std::string> reason = budget.composites.check(glyph_index)) return {true, std::move(*reason)};
    const FT_Error error = FT_Load_Glyph(face, glyph_index, FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP);
    if (error != 0) return {true, freetype_error(error)};
    const FT_GlyphSlot slot = face->glyph;
    if (slot->format != FT_GLYPH_FORMAT_OUTLINE) {
        return {true, "not an outline glyph (FreeType glyph format 0x" + [&] {
                    char buffer[16];
                    std::snprintf(buffer, sizeof buffer, "%08lx", static_cast<unsigned long>(slot->format));
                    return std::string(buffer);
                }() + ")"};
    }
    // The char size is set so that one pixel is one font unit: 26.6 values are font units * 64,
    // and linearHoriAdvance (16.16) is font units * 65536, both unhinted.
    const double to_em_26_6 = 1.0 / (64.0 * units_per_em);
    record.advance = static_cast<float>(static_cast<double>(slot->linearHoriAdvance) / (65536.0 * units_per_em));
    record.bearing_x = static_cast<float>(static_cast<double>(slot->metrics.horiBearingX) * to_em_26_6);
    record.bearing_y = static_cast<float>(static_cast<double>(slot->metrics.horiBearingY) * to_em_26_6);

    OutlineOptions outline_options;
    outline_options.scale = to_em_26_6;
    outline_options.tolerance = static_cast<double>(options.tolerance_em);
    outline_options.split_y_extrema = options.split_y_extrema;
    // Under a transform that stretches, the cubics are lowered finer, so that the deviation after
    // it is still within the tolerance.
    const double stretched = transform ? std::max(1.0, stretch(*transform)) : 1.0;
    if (transform) {
        outline_options.tolerance /= stretched;
        outline_options.split_y_extrema = false;
    }
    OutlineCounters glyph_counters;
    OutlineBuilder builder(outline_options, glyph_counters);
    std::string reason;
    if (!decompose_outline(slot->outline, builder, reason)) return {true, reason};
    std::vector<Contour> contours = builder.finish();
    if (transform) {
        contours = transform_contours(contours, *transform, options.split_y_extrema, glyph_counters);
        glyph_counters.max_deviation *= stretched;
        glyph_counters.seed_max_deviation *= stretched;
    }
    const PackedGlyph packed = pack_contours(contours);
    if (transform) {
        // A layer's outline, drawn at its colour glyph's pen: it has no advance of its own.
        record.advance = 0.0f;
        record.bearing_x = packed.curve_count > 0 ? packed.min_x : 0.0f;
        record.bearing_y = packed.curve_count > 0 ? packed.max_y : 0.0f;
    }
    if (packed.real_curves > options.max_curves_per_glyph) {
        return {true, std::to_string(packed.real_curves) + " curves, more than the limit of " +
                          std::to_string(options.max_curves_per_glyph)};
    }
    if (packed.curve_count > 0 && (std::max({std::fabs(packed.min_x), std::fabs(packed.max_x), std::fabs(packed.min_y),
                                             std::fabs(packed.max_y)}) > kMaxEmCoordinate ||
                                   !std::isfinite(record.advance) || std::fabs(record.advance) > kMaxEmCoordinate)) {
        return {true, "coordinates beyond +-64 em"};
    }
    // An empty glyph's metrics too (an advance of 65535 units at 16 per em; a CFF glyph whose
    // zero-length curve, dropped, left FreeType's bearing far out): the asset holds every
    // record's within the same bound.
    if (std::optional<std::string> why = metrics_out_of_range(record)) return {true, std::move(*why)};

    counters.lines += glyph_counters.lines;
    counters.quadratics += glyph_counters.quadratics;
    counters.cubics += glyph_counters.cubics;
    counters.cubic_pieces += glyph_counters.cubic_pieces;
    counters.dropped_zero_length += glyph_counters.dropped_zero_length;
    counters.closed_contours += glyph_counters.closed_contours;
    counters.y_splits += glyph_counters.y_splits;
    counters.max_deviation = std::max(counters.max_deviation, glyph_counters.max_deviation);
    counters.seed_max_deviation = std::max(counters.seed_max_deviation, glyph_counters.seed_max_deviation);

    record.flags = kGlyphBaked | (transform ? kGlyphSynthetic : 0u);
    if (packed.curve_count == 0) {
        ++report.empty_glyphs;
        return {};
    }
    const GlyphBands bands = build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap);
    if (std::optional<std::string> full = asset_room(asset, packed, bands, budget))
        return {true, std::move(*full), true};
    append_glyph(packed, bands, record, asset);

    report.curve_count += packed.real_curves;
    report.max_curves_per_glyph = std::max(report.max_curves_per_glyph, packed.real_curves);
    report.band_count += bands.band_count;
    report.max_bands_per_glyph = std::max<uint32_t>(report.max_bands_per_glyph, bands.band_count);
    report.max_curves_per_band = std::max(report.max_curves_per_band, bands.max_curves_in_band);
    report.mean_curves_per_band += static_cast<double>(bands.entries);  // summed; divided at the end
    report.mean_curve_tests_per_ray += bands.mean_tests_per_ray;        // summed; divided at the end
    return {};
}

}  // namespace

namespace {

// Refuses options out of range, and font bytes too large or in a container crisp does not bake.
Status check_options(std::span<const std::byte> font_bytes, const BakeOptions& options) {
    if (!(options.tolerance_em > 0.0f && options.tolerance_em <= 0.1f)) {
        return Error{ErrorCode::invalid_argument, "tolerance must be in (0, 0.1] em"};
    }
    if (!(options.max_size_px == 0.0f || (options.max_size_px >= 1.0f && options.max_size_px <= kMaxBakeSizePx))) {
        return Error{ErrorCode::invalid_argument, "the largest size to bake for must be in [1, " +
                                                      std::to_string(static_cast<int>(kMaxBakeSizePx)) +
                                                      "] px per em (0: not given)"};
    }
    if (options.max_curves_per_glyph == 0 || options.max_curves_per_glyph > kMaxCurvesPerGlyph) {
        return Error{ErrorCode::invalid_argument,
                     "the curve limit per glyph must be 1 to " + std::to_string(kMaxCurvesPerGlyph)};
    }
    if (font_bytes.size() > 0x7FFFFFFF) {
        return Error{ErrorCode::font_unreadable, "the font is larger than 2 GiB"};
    }
    return check_font_container(font_bytes);
}

// A FreeType library and the face opened in it; the face, declared last, is closed first.
struct OpenedFace {
    LibraryHandle library;
    FaceHandle face;
};

// Starts FreeType and opens the requested face, refusing a face index past the font's face count.
Result<OpenedFace> open_face(std::span<const std::byte> font_bytes, const BakeOptions& options) {
    FT_Library raw_library = nullptr;
    if (const FT_Error error = FT_Init_FreeType(&raw_library); error != 0) {
        return Error{ErrorCode::font_unreadable, "cannot start FreeType: " + freetype_error(error)};
    }
    LibraryHandle library(raw_library);
    const auto* data = reinterpret_cast<const FT_Byte*>(font_bytes.data());
    const auto size = static_cast<FT_Long>(font_bytes.size());

    FT_Face raw_face = nullptr;
    if (const FT_Error error = FT_New_Memory_Face(library.get(), data, size, -1, &raw_face); error != 0) {
        return Error{ErrorCode::font_unreadable, "not a font FreeType can read: " + freetype_error(error)};
    }
    const FT_Long face_count = raw_face->num_faces;
    FT_Done_Face(raw_face);
    if (static_cast<FT_Long>(options.face_index) >= face_count) {
        return Error{ErrorCode::font_unreadable, "face " + std::to_string(options.face_index) +
                                                     " requested, but the font holds " + std::to_string(face_count) +
                                                     (face_count == 1 ? " face" : " faces")};
    }
    raw_face = nullptr;
    if (const FT_Error error =
            FT_New_Memory_Face(library.get(), data, size, static_cast<FT_Long>(options.face_index), &raw_face);
        error != 0) {
        return Error{ErrorCode::font_unreadable,
                     "cannot open face " + std::to_string(options.face_index) + ": " + freetype_error(error)};
    }
    FaceHandle face(raw_face);
    return OpenedFace{std::move(library), std::move(face)};
}

// Refuses a face without outlines or colour bitmaps, or with units per em or a glyph count outside
// what OpenType allows.
Status check_face(FT_Face face) {
    if (!FT_IS_SCALABLE(face) && !is_colour_bitmap_face(face)) {
        return Error{ErrorCode::font_unsupported,
                     "the face has no scalable outlines and no colour bitmaps (bitmap-only font)"};
    }
    if (Status status = check_units_per_em(face_metrics(face).units_per_em); !status) return status;
    const auto glyph_count = static_cast<uint32_t>(face->num_glyphs);
    if (glyph_count == 0 || glyph_count > 65536) {
        return Error{ErrorCode::font_unsupported, "the face holds " + std::to_string(glyph_count) + " glyphs"};
    }
    return {};
}

// Fills info from the face (names, variation, metrics) and scales the face to one pixel per font unit.
Status read_font_info(FT_Library library, FT_Face face, const BakeOptions& options, FontInfo& info) {
    info.family = face->family_name ? face->family_name : "";
    info.style = face->style_name ? face->style_name : "";
    info.units_per_em = face_metrics(face).units_per_em;
    info.face_index = options.face_index;
    info.tolerance_em = options.tolerance_em;
    if (Status status = apply_variations(library, face, options, info); !status) return status;
    // After the variation: FreeType applies MVAR to these.
    const FaceMetrics metrics = face_metrics(face);
    info.ascender = metrics.ascender;
    info.descender = metrics.descender;
    info.line_gap = std::max(0, metrics.height - (metrics.ascender - metrics.descender));

    // Its strikes are a bitmap-only face's only sizes; BitmapGlyphs selects one.
    if (is_colour_bitmap_face(face)) return {};
    // One pixel per font unit; see bake_glyph.
    if (const FT_Error error = FT_Set_Char_Size(face, 0, static_cast<FT_F26Dot6>(info.units_per_em) * 64, 72, 72);
        error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot scale the face: " + freetype_error(error)};
    }
    return {};
}

// Bakes every wanted glyph (every glyph when `wanted` is empty) into the asset (its colour bitmap,
// its outline), a failed one as an empty record flagged failed, and reports progress; returns how
// many glyphs were requested. A glyph that would take the asset past a limit stops the bake.
Result<uint32_t> bake_glyphs(FT_Face face, const BakeOptions& options, const std::vector<uint8_t>& wanted,
                             BitmapGlyphs& bitmaps, BakeBudget& budget, OutlineCounters& counters, FontAsset& asset,
                             BakeReport& report) {
    const auto glyph_count = static_cast<uint32_t>(face->num_glyphs);
    const uint32_t units_per_em = asset.info.units_per_em;
    const bool all = wanted.empty();
    const uint32_t to_do = all ? glyph_count : static_cast<uint32_t>(std::count(wanted.begin(), wanted.end(), 1));

    asset.glyphs.assign(glyph_count, GlyphRecord{});
    report.glyph_count = glyph_count;
    uint32_t done = 0;
    for (uint32_t glyph = 0; glyph < glyph_count; ++glyph) {
        if (!all && !wanted[glyph]) continue;
        GlyphOutcome outcome;
        if (std::optional<std::string> reason = bitmaps.bake(glyph, asset, report))
            outcome = {true, std::move(*reason)};
        else if (!bitmaps.bitmap_only())
            outcome = bake_glyph(face, glyph, units_per_em, options, budget, counters, asset, report, glyph);
        if (outcome.asset_full) return asset_full(glyph, outcome.reason);
        if (outcome.failed) {
            asset.glyphs[glyph] = GlyphRecord{};
            asset.glyphs[glyph].flags = kGlyphBaked | kGlyphFailed;
            if (report.failed_glyphs == 0)
                report.first_failure = "glyph " + std::to_string(glyph) + ": " + outcome.reason;
            if (report.failed_glyph_ids.size() < kReportedFailures) report.failed_glyph_ids.push_back(glyph);
            ++report.failed_glyphs;
        } else {
            ++report.baked_glyphs;
        }
        ++done;
        if (options.progress && (done % 256 == 0 || done == to_do)) options.progress(done, to_do);
    }
    return to_do;
}

// Appends the outlines of transformed colour layers after the face's glyphs, each its face
// glyph's outline under the layer's transform, converted and banded as any glyph is. Returns why
// each failed (empty where it did not): an asset holds no failed synthetic glyph, so the colour
// glyphs on a failed one are dropped (ColourAssembler::drop_failed_outlines). One that would take
// the asset past a limit stops the bake.
Result<std::vector<std::string>> bake_synthetic_glyphs(FT_Face face, const BakeOptions& options,
                                                       const std::vector<SyntheticOutline>& outlines,
                                                       BakeBudget& budget, OutlineCounters& counters, FontAsset& asset,
                                                       BakeReport& report) {
    std::vector<std::string> failures;
    for (const SyntheticOutline& outline : outlines) {
        const auto record = static_cast<uint32_t>(asset.glyphs.size());
        asset.glyphs.emplace_back();
        const GlyphOutcome outcome = bake_glyph(face, outline.glyph, asset.info.units_per_em, options, budget, counters,
                                                asset, report, record, &outline.transform);
        if (outcome.asset_full) return asset_full(outline.glyph, outcome.reason);
        if (outcome.failed) {
            asset.glyphs[record] = GlyphRecord{};
            asset.glyphs[record].flags = kGlyphSynthetic;
        } else {
            ++report.baked_glyphs;
        }
        failures.push_back(outcome.reason);
    }
    return failures;
}

// Copies the outline counters into the report, and divides its summed means by what they average over.
void finish_report(const OutlineCounters& counters, BakeReport& report) {
    report.line_count = counters.lines;
    report.quadratic_count = counters.quadratics;
    report.cubic_count = counters.cubics;
    report.cubic_pieces = counters.cubic_pieces;
    report.dropped_zero_length = counters.dropped_zero_length;
    report.closed_contours = counters.closed_contours;
    report.y_splits = counters.y_splits;
    report.max_deviation_em = counters.max_deviation;
    report.seed_max_deviation_em = counters.seed_max_deviation;
    report.seed_cubic_pieces = 2 * counters.cubics;
    const uint32_t outlined = report.baked_glyphs - report.empty_glyphs;
    if (outlined > 0) {
        report.mean_curves_per_glyph = static_cast<double>(report.curve_count) / outlined;
        report.mean_curve_tests_per_ray /= outlined;
    }
    report.mean_curves_per_band =
        report.band_count > 0 ? report.mean_curves_per_band / static_cast<double>(report.band_count) : 0.0;
}

}  // namespace

Result<BakeResult> bake_font(std::span<const std::byte> font_bytes, const BakeOptions& given) {
    const auto started = std::chrono::steady_clock::now();
    if (Status status = check_options(font_bytes, given); !status) return status.error();
    // A size to bake for sets the tolerance: kPixelTolerance at that size.
    BakeOptions options = given;
    if (given.max_size_px > 0.0f) options.tolerance_em = kPixelTolerance / given.max_size_px;
    if (Status status = check_font_tables(font_bytes, options.face_index); !status) return status.error();
    Result<OpenedFace> opened = open_face(font_bytes, options);
    if (!opened) return opened.error();
    const FT_Face face = opened->face.get();
    if (Status status = check_face(face); !status) return status.error();
    const auto face_glyphs = static_cast<uint32_t>(face->num_glyphs);
    if (Status status = check_glyph_count(font_bytes, options.face_index, face_glyphs); !status) return status.error();

    BakeResult result;
    FontAsset& asset = result.asset;
    BakeReport& report = result.report;
    FontInfo& info = asset.info;
    if (Status status = read_font_info(opened->library.get(), face, options, info); !status) return status.error();

    std::vector<uint8_t> wanted;  // empty: every glyph
    const auto glyph_count = static_cast<uint32_t>(face->num_glyphs);
    if (!options.all_glyphs) wanted = requested_glyphs(font_bytes, options.face_index, options.codepoints, glyph_count);
    Result<ColourAssembler> colour = read_colour_glyphs(font_bytes, info, glyph_count, options, wanted, asset, report);
    if (!colour) return colour.error();
    if (!options.all_glyphs) colour->mark_layer_glyphs(wanted);

    Result<BitmapGlyphs> bitmaps = BitmapGlyphs::open(face, info.units_per_em);
    if (!bitmaps) return bitmaps.error();
    OutlineCounters counters;
    BakeBudget budget{CompositeBounds(font_bytes, options.face_index, face),
                      font_bytes.size() + uint64_t{glyph_count} * asset_format::kGlyphRecordSize};
    const Result<uint32_t> to_do = bake_glyphs(face, options, wanted, *bitmaps, budget, counters, asset, report);
    if (!to_do) return to_do.error();
    const Result<std::vector<std::string>> failures =
        bake_synthetic_glyphs(face, options, colour->synthetic(), budget, counters, asset, report);
    if (!failures) return failures.error();
    if (Status status = colour->drop_failed_outlines(*failures, options.allow_failed, asset, report); !status) {
        return status.error();
    }
    // COLR's colour glyphs first: a bitmap gives way to them, and its rectangles follow their outlines.
    colour->finish(asset);
    if (Status status = bitmaps->finish(asset); !status) return status.error();
    report.colour_glyphs = static_cast<uint32_t>(asset.colour_glyphs.size());
    report.colour_layers = static_cast<uint32_t>(asset.layers.size());
    report.synthetic_glyphs = static_cast<uint32_t>(asset.glyphs.size() - asset.face_glyph_count());
    if (counters.cubics > 0) info.flags |= kFontCubic;
    info.max_deviation_em = static_cast<float>(counters.max_deviation);
    asset.font_bytes.assign(font_bytes.begin(), font_bytes.end());
    finish_report(counters, report);
    report.tolerance_em = static_cast<double>(options.tolerance_em);
    report.report_size_px = static_cast<double>(given.max_size_px > 0.0f ? given.max_size_px : kDefaultMaxSizePx);
    report.max_deviation_px = report.max_deviation_em * report.report_size_px;

    if (report.failed_glyphs > 0 && !options.allow_failed) {
        return Error{ErrorCode::glyph_failed, std::to_string(report.failed_glyphs) + " of " + std::to_string(*to_do) +
                                                  " glyphs failed; first: " + report.first_failure};
    }
    if (Status status = validate_asset(asset); !status) {
        return Error{ErrorCode::asset_invalid,
                     "the baked asset does not validate (a crisp bug): " + status.error().message};
    }
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return result;
}

Result<BakeResult> bake_font_file(const std::filesystem::path& path, const BakeOptions& options) {
    Result<std::vector<std::byte>> bytes = read_file(path, limits::kFontFileBytes);
    if (!bytes) return bytes.error();
    return bake_font(*bytes, options);
}

}  // namespace crisp
