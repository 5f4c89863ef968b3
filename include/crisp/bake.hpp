// crisp: baking a font (TrueType, OpenType CFF/CFF2, collections, variable fonts) into a FontAsset.
//
// The baker reads outlines with FreeType, unhinted and in font units, normalises them to em, turns
// lines into quadratics, lowers cubics to quadratics within a tolerance, drops zero-length curves,
// closes open contours, and cuts each glyph into bands. It needs no GPU. Colour glyphs (COLRv0
// layers, the COLRv1 paint graph, CPAL palettes) are read by crisp's own COLR reader and flattened
// into layers (docs/colour.md).
//
// The baker is its own library, crisp::bake (CMake target crisp_bake), which links crisp::crisp
// and FreeType: an engine that loads assets baked offline links crisp::crisp alone
// (docs/architecture.md).
#pragma once

#include <crisp/export.hpp>

#include <crisp/asset.hpp>
#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace crisp {

// The cubic-to-quadratic tolerance follows the sizes an asset is drawn at: a lowered cubic
// deviates from the font's by at most kPixelTolerance px at the largest size it is baked for
// (BakeOptions::max_size_px), kDefaultMaxSizePx unless told. An edge moved by d px across a
// channel a third of a pixel wide (subpixel thirds) changes its coverage by at most 3 d: 3/1024
// here, within the 1/255 of an 8-bit code (docs/cubic-lowering.md has the measurement).
inline constexpr float kPixelTolerance = 1.0f / 1024.0f;
inline constexpr float kDefaultMaxSizePx = 16.0f;
// The largest size BakeOptions::max_size_px takes: it bounds how finely a bake cuts cubics (the
// pieces grow as the cube root of the size, and a glyph past kMaxCurvesPerGlyph fails).
inline constexpr float kMaxBakeSizePx = 1024.0f;
// kPixelTolerance at kDefaultMaxSizePx: 1/16384 em (it was 1/4096 em before issue 31).
inline constexpr float kDefaultToleranceEm = kPixelTolerance / kDefaultMaxSizePx;

// Bands are added until the fullest band holds at most this many curves, or until kMaxBands.
inline constexpr uint32_t kTargetCurvesPerBand = 4;
inline constexpr uint32_t kMaxBands = 32;
// Each band reaches this fraction of its height past both of its edges, so a curve whose y-extent
// ends exactly on an edge (or within float rounding of it) is listed in both bands.
inline constexpr float kBandOverlap = 1.0f / 256.0f;

// Limits on one colour glyph's COLRv1 paint graph (docs/limits.md): a glyph whose graph nests
// deeper, or that visits more paints (a shared subgraph counts each time it is reached), fails as
// a malformed glyph; so does a cycle, which is refused rather than followed.
inline constexpr uint32_t kMaxPaintDepth = 64;
inline constexpr uint32_t kMaxPaintNodes = 16384;

// Limits on a TrueType glyph as FreeType would expand it, read from glyf before it is loaded
// (docs/limits.md): a glyph past one fails, naming it. Composites nest a base and its accents a
// level or two deep; a glyph of more points than twice kMaxCurvesPerGlyph has more curves than
// it (a curve takes at least two points), short of zero-length ones.
inline constexpr uint32_t kMaxCompositeDepth = 8;     // levels of composites above a simple glyph
inline constexpr uint32_t kMaxCompositeParts = 1024;  // component references in one glyph's tree
inline constexpr uint32_t kMaxGlyphPoints = 2 * kMaxCurvesPerGlyph;
// Points of all the glyphs one bake loads: twice what kMaxAssetPointBytes holds.
inline constexpr uint64_t kMaxBakePoints = uint64_t{1} << 25;

// The asset's curve points, and its band words with the renderer's flat rows (one per glyph at
// most), each fit one storage buffer of the range every Vulkan device has (maxStorageBufferRange
// is at least 2^27): the bake stops with font_unsupported at the glyph that would pass either, or
// the 1 GiB an asset file may be (docs/limits.md).
inline constexpr uint64_t kMaxAssetPointBytes = uint64_t{1} << 27;
inline constexpr uint64_t kMaxAssetBandBytes = uint64_t{1} << 27;

