// Private to asset/: the .crisp format's layout and limits, and the loader's error messages,
// shared by reading and writing (asset.cpp) and the rules on decoded values (validate.cpp).
#pragma once

#include <crisp/asset.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>

namespace crisp::asset_format {

static_assert(std::endian::native == std::endian::little,
              "crisp supports little-endian hosts only: the asset is stored little-endian and read with memcpy");
static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "floats are stored as IEEE 754 binary32");
static_assert(sizeof(Point) == 8 && std::is_trivially_copyable_v<Point>, "PNTS is copied as a block of Points");
static_assert(sizeof(GlyphRecord) == 48, "a GLYF record mirrors GlyphRecord field for field");
// The colour sections are copied as blocks of their records, as PNTS is.
static_assert(sizeof(ColourGlyph) == 32 && std::is_trivially_copyable_v<ColourGlyph>, "a COLR record is a ColourGlyph");
static_assert(sizeof(ColourLayer) == 8 && std::is_trivially_copyable_v<ColourLayer>, "a LAYR record is a ColourLayer");
static_assert(sizeof(Paint) == 68 && std::is_trivially_copyable_v<Paint>, "a PANT record is a Paint");
static_assert(sizeof(ColourStop) == 12 && std::is_trivially_copyable_v<ColourStop>, "a STOP record is a ColourStop");
static_assert(sizeof(BitmapImage) == 16 && std::is_trivially_copyable_v<BitmapImage>,
              "an IMAG record is a BitmapImage");

// Header.
inline constexpr char kMagic[8] = {'C', 'R', 'I', 'S', 'P', 'F', 'N', 'T'};
inline constexpr size_t kHeaderSize = 32;
inline constexpr size_t kVersionOffset = 8;
inline constexpr size_t kSectionCountOffset = 12;
inline constexpr size_t kFileSizeOffset = 16;
inline constexpr size_t kChecksumOffset = 24;
inline constexpr size_t kReservedOffset = 28;

// Section table.
inline constexpr size_t kSectionTableOffset = kHeaderSize;
inline constexpr size_t kSectionEntrySize = 24;
// Version 1 has the first five sections; version 2 all twelve.
inline constexpr size_t kSectionCountV1 = 5;
inline constexpr size_t kSectionCount = 12;
inline constexpr size_t section_table_end(size_t section_count) {
    return kSectionTableOffset + section_count * kSectionEntrySize;
}
inline constexpr size_t kSectionTableEnd = section_table_end(kSectionCount);
inline constexpr uint64_t kSectionAlignment = 16;  // lets a reader map sections as arrays of 16-byte-aligned data

enum SectionKind : size_t {
    kSectionMeta,
    kSectionGlyf,
    kSectionPnts,
    kSectionBand,
    kSectionFont,
    kSectionColr,
    kSectionLayr,
    kSectionPant,
    kSectionStop,
    kSectionCpal,
    kSectionImag,
    kSectionPixl,
};
inline constexpr std::array<std::array<char, 4>, kSectionCount> kSectionTags = {{
    {'M', 'E', 'T', 'A'},
    {'G', 'L', 'Y', 'F'},
    {'P', 'N', 'T', 'S'},
    {'B', 'A', 'N', 'D'},
    {'F', 'O', 'N', 'T'},
    {'C', 'O', 'L', 'R'},
    {'L', 'A', 'Y', 'R'},
    {'P', 'A', 'N', 'T'},
    {'S', 'T', 'O', 'P'},
    {'C', 'P', 'A', 'L'},
    {'I', 'M', 'A', 'G'},
    {'P', 'I', 'X', 'L'},
}};

// Section contents.
inline constexpr size_t kMetaFixedSize = 48;
inline constexpr size_t kAxisRecordSize = 20;
inline constexpr size_t kGlyphRecordSize = 48;
inline constexpr size_t kPointSize = 8;
inline constexpr size_t kBandWordSize = 4;

// Limits. They bound every allocation and loop by the input size and keep coordinates in a range
// where float arithmetic in the rasterizers stays exact enough.
inline constexpr uint32_t kMinUnitsPerEm = 16;  // the OpenType range
inline constexpr uint32_t kMaxUnitsPerEm = 16384;
inline constexpr uint64_t kMaxGlyphs = 65536;  // glyph indices of a face are 16-bit
inline constexpr uint64_t kMaxGlyphRecords = kMaxGlyphs + kMaxSyntheticGlyphs;
inline constexpr size_t kCpalHeaderSize = 8;  // palette_size, reserved
inline constexpr uint64_t kMaxAxes = 64;
inline constexpr uint64_t kMaxNameBytes = 1024;
inline constexpr float kMaxCoordinateEm = 64.0f;
inline constexpr uint32_t kMaxBandsPerGlyph = 256;
// kMaxCurvesPerGlyph curves and a pad between each two of its contours.
inline constexpr uint32_t kMaxCurveSlotsPerGlyph = 2 * kMaxCurvesPerGlyph;
inline constexpr size_t kMinFontBytes = 12;  // an sfnt header
inline constexpr uint32_t kKnownFontFlags = kFontCubic | kFontVariable;
inline constexpr uint32_t kKnownGlyphFlags = kGlyphBaked | kGlyphFailed | kGlyphSynthetic;
inline constexpr uint32_t kKnownColourGlyphFlags = kColourClipped;

// ---------------------------------------------------------------------------------------------
// Messages

struct Hex {
    uint32_t value;
};

struct Tag {
    std::array<char, 4> chars;
};

inline void append_value(std::string& out, const char* text) {
    out += text;
}

inline void append_value(std::string& out, Hex hex) {
    char digits[8];
    for (int i = 7; i >= 0; --i) digits[7 - i] = "0123456789abcdef"[(hex.value >> (4 * i)) & 0xFu];
    out += "0x";
    out.append(digits, sizeof(digits));
}

inline void append_value(std::string& out, Tag tag) {
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
inline void append_value(std::string& out, T value) {
    // Shortest round-trip form for floats, so a message shows the exact offending value.
    char buffer[64];
    std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    out.append(buffer, result.ptr);
}

// Replaces each "{}" in `pattern` with the next argument.
template <class... Args>
inline std::string format(std::string_view pattern, const Args&... args) {
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

// The rules on the colour sections (validate_colour.cpp), run by validate_asset after the glyphs'.
Status check_colour(const FontAsset& asset);

}  // namespace crisp::asset_format
