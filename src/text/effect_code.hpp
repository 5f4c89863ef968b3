// Private: the effect layers' outlines as GlyphKey::effect codes them (docs/effects.md, "Keys"),
// and the derived glyph each code makes of a glyph.
#pragma once

#include "text/stroke.hpp"

#include <crisp/asset.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>

#include <cstdint>

namespace crisp {

// What an effect layer's outline is: (S(half_width) op G), S with `join` at its corners.
struct EffectShape {
    StrokeOp op = StrokeOp::a;
    StrokeJoin join = StrokeJoin::round;
    double half_width = 0.0;   // em
    double miter_limit = 1.0;  // miter joins
};

// GlyphKey::effect: bits 0-19 the half-width in kEffectWidthUnit, bits 20-22 the op plus one (0:
// no effect), bits 23-24 the join, bits 25-31 the miter limit as round(16 log2(limit)) (miter
// joins only; 0 otherwise).
inline constexpr double kEffectWidthUnit = 1.0 / 262144.0;  // em: 2^-18
inline constexpr uint32_t kEffectWidthCodes = 1u << 20;
// The stroke pieces' tolerance is a quarter of 1/256 px at the top of the key's size octave: a
// derived glyph is made per (font, glyph, effect, octave).
uint32_t effect_octave(const GlyphKey& key);
double effect_tolerance(uint32_t octave);

// The code of `shape`, its half-width and miter limit rounded to the code's steps (a half-width
// of kEffectWidthCodes units or more is refused by the caller: validate_text_effects()).
uint32_t encode_effect(const EffectShape& shape);
// The shape a nonzero code names, as rounded.
EffectShape decode_effect(uint32_t code);

// The derived glyph of `glyph` for effect `code` (not 0): its stroke pieces (stroke_pieces) as
// set A at `tolerance` em, the glyph as set B (pack_derived_glyph). Errors as theirs.
Result<DerivedGlyph> derive_effect_glyph(const FontAsset& asset, const GlyphRecord& glyph, uint32_t code,
                                         double tolerance);

// The derived glyph of colour glyph `colour`'s silhouette (the union of its layers' outlines,
// union_boundary) for effect `code` (its op and stroke as for a glyph; half-width 0 with op
// a_or_b: the silhouette itself), with the advance and flags of the face glyph it colours.
// Errors (ErrorCode::invalid_argument): a bitmap glyph (a layer painted with an image), layers of
// more than limits::kMaxSilhouetteCurves curves, or stroke_pieces()' and pack_derived_glyph()'s.
// Expects a valid asset (load_asset or validate_asset passed it).
Result<DerivedGlyph> derive_silhouette_glyph(const FontAsset& asset, const ColourGlyph& colour, uint32_t code,
                                             double tolerance);

}  // namespace crisp
