// crisp: reading, validating and writing .crisp assets (docs/asset-format.md).
//
// The loader treats its input as hostile: it checks the size, magic, version, declared size and
// checksum before it looks at anything else, checks every section range before it reads one, and
// reads every field with memcpy so no access is unaligned or out of bounds. Decoding only checks
// what the in-memory FontAsset cannot express (section sizes, counts, reserved fields); every rule
// about the decoded values lives in validate_asset, which the baker also runs before it writes.
#include "asset/crc32c.hpp"
#include "core/file_io.hpp"
#include "core/limits.hpp"

#include <crisp/asset.hpp>

#include <hb.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <type_traits>

namespace crisp {

namespace {

static_assert(std::endian::native == std::endian::little,
              "crisp supports little-endian hosts only: the asset is stored little-endian and read with memcpy");
static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "floats are stored as IEEE 754 binary32");
static_assert(sizeof(Point) == 8 && std::is_trivially_copyable_v<Point>, "PNTS is copied as a block of Points");
static_assert(sizeof(GlyphRecord) == 48, "a GLYF record mirrors GlyphRecord field for field");

// Header.
constexpr char kMagic[8] = {'C', 'R', 'I', 'S', 'P', 'F', 'N', 'T'};
constexpr size_t kHeaderSize = 32;
constexpr size_t kVersionOffset = 8;
constexpr size_t kSectionCountOffset = 12;
constexpr size_t kFileSizeOffset = 16;
constexpr size_t kChecksumOffset = 24;
constexpr size_t kReservedOffset = 28;

// Section table.
constexpr size_t kSectionTableOffset = kHeaderSize;
constexpr size_t kSectionEntrySize = 24;
constexpr size_t kSectionCount = 5;
constexpr size_t kSectionTableEnd = kSectionTableOffset + kSectionCount * kSectionEntrySize;
constexpr uint64_t kSectionAlignment = 16;  // lets a reader map sections as arrays of 16-byte-aligned data

enum SectionKind : size_t { kSectionMeta, kSectionGlyf, kSectionPnts, kSectionBand, kSectionFont };
constexpr std::array<std::array<char, 4>, kSectionCount> kSectionTags = {{
    {'M', 'E', 'T', 'A'},
    {'G', 'L', 'Y', 'F'},
    {'P', 'N', 'T', 'S'},
    {'B', 'A', 'N', 'D'},
    {'F', 'O', 'N', 'T'},
}};

// Section contents.
constexpr size_t kMetaFixedSize = 48;
constexpr size_t kAxisRecordSize = 20;
constexpr size_t kGlyphRecordSize = 48;
constexpr size_t kPointSize = 8;
constexpr size_t kBandWordSize = 4;

// Limits. They bound every allocation and loop by the input size and keep coordinates in a range
// where float arithmetic in the rasterizers stays exact enough.
constexpr uint32_t kMinUnitsPerEm = 16;  // the OpenType range
constexpr uint32_t kMaxUnitsPerEm = 16384;
constexpr uint64_t kMaxGlyphs = 65536;  // glyph indices are 16-bit
constexpr uint64_t kMaxAxes = 64;
constexpr uint64_t kMaxNameBytes = 1024;
constexpr float kMaxCoordinateEm = 64.0f;
constexpr uint32_t kMaxBandsPerGlyph = 256;
// kMaxCurvesPerGlyph curves and a pad between each two of its contours.
constexpr uint32_t kMaxCurveSlotsPerGlyph = 2 * kMaxCurvesPerGlyph;
constexpr size_t kMinFontBytes = 12;  // an sfnt header
constexpr uint32_t kKnownFontFlags = kFontCubic | kFontVariable;
constexpr uint32_t kKnownGlyphFlags = kGlyphBaked | kGlyphFailed;

// ---------------------------------------------------------------------------------------------
// Messages

struct Hex {
    uint32_t value;
};

struct Tag {
    std::array<char, 4> chars;
};

void append_value(std::string& out, const char* text) {
    out += text;
}

void append_value(std::string& out, Hex hex) {
    char digits[8];
    for (int i = 7; i >= 0; --i) digits[7 - i] = "0123456789abcdef"[(hex.value >> (4 * i)) & 0xFu];
    out += "0x";
    out.append(digits, sizeof(digits));
}

void append_value(std::string& out, Tag tag) {
    bool printable = std::all_of(tag.chars.begin(), tag.chars.end(), [](char c) { return c >= 0x20 && c < 0x7F; });
    if (printable) {
        out += '\'';
        out.append(tag.chars.data(), tag.chars.size());
        out += '\'';
    } else {
        uint32_t value = 0;
        std::memcpy(&value, tag.chars.data(), 4);
        append_value(out, Hex{value});
    }
}

template <class T>
requires std::is_arithmetic_v<T>
void append_value(std::string& out, T value) {
    // Shortest round-trip form for floats, so a message shows the exact offending value.
    char buffer[64];
    std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    out.append(buffer, result.ptr);
}

// Replaces each "{}" in `pattern` with the next argument.
template <class... Args>
std::string format(std::string_view pattern, const Args&... args) {
    std::string out;
    size_t position = 0;
    auto substitute = [&](const auto& arg) {
        size_t at = pattern.find("{}", position);
        assert(at != std::string_view::npos && "more arguments than placeholders");
        out.append(pattern.substr(position, at - position));
        append_value(out, arg);
        position = at + 2;
    };
    (substitute(args), ...);
    (void)substitute;  // unused when there are no arguments
    out.append(pattern.substr(position));
    return out;
}

template <class... Args>
Error invalid(std::string_view pattern, const Args&... args) {
    return Error{ErrorCode::asset_invalid, format(pattern, args...)};
}

// ---------------------------------------------------------------------------------------------
// Byte access

template <class T>
T load(const std::byte* at) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
}

