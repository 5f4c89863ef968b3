#include "bake/composite.hpp"

#include <crisp/bake.hpp>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_TRUETYPE_TABLES_H

#include <algorithm>

namespace crisp {

namespace {

uint32_t read_u16(std::span<const std::byte> bytes, size_t at) {
    return (std::to_integer<uint32_t>(bytes[at]) << 8) | std::to_integer<uint32_t>(bytes[at + 1]);
}

uint32_t read_u32(std::span<const std::byte> bytes, size_t at) {
    return (read_u16(bytes, at) << 16) | read_u16(bytes, at + 2);
}

// The table `tag` of the face at `face_index` (a collection's 'ttcf' header lists each face's
// directory), or an empty span where it is absent or does not fit the bytes.
std::span<const std::byte> find_table(std::span<const std::byte> bytes, uint32_t face_index, uint32_t tag) {
    size_t directory = 0;
    if (bytes.size() >= 12 && read_u32(bytes, 0) == make_tag("ttcf")) {
        const uint32_t faces = read_u32(bytes, 8);
        if (face_index >= faces || 12 + 4 * size_t{face_index} + 4 > bytes.size()) return {};
        directory = read_u32(bytes, 12 + 4 * size_t{face_index});
    }
    if (directory > bytes.size() || bytes.size() - directory < 12) return {};
    const uint32_t tables = read_u16(bytes, directory + 4);
    for (uint32_t i = 0; i < tables; ++i) {
        const size_t record = directory + 12 + 16 * size_t{i};
        if (record + 16 > bytes.size()) return {};
        if (read_u32(bytes, record) != tag) continue;
        const uint32_t offset = read_u32(bytes, record + 8), length = read_u32(bytes, record + 12);
        if (offset > bytes.size() || length > bytes.size() - offset) return {};
        return bytes.subspan(offset, length);
    }
    return {};
}

// Component flags (OpenType glyf): what follows a component's glyph index.
constexpr uint32_t kArgsAreWords = 0x0001;
constexpr uint32_t kHaveScale = 0x0008;
constexpr uint32_t kMoreComponents = 0x0020;
constexpr uint32_t kHaveXYScale = 0x0040;
constexpr uint32_t kHaveTwoByTwo = 0x0080;

// Sums saturate here: far past every limit, and far from overflow.
constexpr uint64_t kSaturated = uint64_t{1} << 48;

uint64_t saturating_add(uint64_t a, uint64_t b) {
    return std::min(a + b, kSaturated);
}

}  // namespace

CompositeBounds::CompositeBounds(std::span<const std::byte> font_bytes, uint32_t face_index, FT_Face face) {
    const auto* head = static_cast<const TT_Header*>(FT_Get_Sfnt_Table(face, FT_SFNT_HEAD));
    glyf_ = find_table(font_bytes, face_index, make_tag("glyf"));
    loca_ = find_table(font_bytes, face_index, make_tag("loca"));
    if (!head || glyf_.empty() || loca_.empty()) {
        glyf_ = loca_ = {};
        return;
    }
    long_loca_ = head->Index_To_Loc_Format != 0;
    glyph_count_ = static_cast<uint32_t>(face->num_glyphs);
    expansions_.resize(glyph_count_);
}

// A glyph's bytes as FreeType finds them: an end past glyf (or before the start) reads to glyf's
// end, so the walk below sees at least what FreeType may; a start past glyf is an empty glyph.
std::span<const std::byte> CompositeBounds::glyph_bytes(uint32_t glyph) const {
    const size_t entry = long_loca_ ? 4 : 2;
    if ((size_t{glyph} + 2) * entry > loca_.size()) return {};
    const auto offset = [&](uint32_t i) -> uint64_t {
        return long_loca_ ? read_u32(loca_, i * entry) : uint64_t{2} * read_u16(loca_, i * entry);
    };
    const uint64_t start = offset(glyph);
    uint64_t end = offset(glyph + 1);
    if (start >= glyf_.size()) return {};
    if (end > glyf_.size() || end < start) end = glyf_.size();
    return glyf_.subspan(start, end - start);
}

// Walks the glyph's component tree depth first with a stack of its own (a chain of 65,535
// composites must not recurse 65,535 deep), each glyph expanded once and remembered.
void CompositeBounds::expand(uint32_t root) {
    struct Frame {
        uint32_t glyph;
        size_t next;  // byte of its next component record in glyph_bytes()
    };
    std::vector<Frame> stack;
    const auto absorb = [](Expansion& into, const Expansion& part) {
        into.points = saturating_add(into.points, part.points);
        into.parts = saturating_add(into.parts, part.parts);
        into.height = std::max(into.height, part.height + 1);
        into.cyclic = into.cyclic || part.cyclic;
    };
    const auto enter = [&](uint32_t glyph) {
        Expansion& e = expansions_[glyph];
        e.visiting = true;
        const std::span<const std::byte> bytes = glyph_bytes(glyph);
        if (bytes.size() < 10) {
            e.done = true;  // an empty glyph, or one FreeType refuses
            e.visiting = false;
            return;
        }
        const auto contours = static_cast<int16_t>(read_u16(bytes, 0));
        if (contours >= 0) {
            // Its points are one past its last contour's end point.
            const size_t last = 10 + 2 * static_cast<size_t>(contours) - 2;
            if (contours > 0 && last + 2 <= bytes.size()) e.points = read_u16(bytes, last) + uint64_t{1};
            e.done = true;
            e.visiting = false;
            return;
        }
        e.height = 1;
        stack.push_back({glyph, 10});
    };
    enter(root);
    while (!stack.empty()) {
        Frame& frame = stack.back();
        Expansion& parent = expansions_[frame.glyph];
        const std::span<const std::byte> bytes = glyph_bytes(frame.glyph);
        if (frame.next + 4 > bytes.size() || parent.cyclic) {
            parent.done = true;
            parent.visiting = false;
            stack.pop_back();
            if (!stack.empty()) absorb(expansions_[stack.back().glyph], parent);
            continue;
        }
        const uint32_t flags = read_u16(bytes, frame.next), child = read_u16(bytes, frame.next + 2);
        size_t size = 4 + ((flags & kArgsAreWords) ? 4 : 2);
        size += (flags & kHaveScale) ? 2 : (flags & kHaveXYScale) ? 4 : (flags & kHaveTwoByTwo) ? 8 : 0;
        // The last component ends the walk: a record past the glyph's bytes is one FreeType refuses.
        frame.next = (flags & kMoreComponents) ? frame.next + size : bytes.size();
        parent.parts = saturating_add(parent.parts, 1);
        if (child >= glyph_count_) continue;  // FreeType refuses the glyph
        Expansion& below = expansions_[child];
        if (below.visiting) {
            parent.cyclic = true;
            continue;
        }
        if (!below.done) enter(child);          // a composite is pushed (and absorbed when it is popped)
        if (below.done) absorb(parent, below);  // no push: `parent` still holds
    }
}

std::optional<std::string> CompositeBounds::check(uint32_t glyph) {
    if (glyph >= glyph_count_) return std::nullopt;
    if (!expansions_[glyph].done) expand(glyph);
    const Expansion& e = expansions_[glyph];
    if (e.cyclic) return "a composite glyph that contains itself";
    if (e.height > kMaxCompositeDepth) {
        return "composite components nested " + std::to_string(e.height) + " deep, more than the limit of " +
               std::to_string(kMaxCompositeDepth);
    }
    if (e.parts > kMaxCompositeParts) {
        return "a composite of " + (e.parts >= kSaturated ? "over 2^48" : std::to_string(e.parts)) +
               " parts, more than the limit of " + std::to_string(kMaxCompositeParts);
    }
    if (e.points > kMaxGlyphPoints) {
        return (e.points >= kSaturated ? "over 2^48" : std::to_string(e.points)) + " points, more than the limit of " +
               std::to_string(kMaxGlyphPoints);
    }
    if (points_passed_ + e.points > kMaxBakePoints) {
        return "its " + std::to_string(e.points) + " points would take the glyphs baked to more than the limit of " +
               std::to_string(kMaxBakePoints) + " points in one bake";
    }
    points_passed_ += e.points;
    return std::nullopt;
}

}  // namespace crisp