struct Variation {
    uint32_t tag = 0;  // OpenType axis tag
    float value = 0.0f;
};

struct BakeOptions {
    uint32_t face_index = 0;            // face of a collection (.ttc); 0 for single fonts
    std::vector<Variation> variations;  // axis values; unnamed axes stay at their default
    // Code points to bake, with every glyph shaping can substitute for them (GSUB closure) and
    // .notdef. Empty: every glyph of the face.
    std::vector<uint32_t> codepoints;
    bool all_glyphs = true;                    // false: bake only `codepoints` (and their closure)
    float tolerance_em = kDefaultToleranceEm;  // largest cubic-to-quadratic deviation, in (0, 0.1]
    // The largest size (px per em) the asset is drawn at, in [1, kMaxBakeSizePx]; when set (not
    // 0), cubics are lowered within kPixelTolerance / max_size_px em and tolerance_em is not read.
    // 0: not given, tolerance_em holds. Anything else outside that range, or NaN: invalid_argument.
    float max_size_px = 0.0f;
    bool split_y_extrema = false;  // split quadratics at y-extrema (docs/cubic-lowering.md)
    // A glyph with more curves fails; at most kMaxCurvesPerGlyph (asset.hpp).
    uint32_t max_curves_per_glyph = kMaxCurvesPerGlyph;
    // Keep going past failed glyphs, baking them empty; past malformed colour glyphs, drawing
    // them as their COLRv0 layers or plain outline; past a COLR or CPAL table that cannot be
    // read, baking no colour glyphs. Each is counted in the report.
    bool allow_failed = false;
    // Called now and then with (glyphs done, glyphs to do); may be empty.
    std::function<void(uint32_t, uint32_t)> progress;
};

struct BakeReport {
    uint32_t glyph_count = 0;   // glyphs in the face
    uint32_t baked_glyphs = 0;  // glyphs converted (requested and not failed), synthetic ones included
    uint32_t empty_glyphs = 0;  // baked glyphs without an outline (space, ...)
    uint32_t failed_glyphs = 0;
    std::vector<uint32_t> failed_glyph_ids;  // the first few failed glyph indices
    std::string first_failure;               // why the first glyph failed
    uint64_t curve_count = 0;                // quadratic curves, pads excluded
    uint64_t line_count = 0;                 // curves that came from lines
    uint64_t quadratic_count = 0;            // curves that came from quadratics as they were
    uint64_t cubic_count = 0;                // cubics in the source outlines
    uint64_t cubic_pieces = 0;               // quadratics the cubics were lowered to
    uint64_t dropped_zero_length = 0;        // zero-length curves removed
    uint64_t closed_contours = 0;            // open contours closed with a line
    uint64_t y_splits = 0;                   // extra curves from splitting at y-extrema
    uint32_t max_curves_per_glyph = 0;
    double mean_curves_per_glyph = 0.0;  // over baked glyphs with an outline
    uint64_t band_count = 0;
    uint32_t max_bands_per_glyph = 0;
    uint32_t max_curves_per_band = 0;
    double mean_curves_per_band = 0.0;  // over all bands of all glyphs
    // Mean curves a sample ray tests: per glyph, the band curve counts weighted by band height,
    // then averaged over glyphs with an outline. The cost model of the rasterizer.
    double mean_curve_tests_per_ray = 0.0;
    double tolerance_em = 0.0;  // the tolerance the cubics were lowered within
    // The size the deviation is reported at: max_size_px where given, else kDefaultMaxSizePx.
    double report_size_px = 0.0;
    double max_deviation_em = 0.0;  // largest measured cubic-to-quadratic deviation
    // max_deviation_em at report_size_px, in px: a bound on how far a lowered edge lies from the
    // font's at that size and below. An edge that crosses a channel a third of a pixel wide from
    // top to bottom moves its coverage by at most 3 times it (more edges in one channel add up).
    double max_deviation_px = 0.0;
    double seed_max_deviation_em = 0.0;  // the same for the seed's fixed split in two
    uint64_t seed_cubic_pieces = 0;      // 2 per cubic
    uint64_t asset_bytes = 0;            // size of the serialized asset
    // Colour glyphs (COLR/CPAL layers, colour bitmaps), among the requested glyphs.
    uint32_t colour_glyphs = 0;  // base glyphs drawn as colour layers
    uint32_t colour_layers = 0;  // their layers in all
    // Outlines made for transformed COLRv1 layers and bitmaps' rectangles (kGlyphSynthetic records).
    uint32_t synthetic_glyphs = 0;
    // Base glyphs whose COLRv1 paint (or COLRv0 layers) was refused and that fell back to their
    // COLRv0 layers or their plain outline: an unsupported feature (a composite mode, a nested
    // clip), or with allow_failed a malformed graph (a cycle, a limit, a bad offset or palette index).
    uint32_t colour_fallbacks = 0;
    std::string first_colour_fallback;  // "glyph N: " and why, for the first of them
    // What else the reader had to say: palettes past kMaxPalettes dropped, variation deltas not
    // applied, with allow_failed a COLR or CPAL table it could not read.
    std::vector<std::string> colour_notes;
    double seconds = 0.0;
};

