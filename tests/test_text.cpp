#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

namespace crisp {
namespace {

TEST(Text, DecodesValidUtf8) {
    EXPECT_EQ(decode_utf8("a\xC3\xA9\xE9\xAA\xA8\xF0\x9F\x98\x80"),
              (std::vector<uint32_t>{'a', 0xE9, 0x9AA8, 0x1F600}));
    EXPECT_TRUE(decode_utf8("").empty());
}

TEST(Text, InvalidUtf8BecomesReplacementCharacters) {
    const uint32_t r = 0xFFFD;
    EXPECT_EQ(decode_utf8("\xFF"), (std::vector<uint32_t>{r}));
    EXPECT_EQ(decode_utf8("a\xE9\xAA"), (std::vector<uint32_t>{'a', r}));             // truncated: one U+FFFD
    EXPECT_EQ(decode_utf8("\xC0\xAF"), (std::vector<uint32_t>{r, r}));                // overlong
    EXPECT_EQ(decode_utf8("\xED\xA0\x80"), (std::vector<uint32_t>{r, r, r}));         // surrogate
    EXPECT_EQ(decode_utf8("\xF4\x90\x80\x80"), (std::vector<uint32_t>{r, r, r, r}));  // past U+10FFFF
    EXPECT_EQ(decode_utf8("\xE2\x82x"), (std::vector<uint32_t>{r, 'x'}));
}

TEST(Text, ParsesCodepointRanges) {
    auto ranges = parse_codepoint_ranges("U+0041-0043, 0x61,100-101,66");
    ASSERT_TRUE(ranges) << ranges.error().message;
    EXPECT_EQ(*ranges, (std::vector<uint32_t>{'A', 'B', 'C', 'a', 'd', 'e'}));
    for (const char* bad : {"", "x", "U+", "10-5", "U+110000", "1,,2", "0x41-", "-5"}) {
        auto result = parse_codepoint_ranges(bad);
        EXPECT_FALSE(result) << bad;
        if (!result) {
            EXPECT_EQ(result.error().code, ErrorCode::invalid_argument);
        }
    }
}

TEST(Text, ParsesVariations) {
    auto v = parse_variation("wght=700.5");
    ASSERT_TRUE(v);
    EXPECT_EQ(v->tag, make_tag("wght"));
    EXPECT_EQ(v->value, 700.5f);
    for (const char* bad : {"wght", "=5", "wght=", "wght=abc", "toolong=1", "wght=inf", "wght=nan", "wght=1x"}) {
        EXPECT_FALSE(parse_variation(bad)) << bad;
    }
}

TEST(Text, TagsRoundTrip) {
    EXPECT_EQ(make_tag("wght"), 0x77676874u);
    EXPECT_EQ(tag_to_string(make_tag("opsz")), "opsz");
    EXPECT_EQ(tag_to_string(make_tag("ab")), "ab  ");
}

}  // namespace
}  // namespace crisp