template <class T>
void store(std::vector<std::byte>& out, size_t offset, T value) {
    assert(offset + sizeof(T) <= out.size());
    std::memcpy(out.data() + offset, &value, sizeof(T));
}

template <class T>
void append(std::vector<std::byte>& out, T value) {
    size_t at = out.size();
    out.resize(at + sizeof(T));
    std::memcpy(out.data() + at, &value, sizeof(T));
}

void append_bytes(std::vector<std::byte>& out, const void* data, size_t size) {
    if (size == 0) return;
    size_t at = out.size();
    out.resize(at + size);
    std::memcpy(out.data() + at, data, size);
}

// The checksum covers the whole file except its own field.
uint32_t asset_checksum(std::span<const std::byte> file) {
    assert(file.size() >= kHeaderSize);
    uint32_t crc = crc32c(file.first(kChecksumOffset));
    return crc32c(file.subspan(kChecksumOffset + 4), crc);
}

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
        if (glyph_count != asset.glyphs.size())
            status = invalid("asset: font bytes hold {} glyphs in face {}, records say {}", glyph_count,
                             asset.info.face_index, asset.glyphs.size());
        hb_face_destroy(face);
    }
    hb_blob_destroy(blob);
    return status;
}

// ---------------------------------------------------------------------------------------------
// Decoding

struct SectionRange {
    uint64_t offset = 0;
    uint64_t size = 0;
};

