// crisp's reader of the COLR (versions 0 and 1) and CPAL tables: a colour glyph's paint graph
// flattened into layers of an outline and a paint, as docs/colour.md defines them. FreeType is not
// asked (FreeType 2.12's COLRv1 API returned no paint for fonts fontTools makes); the tables are
// read from the font's own table directory. Safe to use with untrusted bytes: every count and
// offset is checked before it is used, a cycle in the paint graph is refused rather than followed,
// and the work per glyph and per font is bounded (kMaxPaintDepth, kMaxPaintNodes, docs/limits.md).
#pragma once

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>
#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace crisp {

// Big-endian reads from a table; `fits` first, as every caller checks its offsets before reading.
namespace sfnt {
inline bool fits(std::span<const std::byte> table, size_t offset, size_t size) {
    return offset <= table.size() && size <= table.size() - offset;
}
inline uint32_t u8(std::span<const std::byte> table, size_t at) {
    return std::to_integer<uint32_t>(table[at]);
}
inline uint32_t u16(std::span<const std::byte> table, size_t at) {
    return u8(table, at) << 8 | u8(table, at + 1);
}
inline int32_t s16(std::span<const std::byte> table, size_t at) {
    return static_cast<int16_t>(static_cast<uint16_t>(u16(table, at)));
}
inline uint32_t u24(std::span<const std::byte> table, size_t at) {
    return u8(table, at) << 16 | u16(table, at + 1);
}
inline uint32_t u32(std::span<const std::byte> table, size_t at) {
    return u16(table, at) << 16 | u16(table, at + 2);
}
inline int32_t s32(std::span<const std::byte> table, size_t at) {
    return static_cast<int32_t>(u32(table, at));
}
}  // namespace sfnt

// Paints the reader visits in all, over every colour glyph of one font: with the per-glyph
// budget, it bounds the work and the layers a small table can ask for (docs/limits.md).
inline constexpr uint64_t kMaxFontPaintNodes = uint64_t{1} << 22;

// The bytes of table `tag` of face `face_index` (a collection's too), found through the face's
// table directory; empty when the face has no such table. font_unreadable, naming the table, when
// the directory or the table's record lies past the bytes.
Result<std::span<const std::byte>> find_sfnt_table(std::span<const std::byte> font, uint32_t face_index, uint32_t tag);

// One layer of a flattened colour glyph, before it joins the asset.
struct ColrLayer {
    uint32_t glyph = 0;        // the face glyph whose outline the layer is
    bool transformed = false;  // the outline is `outline_transform` applied to it: a synthetic glyph
    Affine outline_transform;  // em to em
    Paint paint;               // first_stop and stop_count are left for the asset; the stops are here
    std::vector<ColourStop> stops;
};

struct ColrGlyph {
    std::vector<ColrLayer> layers;  // back to front
    uint32_t flags = 0;             // ColourGlyphFlags
    float clip_min_x = 0.0f, clip_min_y = 0.0f, clip_max_x = 0.0f, clip_max_y = 0.0f;
};

enum class ColrRefusal {
    none,
    unsupported,  // a feature crisp does not draw (a composite mode, a nested clip): the glyph falls back
    malformed,    // a hostile or broken graph (a cycle, a limit, a bad offset or palette index): a failed glyph
};

// What became of one base glyph: its layers, and why COLRv1 (or COLRv0) was refused if it was.
struct ColrOutcome {
    bool colour = false;  // `glyph` holds the layers to draw; false: the glyph draws as its plain outline
    ColrGlyph glyph;
    ColrRefusal refusal = ColrRefusal::none;
    std::string reason;  // the first refusal's, when there was one
};

// COLR and CPAL of one face, their headers read and checked.
class ColrReader {
public:
    // Reads both headers and checks that every array they point to lies inside its table (CPAL
    // may be empty: then only the foreground index is valid). font_unreadable naming the table
    // and the fault otherwise, or when CPAL's palettes are larger than kMaxPaletteSize.
    static Result<ColrReader> open(std::span<const std::byte> colr, std::span<const std::byte> cpal,
                                   uint32_t glyph_count, uint32_t units_per_em);

    // The glyphs with a COLRv0 or COLRv1 record, below glyph_count, ascending, each once.
    std::vector<uint32_t> base_glyphs() const;

    // Flattens `glyph`'s COLRv1 paint graph, else (none, or refused) its COLRv0 layers. A refused
    // COLRv1 graph falls back to the COLRv0 layers when they are good; refusal and reason say why.
    // Every call counts against kMaxFontPaintNodes.
    ColrOutcome flatten(uint32_t glyph);

    // CPAL: the first kMaxPalettes palettes, palette-major, RGBA8 with red in the low byte.
    uint32_t palette_size() const { return palette_size_; }
    const std::vector<uint32_t>& palette_colours() const { return palette_colours_; }
    uint32_t table_palettes() const { return table_palettes_; }      // as many as CPAL holds
    bool has_variation_data() const { return has_variation_data_; }  // COLRv1 deltas (not applied)

private:
    friend class PaintWalk;

