// A JSON document written in order, for the tools' reports: objects, arrays, keys and values with
// correct escaping, ", " between items and ": " after keys, on one line.
//
//     crisp::JsonWriter json;
//     json.begin_object().field("glyphs", 12).key("axes").begin_array().end_array().end_object();
//     std::puts(json.text().c_str());
#pragma once

#include <crisp/result.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace crisp {

class JsonWriter {
public:
    JsonWriter& begin_object();
    JsonWriter& end_object();
    JsonWriter& begin_array();
    JsonWriter& end_array();
    // The next member's name, in an object.
    JsonWriter& key(std::string_view name);

    // A value: a string (escaped; ill-formed UTF-8 becomes U+FFFD), a boolean, an integer (exact),
    // a floating-point number (the shortest form that reads back the same value of its type; null
    // if not finite), or null (an empty optional).
    JsonWriter& null();
    JsonWriter& value(std::string_view text);
    JsonWriter& value(const char* text) { return value(std::string_view(text)); }
    JsonWriter& value(const std::string& text) { return value(std::string_view(text)); }
    template <class T>
    requires std::is_arithmetic_v<T> JsonWriter& value(T number) {
        if constexpr (std::is_same_v<T, bool>) {
            return boolean(number);
        } else if constexpr (std::is_same_v<T, float>) {
            return real(number);
        } else if constexpr (std::is_floating_point_v<T>) {
            return real(static_cast<double>(number));
        } else if constexpr (std::is_signed_v<T>) {
            return integer(static_cast<int64_t>(number));
        } else {
            return unsigned_integer(static_cast<uint64_t>(number));
        }
    }
    template <class T>
    JsonWriter& value(const std::optional<T>& maybe) {
        return maybe ? value(*maybe) : null();
    }
    // An array of values.
    template <class T>
    JsonWriter& value(const std::vector<T>& values) {
        begin_array();
        for (const T& item : values) value(item);
        return end_array();
    }

    // key(name) then value(v).
    template <class T>
    JsonWriter& field(std::string_view name, const T& v) {
        key(name);
        return value(v);
    }

    // The document so far, and with a final newline.
    const std::string& text() const { return out_; }
    std::string line() const { return out_ + "\n"; }
    // Writes the document and a final newline to `path` atomically: flushed to a temporary file
    // and renamed over `path`; on failure (ErrorCode::io, naming the path) a file there is kept.
    Status write_file(const std::filesystem::path& path) const;

private:
    JsonWriter& boolean(bool b);
    JsonWriter& integer(int64_t n);
    JsonWriter& unsigned_integer(uint64_t n);
    JsonWriter& real(double n);
    JsonWriter& real(float n);  // the shortest form that reads back the same float: 0.9, not 0.899999976
    void before_value();

    std::string out_;
    std::vector<bool> first_;  // per open object or array: nothing written in it yet
    bool after_key_ = false;
};

}  // namespace crisp
