#include "transform_reference.hpp"

#include <algorithm>
#include <cmath>

namespace crisp {

namespace {

Vec2 apply(const Projective& map, Vec2 p) {
    const double* m = map.m;
    const double w = m[6] * p.x + m[7] * p.y + m[8];
    return {(m[0] * p.x + m[1] * p.y + m[2]) / w, (m[3] * p.x + m[4] * p.y + m[5]) / w};
}

Vec2 at(const Quad& q, double t) {
    const double s = 1.0 - t;
    return {s * s * q.p0.x + 2.0 * s * t * q.p1.x + t * t * q.p2.x,
            s * s * q.p0.y + 2.0 * s * t * q.p1.y + t * t * q.p2.y};
}

std::vector<Quad> texel_curves(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key,
                               const GlyphRect& rect) {
    const Projective map = em_to_texel(rect, key);
    std::vector<Quad> out;
    const bool perspective = map.m[6] != 0.0 || map.m[7] != 0.0;
    // Every curve that bounds area: the listed ones and those flat in em, which rotate into view.
    std::vector<Quad> quads = listed_quads(asset, glyph);
    const std::vector<uint32_t> flat = flat_curve_words(asset, glyph);
    for (uint32_t slot = 0; slot < 32 * flat.size(); ++slot) {
        if (((flat[slot / 32] >> (slot % 32)) & 1u) == 0) continue;
        const Point* p = &asset.points[size_t{glyph.point_offset} + 2 * size_t{slot}];
        const auto v = [](const Point& q) { return Vec2{static_cast<double>(q.x), static_cast<double>(q.y)}; };
        quads.push_back({v(p[0]), v(p[1]), v(p[2])});
    }
    for (const Quad& q : quads) {
        if (!perspective) {
            out.push_back({apply(map, q.p0), apply(map, q.p1), apply(map, q.p2)});
            continue;
        }
        // Chords: a quadratic's chord of parameter length h lies within |a| h^2 / 4 of it (a =
        // p0 - 2 p1 + p2); |a| in texels bounds it from the control polygon's image, with margin.
        const Vec2 a0 = apply(map, q.p0), a1 = apply(map, q.p1), a2 = apply(map, q.p2);
        const double bend = std::hypot(a0.x - 2.0 * a1.x + a2.x, a0.y - 2.0 * a1.y + a2.y) +
                            std::hypot(a0.x - a2.x, a0.y - a2.y) * 0.25;
        const int pieces =
            std::clamp(static_cast<int>(std::ceil(std::sqrt(bend / (4.0 * kProjectiveChordError)))), 1, 4096);
        Vec2 from = a0;
        for (int i = 1; i <= pieces; ++i) {
            const Vec2 to = i == pieces ? a2 : apply(map, at(q, static_cast<double>(i) / pieces));
            out.push_back({from, {0.5 * (from.x + to.x), 0.5 * (from.y + to.y)}, to});
            from = to;
        }
    }
    return out;
}

}  // namespace

TransformedCoverage::TransformedCoverage(const FontAsset& asset, const GlyphRecord& glyph, const GlyphKey& key)
    : rect_(glyph_rect(glyph, key)), curves_(texel_curves(asset, glyph, key, rect_)), exact_(curves_) {}

std::array<double, 3> TransformedCoverage::texel(const SubpixelLayout& layout, uint32_t tx, uint32_t ty) const {
    std::array<double, 3> out{};
    for (size_t c = 0; c < 3; ++c) {
        const SampleRect& r = layout.channels[c];
        out[c] = coverage(tx + static_cast<double>(r.x0), ty + static_cast<double>(r.y0),
                          tx + static_cast<double>(r.x1), ty + static_cast<double>(r.y1));
    }
    return out;
}

}  // namespace crisp
