// The two coverage references: the Slug sample function (double, float, banded, unbanded) and the
// exact area coverage, held to analytic truths, to each other, and to independent crossing tests.
// docs/coverage.md explains what each test shows and records the numbers measured here.
#include "asset/bands.hpp"
#include "coverage.hpp"
#include "bake/outline.hpp"
#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace crisp {
namespace {

// -------------------------------------------------------------------------------------------------
// Shapes built by hand, packed and banded the way the baker does it.

using Polygon = std::vector<Vec2>;

Contour polygon_contour(const Polygon& vertices) {
    Contour contour;
    for (size_t i = 0; i < vertices.size(); ++i) {
        contour.push_back(line_to_quad(vertices[i], vertices[(i + 1) % vertices.size()]));
    }
    return contour;
}

Polygon reversed(Polygon polygon) {
    std::reverse(polygon.begin(), polygon.end());
    return polygon;
}

Polygon rectangle(double x0, double y0, double x1, double y1) {  // counter-clockwise in y-up
    return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// Vertices on a grid of 2^-20 em (coordinates under 8 em): they and the midpoints that lines
// get as control points are exact in float, so the shapes the tests build are stored exactly.
Vec2 on_grid(Vec2 v) {
    return {std::ldexp(std::round(std::ldexp(v.x, 20)), -20), std::ldexp(std::round(std::ldexp(v.y, 20)), -20)};
}

bool float_exact(double value) {
    return static_cast<double>(static_cast<float>(value)) == value;
}

struct Shape {
    std::vector<Contour> contours;
    PackedGlyph packed;
    FontAsset asset;
    std::vector<Quad> curves;  // the real curves (exactly as packed)
    const GlyphRecord& glyph() const { return asset.glyphs[0]; }
};

// target_per_band 1 forces as many bands as the baker allows, so the banded path is exercised.
Shape make_shape(std::vector<Contour> contours, uint32_t target_per_band = 1) {
    Shape shape;
    for (const Contour& contour : contours) {
        for (const Quad& q : contour) {
            for (const Vec2 p : {q.p0, q.p1, q.p2}) {
                EXPECT_TRUE(float_exact(p.x) && float_exact(p.y)) << "(" << p.x << ", " << p.y << ") is not a float";
            }
        }
    }
    shape.contours = contours;
    shape.packed = pack_contours(contours);
    const GlyphBands bands = build_bands(shape.packed, target_per_band, kMaxBands, kBandOverlap);
    GlyphRecord record;
    record.bbox_min_x = shape.packed.min_x;
    record.bbox_min_y = shape.packed.min_y;
    record.bbox_max_x = shape.packed.max_x;
    record.bbox_max_y = shape.packed.max_y;
    record.curve_count = shape.packed.curve_count;
    record.band_count = bands.band_count;
    record.band_words = bands.band_words;
    record.flags = kGlyphBaked;
    shape.asset.glyphs = {record};
    shape.asset.points = shape.packed.points;
    shape.asset.band_words = bands.words;
    for (const Contour& contour : contours) shape.curves.insert(shape.curves.end(), contour.begin(), contour.end());
    return shape;
}

Shape make_polygon_shape(const std::vector<Polygon>& polygons) {
    std::vector<Contour> contours;
    for (const Polygon& polygon : polygons) contours.push_back(polygon_contour(polygon));
    return make_shape(contours);
}

// -------------------------------------------------------------------------------------------------
// Independent truths.

// Winding number of a point at a height no vertex has, by the textbook crossing test, with Slug's
// sign (a crossing running downwards counts +1).
int polygon_winding(const std::vector<Polygon>& polygons, double x, double y) {
    int winding = 0;
    for (const Polygon& polygon : polygons) {
        for (size_t i = 0; i < polygon.size(); ++i) {
            const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
            if ((a.y < y) == (b.y < y)) continue;
            const double crossing = a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y);
            if (crossing > x) winding += b.y < a.y ? +1 : -1;
        }
    }
    return winding;
}

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
    const Vec2 ab = b - a, ap = p - a;
    const double length2 = ab.x * ab.x + ab.y * ab.y;
    const double t = length2 > 0.0 ? std::clamp((ap.x * ab.x + ap.y * ab.y) / length2, 0.0, 1.0) : 0.0;
    return length(p - (a + t * ab));
}

// Distance from p to a quadratic: dense sampling, then golden-section refinement around the best.
double curve_distance(Vec2 p, const Quad& q) {
    auto distance_at = [&](double t) { return length(evaluate(q, t) - p); };
    constexpr int kSteps = 64;
    int best = 0;
    double best_distance = distance_at(0.0);
    for (int i = 1; i <= kSteps; ++i) {
        const double d = distance_at(static_cast<double>(i) / kSteps);
        if (d < best_distance) {
            best_distance = d;
            best = i;
        }
    }
    double lo = std::max(0.0, static_cast<double>(best - 1) / kSteps);
    double hi = std::min(1.0, static_cast<double>(best + 1) / kSteps);
    const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int i = 0; i < 80; ++i) {
        const double m1 = hi - ratio * (hi - lo), m2 = lo + ratio * (hi - lo);
        if (distance_at(m1) < distance_at(m2)) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    return std::min(best_distance, distance_at(0.5 * (lo + hi)));
}

// Whether any curve passes within `radius` of p; curves whose control-point box is farther are
// skipped (a quadratic lies in the hull of its control points).
bool near_any_curve(Vec2 p, std::span<const Quad> curves, double radius) {
    for (const Quad& q : curves) {
        const double min_x = std::min({q.p0.x, q.p1.x, q.p2.x}), max_x = std::max({q.p0.x, q.p1.x, q.p2.x});
        const double min_y = std::min({q.p0.y, q.p1.y, q.p2.y}), max_y = std::max({q.p0.y, q.p1.y, q.p2.y});
        const double dx = std::max({min_x - p.x, 0.0, p.x - max_x}), dy = std::max({min_y - p.y, 0.0, p.y - max_y});
        if (std::hypot(dx, dy) >= radius) continue;
        if (curve_distance(p, q) < radius) return true;
    }
    return false;
}

double curves_distance(Vec2 p, std::span<const Quad> curves) {
    double best = std::numeric_limits<double>::infinity();
    for (const Quad& q : curves) best = std::min(best, curve_distance(p, q));
    return best;
}

// Whether the curve passes within 1e-9 of (x, y) at height y (roots by the textbook formula).
bool on_curve_at_row(const Quad& q, double x, double y) {
    const double A = q.p0.y - 2 * q.p1.y + q.p2.y, B = 2 * (q.p1.y - q.p0.y), C = q.p0.y - y;
    std::vector<double> roots;
    if (std::fabs(A) < 1e-300) {
        if (B != 0) roots.push_back(-C / B);
    } else {
        const double discriminant = B * B - 4 * A * C;
        if (discriminant >= 0) {
            roots.push_back((-B - std::sqrt(discriminant)) / (2 * A));
            roots.push_back((-B + std::sqrt(discriminant)) / (2 * A));
        }
    }
    if (q.p0.y == y && q.p1.y == y && q.p2.y == y) return std::min({q.p0.x, q.p1.x, q.p2.x}) <= x;
    for (double t : roots) {
        if (t >= -1e-12 && t <= 1 + 1e-12 && std::fabs(evaluate(q, std::clamp(t, 0.0, 1.0)).x - x) < 1e-9) return true;
    }
    return false;
}

// Signed area enclosed by closed outlines (Green's theorem, exact for quadratics): the area of a
// shape without overlaps, positive for counter-clockwise outlines.
double green_area(std::span<const Quad> curves) {
    auto cross = [](Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; };
    double area = 0.0;
    for (const Quad& q : curves) {
        area += (cross(q.p0, q.p1) + cross(q.p1, q.p2)) / 3.0 + cross(q.p0, q.p2) / 6.0;
    }
    return area;
}

// Area of a simple polygon clipped to a rectangle (Sutherland-Hodgman against the four sides).
double clipped_polygon_area(Polygon polygon, double x0, double y0, double x1, double y1) {
    auto clip = [&](auto inside, auto intersect) {
        Polygon out;
        for (size_t i = 0; i < polygon.size(); ++i) {
            const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
            if (inside(b)) {
                if (!inside(a)) out.push_back(intersect(a, b));
                out.push_back(b);
            } else if (inside(a)) {
                out.push_back(intersect(a, b));
            }
        }
        polygon = out;
    };
    auto at_x = [](double x) {
        return [x](Vec2 a, Vec2 b) { return Vec2{x, a.y + (x - a.x) * (b.y - a.y) / (b.x - a.x)}; };
    };
    auto at_y = [](double y) {
        return [y](Vec2 a, Vec2 b) { return Vec2{a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y), y}; };
    };
    clip([&](Vec2 p) { return p.x >= x0; }, at_x(x0));
    clip([&](Vec2 p) { return p.x <= x1; }, at_x(x1));
    clip([&](Vec2 p) { return p.y >= y0; }, at_y(y0));
    clip([&](Vec2 p) { return p.y <= y1; }, at_y(y1));
    double area = 0.0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
        area += a.x * b.y - a.y * b.x;
    }
    return std::fabs(area) / 2.0;
}

Polygon rotated(const Polygon& polygon, Vec2 center, double angle) {
    Polygon out;
    const double c = std::cos(angle), s = std::sin(angle);
    for (Vec2 p : polygon) {
        const Vec2 d = p - center;
        out.push_back(on_grid({center.x + c * d.x - s * d.y, center.y + s * d.x + c * d.y}));
    }
    return out;
}

// -------------------------------------------------------------------------------------------------
// Real glyphs.

struct RealGlyph {
    std::string label;
    const FontAsset* asset = nullptr;
    uint32_t index = 0;
    PackedGlyph packed;  // rebuilt from FreeType: says which slots are pads
    const GlyphRecord& glyph() const { return asset->glyphs[index]; }
};