Result<std::array<SectionRange, kSectionCount>> read_section_table(std::span<const std::byte> file) {
    std::array<SectionRange, kSectionCount> sections;
    std::array<bool, kSectionCount> seen = {};
    for (size_t entry = 0; entry < kSectionCount; ++entry) {
        const std::byte* at = file.data() + kSectionTableOffset + entry * kSectionEntrySize;
        Tag tag;
        std::memcpy(tag.chars.data(), at, 4);
        uint32_t reserved = load<uint32_t>(at + 4);
        uint64_t offset = load<uint64_t>(at + 8);
        uint64_t size = load<uint64_t>(at + 16);

        auto kind = std::find(kSectionTags.begin(), kSectionTags.end(), tag.chars);
        if (kind == kSectionTags.end()) return invalid("asset: section {}: unknown section tag {}", entry, tag);
        size_t index = static_cast<size_t>(kind - kSectionTags.begin());
        if (seen[index]) return invalid("asset: section {}: tag {} appears twice", entry, tag);
        seen[index] = true;
        if (reserved != 0)
            return invalid("asset: section {} {}: reserved field is {}, must be 0", entry, tag, Hex{reserved});
        if (offset % kSectionAlignment != 0)
            return invalid("asset: section {} {}: offset {} is not a multiple of {}", entry, tag, offset,
                           kSectionAlignment);
        if (offset < kSectionTableEnd)
            return invalid("asset: section {} {}: offset {} is inside the header or section table (ends at {})", entry,
                           tag, offset, kSectionTableEnd);
        if (offset > file.size() || size > file.size() - offset)
            return invalid("asset: section {} {}: range [{}, {} + {}) past the {}-byte file", entry, tag, offset,
                           offset, size, file.size());
        sections[index] = {offset, size};
    }

    std::array<size_t, kSectionCount> by_offset = {0, 1, 2, 3, 4};
    std::sort(by_offset.begin(), by_offset.end(), [&](size_t a, size_t b) {
        return sections[a].offset != sections[b].offset ? sections[a].offset < sections[b].offset
                                                        : sections[a].size < sections[b].size;
    });
    for (size_t i = 1; i < kSectionCount; ++i) {
        const SectionRange& previous = sections[by_offset[i - 1]];
        const SectionRange& next = sections[by_offset[i]];
        if (previous.offset + previous.size > next.offset)
            return invalid("asset: sections {} [{}, {}) and {} [{}, {}) overlap", Tag{kSectionTags[by_offset[i - 1]]},
                           previous.offset, previous.offset + previous.size, Tag{kSectionTags[by_offset[i]]},
                           next.offset, next.offset + next.size);
    }
    return sections;
}

Status decode_meta(std::span<const std::byte> meta, FontAsset& asset, uint32_t& glyph_count) {
    if (meta.size() < kMetaFixedSize)
        return invalid("asset: META section is {} bytes, shorter than its {}-byte fixed part", meta.size(),
                       kMetaFixedSize);
    const std::byte* at = meta.data();
    FontInfo& info = asset.info;
    info.units_per_em = load<uint32_t>(at + 0);
    info.ascender = load<int32_t>(at + 4);
    info.descender = load<int32_t>(at + 8);
    info.line_gap = load<int32_t>(at + 12);
    info.face_index = load<uint32_t>(at + 16);
    glyph_count = load<uint32_t>(at + 20);
    info.flags = load<uint32_t>(at + 24);
    info.tolerance_em = load<float>(at + 28);
    info.max_deviation_em = load<float>(at + 32);
    uint32_t axis_count = load<uint32_t>(at + 36);
    uint32_t family_length = load<uint32_t>(at + 40);
    uint32_t style_length = load<uint32_t>(at + 44);

    if (glyph_count < 1 || glyph_count > kMaxGlyphs)
        return invalid("asset: glyph count {} outside 1..{}", glyph_count, kMaxGlyphs);
    if (axis_count > kMaxAxes) return invalid("asset: {} axes, at most {}", axis_count, kMaxAxes);
    if (family_length > kMaxNameBytes)
        return invalid("asset: family name is {} bytes, at most {}", family_length, kMaxNameBytes);
    if (style_length > kMaxNameBytes)
        return invalid("asset: style name is {} bytes, at most {}", style_length, kMaxNameBytes);
    uint64_t expected = kMetaFixedSize + uint64_t{axis_count} * kAxisRecordSize + family_length + style_length;
    if (meta.size() != expected)
        return invalid("asset: META section is {} bytes, its {} axes and {} + {} name bytes need {}", meta.size(),
                       axis_count, family_length, style_length, expected);

    at += kMetaFixedSize;
    info.axes.resize(axis_count);
    for (AxisValue& axis : info.axes) {
        axis.tag = load<uint32_t>(at + 0);
        axis.value = load<float>(at + 4);
        axis.minimum = load<float>(at + 8);
        axis.default_value = load<float>(at + 12);
        axis.maximum = load<float>(at + 16);
        at += kAxisRecordSize;
    }
    info.family.assign(reinterpret_cast<const char*>(at), family_length);
    at += family_length;
    info.style.assign(reinterpret_cast<const char*>(at), style_length);
    return {};
}

