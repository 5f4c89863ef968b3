// Shared by crisp's command-line tools: strict number parsing, and the option table that gives a
// tool both its parsing and its --help.
#pragma once

#include <crisp/result.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace crisp::cli {

// The whole of `text` as a number of type T; nullopt when it is empty, malformed, has trailing
// characters, is out of T's range (for floating point: its magnitude too large or too small for
// T, subnormal included, other than zero; for an unsigned T: negative), or is not finite. `why`,
// when given, receives the reason as a phrase ("is not a number", "is out of range for a 32-bit
// float (too large)", "is negative", ...).
template <class T>
std::optional<T> parse_number(std::string_view text, std::string* why = nullptr) {
    auto refuse = [&](std::string reason) -> std::optional<T> {
        if (why) *why = std::move(reason);
        return std::nullopt;
    };
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    const bool whole = !text.empty() && end == text.data() + text.size();
    if constexpr (std::is_unsigned_v<T>) {
        long long negative = 0;
        const auto [signed_end, signed_ec] = std::from_chars(text.data(), text.data() + text.size(), negative);
        if (!text.empty() && text.front() == '-' && signed_end == text.data() + text.size() &&
            signed_ec != std::errc::invalid_argument) {
            return refuse("is negative");
        }
    }
    if (!whole || (ec != std::errc() && ec != std::errc::result_out_of_range)) return refuse("is not a number");
    if constexpr (std::is_floating_point_v<T>) {
        const char* type = std::is_same_v<T, float> ? "a 32-bit float" : "a 64-bit float";
        if (ec == std::errc::result_out_of_range) {
            // Which end it passed: the magnitude in a wider type (past even that, it is too large
            // or too small for any, and the exponent's sign says which).
            long double wide = 0;
            const auto wide_ec = std::from_chars(text.data(), text.data() + text.size(), wide).ec;
            const size_t exponent = text.find_first_of("eE");
            const bool small = wide_ec == std::errc()
                                   ? std::fabs(wide) < 1.0L
                                   : exponent != std::string_view::npos && text.substr(exponent + 1).starts_with('-');
            return refuse(std::string("is out of range for ") + type + (small ? " (too small)" : " (too large)"));
        }
        if (!std::isfinite(value)) return refuse("is not finite");
        if (value != 0 && std::fabs(value) < std::numeric_limits<T>::min()) {
            return refuse(std::string("is out of range for ") + type + " (too small)");
        }
    } else {
        if (ec == std::errc::result_out_of_range) return refuse("is out of range");
    }
    return value;
}

// `text` from an input as a message shows it: crisp::printable (src/core/utf8.hpp), for the tools
// that do not see src/: control characters, bidirectional controls, a backslash and ill-formed
// UTF-8 escaped, and longer than `max` characters shortened around "...".
std::string printable(std::string_view text, size_t max = 80);
// A path so: printable at crisp::kPrintablePath characters.
std::string printable_path(std::string_view path);

// `text` cut at every `separator`: "a,,b" is {"a", "", "b"}; "" is {""}.
std::vector<std::string_view> split(std::string_view text, char separator);

// The numbers of a `separator`-separated list, each as parse_number reads it; an error
// (ErrorCode::invalid_argument) names `option`, the item and why.
template <class T>
Result<std::vector<T>> parse_number_list(std::string_view option, std::string_view text, char separator = ',') {
    std::vector<T> values;
    for (const std::string_view item : split(text, separator)) {
        std::string why;
        const std::optional<T> value = parse_number<T>(item, &why);
        if (!value) {
            return Error{ErrorCode::invalid_argument, std::string(option) + ": '" + printable(item) + "' " + why};
        }
        values.push_back(*value);
    }
    return values;
}

// The closed range a number option takes, or (low, high] with `low_open`; `unit` follows it in the
// error ("--size must be in (0, 4096] pixels per em").
template <class T>
struct Range {
    T low;
    T high;
    bool low_open = false;
    const char* unit = "";
};

// A tool's command line, declared once: each option with its value's name, its help text and
// what it does with its value. The same table parses argv and prints --help, so the two cannot
// disagree. -h and --help are built in: they print the help on stdout and exit 0. A usage error
// prints "PROGRAM: MESSAGE" and the tool's hint on stderr and exits with the tool's usage code.
//
//     crisp::cli::CommandLine cli("crisp-bake", "usage: crisp-bake FONT [options]\n...");
//     cli.number("--face", "N", "face N of a collection (.ttc); default 0", args.face);
//     cli.parse(argc, argv);
class CommandLine {
public:
    // What an option does with its value (flags get ""); an error is a usage error, its message
    // printed as it is.
    using Apply = std::function<Status(std::string_view value)>;

    // `synopsis`: what --help prints before the options (the usage lines and what the tool does),
    // ending in a newline.
    CommandLine(std::string program, std::string synopsis);

    // How a usage error ends: `hint` is printed after the message (for example
    // "\n(run crisp-bake --help for usage)"); `full_help` prints the whole --help on stderr
    // instead; the process exits with `exit_code`.
    CommandLine& on_usage_error(int exit_code, std::string hint, bool full_help = false);
    // A heading over the options declared after it ("options:"), and text after all options
    // (the exit codes).
    CommandLine& section(std::string heading);
    CommandLine& epilogue(std::string text);

