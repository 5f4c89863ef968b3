// Shared by crisp's command-line tools: strict number parsing.
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

namespace crisp::cli {

// The whole of `text` as a number of type T; nullopt when it is empty, malformed, has trailing
// characters, is out of T's range (for floating point: its magnitude too large or too small for
// T, other than zero), or is not finite. `why`, when given, receives the reason as a phrase ("is
// not a number", "is out of range for a 32-bit float", ...).
template <class T>
std::optional<T> parse_number(std::string_view text, std::string* why = nullptr) {
    auto refuse = [&](const char* reason) -> std::optional<T> {
        if (why) *why = reason;
        return std::nullopt;
    };
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || (ec != std::errc() && ec != std::errc::result_out_of_range) ||
        end != text.data() + text.size()) {
        return refuse("is not a number");
    }
    if (ec == std::errc::result_out_of_range) {
        if constexpr (std::is_same_v<T, float>) return refuse("is out of range for a 32-bit float");
        if constexpr (std::is_same_v<T, double>) return refuse("is out of range for a 64-bit float");
        return refuse("is out of range");
    }
    if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(value)) return refuse("is not finite");
    }
    return value;
}

// `text` safe to print on a terminal: control characters (C0, DEL, and the C1 controls U+0080 to
// U+009F in UTF-8), which could move the cursor or set the window title, become \xNN escapes, and
// so does a backslash; everything else, UTF-8 included, is kept.
inline std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    auto escape = [&](unsigned char byte) {
        static constexpr char kHex[] = "0123456789abcdef";
        out += "\\x";
        out += kHex[byte >> 4];
        out += kHex[byte & 15];
    };
    for (size_t i = 0; i < text.size(); ++i) {
        const auto byte = static_cast<unsigned char>(text[i]);
        const bool c1 = byte == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
                        static_cast<unsigned char>(text[i + 1]) <= 0x9F;
        if (c1) {
            escape(byte);
            escape(static_cast<unsigned char>(text[++i]));
        } else if (byte < 0x20 || byte == 0x7F || byte == '\\') {
            escape(byte);
        } else {
            out += text[i];
        }
    }
    return out;
}

}  // namespace crisp::cli