    ColrReader() = default;
    Status read_colr();
    Status read_cpal();
    // The COLRv1 paint of `glyph` (its offset in COLR), or 0 when it has none.
    size_t v1_paint(uint32_t glyph) const;
    bool v0_record(uint32_t glyph, uint32_t& first_layer, uint32_t& layer_count) const;
    ColrRefusal flatten_v0(uint32_t glyph, ColrGlyph& out, std::string& reason);
    ColrRefusal flatten_v1(uint32_t glyph, size_t paint, ColrGlyph& out, std::string& reason);
    ColrRefusal read_clip_box(uint32_t glyph, ColrGlyph& out, std::string& reason) const;
    // Refuses a palette index past CPAL's entries (the foreground index excepted).
    bool check_palette_index(uint32_t index, std::string& reason) const;

    std::span<const std::byte> colr_;
    std::span<const std::byte> cpal_;
    uint32_t glyph_count_ = 0;
    double units_per_em_ = 1.0;
    uint32_t version_ = 0;
    size_t base_records_ = 0, base_record_count_ = 0;  // COLRv0
    size_t layer_records_ = 0, layer_record_count_ = 0;
    size_t base_glyph_list_ = 0, base_glyph_count_ = 0;  // COLRv1
    size_t layer_list_ = 0, layer_count_ = 0;
    size_t clip_list_ = 0, clip_count_ = 0;
    bool has_variation_data_ = false;
    uint32_t palette_size_ = 0;
    uint32_t table_palettes_ = 0;
    std::vector<uint32_t> palette_colours_;
    uint64_t font_nodes_ = 0;
};

// An outline the asset needs beyond the face's glyphs: a face glyph under a COLRv1 transform.
struct SyntheticOutline {
    uint32_t glyph = 0;  // the face glyph
    Affine transform;    // em to em
};

// Builds the asset's colour sections from flattened glyphs added in ascending glyph order: paints
// and their stops shared where equal, synthetic outlines shared where the glyph and the transform
// are equal.
class ColourAssembler {
public:
    explicit ColourAssembler(uint32_t face_glyph_count) : face_glyph_count_(face_glyph_count) {}

    // Adds `glyph`'s layers. false, with `reason`, when its synthetic outlines would pass
    // kMaxSyntheticGlyphs (nothing of the glyph is added then). A glyph that draws nothing (a
    // clear composite, only dropped layers) gets one transparent layer: an asset's colour glyph
    // has at least one.
    bool add(uint32_t glyph, const ColrGlyph& flat, std::string& reason);

    const std::vector<SyntheticOutline>& synthetic() const { return synthetic_; }
    // Sets wanted[g] for every face glyph some layer's outline is: the bake must convert them.
    void mark_layer_glyphs(std::vector<uint8_t>& wanted) const;

    // After synthetic outline i was baked into record face_glyph_count + i, failures[i] says why
    // it failed (empty: it did not). A colour glyph with a layer on a failed outline is malformed:
    // glyph_failed naming the first, unless allow_failed; then those glyphs fall back to their
    // plain outline (counted in the report) and the failed records leave the asset.
    Status drop_failed_outlines(const std::vector<std::string>& failures, bool allow_failed, FontAsset& asset,
                                BakeReport& report);

    // Moves the colour glyphs, layers, paints and stops into the asset (before any other source of
    // colour glyphs adds its own).
    void finish(FontAsset& asset);

private:
    uint32_t paint_index(const ColrLayer& layer);

    uint32_t face_glyph_count_;
    std::vector<ColourGlyph> colour_glyphs_;
    std::vector<ColourLayer> layers_;
    std::vector<Paint> paints_;
    std::vector<ColourStop> stops_;
    std::vector<SyntheticOutline> synthetic_;
    std::map<std::string, uint32_t> paint_keys_;
    std::map<std::string, uint32_t> synthetic_keys_;
};

// The bake's colour step: reads face info.face_index's COLR and CPAL, fills the asset's palettes,
// and flattens the colour glyphs that `wanted` asks for (all of them when it is empty), in glyph
// order. A refused COLRv1 paint falls back as ColrReader::flatten says and is counted in the
// report. glyph_failed naming the first malformed glyph and why, and font_unreadable for tables
// that cannot be read, unless options.allow_failed (then: that glyph falls back; no colour glyphs).
Result<ColourAssembler> read_colour_glyphs(std::span<const std::byte> font_bytes, const FontInfo& info,
                                           uint32_t glyph_count, const BakeOptions& options,
                                           const std::vector<uint8_t>& wanted, FontAsset& asset, BakeReport& report);

}  // namespace crisp