Status decode_glyphs(std::span<const std::byte> glyf, uint32_t glyph_count, FontAsset& asset) {
    uint64_t expected = uint64_t{glyph_count} * kGlyphRecordSize;
    if (glyf.size() != expected)
        return invalid("asset: GLYF section is {} bytes, {} glyphs need {}", glyf.size(), glyph_count, expected);
    asset.glyphs.resize(glyph_count);
    const std::byte* at = glyf.data();
    for (GlyphRecord& glyph : asset.glyphs) {
        glyph.advance = load<float>(at + 0);
        glyph.bearing_x = load<float>(at + 4);
        glyph.bearing_y = load<float>(at + 8);
        glyph.bbox_min_x = load<float>(at + 12);
        glyph.bbox_min_y = load<float>(at + 16);
        glyph.bbox_max_x = load<float>(at + 20);
        glyph.bbox_max_y = load<float>(at + 24);
        glyph.point_offset = load<uint32_t>(at + 28);
        glyph.curve_count = load<uint32_t>(at + 32);
        glyph.band_offset = load<uint32_t>(at + 36);
        glyph.band_count = load<uint16_t>(at + 40);
        glyph.band_words = load<uint16_t>(at + 42);
        glyph.flags = load<uint32_t>(at + 44);
        at += kGlyphRecordSize;
    }
    return {};
}

// ---------------------------------------------------------------------------------------------
// Encoding

// An upper bound on the serialized size (each section padded by a whole alignment), reserved at once.
size_t serialized_capacity(const FontAsset& asset) {
    const FontInfo& info = asset.info;
    return kSectionTableEnd + kSectionCount * kSectionAlignment + kMetaFixedSize + info.axes.size() * kAxisRecordSize +
           info.family.size() + info.style.size() + asset.glyphs.size() * kGlyphRecordSize +
           asset.points.size() * kPointSize + asset.band_words.size() * kBandWordSize + asset.font_bytes.size();
}

// Appends the META section: the fixed part, the axis records, then the family and style names.
void encode_meta(const FontAsset& asset, std::vector<std::byte>& out) {
    const FontInfo& info = asset.info;
    append<uint32_t>(out, info.units_per_em);
    append<int32_t>(out, info.ascender);
    append<int32_t>(out, info.descender);
    append<int32_t>(out, info.line_gap);
    append<uint32_t>(out, info.face_index);
    append<uint32_t>(out, static_cast<uint32_t>(asset.glyphs.size()));
    append<uint32_t>(out, info.flags);
    append<float>(out, info.tolerance_em);
    append<float>(out, info.max_deviation_em);
    append<uint32_t>(out, static_cast<uint32_t>(info.axes.size()));
    append<uint32_t>(out, static_cast<uint32_t>(info.family.size()));
    append<uint32_t>(out, static_cast<uint32_t>(info.style.size()));
    for (const AxisValue& axis : info.axes) {
        append<uint32_t>(out, axis.tag);
        append<float>(out, axis.value);
        append<float>(out, axis.minimum);
        append<float>(out, axis.default_value);
        append<float>(out, axis.maximum);
    }
    append_bytes(out, info.family.data(), info.family.size());
    append_bytes(out, info.style.data(), info.style.size());
}

// Appends the GLYF section: one fixed-size record per glyph, field for field.
void encode_glyphs(const std::vector<GlyphRecord>& glyphs, std::vector<std::byte>& out) {
    for (const GlyphRecord& glyph : glyphs) {
        append<float>(out, glyph.advance);
        append<float>(out, glyph.bearing_x);
        append<float>(out, glyph.bearing_y);
        append<float>(out, glyph.bbox_min_x);
        append<float>(out, glyph.bbox_min_y);
        append<float>(out, glyph.bbox_max_x);
        append<float>(out, glyph.bbox_max_y);
        append<uint32_t>(out, glyph.point_offset);
        append<uint32_t>(out, glyph.curve_count);
        append<uint32_t>(out, glyph.band_offset);
        append<uint16_t>(out, glyph.band_count);
        append<uint16_t>(out, glyph.band_words);
        append<uint32_t>(out, glyph.flags);
    }
}

