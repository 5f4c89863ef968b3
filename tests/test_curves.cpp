#include "asset/curves.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <cmath>
#include <vector>

namespace crisp {
namespace {

// Evaluated here independently of bake/curves.cpp, in the power basis.
Vec2 cubic_at(const Cubic& c, double t) {
    const Vec2 a = c.p3 - 3.0 * c.p2 + 3.0 * c.p1 - c.p0;
    const Vec2 b = 3.0 * (c.p2 - 2.0 * c.p1 + c.p0);
    const Vec2 d = 3.0 * (c.p1 - c.p0);
    return c.p0 + t * (d + t * (b + t * a));
}

Vec2 quad_at(const Quad& q, double t) {
    const Vec2 a = q.p2 - 2.0 * q.p1 + q.p0;
    const Vec2 b = 2.0 * (q.p1 - q.p0);
    return q.p0 + t * (b + t * a);
}

double distance(Vec2 a, Vec2 b) {
    return std::hypot(a.x - b.x, a.y - b.y);
}

// Largest distance between the cubic and its pieces at equal parameters, sampled densely, and
// checks that the pieces join up into one continuous curve from p0 to p3.
double check_lowering(const Cubic& c, double tolerance) {
    std::vector<Quad> pieces;
    lower_cubic(c, tolerance, pieces);
    EXPECT_FALSE(pieces.empty());
    EXPECT_EQ(pieces.front().p0, c.p0);
    EXPECT_EQ(pieces.back().p2, c.p3);
    for (size_t i = 1; i < pieces.size(); ++i) EXPECT_EQ(pieces[i - 1].p2, pieces[i].p0);
    const double n = static_cast<double>(pieces.size());
    double worst = 0.0;
    for (size_t i = 0; i < pieces.size(); ++i) {
        for (int k = 0; k <= 200; ++k) {
            const double s = k / 200.0;
            const double t = (static_cast<double>(i) + s) / n;
            worst = std::max(worst, distance(cubic_at(c, t), quad_at(pieces[i], s)));
        }
    }
    return worst;
}

TEST(Curves, LineToQuadraticIsExact) {
    const Vec2 a{-3.25, 7.5}, b{12.125, -0.75};
    const Quad q = line_to_quad(a, b);
    for (int k = 0; k <= 64; ++k) {
        const double t = k / 64.0;
        const Vec2 on_line{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
        EXPECT_NEAR(quad_at(q, t).x, on_line.x, 1e-12);
        EXPECT_NEAR(quad_at(q, t).y, on_line.y, 1e-12);
    }
    // The control point is the midpoint, on the line.
    EXPECT_DOUBLE_EQ(q.p1.x, (a.x + b.x) / 2);
    EXPECT_DOUBLE_EQ(q.p1.y, (a.y + b.y) / 2);
}

TEST(Curves, MidpointErrorIsTheMeasuredError) {
    const Cubic c{{0, 0}, {0.2, 0.9}, {0.9, 1.1}, {1, 0}};
    const Quad q = midpoint_quad(c);
    double worst = 0.0;
    for (int k = 0; k <= 20000; ++k)
        worst = std::max(worst, distance(cubic_at(c, k / 20000.0), quad_at(q, k / 20000.0)));
    EXPECT_NEAR(midpoint_error(c), worst, 1e-6 * worst);
}

struct HardCubic {
    const char* name;
    Cubic cubic;
};

const HardCubic kHardCubics[] = {
    {"cusp", {{0, 0}, {1, 1}, {0, 1}, {1, 0}}},
    {"loop", {{0, 0}, {1.5, 1}, {-0.5, 1}, {1, 0}}},
    {"inflection", {{0, 0}, {0.3, 1}, {0.7, -1}, {1, 0}}},
    {"near-degenerate", {{0, 0}, {1e-9, 0}, {1, 1e-9}, {1, 0}}},
    {"collinear-overshoot", {{0, 0}, {2, 0}, {-1, 0}, {1, 0}}},
    {"all-equal", {{0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}}},
    {"quadratic-in-disguise", {{0, 0}, {2.0 / 3, 2.0 / 3}, {4.0 / 3, 2.0 / 3}, {2, 0}}},
    {"tiny", {{0, 0}, {1e-6, 2e-6}, {3e-6, 2e-6}, {4e-6, 0}}},
    {"wide", {{-30, -20}, {40, 35}, {-35, 30}, {25, -15}}},
};

TEST(Curves, CubicLoweringStaysWithinToleranceOnHardCubics) {
    for (const HardCubic& hard : kHardCubics) {
        for (const double tolerance : {1e-2, 1.0 / 4096, 1e-5}) {
            SCOPED_TRACE(std::string(hard.name) + " at tolerance " + std::to_string(tolerance));
            EXPECT_LE(check_lowering(hard.cubic, tolerance), tolerance * (1 + 1e-9));
        }
    }
}

TEST(Curves, CubicLoweringUsesFewPieces) {
    // A quadratic written as a cubic needs one piece; error falls as n^3, so a 1000x tighter
    // tolerance costs 10x the pieces, not 1000x.
    std::vector<Quad> pieces;
    lower_cubic(kHardCubics[6].cubic, 1e-9, pieces);
    EXPECT_EQ(pieces.size(), 1u);
    std::vector<Quad> loose, tight;
    lower_cubic(kHardCubics[1].cubic, 1e-3, loose);
    lower_cubic(kHardCubics[1].cubic, 1e-6, tight);
    EXPECT_LE(tight.size(), 10 * loose.size() + 1);
    EXPECT_GT(tight.size(), loose.size());
}

TEST(Curves, SeedSplitIsWorseThanAdaptiveOnALoop) {
    Quad seed[2];
    seed_split_cubic(kHardCubics[1].cubic, seed);
    const double seed_error = std::max(sampled_deviation(kHardCubics[1].cubic, 0.0, 0.5, seed[0], 256),
                                       sampled_deviation(kHardCubics[1].cubic, 0.5, 1.0, seed[1], 256));
    EXPECT_GT(seed_error, 10 * check_lowering(kHardCubics[1].cubic, 1.0 / 4096));
}

struct CubicCollector {
    std::vector<Cubic> cubics;
    Vec2 pen;
};

Vec2 to_vec(const FT_Vector* v) {
    return {static_cast<double>(v->x) / 1000.0, static_cast<double>(v->y) / 1000.0};
}

TEST(Curves, CubicLoweringStaysWithinToleranceOnEveryCubicOfACffFont) {
    FT_Library library = nullptr;
    ASSERT_EQ(FT_Init_FreeType(&library), 0);
    FT_Face face = nullptr;
    ASSERT_EQ(FT_New_Face(library, test::kInterCff.c_str(), 0, &face), 0);
    FT_Outline_Funcs funcs{};
    funcs.move_to = [](const FT_Vector* to, void* user) {
        static_cast<CubicCollector*>(user)->pen = to_vec(to);
        return 0;
    };
    funcs.line_to = funcs.move_to;
    funcs.conic_to = [](const FT_Vector*, const FT_Vector* to, void* user) {
        static_cast<CubicCollector*>(user)->pen = to_vec(to);
        return 0;
    };
    funcs.cubic_to = [](const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
        auto* collector = static_cast<CubicCollector*>(user);
        collector->cubics.push_back({collector->pen, to_vec(c1), to_vec(c2), to_vec(to)});
        collector->pen = to_vec(to);
        return 0;
    };
    CubicCollector collector;
    const double units_per_em = face->units_per_EM;
    for (FT_Long glyph = 0; glyph < face->num_glyphs; ++glyph) {
        ASSERT_EQ(FT_Load_Glyph(face, static_cast<FT_UInt>(glyph), FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING), 0);
        FT_Outline_Decompose(&face->glyph->outline, &funcs, &collector);
    }
    FT_Done_Face(face);
    FT_Done_FreeType(library);
    ASSERT_GT(collector.cubics.size(), 10000u);

    const double tolerance = 1.0 / 4096;
    double worst = 0.0;
    for (Cubic c : collector.cubics) {
        // to_vec divided by 1000; bring it to em.
        for (Vec2* p : {&c.p0, &c.p1, &c.p2, &c.p3}) *p = (1000.0 / units_per_em) * *p;
        worst = std::max(worst, check_lowering(c, tolerance));
    }
    EXPECT_LE(worst, tolerance * (1 + 1e-9));
    EXPECT_GT(worst, tolerance / 8);  // the font does exercise the tolerance
}

TEST(Curves, SplitAtYExtremumGivesMonotonicPieces) {
    const Quad q{{0, 0}, {1, 2}, {2, -0.5}};
    Quad pieces[2];
    ASSERT_EQ(split_at_y_extremum(q, pieces), 2);
    EXPECT_EQ(pieces[0].p0, q.p0);
    EXPECT_EQ(pieces[1].p2, q.p2);
    EXPECT_EQ(pieces[0].p2, pieces[1].p0);
    for (const Quad& piece : pieces) {
        double previous = piece.p0.y;
        const double direction = piece.p2.y - piece.p0.y;
        for (int k = 1; k <= 100; ++k) {
            const double y = quad_at(piece, k / 100.0).y;
            EXPECT_GE((y - previous) * direction, -1e-12);
            previous = y;
        }
    }
    // The pieces trace the original curve: the extremum is the curve's highest point.
    EXPECT_NEAR(pieces[0].p2.y, 8.0 / 9.0, 1e-12);  // max of y(t) = 4t - 4.5t^2, at t = 4/9
    // Monotonic curves are left alone.
    ASSERT_EQ(split_at_y_extremum(line_to_quad({0, 0}, {1, 1}), pieces), 1);
}

TEST(Curves, ZeroLengthIsDetected) {
    EXPECT_TRUE(is_zero_length({{1, 1}, {1, 1}, {1, 1}}));
    EXPECT_FALSE(is_zero_length({{1, 1}, {2, 1}, {1, 1}}));  // a spike has length
}

}  // namespace
}  // namespace crisp
