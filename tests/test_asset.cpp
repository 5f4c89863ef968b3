// crisp: tests of the .crisp asset format: CRC-32C, serialization round trips, the loader's
// rejection of truncated, corrupted and structurally invalid assets, validate_asset's rules, the
// atomic file write and FontAsset::band_of.
#include <crisp/asset.hpp>

#include "asset/crc32c.hpp"
#include "core/file_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <hb.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef CRISP_SOURCE_DIR
#error "CRISP_SOURCE_DIR must name the repository root"
#endif

namespace crisp {
namespace {

namespace fs = std::filesystem;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Byte layout constants, restated from docs/asset-format.md rather than shared with the code, so
// a layout change that forgets the document shows up here.
constexpr size_t kChecksumOffset = 24;
constexpr size_t kSectionTableOffset = 32;
constexpr size_t kSectionEntrySize = 24;
constexpr size_t kSectionCount = 12;
constexpr size_t kSectionTableEnd = kSectionTableOffset + kSectionCount * kSectionEntrySize;
constexpr size_t kGlyphRecordSize = 48;
constexpr size_t kGlyphPointOffsetField = 28;
constexpr size_t kGlyphBandOffsetField = 36;
constexpr size_t kGlyphBandWordsField = 42;
constexpr size_t kMetaGlyphCountField = 20;

std::span<const std::byte> as_bytes(std::string_view text) {
    return std::as_bytes(std::span(text.data(), text.size()));
}

std::vector<std::byte> read_file(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    std::vector<char> chars((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::vector<std::byte> bytes(chars.size());
    if (!chars.empty()) std::memcpy(bytes.data(), chars.data(), chars.size());
    return bytes;
}

unsigned harfbuzz_glyph_count(const std::vector<std::byte>& font) {
    hb_blob_t* blob = hb_blob_create(reinterpret_cast<const char*>(font.data()), static_cast<unsigned>(font.size()),
                                     HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    hb_face_t* face = hb_face_create(blob, 0);
    unsigned count = hb_face_get_glyph_count(face);
    hb_face_destroy(face);
    hb_blob_destroy(blob);
    return count;
}

// A closed contour of line segments as quadratics: 2 * corners.size() + 1 points, the control
// points at the edge midpoints and the last point equal to the first.
std::vector<Point> polygon(const std::vector<Point>& corners) {
    std::vector<Point> points;
    for (size_t i = 0; i < corners.size(); ++i) {
        Point from = corners[i];
        Point to = corners[(i + 1) % corners.size()];
        points.push_back(from);
        points.push_back({(from.x + to.x) * 0.5f, (from.y + to.y) * 0.5f});
    }
    points.push_back(corners[0]);
    return points;
}

// Appends a glyph built from closed contours (each 2n + 1 points), with a pad slot between
// contours, a bbox over every point and `band_count` bands whose bitsets list each real curve
// whose y-extent touches the band.
void add_glyph(FontAsset& asset, uint32_t glyph_index, const std::vector<std::vector<Point>>& contours,
               uint16_t band_count) {
    std::vector<Point> points;
    std::vector<bool> is_pad;
    for (const std::vector<Point>& contour : contours) {
        if (!points.empty()) {
            points.push_back(points.back());  // the pad's control point; its end is the next contour's start
            is_pad.push_back(true);
        }
        points.insert(points.end(), contour.begin(), contour.end());
        is_pad.insert(is_pad.end(), (contour.size() - 1) / 2, false);
    }
    uint32_t curve_count = static_cast<uint32_t>(is_pad.size());
    EXPECT_EQ(points.size(), 2 * size_t{curve_count} + 1);

    GlyphRecord& glyph = asset.glyphs.at(glyph_index);
    glyph.bbox_min_x = glyph.bbox_max_x = points[0].x;
    glyph.bbox_min_y = glyph.bbox_max_y = points[0].y;
    for (Point point : points) {
        glyph.bbox_min_x = std::min(glyph.bbox_min_x, point.x);
        glyph.bbox_max_x = std::max(glyph.bbox_max_x, point.x);
        glyph.bbox_min_y = std::min(glyph.bbox_min_y, point.y);
        glyph.bbox_max_y = std::max(glyph.bbox_max_y, point.y);
    }
    glyph.advance = glyph.bbox_max_x + 0.1f;
    glyph.bearing_x = glyph.bbox_min_x;
    glyph.bearing_y = glyph.bbox_max_y;
    glyph.point_offset = static_cast<uint32_t>(asset.points.size());
    glyph.curve_count = curve_count;
    glyph.band_offset = static_cast<uint32_t>(asset.band_words.size());
    glyph.band_count = band_count;
    glyph.band_words = static_cast<uint16_t>((curve_count + 31) / 32);
    glyph.flags = kGlyphBaked;

    float band_height = (glyph.bbox_max_y - glyph.bbox_min_y) / band_count;
    for (uint32_t band = 0; band < band_count; ++band) {
        float low = glyph.bbox_min_y + static_cast<float>(band) * band_height;
        float high = low + band_height;
        std::vector<uint32_t> words(glyph.band_words, 0u);
        for (uint32_t curve = 0; curve < curve_count; ++curve) {
            if (is_pad[curve]) continue;
            const Point* p = &points[2 * curve];
            float curve_low = std::min({p[0].y, p[1].y, p[2].y});
            float curve_high = std::max({p[0].y, p[1].y, p[2].y});
            if (curve_low <= high && curve_high >= low) words[curve / 32] |= 1u << (curve % 32);
        }
        asset.band_words.insert(asset.band_words.end(), words.begin(), words.end());
    }
    asset.points.insert(asset.points.end(), points.begin(), points.end());
}

constexpr uint32_t kSquareGlyph = 1;
constexpr uint32_t kTriangleGlyph = 2;
constexpr uint32_t kTwoContourGlyph = 3;
constexpr uint32_t kManyCurveGlyph = 4;  // 40 curves: two words per band

// The smallest font HarfBuzz accepts with a glyph count: an sfnt header and a version 0.5 maxp
// table (big-endian, as OpenType is).
std::vector<std::byte> minimal_font(uint16_t glyph_count) {
    const uint8_t bytes[] = {
        0x00,
        0x01,
        0x00,
        0x00,  // sfnt version 1.0: TrueType
        0x00,
        0x01,  // one table
        0x00,
        0x10,
        0x00,
        0x00,
        0x00,
        0x00,  // searchRange, entrySelector, rangeShift
        'm',
        'a',
        'x',
        'p',  // table record: tag, checksum, offset, length
        0x00,
        0x00,
        0x00,
        0x00,
        0x00,
        0x00,
        0x00,
        0x1C,
        0x00,
        0x00,
        0x00,
        0x06,
        0x00,
        0x00,
        0x50,
        0x00,  // maxp version 0.5
        static_cast<uint8_t>(glyph_count >> 8),
        static_cast<uint8_t>(glyph_count),
        0x00,
        0x00,  // padding to a multiple of 4
    };
    std::vector<std::byte> font(sizeof(bytes));
    std::memcpy(font.data(), bytes, sizeof(bytes));
    return font;
}

FontAsset make_valid_asset(std::vector<std::byte> font_bytes) {
    FontAsset asset;
    asset.font_bytes = std::move(font_bytes);
    EXPECT_GT(asset.font_bytes.size(), 12u);

    FontInfo& info = asset.info;
    info.family = "DejaVu Sans";
    info.style = "Book \xE2\x80\x94 synthetic";  // an em dash: names are UTF-8
    info.units_per_em = 2048;
    info.ascender = 1901;
    info.descender = -483;
    info.line_gap = 0;
    info.face_index = 0;
    info.flags = kFontVariable;
    info.tolerance_em = 1.0f / 4096.0f;
    info.max_deviation_em = 0.0001f;
    info.axes.push_back({0x77676874u, 500.0f, 100.0f, 400.0f, 900.0f});  // 'wght'

    unsigned glyph_count = harfbuzz_glyph_count(asset.font_bytes);
    EXPECT_GT(glyph_count, kManyCurveGlyph);
    asset.glyphs.resize(glyph_count);
    for (size_t i = 0; i < asset.glyphs.size(); ++i) {
        // Empty glyphs, baked or not; their offsets are ignored and left at odd values on purpose.
        GlyphRecord& glyph = asset.glyphs[i];
        glyph.advance = 0.5f;
        glyph.flags = i % 3 == 0 ? 0u : kGlyphBaked;
        glyph.point_offset = static_cast<uint32_t>(i * 7);
        glyph.band_offset = 0xFFFFFFFFu;
    }
    asset.glyphs[5].flags = kGlyphBaked | kGlyphFailed;

    add_glyph(asset, kSquareGlyph, {polygon({{0.0f, 0.0f}, {0.5f, 0.0f}, {0.5f, 0.5f}, {0.0f, 0.5f}})}, 2);
    add_glyph(asset, kTriangleGlyph, {polygon({{0.1f, 0.0f}, {0.7f, 0.0f}, {0.4f, 0.6f}})}, 1);
    add_glyph(asset, kTwoContourGlyph,
              {polygon({{0.0f, 0.0f}, {0.6f, 0.0f}, {0.6f, 0.6f}, {0.0f, 0.6f}}),
               polygon({{0.2f, 0.2f}, {0.2f, 0.4f}, {0.4f, 0.4f}, {0.4f, 0.2f}})},
              3);
    std::vector<Point> corners;
    for (int i = 0; i < 40; ++i) {
        double angle = 2.0 * std::numbers::pi * i / 40.0;
        corners.push_back(
            {static_cast<float>(0.3 + 0.25 * std::cos(angle)), static_cast<float>(0.35 + 0.3 * std::sin(angle))});
    }
    add_glyph(asset, kManyCurveGlyph, {polygon(corners)}, 4);
    asset.points.push_back({-1.0f, 2.0f});  // referenced by no glyph, still checked

    EXPECT_EQ(asset.glyphs[kTwoContourGlyph].curve_count, 9u);
    EXPECT_EQ(asset.glyphs[kManyCurveGlyph].band_words, 2u);
    return asset;
}

// The fixture: DejaVu Sans's bytes and glyph count, four glyphs with curves, the rest empty.
const FontAsset& valid_asset() {
    static const FontAsset asset = make_valid_asset(read_file(CRISP_SOURCE_DIR "/fonts/DejaVuSans.ttf"));
    return asset;
}

// The same glyphs with a 36-byte font of 12 glyphs: a file of under 2 KB, where random changes
// mostly land in the structure and each load takes microseconds.
const FontAsset& small_asset() {
    static const FontAsset asset = make_valid_asset(minimal_font(12));
    return asset;
}

const std::vector<std::byte>& valid_bytes() {
    static const std::vector<std::byte> bytes = serialize_asset(valid_asset());
    return bytes;
}

template <class T>
T peek(const std::vector<std::byte>& bytes, size_t at) {
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));
    return value;
}

template <class T>
void poke(std::vector<std::byte>& bytes, size_t at, T value) {
    std::memcpy(bytes.data() + at, &value, sizeof(T));
}

// Recomputes the checksum after a deliberate change, so that the structural checks behind it
// are what rejects the change.
void reseal(std::vector<std::byte>& bytes) {
    std::span<const std::byte> all(bytes);
    uint32_t crc = crc32c(all.first(kChecksumOffset));
    crc = crc32c(all.subspan(kChecksumOffset + 4), crc);
    poke<uint32_t>(bytes, kChecksumOffset, crc);
}

struct SectionEntry {
    size_t entry_at = 0;  // where the entry lies in the section table
    uint64_t offset = 0;
    uint64_t size = 0;
};

SectionEntry find_section(const std::vector<std::byte>& bytes, std::string_view tag) {
    for (size_t i = 0; i < kSectionCount; ++i) {
        size_t at = kSectionTableOffset + i * kSectionEntrySize;
        if (std::memcmp(bytes.data() + at, tag.data(), 4) == 0)
            return {at, peek<uint64_t>(bytes, at + 8), peek<uint64_t>(bytes, at + 16)};
    }
    ADD_FAILURE() << "no section " << tag;
    return {};
}

size_t glyph_field_at(const std::vector<std::byte>& bytes, uint32_t glyph, size_t field) {
    return static_cast<size_t>(find_section(bytes, "GLYF").offset) + glyph * kGlyphRecordSize + field;
}

size_t point_at(const std::vector<std::byte>& bytes, size_t point) {
    return static_cast<size_t>(find_section(bytes, "PNTS").offset) + point * 8;
}

size_t band_word_at(const std::vector<std::byte>& bytes, size_t word) {
    return static_cast<size_t>(find_section(bytes, "BAND").offset) + word * 4;
}

void expect_rejected(const std::vector<std::byte>& bytes, ErrorCode code, std::string_view fragment) {
    Result<FontAsset> result = load_asset(bytes);
    ASSERT_FALSE(result.ok()) << "accepted; expected a message with \"" << fragment << "\"";
    EXPECT_EQ(static_cast<int>(result.error().code), static_cast<int>(code)) << result.error().message;
    EXPECT_NE(result.error().message.find(fragment), std::string::npos)
        << "message \"" << result.error().message << "\" lacks \"" << fragment << "\"";
}

// Applies `change` to a copy of the valid asset's bytes, reseals it and expects `fragment`.
void expect_resealed_fault(const std::function<void(std::vector<std::byte>&)>& change, std::string_view fragment,
                           ErrorCode code = ErrorCode::asset_invalid) {
    std::vector<std::byte> bytes = valid_bytes();
    change(bytes);
    reseal(bytes);
    expect_rejected(bytes, code, fragment);
}

void expect_invalid(const std::function<void(FontAsset&)>& change, std::string_view fragment,
                    const FontAsset& base = valid_asset()) {
    FontAsset asset = base;
    change(asset);
    Status status = validate_asset(asset);
    ASSERT_FALSE(status.ok()) << "accepted; expected a message with \"" << fragment << "\"";
    EXPECT_EQ(static_cast<int>(status.error().code), static_cast<int>(ErrorCode::asset_invalid));
    EXPECT_NE(status.error().message.find(fragment), std::string::npos)
        << "message \"" << status.error().message << "\" lacks \"" << fragment << "\"";
}

using test::TemporaryDirectory;

// ---------------------------------------------------------------------------------------------
// CRC-32C

TEST(Crc32c, KnownAnswers) {
    EXPECT_EQ(crc32c(as_bytes("123456789")), 0xE3069283u);
    EXPECT_EQ(crc32c({}), 0u);
    EXPECT_EQ(crc32c(as_bytes("a")), 0xC1D04330u);

    // RFC 3720 (iSCSI), B.4.
    std::vector<std::byte> zeros(32, std::byte{0x00});
    std::vector<std::byte> ones(32, std::byte{0xFF});
    std::vector<std::byte> ascending(32);
    std::vector<std::byte> descending(32);
    for (size_t i = 0; i < 32; ++i) {
        ascending[i] = static_cast<std::byte>(i);
        descending[i] = static_cast<std::byte>(31 - i);
    }
    EXPECT_EQ(crc32c(zeros), 0x8A9136AAu);
    EXPECT_EQ(crc32c(ones), 0x62A8AB43u);
    EXPECT_EQ(crc32c(ascending), 0x46DD794Eu);
    EXPECT_EQ(crc32c(descending), 0x113FDB5Cu);
}

TEST(Crc32c, IncrementalEqualsOneShot) {
    std::mt19937 random(1234);
    std::vector<std::byte> bytes(1031);
    for (std::byte& b : bytes) b = static_cast<std::byte>(random());
    std::span<const std::byte> all(bytes);

    // Every start alignment and every split point, so the 8-byte loop and the tail both run at
    // every phase.
    for (size_t start = 0; start < 8; ++start) {
        std::span<const std::byte> data = all.subspan(start);
        uint32_t one_shot = crc32c(data);
        for (size_t split = 0; split <= data.size(); ++split) {
            uint32_t incremental = crc32c(data.subspan(split), crc32c(data.first(split)));
            ASSERT_EQ(incremental, one_shot) << "start " << start << ", split " << split;
        }
    }

    // Against the bitwise definition.
    uint32_t expected = ~0u;
    for (std::byte b : bytes) {
        expected ^= std::to_integer<uint32_t>(b);
        for (int bit = 0; bit < 8; ++bit) expected = (expected >> 1) ^ ((expected & 1u) ? 0x82F63B78u : 0u);
    }
    EXPECT_EQ(crc32c(bytes), ~expected);
}

// ---------------------------------------------------------------------------------------------
// Round trip and layout

TEST(Asset, FixtureIsValid) {
    Status status = validate_asset(valid_asset());
    EXPECT_TRUE(status.ok()) << status.error().message;
}

TEST(Asset, RoundTrip) {
    Result<FontAsset> loaded = load_asset(valid_bytes());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(*loaded == valid_asset());
    EXPECT_EQ(serialize_asset(*loaded), valid_bytes());
}

TEST(Asset, SerializedLayout) {
    const std::vector<std::byte>& bytes = valid_bytes();
    ASSERT_GE(bytes.size(), kSectionTableEnd);
    EXPECT_EQ(std::memcmp(bytes.data(), "CRISPFNT", 8), 0);
    EXPECT_EQ(peek<uint32_t>(bytes, 8), kAssetVersion);
    EXPECT_EQ(peek<uint32_t>(bytes, 12), kSectionCount);
    EXPECT_EQ(peek<uint64_t>(bytes, 16), bytes.size());
    EXPECT_EQ(peek<uint32_t>(bytes, 28), 0u);

    // META GLYF PNTS BAND FONT COLR LAYR PANT STOP CPAL IMAG PIXL, in that order, 16-byte aligned, zero
    // padding, nothing after PIXL.
    const char* const tags[] = {"META", "GLYF", "PNTS", "BAND", "FONT", "COLR",
                                "LAYR", "PANT", "STOP", "CPAL", "IMAG", "PIXL"};
    uint64_t end = kSectionTableEnd;
    for (size_t i = 0; i < kSectionCount; ++i) {
        size_t at = kSectionTableOffset + i * kSectionEntrySize;
        EXPECT_EQ(std::memcmp(bytes.data() + at, tags[i], 4), 0) << "entry " << i;
        EXPECT_EQ(peek<uint32_t>(bytes, at + 4), 0u);
        uint64_t offset = peek<uint64_t>(bytes, at + 8);
        uint64_t size = peek<uint64_t>(bytes, at + 16);
        EXPECT_EQ(offset % 16, 0u) << tags[i];
        EXPECT_EQ(offset, (end + 15) / 16 * 16) << tags[i];
        for (uint64_t pad = end; pad < offset; ++pad) EXPECT_EQ(bytes[pad], std::byte{0}) << "padding at " << pad;
        end = offset + size;
    }
    EXPECT_EQ(end, bytes.size());

    const FontAsset& asset = valid_asset();
    EXPECT_EQ(find_section(bytes, "META").size,
              48 + 20 * asset.info.axes.size() + asset.info.family.size() + asset.info.style.size());
    EXPECT_EQ(find_section(bytes, "GLYF").size, 48 * asset.glyphs.size());
    EXPECT_EQ(find_section(bytes, "PNTS").size, 8 * asset.points.size());
    EXPECT_EQ(find_section(bytes, "BAND").size, 4 * asset.band_words.size());
    EXPECT_EQ(find_section(bytes, "FONT").size, asset.font_bytes.size());

    // One record decoded by hand, field by field.
    const GlyphRecord& glyph = asset.glyphs[kTwoContourGlyph];
    size_t at = glyph_field_at(bytes, kTwoContourGlyph, 0);
    EXPECT_EQ(peek<float>(bytes, at + 0), glyph.advance);
    EXPECT_EQ(peek<float>(bytes, at + 12), glyph.bbox_min_x);
    EXPECT_EQ(peek<float>(bytes, at + 24), glyph.bbox_max_y);
    EXPECT_EQ(peek<uint32_t>(bytes, at + 28), glyph.point_offset);
    EXPECT_EQ(peek<uint32_t>(bytes, at + 32), glyph.curve_count);
    EXPECT_EQ(peek<uint32_t>(bytes, at + 36), glyph.band_offset);
    EXPECT_EQ(peek<uint16_t>(bytes, at + 40), glyph.band_count);
    EXPECT_EQ(peek<uint16_t>(bytes, at + 42), glyph.band_words);
    EXPECT_EQ(peek<uint32_t>(bytes, at + 44), glyph.flags);
}

std::vector<std::byte> from_hex(std::string_view hex) {
    std::vector<std::byte> bytes;
    for (size_t i = 0; i + 1 < hex.size(); i += 2)
        bytes.push_back(static_cast<std::byte>(std::stoi(std::string(hex.substr(i, 2)), nullptr, 16)));
    return bytes;
}

// The asset of the worked examples at the end of docs/asset-format.md.
FontAsset example_asset() {
    FontAsset asset;
    asset.font_bytes = minimal_font(1);
    asset.info.family = "Ex";
    asset.info.style = "R";
    asset.info.units_per_em = 1000;
    asset.info.ascender = 800;
    asset.info.descender = -200;
    asset.info.line_gap = 90;
    asset.info.tolerance_em = 1.0f / 4096.0f;
    asset.glyphs.resize(1);
    asset.glyphs[0].advance = 0.5f;
    asset.glyphs[0].flags = kGlyphBaked;
    return asset;
}

TEST(Asset, DocumentedExample) {
    // The worked example at the end of docs/asset-format.md, byte for byte.
    const std::vector<std::byte> expected = from_hex(
        "4352495350464e54020000000c000000e001000000000000f5bba9f900000000"
        "4d4554410000000040010000000000003300000000000000474c594600000000"
        "80010000000000003000000000000000504e545300000000b001000000000000"
        "000000000000000042414e4400000000b0010000000000000000000000000000"
        "464f4e5400000000b0010000000000002400000000000000434f4c5200000000"
        "e00100000000000000000000000000004c41595200000000e001000000000000"
        "000000000000000050414e5400000000e0010000000000000000000000000000"
        "53544f5000000000e00100000000000000000000000000004350414c00000000"
        "e0010000000000000000000000000000494d414700000000e001000000000000"
        "00000000000000005049584c00000000e0010000000000000000000000000000"
        "e80300002003000038ffffff5a00000000000000010000000000000000008039"
        "0000000000000000020000000100000045785200000000000000000000000000"
        "0000003f00000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000010000000001000000010010000000006d617870"
        "000000000000001c000000060000500000010000000000000000000000000000");
    ASSERT_EQ(expected.size(), 480u);
    EXPECT_EQ(serialize_asset(example_asset()), expected);
    Result<FontAsset> loaded = load_asset(expected);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(*loaded == example_asset());
}

TEST(Asset, Version1FilesStillLoad) {
    // The version 1 example of docs/asset-format.md: five sections, no colour glyphs.
    const std::vector<std::byte> expected = from_hex(
        "4352495350464e54010000000500000034010000000000003b8c04c700000000"
        "4d45544100000000a0000000000000003300000000000000474c594600000000"
        "e0000000000000003000000000000000504e5453000000001001000000000000"
        "000000000000000042414e440000000010010000000000000000000000000000"
        "464f4e5400000000100100000000000024000000000000000000000000000000"
        "e80300002003000038ffffff5a00000000000000010000000000000000008039"
        "0000000000000000020000000100000045785200000000000000000000000000"
        "0000003f00000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000010000000001000000010010000000006d617870"
        "000000000000001c000000060000500000010000");
    ASSERT_EQ(expected.size(), 308u);
    Result<FontAsset> loaded = load_asset(expected);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(*loaded == example_asset());
}

// ---------------------------------------------------------------------------------------------
// Corrupted input

TEST(Asset, EveryTruncationIsRejected) {
    const std::vector<std::byte>& bytes = valid_bytes();
    size_t accepted = 0;
    for (size_t length = 0; length < bytes.size(); ++length) {
        Result<FontAsset> result = load_asset(std::span(bytes).first(length));
        if (result.ok() || result.error().code != ErrorCode::asset_invalid ||
            result.error().message.find("truncated") == std::string::npos) {
            ADD_FAILURE() << "length " << length << ": "
                          << (result.ok() ? std::string("accepted") : result.error().message);
            if (++accepted > 10) return;
        }
    }
    std::vector<std::byte> longer = bytes;
    longer.push_back(std::byte{0});
    expect_rejected(longer, ErrorCode::asset_invalid, "size mismatch: header says");
}

TEST(Asset, SingleByteFlipsAreRejected) {
    std::vector<std::byte> bytes = valid_bytes();
    std::mt19937 random(42);
    std::uniform_int_distribution<size_t> position(0, bytes.size() - 1);
    std::uniform_int_distribution<int> mask(1, 255);
    for (int i = 0; i < 300; ++i) {
        // Half the flips anywhere, half in the small sections before FONT where the structure is.
        size_t at =
            i % 2 == 0 ? position(random) : position(random) % static_cast<size_t>(find_section(bytes, "FONT").offset);
        std::byte original = bytes[at];
        bytes[at] ^= static_cast<std::byte>(mask(random));
        Result<FontAsset> result = load_asset(bytes);
        ASSERT_FALSE(result.ok()) << "flip at " << at << " accepted";
        if (at >= kSectionTableOffset) {
            EXPECT_NE(result.error().message.find("checksum mismatch"), std::string::npos)
                << "flip at " << at << ": " << result.error().message;
        }
        bytes[at] = original;
    }
}

// Flips bytes in each region of `bytes`, reseals the checksum, and checks that the loader either
// rejects the result with an asset error or returns an asset that validates.
void run_resealed_flips(std::vector<std::byte> bytes, int flips_per_region, uint32_t seed) {
    struct Region {
        const char* name;
        size_t begin;
        size_t end;
    };
    auto section_region = [&](const char* tag) {
        SectionEntry section = find_section(bytes, tag);
        return Region{tag, static_cast<size_t>(section.offset), static_cast<size_t>(section.offset + section.size)};
    };
    const Region regions[] = {
        {"header", 0, kSectionTableOffset},
        {"section table", kSectionTableOffset, kSectionTableEnd},
        section_region("META"),
        section_region("GLYF"),
        section_region("PNTS"),
        section_region("BAND"),
        section_region("FONT"),
    };
    const std::vector<std::byte> header(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(kSectionTableEnd));

    std::mt19937 random(seed);
    std::uniform_int_distribution<int> mask(1, 255);
    std::uniform_int_distribution<int> bit(0, 7);
    int rejected = 0;
    int accepted = 0;
    for (const Region& region : regions) {
        ASSERT_LT(region.begin, region.end) << region.name;
        std::uniform_int_distribution<size_t> position(region.begin, region.end - 1);
        for (int i = 0; i < flips_per_region; ++i) {
            size_t at = position(random);
            std::byte original = bytes[at];
            // Single bits keep most values plausible and reach deeper checks; whole bytes vary more.
            bytes[at] ^= i % 2 == 0 ? static_cast<std::byte>(1 << bit(random)) : static_cast<std::byte>(mask(random));
            reseal(bytes);

            Result<FontAsset> result = load_asset(bytes);
            if (result.ok()) {
                ++accepted;
                Status status = validate_asset(*result);
                EXPECT_TRUE(status.ok()) << region.name << " flip at " << at << ": " << status.error().message;
                // A change inside a section's contents that passes is a different valid asset, and
                // it serializes back to exactly these bytes.
                if (region.begin >= kSectionTableEnd) {
                    EXPECT_TRUE(serialize_asset(*result) == bytes) << region.name << " flip at " << at;
                }
            } else {
                ++rejected;
                ErrorCode code = result.error().code;
                EXPECT_TRUE(code == ErrorCode::asset_invalid || code == ErrorCode::asset_version)
                    << region.name << " flip at " << at << ": " << result.error().message;
                EXPECT_EQ(result.error().message.rfind("asset: ", 0), 0u) << result.error().message;
            }
            bytes[at] = original;
            std::copy(header.begin(), header.end(), bytes.begin());  // the checksum
        }
    }
    EXPECT_GT(rejected, 0);
    EXPECT_GT(accepted, 0);
}

TEST(Asset, ResealedFlipsAreRejectedOrValid) {
    run_resealed_flips(serialize_asset(small_asset()), 2000, 7);
}

TEST(Asset, ResealedFlipsAreRejectedOrValidWithARealFont) {
    // Fewer: each load checksums 760 KB.
    run_resealed_flips(valid_bytes(), 20, 8);
}

// ---------------------------------------------------------------------------------------------
// Targeted structural faults, each behind a valid checksum

TEST(AssetFault, BadMagic) {
    expect_resealed_fault([](std::vector<std::byte>& bytes) { bytes[3] = std::byte{'X'}; }, "bad magic");
}

TEST(AssetFault, VersionThree) {
    expect_resealed_fault([](std::vector<std::byte>& bytes) { poke<uint32_t>(bytes, 8, 3); },
                          "version 3 is not supported (this build reads versions 1 and 2)", ErrorCode::asset_version);
}

TEST(AssetFault, ChecksumMismatch) {
    std::vector<std::byte> bytes = valid_bytes();
    bytes[bytes.size() / 2] ^= std::byte{0x10};
    expect_rejected(bytes, ErrorCode::asset_invalid, "checksum mismatch (stored 0x");
}

TEST(AssetFault, HeaderReservedField) {
    expect_resealed_fault([](std::vector<std::byte>& bytes) { poke<uint32_t>(bytes, 28, 1); },
                          "header reserved field is 0x00000001");
}

TEST(AssetFault, SectionCount) {
    expect_resealed_fault([](std::vector<std::byte>& bytes) { poke<uint32_t>(bytes, 12, 4); },
                          "4 sections, version 2 has exactly 12");
}

TEST(AssetFault, PointRangePastEnd) {
    const FontAsset& asset = valid_asset();
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            poke<uint32_t>(bytes, glyph_field_at(bytes, kManyCurveGlyph, kGlyphPointOffsetField),
                           static_cast<uint32_t>(asset.points.size() - 10));
        },
        "glyph 4: point range [");
    // Offsets near 2^32 must not wrap around.
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            poke<uint32_t>(bytes, glyph_field_at(bytes, kSquareGlyph, kGlyphPointOffsetField), 0xFFFFFFFFu);
        },
        "glyph 1: point range [4294967295, 4294967304) past the");
}

