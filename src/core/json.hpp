// A small strict JSON reader and writer (RFC 8259) for crisp's layout and scene files.
//
// Safe for untrusted input: nesting is limited, numbers must be finite, strings must be valid
// UTF-8, and every syntax error names its line and column. Readers of the values name faults by
// their path ("runs[2].size").
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace crisp::json {

struct Value;
struct Member;
using Array = std::vector<Value>;
using Object = std::vector<Member>;  // in file order; duplicate names are an error

struct Value {
    enum class Type { null, boolean, number, string, array, object };
    Type type = Type::null;
    bool boolean = false;
    double number = 0.0;
    std::string string;
    Array array;
    Object object;

    // The member named `key`, or nullptr (also when this is not an object).
    const Value* find(std::string_view key) const;
    const char* type_name() const;
};

struct Member {
    std::string name;
    Value value;
};

inline constexpr size_t kMaxDepth = 64;

// Parses a whole document. Errors are ErrorCode::invalid_argument: "line 3, column 14: ...".
Result<Value> parse(std::string_view text);

// Appends `text` as a JSON string literal, quoted and escaped; ill-formed UTF-8 becomes U+FFFD.
void append_string(std::string& out, std::string_view text);
// `text` as a JSON string literal (append_string to an empty string).
std::string quote(std::string_view text);

// Appends a number in the shortest form that reads back to the same double.
void append_number(std::string& out, double value);

}  // namespace crisp::json
