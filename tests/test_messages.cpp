// Messages that quote an input (issue 28, items 17 to 19): what they quote is escaped and short,
// numbers out of range say which end, FreeType's errors have words, and a font's faults name the
// table.
#include "bake/outline.hpp"
#include "cli.hpp"
#include "core/json.hpp"
#include "core/utf8.hpp"
#include "scene.hpp"
#include "test_support.hpp"

#include <crisp/bake.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

namespace crisp {
namespace {

// Whether `text` holds a byte a terminal acts on: C0, DEL, or the UTF-8 of a C1 control.
bool has_control(std::string_view text) {
    for (size_t i = 0; i < text.size(); ++i) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x20 || byte == 0x7F) return true;
        if (byte == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) <= 0x9F &&
            static_cast<unsigned char>(text[i + 1]) >= 0x80)
            return true;
    }
    return false;
}

TEST(Messages, PrintableEscapesWhatATerminalWouldActOn) {
    EXPECT_EQ(printable("wght"), "wght");
    EXPECT_EQ(printable("\x1b[2J"), "\\x1b[2J");
    EXPECT_EQ(printable("Evil\x1b]0;pwned\x07Sans"), "Evil\\x1b]0;pwned\\x07Sans");
    EXPECT_EQ(printable(std::string_view("a\0b\x7f", 4)), "a\\x00b\\x7f");
    EXPECT_EQ(printable("a\\x1b"), "a\\x5cx1b");                                   // an escape reads back as one
    EXPECT_EQ(printable("caf\xc3\xa9 \xe6\xb0\xb8"), "caf\xc3\xa9 \xe6\xb0\xb8");  // UTF-8 is kept
    EXPECT_EQ(printable("\xc2\x9b"
                        "31m"),
              "\\u{9b}31m");  // C1 CSI
    EXPECT_EQ(printable("abc\xe2\x80\xae"
                        "fdp.exe"),
              "abc\\u{202e}fdp.exe");  // right-to-left override
    EXPECT_EQ(printable("a\xe2\x80\xa8"
                        "b"),
              "a\\u{2028}b");                                 // line separator
    EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");           // ill-formed: each byte
    EXPECT_EQ(printable("x\xe6\xb0"), "x\\xe6\\xb0");         // a truncated sequence
    EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");  // a surrogate
    EXPECT_EQ(printable(""), "");
}

TEST(Messages, PrintableShortensLongTextKeepingBothEnds) {
    const std::string exact(80, 'k');
    EXPECT_EQ(printable(exact), exact);

    // A 10 MB key: 39 characters, "...", 38 characters.
    const std::string key = "start" + std::string(size_t{10} << 20, 'k') + "end";
    const std::string shown = printable(key);
    EXPECT_EQ(shown.size(), 80u);
    EXPECT_EQ(shown.substr(0, 5), "start");
    EXPECT_EQ(shown.substr(39, 3), "...");
    EXPECT_EQ(shown.substr(77), "end");

    // A path keeps its file name.
    const std::string path = "/" + std::string(300, 'd') + "/font.ttf";
    const std::string short_path = printable(path, 40);
    EXPECT_EQ(short_path.size(), 40u);
    EXPECT_EQ(short_path.substr(31), "/font.ttf");
    EXPECT_EQ(printable(path, kPrintablePath), path);

    // Escapes count by what they show, and are never cut in two.
    const std::string escapes = printable(std::string(1000, '\x1b'));
    EXPECT_LE(escapes.size(), 80u);
    EXPECT_FALSE(has_control(escapes));
    std::string nine;
    for (int i = 0; i < 9; ++i) nine += "\\x1b";
    EXPECT_EQ(escapes, nine + "..." + nine);

    // Characters, not bytes: 39 + 3 + 38 of a two-byte letter.
    std::string accents;
    for (int i = 0; i < 1000; ++i) accents += "\xc3\xa9";
    const std::string shown_accents = printable(accents);
    EXPECT_EQ(shown_accents.size(), 39u * 2 + 3 + 38 * 2);
    EXPECT_EQ(shown_accents.substr(78, 3), "...");
    EXPECT_EQ(shown_accents.find('\\'), std::string::npos);  // no letter was cut into bytes
}