TEST(AssetFault, BandRangePastEnd) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            poke<uint32_t>(bytes, glyph_field_at(bytes, kTriangleGlyph, kGlyphBandOffsetField), 0xFFFFFFFFu);
        },
        "glyph 2: band range [4294967295, 4294967296) past the");
}

TEST(AssetFault, PointOutsideBbox) {
    const GlyphRecord& square = valid_asset().glyphs[kSquareGlyph];
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) { poke<float>(bytes, point_at(bytes, square.point_offset + 3), 0.75f); },
        "glyph 1: point 3 (0.75, 0.25) outside its bbox");
    // Just past the edge by one ulp.
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            poke<float>(bytes, point_at(bytes, square.point_offset + 4) + 4, std::nextafter(0.5f, 1.0f));
        },
        "glyph 1: point 4 (0.5, 0.50000006) outside its bbox");
}

TEST(AssetFault, NanCoordinate) {
    expect_resealed_fault([](std::vector<std::byte>& bytes) { poke<float>(bytes, point_at(bytes, 7) + 4, kNan); },
                          "point 7 (0, nan) is not finite");
}

TEST(AssetFault, BandWordsMismatch) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            poke<uint16_t>(bytes, glyph_field_at(bytes, kManyCurveGlyph, kGlyphBandWordsField), 1);
        },
        "glyph 4: band_words 1 for 40 curves, expected 2");
}

