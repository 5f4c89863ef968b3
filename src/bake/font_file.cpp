#include "bake/font_file.hpp"

#include "bake/colr.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace crisp {

using sfnt::fits;
using sfnt::u16;
using sfnt::u32;

namespace {

bool starts_with(std::span<const std::byte> bytes, std::string_view prefix) {
    if (bytes.size() < prefix.size()) return false;
    for (size_t i = 0; i < prefix.size(); ++i) {
        if (bytes[i] != static_cast<std::byte>(prefix[i])) return false;
    }
    return true;
}

}  // namespace

Status check_font_container(std::span<const std::byte> font_bytes) {
    // FreeType opens these, but HarfBuzz (shaping, from the asset's font bytes) does not, and the
    // asset must hold bytes it can shape: refused up front, saying what to do instead.
    if (starts_with(font_bytes, "wOFF")) {
        return Error{ErrorCode::font_unsupported,
                     "a WOFF font: crisp bakes TrueType and OpenType; decompress it first (fontTools: "
                     "python3 -c \"from fontTools.ttLib import TTFont; f = TTFont('in.woff'); f.flavor = None; "
                     "f.save('out.otf')\")"};
    }
    if (starts_with(font_bytes, "wOF2")) {
        return Error{ErrorCode::font_unsupported,
                     "a WOFF2 font: crisp bakes TrueType and OpenType; decompress it first (woff2_decompress from "
                     "the woff2 package, or fontTools with brotli)"};
    }
    if ((font_bytes.size() >= 2 && font_bytes[0] == std::byte{0x80} && font_bytes[1] == std::byte{0x01}) ||
        starts_with(font_bytes, "%!PS-AdobeFont") || starts_with(font_bytes, "%!FontType1")) {
        return Error{ErrorCode::font_unsupported,
                     "a PostScript Type 1 font: crisp bakes TrueType and OpenType; convert it to OpenType CFF first "
                     "(FontForge, for one)"};
    }
    // A CFF or CFF2 table on its own (its header: major version, minor 0, header size, offset
    // size): FreeType reads it, HarfBuzz finds no face in it.
    if (font_bytes.size() >= 4 && (font_bytes[0] == std::byte{1} || font_bytes[0] == std::byte{2}) &&
        font_bytes[1] == std::byte{0} && std::to_integer<unsigned>(font_bytes[2]) >= 4 &&
        std::to_integer<unsigned>(font_bytes[3]) >= 1 && std::to_integer<unsigned>(font_bytes[3]) <= 4) {
        return Error{ErrorCode::font_unsupported,
                     "a bare CFF font (a CFF table without the OpenType file around it): crisp bakes TrueType and "
                     "OpenType; make it an OpenType CFF font first (FontForge, or makeotf)"};
    }
    const uint32_t version = font_bytes.size() >= 4 ? sfnt::u32(font_bytes, 0) : 0;
    if (version != 0x00010000 && version != make_tag("OTTO") && version != make_tag("true") &&
        version != make_tag("typ1") && version != make_tag("ttcf")) {
        if (font_bytes.size() < 4) {
            return Error{ErrorCode::font_unreadable, "not a font: " + std::to_string(font_bytes.size()) + " bytes"};
        }
        char bytes[16];
        std::snprintf(bytes, sizeof bytes, "0x%08x", version);
        return Error{ErrorCode::font_unreadable,
                     std::string("not a TrueType or OpenType font: it starts with ") + bytes +
                         ", not an sfnt version (0x00010000, 'OTTO', 'true', 'typ1') or a collection's 'ttcf'"};
    }
    return {};
}

