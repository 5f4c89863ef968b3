// crisp: reading and writing .crisp assets (docs/asset-format.md); the rules on the decoded values are
// validate.cpp's.
//
// The loader treats its input as hostile: it checks the size, magic, version, declared size and
// checksum before it looks at anything else, checks every section range before it reads one, and
// reads every field with memcpy so no access is unaligned or out of bounds. Decoding only checks
// what the in-memory FontAsset cannot express (section sizes, counts, reserved fields); every rule
// about the decoded values lives in validate_asset, which the baker also runs before it writes.
#include "asset/asset_format.hpp"
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

using namespace asset_format;

namespace {

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
// Decoding

struct SectionRange {
    uint64_t offset = 0;
    uint64_t size = 0;
};

// The table of a file with `count` sections (the first `count` kinds); the others stay empty.
Result<std::array<SectionRange, kSectionCount>> read_section_table(std::span<const std::byte> file, size_t count) {
    std::array<SectionRange, kSectionCount> sections = {};
    std::array<bool, kSectionCount> seen = {};
    const size_t table_end = section_table_end(count);
    for (size_t entry = 0; entry < count; ++entry) {
        const std::byte* at = file.data() + kSectionTableOffset + entry * kSectionEntrySize;
        Tag tag;
        std::memcpy(tag.chars.data(), at, 4);
        uint32_t reserved = load<uint32_t>(at + 4);
        uint64_t offset = load<uint64_t>(at + 8);
        uint64_t size = load<uint64_t>(at + 16);

        auto kind =
            std::find(kSectionTags.begin(), kSectionTags.begin() + static_cast<std::ptrdiff_t>(count), tag.chars);
        if (kind == kSectionTags.begin() + static_cast<std::ptrdiff_t>(count))
            return invalid("asset: section {}: unknown section tag {}", entry, tag);
        size_t index = static_cast<size_t>(kind - kSectionTags.begin());
        if (seen[index]) return invalid("asset: section {}: tag {} appears twice", entry, tag);
        seen[index] = true;
        if (reserved != 0)
            return invalid("asset: section {} {}: reserved field is {}, must be 0", entry, tag, Hex{reserved});
        if (offset % kSectionAlignment != 0)
            return invalid("asset: section {} {}: offset {} is not a multiple of {}", entry, tag, offset,
                           kSectionAlignment);
        if (offset < table_end)
            return invalid("asset: section {} {}: offset {} is inside the header or section table (ends at {})", entry,
                           tag, offset, table_end);
        if (offset > file.size() || size > file.size() - offset)
            return invalid("asset: section {} {}: range [{}, {} + {}) past the {}-byte file", entry, tag, offset,
                           offset, size, file.size());
        sections[index] = {offset, size};
    }

    std::array<size_t, kSectionCount> by_offset;
    for (size_t i = 0; i < kSectionCount; ++i) by_offset[i] = i;
    std::sort(by_offset.begin(), by_offset.begin() + static_cast<std::ptrdiff_t>(count), [&](size_t a, size_t b) {
        return sections[a].offset != sections[b].offset ? sections[a].offset < sections[b].offset
                                                        : sections[a].size < sections[b].size;
    });
    for (size_t i = 1; i < count; ++i) {
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

    if (glyph_count < 1 || glyph_count > kMaxGlyphRecords)
        return invalid("asset: glyph count {} outside 1..{}", glyph_count, kMaxGlyphRecords);
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

// A section that is an array of fixed-size records, copied as a block.
template <class Record>
Status decode_records(std::span<const std::byte> section, const char* tag, std::vector<Record>& out) {
    if (section.size() % sizeof(Record) != 0)
        return invalid("asset: {} section is {} bytes, not a multiple of {}", tag, section.size(), sizeof(Record));
    out.resize(section.size() / sizeof(Record));
    if (!section.empty()) std::memcpy(out.data(), section.data(), section.size());
    return {};
}

Status decode_palettes(std::span<const std::byte> cpal, FontAsset& asset) {
    if (cpal.empty()) return {};
    if (cpal.size() < kCpalHeaderSize)
        return invalid("asset: CPAL section is {} bytes, shorter than its {}-byte header", cpal.size(),
                       kCpalHeaderSize);
    asset.palette_size = load<uint32_t>(cpal.data());
    uint32_t reserved = load<uint32_t>(cpal.data() + 4);
    if (reserved != 0) return invalid("asset: CPAL reserved field is {}, must be 0", Hex{reserved});
    return decode_records(cpal.subspan(kCpalHeaderSize), "CPAL", asset.palette_colours);
}

// ---------------------------------------------------------------------------------------------
// Encoding

// An upper bound on the serialized size (each section padded by a whole alignment), reserved at once.
size_t serialized_capacity(const FontAsset& asset) {
    const FontInfo& info = asset.info;
    return kSectionTableEnd + kSectionCount * kSectionAlignment + kMetaFixedSize + info.axes.size() * kAxisRecordSize +
           info.family.size() + info.style.size() + asset.glyphs.size() * kGlyphRecordSize +
           asset.points.size() * kPointSize + asset.band_words.size() * kBandWordSize + asset.font_bytes.size() +
           asset.colour_glyphs.size() * sizeof(ColourGlyph) + asset.layers.size() * sizeof(ColourLayer) +
           asset.paints.size() * sizeof(Paint) + asset.stops.size() * sizeof(ColourStop) + kCpalHeaderSize +
           asset.palette_colours.size() * 4 + asset.images.size() * sizeof(BitmapImage) + asset.image_bytes.size();
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

uint32_t FontAsset::face_glyph_count() const {
    auto synthetic = std::find_if(glyphs.begin(), glyphs.end(),
                                  [](const GlyphRecord& glyph) { return (glyph.flags & kGlyphSynthetic) != 0; });
    return static_cast<uint32_t>(synthetic - glyphs.begin());
}

uint32_t FontAsset::palette_count() const {
    return palette_size == 0 ? 0 : static_cast<uint32_t>(palette_colours.size() / palette_size);
}

const ColourGlyph* FontAsset::colour_glyph(uint32_t glyph) const {
    auto at = std::lower_bound(colour_glyphs.begin(), colour_glyphs.end(), glyph,
                               [](const ColourGlyph& entry, uint32_t value) { return entry.glyph < value; });
    return at != colour_glyphs.end() && at->glyph == glyph ? &*at : nullptr;
}

Result<FontAsset> load_asset(std::span<const std::byte> bytes) {
    // Cheap checks first: a truncated or foreign file fails before the checksum pass.
    if (bytes.size() < kHeaderSize)
        return invalid("asset: truncated: {} bytes, shorter than the {}-byte header", bytes.size(), kHeaderSize);
    if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return invalid("asset: bad magic (not a crisp asset)");
    uint32_t version = load<uint32_t>(bytes.data() + kVersionOffset);
    if (version != 1 && version != kAssetVersion)
        return Error{
            ErrorCode::asset_version,
            format("asset: version {} is not supported (this build reads versions 1 and {})", version, kAssetVersion)};
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

    const size_t expected_sections = version == 1 ? kSectionCountV1 : kSectionCount;
    uint32_t section_count = load<uint32_t>(bytes.data() + kSectionCountOffset);
    if (section_count != expected_sections)
        return invalid("asset: {} sections, version {} has exactly {}", section_count, version, expected_sections);
    if (bytes.size() < section_table_end(expected_sections))
        return invalid("asset: truncated: the section table ends at {}, past the {}-byte file",
                       section_table_end(expected_sections), bytes.size());
    Result<std::array<SectionRange, kSectionCount>> table = read_section_table(bytes, expected_sections);
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

    // Colour glyphs (version 2; a version 1 file's ranges are empty).
    const Status colour[] = {
        decode_records(section(kSectionColr), "COLR", asset.colour_glyphs),
        decode_records(section(kSectionLayr), "LAYR", asset.layers),
        decode_records(section(kSectionPant), "PANT", asset.paints),
        decode_records(section(kSectionStop), "STOP", asset.stops),
        decode_palettes(section(kSectionCpal), asset),
        decode_records(section(kSectionImag), "IMAG", asset.images),
    };
    for (const Status& status : colour)
        if (!status) return status.error();
    std::span<const std::byte> pixels = section(kSectionPixl);
    asset.image_bytes.assign(pixels.begin(), pixels.end());

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

    auto block = [&](SectionKind kind, const auto& records) {
        begin_section(kind);
        append_bytes(out, records.data(), records.size() * sizeof(records[0]));
        end_section(kind);
    };
    block(kSectionColr, asset.colour_glyphs);
    block(kSectionLayr, asset.layers);
    block(kSectionPant, asset.paints);
    block(kSectionStop, asset.stops);
    begin_section(kSectionCpal);
    if (!asset.palette_colours.empty()) {
        append<uint32_t>(out, asset.palette_size);
        append<uint32_t>(out, 0);
        append_bytes(out, asset.palette_colours.data(), asset.palette_colours.size() * 4);
    }
    end_section(kSectionCpal);
    block(kSectionImag, asset.images);
    block(kSectionPixl, asset.image_bytes);

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