TEST(AssetFault, StrayBitPastCurveCount) {
    const GlyphRecord& many = valid_asset().glyphs[kManyCurveGlyph];
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            // Band 2's second word holds curves 32..39; bit 9 of it is curve 41.
            size_t word = many.band_offset + 2 * many.band_words + 1;
            poke<uint32_t>(bytes, band_word_at(bytes, word),
                           peek<uint32_t>(bytes, band_word_at(bytes, word)) | (1u << 9));
        },
        "glyph 4: band 2: bit 41 set past its 40 curves");
    const GlyphRecord& square = valid_asset().glyphs[kSquareGlyph];
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            poke<uint32_t>(bytes, band_word_at(bytes, square.band_offset + 1), 1u << 31);
        },
        "glyph 1: band 1: bit 31 set past its 4 curves");
}

TEST(AssetFault, GlyphCountDiffersFromFont) {
    // One record fewer in both META and GLYF, so only the font's own count disagrees.
    size_t glyph_count = valid_asset().glyphs.size();
    expect_resealed_fault(
        [&](std::vector<std::byte>& bytes) {
            SectionEntry meta = find_section(bytes, "META");
            SectionEntry glyf = find_section(bytes, "GLYF");
            poke<uint32_t>(bytes, static_cast<size_t>(meta.offset) + kMetaGlyphCountField,
                           static_cast<uint32_t>(glyph_count - 1));
            poke<uint64_t>(bytes, glyf.entry_at + 16, glyf.size - kGlyphRecordSize);
        },
        "asset: font bytes hold " + std::to_string(glyph_count) + " glyphs in face 0, records say " +
            std::to_string(glyph_count - 1));
}

