// Text effects' parameters (include/crisp/effects.hpp) and the outlines their layers draw.
#include "core/limits.hpp"
#include "text/effect_code.hpp"

#include <crisp/effects.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

namespace crisp {

namespace {

std::string number(float v) {
    std::ostringstream out;
    out << v;
    return out.str();
}

Status refused(const std::string& what) {
    return Error{ErrorCode::invalid_argument, "effects: " + what};
}

// A width in pixels: finite, not negative, at most kMaxEffectWidth.
Status check_width(const char* name, float v) {
    if (!std::isfinite(v)) return refused(std::string(name) + " " + number(v) + " is not finite");
    if (v < 0.0f) return refused(std::string(name) + " " + number(v) + " is negative");
    if (v > kMaxEffectWidth) {
        return refused(std::string(name) + " " + number(v) + " is past " + number(kMaxEffectWidth) + " px");
    }
    return {};
}

Status check_color(const char* name, const std::array<float, 4>& color) {
    for (float c : color) {
        if (!std::isfinite(c) || c < 0.0f || c > 1.0f) {
            return refused(std::string(name) + " color component " + number(c) + " is not in [0, 1]");
        }
    }
    return {};
}

}  // namespace

namespace {

constexpr OutlinePlacement kPlacements[] = {OutlinePlacement::outside, OutlinePlacement::inside,
                                            OutlinePlacement::centred};
constexpr LineJoin kJoins[] = {LineJoin::round, LineJoin::miter, LineJoin::bevel};

template <typename Enum, size_t N>
std::optional<Enum> parse_name(std::string_view name, const Enum (&values)[N], const char* (*name_of)(Enum)) {
    for (Enum v : values) {
        if (name == name_of(v)) return v;
    }
    return std::nullopt;
}

}  // namespace

const char* outline_placement_name(OutlinePlacement placement) {
    switch (placement) {
        case OutlinePlacement::outside:
            return "outside";
        case OutlinePlacement::inside:
            return "inside";
        case OutlinePlacement::centred:
            return "centred";
    }
    return "unknown";
}

const char* line_join_name(LineJoin join) {
    switch (join) {
        case LineJoin::round:
            return "round";
        case LineJoin::miter:
            return "miter";
        case LineJoin::bevel:
            return "bevel";
    }
    return "unknown";
}

std::optional<OutlinePlacement> parse_outline_placement(std::string_view name) {
    return parse_name(name, kPlacements, outline_placement_name);
}

std::optional<LineJoin> parse_line_join(std::string_view name) {
    return parse_name(name, kJoins, line_join_name);
}

Status validate_text_effects(const TextEffects& effects) {
    if (!std::isfinite(effects.weight)) return refused("weight " + number(effects.weight) + " is not finite");
    if (std::abs(effects.weight) > kMaxEffectWidth) {
        return refused("weight " + number(effects.weight) + " is past +-" + number(kMaxEffectWidth) + " px");
    }
    if (const auto& o = effects.outline) {
        if (Status s = check_width("outline width", o->width); !s) return s;
        if (static_cast<uint8_t>(o->placement) > static_cast<uint8_t>(OutlinePlacement::centred)) {
            return refused("outline placement " + std::to_string(static_cast<int>(o->placement)) + " is unknown");
        }
        if (static_cast<uint8_t>(o->join) > static_cast<uint8_t>(LineJoin::bevel)) {
            return refused("outline join " + std::to_string(static_cast<int>(o->join)) + " is unknown");
        }
        if (!(o->miter_limit >= 1.0f && o->miter_limit <= kMaxMiterLimit)) {
            return refused("outline miter_limit " + number(o->miter_limit) + " is not in [1, " +
                           number(kMaxMiterLimit) + "]");
        }
        if (Status s = check_color("outline", o->color); !s) return s;
    }
    if (const auto& sh = effects.shadow) {
        for (float v : {sh->offset_x, sh->offset_y}) {
            if (!std::isfinite(v) || std::abs(v) > kMaxShadowOffset) {
                return refused("shadow offset " + number(v) + " is not finite or past +-" + number(kMaxShadowOffset) +
                               " px");
            }
        }
        if (!(sh->blur >= 0.0f && sh->blur <= kMaxEffectBlur)) {
            return refused("shadow blur " + number(sh->blur) + " is not in [0, " + number(kMaxEffectBlur) + "] px");
        }
        if (Status s = check_color("shadow", sh->color); !s) return s;
    }
    if (const auto& g = effects.glow) {
        if (!(g->radius > 0.0f && g->radius <= kMaxEffectBlur)) {
            return refused("glow radius " + number(g->radius) + " is not in (0, " + number(kMaxEffectBlur) + "] px");
        }
        if (Status s = check_color("glow", g->color); !s) return s;
    }
    return {};
}

Status validate_text_effects(const TextEffects& effects, float size) {
    if (Status s = validate_text_effects(effects); !s) return s;
    if (!(size > 0.0f) || !std::isfinite(size)) return refused("size " + number(size) + " is not positive and finite");
    const float weight = std::abs(effects.weight);
    if (weight / size > kMaxEffectReachEm) {
        return refused("weight " + number(effects.weight) + " px reaches past " + number(kMaxEffectReachEm) +
                       " em at " + number(size) + " px per em");
    }
    if (const auto& o = effects.outline) {
        const float reach =
            (o->placement == OutlinePlacement::centred ? o->width / 2.0f : o->width) + std::max(effects.weight, 0.0f);
        if (reach / size > kMaxEffectReachEm) {
            return refused("outline width " + number(o->width) + " px reaches past " + number(kMaxEffectReachEm) +
                           " em at " + number(size) + " px per em");
        }
    }
    return {};
}

// The widest reach rounds to the last code (one unit short of 4 em).
static_assert(static_cast<double>(kMaxEffectReachEm) <= limits::kMaxStrokeHalfWidthEm);
static_assert(static_cast<double>(kMaxEffectReachEm) / kEffectWidthUnit <= kEffectWidthCodes);

uint32_t encode_effect(const EffectShape& shape) {
    const double units = std::round(shape.half_width / kEffectWidthUnit);
    const auto width = static_cast<uint32_t>(std::clamp(units, 0.0, static_cast<double>(kEffectWidthCodes - 1)));
    uint32_t miter = 0;
    if (shape.join == StrokeJoin::miter) {
        miter = static_cast<uint32_t>(
            std::clamp(std::round(16.0 * std::log2(std::max(shape.miter_limit, 1.0))), 0.0, 127.0));
    }
    return width | ((static_cast<uint32_t>(shape.op) + 1u) << 20) | (static_cast<uint32_t>(shape.join) << 23) |
           (miter << 25);
}

EffectShape decode_effect(uint32_t code) {
    EffectShape shape;
    shape.half_width = static_cast<double>(code & (kEffectWidthCodes - 1)) * kEffectWidthUnit;
    shape.op = static_cast<StrokeOp>(((code >> 20) & 7u) - 1u);
    shape.join = static_cast<StrokeJoin>((code >> 23) & 3u);
    shape.miter_limit = std::exp2(static_cast<double>(code >> 25) / 16.0);
    return shape;
}

uint32_t effect_octave(const GlyphKey& key) {
    const double pixels = static_cast<double>(std::max(key.size_x, key.size_y)) / kSizeOne;
    return pixels <= 1.0 ? 0u : static_cast<uint32_t>(std::min(std::ceil(std::log2(pixels)), 24.0));
}

double effect_tolerance(uint32_t octave) {
    return 1.0 / (1024.0 * std::exp2(static_cast<double>(octave)));
}

Result<DerivedGlyph> derive_effect_glyph(const FontAsset& asset, const GlyphRecord& glyph, uint32_t code,
                                         double tolerance) {
    const EffectShape shape = decode_effect(code);
    std::vector<Contour> pieces;
    if (shape.half_width > 0.0) {
        const StrokeStyle style{shape.half_width, shape.join, shape.miter_limit, tolerance};
        // The stroke follows the fill's boundary: a glyph drawn with overlapping contours (variable
        // fonts often are) would otherwise be outlined along the edges inside it.
        if (Status s = stroke_pieces(boundary_contours(glyph_contours(asset, glyph)), style, pieces); !s) {
            return s.error();
        }
    }
    return pack_derived_glyph(pieces, asset, glyph);
}

Result<DerivedGlyph> derive_silhouette_glyph(const FontAsset& asset, const ColourGlyph& colour, uint32_t code,
                                             double tolerance) {
    std::vector<std::vector<Contour>> fills;
    uint64_t curves = 0;
    for (uint32_t i = 0; i < colour.layer_count; ++i) {
        const ColourLayer& layer = asset.layers[size_t{colour.first_layer} + i];
        if (asset.paints[layer.paint].kind == PaintKind::image) {
            return Error{ErrorCode::invalid_argument, "derived glyph: colour glyph " + std::to_string(colour.glyph) +
                                                          " is a bitmap, without an outline to draw effects of"};
        }
        const GlyphRecord& outline = asset.glyphs[layer.glyph];
        if (outline.curve_count == 0) continue;
        curves += outline.curve_count;
        if (curves > limits::kMaxSilhouetteCurves) {
            return Error{ErrorCode::invalid_argument,
                         "derived glyph: colour glyph " + std::to_string(colour.glyph) + "'s layers have more than " +
                             std::to_string(limits::kMaxSilhouetteCurves) + " curves (limits::kMaxSilhouetteCurves)"};
        }
        fills.push_back(glyph_contours(asset, outline));
    }
    const std::vector<Contour> silhouette = union_boundary(fills);
    const EffectShape shape = decode_effect(code);
    std::vector<Contour> pieces;
    if (shape.half_width > 0.0) {
        const StrokeStyle style{shape.half_width, shape.join, shape.miter_limit, tolerance};
        if (Status s = stroke_pieces(silhouette, style, pieces); !s) return s.error();
    }
    return pack_derived_glyph(pieces, silhouette, asset.glyphs[colour.glyph]);
}

}  // namespace crisp