// The pixels (at `size` pixels per em, pixel i covering [i, i + 1) / size) the glyph's em bbox
// touches: columns [i0, i1), rows [j0, j1).
struct PixelBox {
    int i0, i1, j0, j1;
};
PixelBox pixel_box(const GlyphRecord& record, int size) {
    const auto low = [size](float em) { return static_cast<int>(std::floor(static_cast<double>(em) * size)); };
    const auto high = [size](float em) { return static_cast<int>(std::ceil(static_cast<double>(em) * size)); };
    return {low(record.bbox_min_x), high(record.bbox_max_x), low(record.bbox_min_y), high(record.bbox_max_y)};
}

struct FontKey {
    std::string path;
    uint32_t face = 0;
    std::string text;
    bool split = false;
    auto operator<=>(const FontKey&) const = default;
};

const FontAsset& baked_font(const FontKey& key) {
    static std::map<FontKey, std::unique_ptr<FontAsset>> cache;
    auto found = cache.find(key);
    if (found != cache.end()) return *found->second;
    BakeOptions options;
    options.face_index = key.face;
    options.all_glyphs = false;
    options.codepoints = decode_utf8(key.text);
    options.split_y_extrema = key.split;
    Result<BakeResult> result = bake_font_file(key.path, options);
    EXPECT_TRUE(result.ok()) << key.path << ": " << (result.ok() ? "" : result.error().message);
    auto asset = std::make_unique<FontAsset>(result.ok() ? std::move(result->asset) : FontAsset{});
    return *cache.emplace(key, std::move(asset)).first->second;
}

// The glyphs of `text` (by cmap), with their pads found by running the baker's own outline
// pipeline again, independently of the bands.
std::vector<RealGlyph> real_glyphs(const FontKey& key) {
    const FontAsset& asset = baked_font(key);
    std::vector<RealGlyph> glyphs;
    FT_Library library = nullptr;
    if (FT_Init_FreeType(&library) != 0) {
        ADD_FAILURE() << "FreeType";
        return glyphs;
    }
    FT_Face face = nullptr;
    if (FT_New_Face(library, key.path.c_str(), static_cast<FT_Long>(key.face), &face) != 0) {
        ADD_FAILURE() << "cannot open " << key.path;
        FT_Done_FreeType(library);
        return glyphs;
    }
    const double units_per_em = face->units_per_EM;
    EXPECT_EQ(FT_Set_Char_Size(face, 0, static_cast<FT_F26Dot6>(face->units_per_EM) * 64, 72, 72), 0);
    for (uint32_t codepoint : decode_utf8(key.text)) {
        const FT_UInt index = FT_Get_Char_Index(face, codepoint);
        EXPECT_NE(index, 0u) << "U+" << std::hex << codepoint << " missing from " << key.path;
        EXPECT_EQ(FT_Load_Glyph(face, index, FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP), 0);
        OutlineOptions options;
        options.scale = 1.0 / (64.0 * units_per_em);
        options.tolerance = static_cast<double>(kDefaultToleranceEm);
        options.split_y_extrema = key.split;
        options.measure_seed = false;
        OutlineCounters counters;
        OutlineBuilder builder(options, counters);
        std::string error;
        EXPECT_TRUE(decompose_outline(face->glyph->outline, builder, error)) << error;
        RealGlyph glyph;
        glyph.asset = &asset;
        glyph.index = index;
        glyph.packed = pack_contours(builder.finish());
        char label[64];
        std::snprintf(label, sizeof label, "U+%04X of %s", codepoint,
                      std::filesystem::path(key.path).filename().string().c_str());
        glyph.label = label;
        // Same pipeline, same floats: the asset's points are the packed points.
        const GlyphRecord& record = asset.glyphs[index];
        EXPECT_EQ(record.curve_count, glyph.packed.curve_count) << glyph.label;
        if (record.curve_count == glyph.packed.curve_count && record.curve_count > 0) {
            const std::vector<Point> stored(asset.points.begin() + record.point_offset,
                                            asset.points.begin() + record.point_offset + 2 * record.curve_count + 1);
            EXPECT_EQ(stored, glyph.packed.points) << glyph.label;
        }
        glyphs.push_back(std::move(glyph));
    }
    FT_Done_Face(face);
    FT_Done_FreeType(library);
    return glyphs;
}

std::vector<Quad> packed_quads(const PackedGlyph& packed) {
    std::vector<Quad> quads;
    auto to_vec = [](const Point& p) { return Vec2{static_cast<double>(p.x), static_cast<double>(p.y)}; };
    for (uint32_t slot = 0; slot < packed.curve_count; ++slot) {
        if (!packed.is_curve[slot]) continue;
        const Point* p = &packed.points[2 * size_t{slot}];
        quads.push_back({to_vec(p[0]), to_vec(p[1]), to_vec(p[2])});
    }
    return quads;
}

const FontKey kDejaVu{test::kDejaVuSans, 0, "g@&l", false};
const FontKey kInter{test::kInterCff, 0, "Sl@", false};
const FontKey kInterSplit{test::kInterCff, 0, "S@", true};
const FontKey kNoto{test::kNotoCjk, 0, "龘", false};

// =================================================================================================
// The sign convention and the root-code table.

TEST(Coverage, ClockwiseWindsPlusOneCounterClockwiseMinusOne) {
    const Polygon square = rectangle(1, 1, 3, 3);
    const Shape ccw = make_polygon_shape({square});
    const Shape cw = make_polygon_shape({reversed(square)});
    EXPECT_EQ(winding_number(ccw.curves, {2.0, 2.0}), -1);
    EXPECT_EQ(winding_number(cw.curves, {2.0, 2.0}), +1);
    EXPECT_EQ(winding_number(ccw.curves, {0.5, 2.0}), 0);
    EXPECT_EQ(winding_number(cw.curves, {3.5, 2.0}), 0);
    // The crossing walk, which knows nothing of root codes, agrees.
    EXPECT_EQ(ExactCoverage(ccw.curves).winding(2.0, 2.0), -1);
    EXPECT_EQ(ExactCoverage(cw.curves).winding(2.0, 2.0), +1);

    // TrueType outer contours run clockwise (+1), CFF ones counter-clockwise (-1): the middle of
    // the stem of an 'l' in each. The nonzero rule fills both.
    for (const auto& [key, expected] : {std::pair{kDejaVu, +1}, std::pair{kInter, -1}}) {
        for (const RealGlyph& glyph : real_glyphs(key)) {
            if (glyph.label.rfind("U+006C", 0) != 0) continue;
            const GlyphRecord& record = glyph.glyph();
            const double x = 0.5 * static_cast<double>(record.bbox_min_x + record.bbox_max_x);
            const double y = 0.5 * static_cast<double>(record.bbox_min_y + record.bbox_max_y);
            EXPECT_EQ(winding_number_banded<double>(*glyph.asset, record, x, y), expected) << glyph.label;
            EXPECT_EQ(winding_number_banded<float>(*glyph.asset, record, static_cast<float>(x), static_cast<float>(y)),
                      expected)
                << glyph.label;
            EXPECT_LT(expected * green_area(packed_quads(glyph.packed)), 0.0) << glyph.label;  // Green: CCW > 0
        }
    }
}

// Each curve on its own: its contribution at a height on the ray must be what the crossing walk
// says for a ray moved down by an infinitesimal (the walk's (y_lo, y_hi] rule), for every one of
// the eight sign classes. Integer control points keep every height and extremum exact.
TEST(Coverage, RootCodeTableMatchesTheCrossingsOfEachCurve) {
    std::mt19937 random(12345);
    std::uniform_int_distribution<int> coordinate(-4, 4);
    int class_seen[8] = {};
    int class_nonzero[8] = {};
    int checked = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        Quad q;
        q.p0 = {static_cast<double>(coordinate(random)), static_cast<double>(coordinate(random))};
        q.p1 = {static_cast<double>(coordinate(random)), static_cast<double>(coordinate(random))};
        q.p2 = {static_cast<double>(coordinate(random)), static_cast<double>(coordinate(random))};
        const ExactCoverage walk(std::span<const Quad>(&q, 1));
        for (int row = -9; row <= 9; ++row) {
            const double y = row / 2.0;
            for (int column = -13; column <= 13; ++column) {
                const double x = column / 3.0 + 1.0 / 7.0;
                // Skip samples on the curve itself, where rounding decides.
                if (on_curve_at_row(q, x, y)) continue;
                const int expected = walk.winding(x, y);
                const unsigned shift =
                    (q.p0.y - y < 0 ? 1u : 0u) | (q.p1.y - y < 0 ? 2u : 0u) | (q.p2.y - y < 0 ? 4u : 0u);
                ++class_seen[shift];
                const int slug = curve_winding(q, {x, y});
                class_nonzero[shift] += slug != 0;
                ++checked;
                ASSERT_EQ(slug, expected)
                    << "curve (" << q.p0.x << "," << q.p0.y << ") (" << q.p1.x << "," << q.p1.y << ") (" << q.p2.x
                    << "," << q.p2.y << ") sample (" << x << "," << y << ") class " << shift;
                ASSERT_EQ(curve_winding(q, {x, y}, RootSolver::stable), expected);
                ASSERT_EQ(curve_winding<float>(static_cast<float>(q.p0.x - x), static_cast<float>(q.p0.y - y),
                                               static_cast<float>(q.p1.x - x), static_cast<float>(q.p1.y - y),
                                               static_cast<float>(q.p2.x - x), static_cast<float>(q.p2.y - y)),
                          expected);
            }
        }
    }
    EXPECT_GT(checked, 1000000);
    std::printf("%d single-curve samples checked\n", checked);
    for (int shift = 0; shift < 8; ++shift) EXPECT_GT(class_seen[shift], 100) << "class " << shift;
    // Classes 1 to 6 do count crossings; 0 and 7 never do.
    for (int shift = 1; shift <= 6; ++shift) EXPECT_GT(class_nonzero[shift], 10) << "class " << shift;
    EXPECT_EQ(class_nonzero[0], 0);
    EXPECT_EQ(class_nonzero[7], 0);
}