TEST(AssetFault, GlyphCountDiffersFromRecords) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            size_t at = static_cast<size_t>(find_section(bytes, "META").offset) + kMetaGlyphCountField;
            poke<uint32_t>(bytes, at, peek<uint32_t>(bytes, at) + 1);
        },
        "asset: GLYF section is");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            poke<uint32_t>(bytes, static_cast<size_t>(find_section(bytes, "META").offset) + kMetaGlyphCountField, 0);
        },
        "asset: glyph count 0 outside 1..131072");
}

TEST(AssetFault, OverlappingSections) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry glyf = find_section(bytes, "GLYF");
            SectionEntry pnts = find_section(bytes, "PNTS");
            poke<uint64_t>(bytes, pnts.entry_at + 8, glyf.offset + glyf.size - glyf.size % 16 - 16);
        },
        "overlap");
}

TEST(AssetFault, UnknownSectionTag) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) { bytes[find_section(bytes, "BAND").entry_at + 3] = std::byte{'X'}; },
        "unknown section tag 'BANX'");
}

TEST(AssetFault, DuplicateSectionTag) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            std::memcpy(bytes.data() + find_section(bytes, "BAND").entry_at, "PNTS", 4);
        },
        "tag 'PNTS' appears twice");
}

TEST(AssetFault, MisalignedSectionOffset) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry pnts = find_section(bytes, "PNTS");
            poke<uint64_t>(bytes, pnts.entry_at + 8, pnts.offset + 8);
        },
        "'PNTS': offset");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry pnts = find_section(bytes, "PNTS");
            poke<uint64_t>(bytes, pnts.entry_at + 8, pnts.offset + 4);
        },
        "is not a multiple of 16");
}