struct BakeResult {
    FontAsset asset;
    BakeReport report;
};

// Bakes a font held in memory. Errors: ErrorCode::font_unreadable (FreeType cannot open the
// bytes, they are not an sfnt, face_index is past the collection, a table lies past the end of
// the bytes (a truncated font), or maxp's glyph count is not the CFF table's or loca's: the
// message names the table), font_unsupported (a WOFF, WOFF2, Type 1 or bare CFF font, as
// check_font_container says; neither scalable outlines nor colour bitmaps; units per em outside
// 16..16384; a variation on a face without axes or an unknown axis tag; an asset that would pass
// kMaxAssetPointBytes, kMaxAssetBandBytes or 1 GiB, at the glyph that would pass it),
// invalid_argument (a tolerance outside (0, 0.1], a max_size_px neither 0 nor in [1,
// kMaxBakeSizePx], or a non-finite axis value), glyph_failed (a
// glyph could not be converted, its advance or bearing is past +-64 em, or a colour glyph's paint
// graph is malformed: a cycle, a limit passed, a bad offset or palette index; with allow_failed
// false, the message names the first glyph and why). A COLR or CPAL table that
// cannot be read at all is font_unreadable naming the table, unless allow_failed. Layers of the
// requested colour glyphs are baked even when `codepoints` does not reach them. Hostile font
// bytes never crash the baker.
CRISP_API Result<BakeResult> bake_font(std::span<const std::byte> font_bytes, const BakeOptions& options);

// font_unsupported, with what to do instead, for the font containers crisp does not bake though
// FreeType could open them: WOFF, WOFF2 (decompress them first), PostScript Type 1 (PFA, PFB:
// convert them to OpenType CFF) and a bare CFF table (make it OpenType CFF); font_unreadable,
// naming its first bytes, for anything else that does not start as an sfnt (0x00010000, 'OTTO',
// 'true', 'typ1') or a collection ('ttcf'); success for those.
CRISP_API Status check_font_container(std::span<const std::byte> font_bytes);

// Reads the file, then bake_font. An unreadable file returns ErrorCode::io: a file that is not a
// regular file, or larger than 256 MiB (docs/limits.md), is refused before it is read.
CRISP_API Result<BakeResult> bake_font_file(const std::filesystem::path& path, const BakeOptions& options);

// Parses "wght=700" into a Variation; returns invalid_argument naming the fault otherwise.
CRISP_API Result<Variation> parse_variation(std::string_view text);

// Parses code point ranges "U+0020-007E,0x4E00-0x4E10,65" into a sorted list without duplicates.
CRISP_API Result<std::vector<uint32_t>> parse_codepoint_ranges(std::string_view text);

// A four-character tag as its 32-bit value, and back.
CRISP_API uint32_t make_tag(std::string_view four_chars);
CRISP_API std::string tag_to_string(uint32_t tag);

}  // namespace crisp