// The sign bit, not "< 0", decides: -0.0 is below the ray. A curve arriving at the ray with its
// end point at -0.0 is counted as ending below it (no crossing) where +0.0 counts one.
TEST(Coverage, NegativeZeroIsBelowTheRay) {
    const float up = 1.0f, down = -1.0f;
    // Upwards from below to an end point on the ray: counted (root 2, -1) when the end is +0.
    EXPECT_EQ(curve_winding<float>(1.0f, down, 1.0f, -0.5f, 1.0f, 0.0f), -1);
    EXPECT_EQ(curve_winding<float>(1.0f, down, 1.0f, -0.5f, 1.0f, -0.0f), 0);
    // Downwards from an end point on the ray: counted (root 1, +1) when the start is +0.
    EXPECT_EQ(curve_winding<float>(1.0f, 0.0f, 1.0f, -0.5f, 1.0f, down), +1);
    EXPECT_EQ(curve_winding<float>(1.0f, -0.0f, 1.0f, -0.5f, 1.0f, down), 0);
    EXPECT_EQ(curve_winding<double>(1.0, -0.0, 1.0, 0.5, 1.0, static_cast<double>(up)), -1);
}

// =================================================================================================
// Exact coverage against analytic areas.

TEST(ExactCoverage, AxisAlignedAndRotatedPolygonsMatchClippedAreas) {
    const std::vector<Polygon> polygons = {
        rectangle(0.25, 0.5, 1.75, 1.25),
        reversed(rectangle(0.25, 0.5, 1.75, 1.25)),
        rotated(rectangle(0.2, 0.3, 1.6, 1.1), {0.9, 0.7}, 0.5235987755982988),
        {{0.1, 0.2}, {1.7, 0.45}, {0.6, 1.6}},
        reversed(rotated({{0.1, 0.2}, {1.7, 0.45}, {0.6, 1.6}}, {0.8, 0.8}, 1.1)),
        {{0.0, 0.0}, {1.5, 0.0}, {1.5, 1.5}, {1.0, 1.5}, {1.0, 0.5}, {0.5, 0.5}, {0.5, 1.5}, {0.0, 1.5}},  // a U
    };
    const double boxes[][4] = {{-1, -1, 3, 3},       {0.5, 0.6, 0.9, 0.95}, {0.3, 0.1, 1.3, 0.9},
                               {1.1, 0.8, 1.9, 1.8}, {0.0, 0.0, 0.7, 0.3},  {0.45, 0.45, 1.05, 1.55},
                               {0.7, 0.2, 0.8, 0.3}, {-0.5, 1.0, 0.2, 2.0}};
    for (size_t p = 0; p < polygons.size(); ++p) {
        Polygon polygon;
        for (Vec2 v : polygons[p]) polygon.push_back(on_grid(v));
        const Shape shape = make_polygon_shape({polygon});
        const ExactCoverage exact(shape.asset, shape.glyph());
        for (const auto& box : boxes) {
            const double expected = clipped_polygon_area(polygon, box[0], box[1], box[2], box[3]);
            const double box_area = (box[2] - box[0]) * (box[3] - box[1]);
            EXPECT_NEAR(exact.area(box[0], box[1], box[2], box[3]), expected, 1e-12 * box_area)
                << "polygon " << p << " box " << box[0] << "," << box[1] << "," << box[2] << "," << box[3];
            EXPECT_NEAR(exact.coverage(box[0], box[1], box[2], box[3]), expected / box_area, 1e-12);
        }
    }
}

// A quadratic and its chord bound 2/3 of the control triangle; the part of the parabolic region
// y <= 1 - x^2 above a height h has area 4/3 (1 - h)^{3/2}, which exercises the square-root
// behaviour at the apex (an extremum inside the curve).
TEST(ExactCoverage, ParabolicSegments) {
    const Quad arch{{-1, 0}, {0, 2}, {1, 0}};
    const Shape shape = make_shape({{arch, line_to_quad({1, 0}, {-1, 0})}});
    const ExactCoverage exact(shape.asset, shape.glyph());
    EXPECT_NEAR(exact.area(-2, -1, 2, 3), 4.0 / 3.0, 1e-12);
    EXPECT_NEAR(exact.area(0, -1, 2, 3), 2.0 / 3.0, 1e-12);
    for (const double h : {0.0, 0.1, 0.5, 0.9, 0.99, 0.999999}) {
        EXPECT_NEAR(exact.area(-2, h, 2, 3), 4.0 / 3.0 * std::pow(1.0 - h, 1.5), 1e-12) << h;
        // A box whose top is exactly at the apex, and one just below it.
        EXPECT_NEAR(exact.area(-2, h, 2, 1), 4.0 / 3.0 * std::pow(1.0 - h, 1.5), 1e-12) << h;
    }
    EXPECT_NEAR(exact.area(-2, -1, 2, 0.75), 4.0 / 3.0 - 4.0 / 3.0 * std::pow(0.25, 1.5), 1e-12);

    // A skewed segment, clockwise, and a bowl (extremum at the bottom).
    const Quad skew{{0.25, 0.125}, {1.875, 1.75}, {0.1875, 1.3125}};
    const double triangle = std::fabs((skew.p1.x - skew.p0.x) * (skew.p2.y - skew.p0.y) -
                                      (skew.p2.x - skew.p0.x) * (skew.p1.y - skew.p0.y)) /
                            2.0;
    const Shape skewed = make_shape({{skew, line_to_quad(skew.p2, skew.p0)}});
    EXPECT_NEAR(ExactCoverage(skewed.asset, skewed.glyph()).area(-1, -1, 3, 3), 2.0 / 3.0 * triangle, 1e-12);
    const Quad bowl{{1, 1}, {0, -1}, {-1, 1}};
    const Shape bowled = make_shape({{bowl, line_to_quad({-1, 1}, {1, 1})}});
    const ExactCoverage bowl_exact(bowled.asset, bowled.glyph());
    EXPECT_NEAR(bowl_exact.area(-2, -1, 2, 2), 4.0 / 3.0, 1e-12);
    // Below height h the bowl y >= x^2 holds 4/3 h^{3/2}.
    EXPECT_NEAR(bowl_exact.area(-2, -1, 2, 0.25), 4.0 / 3.0 * std::pow(0.25, 1.5), 1e-12);
}

TEST(ExactCoverage, OverlapsHolesAndSelfIntersectionsUnderTheNonzeroRule) {
    const Polygon a = rectangle(0, 0, 3, 3), b = rectangle(1, 1, 4, 4);
    const double boxes[][4] = {{-1, -1, 5, 5}, {0.5, 0.5, 3.5, 3.5}, {2, 2, 3, 3}, {1.5, 0.2, 2.5, 3.7}};
    for (const auto& box : boxes) {
        const double box_area = (box[2] - box[0]) * (box[3] - box[1]);
        const double area_a = clipped_polygon_area(a, box[0], box[1], box[2], box[3]);
        const double area_b = clipped_polygon_area(b, box[0], box[1], box[2], box[3]);
        const double overlap = clipped_polygon_area(rectangle(1, 1, 3, 3), box[0], box[1], box[2], box[3]);
        // Same direction: the union; the overlap (winding 2) counts once.
        const Shape same = make_polygon_shape({a, b});
        EXPECT_NEAR(ExactCoverage(same.curves).area(box[0], box[1], box[2], box[3]), area_a + area_b - overlap,
                    1e-12 * box_area);
        EXPECT_LE(ExactCoverage(same.curves).coverage(box[0], box[1], box[2], box[3]), 1.0);
        // The same square twice: winding 2 everywhere inside, coverage as for one.
        const Shape twice = make_polygon_shape({a, a});
        EXPECT_NEAR(ExactCoverage(twice.curves).area(box[0], box[1], box[2], box[3]), area_a, 1e-12 * box_area);
        // Opposite directions: the overlap winds 0 and is empty.
        const Shape opposite = make_polygon_shape({a, reversed(b)});
        EXPECT_NEAR(ExactCoverage(opposite.curves).area(box[0], box[1], box[2], box[3]), area_a + area_b - 2 * overlap,
                    1e-12 * box_area);
        // A ring: a clockwise outer contour and a counter-clockwise hole.
        const Shape ring = make_polygon_shape({reversed(a), rectangle(1, 1, 2, 2)});
        const double hole = clipped_polygon_area(rectangle(1, 1, 2, 2), box[0], box[1], box[2], box[3]);
        EXPECT_NEAR(ExactCoverage(ring.curves).area(box[0], box[1], box[2], box[3]), area_a - hole, 1e-12 * box_area);
        // An inner contour in the same direction is no hole under the nonzero rule.
        const Shape filled = make_polygon_shape({reversed(a), reversed(rectangle(1, 1, 2, 2))});
        EXPECT_NEAR(ExactCoverage(filled.curves).area(box[0], box[1], box[2], box[3]), area_a, 1e-12 * box_area);
    }

    // A bow-tie: two triangles of area 1 winding +1 and -1.
    const Shape bowtie = make_polygon_shape({{{0, 0}, {2, 2}, {2, 0}, {0, 2}}});
    const ExactCoverage bowtie_exact(bowtie.curves);
    EXPECT_NEAR(bowtie_exact.area(-1, -1, 3, 3), 2.0, 1e-12);
    EXPECT_NEAR(bowtie_exact.area(0, 0, 1, 2), 1.0, 1e-12);
    EXPECT_NEAR(bowtie_exact.area(0.5, 0.5, 1.5, 1.5), 0.5, 1e-12);
    EXPECT_EQ(bowtie_exact.winding(0.25, 1.0), -bowtie_exact.winding(1.75, 1.0));

    // A pentagram {5/2}: its pentagon winds twice, so the nonzero rule fills the whole star,
    // 10 triangles of sides R and r around the centre.
    Polygon star;
    const double R = 1.0;
    for (int k = 0; k < 5; ++k) {
        const double angle = std::numbers::pi / 2 + 2 * std::numbers::pi * 2 * k / 5;
        star.push_back(on_grid({R * std::cos(angle), R * std::sin(angle)}));
    }
    const Shape star_shape = make_polygon_shape({star});
    // The vertices are rounded to the grid, which moves the area by about 1e-6.
    const double r = R * std::cos(2 * std::numbers::pi / 5) / std::cos(std::numbers::pi / 5);
    const double star_area = 5 * R * r * std::sin(std::numbers::pi / 5);
    EXPECT_NEAR(ExactCoverage(star_shape.curves).area(-2, -2, 2, 2), star_area, 1e-6);
    // Even-odd would leave the pentagon out: the nonzero area is well above that.
    EXPECT_GT(ExactCoverage(star_shape.curves).area(-2, -2, 2, 2), 0.9 * star_area);
    EXPECT_EQ(std::abs(ExactCoverage(star_shape.curves).winding(0.0, 0.0)), 2);
}