TEST(AssetFault, SectionOutOfBounds) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry pixels = find_section(bytes, "PIXL");  // the last section
            poke<uint64_t>(bytes, pixels.entry_at + 16, pixels.size + 1);
        },
        "'PIXL': range [");
    // offset + size wraps around 2^64.
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry band = find_section(bytes, "BAND");
            poke<uint64_t>(bytes, band.entry_at + 16, ~uint64_t{0} - band.offset + 16);
        },
        "past the");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) { poke<uint64_t>(bytes, find_section(bytes, "META").entry_at + 8, 144); },
        "inside the header or section table");
}

TEST(AssetFault, SectionSizes) {
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry pnts = find_section(bytes, "PNTS");
            poke<uint64_t>(bytes, pnts.entry_at + 16, pnts.size - 4);
        },
        "PNTS section is");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry band = find_section(bytes, "BAND");
            poke<uint64_t>(bytes, band.entry_at + 16, band.size - 2);
        },
        "BAND section is");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry meta = find_section(bytes, "META");
            poke<uint64_t>(bytes, meta.entry_at + 16, meta.size - 1);
        },
        "META section is");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry meta = find_section(bytes, "META");
            poke<uint32_t>(bytes, static_cast<size_t>(meta.offset) + 36, 0xFFFFFFFFu);  // axis count
        },
        "4294967295 axes, at most 64");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry meta = find_section(bytes, "META");
            poke<uint32_t>(bytes, static_cast<size_t>(meta.offset) + 40, 0x7FFFFFFFu);  // family length
        },
        "family name is 2147483647 bytes");
    expect_resealed_fault(
        [](std::vector<std::byte>& bytes) {
            SectionEntry font = find_section(bytes, "FONT");
            poke<uint64_t>(bytes, font.entry_at + 16, 11);
        },
        "font bytes are 11 bytes, at least 12");
}

// ---------------------------------------------------------------------------------------------
// validate_asset on in-memory assets

TEST(AssetValidate, FontInfo) {
    expect_invalid([](FontAsset& a) { a.info.units_per_em = 15; }, "units_per_em 15 outside 16..16384");
    expect_invalid([](FontAsset& a) { a.info.units_per_em = 16385; }, "units_per_em 16385");
    expect_invalid([](FontAsset& a) { a.info.flags |= 1u << 7; }, "font flags 0x00000082 hold unknown bits");
    expect_invalid([](FontAsset& a) { a.info.tolerance_em = 0.0f; }, "tolerance_em 0 is not finite and positive");
    expect_invalid([](FontAsset& a) { a.info.tolerance_em = kInfinity; }, "tolerance_em inf");
    expect_invalid([](FontAsset& a) { a.info.max_deviation_em = -0.5f; }, "max_deviation_em -0.5");
    expect_invalid([](FontAsset& a) { a.info.max_deviation_em = kNan; }, "max_deviation_em nan");
    expect_invalid([](FontAsset& a) { a.info.axes.resize(65); }, "65 axes, at most 64");
    expect_invalid([](FontAsset& a) { a.info.flags &= ~uint32_t{kFontVariable}; },
                   "the variable flag is clear but 1 axes");
    expect_invalid([](FontAsset& a) { a.info.axes.clear(); }, "the variable flag is set but 0 axes");
    expect_invalid([](FontAsset& a) { a.info.axes[0].value = 950.0f; }, "axis 0 'wght': value 950 outside [100, 900]");
    expect_invalid([](FontAsset& a) { a.info.axes[0].default_value = 50.0f; },
                   "axis 0 'wght': minimum 100, default 50");
    expect_invalid([](FontAsset& a) { a.info.axes[0].maximum = kNan; }, "is not finite");
    expect_invalid([](FontAsset& a) { a.info.family.assign(1025, 'a'); }, "family name is 1025 bytes, at most 1024");
    expect_invalid([](FontAsset& a) { a.info.family.push_back('\0'); }, "family name holds a NUL byte");
    expect_invalid([](FontAsset& a) { a.info.style = "\xC0\xAF"; }, "style name is not valid UTF-8");  // overlong '/'
    expect_invalid([](FontAsset& a) { a.info.style = "\xED\xA0\x80"; }, "style name is not valid UTF-8");  // surrogate
    expect_invalid([](FontAsset& a) { a.info.style = "ok\xE2\x80"; }, "style name is not valid UTF-8");    // cut short
}

