// UTF-8 decoding: the run time's (layout, the JSON reader) and the tools'; text made safe to print.
#include "core/utf8.hpp"

#include <algorithm>
#include <cstdio>

namespace crisp {

namespace {

// One code point of `s` from `i` (i < n): its value and length in bytes; an ill-formed sequence is
// its maximal ill-formed subpart (Unicode 15, 3.9), `good` false.
struct Decoded {
    uint32_t code_point;
    size_t length;
    bool good;
};

Decoded decode_at(const unsigned char* s, size_t n, size_t i) {
    const unsigned char b = s[i];
    if (b < 0x80) return {b, 1, true};
    uint32_t need = 0, cp = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (b >= 0xC2 && b <= 0xDF) {
        need = 1;
        cp = b & 0x1Fu;
    } else if (b >= 0xE0 && b <= 0xEF) {
        need = 2;
        cp = b & 0x0Fu;
        if (b == 0xE0) lo = 0xA0;
        if (b == 0xED) hi = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
        need = 3;
        cp = b & 0x07u;
        if (b == 0xF0) lo = 0x90;
        if (b == 0xF4) hi = 0x8F;
    } else {
        return {0xFFFD, 1, false};
    }
    size_t j = i + 1;
    for (uint32_t k = 0; k < need; ++k, ++j) {
        if (j >= n || s[j] < lo || s[j] > hi) return {0xFFFD, j - i, false};
        cp = (cp << 6) | (s[j] & 0x3Fu);
        lo = 0x80;
        hi = 0xBF;
    }
    return {cp, j - i, true};
}

// Invalid input becomes U+FFFD, one per maximal ill-formed subpart (Unicode 15, 3.9 U+FFFD
// substitution), so a truncated sequence costs one replacement, not one per byte.
void decode(std::string_view text, std::vector<uint32_t>& codepoints, std::vector<uint32_t>* offsets) {
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    for (size_t i = 0; i < n;) {
        if (offsets) offsets->push_back(static_cast<uint32_t>(i));
        const Decoded decoded = decode_at(s, n, i);
        codepoints.push_back(decoded.code_point);
        i += decoded.length;
    }
    if (offsets) offsets->push_back(static_cast<uint32_t>(n));
}

// Code points a terminal or a log would act on rather than show: C0, DEL and C1 controls (a
// cursor move, a new window title), the bidirectional controls that reorder the rest of a line,
// and the line and paragraph separators. A backslash too, so that an escape reads back as one.
bool needs_escape(uint32_t cp) {
    return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == '\\' || cp == 0x061C || cp == 0x200E || cp == 0x200F ||
           (cp >= 0x2028 && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
}

// Appends the code point at `i` as printable() shows it; returns its length in bytes.
size_t append_printable(std::string& out, const unsigned char* s, size_t n, size_t i) {
    static constexpr char kHex[] = "0123456789abcdef";
    const Decoded decoded = decode_at(s, n, i);
    if (!decoded.good || (decoded.code_point < 0x80 && needs_escape(decoded.code_point))) {
        for (size_t k = 0; k < decoded.length; ++k) {
            out += "\\x";
            out += kHex[s[i + k] >> 4];
            out += kHex[s[i + k] & 15];
        }
    } else if (needs_escape(decoded.code_point)) {
        char buffer[16];
        std::snprintf(buffer, sizeof buffer, "\\u{%x}", decoded.code_point);
        out += buffer;
    } else {
        out.append(reinterpret_cast<const char*>(s + i), decoded.length);
    }
    return decoded.length;
}

}  // namespace

void append_utf8(std::string& out, uint32_t codepoint) {
    if (codepoint < 0x80) {
        out += static_cast<char>(codepoint);
    } else if (codepoint < 0x800) {
        out += static_cast<char>(0xC0 | (codepoint >> 6));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    } else if (codepoint < 0x10000) {
        out += static_cast<char>(0xE0 | (codepoint >> 12));
        out += static_cast<char>(0x80 | ((codepoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (codepoint >> 18));
        out += static_cast<char>(0x80 | ((codepoint >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((codepoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    }
}

std::vector<uint32_t> decode_utf8(std::string_view text) {
    std::vector<uint32_t> out;
    out.reserve(text.size());
    decode(text, out, nullptr);
    return out;
}

void decode_utf8_with_offsets(std::string_view text, std::vector<uint32_t>& codepoints,
                              std::vector<uint32_t>& offsets) {
    codepoints.clear();
    offsets.clear();
    codepoints.reserve(text.size());
    offsets.reserve(text.size() + 1);
    decode(text, codepoints, &offsets);
}

std::string printable(std::string_view text, size_t max) {
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    std::string out;
    // Characters of `out` (its escapes count each of their characters): a code point each.
    const auto characters = [](std::string_view shown) {
        size_t count = 0;
        for (const char c : shown) count += (static_cast<unsigned char>(c) & 0xC0u) != 0x80u;
        return count;
    };
    const size_t kept = max > 3 ? max - 3 : 0;
    const size_t head_budget = (kept + 1) / 2, tail_budget = kept - head_budget;
    size_t head_end = 0, head_bytes = 0, shown = 0;  // in `out`, and in `text`, at the head's last whole piece
    size_t i = 0;
    while (i < n) {
        const size_t before = out.size();
        i += append_printable(out, s, n, i);
        shown += characters(std::string_view(out).substr(before));
        if (shown > max) break;
        if (shown <= head_budget) head_end = out.size(), head_bytes = i;
    }
    if (shown <= max) return out;
    out.resize(head_end);
    out += "...";
    // The end: from far enough back that it shows at least `tail_budget` characters (each is at
    // most four bytes), at the start of a sequence; only its last `tail_budget` are kept.
    size_t from = std::max(head_bytes, n - std::min(n, 4 * tail_budget + 3));
    for (size_t k = 0; k < 3 && from < n && from > head_bytes && (s[from] & 0xC0u) == 0x80u; ++k) ++from;
    std::string tail;
    std::vector<size_t> starts;  // in `tail`, of each piece
    while (from < n) {
        starts.push_back(tail.size());
        from += append_printable(tail, s, n, from);
    }
    size_t cut = tail.size(), tail_shown = 0;
    for (size_t k = starts.size(); k-- > 0;) {
        const size_t piece = characters(std::string_view(tail).substr(starts[k], cut - starts[k]));
        if (tail_shown + piece > tail_budget) break;
        tail_shown += piece;
        cut = starts[k];
    }
    out.append(tail, cut, std::string::npos);
    return out;
}

}  // namespace crisp