    // `names`: "--face" or "-o, --output" (every comma-separated name selects the option).
    // `help`: lines after the first are indented under it.
    CommandLine& flag(std::string names, std::string help, bool& target, bool value = true);
    CommandLine& flag(std::string names, std::string help, std::function<void()> apply);
    CommandLine& text(std::string names, std::string value_name, std::string help, std::string& target);
    CommandLine& text(std::string names, std::string value_name, std::string help, std::optional<std::string>& target);
    // Repeatable: every value is appended.
    CommandLine& repeated(std::string names, std::string value_name, std::string help,
                          std::vector<std::string>& target);
    // UTF-8 text whose code points are appended to `target` (ill-formed bytes become U+FFFD).
    CommandLine& codepoints(std::string names, std::string value_name, std::string help, std::vector<uint32_t>& target);
    CommandLine& option(std::string names, std::string value_name, std::string help, Apply apply);

    // A number as parse_number reads it, within `range` when one is given. `target`: a T or a
    // std::optional<T>.
    template <class T, class Target>
    CommandLine& number(std::string names, std::string value_name, std::string help, Target& target) {
        return number_option<T>(std::move(names), std::move(value_name), std::move(help), target, std::nullopt);
    }
    template <class T, class Target>
    CommandLine& number(std::string names, std::string value_name, std::string help, Target& target, Range<T> range) {
        return number_option<T>(std::move(names), std::move(value_name), std::move(help), target, range);
    }

    // One of `values`, named by `name` ("--composite takes tiled, draw or exact, not 'x'").
    template <class E>
    CommandLine& choice(std::string names, std::string value_name, std::string help, E& target, std::vector<E> values,
                        std::function<std::string(const E&)> name) {
        const std::string option_name = last_name(names);
        return option(std::move(names), std::move(value_name), std::move(help),
                      [&target, values, name, option_name](std::string_view text) -> Status {
                          std::vector<std::string> names_of;
                          for (const E& value : values) {
                              names_of.push_back(name(value));
                              if (names_of.back() == text) {
                                  target = value;
                                  return {};
                              }
                          }
                          return Error{ErrorCode::invalid_argument, not_one_of(option_name, names_of, text)};
                      });
    }
    CommandLine& choice(std::string names, std::string value_name, std::string help, std::string& target,
                        std::vector<std::string> values);

    // Arguments that are not options, in order; without it, any is a usage error.
    CommandLine& positional(Apply apply);

    // Reads argv, applying each option in order; exits on --help or a usage error.
    void parse(int argc, char** argv);
    // Whether the option named `name` (any of its names) was on the command line.
    bool given(std::string_view name) const;
    // A usage error found after parse() (options that exclude each other, a missing one).
    [[noreturn]] void fail(const std::string& message) const;
    // The --help text.
    std::string help() const;

    // "OPTION must be in LOW..HIGH" (or "(LOW, HIGH]", or "at least LOW" where HIGH is T's
    // largest value), with the range's unit.
    template <class T>
    static std::string out_of_range(std::string_view option, const Range<T>& range) {
        if (range.high == std::numeric_limits<T>::max() && !range.low_open) {
            return std::string(option) + " must be at least " + std::to_string(range.low) + range.unit;
        }
        return range_message(option, static_cast<double>(range.low), static_cast<double>(range.high), range.low_open,
                             range.unit);
    }
    // parse_number's value of `text`, within `range` if any; errors name `option`.
    template <class T>
    static Result<T> checked_number(std::string_view option, std::string_view text,
                                    const std::optional<Range<T>>& range) {
        std::string why;
        const std::optional<T> value = parse_number<T>(text, &why);
        if (!value)
            return Error{ErrorCode::invalid_argument, std::string(option) + ": '" + printable(text) + "' " + why};
        if (range && !((range->low_open ? *value > range->low : *value >= range->low) && *value <= range->high)) {
            return Error{ErrorCode::invalid_argument, out_of_range(option, *range)};
        }
        return *value;
    }

private:
    template <class T, class Target>
    CommandLine& number_option(std::string names, std::string value_name, std::string help, Target& target,
                               std::optional<Range<T>> range) {
        const std::string option_name = last_name(names);
        return option(std::move(names), std::move(value_name), std::move(help),
                      [&target, range, option_name](std::string_view text) -> Status {
                          Result<T> value = checked_number<T>(option_name, text, range);
                          if (!value) return value.error();
                          target = *value;
                          return {};
                      });
    }

    struct Entry {
        std::string names;       // empty: a section heading, in `help`
        std::string value_name;  // empty: a flag
        std::string help;
        Apply apply;
        bool given = false;
    };
    static std::string last_name(std::string_view names);
    static std::string not_one_of(std::string_view option, const std::vector<std::string>& names,
                                  std::string_view text);
    static std::string range_message(std::string_view option, double low, double high, bool low_open, const char* unit);
    Entry* find(std::string_view name);
    const Entry* find(std::string_view name) const;

    std::string program_;
    std::string synopsis_;
    std::string epilogue_;
    std::string hint_;
    int usage_exit_code_ = 2;
    bool full_help_on_error_ = false;
    std::vector<Entry> entries_;
    Apply positional_;
};

}  // namespace crisp::cli
