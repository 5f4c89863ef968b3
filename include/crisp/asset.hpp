// crisp: the .crisp font asset, the only contract between the offline baker and the run time.
//
// An asset holds, for one face of one font at fixed variation-axis values, every baked glyph as
// quadratic Bezier curves in em units (y up), cut into horizontal bands that each carry a bitset
// of the curves touching them; the face's metrics; and the original font bytes, so that HarfBuzz
// can shape from the asset alone. The byte layout is documented in docs/asset-format.md.
//
// Curve storage. A glyph's curves live in `FontAsset::points` as a run of 2 * curve_count + 1
// points starting at `GlyphRecord::point_offset`: curve i is (points[2i], points[2i+1],
// points[2i+2]) relative to that offset, so consecutive curves of a contour share their end
// point. Where one contour ends and the next begins, the slot between them is a pad curve that
// no band references; readers only ever visit curves through the band bitsets.
#pragma once

#include <crisp/export.hpp>

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace crisp {

// Version 2 added colour glyphs (the COLR, LAYR, PANT, STOP, CPAL and IMAG sections); version 1
// assets load as assets without them.
inline constexpr uint32_t kAssetVersion = 2;

// The most curves one glyph may have, in the baker and (with the pads between its contours, twice
// as many curve slots) in the loader: the most complex glyphs of common fonts have about 550 (a CJK
// face's), and a glyph's cost in every sample grows with its curves (docs/limits.md).
inline constexpr uint32_t kMaxCurvesPerGlyph = 4096;

struct Point {
    float x = 0.0f;
    float y = 0.0f;
    friend bool operator==(const Point&, const Point&) = default;
};

enum GlyphFlags : uint32_t {
    kGlyphBaked = 1u << 0,   // the glyph was requested and converted (absent glyphs have no curves)
    kGlyphFailed = 1u << 1,  // conversion failed; baked with --allow-failed as an empty glyph
    // Not a glyph of the face: an outline the baker made for a colour glyph's layer (a layer glyph
    // under a COLRv1 transform, a bitmap's rectangle). Synthetic records follow the face's glyphs
    // (FontAsset::face_glyph_count()); shaping never produces them, only ColourLayer::glyph names them.
    kGlyphSynthetic = 1u << 2,
};

// One glyph, indexed by the font's glyph index. All lengths are in em (font units / units per em),
// y up, origin at the pen position on the baseline.
struct GlyphRecord {
    float advance = 0.0f;     // horizontal advance
    float bearing_x = 0.0f;   // left side bearing: pen to the left edge of the outline's bbox
    float bearing_y = 0.0f;   // top side bearing: baseline to the top edge of the outline's bbox
    float bbox_min_x = 0.0f;  // bbox of every curve point (on- and off-curve), so all curves lie inside
    float bbox_min_y = 0.0f;
    float bbox_max_x = 0.0f;
    float bbox_max_y = 0.0f;
    uint32_t point_offset = 0;  // first point in FontAsset::points
    uint32_t curve_count = 0;   // curve slots, pads included; the glyph owns 2 * curve_count + 1 points
    uint32_t band_offset = 0;   // first word in FontAsset::band_words
    uint16_t band_count = 0;    // bands split [bbox_min_y, bbox_max_y] into equal heights
    uint16_t band_words = 0;    // words per band: ceil(curve_count / 32)
    uint32_t flags = 0;         // GlyphFlags
    friend bool operator==(const GlyphRecord&, const GlyphRecord&) = default;
};

struct AxisValue {
    uint32_t tag = 0;  // OpenType axis tag, e.g. 'wght' = 0x77676874
    float value = 0.0f;
    float minimum = 0.0f;
    float default_value = 0.0f;
    float maximum = 0.0f;
    friend bool operator==(const AxisValue&, const AxisValue&) = default;
};

enum FontFlags : uint32_t {
    kFontCubic = 1u << 0,     // outlines were cubic (CFF, CFF2) and have been lowered to quadratics
    kFontVariable = 1u << 1,  // the face has variation axes; `axes` holds the baked instance
};

struct FontInfo {
    std::string family;
    std::string style;
    uint32_t units_per_em = 0;
    int32_t ascender = 0;           // font units, positive above the baseline
    int32_t descender = 0;          // font units, negative below the baseline
    int32_t line_gap = 0;           // font units
    uint32_t face_index = 0;        // face within the font bytes (a collection holds several)
    uint32_t flags = 0;             // FontFlags
    float tolerance_em = 0.0f;      // cubic lowering tolerance the asset was baked with
    float max_deviation_em = 0.0f;  // largest measured cubic-to-quadratic deviation
    std::vector<AxisValue> axes;
    friend bool operator==(const FontInfo&, const FontInfo&) = default;
};

// ---- Colour glyphs (docs/colour.md). A colour glyph (COLRv0, COLRv1, or a CBDT/sbix bitmap) is
// baked into a list of layers in paint order, back to front: each layer is an outline glyph of the
// asset (rasterized into the atlas like any glyph) filled with a paint. The COLRv1 paint graph is
// flattened at bake time: transforms are folded into the layer's outline (a synthetic glyph) and
// into its paint's mapping, groups composited src-over (and the other modes a layer list can
// express exactly) become consecutive layers.

// The palette index that means "the text's own colour" (CPAL's 0xFFFF).
inline constexpr uint32_t kForegroundPaletteIndex = 0xFFFF;

// Limits on colour glyphs (docs/limits.md): the baker refuses a glyph past them, the loader an
// asset. Every layer is a quad the compositor sorts and a glyph the atlas holds.
inline constexpr uint32_t kMaxColourLayers = 1024;      // layers of one colour glyph
inline constexpr uint32_t kMaxColourStops = 256;        // stops of one colour line
inline constexpr uint32_t kMaxPalettes = 256;           // CPAL palettes kept
inline constexpr uint32_t kMaxPaletteSize = 4096;       // entries per palette
inline constexpr uint32_t kMaxBitmapSide = 1024;        // pixels a side of one bitmap glyph
inline constexpr uint32_t kMaxSyntheticGlyphs = 65536;  // synthetic outline records

enum class PaintKind : uint32_t {
    solid = 0,   // one stop: its colour
    linear = 1,  // geometry: p0 (x, y), p1 (x, y); colour line t = 0 at p0, 1 at p1
    radial = 2,  // geometry: c0 (x, y), r0, c1 (x, y), r1: the two-point conical gradient
    sweep = 3,   // geometry: centre (x, y), start and end angle in turns (1 = 360 degrees, counter-clockwise)
    image = 4,   // a bitmap (PaintBitmap::image) over the unit square [0, 1]^2 of paint space, y down
};
enum class PaintExtend : uint32_t { pad = 0, repeat = 1, reflect = 2 };

// An affine map: x' = xx * x + xy * y + dx, y' = yx * x + yy * y + dy.
struct Affine {
    float xx = 1.0f;
    float yx = 0.0f;
    float xy = 0.0f;
    float yy = 1.0f;
    float dx = 0.0f;
    float dy = 0.0f;
    friend bool operator==(const Affine&, const Affine&) = default;
};

// A colour of a colour line: a palette entry (or kForegroundPaletteIndex) times an alpha.
struct ColourStop {
    float offset = 0.0f;  // position on the colour line; stops are sorted by it
    uint32_t palette_index = 0;
    float alpha = 1.0f;  // [0, 1]
    friend bool operator==(const ColourStop&, const ColourStop&) = default;
};

struct Paint {
    PaintKind kind = PaintKind::solid;
    PaintExtend extend = PaintExtend::pad;
    uint32_t first_stop = 0;  // in FontAsset::stops; a solid paint has exactly one stop
    uint32_t stop_count = 0;
    uint32_t image = 0;  // image paints: index in FontAsset::images
    // From the glyph's em space (y up, origin at the pen) to the paint's own space, where its
    // geometry is given.
    Affine to_paint;
    float geometry[6] = {};
    friend bool operator==(const Paint&, const Paint&) = default;
};

struct ColourLayer {
    uint32_t glyph = 0;  // the layer's outline: a glyph of the asset (a face glyph or a synthetic one)
    uint32_t paint = 0;  // index in FontAsset::paints
    friend bool operator==(const ColourLayer&, const ColourLayer&) = default;
};

enum ColourGlyphFlags : uint32_t {
    kColourClipped = 1u << 0,  // the clip box holds: nothing of the glyph shows outside it
};

struct ColourGlyph {
    uint32_t glyph = 0;        // the face glyph shaping gives; ColourGlyphs are sorted by it, once each
    uint32_t first_layer = 0;  // in FontAsset::layers
    uint32_t layer_count = 0;
    uint32_t flags = 0;       // ColourGlyphFlags
    float clip_min_x = 0.0f;  // em: the COLRv1 clip box
    float clip_min_y = 0.0f;
    float clip_max_x = 0.0f;
    float clip_max_y = 0.0f;
    friend bool operator==(const ColourGlyph&, const ColourGlyph&) = default;
};

// A bitmap glyph's pixels: premultiplied RGBA8, sRGB-encoded, rows top to bottom, compressed with
// zlib (RFC 1950) in FontAsset::image_bytes.
struct BitmapImage {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t byte_offset = 0;  // in FontAsset::image_bytes
    uint32_t byte_count = 0;
    friend bool operator==(const BitmapImage&, const BitmapImage&) = default;
};

// A font asset in memory. `glyphs` is indexed by glyph index and holds one record for every glyph
// of the face, baked or not, then the synthetic glyphs of colour layers.
struct CRISP_API FontAsset {
    FontInfo info;
    std::vector<GlyphRecord> glyphs;
    std::vector<Point> points;
    std::vector<uint32_t> band_words;
    std::vector<std::byte> font_bytes;
    // Colour glyphs; all empty for a font without any.
    std::vector<ColourGlyph> colour_glyphs;
    std::vector<ColourLayer> layers;
    std::vector<Paint> paints;
    std::vector<ColourStop> stops;
    // CPAL: palette_count palettes of palette_size entries each, RGBA8 (red in the low byte),
    // sRGB-encoded, straight alpha, palette-major.
    uint32_t palette_size = 0;
    std::vector<uint32_t> palette_colours;
    std::vector<BitmapImage> images;
    std::vector<std::byte> image_bytes;
    friend bool operator==(const FontAsset&, const FontAsset&) = default;

    // The glyphs of the face: the records before the first synthetic one.
    uint32_t face_glyph_count() const;
    uint32_t palette_count() const;
    // The colour glyph of face glyph `glyph`, or nullptr when it has none (a binary search).
    const ColourGlyph* colour_glyph(uint32_t glyph) const;

    // The band holding em-space height y: with h = (bbox_max_y - bbox_min_y) / band_count,
    // clamp(floor((y - bbox_min_y) / h), 0, band_count - 1), evaluated in float in that order (as a
    // shader does); a y on a band edge belongs to the upper band. 0 when the glyph has no bands,
    // when h <= 0, or when y is NaN. The baker, the CPU reference and the shaders share this rule.
    static uint32_t band_of(const GlyphRecord& glyph, float y);
};

// Parses and validates an asset. Safe to use with untrusted input: every offset, count, float and
// the checksum is checked before anything is used, and a bad asset returns
// ErrorCode::asset_invalid (or asset_version) with a message naming the fault; nothing crashes
// and nothing is read out of bounds.
CRISP_API Result<FontAsset> load_asset(std::span<const std::byte> bytes);

// Reads a file and loads it as above. An unreadable file returns ErrorCode::io.
CRISP_API Result<FontAsset> load_asset_file(const std::filesystem::path& path);

// Checks an in-memory asset against the same rules the loader applies (so a baker can refuse to
// write an asset the loader would reject). Returns ErrorCode::asset_invalid naming the fault.
CRISP_API Status validate_asset(const FontAsset& asset);

// Encodes an asset in the file format (little-endian, checksummed). The asset must be valid.
CRISP_API std::vector<std::byte> serialize_asset(const FontAsset& asset);

// Writes serialize_asset(asset) to `path` atomically: the bytes go to a temporary file beside it,
// which is flushed and renamed over `path` only when complete. On failure (ErrorCode::io) an
// existing file at `path` is untouched and no temporary file is left behind.
CRISP_API Status save_asset_file(const FontAsset& asset, const std::filesystem::path& path);

}  // namespace crisp