TEST(AssetValidate, Glyphs) {
    expect_invalid([](FontAsset& a) { a.glyphs.clear(); }, "glyph count 0 outside 1..131072");
    expect_invalid([](FontAsset& a) { a.glyphs.resize(65537); }, "glyph count 65537");
    expect_invalid([](FontAsset& a) { a.glyphs[9].flags = 8; }, "glyph 9: flags 0x00000008 hold unknown bits");
    expect_invalid([](FontAsset& a) { a.glyphs[9].advance = kInfinity; }, "glyph 9: advance inf is not finite");
    expect_invalid([](FontAsset& a) { a.glyphs[9].bearing_y = -64.5f; },
                   "glyph 9: bearing_y -64.5 outside [-64, 64] em");
    expect_invalid([](FontAsset& a) { a.glyphs[9].band_count = 1; }, "glyph 9: no curves but 1 bands of 0 words");
    expect_invalid([](FontAsset& a) { a.glyphs[kSquareGlyph].flags = 0; },
                   "glyph 1: 4 curves but the glyph is not baked");
    expect_invalid(
        [](FontAsset& a) { std::swap(a.glyphs[kSquareGlyph].bbox_min_x, a.glyphs[kSquareGlyph].bbox_max_x); },
        "glyph 1: bbox [0.5, 0] x [0, 0.5] is inverted");
    expect_invalid([](FontAsset& a) { a.glyphs[kSquareGlyph].band_count = 0; }, "glyph 1: band count 0 outside 1..256");
    expect_invalid([](FontAsset& a) { a.glyphs[kSquareGlyph].band_count = 257; }, "glyph 1: band count 257");
    expect_invalid([](FontAsset& a) { a.glyphs[kTriangleGlyph].bbox_max_x = 0.69f; },
                   "glyph 2: point 2 (0.7, 0) outside its bbox");
    // Ranges come in glyph order without overlap, which also bounds validation by the asset's size.
    expect_invalid([](FontAsset& a) { a.glyphs[kTriangleGlyph] = a.glyphs[kSquareGlyph]; },
                   "glyph 2: point range starts at 0, inside the range of an earlier glyph");
    expect_invalid([](FontAsset& a) { a.glyphs[kSquareGlyph].flags |= kGlyphFailed; },
                   "glyph 1: a failed glyph must be baked empty");
    expect_invalid([](FontAsset& a) { a.glyphs[9].flags = kGlyphFailed; },
                   "glyph 9: a failed glyph must be baked empty");
    // An empty glyph's bbox may be anything finite, inverted included.
    FontAsset asset = valid_asset();
    asset.glyphs[9].bbox_min_x = 1.0f;
    Status status = validate_asset(asset);
    EXPECT_TRUE(status.ok()) << status.error().message;
}

TEST(AssetValidate, Points) {
    // The trailing point belongs to no glyph and is checked all the same.
    expect_invalid([](FontAsset& a) { a.points.back().x = 64.25f; }, "(64.25, 2) outside [-64, 64] em");
    expect_invalid([](FontAsset& a) { a.points.back().y = -kInfinity; }, "(-1, -inf) is not finite");
    FontAsset asset = valid_asset();
    asset.points.back() = {-64.0f, 64.0f};
    Status status = validate_asset(asset);
    EXPECT_TRUE(status.ok()) << status.error().message;
}

TEST(AssetValidate, FontBytes) {
    expect_invalid([](FontAsset& a) { a.font_bytes.resize(11); }, "font bytes are 11 bytes, at least 12 needed");
    expect_invalid([](FontAsset& a) { a.font_bytes.assign(64, std::byte{0}); }, "font bytes hold 0 faces");
    expect_invalid([](FontAsset& a) { a.info.face_index = 1; }, "font bytes hold 1 faces, face_index is 1");
    expect_invalid([](FontAsset& a) { a.glyphs.pop_back(); }, "glyphs in face 0, records say");
}

// ---------------------------------------------------------------------------------------------
// Files

TEST(AssetFile, SaveWritesALoadableFileAndNoTemporary) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    fs::path path = directory.path() / "dejavu.crisp";

    mode_t previous_mask = ::umask(022);
    Status saved = save_asset_file(valid_asset(), path);
    ::umask(previous_mask);
    ASSERT_TRUE(saved.ok()) << saved.error().message;
    EXPECT_EQ(directory.entries(), std::vector<std::string>{"dejavu.crisp"});
    EXPECT_EQ(read_file(path), valid_bytes());
    struct stat info = {};
    ASSERT_EQ(::stat(path.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0644u) << "the asset gets the umask's permissions, not mkstemp's 0600";

    Result<FontAsset> loaded = load_asset_file(path);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(*loaded == valid_asset());

    // Saving again replaces the file, still without leftovers.
    FontAsset changed = valid_asset();
    changed.info.line_gap = 67;
    saved = save_asset_file(changed, path);
    ASSERT_TRUE(saved.ok()) << saved.error().message;
    EXPECT_EQ(directory.entries(), std::vector<std::string>{"dejavu.crisp"});
    loaded = load_asset_file(path);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_EQ(loaded->info.line_gap, 67);
}

TEST(AssetFile, SaveIntoMissingDirectoryFails) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    fs::path path = directory.path() / "missing" / "dejavu.crisp";
    Status saved = save_asset_file(valid_asset(), path);
    ASSERT_FALSE(saved.ok());
    EXPECT_EQ(static_cast<int>(saved.error().code), static_cast<int>(ErrorCode::io));
    EXPECT_NE(saved.error().message.find(path.string()), std::string::npos) << saved.error().message;
    EXPECT_NE(saved.error().message.find("No such file or directory"), std::string::npos) << saved.error().message;
    EXPECT_TRUE(directory.entries().empty());
}

TEST(AssetFile, FailedSaveLeavesExistingFileAndNoTemporary) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    fs::path good = directory.path() / "good.crisp";
    ASSERT_TRUE(save_asset_file(valid_asset(), good).ok());
    const std::vector<std::byte> good_bytes = read_file(good);

    // The target is a directory: the rename fails after the whole temporary was written.
    fs::path occupied = directory.path() / "occupied.crisp";
    fs::create_directory(occupied);
    Status saved = save_asset_file(valid_asset(), occupied);
    ASSERT_FALSE(saved.ok());
    EXPECT_EQ(static_cast<int>(saved.error().code), static_cast<int>(ErrorCode::io));
    EXPECT_NE(saved.error().message.find(occupied.string()), std::string::npos) << saved.error().message;
    EXPECT_TRUE(fs::is_directory(occupied));
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"good.crisp", "occupied.crisp"}));
    EXPECT_EQ(read_file(good), good_bytes);

    // Writing over the existing file fails part way (a file size limit stands in for a full
    // disk): the old contents stay and the partial temporary is removed.
    std::vector<std::byte> other(good_bytes.size(), std::byte{0x5A});
    struct rlimit previous_limit = {};
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &previous_limit), 0);
    struct rlimit small_limit = previous_limit;
    small_limit.rlim_cur = std::min<rlim_t>(4096, previous_limit.rlim_max);
    auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small_limit), 0);
    Status written = write_file_atomically(good, other);
    ::setrlimit(RLIMIT_FSIZE, &previous_limit);
    std::signal(SIGXFSZ, previous_handler);
    ASSERT_FALSE(written.ok());
    EXPECT_EQ(static_cast<int>(written.error().code), static_cast<int>(ErrorCode::io));
    EXPECT_NE(written.error().message.find("File too large"), std::string::npos) << written.error().message;
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"good.crisp", "occupied.crisp"}));
    EXPECT_EQ(read_file(good), good_bytes);
}