TEST(ExactCoverage, HairlinesThinnerThanAThousandthOfTheBox) {
    // Widths 2^-14 (6e-5) and 2^-23 (1.2e-7) of a unit box, at dyadic positions so that every
    // vertex and midpoint is exact in float.
    for (const double width : {std::ldexp(1.0, -14), std::ldexp(1.0, -23)}) {
        // Vertical, and slanted across the whole box.
        const Polygon vertical = rectangle(0.296875, -1, 0.296875 + width, 2);
        const Polygon slanted = {{0.125, 0}, {0.125 + width, 0}, {0.8125 + width, 1}, {0.8125, 1}};
        for (const Polygon& polygon : {vertical, slanted}) {
            const Polygon& exact_vertices = polygon;
            const Shape shape = make_polygon_shape({polygon});
            const ExactCoverage exact(shape.curves);
            const double expected = clipped_polygon_area(exact_vertices, 0, 0, 1, 1);
            EXPECT_GT(expected, 0.5 * width);
            EXPECT_NEAR(exact.area(0, 0, 1, 1), expected, 1e-13);
            EXPECT_NEAR(exact.area(0.2, 0.25, 0.9, 0.5), clipped_polygon_area(exact_vertices, 0.2, 0.25, 0.9, 0.5),
                        1e-13);
        }
    }
}

TEST(ExactCoverage, RealGlyphAreaIsAdditiveAndMatchesGreensTheorem) {
    for (const FontKey& key : {kDejaVu, kInter, kNoto}) {
        for (const RealGlyph& glyph : real_glyphs(key)) {
            const GlyphRecord& record = glyph.glyph();
            const ExactCoverage exact(*glyph.asset, record);
            const double x0 = static_cast<double>(record.bbox_min_x) - 0.01;
            const double y0 = static_cast<double>(record.bbox_min_y) - 0.01;
            const double x1 = static_cast<double>(record.bbox_max_x) + 0.013;
            const double y1 = static_cast<double>(record.bbox_max_y) + 0.017;
            const double whole = exact.area(x0, y0, x1, y1);
            // These glyphs have no overlapping contours, so Green's theorem gives the same area.
            EXPECT_NEAR(whole, std::fabs(green_area(packed_quads(glyph.packed))), 1e-11) << glyph.label;
            constexpr int kColumns = 23, kRows = 19;
            double sum = 0.0;
            for (int j = 0; j < kRows; ++j) {
                for (int i = 0; i < kColumns; ++i) {
                    const double bx0 = x0 + (x1 - x0) * i / kColumns, bx1 = x0 + (x1 - x0) * (i + 1) / kColumns;
                    const double by0 = y0 + (y1 - y0) * j / kRows, by1 = y0 + (y1 - y0) * (j + 1) / kRows;
                    const double coverage = exact.coverage(bx0, by0, bx1, by1);
                    EXPECT_GE(coverage, 0.0);
                    EXPECT_LE(coverage, 1.0);
                    sum += exact.area(bx0, by0, bx1, by1);
                }
            }
            EXPECT_NEAR(sum, whole, 1e-11) << glyph.label;
        }
    }
}

// =================================================================================================
// The sample function on hard cases, against independent truths.

// How far below the sample row the truth is evaluated: a generic height no vertex has, standing
// for Slug's "a point on the ray counts as above it" (the ray moved down by an infinitesimal).
constexpr double kBelow = 0x1p-30;

struct SampleStats {
    int checked = 0;
    int on_vertex_rows = 0;
    int boxes = 0;
};

// Checks every form of the sample function at (x, y) against `expected`, and the exact coverage
// of a small box around it when the sample is at least `edge_distance` from every curve.
void check_sample(const Shape& shape, const ExactCoverage& exact, double x, double y, int expected,
                  double edge_distance, SampleStats& stats) {
    SCOPED_TRACE(testing::Message() << "sample (" << x << ", " << y << ")");
    ++stats.checked;
    EXPECT_EQ(winding_number(shape.curves, {x, y}), expected);
    EXPECT_EQ(winding_number(shape.curves, {x, y}, RootSolver::stable), expected);
    EXPECT_EQ(winding_number(shape.packed.points, shape.packed.is_curve, {x, y}), expected);
    EXPECT_EQ(winding_number_banded<double>(shape.asset, shape.glyph(), x, y), expected);
    ASSERT_TRUE(float_exact(x) && float_exact(y));
    EXPECT_EQ(winding_number_banded<float>(shape.asset, shape.glyph(), static_cast<float>(x), static_cast<float>(y)),
              expected);
    EXPECT_EQ(winding_number_banded<float>(shape.asset, shape.glyph(), static_cast<float>(x), static_cast<float>(y),
                                           RootSolver::stable),
              expected);
    // The crossing walk at the row itself, with its (y_lo, y_hi] rule.
    EXPECT_EQ(exact.winding(x, y), expected);
    if (edge_distance > 2e-3) {
        ++stats.boxes;
        EXPECT_EQ(exact.coverage(x - 1e-3, y - 1e-3, x + 1e-3, y + 1e-3), expected != 0 ? 1.0 : 0.0);
    }
}