// Fills in the header and section table at the start of out, and last the checksum, which covers both.
void store_header(const std::array<SectionRange, kSectionCount>& sections, std::vector<std::byte>& out) {
    std::memcpy(out.data(), kMagic, sizeof(kMagic));
    store<uint32_t>(out, kVersionOffset, kAssetVersion);
    store<uint32_t>(out, kSectionCountOffset, static_cast<uint32_t>(kSectionCount));
    store<uint64_t>(out, kFileSizeOffset, out.size());
    store<uint32_t>(out, kReservedOffset, 0);
    for (size_t kind = 0; kind < kSectionCount; ++kind) {
        size_t at = kSectionTableOffset + kind * kSectionEntrySize;
        std::memcpy(out.data() + at, kSectionTags[kind].data(), 4);
        store<uint32_t>(out, at + 4, 0);
        store<uint64_t>(out, at + 8, sections[kind].offset);
        store<uint64_t>(out, at + 16, sections[kind].size);
    }
    store<uint32_t>(out, kChecksumOffset, asset_checksum(out));  // last: it covers everything else
}

}  // namespace

// -------------------------------------------------------------------------------------------------

uint32_t FontAsset::band_of(const GlyphRecord& glyph, float y) {
    if (glyph.band_count == 0) return 0;
    // The same float operations a shader does, so both sides pick the same band for the same y.
    float band_height = (glyph.bbox_max_y - glyph.bbox_min_y) / static_cast<float>(glyph.band_count);
    if (!(band_height > 0.0f)) return 0;
    float band = std::floor((y - glyph.bbox_min_y) / band_height);
    if (!(band > 0.0f))  // below the glyph, or NaN
        return 0;
    uint32_t last = uint32_t{glyph.band_count} - 1u;
    if (band >= static_cast<float>(last)) return last;
    return static_cast<uint32_t>(band);
}

Status validate_asset(const FontAsset& asset) {
    if (Status status = check_info(asset.info); !status) return status;
    if (asset.glyphs.empty() || asset.glyphs.size() > kMaxGlyphs)
        return invalid("asset: glyph count {} outside 1..{}", asset.glyphs.size(), kMaxGlyphs);

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

    return check_font_bytes(asset);
}