TEST(AssetFile, WriteAtomicallyEdgeCases) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    fs::path empty = directory.path() / "empty.bin";
    ASSERT_TRUE(write_file_atomically(empty, {}).ok());
    EXPECT_TRUE(fs::is_regular_file(empty));
    EXPECT_EQ(fs::file_size(empty), 0u);

    Status no_name = write_file_atomically(directory.path() / "", as_bytes("x"));
    ASSERT_FALSE(no_name.ok());
    EXPECT_EQ(static_cast<int>(no_name.error().code), static_cast<int>(ErrorCode::io));

    Status too_long = write_file_atomically(directory.path() / std::string(300, 'n'), as_bytes("x"));
    ASSERT_FALSE(too_long.ok());
    EXPECT_EQ(static_cast<int>(too_long.error().code), static_cast<int>(ErrorCode::io));
    EXPECT_EQ(directory.entries(), std::vector<std::string>{"empty.bin"});
}

TEST(AssetFile, LoadFailures) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    fs::path missing = directory.path() / "missing.crisp";
    Result<FontAsset> loaded = load_asset_file(missing);
    ASSERT_FALSE(loaded.ok());
    EXPECT_EQ(static_cast<int>(loaded.error().code), static_cast<int>(ErrorCode::io));
    EXPECT_NE(loaded.error().message.find(missing.string()), std::string::npos) << loaded.error().message;
    EXPECT_NE(loaded.error().message.find("No such file or directory"), std::string::npos) << loaded.error().message;

    loaded = load_asset_file(directory.path());
    ASSERT_FALSE(loaded.ok());
    EXPECT_EQ(static_cast<int>(loaded.error().code), static_cast<int>(ErrorCode::io));

    // A readable file that is no asset is asset_invalid, not io.
    loaded = load_asset_file(CRISP_SOURCE_DIR "/fonts/DejaVuSans.ttf");
    ASSERT_FALSE(loaded.ok());
    EXPECT_EQ(static_cast<int>(loaded.error().code), static_cast<int>(ErrorCode::asset_invalid));
    EXPECT_NE(loaded.error().message.find("bad magic"), std::string::npos) << loaded.error().message;
}

// ---------------------------------------------------------------------------------------------
// band_of

TEST(BandOf, EdgesAndOutOfRange) {
    GlyphRecord glyph;
    glyph.bbox_min_y = -0.25f;
    glyph.bbox_max_y = 0.75f;  // four bands of 0.25
    glyph.band_count = 4;

    EXPECT_EQ(FontAsset::band_of(glyph, -0.25f), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, -0.0001f), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, 0.0f), 1u);  // a band's lower edge belongs to it
    EXPECT_EQ(FontAsset::band_of(glyph, 0.2499f), 1u);
    EXPECT_EQ(FontAsset::band_of(glyph, 0.25f), 2u);
    EXPECT_EQ(FontAsset::band_of(glyph, 0.5f), 3u);
    EXPECT_EQ(FontAsset::band_of(glyph, 0.75f), 3u);  // the top edge stays in the last band
    EXPECT_EQ(FontAsset::band_of(glyph, 2.0f), 3u);
    EXPECT_EQ(FontAsset::band_of(glyph, -2.0f), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, kInfinity), 3u);
    EXPECT_EQ(FontAsset::band_of(glyph, -kInfinity), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, kNan), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, std::numeric_limits<float>::max()), 3u);

    glyph.band_count = 1;
    EXPECT_EQ(FontAsset::band_of(glyph, 0.5f), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, 9.0f), 0u);

    // A flat glyph (zero height) has one usable band.
    glyph.band_count = 3;
    glyph.bbox_max_y = glyph.bbox_min_y;
    EXPECT_EQ(FontAsset::band_of(glyph, glyph.bbox_min_y), 0u);
    EXPECT_EQ(FontAsset::band_of(glyph, 1.0f), 0u);

    glyph.band_count = 0;
    EXPECT_EQ(FontAsset::band_of(glyph, 0.0f), 0u);
}

TEST(BandOf, MatchesTheFloatFormula) {
    // The rule is the float expression clamp(floor((y - min_y) / h), 0, count - 1); check it over
    // many y, including ones that land within rounding of a band edge.
    GlyphRecord glyph;
    glyph.bbox_min_y = -0.2123f;
    glyph.bbox_max_y = 0.7311f;
    glyph.band_count = 7;
    float height = (glyph.bbox_max_y - glyph.bbox_min_y) / 7.0f;
    std::mt19937 random(3);
    std::uniform_real_distribution<float> y_distribution(-0.3f, 0.8f);
    for (int i = 0; i < 10000; ++i) {
        float y = i < 8 ? glyph.bbox_min_y + static_cast<float>(i) * height : y_distribution(random);
        float band = std::floor((y - glyph.bbox_min_y) / height);
        uint32_t expected = band < 0.0f ? 0u : band > 6.0f ? 6u : static_cast<uint32_t>(band);
        ASSERT_EQ(FontAsset::band_of(glyph, y), expected) << "y " << y;
    }
}

// ---------------------------------------------------------------------------------------------
// Colour glyphs (version 2)

// The small fixture with a synthetic glyph (a copy of the square under a transform), two palettes,
// a paint of every kind and two colour glyphs.
FontAsset make_colour_asset() {
    FontAsset asset = small_asset();
    const uint32_t synthetic = static_cast<uint32_t>(asset.glyphs.size());
    asset.glyphs.emplace_back();
    add_glyph(asset, synthetic, {polygon({{0.0f, 0.0f}, {0.25f, 0.0f}, {0.25f, 0.5f}, {0.0f, 0.5f}})}, 1);
    asset.glyphs[synthetic].flags |= kGlyphSynthetic;

    asset.palette_size = 2;
    asset.palette_colours = {0xFF0000FFu, 0x8000FF00u, 0xFFFFFFFFu, 0xFF000000u};
    asset.stops = {
        {0.0f, 0, 1.0f},                                          // paint 0: solid
        {0.0f, 1, 1.0f},  {1.0f, kForegroundPaletteIndex, 0.5f},  // paint 1: linear
        {0.25f, 0, 1.0f}, {0.75f, 1, 0.25f},                      // paint 2: radial
        {0.0f, 0, 1.0f},  {0.5f, 1, 1.0f},
        {1.0f, 0, 1.0f},  // paint 3: sweep
    };
    Paint solid;
    solid.stop_count = 1;
    Paint linear{PaintKind::linear, PaintExtend::repeat, 1, 2, 0, {}, {0.0f, 0.0f, 0.5f, 0.5f, 0.0f, 0.0f}};
    Paint radial{PaintKind::radial, PaintExtend::reflect, 3, 2, 0, {}, {0.2f, 0.2f, 0.0f, 0.3f, 0.3f, 0.4f}};
    Paint sweep{PaintKind::sweep,
                PaintExtend::pad,
                5,
                3,
                0,
                {2.0f, 0.0f, 0.0f, 2.0f, -1.0f, 0.0f},
                {0.3f, 0.3f, 0.0f, 0.5f, 0.0f, 0.0f}};
    Paint image{PaintKind::image, PaintExtend::pad, 0, 0, 0, {4.0f, 0.0f, 0.0f, -2.0f, 0.0f, 1.0f}, {}};
    asset.paints = {solid, linear, radial, sweep, image};
    asset.images = {{3, 2, 0, 5}};
    asset.image_bytes = {std::byte{1}, std::byte{2}, std::byte{3}, std::byte{4}, std::byte{5}};
    asset.layers = {{kSquareGlyph, 0}, {kTriangleGlyph, 1}, {kTwoContourGlyph, 2}, {synthetic, 4}, {kSquareGlyph, 3}};
    asset.colour_glyphs = {
        {kSquareGlyph, 0, 3, 0, 0.0f, 0.0f, 0.0f, 0.0f},
        {kTwoContourGlyph, 3, 2, kColourClipped, -0.1f, -0.2f, 0.8f, 0.9f},
    };
    return asset;
}

