// The limits crisp puts on its inputs, so that a small or hostile input cannot take minutes or
// gigabytes (docs/limits.md lists each with its reason). Each is checked where the input is read,
// and passing it is an error that names the limit.
#pragma once

#include <cstdint>

namespace crisp::limits {

// Bytes read from one file, by kind. Only regular files are read (a device, FIFO or socket has
// no size to check before reading, and /dev/zero never ends).
// The largest fonts in use are pan-CJK collections of about 100 MiB (Noto Sans CJK: 20-60 MiB).
inline constexpr uint64_t kFontFileBytes = uint64_t{256} << 20;
// An asset holds its font's bytes and its curves and bands: a full CJK face bakes to a few times
// its font's size.
inline constexpr uint64_t kAssetFileBytes = uint64_t{1} << 30;
// A subpixel layout file is three rectangles: a few hundred bytes.
inline constexpr uint64_t kLayoutFileBytes = uint64_t{1} << 20;
// A scene file lists runs of text: 64 MiB is hundreds of thousands of runs.
inline constexpr uint64_t kSceneFileBytes = uint64_t{64} << 20;
// A PFM coverage image of the largest canvas, 16384 x 16384 x 3 floats, plus its header.
inline constexpr uint64_t kImageFileBytes = uint64_t{16384} * 16384 * 3 * 4 + 4096;

// Curves of one glyph's stroke pieces (src/text/stroke.hpp): a glyph of a few hundred curves
// stroked at a quarter em makes a few thousand; each is tested by every sample of its bands.
inline constexpr uint32_t kMaxStrokeCurves = 65536;
// Curves of all layers of one colour glyph whose silhouette an effect outlines (the union of the
// layers, src/text/boundary.cpp, tests every piece against every curve): emoji have a few hundred.
inline constexpr uint32_t kMaxSilhouetteCurves = 8192;
// A stroke's half-width in em: an outline 8 em wide is far past any effect's use, and its pieces
// would reach far outside the glyph's rect.
inline constexpr double kMaxStrokeHalfWidthEm = 4.0;

}  // namespace crisp::limits
