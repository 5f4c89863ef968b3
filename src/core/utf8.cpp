// UTF-8 decoding: the run time's (layout, the JSON reader) and the tools'.
#include "core/utf8.hpp"

namespace crisp {

namespace {

// Invalid input becomes U+FFFD, one per maximal ill-formed subpart (Unicode 15, 3.9 U+FFFD
// substitution), so a truncated sequence costs one replacement, not one per byte.
void decode(std::string_view text, std::vector<uint32_t>& codepoints, std::vector<uint32_t>* offsets) {
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    size_t i = 0;
    while (i < n) {
        const unsigned char b = s[i];
        if (offsets) offsets->push_back(static_cast<uint32_t>(i));
        if (b < 0x80) {
            codepoints.push_back(b);
            ++i;
            continue;
        }
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
            codepoints.push_back(0xFFFD);
            ++i;
            continue;
        }
        size_t j = i + 1;
        bool good = true;
        for (uint32_t k = 0; k < need; ++k, ++j) {
            if (j >= n || s[j] < lo || s[j] > hi) {
                good = false;
                break;
            }
            cp = (cp << 6) | (s[j] & 0x3Fu);
            lo = 0x80;
            hi = 0xBF;
        }
        codepoints.push_back(good ? cp : 0xFFFDu);
        i = j;
    }
    if (offsets) offsets->push_back(static_cast<uint32_t>(n));
}

}  // namespace

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

}  // namespace crisp