namespace {

Error unreadable(const std::string& why) {
    return Error{ErrorCode::font_unreadable, why};
}

std::string quoted_tag(uint32_t tag) {
    return "'" + printable(tag_to_string(tag)) + "'";
}

// The offset of face `face_index`'s table directory, after checking the collection header;
// kNoFace past a collection's faces (open_face names their count).
constexpr size_t kNoFace = SIZE_MAX;

Result<size_t> directory_offset(std::span<const std::byte> font, uint32_t face_index) {
    if (!fits(font, 0, 12)) {
        return unreadable("the font is " + std::to_string(font.size()) + " bytes, shorter than its 12-byte header");
    }
    if (u32(font, 0) != make_tag("ttcf")) return size_t{0};
    const uint32_t face_count = u32(font, 8);
    if (face_index >= face_count) return kNoFace;
    if (!fits(font, 12, size_t{4} * face_count)) {
        return unreadable("the collection header's " + std::to_string(face_count) +
                          " face offsets run past the font's end (" + std::to_string(font.size()) +
                          " bytes): the font is truncated");
    }
    return size_t{u32(font, 12 + size_t{4} * face_index)};
}

}  // namespace

Status check_units_per_em(uint32_t units_per_em) {
    if (units_per_em < 16 || units_per_em > 16384) {
        return Error{ErrorCode::font_unsupported,
                     "units per em is " + std::to_string(units_per_em) + ", outside the 16 to 16384 OpenType allows"};
    }
    return {};
}

Status check_font_tables(std::span<const std::byte> font, uint32_t face_index) {
    Result<size_t> directory = directory_offset(font, face_index);
    if (!directory) return directory.error();
    if (*directory == kNoFace) return {};
    const std::string end = " the font's end (" + std::to_string(font.size()) + " bytes): the font is truncated";
    if (!fits(font, *directory, 12)) {
        return unreadable("the table directory at offset " + std::to_string(*directory) + " lies past" + end);
    }
    const size_t table_count = u16(font, *directory + 4);
    if (!fits(font, *directory + 12, table_count * 16)) {
        return unreadable("the table directory's " + std::to_string(table_count) + " records run past" + end);
    }
    // Of the tables past the end, the one that starts first: where the font was cut.
    size_t cut = SIZE_MAX;
    for (size_t i = 0; i < table_count; ++i) {
        const size_t record = *directory + 12 + 16 * i;
        if (!fits(font, u32(font, record + 8), u32(font, record + 12)) &&
            (cut == SIZE_MAX || u32(font, record + 8) < u32(font, cut + 8))) {
            cut = record;
        }
    }
    if (cut != SIZE_MAX) {
        return unreadable("the " + quoted_tag(u32(font, cut)) + " table (" + std::to_string(u32(font, cut + 12)) +
                          " bytes at offset " + std::to_string(u32(font, cut + 8)) + ") runs past" + end);
    }
    const Result<std::span<const std::byte>> head = find_sfnt_table(font, face_index, make_tag("head"));
    if (!head) return head.error();
    // Without head (or too short for it) FreeType says what is wrong; with it, units per em is
    // FreeType's first refusal, which it words only as a broken table.
    if (fits(*head, 18, 2)) return check_units_per_em(u16(*head, 18));
    return {};
}

Status check_glyph_count(std::span<const std::byte> font, uint32_t face_index, uint32_t freetype_glyphs) {
    const Result<std::span<const std::byte>> maxp = find_sfnt_table(font, face_index, make_tag("maxp"));
    if (!maxp) return maxp.error();
    if (!fits(*maxp, 4, 2)) {
        return unreadable("the font has no maxp table (or one of " + std::to_string(maxp->size()) +
                          " bytes), which holds the glyph count HarfBuzz shapes by");
    }
    const uint32_t maxp_glyphs = u16(*maxp, 4);
    if (maxp_glyphs == freetype_glyphs) return {};
    std::string other = "the glyph outlines";
    for (const char* tag : {"CFF ", "CFF2", "loca"}) {
        const Result<std::span<const std::byte>> table = find_sfnt_table(font, face_index, make_tag(tag));
        if (table && !table->empty()) {
            other = tag[0] == 'l' ? "loca's offsets"
                                  : std::string("the ") + (tag[3] == '2' ? "CFF2" : "CFF") + " table's CharStrings";
            break;
        }
    }
    return unreadable("maxp says the face has " + std::to_string(maxp_glyphs) + " glyphs, but " + other + " hold " +
                      std::to_string(freetype_glyphs));
}

}  // namespace crisp
