// The compositor's glyph quads: sorted front to back for the tile and draw paths, ranked for the
// reference modes.
#include "composite/quads.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace crisp::composite {

float clamp01(float value) {
    return value >= 0.0f ? std::min(value, 1.0f) : 0.0f;  // NaN -> 0
}

uint32_t depth_bits(float depth, int bits) {
    const float full = std::ldexp(1.0f, bits);
    const float scaled = clamp01(depth) * full;
    const float saturate = full - 2.0f;
    return scaled >= saturate ? static_cast<uint32_t>(saturate) : static_cast<uint32_t>(scaled);
}

gpu::CompositeQuad make_quad(const DrawnGlyph& glyph, size_t paint_count) {
    const GlyphInstance& instance = glyph.instance;
    gpu::CompositeQuad q{};
    q.x = instance.x;
    q.y = instance.y;
    q.width = instance.width;
    q.height = instance.height;
    q.atlas_x = glyph.atlas_x;
    q.atlas_y = glyph.atlas_y;
    q.depth = clamp01(instance.depth);
    q.color = {clamp01(instance.color[0]), clamp01(instance.color[1]), clamp01(instance.color[2]),
               clamp01(instance.color[3])};
    // Settings outside the ranges resolve_contrast() gives (a DrawnGlyph made by hand) blend as is.
    const GlyphContrast& c = glyph.contrast;
    const bool valid = c.gamma >= 1.0f && c.gamma <= 4.0f && c.contrast >= 0.0f && c.contrast <= 4.0f &&
                       c.darkening >= 1.0f && c.darkening <= kMaxStemDarkeningFactor;
    const GlyphContrast used = valid ? c : GlyphContrast{};
    q.contrast_gamma = used.gamma;
    q.contrast_k = used.contrast;
    q.contrast_darkening = used.darkening;
    // A paint index past the frame's paints (a DrawnGlyph made by hand) fills with the colour.
    q.paint = glyph.paint < paint_count ? glyph.paint : gpu::kNoQuadPaint;
    q.stack = glyph.stack;
    return q;
}

namespace {

constexpr uint32_t kMaxQuadSide = 0xFFFFu;

bool reaches(const GlyphInstance& g, uint32_t width, uint32_t height) {
    if (g.width == 0 || g.height == 0 || g.width > kMaxQuadSide || g.height > kMaxQuadSide) return false;
    const int64_t x = g.x, y = g.y;
    return x < int64_t{width} && y < int64_t{height} && x + g.width > 0 && y + g.height > 0;
}

// Everything a quad's fragments depend on, most significant first: the sort key.
auto content(const gpu::CompositeQuad& q) {
    return std::make_tuple(q.key_depth, ~q.rank, ~q.stack, q.y, q.x, q.height, q.width, q.atlas_y, q.atlas_x, q.color.w,
                           q.color.x, q.color.y, q.color.z, q.paint);
}

}  // namespace

void sort_front_to_back(std::span<const DrawnGlyph> glyphs, size_t paint_count, uint32_t width, uint32_t height,
                        std::vector<gpu::CompositeQuad>& out) {
    // Built in `out` itself (the rank holds the paint order), so that a frame allocates nothing
    // once `out` has grown to the frame's glyphs.
    out.clear();
    for (const DrawnGlyph& glyph : glyphs) {
        if (!reaches(glyph.instance, width, height)) continue;
        gpu::CompositeQuad quad = make_quad(glyph, paint_count);
        quad.key_depth = depth_bits(glyph.instance.depth, 32);
        quad.rank = glyph.instance.paint_order;
        out.push_back(quad);
    }
    auto front_first = [](const gpu::CompositeQuad& a, const gpu::CompositeQuad& b) { return content(a) < content(b); };
    // A UI submits runs in paint order at few depths: often already sorted back to front.
    std::reverse(out.begin(), out.end());
    if (!std::is_sorted(out.begin(), out.end(), front_first)) std::sort(out.begin(), out.end(), front_first);
}

uint64_t quad_tile_pairs(const gpu::CompositeQuad& q, uint32_t width, uint32_t height) {
    const int64_t side = gpu::kTileSide;
    const int64_t x0 = std::max<int64_t>(q.x, 0), y0 = std::max<int64_t>(q.y, 0);
    const int64_t x1 = std::min<int64_t>(int64_t{q.x} + q.width, width);
    const int64_t y1 = std::min<int64_t>(int64_t{q.y} + q.height, height);
    if (x0 >= x1 || y0 >= y1) return 0;
    return static_cast<uint64_t>(((x1 - 1) / side - x0 / side + 1) * ((y1 - 1) / side - y0 / side + 1));
}

void rank_quads(std::span<const DrawnGlyph> glyphs, size_t paint_count, std::vector<gpu::CompositeQuad>& out) {
    out.clear();
    struct Order {
        uint32_t depth;
        uint32_t paint_order;
        uint32_t stack;
        uint32_t quad;
    };
    std::vector<Order> orders;
    orders.reserve(glyphs.size());
    for (const DrawnGlyph& glyph : glyphs) {
        const GlyphInstance& instance = glyph.instance;
        if (instance.width == 0 || instance.height == 0) continue;
        orders.push_back(
            {depth_bits(instance.depth, 32), instance.paint_order, glyph.stack, static_cast<uint32_t>(out.size())});
        out.push_back(make_quad(glyph, paint_count));
    }
    // Paint orders become dense ranks within each depth plane; each block of 256 ranks is also one
    // depth step nearer, as the first compositor's 8-bit paint-order keys needed.
    std::sort(orders.begin(), orders.end(), [](const Order& a, const Order& b) {
        return std::tie(a.depth, a.paint_order, a.stack) < std::tie(b.depth, b.paint_order, b.stack);
    });
    uint32_t rank = 0;
    for (size_t i = 0; i < orders.size(); ++i) {
        const Order& o = orders[i];
        if (i == 0 || o.depth != orders[i - 1].depth) {
            rank = 0;
        } else if (o.paint_order != orders[i - 1].paint_order || o.stack != orders[i - 1].stack) {
            ++rank;
        }
        gpu::CompositeQuad& q = out[o.quad];
        const uint32_t block = rank >> 8;
        q.rank = rank;
        q.key_depth = o.depth - std::min(o.depth, block);
    }
}

}  // namespace crisp::composite
