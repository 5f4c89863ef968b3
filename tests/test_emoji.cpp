// Emoji in layout: the emoji data and sequences.
#include "core/utf8.hpp"
#include "text/emoji.hpp"

#include <gtest/gtest.h>

#include <string_view>
#include <vector>

namespace crisp {
namespace {

using detail::emoji_presentation;
using detail::emoji_properties;
using detail::emoji_sequence_end;
using detail::Presentation;

size_t sequence_length(std::string_view utf8) {
    return emoji_sequence_end(decode_utf8(utf8), 0);
}

Presentation presentation(std::string_view utf8) {
    const std::vector<uint32_t> text = decode_utf8(utf8);
    return emoji_presentation(std::span(text).first(emoji_sequence_end(text, 0)));
}

TEST(EmojiData, PropertiesFromEmojiData) {
    EXPECT_EQ(emoji_properties('a'), 0u);
    EXPECT_EQ(emoji_properties('1'), detail::kEmoji);  // a keycap base, text by default
    EXPECT_EQ(emoji_properties('#'), detail::kEmoji);
    EXPECT_EQ(emoji_properties(0xA9), detail::kEmoji | detail::kExtendedPictographic);  // ©
    EXPECT_EQ(emoji_properties(0x2764), detail::kEmoji | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x1F600), detail::kEmoji | detail::kEmojiPresentation | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x26A1), detail::kEmoji | detail::kEmojiPresentation | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x1F1FA), detail::kEmoji | detail::kEmojiPresentation);  // regional indicator
    EXPECT_EQ(emoji_properties(0x1F3FD), detail::kEmoji | detail::kEmojiPresentation);  // skin tone
    EXPECT_EQ(emoji_properties(0x1FC00), detail::kExtendedPictographic);                // reserved
    EXPECT_EQ(emoji_properties(0x1FFFE), 0u);
    EXPECT_EQ(emoji_properties(0x200D), 0u);
    EXPECT_EQ(emoji_properties(0x10FFFF), 0u);
    EXPECT_EQ(emoji_properties(0x110000), 0u);
    EXPECT_EQ(emoji_properties(0xFFFFFFFF), 0u);
}

TEST(EmojiData, Sequences) {
    EXPECT_EQ(sequence_length("a"), 1u);
    EXPECT_EQ(sequence_length("12"), 1u);
    EXPECT_EQ(sequence_length("\U0001F600\U0001F600"), 1u);
    EXPECT_EQ(sequence_length("\u2764\uFE0F!"), 2u);
    EXPECT_EQ(sequence_length("\u2764\uFE0E!"), 2u);
    EXPECT_EQ(sequence_length("\U0001F44D\U0001F3FDx"), 2u);                       // skin tone
    EXPECT_EQ(sequence_length("\U0001F468\u200D\U0001F469\u200D\U0001F467"), 5u);  // ZWJ family
    EXPECT_EQ(sequence_length("\u2764\uFE0F\u200D\U0001F525"), 4u);                // ZWJ after a selector
    EXPECT_EQ(sequence_length("\U0001F44D\U0001F3FB\u200D\u2764"), 4u);            // ZWJ after a modifier
    EXPECT_EQ(sequence_length("\U0001F600\u200D"), 1u);   // a trailing joiner continues nothing
    EXPECT_EQ(sequence_length("\U0001F600\u200Da"), 1u);  // nor one before a letter
    EXPECT_EQ(sequence_length("a\u200D\U0001F600"), 1u);
    EXPECT_EQ(sequence_length("\U0001F1FA\U0001F1F8\U0001F1EB"), 2u);  // a flag, then a lone indicator
    EXPECT_EQ(sequence_length("\U0001F1EB"), 1u);
    EXPECT_EQ(sequence_length("1\uFE0F\u20E3"), 3u);  // keycap
    EXPECT_EQ(sequence_length("#\uFE0F\u20E3"), 3u);
    EXPECT_EQ(sequence_length("1\u20E3"), 1u);  // no U+FE0F: a digit and an enclosing mark
    EXPECT_EQ(sequence_length("\U0001F3F4\U000E0067\U000E0062\U000E0065\U000E006E\U000E0067\U000E007Fx"), 7u);

    EXPECT_EQ(presentation("a"), Presentation::none);
    EXPECT_EQ(presentation("\u2764"), Presentation::text);
    EXPECT_EQ(presentation("\u2764\uFE0F"), Presentation::emoji);
    EXPECT_EQ(presentation("\u2764\uFE0E"), Presentation::text);
    EXPECT_EQ(presentation("\U0001F600"), Presentation::emoji);
    EXPECT_EQ(presentation("\U0001F600\uFE0E"), Presentation::text);
    EXPECT_EQ(presentation("1"), Presentation::text);
    EXPECT_EQ(presentation("1\uFE0F\u20E3"), Presentation::emoji);
    EXPECT_EQ(presentation("\u2764\u200D\U0001F525"), Presentation::emoji);  // a ZWJ sequence is an emoji
    EXPECT_EQ(presentation("\U0001F1FA\U0001F1F8"), Presentation::emoji);
}

}  // namespace
}  // namespace crisp
