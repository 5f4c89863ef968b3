// Morton (Z-order) codes for the glyph atlas's cells, and the transposed order (N-order) the
// atlas uses: consecutive indices 2k and 2k + 1 are vertical neighbours, so an aligned run of two
// cells is a 1x2 column, the shape of tall glyphs such as l, j and 1.
#pragma once

#include <cstdint>

namespace crisp {

struct CellCoord {
    uint32_t x = 0;
    uint32_t y = 0;
    friend bool operator==(const CellCoord&, const CellCoord&) = default;
};

// Moves bit i of the low 16 bits of v to bit 2i.
constexpr uint32_t morton_spread(uint32_t v) {
    v &= 0x0000FFFFu;
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

// Moves bit 2i of v to bit i; the inverse of morton_spread.
constexpr uint32_t morton_compact(uint32_t v) {
    v &= 0x55555555u;
    v = (v | (v >> 1)) & 0x33333333u;
    v = (v | (v >> 2)) & 0x0F0F0F0Fu;
    v = (v | (v >> 4)) & 0x00FF00FFu;
    v = (v | (v >> 8)) & 0x0000FFFFu;
    return v;
}

// Z-order: x in the even bits, y in the odd bits. Coordinates use their low 16 bits.
constexpr uint32_t morton_encode(CellCoord cell) {
    return morton_spread(cell.x) | (morton_spread(cell.y) << 1);
}
constexpr CellCoord morton_decode(uint32_t index) {
    return {morton_compact(index), morton_compact(index >> 1)};
}

// N-order (transposed Z-order): y in the even bits, x in the odd bits.
constexpr uint32_t n_order_encode(CellCoord cell) {
    return morton_encode({cell.y, cell.x});
}
constexpr CellCoord n_order_decode(uint32_t index) {
    const CellCoord swapped = morton_decode(index);
    return {swapped.y, swapped.x};
}

}  // namespace crisp