// Rows: every vertex height (the hard rows), halfway between them, and a little off them.
// Columns: a 1/8 grid offset by 1/32 (never a vertex of these shapes), over the shape and beyond.
void sample_rows_and_columns(const Shape& shape, const std::function<int(double, double)>& truth,
                             const std::function<double(Vec2)>& distance, SampleStats& stats) {
    std::vector<double> rows;
    for (const Quad& q : shape.curves) {
        for (const Vec2 p : {q.p0, q.p1, q.p2}) rows.push_back(p.y);
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    const size_t vertex_rows = rows.size();
    for (size_t i = 0; i + 1 < vertex_rows; ++i) rows.push_back(on_grid({0, 0.5 * (rows[i] + rows[i + 1])}).y);
    for (size_t i = 0; i < vertex_rows; ++i) {
        rows.push_back(rows[i] + 0x1p-12);
        rows.push_back(rows[i] - 0x1p-12);
    }
    const ExactCoverage exact(shape.curves);
    const double x_min = std::floor(static_cast<double>(shape.packed.min_x)) - 1.0;
    const double x_max = std::ceil(static_cast<double>(shape.packed.max_x)) + 1.0;
    for (size_t r = 0; r < rows.size(); ++r) {
        const double y = rows[r];
        for (double x = x_min + 1.0 / 32; x < x_max; x += 1.0 / 8) {
            const double edge = distance({x, y});
            if (edge < 1e-9) continue;  // on the outline: rounding decides, and either answer is right
            if (r < vertex_rows) ++stats.on_vertex_rows;
            check_sample(shape, exact, x, y, truth(x, y), edge, stats);
        }
    }
}

void check_polygons(const char* name, const std::vector<Polygon>& polygons) {
    SCOPED_TRACE(name);
    const Shape shape = make_polygon_shape(polygons);
    SampleStats stats;
    sample_rows_and_columns(
        shape, [&](double x, double y) { return polygon_winding(polygons, x, y - kBelow); },
        [&](Vec2 p) {
            double best = std::numeric_limits<double>::infinity();
            for (const Polygon& polygon : polygons) {
                for (size_t i = 0; i < polygon.size(); ++i) {
                    best = std::min(best, segment_distance(p, polygon[i], polygon[(i + 1) % polygon.size()]));
                }
            }
            return best;
        },
        stats);
    EXPECT_GT(stats.on_vertex_rows, 50);
    EXPECT_GT(stats.boxes, 20);
}

// Curved and degenerate shapes: the truth is the crossing walk one infinitesimal below the row.
void check_curves(const char* name, const std::vector<Contour>& contours) {
    SCOPED_TRACE(name);
    const Shape shape = make_shape(contours);
    const ExactCoverage walk(shape.curves);
    SampleStats stats;
    sample_rows_and_columns(
        shape, [&](double x, double y) { return walk.winding(x, y - kBelow); },
        [&](Vec2 p) { return curves_distance(p, shape.curves); }, stats);
    EXPECT_GT(stats.on_vertex_rows, 50);
    EXPECT_GT(stats.boxes, 20);
}

TEST(Coverage, HardCasesPolygons) {
    const Polygon square = rectangle(1, 1, 3, 3);
    check_polygons("square, counter-clockwise", {square});
    check_polygons("square, clockwise", {reversed(square)});
    check_polygons("diamond: rows through a bottom, a top and two side vertices", {{{2, 0}, {4, 2}, {2, 4}, {0, 2}}});
    // Valleys at y = 2, peaks at y = 4, and a vertex at (6, 2) where the right side runs straight on.
    check_polygons("crown", {{{0, 0}, {6, 0}, {6, 2}, {6, 4}, {5, 2}, {4, 4}, {3, 2}, {2, 4}, {1, 2}, {0, 4}}});
    check_polygons("staircase: horizontal edges on the rows",
                   {{{0, 0}, {4, 0}, {4, 1}, {3, 1}, {3, 2}, {2, 2}, {2, 3}, {0, 3}}});
    check_polygons("overlapping squares, same direction", {rectangle(0, 0, 3, 3), rectangle(1, 1, 4, 4)});
    check_polygons("the same square twice", {rectangle(0, 0, 3, 3), rectangle(0, 0, 3, 3)});
    check_polygons("overlapping squares, opposite directions",
                   {rectangle(0, 0, 3, 3), reversed(rectangle(1, 1, 4, 4))});
    check_polygons("ring with an island",
                   {reversed(rectangle(0, 0, 4, 4)), rectangle(1, 1, 3, 3), reversed(rectangle(1.5, 1.5, 2.5, 2.5))});
    check_polygons("bow-tie: the row through the crossing", {{{0, 0}, {2, 2}, {2, 0}, {0, 2}}});
    Polygon star;
    for (int k = 0; k < 5; ++k) {
        const double angle = std::numbers::pi / 2 + 2 * std::numbers::pi * 2 * k / 5;
        star.push_back(on_grid({2 + 2 * std::cos(angle), 2 + 2 * std::sin(angle)}));
    }
    check_polygons("pentagram: its centre winds twice", {star});
}

TEST(Coverage, HardCasesCurvesTangentsAndDegenerateQuadratics) {
    // An arch whose apex (2, 2) is tangent to the row y = 2, and a bowl tangent to y = 0 at (2, 0).
    check_curves("arch", {{Quad{{4, 0}, {2, 4}, {0, 0}}, line_to_quad({0, 0}, {4, 0})}});
    check_curves("bowl", {{Quad{{0, 2}, {2, -2}, {4, 2}}, line_to_quad({4, 2}, {4, 3}), line_to_quad({4, 3}, {0, 3}),
                           line_to_quad({0, 3}, {0, 2})}});
    // An 'o' the TrueType way: quadratics meeting at the extrema with horizontal and vertical
    // tangents, outer clockwise, inner counter-clockwise.
    auto circle = [](double r, bool clockwise) {
        const Vec2 c{2, 2};
        std::vector<Vec2> on = {{0, r}, {r, 0}, {0, -r}, {-r, 0}};
        std::vector<Vec2> off = {{r, r}, {r, -r}, {-r, -r}, {-r, r}};
        Contour contour;
        for (size_t i = 0; i < 4; ++i) contour.push_back({c + on[i], c + off[i], c + on[(i + 1) % 4]});
        if (!clockwise) {
            std::reverse(contour.begin(), contour.end());
            for (Quad& q : contour) std::swap(q.p0, q.p2);
        }
        return contour;
    };
    check_curves("o", {circle(1.5, true), circle(0.75, false)});
    // A square whose right edge is a collinear quadratic with its control point off the middle,
    // whose top carries a zero-area spike (p0 == p2), whose left edge overshoots below the bottom
    // and comes back (a collinear quadratic with its control point outside the segment), with a
    // zero-length quadratic at a corner.
    check_curves("degenerate quadratics", {{
                                              line_to_quad({1, 1}, {3, 1}),
                                              Quad{{3, 1}, {3, 1.25}, {3, 3}},
                                              line_to_quad({3, 3}, {2, 3}),
                                              Quad{{2, 3}, {2, 4}, {2, 3}},
                                              line_to_quad({2, 3}, {1, 3}),
                                              Quad{{1, 3}, {1, 3}, {1, 3}},
                                              Quad{{1, 3}, {1, 0}, {1, 1}},
                                          }});
    // Two same-direction parabolic lenses overlapping (winding 2 where they meet), and a contour
    // of quadratics crossing itself.
    check_curves("overlapping lenses", {{Quad{{0, 0}, {2, 3}, {4, 0}}, Quad{{4, 0}, {2, -3}, {0, 0}}},
                                        {Quad{{1, 0.5}, {3, 3.5}, {5, 0.5}}, Quad{{5, 0.5}, {3, -2.5}, {1, 0.5}}}});
    check_curves("self-intersecting curves", {{Quad{{0, 0}, {4, 1}, {4, 4}}, Quad{{4, 4}, {2, 2}, {4, 0}},
                                               Quad{{4, 0}, {0, 2}, {0, 4}}, line_to_quad({0, 4}, {0, 0})}});
}

// Slug solves |a| < kLinearEpsilon as the line -2 b t + c = 0. A curve that leaves its start
// horizontally (y1 == y2, so b == 0) and ends less than kLinearEpsilon higher or lower divides by
// zero there, and its crossing is lost (the x of t = inf is NaN or infinite). The rows affected
// lie within the curve's own height, under 1/65536 em. The stable solver gets it right.
TEST(Coverage, SlugLinearCaseLosesAFlatStartingCurve) {
    const double dip = 0x1p-20;  // the curve ends 2^-20 em below its start: |a| = 2^-20 < 2^-16
    const std::vector<Contour> contours = {{Quad{{0, 0}, {1, 0}, {2, -dip}}, line_to_quad({2, -dip}, {2, -1}),
                                            line_to_quad({2, -1}, {0, -1}), line_to_quad({0, -1}, {0, 0})}};
    const Shape shape = make_shape(contours);
    const ExactCoverage walk(shape.curves);
    const double y = -0x1p-21;  // halfway down the dip: the curve crosses at x = 2 sqrt(1/2)
    for (const double x : {0.5, 1.0, 1.25, 1.5, 1.75}) {
        const int truth = walk.winding(x, y);
        EXPECT_EQ(truth, x < std::sqrt(2.0) ? 1 : 0);
        EXPECT_EQ(winding_number(shape.curves, {x, y}, RootSolver::stable), truth) << x;
        EXPECT_EQ(winding_number_banded<float>(shape.asset, shape.glyph(), static_cast<float>(x), static_cast<float>(y),
                                               RootSolver::stable),
                  truth)
            << x;
        // Slug: the curve's crossing is lost, so every sample left of the right edge reads 0.
        EXPECT_EQ(winding_number(shape.curves, {x, y}), 0) << x;
        EXPECT_EQ(
            winding_number_banded<float>(shape.asset, shape.glyph(), static_cast<float>(x), static_cast<float>(y)), 0)
            << x;
    }
    // Below the dip the curve is not crossed and both agree.
    EXPECT_EQ(winding_number(shape.curves, {1.0, -0.5}), 1);
    EXPECT_EQ(winding_number(shape.curves, {1.0, -0.5}, RootSolver::stable), 1);
}

// =================================================================================================
// Real glyphs.

// A grid of float samples over the glyph's bbox (and a margin), plus rows at the height of every
// point of the glyph, where end points and horizontal segments sit on the ray.
std::vector<std::pair<float, float>> glyph_samples(const GlyphRecord& glyph, const PackedGlyph& packed, int columns,
                                                   int rows) {
    std::vector<std::pair<float, float>> samples;
    const double margin = 0.02;
    const double x0 = static_cast<double>(glyph.bbox_min_x) - margin,
                 x1 = static_cast<double>(glyph.bbox_max_x) + margin;
    const double y0 = static_cast<double>(glyph.bbox_min_y) - margin,
                 y1 = static_cast<double>(glyph.bbox_max_y) + margin;
    std::vector<float> xs, ys;
    for (int i = 0; i < columns; ++i) xs.push_back(static_cast<float>(x0 + (x1 - x0) * (i + 0.5) / columns));
    for (int j = 0; j < rows; ++j) ys.push_back(static_cast<float>(y0 + (y1 - y0) * (j + 0.5) / rows));
    for (const Point& p : packed.points) ys.push_back(p.y);
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    for (float y : ys) {
        for (float x : xs) samples.emplace_back(x, y);
    }
    return samples;
}

template <class Real>
int unbanded_winding(const PackedGlyph& packed, Real x, Real y, RootSolver solver = RootSolver::slug) {
    int winding = 0;
    for (uint32_t slot = 0; slot < packed.curve_count; ++slot) {
        if (!packed.is_curve[slot]) continue;
        const Point* p = &packed.points[2 * size_t{slot}];
        winding += curve_winding<Real>(static_cast<Real>(p[0].x) - x, static_cast<Real>(p[0].y) - y,
                                       static_cast<Real>(p[1].x) - x, static_cast<Real>(p[1].y) - y,
                                       static_cast<Real>(p[2].x) - x, static_cast<Real>(p[2].y) - y, solver);
    }
    return winding;
}

std::vector<RealGlyph> all_real_glyphs() {
    std::vector<RealGlyph> glyphs;
    for (const FontKey& key : {kDejaVu, kInter, kInterSplit, kNoto}) {
        for (RealGlyph& glyph : real_glyphs(key)) glyphs.push_back(std::move(glyph));
    }
    return glyphs;
}

// The bands list exactly the real curves that are not flat, and testing only the sample's band
// gives the same winding number as testing every real curve, in double and in float, on every
// sample of a grid and on every row through a point of the glyph.
TEST(Coverage, BandsLoseNothing) {
    uint64_t samples = 0, inside = 0;
    for (const RealGlyph& glyph : all_real_glyphs()) {
        SCOPED_TRACE(glyph.label);
        const GlyphRecord& record = glyph.glyph();
        std::vector<uint32_t> expected_slots;
        for (uint32_t slot = 0; slot < glyph.packed.curve_count; ++slot) {
            const Point* p = &glyph.packed.points[2 * size_t{slot}];
            if (glyph.packed.is_curve[slot] && !(p[0].y == p[1].y && p[1].y == p[2].y)) expected_slots.push_back(slot);
        }
        EXPECT_EQ(listed_curves(*glyph.asset, record), expected_slots);
        // Every contour closes on the very point it starts from, bit for bit: the tie rules (a
        // point on the ray is above it, -0.0 is below) then see a shared vertex the same way
        // from both of its curves.
        for (uint32_t slot = 0; slot < glyph.packed.curve_count;) {
            const uint32_t first = slot;
            while (slot < glyph.packed.curve_count && glyph.packed.is_curve[slot]) ++slot;
            const Point start = glyph.packed.points[2 * size_t{first}], end = glyph.packed.points[2 * size_t{slot}];
            EXPECT_EQ(std::memcmp(&start, &end, sizeof(Point)), 0) << "contour from slot " << first;
            ++slot;  // past the pad
        }
        const std::vector<uint32_t> listed = listed_curves(*glyph.asset, record);
        int mismatches = 0, strays = 0;
        for (const auto& [x, y] : glyph_samples(record, glyph.packed, 79, 83)) {
            // Each curve outside the sample's band adds exactly 0 on its own, so a shader may test
            // any superset of the band (the union of the bands its subgroup touches) and agree.
            const uint32_t band = FontAsset::band_of(record, y);
            for (const uint32_t slot : listed) {
                const uint32_t word =
                    glyph.asset->band_words[record.band_offset + size_t{band} * record.band_words + slot / 32];
                if ((word >> (slot % 32)) & 1u) continue;
                const Point* p = &glyph.packed.points[2 * size_t{slot}];
                if (curve_winding<float>(p[0].x - x, p[0].y - y, p[1].x - x, p[1].y - y, p[2].x - x, p[2].y - y) != 0 ||
                    curve_winding<double>(static_cast<double>(p[0].x) - static_cast<double>(x),
                                          static_cast<double>(p[0].y) - static_cast<double>(y),
                                          static_cast<double>(p[1].x) - static_cast<double>(x),
                                          static_cast<double>(p[1].y) - static_cast<double>(y),
                                          static_cast<double>(p[2].x) - static_cast<double>(x),
                                          static_cast<double>(p[2].y) - static_cast<double>(y)) != 0) {
                    if (++strays <= 5)
                        ADD_FAILURE() << "curve " << slot << " outside band " << band << " counts at (" << x << ", "
                                      << y << ")";
                }
            }
            const auto xd = static_cast<double>(x), yd = static_cast<double>(y);
            const int all_double = unbanded_winding<double>(glyph.packed, xd, yd);
            const int all_float = unbanded_winding<float>(glyph.packed, x, y);
            ++samples;
            inside += all_double != 0;
            if (winding_number_banded<double>(*glyph.asset, record, xd, yd) != all_double ||
                winding_number(glyph.packed.points, glyph.packed.is_curve, {xd, yd}) != all_double ||
                winding_number_banded<float>(*glyph.asset, record, x, y) != all_float ||
                winding_number_banded<float>(*glyph.asset, record, x, y, RootSolver::stable) !=
                    unbanded_winding<float>(glyph.packed, x, y, RootSolver::stable)) {
                if (++mismatches <= 5) ADD_FAILURE() << "banded != unbanded at (" << x << ", " << y << ")";
            }
        }
        EXPECT_EQ(mismatches, 0);
        EXPECT_EQ(strays, 0);
    }
    EXPECT_GT(samples, 100000u);
    EXPECT_GT(inside, samples / 10);
    // 龘 in Noto Sans CJK is cut into many bands.
    EXPECT_GE(real_glyphs(kNoto)[0].glyph().band_count, 16u);
}

// Samples at a known distance from the outline: points of every curve pushed off along its
// normal by delta (then rounded to float, and kept only if still at least delta / 2 from every
// curve). The truth is the crossing walk in double. Measured here, and recorded in
// docs/coverage.md: how many samples each form of the sample function gets wrong at each distance.
TEST(Coverage, FloatAgreesWithDoubleAwayFromEdges) {
    const double deltas[] = {1e-8, 1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4};
    constexpr size_t kDeltas = std::size(deltas);
    enum { kFloatSlug, kFloatStable, kDoubleSlug, kDoubleStable, kForms };
    struct Counts {
        int wrong[kForms][kDeltas] = {};
        int total[kDeltas] = {};
    };
    // Fonts as baked by default, and Inter baked with its curves split at y-extrema.
    Counts groups[2];
    const std::vector<FontKey> fonts[2] = {{kDejaVu, kInter, kNoto}, {kInterSplit}};
    for (int group = 0; group < 2; ++group) {
        Counts& counts = groups[group];
        for (const FontKey& key : fonts[group]) {
            for (const RealGlyph& glyph : real_glyphs(key)) {
                const GlyphRecord& record = glyph.glyph();
                const std::vector<Quad> curves = packed_quads(glyph.packed);
                const ExactCoverage walk(curves);
                for (const Quad& q : curves) {
                    for (int k = 0; k < 16; ++k) {
                        const double t = (k + 0.5) / 16;
                        const Vec2 on = evaluate(q, t);
                        const Vec2 tangent = 2.0 * ((1 - t) * (q.p1 - q.p0) + t * (q.p2 - q.p1));
                        const double norm = length(tangent);
                        if (norm == 0) continue;
                        const Vec2 normal{-tangent.y / norm, tangent.x / norm};
                        for (size_t d = 0; d < kDeltas; ++d) {
                            for (const double side : {-1.0, 1.0}) {
                                const Vec2 target = on + side * deltas[d] * normal;
                                const auto x = static_cast<float>(target.x), y = static_cast<float>(target.y);
                                const Vec2 sample{static_cast<double>(x), static_cast<double>(y)};
                                if (near_any_curve(sample, curves, 0.5 * deltas[d])) continue;
                                const bool truth = walk.winding(sample.x, sample.y) != 0;
                                ++counts.total[d];
                                const bool answers[kForms] = {
                                    winding_number_banded<float>(*glyph.asset, record, x, y) != 0,
                                    winding_number_banded<float>(*glyph.asset, record, x, y, RootSolver::stable) != 0,
                                    winding_number_banded<double>(*glyph.asset, record, sample.x, sample.y) != 0,
                                    winding_number_banded<double>(*glyph.asset, record, sample.x, sample.y,
                                                                  RootSolver::stable) != 0,
                                };
                                for (int form = 0; form < kForms; ++form)
                                    counts.wrong[form][d] += answers[form] != truth;
                            }
                        }
                    }
                }
            }
        }
        std::printf(
            "samples wrong at a distance from the outline (%s): float Slug, float stable, double Slug, "
            "double stable\n",
            group == 0 ? "DejaVu Sans g@&l, Inter S@l, Noto CJK 龘" : "Inter S@ split at y-extrema");
        for (size_t d = 0; d < kDeltas; ++d) {
            std::printf("  %.0e em: %5d %5d %5d %5d of %d\n", deltas[d], counts.wrong[kFloatSlug][d],
                        counts.wrong[kFloatStable][d], counts.wrong[kDoubleSlug][d], counts.wrong[kDoubleStable][d],
                        counts.total[d]);
        }
        for (size_t d = 0; d < kDeltas; ++d) {
            EXPECT_GT(counts.total[d], 2000);
            EXPECT_EQ(counts.wrong[kDoubleStable][d], 0) << deltas[d];
            // Slug's linear case misplaces a crossing by up to |a| < 1/65536 em, in double as in
            // float; curves split at their y-extrema start flat (b == 0) and meet it most.
            if (deltas[d] >= kLinearEpsilon) {
                EXPECT_EQ(counts.wrong[kDoubleSlug][d], 0) << deltas[d];
                EXPECT_EQ(counts.wrong[kFloatSlug][d], 0) << deltas[d];
            }
            // Float's own rounding (a few 1e-8 em at coordinates near 1 em) stays within 3e-7 em.
            if (deltas[d] >= 3e-7) {
                EXPECT_EQ(counts.wrong[kFloatStable][d], 0) << deltas[d];
            }
        }
    }
    // The split curves do trip Slug's linear case; this documents it (docs/coverage.md).
    EXPECT_GT(groups[1].wrong[kDoubleSlug][3], 0);
}

struct ErrorStats {
    double mean = 0.0, p99 = 0.0, max = 0.0;
    size_t pixels = 0;
};

ErrorStats error_stats(std::vector<double> errors) {
    ErrorStats stats;
    stats.pixels = errors.size();
    if (errors.empty()) return stats;
    std::sort(errors.begin(), errors.end());
    for (double e : errors) stats.mean += e;
    stats.mean /= static_cast<double>(errors.size());
    stats.p99 = errors[std::min(errors.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(errors.size())))];
    stats.max = errors.back();
    return stats;
}

