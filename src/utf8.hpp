// UTF-8 decoding with byte offsets, for layout's clusters.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace crisp {

// Decodes like crisp::decode_utf8 (one U+FFFD per maximal ill-formed subpart) into `codepoints`,
// and the byte offset of every code point, plus a final entry holding text.size(), into `offsets`
// (both cleared first; their capacity is reused).
void decode_utf8_with_offsets(std::string_view text, std::vector<uint32_t>& codepoints,
                              std::vector<uint32_t>& offsets);

}  // namespace crisp
