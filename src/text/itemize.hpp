// Private to layout: decoding and itemization. Text becomes code points with byte offsets, then
// per paragraph: character classes (spaces, marks, line break opportunities), bidi embedding
// levels, resolved scripts and the font of every character.
#pragma once

#include "core/utf8.hpp"

#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include <hb.h>

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace crisp::detail {

// Per-character bits. The first group comes from the code points alone (classify); the shaping
// step adds the second.
enum CharFlags : uint8_t {
    kCharSpace = 1u << 0,         // breaking white space: hangs at the end of a line
    kCharTab = 1u << 1,           // U+0009 (also kCharSpace)
    kCharBreakBefore = 1u << 2,   // a line may break before this character
    kCharAttached = 1u << 3,      // a combining mark, joiner or variation selector: part of the previous cluster
    kCharCommon = 1u << 4,        // script Common, Inherited or Unknown: follows its neighbours
    kCharEmojiNext = 1u << 5,     // continues the emoji sequence before it (text/emoji.hpp): same font, run, level
    kCharClusterStart = 1u << 6,  // a shaped cluster starts here
    kCharUnsafe = 1u << 7,        // HarfBuzz: breaking before this cluster changes the shaping
};

// Mandatory breaks (UAX #14 BK, CR, LF, NL): LF, VT, FF, CR, NEL, U+2028, U+2029.
inline bool is_hard_break(uint32_t cp) {
    return (cp >= 0x0A && cp <= 0x0D) || cp == 0x85 || cp == 0x2028 || cp == 0x2029;
}

// Unicode's Default_Ignorable_Code_Point: what HarfBuzz removes from the glyphs it makes.
bool is_default_ignorable(uint32_t cp);

// Fills `flags` (same length as `text`, one paragraph) with the first group of CharFlags.
void classify(std::span<const uint32_t> text, std::span<uint8_t> flags);

struct BidiScratch {
    std::vector<uint32_t> types;      // FriBidiCharType
    std::vector<uint32_t> brackets;   // FriBidiBracketType
    std::vector<signed char> levels;  // FriBidiLevel
};

// Embedding levels of one paragraph (UAX #9 up to I2, with L1 for segment separators and the
// paragraph's end). Returns the paragraph level: 0 (LTR) or 1 (RTL).
uint8_t resolve_levels(std::span<const uint32_t> text, Direction direction, BidiScratch& scratch,
                       std::span<uint8_t> levels);

// Script of every character: Common, Inherited and Unknown take the script of the run they are
// in (the preceding character's; at the start, the first real script after them).
void resolve_scripts(std::span<const uint32_t> text, std::span<const uint8_t> flags, std::span<hb_script_t> scripts);

// Font (index into `fonts`) of every character of one paragraph; see layout.hpp for the rule. An
// emoji sequence takes the font chosen for its first character: the first font with a colour glyph
// for it where it is presented as emoji, the first with a plain one where as text.
void choose_fonts(std::span<const Font* const> fonts, std::span<const uint32_t> text, std::span<const uint8_t> flags,
                  std::span<uint16_t> font_of);

}  // namespace crisp::detail