// coverage_points over pixel boxes converges to exact_coverage: at 512 R2 samples the error over
// touched pixels is small, and it is larger at 64 samples. Large sizes test a deterministic subset
// of the pixels to stay fast.
TEST(Coverage, PointSamplesConvergeToExactCoverage) {
    std::vector<RealGlyph> glyphs;
    for (const FontKey& key : {kDejaVu, kInter, kNoto}) {
        for (RealGlyph& glyph : real_glyphs(key)) {
            if (glyph.label.rfind("U+006C", 0) == 0 || glyph.label.rfind("U+0040 of Inter", 0) == 0) continue;
            glyphs.push_back(std::move(glyph));
        }
    }
    std::printf("%-28s %5s %7s | %-26s | %-26s\n", "glyph", "px/em", "pixels", "512 samples: mean p99 max",
                "64 samples: mean p99 max");
    for (const int size : {6, 16, 50, 200}) {
        std::vector<double> all512, all64;
        for (const RealGlyph& glyph : glyphs) {
            const GlyphRecord& record = glyph.glyph();
            const ExactCoverage exact(*glyph.asset, record);
            const double pixel = 1.0 / size;
            const auto [i0, i1, j0, j1] = pixel_box(record, size);
            const int count = (i1 - i0) * (j1 - j0);
            const int stride = std::max(1, count / 1500);
            std::vector<double> errors512, errors64;
            for (int j = j0; j < j1; ++j) {
                for (int i = i0; i < i1; ++i) {
                    if ((i * 7 + j * 13) % stride != 0) continue;
                    const double x0 = i * pixel, y0 = j * pixel, x1 = x0 + pixel, y1 = y0 + pixel;
                    const double truth = exact.coverage(x0, y0, x1, y1);
                    const double points64 = coverage_points(*glyph.asset, record, x0, y0, x1, y1, 64);
                    const double points448 = coverage_points(*glyph.asset, record, x0, y0, x1, y1, 448, 64);
                    const double points512 = (64 * points64 + 448 * points448) / 512;
                    if (truth == 0.0 && points512 == 0.0 && points64 == 0.0) continue;  // untouched
                    errors512.push_back(std::fabs(points512 - truth));
                    errors64.push_back(std::fabs(points64 - truth));
                }
            }
            const ErrorStats s512 = error_stats(errors512), s64 = error_stats(errors64);
            std::printf("%-28s %5d %7zu | %.5f %.5f %.5f | %.5f %.5f %.5f\n", glyph.label.c_str(), size, s512.pixels,
                        s512.mean, s512.p99, s512.max, s64.mean, s64.p99, s64.max);
            all512.insert(all512.end(), errors512.begin(), errors512.end());
            all64.insert(all64.end(), errors64.begin(), errors64.end());
        }
        const ErrorStats s512 = error_stats(all512), s64 = error_stats(all64);
        std::printf("%-28s %5d %7zu | %.5f %.5f %.5f | %.5f %.5f %.5f\n", "all", size, s512.pixels, s512.mean, s512.p99,
                    s512.max, s64.mean, s64.p99, s64.max);
        // Bounds about 1.7 to 2 times what docs/coverage.md records.
        EXPECT_GT(s512.pixels, 100u);
        EXPECT_LT(s512.mean, 0.005) << size;
        EXPECT_LT(s512.p99, 0.025) << size;
        EXPECT_LT(s512.max, 0.03) << size;
        EXPECT_GT(s64.mean, 3.0 * s512.mean) << size;
    }
}

