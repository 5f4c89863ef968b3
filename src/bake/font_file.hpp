// The font's bytes checked before FreeType reads them, and against what FreeType made of them:
// faults of a font that would otherwise bake silently wrong (a truncated font's glyphs empty, its
// axes lost) or end in an asset that fails its own validation. Each refusal names the table.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <span>

namespace crisp {

// font_unreadable naming the table when the face's table directory, or a table it lists, lies
// past the end of the bytes (a truncated font); font_unsupported with the documented message when
// head's units per em is outside 16..16384 (FreeType refuses such a face with a bare "broken
// table"). Run after check_font_container.
Status check_font_tables(std::span<const std::byte> font_bytes, uint32_t face_index);

// font_unreadable when FreeType's glyph count for the face (`freetype_glyphs`: CFF's CharStrings,
// or loca's offsets where loca is short) is not maxp's, which HarfBuzz shapes by: the message
// names both tables and both counts.
Status check_glyph_count(std::span<const std::byte> font_bytes, uint32_t face_index, uint32_t freetype_glyphs);

// font_unsupported, "units per em is N, outside the 16 to 16384 OpenType allows", or success.
Status check_units_per_em(uint32_t units_per_em);

}  // namespace crisp
