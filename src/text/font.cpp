// crisp::Font: a FontAsset with the HarfBuzz blob, face and font that shape from its font bytes.
#include <crisp/font.hpp>

#include <hb-ot.h>
#include <hb.h>

#include <string>
#include <utility>
#include <vector>

namespace crisp {

namespace {

bool is_baked_glyph(const FontAsset& asset, hb_codepoint_t glyph) {
    if (glyph >= asset.glyphs.size()) return false;
    const uint32_t flags = asset.glyphs[glyph].flags;
    return (flags & kGlyphBaked) != 0 && (flags & kGlyphFailed) == 0;
}

// The font functions of the font crisp shapes with. HarfBuzz asks them which glyph a code point
// maps to; answering "none" for glyphs the asset did not bake makes a subset asset behave like a
// font that lacks those characters, so HarfBuzz's own decisions (composing e + U+0301 into é or
// not, inserting a dotted circle, falling back to .notdef) only ever pick glyphs crisp can draw.
// Everything else (advances, extents, GSUB/GPOS) comes unchanged from the parent font.
hb_bool_t get_nominal_glyph(hb_font_t* font, void* font_data, hb_codepoint_t unicode, hb_codepoint_t* glyph, void*) {
    if (unicode > 0x10FFFF || (unicode >= 0xD800 && unicode <= 0xDFFF)) return false;
    hb_codepoint_t found = 0;
    if (!hb_font_get_nominal_glyph(hb_font_get_parent(font), unicode, &found)) return false;
    if (!is_baked_glyph(*static_cast<const FontAsset*>(font_data), found)) return false;
    *glyph = found;
    return true;
}

unsigned get_nominal_glyphs(hb_font_t* font, void* font_data, unsigned count, const hb_codepoint_t* first_unicode,
                            unsigned unicode_stride, hb_codepoint_t* first_glyph, unsigned glyph_stride, void*) {
    // Same contract as HarfBuzz's: the number of leading code points mapped, stopping at the first
    // that is not. Strides are in bytes.
    const unsigned done = hb_font_get_nominal_glyphs(hb_font_get_parent(font), count, first_unicode, unicode_stride,
                                                     first_glyph, glyph_stride);
    const auto& asset = *static_cast<const FontAsset*>(font_data);
    auto* glyph_bytes = reinterpret_cast<unsigned char*>(first_glyph);
    for (unsigned i = 0; i < done; ++i) {
        const auto* glyph = reinterpret_cast<const hb_codepoint_t*>(glyph_bytes + size_t{i} * glyph_stride);
        if (!is_baked_glyph(asset, *glyph)) return i;
    }
    return done;
}

hb_bool_t get_variation_glyph(hb_font_t* font, void* font_data, hb_codepoint_t unicode, hb_codepoint_t selector,
                              hb_codepoint_t* glyph, void*) {
    hb_codepoint_t found = 0;
    if (!hb_font_get_variation_glyph(hb_font_get_parent(font), unicode, selector, &found)) return false;
    if (!is_baked_glyph(*static_cast<const FontAsset*>(font_data), found)) return false;
    *glyph = found;
    return true;
}

Error invalid(std::string message) {
    return Error{ErrorCode::asset_invalid, std::move(message)};
}

}  // namespace

struct CRISP_HIDDEN Font::State {
    // The asset lives here, behind a pointer, and never moves again: the blob reads its font bytes
    // in place and the font functions hold its address.
    FontAsset asset;
    FontId id = 0;
    hb_blob_t* blob = nullptr;
    hb_face_t* face = nullptr;
    hb_font_t* parent = nullptr;  // HarfBuzz's OpenType font functions
    hb_font_funcs_t* funcs = nullptr;
    hb_font_t* font = nullptr;  // child of `parent` with crisp's glyph look-up

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;
    ~State() {
        // Children before parents; the destroy functions accept null.
        hb_font_destroy(font);
        hb_font_funcs_destroy(funcs);
        hb_font_destroy(parent);
        hb_face_destroy(face);
        hb_blob_destroy(blob);
    }
};

Result<Font> Font::create(FontAsset asset, FontId id) {
    if (Status status = validate_asset(asset); !status) return status.error();

    auto state = std::make_unique<State>();
    state->asset = std::move(asset);
    state->id = id;
    const FontAsset& owned = state->asset;

    // validate_asset checked that the bytes fit HarfBuzz's unsigned length and hold the face.
    state->blob =
        hb_blob_create(reinterpret_cast<const char*>(owned.font_bytes.data()),
                       static_cast<unsigned>(owned.font_bytes.size()), HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    if (owned.info.face_index >= hb_face_count(state->blob))
        return invalid("font: HarfBuzz finds no face " + std::to_string(owned.info.face_index) + " in the font bytes");
    state->face = hb_face_create(state->blob, owned.info.face_index);
    const unsigned glyph_count = hb_face_get_glyph_count(state->face);
    if (glyph_count == 0 || glyph_count != owned.face_glyph_count())
        return invalid("font: HarfBuzz reads " + std::to_string(glyph_count) + " glyphs, the asset has " +
                       std::to_string(owned.face_glyph_count()));
    const unsigned upem = hb_face_get_upem(state->face);
    if (upem != owned.info.units_per_em)
        return invalid("font: HarfBuzz reads " + std::to_string(upem) + " units per em, the asset says " +
                       std::to_string(owned.info.units_per_em));

    state->parent = hb_font_create(state->face);
    // One unit of scale per font unit: HarfBuzz positions come out in font units, which the
    // layout divides by units_per_em. (validate_asset bounds units_per_em far below INT_MAX.)
    const int scale = static_cast<int>(upem);
    hb_font_set_scale(state->parent, scale, scale);
    if (!owned.info.axes.empty()) {
        // Shape the instance the asset baked, or advances and GPOS would not match the outlines.
        std::vector<hb_variation_t> variations;
        for (const AxisValue& axis : owned.info.axes) variations.push_back({axis.tag, axis.value});
        hb_font_set_variations(state->parent, variations.data(), static_cast<unsigned>(variations.size()));
    }
    hb_font_make_immutable(state->parent);

    state->funcs = hb_font_funcs_create();
    hb_font_funcs_set_nominal_glyph_func(state->funcs, get_nominal_glyph, nullptr, nullptr);
    hb_font_funcs_set_nominal_glyphs_func(state->funcs, get_nominal_glyphs, nullptr, nullptr);
    hb_font_funcs_set_variation_glyph_func(state->funcs, get_variation_glyph, nullptr, nullptr);
    hb_font_funcs_make_immutable(state->funcs);

    // The sub-font inherits scale and variation coordinates from its parent.
    state->font = hb_font_create_sub_font(state->parent);
    hb_font_set_funcs(state->font, state->funcs, const_cast<FontAsset*>(&owned), nullptr);
    hb_font_make_immutable(state->font);
    return Font(std::move(state));
}

Font::Font(std::unique_ptr<State> state) : state_(std::move(state)) {}
Font::Font(Font&& other) noexcept = default;
Font& Font::operator=(Font&& other) noexcept = default;
Font::~Font() = default;

const FontAsset& Font::asset() const {
    assert(state_);
    return state_->asset;
}

FontId Font::id() const {
    assert(state_);
    return state_->id;
}

uint32_t Font::units_per_em() const {
    return asset().info.units_per_em;
}

float Font::ascender() const {
    return static_cast<float>(asset().info.ascender) / static_cast<float>(units_per_em());
}

float Font::descender() const {
    return static_cast<float>(asset().info.descender) / static_cast<float>(units_per_em());
}

float Font::line_gap() const {
    return static_cast<float>(asset().info.line_gap) / static_cast<float>(units_per_em());
}

float Font::line_height() const {
    return ascender() - descender() + line_gap();
}

bool Font::has_glyph_for(uint32_t codepoint) const {
    hb_codepoint_t glyph = 0;
    return hb_font_get_nominal_glyph(harfbuzz_font(), codepoint, &glyph) != 0;
}

uint32_t Font::nominal_glyph(uint32_t codepoint) const {
    hb_codepoint_t glyph = 0;
    return hb_font_get_nominal_glyph(harfbuzz_font(), codepoint, &glyph) ? glyph : 0;
}

bool Font::has_colour_glyph_for(uint32_t codepoint) const {
    hb_codepoint_t glyph = 0;
    return hb_font_get_nominal_glyph(harfbuzz_font(), codepoint, &glyph) && asset().colour_glyph(glyph) != nullptr;
}

const GlyphRecord* Font::glyph_record(uint32_t glyph) const {
    const std::vector<GlyphRecord>& glyphs = asset().glyphs;
    return glyph < glyphs.size() ? &glyphs[glyph] : nullptr;
}

bool Font::is_baked(uint32_t glyph) const {
    return is_baked_glyph(asset(), glyph);
}

hb_font_t* Font::harfbuzz_font() const {
    assert(state_);
    return state_->font;
}

}  // namespace crisp
