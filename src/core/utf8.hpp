// UTF-8 decoding, for layout's clusters, the JSON reader and the tools.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace crisp {

// Decodes UTF-8 into code points. Invalid input becomes U+FFFD, one per maximal ill-formed subpart
// (Unicode 15, 3.9 U+FFFD substitution), so a truncated sequence costs one replacement, not one
// per byte.
std::vector<uint32_t> decode_utf8(std::string_view text);

// Decodes like decode_utf8 into `codepoints`, and the byte offset of every code point, plus a final
// entry holding text.size(), into `offsets` (both cleared first; their capacity is reused).
void decode_utf8_with_offsets(std::string_view text, std::vector<uint32_t>& codepoints, std::vector<uint32_t>& offsets);

}  // namespace crisp
