// Private to text/: emoji properties and emoji sequences (Unicode TR51), which itemization uses to
// keep a sequence in one font and run and to choose a colour or a plain font for it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace crisp::detail {

enum EmojiProperties : uint8_t {
    kEmoji = 1u << 0,                 // Emoji=Yes: may be drawn as an emoji
    kEmojiPresentation = 1u << 1,     // Emoji_Presentation=Yes: drawn as an emoji unless U+FE0E follows
    kExtendedPictographic = 1u << 2,  // may follow U+200D in an emoji ZWJ sequence (UAX #29 GB11)
};

// The EmojiProperties of a code point, from Unicode's emoji-data.txt (text/emoji_data.inc says
// which version). Any value is accepted; those past U+10FFFF have none.
uint8_t emoji_properties(uint32_t cp);

// The end of the emoji sequence starting at text[begin] (begin + 1 when it is a single character or
// none): a regional indicator pair (a flag), or an emoji character with an optional U+FE0E or
// U+FE0F, the keycap U+20E3 after a 0-9 # * and U+FE0F, an optional skin tone modifier
// (U+1F3FB..1F3FF) and tags (U+E0020..E007E, then U+E007F); elements joined by U+200D where an
// Extended_Pictographic character follows it, as HarfBuzz joins them into one cluster.
size_t emoji_sequence_end(std::span<const uint32_t> text, size_t begin);

enum class Presentation : uint8_t {
    none,   // not an emoji
    text,   // prefers a font with a plain outline
    emoji,  // prefers a font with a colour glyph
};

// The presentation of an emoji sequence (what emoji_sequence_end spans), from TR51: U+FE0E after
// the first character makes it text, U+FE0F emoji; otherwise Emoji_Presentation makes it emoji,
// and so does anything that continues the sequence (a modifier, a keycap, tags, a ZWJ element);
// a lone emoji character without Emoji_Presentation is text.
Presentation emoji_presentation(std::span<const uint32_t> sequence);

}  // namespace crisp::detail
