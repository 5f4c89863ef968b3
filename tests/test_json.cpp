#include "core/json.hpp"

#include <gtest/gtest.h>

#include <string>

namespace crisp {
namespace {

TEST(Json, ParsesDocuments) {
    auto value = json::parse(R"( {"a": [1, -2.5e3, true, false, null], "b": {"c": "x\u00e9\ud83d\ude00\n"}} )");
    ASSERT_TRUE(value) << value.error().message;
    const json::Value* a = value->find("a");
    ASSERT_TRUE(a && a->type == json::Value::Type::array && a->array.size() == 5);
    EXPECT_EQ(a->array[1].number, -2500.0);
    EXPECT_TRUE(a->array[2].boolean);
    EXPECT_EQ(a->array[4].type, json::Value::Type::null);
    EXPECT_EQ(value->find("b")->find("c")->string, "x\xC3\xA9\xF0\x9F\x98\x80\n");
    EXPECT_EQ(value->find("zzz"), nullptr);
}

TEST(Json, RejectsMalformedInputWithAPosition) {
    const struct {
        const char* text;
        const char* fragment;
    } cases[] = {
        {"", "unexpected end"},
        {"{", "expected a member name"},
        {"[1,]", "unexpected character ']'"},
        {"[1 2]", "expected ',' or ']'"},
        {"{\"a\" 1}", "expected ':'"},
        {"{\"a\": 1, \"a\": 2}", "duplicate member \"a\""},
        {"01", "unexpected text after"},
        {"1.", "no digit after '.'"},
        {"1e", "no digit in the exponent"},
        {"1e999", "out of range"},
        {"\"abc", "unterminated string"},
        {"\"a\x01\"", "control character"},
        {"\"\\x\"", "unknown escape"},
        {"\"\\ud800\"", "high surrogate"},
        {"\"\\udc00\"", "lone low surrogate"},
        {"\"\xC0\xAF\"", "invalid UTF-8"},
        {"tru", "expected 'true'"},
        {"[1]\n  x", "line 2, column 3"},
    };
    for (const auto& c : cases) {
        auto value = json::parse(c.text);
        ASSERT_FALSE(value) << c.text;
        EXPECT_EQ(value.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(value.error().message.find(c.fragment), std::string::npos) << c.text << ": " << value.error().message;
    }
}

TEST(Json, LimitsNesting) {
    EXPECT_TRUE(json::parse(std::string(json::kMaxDepth, '[') + std::string(json::kMaxDepth, ']')));
    auto deep = json::parse(std::string(100000, '['));
    ASSERT_FALSE(deep);
    EXPECT_NE(deep.error().message.find("nested deeper"), std::string::npos);
}

TEST(Json, WritesWhatItReads) {
    std::string out;
    json::append_string(out, "a\"b\\c\n\x01");
    out += ' ';
    json::append_number(out, 0.1);
    auto value = json::parse("[" + out.substr(0, out.find(' ')) + "," + out.substr(out.find(' ') + 1) + "]");
    ASSERT_TRUE(value) << out;
    EXPECT_EQ(value->array[0].string, "a\"b\\c\n\x01");
    EXPECT_EQ(value->array[1].number, 0.1);
    // Ill-formed UTF-8 becomes U+FFFD, so the output is still valid JSON.
    std::string bad;
    json::append_string(bad,
                        "a\xFF"
                        "b\xC3\xA9");
    EXPECT_EQ(bad,
              "\"a\xEF\xBF\xBD"
              "b\xC3\xA9\"");
    EXPECT_TRUE(json::parse(bad));
}

}  // namespace
}  // namespace crisp
