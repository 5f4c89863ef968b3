// crisp: a font ready for shaping: a FontAsset together with the HarfBuzz objects that shape from
// the font bytes inside it.
//
// A Font owns its asset. HarfBuzz reads the original font bytes the asset carries, so shaping
// (kerning, ligatures, mark positioning, joining) needs nothing but the asset. Positions come out
// of HarfBuzz in font units and are converted to em. A Font only ever produces glyphs the asset
// has baked: to HarfBuzz a code point whose glyph is not baked (a subset asset, a glyph that
// failed) is a code point the font lacks, so fallback and .notdef behave as for a missing glyph.
//
// A Font is immutable after creation; one Font may be used by several threads at once (HarfBuzz
// fonts are thread-safe for shaping), each with its own Layouter.
#pragma once

#include <crisp/export.hpp>

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <memory>

// HarfBuzz's font type, for callers who shape with HarfBuzz themselves (see harfbuzz_font()).
struct hb_font_t;

namespace crisp {

class CRISP_API Font {
public:
    // Takes ownership of `asset` and opens its font bytes with HarfBuzz at the face index and
    // variation-axis values the asset was baked with. `id` is the FontId that every GlyphKey of
    // this font carries; the caller chooses it and keeps it unique among the fonts one atlas sees.
    // Errors: ErrorCode::asset_invalid when the asset fails validate_asset() (the message names the
    // fault), when HarfBuzz cannot open the face, or when the face disagrees with the asset's
    // glyph count (its face glyphs, synthetic ones excluded) or units per em. Safe to use with
    // untrusted assets.
    static Result<Font> create(FontAsset asset, FontId id);

    Font(Font&& other) noexcept;
    Font& operator=(Font&& other) noexcept;
    Font(const Font&) = delete;
    Font& operator=(const Font&) = delete;
    ~Font();
    // A moved-from Font may only be destroyed or assigned to; every other call asserts.

    const FontAsset& asset() const;
    FontId id() const;
    uint32_t units_per_em() const;
    float ascender() const;   // em, positive above the baseline
    float descender() const;  // em, negative below the baseline
    float line_gap() const;   // em
    // Baseline-to-baseline distance in em: ascender - descender + line_gap.
    float line_height() const;

    // True when the font's cmap maps `codepoint` to a glyph and that glyph is baked in the asset
    // (kGlyphBaked set, kGlyphFailed clear). Any value is accepted; values past U+10FFFF and
    // surrogates return false.
    bool has_glyph_for(uint32_t codepoint) const;
    // The glyph has_glyph_for() found, or 0 (.notdef) when it returns false.
    uint32_t nominal_glyph(uint32_t codepoint) const;
    // True when has_glyph_for(codepoint) and the asset has a colour glyph (FontAsset::colour_glyph)
    // for that nominal glyph: layout draws it in colour. Any value is accepted, as above.
    bool has_colour_glyph_for(uint32_t codepoint) const;
    // The record of glyph index `glyph`, or nullptr when the index is past the font's glyphs.
    const GlyphRecord* glyph_record(uint32_t glyph) const;
    // True when `glyph` is a glyph of the font that the asset baked and did not fail.
    bool is_baked(uint32_t glyph) const;

    // The HarfBuzz font crisp shapes with: scaled to font units (x and y scale = units per em),
    // with the asset's variation coordinates, reporting unbaked glyphs as absent. Owned by the
    // Font and valid while it lives; callers may shape with it but must not modify it.
    hb_font_t* harfbuzz_font() const;

private:
    struct State;
    explicit Font(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

}  // namespace crisp