// =================================================================================================
// Row samples: the covered length of a segment under the nonzero rule.

// The covered length of [x0, x1] at height y one infinitesimal below the row (Slug's convention),
// by the textbook crossing test on the polygons' edges: crossings sorted, winding walked.
double polygon_row_length(const std::vector<Polygon>& polygons, double y, double x0, double x1) {
    const double below = y - kBelow;
    std::vector<std::pair<double, int>> crossings;
    for (const Polygon& polygon : polygons) {
        for (size_t i = 0; i < polygon.size(); ++i) {
            const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
            if ((a.y < below) == (b.y < below)) continue;
            crossings.push_back({a.x + (below - a.y) * (b.x - a.x) / (b.y - a.y), b.y < a.y ? +1 : -1});
        }
    }
    std::sort(crossings.begin(), crossings.end());
    int winding = 0;
    for (const auto& [x, direction] : crossings) {
        if (x > x0) winding += direction;
    }
    double length = 0.0, at = x0;
    for (const auto& [x, direction] : crossings) {
        if (!(x > x0)) continue;
        const double clipped = std::min(x, x1);
        if (winding != 0) length += clipped - at;
        at = clipped;
        winding -= direction;
    }
    if (winding != 0) length += x1 - at;
    return length;
}

// Every form of the row function (double and float, the curves and the bands) on `shape` at row y.
void expect_row_length(const Shape& shape, double y, double x0, double x1, double expected, double tolerance,
                       double float_tolerance = 0.0) {
    SCOPED_TRACE(testing::Message() << "row " << y << ", [" << x0 << ", " << x1 << "]");
    EXPECT_NEAR(row_covered_length<double>(shape.curves, y, x0, x1), expected, tolerance);
    EXPECT_NEAR(row_covered_length_banded<double>(shape.asset, shape.glyph(), y, x0, x1), expected, tolerance);
    const auto yf = static_cast<float>(y), x0f = static_cast<float>(x0), x1f = static_cast<float>(x1);
    float_tolerance = std::max({float_tolerance, tolerance, 4e-7 * (1.0 + std::fabs(x1))});
    EXPECT_NEAR(row_covered_length<float>(shape.curves, yf, x0f, x1f), expected, float_tolerance);
    EXPECT_NEAR(row_covered_length_banded<float>(shape.asset, shape.glyph(), yf, x0f, x1f), expected, float_tolerance);
}

TEST(RowSamples, SequenceIsStratifiedAtEveryPowerOfTwo) {
    EXPECT_EQ(radical_inverse_2(0), 0.0);
    EXPECT_EQ(radical_inverse_2(1), 0.5);
    EXPECT_EQ(radical_inverse_2(6), 0.375);
    for (uint32_t count = 1; count <= 512; count *= 2) {
        std::vector<int> strata(count, 0);
        double worst_offset = 0.0;
        for (uint32_t n = 0; n < count; ++n) {
            const double v = row_height(n);
            ASSERT_TRUE(v >= 0.0 && v < 1.0);
            EXPECT_EQ(static_cast<double>(static_cast<float>(v)), v);  // the shader's float is exact
            const auto stratum = static_cast<size_t>(v * count);
            ++strata[stratum];
            worst_offset = std::max(worst_offset, std::fabs(v - (static_cast<double>(stratum) + 0.5) / count));
        }
        for (int in_stratum : strata) EXPECT_EQ(in_stratum, 1) << count << " samples";
        // 73/1024: the 64 and 512 sets within 1/1024 of their strata's centres, the first frame's 8
        // within 9/1024 (docs/rasterizer.md).
        if (count == 64 || count == 512) {
            EXPECT_LE(worst_offset, 1.0 / 1024) << count << " samples";
        }
        if (count == 8) {
            EXPECT_LE(worst_offset, 9.0 / 1024);
        }
    }
    // Frames after the first continue the sequence: samples 8..15 fill the eighths' other halves.
    for (uint32_t n = 8; n < 16; ++n) EXPECT_EQ(static_cast<int>(row_height(n) * 16) % 2, 0);
}

TEST(RowSamples, HardCasePolygonsMatchTheCrossingTest) {
    const Polygon square = rectangle(1, 1, 3, 3);
    const std::vector<std::pair<const char*, std::vector<Polygon>>> cases = {
        {"square, counter-clockwise", {square}},
        {"square, clockwise", {reversed(square)}},
        {"diamond", {{{2, 0}, {4, 2}, {2, 4}, {0, 2}}}},
        {"crown", {{{0, 0}, {6, 0}, {6, 2}, {6, 4}, {5, 2}, {4, 4}, {3, 2}, {2, 4}, {1, 2}, {0, 4}}}},
        {"staircase", {{{0, 0}, {4, 0}, {4, 1}, {3, 1}, {3, 2}, {2, 2}, {2, 3}, {0, 3}}}},
        {"overlapping squares, same direction", {rectangle(0, 0, 3, 3), rectangle(1, 1, 4, 4)}},
        {"the same square twice", {rectangle(0, 0, 3, 3), rectangle(0, 0, 3, 3)}},
        {"overlapping squares, opposite directions", {rectangle(0, 0, 3, 3), reversed(rectangle(1, 1, 4, 4))}},
        {"ring with an island",
         {reversed(rectangle(0, 0, 4, 4)), rectangle(1, 1, 3, 3), reversed(rectangle(1.5, 1.5, 2.5, 2.5))}},
        {"bow-tie", {{{0, 0}, {2, 2}, {2, 0}, {0, 2}}}},
    };
    int rows = 0;
    for (const auto& [name, polygons] : cases) {
        SCOPED_TRACE(name);
        const Shape shape = make_polygon_shape(polygons);
        std::vector<double> heights;
        for (const Polygon& polygon : polygons) {
            for (const Vec2 p : polygon) {
                heights.push_back(p.y);  // rows through vertices and horizontal edges
                heights.push_back(p.y + 0x1p-12);
                heights.push_back(p.y - 0x1p-12);
            }
        }
        heights.push_back(1.3125);
        // Segments ending on vertices, on edges (crossings exactly at x0 or x1), and between.
        for (const double y : heights) {
            for (const auto& [x0, x1] : {std::pair{-1.0, 7.0},
                                         {0.0, 1.0},
                                         {1.0, 3.0},
                                         {0.5, 3.5},
                                         {2.0, 4.0},
                                         {1.5, 2.5},
                                         {0.25, 0.375},
                                         {3.0, 6.0}}) {
                // The truth is taken kBelow under the row: slanted edges move it by about that much.
                expect_row_length(shape, y, x0, x1, polygon_row_length(polygons, y, x0, x1), 1e-8);
                ++rows;
            }
        }
    }
    EXPECT_GT(rows, 500);
}

TEST(RowSamples, OverlappingContoursCountTheirUnionNotTheirSum) {
    // Both squares wind the same way: across the overlap the winding is 2, and the row [0.5, 3.5]
    // at y = 2 crosses both squares' left and right edges inside the segment. Summing signed
    // coverage per contour would give 2.5 + 2.5 = 5 (more than the segment); the union is 3.
    const Shape same = make_polygon_shape({rectangle(0, 0, 3, 3), rectangle(1, 1, 4, 4)});
    expect_row_length(same, 2.0, 0.5, 3.5, 3.0, 0.0);
    expect_row_length(same, 2.0, -1.0, 5.0, 4.0, 0.0);
    // The same square twice: winding 2 everywhere inside, covered once.
    const Shape twice = make_polygon_shape({rectangle(0, 0, 3, 3), rectangle(0, 0, 3, 3)});
    expect_row_length(twice, 1.5, -1.0, 2.0, 2.0, 0.0);
    // Opposite directions: the overlap winds 0 and is a hole.
    const Shape opposite = make_polygon_shape({rectangle(0, 0, 3, 3), reversed(rectangle(1, 1, 4, 4))});
    expect_row_length(opposite, 2.0, 0.5, 3.5, 1.0, 0.0);
    EXPECT_EQ(row_units<float>(3.0f, 3.0f, 0.999f, 64), 64u);
    EXPECT_EQ(row_units<float>(0.0f, 3.0f, 0.999f, 64), 0u);
}

TEST(RowSamples, SegmentsEndingExactlyOnARoot) {
    const Shape square = make_polygon_shape({rectangle(1, 1, 3, 3)});
    for (const double y : {1.0, 2.0, 3.0}) {  // the bottom edge row is not covered, the top one is
        const double inside = (y > 1.0) ? 1.0 : 0.0;
        expect_row_length(square, y, 1.0, 2.0, inside, 0.0);      // x0 on the left edge's crossing
        expect_row_length(square, y, 0.0, 1.0, 0.0, 0.0);         // x1 on it
        expect_row_length(square, y, 2.0, 3.0, inside, 0.0);      // x1 on the right edge's crossing
        expect_row_length(square, y, 3.0, 4.0, 0.0, 0.0);         // x0 on it
        expect_row_length(square, y, 1.0, 3.0, 2 * inside, 0.0);  // both ends on crossings
    }
    // A slanted edge: the diamond's crossing at y = 1 is x = 1 (left) and 3 (right).
    const Shape diamond = make_polygon_shape({{{2, 0}, {4, 2}, {2, 4}, {0, 2}}});
    expect_row_length(diamond, 1.0, 1.0, 3.0, 2.0, 0.0);
    expect_row_length(diamond, 1.0, 1.0, 1.5, 0.5, 0.0);
    expect_row_length(diamond, 1.0, 0.5, 1.0, 0.0, 0.0);
}