TEST(Messages, JsonFaultsQuoteKeysEscapedAndShort) {
    // A layout file's 10 MB member name with a terminal escape in it.
    const std::string text = "{\"\\u001b[2J" + std::string(size_t{10} << 20, 'k') + "\": 1}";
    Result<SubpixelLayout> layout = parse_subpixel_layout(text);
    ASSERT_FALSE(layout);
    const std::string& message = layout.error().message;
    EXPECT_LT(message.size(), 200u) << message.substr(0, 200);
    EXPECT_FALSE(has_control(message));
    EXPECT_NE(message.find("unknown member \"\\x1b[2Jkkk"), std::string::npos) << message;

    Result<json::Value> duplicate = json::parse("{\"\\u001b]0;t\\u0007\": 1, \"\\u001b]0;t\\u0007\": 2}");
    ASSERT_FALSE(duplicate);
    EXPECT_NE(duplicate.error().message.find("duplicate member \"\\x1b]0;t\\x07\""), std::string::npos)
        << duplicate.error().message;
    Result<json::Value> stray = json::parse("[1, \x1b]");
    ASSERT_FALSE(stray);
    EXPECT_NE(stray.error().message.find("unexpected character '\\x1b'"), std::string::npos) << stray.error().message;

    Result<Scene> scene = parse_scene(R"({"fonts": ["a.crisp"], "canvas": [8, 8], "runs": [], "\u009b2J": 1})");
    ASSERT_FALSE(scene);
    EXPECT_FALSE(has_control(scene.error().message));
    EXPECT_NE(scene.error().message.find("unknown member \"\\u{9b}2J\""), std::string::npos) << scene.error().message;
    Result<Scene> mode =
        parse_scene(R"({"fonts": ["a.crisp"], "canvas": [8, 8], "contrast": {"mode": "\u001bc"}, "runs": []})");
    ASSERT_FALSE(mode);
    EXPECT_NE(mode.error().message.find("got \"\\x1bc\""), std::string::npos) << mode.error().message;

    Result<SubpixelLayout> preset = resolve_subpixel_layout("\x1b[2J");
    ASSERT_FALSE(preset);
    EXPECT_FALSE(has_control(preset.error().message)) << preset.error().message;
}

TEST(Messages, LayoutNumbersOutOfRangeSaySo) {
    Result<SubpixelLayout> huge =
        parse_subpixel_layout(R"({"r": [1e308, 0, 0.34, 1], "g": [0.33, 0, 0.67, 1], "b": [0.67, 0, 1, 1]})");
    ASSERT_FALSE(huge);
    EXPECT_NE(huge.error().message.find("r[0]: expected a number, at most 1e6 in magnitude: 1e+308 is out of range"),
              std::string::npos)
        << huge.error().message;
    Result<SubpixelLayout> gamma = parse_subpixel_layout(
        R"({"r": [0, 0, 0.34, 1], "g": [0.33, 0, 0.67, 1], "b": [0.67, 0, 1, 1], "contrast": {"gamma": -1e300}})");
    ASSERT_FALSE(gamma);
    EXPECT_NE(gamma.error().message.find(
                  "contrast.gamma: expected a number, at most 1e6 in magnitude: -1e+300 is out of range"),
              std::string::npos)
        << gamma.error().message;
    Result<SubpixelLayout> text =
        parse_subpixel_layout(R"({"r": ["0", 0, 0.34, 1], "g": [0.33, 0, 0.67, 1], "b": [0.67, 0, 1, 1]})");
    ASSERT_FALSE(text);
    EXPECT_NE(text.error().message.find("r[0]: expected a number"), std::string::npos) << text.error().message;
}

