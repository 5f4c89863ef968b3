// crisp: the rules every decoded or baked asset keeps (validate_asset), which the loader checks
// after decoding and the baker before it writes (docs/asset-format.md).
#include "asset/asset_format.hpp"
#include "core/limits.hpp"

#include <crisp/asset.hpp>

#include <hb.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <string_view>

namespace crisp {

using namespace asset_format;

namespace {

// ---------------------------------------------------------------------------------------------
// Validation

bool is_valid_utf8(std::string_view text) {
    size_t i = 0;
    while (i < text.size()) {
        uint32_t lead = static_cast<unsigned char>(text[i]);
        if (lead < 0x80) {
            ++i;
            continue;
        }
        size_t length = 0;
        uint32_t code_point = 0;
        uint32_t smallest = 0;  // below it the encoding is overlong
        if ((lead & 0xE0u) == 0xC0u) {
            length = 2, code_point = lead & 0x1Fu, smallest = 0x80;
        } else if ((lead & 0xF0u) == 0xE0u) {
            length = 3, code_point = lead & 0x0Fu, smallest = 0x800;
        } else if ((lead & 0xF8u) == 0xF0u) {
            length = 4, code_point = lead & 0x07u, smallest = 0x10000;
        } else {
            return false;
        }
        if (text.size() - i < length) return false;
        for (size_t k = 1; k < length; ++k) {
            uint32_t next = static_cast<unsigned char>(text[i + k]);
            if ((next & 0xC0u) != 0x80u) return false;
            code_point = (code_point << 6) | (next & 0x3Fu);
        }
        if (code_point < smallest || code_point > 0x10FFFF || (code_point >= 0xD800 && code_point <= 0xDFFF))
            return false;
        i += length;
    }
    return true;
}

Status check_name(const char* what, const std::string& name) {
    if (name.size() > kMaxNameBytes)
        return invalid("asset: {} name is {} bytes, at most {}", what, name.size(), kMaxNameBytes);
    if (name.find('\0') != std::string::npos) return invalid("asset: {} name holds a NUL byte", what);
    if (!is_valid_utf8(name)) return invalid("asset: {} name is not valid UTF-8", what);
    return {};
}

Status check_info(const FontInfo& info) {
    if (info.units_per_em < kMinUnitsPerEm || info.units_per_em > kMaxUnitsPerEm)
        return invalid("asset: units_per_em {} outside {}..{}", info.units_per_em, kMinUnitsPerEm, kMaxUnitsPerEm);
    if ((info.flags & ~kKnownFontFlags) != 0) return invalid("asset: font flags {} hold unknown bits", Hex{info.flags});
    if (!std::isfinite(info.tolerance_em) || !(info.tolerance_em > 0.0f))
        return invalid("asset: tolerance_em {} is not finite and positive", info.tolerance_em);
    if (!std::isfinite(info.max_deviation_em) || !(info.max_deviation_em >= 0.0f))
        return invalid("asset: max_deviation_em {} is not finite and non-negative", info.max_deviation_em);
    if (((info.flags & kFontVariable) != 0) != !info.axes.empty())
        return invalid("asset: the variable flag is {} but {} axes are stored",
                       (info.flags & kFontVariable) ? "set" : "clear", info.axes.size());
    if (info.axes.size() > kMaxAxes) return invalid("asset: {} axes, at most {}", info.axes.size(), kMaxAxes);
    for (size_t i = 0; i < info.axes.size(); ++i) {
        const AxisValue& axis = info.axes[i];
        // An OpenType tag is stored as its big-endian value ('wght' = 0x77676874); show it as text.
        Tag tag{{static_cast<char>(axis.tag >> 24), static_cast<char>(axis.tag >> 16), static_cast<char>(axis.tag >> 8),
                 static_cast<char>(axis.tag)}};
        if (!std::isfinite(axis.value) || !std::isfinite(axis.minimum) || !std::isfinite(axis.default_value) ||
            !std::isfinite(axis.maximum))
            return invalid("asset: axis {} {}: value {}, range [{}, {}, {}] is not finite", i, tag, axis.value,
                           axis.minimum, axis.default_value, axis.maximum);
        if (!(axis.minimum <= axis.default_value && axis.default_value <= axis.maximum))
            return invalid("asset: axis {} {}: minimum {}, default {}, maximum {} out of order", i, tag, axis.minimum,
                           axis.default_value, axis.maximum);
        if (!(axis.minimum <= axis.value && axis.value <= axis.maximum))
            return invalid("asset: axis {} {}: value {} outside [{}, {}]", i, tag, axis.value, axis.minimum,
                           axis.maximum);
    }
    if (Status status = check_name("family", info.family); !status) return status;
    if (Status status = check_name("style", info.style); !status) return status;
    return {};
}

bool is_in_coordinate_range(float value) {
    return value >= -kMaxCoordinateEm && value <= kMaxCoordinateEm;
}

Status check_glyph(const FontAsset& asset, size_t index) {
    const GlyphRecord& glyph = asset.glyphs[index];

    if ((glyph.flags & ~kKnownGlyphFlags) != 0)
        return invalid("asset: glyph {}: flags {} hold unknown bits", index, Hex{glyph.flags});

    const std::pair<const char*, float> fields[] = {
        {"advance", glyph.advance},       {"bearing_x", glyph.bearing_x},   {"bearing_y", glyph.bearing_y},
        {"bbox_min_x", glyph.bbox_min_x}, {"bbox_min_y", glyph.bbox_min_y}, {"bbox_max_x", glyph.bbox_max_x},
        {"bbox_max_y", glyph.bbox_max_y},
    };
    for (const auto& [name, value] : fields) {
        if (!std::isfinite(value)) return invalid("asset: glyph {}: {} {} is not finite", index, name, value);
        if (!is_in_coordinate_range(value))
            return invalid("asset: glyph {}: {} {} outside [-64, 64] em", index, name, value);
    }

    if ((glyph.flags & kGlyphFailed) != 0 && ((glyph.flags & kGlyphBaked) == 0 || glyph.curve_count != 0))
        return invalid("asset: glyph {}: a failed glyph must be baked empty (flags {}, {} curves)", index,
                       Hex{glyph.flags}, glyph.curve_count);

    if (glyph.curve_count == 0) {
        if (glyph.band_count != 0 || glyph.band_words != 0)
            return invalid("asset: glyph {}: no curves but {} bands of {} words", index, glyph.band_count,
                           glyph.band_words);
        return {};
    }

    if ((glyph.flags & kGlyphBaked) == 0)
        return invalid("asset: glyph {}: {} curves but the glyph is not baked", index, glyph.curve_count);
    if (glyph.curve_count > kMaxCurveSlotsPerGlyph)
        return invalid("asset: glyph {}: {} curve slots, at most {} (docs/limits.md)", index, glyph.curve_count,
                       kMaxCurveSlotsPerGlyph);
    if (glyph.bbox_min_x > glyph.bbox_max_x || glyph.bbox_min_y > glyph.bbox_max_y)
        return invalid("asset: glyph {}: bbox [{}, {}] x [{}, {}] is inverted", index, glyph.bbox_min_x,
                       glyph.bbox_max_x, glyph.bbox_min_y, glyph.bbox_max_y);
    if (glyph.band_count < 1 || glyph.band_count > kMaxBandsPerGlyph)
        return invalid("asset: glyph {}: band count {} outside 1..{}", index, glyph.band_count, kMaxBandsPerGlyph);
    uint64_t expected_words = (uint64_t{glyph.curve_count} + 31) / 32;
    if (glyph.band_words != expected_words)
        return invalid("asset: glyph {}: band_words {} for {} curves, expected {}", index, glyph.band_words,
                       glyph.curve_count, expected_words);

    uint64_t point_begin = glyph.point_offset;
    uint64_t point_end = point_begin + 2 * uint64_t{glyph.curve_count} + 1;
    if (point_end > asset.points.size())
        return invalid("asset: glyph {}: point range [{}, {}) past the {} points", index, point_begin, point_end,
                       asset.points.size());
    uint64_t word_begin = glyph.band_offset;
    uint64_t word_end = word_begin + uint64_t{glyph.band_count} * glyph.band_words;
    if (word_end > asset.band_words.size())
        return invalid("asset: glyph {}: band range [{}, {}) past the {} band words", index, word_begin, word_end,
                       asset.band_words.size());

    // Exact comparisons: the baker computes the bbox from these very floats, and the rasterizers
    // rely on every curve lying inside it.
    for (uint64_t i = point_begin; i < point_end; ++i) {
        Point point = asset.points[i];
        if (point.x < glyph.bbox_min_x || point.x > glyph.bbox_max_x || point.y < glyph.bbox_min_y ||
            point.y > glyph.bbox_max_y)
            return invalid("asset: glyph {}: point {} ({}, {}) outside its bbox [{}, {}] x [{}, {}]", index,
                           i - point_begin, point.x, point.y, glyph.bbox_min_x, glyph.bbox_max_x, glyph.bbox_min_y,
                           glyph.bbox_max_y);
    }

    // A set bit past the last curve would send a rasterizer to points of the next glyph.
    uint32_t used_bits = glyph.curve_count % 32;
    if (used_bits != 0) {
        uint32_t stray_mask = ~((1u << used_bits) - 1u);
        for (uint32_t band = 0; band < glyph.band_count; ++band) {
            uint64_t last_word = word_begin + uint64_t{band} * glyph.band_words + glyph.band_words - 1;
            uint32_t stray = asset.band_words[last_word] & stray_mask;
            if (stray != 0)
                return invalid("asset: glyph {}: band {}: bit {} set past its {} curves", index, band,
                               uint64_t{glyph.band_words - 1u} * 32 + static_cast<uint32_t>(std::countr_zero(stray)),
                               glyph.curve_count);
        }
    }
    return {};
}

Status check_font_bytes(const FontAsset& asset) {
    const std::vector<std::byte>& font = asset.font_bytes;
    if (font.size() < kMinFontBytes)
        return invalid("asset: font bytes are {} bytes, at least {} needed", font.size(), kMinFontBytes);
    if (font.size() > UINT_MAX) return invalid("asset: font bytes are {} bytes, more than HarfBuzz reads", font.size());

    // Read-only and uncopied: the blob only lives for this check.
    hb_blob_t* blob = hb_blob_create(reinterpret_cast<const char*>(font.data()), static_cast<unsigned>(font.size()),
                                     HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    unsigned face_count = hb_face_count(blob);
    Status status;
    if (asset.info.face_index >= face_count) {
        status = invalid("asset: font bytes hold {} faces, face_index is {}", face_count, asset.info.face_index);
    } else {
        hb_face_t* face = hb_face_create(blob, asset.info.face_index);
        unsigned glyph_count = hb_face_get_glyph_count(face);
        if (glyph_count != asset.face_glyph_count())
            status = invalid("asset: font bytes hold {} glyphs in face {}, records say {}", glyph_count,
                             asset.info.face_index, asset.face_glyph_count());
        hb_face_destroy(face);
    }
    hb_blob_destroy(blob);
    return status;
}
}  // namespace

Status validate_asset(const FontAsset& asset) {
    if (Status status = check_info(asset.info); !status) return status;
    if (asset.glyphs.empty() || asset.glyphs.size() > kMaxGlyphRecords)
        return invalid("asset: glyph count {} outside 1..{}", asset.glyphs.size(), kMaxGlyphRecords);
    if (asset.face_glyph_count() > kMaxGlyphs)
        return invalid("asset: glyph count {} of the face outside 1..{}", asset.face_glyph_count(), kMaxGlyphs);

    // Every point, referenced or not: a reader may upload PNTS as a whole.
    for (size_t i = 0; i < asset.points.size(); ++i) {
        Point point = asset.points[i];
        if (!std::isfinite(point.x) || !std::isfinite(point.y))
            return invalid("asset: point {} ({}, {}) is not finite", i, point.x, point.y);
        if (!is_in_coordinate_range(point.x) || !is_in_coordinate_range(point.y))
            return invalid("asset: point {} ({}, {}) outside [-64, 64] em", i, point.x, point.y);
    }

    // Glyph ranges come in glyph order and never overlap, as the baker writes them. Besides
    // catching corruption this bounds validation by the size of the asset: with shared ranges a
    // hostile file could make every glyph re-check the same million points.
    uint64_t points_end = 0, words_end = 0;
    for (size_t i = 0; i < asset.glyphs.size(); ++i) {
        if (Status status = check_glyph(asset, i); !status) return status;
        const GlyphRecord& glyph = asset.glyphs[i];
        if (glyph.curve_count == 0) continue;
        if (glyph.point_offset < points_end)
            return invalid(
                "asset: glyph {}: point range starts at {}, inside the range of an earlier glyph (ends at {})", i,
                glyph.point_offset, points_end);
        if (glyph.band_offset < words_end)
            return invalid(
                "asset: glyph {}: band range starts at {}, inside the range of an earlier glyph (ends at {})", i,
                glyph.band_offset, words_end);
        points_end = uint64_t{glyph.point_offset} + 2 * uint64_t{glyph.curve_count} + 1;
        words_end = uint64_t{glyph.band_offset} + uint64_t{glyph.band_count} * glyph.band_words;
    }

    if (Status status = check_colour(asset); !status) return status;
    return check_font_bytes(asset);
}

}  // namespace crisp
