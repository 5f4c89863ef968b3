// UTF-8 decoding and encoding, for layout's clusters, the JSON reader and the tools; text from an input made safe
// to print in a message.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace crisp {

// Decodes UTF-8 into code points. Invalid input becomes U+FFFD, one per maximal ill-formed subpart
// (Unicode 15, 3.9 U+FFFD substitution), so a truncated sequence costs one replacement, not one
// per byte.
std::vector<uint32_t> decode_utf8(std::string_view text);

// Appends `codepoint` (at most U+10FFFF; callers pass scalar values) to `out` as UTF-8.
void append_utf8(std::string& out, uint32_t codepoint);

// Decodes like decode_utf8 into `codepoints`, and the byte offset of every code point, plus a final
// entry holding text.size(), into `offsets` (both cleared first; their capacity is reused).
void decode_utf8_with_offsets(std::string_view text, std::vector<uint32_t>& codepoints, std::vector<uint32_t>& offsets);

// `text` (a name, a path, a key, a tag from an input) as a message shows it: control characters
// (C0 and DEL as \xNN, C1 as \u{80} to \u{9f}), which could move a terminal's cursor or set its
// title, the bidirectional controls and line separators (as \u{202e}, ...), and a backslash
// (\x5c) are escaped, and so is each byte of ill-formed UTF-8 (\xff); the rest of UTF-8 is kept.
// Longer than `max` characters as shown, it keeps its start and its end around "...", `max` in
// all (the end of a path is its file name), reading only about `max` bytes of each end.
std::string printable(std::string_view text, size_t max = 80);

// What printable() keeps of a path: a deep but real one is a few hundred characters.
inline constexpr size_t kPrintablePath = 512;

}  // namespace crisp
