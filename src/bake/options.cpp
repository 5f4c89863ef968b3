// Small text parsers of the baker's options, shared with the tools: code point ranges, axis values,
// tags.
#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>

namespace crisp {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

// `base` is 10, or 16 for the end of a range whose start was written in hex (U+0041-005A).
bool parse_codepoint(std::string_view s, uint32_t& value, int& base) {
    s = trim(s);
    if (s.size() > 2 &&
        (s.substr(0, 2) == "U+" || s.substr(0, 2) == "u+" || s.substr(0, 2) == "0x" || s.substr(0, 2) == "0X")) {
        s.remove_prefix(2);
        base = 16;
    }
    if (s.empty()) return false;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value, base);
    return ec == std::errc() && end == s.data() + s.size() && value <= 0x10FFFF;
}

}  // namespace

Result<std::vector<uint32_t>> parse_codepoint_ranges(std::string_view text) {
    std::vector<uint32_t> out;
    if (trim(text).empty()) return Error{ErrorCode::invalid_argument, "code point ranges: empty"};
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = std::min(text.find(',', start), text.size());
        const std::string_view item = trim(text.substr(start, comma - start));
        const size_t dash = item.find('-');
        uint32_t first = 0, last = 0;
        int base = 10;
        const bool ok = dash == std::string_view::npos ? parse_codepoint(item, first, base) && (last = first, true)
                                                       : parse_codepoint(item.substr(0, dash), first, base) &&
                                                             parse_codepoint(item.substr(dash + 1), last, base);
        if (!ok || first > last) {
            return Error{ErrorCode::invalid_argument,
                         "code point ranges: bad item '" + printable(item) +
                             "' (expected N, N-M, U+XXXX or 0xXXXX, at most U+10FFFF, first <= last)"};
        }
        if (out.size() + (last - first + 1) > 0x110000) {
            return Error{ErrorCode::invalid_argument, "code point ranges: too many code points"};
        }
        for (uint32_t cp = first; cp <= last; ++cp) out.push_back(cp);
        start = comma + 1;
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

uint32_t make_tag(std::string_view four_chars) {
    uint32_t tag = 0;
    for (size_t i = 0; i < 4; ++i) {
        const char c = i < four_chars.size() ? four_chars[i] : ' ';
        tag = (tag << 8) | static_cast<unsigned char>(c);
    }
    return tag;
}

std::string tag_to_string(uint32_t tag) {
    std::string s(4, ' ');
    for (int i = 0; i < 4; ++i) s[static_cast<size_t>(i)] = static_cast<char>((tag >> (24 - 8 * i)) & 0xFF);
    return s;
}

Result<Variation> parse_variation(std::string_view text) {
    const size_t equals = text.find('=');
    const std::string_view tag = equals == std::string_view::npos ? std::string_view{} : text.substr(0, equals);
    if (tag.empty() || tag.size() > 4 ||
        !std::all_of(tag.begin(), tag.end(), [](char c) { return c >= 0x20 && c <= 0x7E; })) {
        return Error{
            ErrorCode::invalid_argument,
            "variation '" + printable(text) + "': expected TAG=VALUE with a tag of 1 to 4 characters, e.g. wght=700"};
    }
    const std::string value_text(trim(text.substr(equals + 1)));
    float value = 0.0f;
    const auto [end, ec] = std::from_chars(value_text.data(), value_text.data() + value_text.size(), value);
    const bool whole = !value_text.empty() && end == value_text.data() + value_text.size();
    if (whole && ec == std::errc::result_out_of_range) {
        return Error{ErrorCode::invalid_argument, "variation '" + printable(text) + "': value '" +
                                                      printable(value_text) + "' is out of range for a 32-bit float"};
    }
    if (!whole || ec != std::errc() || !std::isfinite(value)) {
        return Error{ErrorCode::invalid_argument, "variation '" + printable(text) + "': value '" +
                                                      printable(value_text) + "' is not a finite number"};
    }
    return Variation{make_tag(tag), value};
}

}  // namespace crisp