const FontAsset& colour_asset() {
    static const FontAsset asset = make_colour_asset();
    return asset;
}

void expect_colour_invalid(const std::function<void(FontAsset&)>& change, std::string_view fragment) {
    expect_invalid(change, fragment, colour_asset());
}

TEST(AssetColour, FixtureIsValidAndRoundTrips) {
    const FontAsset& asset = colour_asset();
    Status status = validate_asset(asset);
    ASSERT_TRUE(status.ok()) << status.error().message;
    EXPECT_EQ(asset.face_glyph_count(), small_asset().glyphs.size());
    EXPECT_EQ(asset.palette_count(), 2u);
    ASSERT_NE(asset.colour_glyph(kTwoContourGlyph), nullptr);
    EXPECT_EQ(asset.colour_glyph(kTwoContourGlyph)->first_layer, 3u);
    EXPECT_EQ(asset.colour_glyph(kTriangleGlyph), nullptr);

    std::vector<std::byte> bytes = serialize_asset(asset);
    Result<FontAsset> loaded = load_asset(bytes);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(*loaded == asset);
    EXPECT_EQ(find_section(bytes, "COLR").size, 32 * asset.colour_glyphs.size());
    EXPECT_EQ(find_section(bytes, "LAYR").size, 8 * asset.layers.size());
    EXPECT_EQ(find_section(bytes, "PANT").size, 68 * asset.paints.size());
    EXPECT_EQ(find_section(bytes, "STOP").size, 12 * asset.stops.size());
    EXPECT_EQ(find_section(bytes, "CPAL").size, 8 + 4 * asset.palette_colours.size());
    EXPECT_EQ(find_section(bytes, "IMAG").size, 16 * asset.images.size());
    EXPECT_EQ(find_section(bytes, "PIXL").size, asset.image_bytes.size());
    // A paint record field by field: kind, extend, first stop, stop count, image, to_paint, geometry.
    const size_t paint = static_cast<size_t>(find_section(bytes, "PANT").offset) + 68 * 3;
    EXPECT_EQ(peek<uint32_t>(bytes, paint + 0), 3u);
    EXPECT_EQ(peek<uint32_t>(bytes, paint + 8), 5u);
    EXPECT_EQ(peek<uint32_t>(bytes, paint + 12), 3u);
    EXPECT_EQ(peek<float>(bytes, paint + 20), 2.0f);
    EXPECT_EQ(peek<float>(bytes, paint + 36), -1.0f);
    EXPECT_EQ(peek<float>(bytes, paint + 56), 0.5f);
}

TEST(AssetColour, CorruptedFilesAreRejectedOrValid) {
    run_resealed_flips(serialize_asset(colour_asset()), 400, 11);
    const std::vector<std::byte> bytes = serialize_asset(colour_asset());
    for (size_t length = 0; length < bytes.size(); length += 7) {
        Result<FontAsset> result = load_asset(std::span(bytes).first(length));
        EXPECT_FALSE(result.ok()) << "a " << length << "-byte prefix loaded";
    }
}

TEST(AssetColour, SectionsOfWholeRecords) {
    std::vector<std::byte> bytes = serialize_asset(colour_asset());
    SectionEntry pant = find_section(bytes, "PANT");
    poke<uint64_t>(bytes, pant.entry_at + 16, pant.size - 4);
    reseal(bytes);
    expect_rejected(bytes, ErrorCode::asset_invalid, "PANT section is 336 bytes, not a multiple of 68");
    bytes = serialize_asset(colour_asset());
    poke<uint32_t>(bytes, static_cast<size_t>(find_section(bytes, "CPAL").offset) + 4, 9);
    reseal(bytes);
    expect_rejected(bytes, ErrorCode::asset_invalid, "CPAL reserved field is 0x00000009");
}

TEST(AssetColour, Rules) {
    const uint32_t synthetic = colour_asset().face_glyph_count();
    expect_colour_invalid([](FontAsset& a) { a.glyphs[3].flags |= kGlyphSynthetic; },
                          "follows the synthetic glyph 3 but is not synthetic");
    expect_colour_invalid([&](FontAsset& a) { a.glyphs[synthetic] = GlyphRecord{.flags = kGlyphSynthetic}; },
                          "must be baked and not failed");
    expect_colour_invalid([](FontAsset& a) { a.palette_colours.pop_back(); }, "are not whole palettes of 2");
    expect_colour_invalid([](FontAsset& a) { a.palette_size = 0; }, "palette colours but a palette size of 0");
    expect_colour_invalid([](FontAsset& a) { a.stops[0].palette_index = 2; },
                          "paint 0: palette index 2 past the 2 entries");
    expect_colour_invalid([](FontAsset& a) { a.stops[2].alpha = 1.5f; }, "paint 1: stop alpha 1.5 outside [0, 1]");
    expect_colour_invalid([](FontAsset& a) { a.stops[4].offset = 0.1f; }, "paint 2: stop offset 0.1 after 0.25");
    expect_colour_invalid([](FontAsset& a) { a.stops[5].offset = kNan; }, "is not a sane number");
    expect_colour_invalid([](FontAsset& a) { a.paints[0].stop_count = 2; }, "2 stops, a solid paint wants 1..1");
    expect_colour_invalid([](FontAsset& a) { a.paints[1].stop_count = 0; }, "0 stops, a gradient wants 1..256");
    expect_colour_invalid([](FontAsset& a) { a.paints[3].stop_count = 4; }, "past the 8 stops");
    expect_colour_invalid([](FontAsset& a) { a.paints[2].first_stop = 2; }, "inside an earlier paint's");
    expect_colour_invalid([](FontAsset& a) { a.paints[1].kind = static_cast<PaintKind>(9); }, "kind 9 is unknown");
    expect_colour_invalid([](FontAsset& a) { a.paints[1].extend = static_cast<PaintExtend>(3); },
                          "extend 3 is unknown");
    expect_colour_invalid([](FontAsset& a) { a.paints[2].geometry[5] = -0.5f; }, "is negative");
    expect_colour_invalid([](FontAsset& a) { a.paints[3].to_paint.dx = kInfinity; }, "mapping value inf");
    expect_colour_invalid([](FontAsset& a) { a.paints[4].image = 1; }, "image 1 past the 1 images");
    expect_colour_invalid([](FontAsset& a) { a.paints[4].stop_count = 1; }, "an image paint has 1 stops");
    expect_colour_invalid([](FontAsset& a) { a.images[0].width = kMaxBitmapSide + 1; }, "each side 1..1024");
    expect_colour_invalid([](FontAsset& a) { a.images[0].byte_count = 6; }, "past the 5 image bytes");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[1].glyph = kSquareGlyph; }, "sorted, each once");
    expect_colour_invalid([&](FontAsset& a) { a.colour_glyphs[1].glyph = synthetic; }, "is not one of the face's");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[0].layer_count = 0; }, "0 layers, 1..1024");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[1].first_layer = 2; }, "inside an earlier glyph's");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[1].layer_count = 3; }, "past the 5 layers");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[1].clip_min_x = 1.0f; }, "clip box");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs[0].flags = 2; }, "flags 0x00000002 hold unknown bits");
    expect_colour_invalid([](FontAsset& a) { a.layers[0].glyph = 0; }, "names glyph 0, which is not baked");
    expect_colour_invalid([](FontAsset& a) { a.layers[1].paint = 5; }, "names paint 5, past the 5 paints");
    expect_colour_invalid([](FontAsset& a) { a.colour_glyphs.clear(); }, "5 layers but no colour glyph");
}

}  // namespace
}  // namespace crisp