Result<FontAsset> load_asset(std::span<const std::byte> bytes) {
    // Cheap checks first: a truncated or foreign file fails before the checksum pass.
    if (bytes.size() < kHeaderSize)
        return invalid("asset: truncated: {} bytes, shorter than the {}-byte header", bytes.size(), kHeaderSize);
    if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return invalid("asset: bad magic (not a crisp asset)");
    uint32_t version = load<uint32_t>(bytes.data() + kVersionOffset);
    if (version != kAssetVersion)
        return Error{
            ErrorCode::asset_version,
            format("asset: version {} is not supported (this build reads version {})", version, kAssetVersion)};
    uint64_t file_size = load<uint64_t>(bytes.data() + kFileSizeOffset);
    if (file_size > bytes.size())
        return invalid("asset: truncated: header says {} bytes, got {}", file_size, bytes.size());
    if (file_size < bytes.size())
        return invalid("asset: size mismatch: header says {} bytes, got {}", file_size, bytes.size());
    uint32_t reserved = load<uint32_t>(bytes.data() + kReservedOffset);
    if (reserved != 0) return invalid("asset: header reserved field is {}, must be 0", Hex{reserved});
    uint32_t stored_checksum = load<uint32_t>(bytes.data() + kChecksumOffset);
    uint32_t computed_checksum = asset_checksum(bytes);
    if (stored_checksum != computed_checksum)
        return invalid("asset: checksum mismatch (stored {}, computed {})", Hex{stored_checksum},
                       Hex{computed_checksum});

    uint32_t section_count = load<uint32_t>(bytes.data() + kSectionCountOffset);
    if (section_count != kSectionCount)
        return invalid("asset: {} sections, version 1 has exactly {}", section_count, kSectionCount);
    if (bytes.size() < kSectionTableEnd)
        return invalid("asset: truncated: the section table ends at {}, past the {}-byte file", kSectionTableEnd,
                       bytes.size());
    Result<std::array<SectionRange, kSectionCount>> table = read_section_table(bytes);
    if (!table) return table.error();
    auto section = [&](SectionKind kind) {
        const SectionRange& range = table.value()[kind];
        return bytes.subspan(static_cast<size_t>(range.offset), static_cast<size_t>(range.size));
    };

    FontAsset asset;
    uint32_t glyph_count = 0;
    if (Status status = decode_meta(section(kSectionMeta), asset, glyph_count); !status) return status.error();
    if (Status status = decode_glyphs(section(kSectionGlyf), glyph_count, asset); !status) return status.error();

    std::span<const std::byte> points = section(kSectionPnts);
    if (points.size() % kPointSize != 0)
        return invalid("asset: PNTS section is {} bytes, not a multiple of {}", points.size(), kPointSize);
    asset.points.resize(points.size() / kPointSize);
    if (!points.empty()) std::memcpy(asset.points.data(), points.data(), points.size());

    std::span<const std::byte> words = section(kSectionBand);
    if (words.size() % kBandWordSize != 0)
        return invalid("asset: BAND section is {} bytes, not a multiple of {}", words.size(), kBandWordSize);
    asset.band_words.resize(words.size() / kBandWordSize);
    if (!words.empty()) std::memcpy(asset.band_words.data(), words.data(), words.size());

    std::span<const std::byte> font = section(kSectionFont);
    asset.font_bytes.assign(font.begin(), font.end());

    if (Status status = validate_asset(asset); !status) return status.error();
    return asset;
}

std::vector<std::byte> serialize_asset(const FontAsset& asset) {
    assert(validate_asset(asset).ok() && "serialize_asset needs an asset that validate_asset accepts");
    std::vector<std::byte> out(kSectionTableEnd);  // the header and section table, filled in last
    out.reserve(serialized_capacity(asset));
    std::array<SectionRange, kSectionCount> sections;
    auto begin_section = [&](SectionKind kind) {
        out.resize((out.size() + kSectionAlignment - 1) / kSectionAlignment * kSectionAlignment);  // zero padding
        sections[kind].offset = out.size();
    };
    auto end_section = [&](SectionKind kind) { sections[kind].size = out.size() - sections[kind].offset; };

    begin_section(kSectionMeta);
    encode_meta(asset, out);
    end_section(kSectionMeta);

    begin_section(kSectionGlyf);
    encode_glyphs(asset.glyphs, out);
    end_section(kSectionGlyf);

    begin_section(kSectionPnts);
    append_bytes(out, asset.points.data(), asset.points.size() * kPointSize);
    end_section(kSectionPnts);

    begin_section(kSectionBand);
    append_bytes(out, asset.band_words.data(), asset.band_words.size() * kBandWordSize);
    end_section(kSectionBand);

    begin_section(kSectionFont);
    append_bytes(out, asset.font_bytes.data(), asset.font_bytes.size());
    end_section(kSectionFont);

    store_header(sections, out);
    return out;
}

// -------------------------------------------------------------------------------------------------

Status save_asset_file(const FontAsset& asset, const std::filesystem::path& path) {
    std::vector<std::byte> bytes = serialize_asset(asset);
    return write_file_atomically(path, bytes);
}

Result<FontAsset> load_asset_file(const std::filesystem::path& path) {
    Result<std::vector<std::byte>> bytes = read_file(path, limits::kAssetFileBytes);
    if (!bytes) return bytes.error();
    return load_asset(*bytes);
}

}  // namespace crisp
