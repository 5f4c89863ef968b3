// The size of a TrueType glyph once its composite components are expanded, read from loca and glyf
// before FreeType loads it: FreeType expands a composite part by part, so thirty glyphs of
// 1000 x 1000 x 1000 empty parts (a 257 KB font) took 76 s and 2.1 GB to bake.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

struct FT_FaceRec_;

namespace crisp {

class CompositeBounds {
public:
    // Reads the table directory of face `face_index` of `font_bytes` (which outlive this) and
    // FreeType's `face` for the glyph count and loca format. A face without glyf and loca (CFF,
    // CFF2, bitmaps) has nothing to bound: check() passes every glyph.
    CompositeBounds(std::span<const std::byte> font_bytes, uint32_t face_index, FT_FaceRec_* face);

    // Why `glyph` must not be loaded: its components nest deeper than kMaxCompositeDepth, refer to
    // themselves, or expand to more than kMaxCompositeParts parts or kMaxGlyphPoints points
    // (include/crisp/bake.hpp); nullopt when it may. Each glyph's tree is walked once per bake.
    std::optional<std::string> check(uint32_t glyph);

    // Points that check() has passed so far (the budget kMaxBakePoints is spent on them).
    uint64_t points_passed() const { return points_passed_; }

private:
    struct Expansion {
        uint64_t points = 0;
        uint64_t parts = 0;   // component references in the tree, each reached as often as it is
        uint32_t height = 0;  // levels of composites below and including this glyph; 0 for a simple glyph
        bool cyclic = false;  // reaches itself
        bool done = false;
        bool visiting = false;
    };
    void expand(uint32_t glyph);
    std::span<const std::byte> glyph_bytes(uint32_t glyph) const;

    std::span<const std::byte> glyf_;
    std::span<const std::byte> loca_;
    bool long_loca_ = false;
    uint32_t glyph_count_ = 0;
    std::vector<Expansion> expansions_;
    uint64_t points_passed_ = 0;
};

}  // namespace crisp