TEST(RowSamples, HorizontalTangentsAtTheRowHeight) {
    // An arch tangent to y = 2 at its apex (2, 2), a bowl tangent to y = 0 at (2, 0), and lenses
    // and circles whose extrema lie on the rows: the truth is the area of a strip just below the
    // row divided by its height (exact coverage), where the covered length varies as sqrt(depth).
    const std::vector<std::pair<const char*, std::vector<Contour>>> cases = {
        {"arch", {{Quad{{4, 0}, {2, 4}, {0, 0}}, line_to_quad({0, 0}, {4, 0})}}},
        {"bowl",
         {{Quad{{0, 2}, {2, -2}, {4, 2}}, line_to_quad({4, 2}, {4, 3}), line_to_quad({4, 3}, {0, 3}),
           line_to_quad({0, 3}, {0, 2})}}},
        {"overlapping lenses",
         {{Quad{{0, 0}, {2, 3}, {4, 0}}, Quad{{4, 0}, {2, -3}, {0, 0}}},
          {Quad{{1, 0.5}, {3, 3.5}, {5, 0.5}}, Quad{{5, 0.5}, {3, -2.5}, {1, 0.5}}}}},
        {"self-intersecting curves",
         {{Quad{{0, 0}, {4, 1}, {4, 4}}, Quad{{4, 4}, {2, 2}, {4, 0}}, Quad{{4, 0}, {0, 2}, {0, 4}},
           line_to_quad({0, 4}, {0, 0})}}},
    };
    constexpr double kStrip = 0x1p-40;
    for (const auto& [name, contours] : cases) {
        SCOPED_TRACE(name);
        const Shape shape = make_shape(contours);
        const ExactCoverage exact(shape.curves);
        for (const double y : {0.0, 2.0, 1.5, 2.0 - 0x1p-12, 0.5, 2.0 + 0x1p-12, 2.0 - 0x1p-23, 0x1p-30, 2.25}) {
            for (const auto& [x0, x1] : {std::pair{-1.0, 6.0}, {1.5, 2.5}, {2.0, 2.0 + 0x1p-10}, {0.75, 3.25}}) {
                const double truth = exact.area(x0, y - kStrip, x1, y) / kStrip;
                // At an extremum the strip's mean length is off by about sqrt(kStrip) = 1e-6. In
                // float, a row within 1e-9 of a tangent loses the discriminant (b^2 - a c cancels):
                // the crossings, sqrt(1e-9) apart, are missed, as point samples miss them there.
                expect_row_length(shape, y, x0, x1, truth, 1e-5, 2e-4);
            }
        }
        // At the apex row itself the arch touches the row in one point: nothing is covered.
        if (std::string_view(name) == "arch") expect_row_length(shape, 2.0, 0.0, 4.0, 0.0, 0.0);
    }
}

TEST(RowSamples, MoreCrossingsThanTheRegistersHoldTakeMorePassesAndStayExact) {
    // A comb of 13 bars 0.05 wide every 0.1 (26 crossings inside [-0.01, 1.3]), and a second comb
    // of the same direction overlapping each bar by half, so that the winding reaches 2 across
    // pass boundaries: the union must come out, whatever pass a crossing falls in.
    std::vector<Polygon> comb, overlapping;
    for (int i = 0; i < 13; ++i) {
        const double x = 0.1 * i;
        comb.push_back(rectangle(on_grid({x, 0}).x, 0, on_grid({x + 0.05, 0}).x, 1));
        overlapping.push_back(comb.back());
        overlapping.push_back(rectangle(on_grid({x + 0.025, 0}).x, 0.25, on_grid({x + 0.075, 0}).x, 1));
    }
    for (const auto* polygons : {&comb, &overlapping}) {
        const Shape shape = make_polygon_shape(*polygons);
        for (const double y : {0.5, 1.0, 0.25}) {
            const double truth = polygon_row_length(*polygons, y, -0.01, 1.3);
            uint32_t passes = 0, float_passes = 0;
            EXPECT_NEAR(row_covered_length<double>(shape.curves, y, -0.01, 1.3, &passes), truth, 1e-12);
            EXPECT_NEAR(row_covered_length_banded<float>(shape.asset, shape.glyph(), static_cast<float>(y), -0.01f,
                                                         1.3f, &float_passes),
                        truth, 1e-5);
            const size_t crossings = 2 * polygons->size() - (y < 0.25 + 1e-9 && polygons == &overlapping ? 13 * 2 : 0);
            EXPECT_GE(passes, (crossings + kRowCrossings - 1) / kRowCrossings) << y;
            EXPECT_GT(passes, 2u);
            EXPECT_EQ(float_passes, passes);
            expect_row_length(shape, y, -0.01, 1.3, truth, 1e-12);
        }
    }
    // More than kRowCrossings crossings at one x: the pass after them starts there.
    std::vector<Polygon> stacked;
    for (int i = 0; i < 6; ++i) stacked.push_back(rectangle(1, 0, 2, 1));
    const Shape shape = make_polygon_shape(stacked);
    uint32_t passes = 0;
    EXPECT_EQ(row_covered_length<double>(shape.curves, 0.5, 0.0, 3.0, &passes), 1.0);
    EXPECT_GT(passes, 1u);
}

// Row samples against point samples, both against exact area coverage over pixel boxes: mean
// absolute error per touched pixel and the worst pixel, at 8 (the first frame), 64 and 512 samples.
// Rows are as the atlas holds them (quantized to 1/64 with the dither). docs/coverage.md and
// docs/results/lavapipe-row-samples.md record the table this prints.
TEST(RowSamples, ConvergeToExactCoverageFasterThanPoints) {
    const FontKey variable{test::kInterVariable, 0, "Ak$", false};  // overlapping contours
    std::vector<RealGlyph> glyphs;
    for (const FontKey& key : {kDejaVu, kInter, variable}) {
        for (RealGlyph& glyph : real_glyphs(key)) {
            if (glyph.label.rfind("U+006C", 0) == 0 || glyph.label.rfind("U+0040 of Inter", 0) == 0) continue;
            glyphs.push_back(std::move(glyph));
        }
    }
    constexpr uint32_t kCounts[3] = {8, 64, 512};
    std::printf("%-28s %5s %6s | %-29s | %-29s | %-29s\n", "glyph", "px/em", "pixels", "8 samples: points / rows",
                "64: points / rows", "512: points / rows");
    for (const int size : {7, 16, 40}) {
        // [kind][count]: all glyphs' errors
        std::vector<double> all[2][3];
        for (const RealGlyph& glyph : glyphs) {
            const GlyphRecord& record = glyph.glyph();
            const ExactCoverage exact(*glyph.asset, record);
            const double pixel = 1.0 / size;
            const auto [i0, i1, j0, j1] = pixel_box(record, size);
            const int stride = std::max(1, (i1 - i0) * (j1 - j0) / 600);
            std::vector<double> errors[2][3];
            for (int j = j0; j < j1; ++j) {
                for (int i = i0; i < i1; ++i) {
                    if ((i * 7 + j * 13) % stride != 0) continue;
                    const double x0 = i * pixel, y0 = j * pixel, x1 = x0 + pixel, y1 = y0 + pixel;
                    const double truth = exact.coverage(x0, y0, x1, y1);
                    double got[2][3];
                    uint32_t done = 0;
                    double sums[2] = {0.0, 0.0};
                    for (size_t k = 0; k < 3; ++k) {
                        const uint32_t more = kCounts[k] - done;
                        sums[0] += more * coverage_points(*glyph.asset, record, x0, y0, x1, y1, more, done);
                        sums[1] += more * coverage_rows(*glyph.asset, record, x0, y0, x1, y1, more, done);
                        done = kCounts[k];
                        for (int kind = 0; kind < 2; ++kind) got[kind][k] = sums[kind] / done;
                    }
                    if (truth == 0.0 && got[0][2] == 0.0 && got[1][2] == 0.0) continue;  // untouched
                    for (int kind = 0; kind < 2; ++kind) {
                        for (size_t k = 0; k < 3; ++k) errors[kind][k].push_back(std::fabs(got[kind][k] - truth));
                    }
                }
            }
            auto print = [&](const char* label, std::vector<double>(&e)[2][3]) {
                std::printf("%-28s %5d %6zu", label, size, e[0][0].size());
                for (size_t k = 0; k < 3; ++k) {
                    const ErrorStats p = error_stats(e[0][k]), r = error_stats(e[1][k]);
                    std::printf(" | %.4f %.3f / %.4f %.3f", p.mean, p.max, r.mean, r.max);
                }
                std::printf("\n");
            };
            print(glyph.label.c_str(), errors);
            for (int kind = 0; kind < 2; ++kind) {
                for (size_t k = 0; k < 3; ++k) {
                    all[kind][k].insert(all[kind][k].end(), errors[kind][k].begin(), errors[kind][k].end());
                }
            }
        }
        const ErrorStats p8 = error_stats(all[0][0]), r8 = error_stats(all[1][0]);
        const ErrorStats p64 = error_stats(all[0][1]), r64 = error_stats(all[1][1]);
        const ErrorStats p512 = error_stats(all[0][2]), r512 = error_stats(all[1][2]);
        std::printf("%-28s %5d %6zu | %.4f %.3f / %.4f %.3f | %.4f %.3f / %.4f %.3f | %.4f %.3f / %.4f %.3f\n", "all",
                    size, p8.pixels, p8.mean, p8.max, r8.mean, r8.max, p64.mean, p64.max, r64.mean, r64.max, p512.mean,
                    p512.max, r512.mean, r512.max);
        EXPECT_GT(p8.pixels, 100u);
        // Generous bounds: rows are clearly better at 8 and 64 samples and no worse converged.
        EXPECT_LT(r8.mean, 0.7 * p8.mean) << size;
        EXPECT_LT(r8.max, p8.max) << size;
        EXPECT_LT(r64.mean, 0.5 * p64.mean) << size;
        EXPECT_LT(r512.mean, p512.mean) << size;
        EXPECT_LT(r512.max, 0.02) << size;
    }
}
}  // namespace
}  // namespace crisp
