// Shared by crisp's command-line tools: strict number parsing.
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <type_traits>

namespace crisp::cli {

// The whole of `text` as a number of type T; nullopt when it is empty, malformed, has trailing
// characters, is out of T's range, or (for floating point) is not finite.
template <class T>
std::optional<T> parse_number(std::string_view text) {
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
    if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(value)) return std::nullopt;
    }
    return value;
}

}  // namespace crisp::cli