TEST(Messages, NumbersPastTheirRangeSayWhichEnd) {
    const auto why = [](auto parsed, std::string_view text) {
        std::string reason;
        EXPECT_FALSE(cli::parse_number<decltype(parsed)>(text, &reason)) << text;
        return reason;
    };
    EXPECT_EQ(why(0.0f, "1e39"), "is out of range for a 32-bit float (too large)");
    EXPECT_EQ(why(0.0f, "-1e39"), "is out of range for a 32-bit float (too large)");
    EXPECT_EQ(why(0.0f, "1e-46"), "is out of range for a 32-bit float (too small)");
    EXPECT_EQ(why(0.0f, "1e-45"), "is out of range for a 32-bit float (too small)");  // subnormal
    EXPECT_EQ(why(0.0, "1e-400"), "is out of range for a 64-bit float (too small)");
    EXPECT_EQ(why(0.0, "1e400"), "is out of range for a 64-bit float (too large)");
    EXPECT_EQ(why(0.0f, "inf"), "is not finite");
    EXPECT_EQ(why(0u, "-1"), "is negative");
    EXPECT_EQ(why(0u, "-x"), "is not a number");
    EXPECT_EQ(why(0u, "99999999999"), "is out of range");
    EXPECT_EQ(cli::parse_number<float>("0"), 0.0f);
    EXPECT_EQ(cli::parse_number<float>("1.2e-38"), 1.2e-38f);
    EXPECT_EQ(cli::parse_number<uint32_t>("7"), 7u);

    Result<Variation> huge = parse_variation("wght=1e39");
    ASSERT_FALSE(huge);
    EXPECT_NE(huge.error().message.find("'1e39' is out of range for a 32-bit float"), std::string::npos)
        << huge.error().message;
    Result<Variation> word = parse_variation("wght=bold");
    ASSERT_FALSE(word);
    EXPECT_NE(word.error().message.find("is not a finite number"), std::string::npos) << word.error().message;
    Result<Variation> escape = parse_variation("\x1b[2J");
    ASSERT_FALSE(escape);
    EXPECT_FALSE(has_control(escape.error().message)) << escape.error().message;
}

TEST(Messages, FreeTypeErrorsHaveWords) {
    EXPECT_EQ(freetype_error(8), "FreeType error 8 (broken table)");
    EXPECT_EQ(freetype_error(10), "FreeType error 10 (array allocation size too large)");
    EXPECT_EQ(freetype_error(20), "FreeType error 20 (invalid outline)");
    EXPECT_EQ(freetype_error(21), "FreeType error 21 (invalid composite glyph)");
    EXPECT_EQ(freetype_error(250), "FreeType error 250");
}

TEST(Messages, FontFaultsNameTheTable) {
    const std::vector<std::byte> font = test::read_file(test::kDejaVuSans);
    for (const size_t percent : {25u, 50u, 99u}) {
        const std::vector<std::byte> cut(font.begin(), font.begin() + static_cast<long>(font.size() * percent / 100));
        Result<BakeResult> baked = bake_font(cut, BakeOptions{});
        ASSERT_FALSE(baked) << percent;
        EXPECT_EQ(baked.error().code, ErrorCode::font_unreadable);
        EXPECT_NE(baked.error().message.find("' table ("), std::string::npos) << baked.error().message;
        EXPECT_NE(baked.error().message.find("the font is truncated"), std::string::npos) << baked.error().message;
    }
    const std::byte bare_cff[] = {std::byte{1}, std::byte{0}, std::byte{4}, std::byte{2}, std::byte{0}, std::byte{1}};
    const Status bare = check_font_container(bare_cff);
    ASSERT_FALSE(bare);
    EXPECT_EQ(bare.error().code, ErrorCode::font_unsupported);
    EXPECT_NE(bare.error().message.find("a bare CFF font"), std::string::npos) << bare.error().message;
    const std::byte zeros[16] = {};
    const Status none = check_font_container(zeros);
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().code, ErrorCode::font_unreadable);
    EXPECT_NE(none.error().message.find("not a TrueType or OpenType font: it starts with 0x00000000"),
              std::string::npos)
        << none.error().message;
    EXPECT_TRUE(check_font_container(font));
}

}  // namespace
}  // namespace crisp
