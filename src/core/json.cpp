#include "core/json.hpp"

#include "core/utf8.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace crisp::json {

const Value* Value::find(std::string_view key) const {
    for (const auto& [name, value] : object) {
        if (name == key) return &value;
    }
    return nullptr;
}

const char* Value::type_name() const {
    switch (type) {
        case Type::null:
            return "null";
        case Type::boolean:
            return "a boolean";
        case Type::number:
            return "a number";
        case Type::string:
            return "a string";
        case Type::array:
            return "an array";
        case Type::object:
            return "an object";
    }
    return "?";
}

namespace {

// The character a one-letter JSON escape stands for ('n' for a newline), or '\0' for any other letter.
char simple_escape(char letter) {
    switch (letter) {
        case '"':
            return '"';
        case '\\':
            return '\\';
        case '/':
            return '/';
        case 'b':
            return '\b';
        case 'f':
            return '\f';
        case 'n':
            return '\n';
        case 'r':
            return '\r';
        case 't':
            return '\t';
        default:
            return '\0';
    }
}

class Parser {
public:
    explicit Parser(std::string_view text) : text_(text) {}

    Result<Value> document() {
        skip_space();
        Value value;
        if (!parse_value(value, 0)) return fail();
        skip_space();
        if (pos_ != text_.size()) {
            error_ = "unexpected text after the JSON value";
            return fail();
        }
        return value;
    }

private:
    Error fail() const {
        // Line and column of the error position, counted in bytes from 1.
        size_t line = 1, column = 1;
        for (size_t i = 0; i < pos_ && i < text_.size(); ++i) {
            if (text_[i] == '\n') {
                ++line;
                column = 1;
            } else {
                ++column;
            }
        }
        return Error{ErrorCode::invalid_argument,
                     "line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + error_};
    }

    bool at_end() const { return pos_ >= text_.size(); }
    char peek() const { return at_end() ? '\0' : text_[pos_]; }

    void skip_space() {
        while (!at_end() && (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r')) ++pos_;
    }

    bool literal(std::string_view word) {
        if (text_.substr(pos_, word.size()) != word) {
            error_ = "expected '" + std::string(word) + "'";
            return false;
        }
        pos_ += word.size();
        return true;
    }

    bool parse_value(Value& value, size_t depth) {
        if (depth > kMaxDepth) {
            error_ = "nested deeper than " + std::to_string(kMaxDepth) + " levels";
            return false;
        }
        switch (peek()) {
            case '{':
                return parse_object(value, depth);
            case '[':
                return parse_array(value, depth);
            case '"':
                value.type = Value::Type::string;
                return parse_string(value.string);
            case 't':
                value.type = Value::Type::boolean;
                value.boolean = true;
                return literal("true");
            case 'f':
                value.type = Value::Type::boolean;
                value.boolean = false;
                return literal("false");
            case 'n':
                value.type = Value::Type::null;
                return literal("null");
            default:
                if (peek() == '-' || (peek() >= '0' && peek() <= '9')) return parse_number(value);
                error_ = at_end() ? "unexpected end of text"
                                  : "unexpected character '" + printable(text_.substr(pos_, 1)) + "'";
                return false;
        }
    }

    bool parse_number(Value& value) {
        const size_t start = pos_;
        if (peek() == '-') ++pos_;
        if (peek() == '0') {
            ++pos_;
        } else if (peek() >= '1' && peek() <= '9') {
            while (peek() >= '0' && peek() <= '9') ++pos_;
        } else {
            error_ = "malformed number";
            return false;
        }
        if (peek() == '.') {
            ++pos_;
            if (!(peek() >= '0' && peek() <= '9')) {
                error_ = "malformed number: no digit after '.'";
                return false;
            }
            while (peek() >= '0' && peek() <= '9') ++pos_;
        }
        if (peek() == 'e' || peek() == 'E') {
            ++pos_;
            if (peek() == '+' || peek() == '-') ++pos_;
            if (!(peek() >= '0' && peek() <= '9')) {
                error_ = "malformed number: no digit in the exponent";
                return false;
            }
            while (peek() >= '0' && peek() <= '9') ++pos_;
        }
        double number = 0.0;
        const auto [end, ec] = std::from_chars(text_.data() + start, text_.data() + pos_, number);
        if (ec != std::errc() || end != text_.data() + pos_ || !std::isfinite(number)) {
            pos_ = start;
            error_ = "number out of range";
            return false;
        }
        value.type = Value::Type::number;
        value.number = number;
        return true;
    }

    bool hex4(uint32_t& value) {
        value = 0;
        for (int i = 0; i < 4; ++i) {
            const char c = peek();
            uint32_t digit = 0;
            if (c >= '0' && c <= '9')
                digit = static_cast<uint32_t>(c - '0');
            else if (c >= 'a' && c <= 'f')
                digit = static_cast<uint32_t>(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F')
                digit = static_cast<uint32_t>(c - 'A' + 10);
            else {
                error_ = "malformed \\u escape";
                return false;
            }
            value = value * 16 + digit;
            ++pos_;
        }
        return true;
    }

    // Length of the valid UTF-8 sequence at pos_, or 0.
    size_t utf8_length() const {
        const auto* s = reinterpret_cast<const unsigned char*>(text_.data());
        const size_t n = text_.size(), i = pos_;
        const unsigned char b = s[i];
        size_t need = 0;
        unsigned char lo = 0x80, hi = 0xBF;
        if (b >= 0xC2 && b <= 0xDF)
            need = 1;
        else if (b >= 0xE0 && b <= 0xEF) {
            need = 2;
            if (b == 0xE0) lo = 0xA0;
            if (b == 0xED) hi = 0x9F;
        } else if (b >= 0xF0 && b <= 0xF4) {
            need = 3;
            if (b == 0xF0) lo = 0x90;
            if (b == 0xF4) hi = 0x8F;
        } else
            return 0;
        for (size_t k = 1; k <= need; ++k) {
            if (i + k >= n || s[i + k] < lo || s[i + k] > hi) return 0;
            lo = 0x80;
            hi = 0xBF;
        }
        return need + 1;
    }

    bool parse_string(std::string& out) {
        ++pos_;  // the opening quote
        while (true) {
            if (at_end()) {
                error_ = "unterminated string";
                return false;
            }
            const auto c = static_cast<unsigned char>(peek());
            if (c == '"') {
                ++pos_;
                return true;
            }
            if (c < 0x20) {
                error_ = "control character in a string";
                return false;
            }
            if (c == '\\') {
                if (!parse_escape(out)) return false;
                continue;
            }
            if (c < 0x80) {
                out += static_cast<char>(c);
                ++pos_;
                continue;
            }
            const size_t length = utf8_length();
            if (length == 0) {
                error_ = "invalid UTF-8 in a string";
                return false;
            }
            out.append(text_.substr(pos_, length));
            pos_ += length;
        }
    }

    // Appends what the escape at pos_ (its backslash) stands for, and moves past it.
    bool parse_escape(std::string& out) {
        ++pos_;
        const char e = peek();
        ++pos_;
        if (e == 'u') return parse_unicode_escape(out);
        const char unescaped = simple_escape(e);
        if (unescaped == '\0') {
            --pos_;
            error_ = "unknown escape";
            return false;
        }
        out += unescaped;
        return true;
    }

    // Appends as UTF-8 the code point of a \uXXXX escape whose hex digits start at pos_, joining a
    // surrogate pair written as two escapes.
    bool parse_unicode_escape(std::string& out) {
        uint32_t cp = 0;
        if (!hex4(cp)) return false;
        if (cp >= 0xD800 && cp <= 0xDBFF) {
            uint32_t low = 0;
            if (peek() != '\\' || text_.substr(pos_, 2) != "\\u") {
                error_ = "a high surrogate without its low surrogate";
                return false;
            }
            pos_ += 2;
            if (!hex4(low)) return false;
            if (low < 0xDC00 || low > 0xDFFF) {
                error_ = "a high surrogate without its low surrogate";
                return false;
            }
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
        } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            error_ = "a lone low surrogate";
            return false;
        }
        append_utf8(out, cp);
        return true;
    }

    bool parse_array(Value& value, size_t depth) {
        value.type = Value::Type::array;
        ++pos_;
        skip_space();
        if (peek() == ']') {
            ++pos_;
            return true;
        }
        while (true) {
            skip_space();
            value.array.emplace_back();
            if (!parse_value(value.array.back(), depth + 1)) return false;
            skip_space();
            if (peek() == ',') {
                ++pos_;
                continue;
            }
            if (peek() == ']') {
                ++pos_;
                return true;
            }
            error_ = "expected ',' or ']' in an array";
            return false;
        }
    }

    bool parse_object(Value& value, size_t depth) {
        value.type = Value::Type::object;
        ++pos_;
        skip_space();
        if (peek() == '}') {
            ++pos_;
            return true;
        }
        while (true) {
            skip_space();
            if (peek() != '"') {
                error_ = "expected a member name in quotes";
                return false;
            }
            std::string key;
            const size_t key_pos = pos_;
            if (!parse_string(key)) return false;
            if (value.find(key)) {
                pos_ = key_pos;
                error_ = "duplicate member \"" + printable(key) + "\"";
                return false;
            }
            skip_space();
            if (peek() != ':') {
                error_ = "expected ':' after a member name";
                return false;
            }
            ++pos_;
            skip_space();
            value.object.push_back(Member{std::move(key), Value{}});
            if (!parse_value(value.object.back().value, depth + 1)) return false;
            skip_space();
            if (peek() == ',') {
                ++pos_;
                continue;
            }
            if (peek() == '}') {
                ++pos_;
                return true;
            }
            error_ = "expected ',' or '}' in an object";
            return false;
        }
    }

    std::string_view text_;
    size_t pos_ = 0;
    std::string error_;
};

}  // namespace

Result<Value> parse(std::string_view text) {
    return Parser(text).document();
}

void append_string(std::string& out, std::string_view text) {
    // Decoded first, so ill-formed UTF-8 (a file name, say) becomes U+FFFD and the output stays
    // valid JSON.
    out += '"';
    for (const uint32_t c : decode_utf8(text)) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += static_cast<char>(c);
        } else if (c < 0x20 || c == 0x7F) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
            out += buffer;
        } else {
            append_utf8(out, c);
        }
    }
    out += '"';
}

std::string quote(std::string_view text) {
    std::string out;
    append_string(out, text);
    return out;
}

void append_number(std::string& out, double value) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, ec == std::errc() ? end : buffer);
}

}  // namespace crisp::json
