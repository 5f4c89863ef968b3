// Transform placement on the CPU (docs/transforms.md): quantized keys, rects and texel maps of
// transformed keys, text on a plane against a camera built by hand, the refusals, and what a
// transformed glyph costs the rasterizer.
#include "plane_support.hpp"
#include "test_support.hpp"

#include <crisp/compositor.hpp>
#include <crisp/glyph.hpp>
#include <crisp/transform.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace crisp {
namespace {

constexpr float kSize = 14.0f;

// DejaVu Sans with the glyphs the tests use, made once.
const Font& font() {
    static const std::unique_ptr<Font> made = test::bake_test_font("AEoB");
    EXPECT_TRUE(made);
    return *made;
}

GlyphInstance laid_out(char32_t c, float size, float x, float y) {
    TextStyle style;
    style.size = size;
    LayoutOptions options;
    options.origin_x = x;
    options.origin_y = y;
    const std::string text(1, static_cast<char>(c));
    const TextLayout layout = test::layout_or_fail({&font()}, text, style, options);
    EXPECT_EQ(layout.glyphs.size(), 1u);
    return layout.glyphs.empty() ? GlyphInstance{} : layout.glyphs[0];
}

const GlyphRecord& record_of(const GlyphInstance& g) {
    return font().asset().glyphs[g.key.glyph];
}

TextTransform rotation(double degrees, double scale = 1.0) {
    const double t = degrees * std::numbers::pi / 180.0;
    const auto c = static_cast<float>(std::cos(t) * scale), s = static_cast<float>(std::sin(t) * scale);
    return {c, -s, s, c, 0.0f, 0.0f};
}

// `laid` placed as requests.cpp places a draw's glyph: its subpixel offset cleared, then
// place_glyph() at `steps`.
bool place(const GlyphInstance& laid, const GlyphPlacement& placement, const TransformSteps& steps,
           GlyphInstance& out) {
    out = laid;
    out.key.subpixel_x = out.key.subpixel_y = 0;
    return place_glyph(record_of(laid), placement, steps, out);
}

GlyphPlacement transformed(const GlyphInstance& laid, const TextTransform& t) {
    return place_transformed(t, laid.pen_x, laid.pen_y, laid.key.size_x / 256.0, laid.key.size_y / 256.0, 0.0, 0.0);
}

TEST(TransformPlacement, FineKeysStepBy1Over256PixelPerEmAndCoarseOnesBy64) {
    const GlyphInstance laid = laid_out('A', kSize, 20.3f, 30.7f);
    GlyphPlacement p;
    p.pen_x = 20.3;
    p.pen_y = 30.7;
    const double linear[4] = {14.0013, 0.3017, -0.2093, -13.8871};
    std::copy(std::begin(linear), std::end(linear), std::begin(p.linear));
    p.perspective[0] = 0.0031;
    p.perspective[1] = -0.0007;
    GlyphInstance fine, coarse;
    ASSERT_TRUE(place(laid, p, kStillTransformSteps, fine));
    ASSERT_TRUE(place(laid, p, kMovingTransformSteps, coarse));
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(fine.key.linear[i], std::lround(linear[i] * kLinearOne)) << i;
        EXPECT_EQ(coarse.key.linear[i] % 64, 0) << i;
        EXPECT_EQ(coarse.key.linear[i], 64 * std::lround(linear[i] * kLinearOne / 64.0)) << i;
    }
    EXPECT_EQ(fine.key.perspective[0], std::lround(0.0031 * kPerspectiveOne));
    EXPECT_EQ(fine.key.perspective[1], std::lround(-0.0007 * kPerspectiveOne));
    for (int i = 0; i < 2; ++i) EXPECT_EQ(coarse.key.perspective[i] % 1024, 0) << i;
    // The pen: 1/256 px still, quarter pixels moving.
    EXPECT_EQ(fine.key.subpixel_x, std::lround(0.3 * 256));
    EXPECT_EQ(fine.key.subpixel_y, std::lround(0.7 * 256));
    EXPECT_EQ(coarse.key.subpixel_x, 64);
    EXPECT_EQ(coarse.key.subpixel_y, 192);
    // The key's sizes: its linear part's column lengths.
    const double q0 = fine.key.linear[0] / kLinearOne, q2 = fine.key.linear[2] / kLinearOne;
    EXPECT_EQ(fine.key.size_x, static_cast<uint32_t>(std::lround(std::hypot(q0, q2) * kSizeOne)));
    EXPECT_TRUE(is_transformed(fine.key));
    EXPECT_NE(fine.key, coarse.key);
}

TEST(TransformPlacement, IdentityLikeTransformsGiveTheLayoutsOwnKey) {
    const GlyphInstance laid = laid_out('A', kSize, 20.3f, 30.7f);
    for (const TextTransform& t : {TextTransform{}, rotation(360.0), rotation(-0.0001)}) {
        GlyphInstance placed;
        ASSERT_TRUE(place(laid, transformed(laid, t), kStillTransformSteps, placed));
        EXPECT_FALSE(is_transformed(placed.key));
        EXPECT_EQ(placed.key, laid.key);
        EXPECT_EQ(placed.x, laid.x);
        EXPECT_EQ(placed.y, laid.y);
        EXPECT_EQ(placed.width, laid.width);
        EXPECT_EQ(placed.height, laid.height);
    }
    // A uniform scale of 2 about the pen: the axis-aligned key of twice the size.
    GlyphInstance doubled;
    TextTransform scale{2.0f, 0.0f, 0.0f, 2.0f, laid.pen_x, laid.pen_y};
    ASSERT_TRUE(place(laid, transformed(laid, scale), kStillTransformSteps, doubled));
    EXPECT_FALSE(is_transformed(doubled.key));
    EXPECT_EQ(doubled.key.size_x, 2 * laid.key.size_x);
    EXPECT_EQ(doubled.key.size_y, 2 * laid.key.size_y);
}

TEST(TransformPlacement, MirroredAndRotatedKeysCarryTheirSigns) {
    const GlyphInstance laid = laid_out('A', kSize, 20.0f, 30.0f);
    const int32_t one = static_cast<int32_t>(static_cast<double>(kSize) * kLinearOne);
    GlyphInstance mirrored_x, mirrored_y, turned;
    ASSERT_TRUE(
        place(laid, transformed(laid, {-1.0f, 0.0f, 0.0f, 1.0f, 20.0f, 30.0f}), kStillTransformSteps, mirrored_x));
    ASSERT_TRUE(
        place(laid, transformed(laid, {1.0f, 0.0f, 0.0f, -1.0f, 20.0f, 30.0f}), kStillTransformSteps, mirrored_y));
    ASSERT_TRUE(place(laid, transformed(laid, rotation(180.0)), kStillTransformSteps, turned));
    // em y up to pixels y down: the untransformed L is diag(size, -size).
    EXPECT_TRUE(is_transformed(mirrored_x.key));
    EXPECT_EQ(mirrored_x.key.linear[0], -one);
    EXPECT_EQ(mirrored_x.key.linear[3], -one);
    EXPECT_TRUE(is_transformed(mirrored_y.key));
    EXPECT_EQ(mirrored_y.key.linear[0], one);
    EXPECT_EQ(mirrored_y.key.linear[3], one);
    EXPECT_EQ(turned.key.linear[0], -one);
    EXPECT_EQ(turned.key.linear[3], one);
    EXPECT_EQ(mirrored_x.key.size_x, laid.key.size_x);
    EXPECT_EQ(mirrored_y.key.size_y, laid.key.size_y);
    // Mirrored in x about its pen: the rect lies left of the pen, as wide as the laid-out one.
    EXPECT_LT(mirrored_x.x + static_cast<int32_t>(mirrored_x.width), laid.x + static_cast<int32_t>(laid.width));
    EXPECT_EQ(mirrored_x.width, laid.width);
    // Mirrored in y about the baseline: below it.
    EXPECT_GE(mirrored_y.y + kGlyphPadding, 30);
}

TEST(TransformPlacement, RefusesWhatCannotBeDrawnAndLeavesTheGlyphAlone) {
    const GlyphInstance laid = laid_out('A', kSize, 20.0f, 30.0f);
    GlyphPlacement good = transformed(laid, rotation(37.0));
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    std::vector<GlyphPlacement> bad(8, good);
    bad[0].linear[1] = nan;
    bad[1].pen_x = inf;
    bad[2].perspective[0] = nan;
    bad[3].linear[0] = bad[3].linear[1] = bad[3].linear[2] = bad[3].linear[3] = 0.0;  // singular
    bad[4].linear[0] = 2.0;                                                           // rank 1, exactly in key units
    bad[4].linear[1] = 4.0;
    bad[4].linear[2] = 1.0;
    bad[4].linear[3] = 2.0;
    bad[5].linear[0] = 8388608.0;  // 2^23 px per em
    bad[6].perspective[1] = 2048.0;
    bad[7].pen_y = 3.0e7;
    for (size_t i = 0; i < bad.size(); ++i) {
        GlyphInstance glyph = laid;
        EXPECT_FALSE(place_glyph(record_of(laid), bad[i], kStillTransformSteps, glyph)) << i;
        EXPECT_EQ(glyph.key, laid.key) << i;
        EXPECT_EQ(glyph.x, laid.x) << i;
    }
    // A tiny but regular linear part (det 2^-14 px^2 per em^2) is drawn: a glyph smaller than a texel.
    GlyphPlacement tiny = good;
    tiny.linear[0] = 1.0 / 128.0;
    tiny.linear[1] = tiny.linear[2] = 0.0;
    tiny.linear[3] = 1.0 / 128.0;
    GlyphInstance glyph;
    EXPECT_TRUE(place(laid, tiny, kStillTransformSteps, glyph));
}

TEST(TransformPlacement, ValidTransformAndValidPlaneEdges) {
    EXPECT_TRUE(valid_transform({}));
    EXPECT_TRUE(valid_transform(rotation(271.3, 0.25)));
    EXPECT_TRUE(valid_transform({-1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}));
    EXPECT_TRUE(valid_transform({1.0f / 256, 0.0f, 0.0f, 1.0f / 256, 0.0f, 0.0f}));  // det 2^-16: the limit
    EXPECT_FALSE(valid_transform({1.0f / 512, 0.0f, 0.0f, 1.0f / 256, 0.0f, 0.0f}));
    EXPECT_FALSE(valid_transform({0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f}));
    EXPECT_FALSE(valid_transform({1.0f, 2.0f, 2.0f, 4.0f, 0.0f, 0.0f}));  // rank 1
    EXPECT_FALSE(valid_transform({65537.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}));
    EXPECT_TRUE(valid_transform({65536.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}));
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    EXPECT_FALSE(valid_transform({nan, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}));
    EXPECT_FALSE(valid_transform({1.0f, 0.0f, 0.0f, 1.0f, inf, 0.0f}));
    EXPECT_FALSE(valid_transform({1.0f, 0.0f, 0.0f, 1.0f, 0.0f, nan}));

    const TextPlane good = test::plane_seen_from({0.0, 0.0, 10.0}, {0.0, 0.0, 0.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_TRUE(valid_plane(good));
    TextPlane parallel = good;
    parallel.axis_y = {-0.04f, 0.0f, 0.0f};
    EXPECT_FALSE(valid_plane(parallel));
    TextPlane zero_axis = good;
    zero_axis.axis_x = {0.0f, 0.0f, 0.0f};
    EXPECT_FALSE(valid_plane(zero_axis));
    for (size_t i : {2u, 3u}) {
        TextPlane flat = good;
        flat.viewport[i] = 0.0f;
        EXPECT_FALSE(valid_plane(flat)) << i;
        flat.viewport[i] = -5.0f;
        EXPECT_FALSE(valid_plane(flat)) << i;
    }
    TextPlane not_finite = good;
    not_finite.view_projection[5] = nan;
    EXPECT_FALSE(valid_plane(not_finite));
    not_finite = good;
    not_finite.origin[2] = inf;
    EXPECT_FALSE(valid_plane(not_finite));
    not_finite = good;
    not_finite.viewport[0] = nan;
    EXPECT_FALSE(valid_plane(not_finite));
}

TEST(TransformPlacement, RectHoldsTheMappedBboxCornersWithPadding) {
    const GlyphInstance laid = laid_out('A', kSize, 20.0f, 30.0f);
    const GlyphRecord& g = record_of(laid);
    GlyphPlacement projective = transformed(laid, rotation(20.0));
    projective.perspective[0] = 0.2;
    projective.perspective[1] = -0.1;
    for (const GlyphPlacement& p : {transformed(laid, rotation(37.0)), transformed(laid, rotation(271.3, 8.0)),
                                    transformed(laid, {1.0f, 0.5f, -0.5f, 1.0f, 0.0f, 0.0f}),
                                    transformed(laid, rotation(90.0, 0.25)), projective}) {
        GlyphInstance placed;
        ASSERT_TRUE(place(laid, p, kStillTransformSteps, placed));
        ASSERT_TRUE(is_transformed(placed.key));
        const GlyphRect rect = glyph_rect(g, placed.key);
        ASSERT_GT(rect.width, 0u);
        double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
        for (int corner = 0; corner < 4; ++corner) {
            const double ex = (corner & 1) ? g.bbox_max_x : g.bbox_min_x,
                         ey = (corner & 2) ? g.bbox_max_y : g.bbox_min_y;
            const std::array<double, 2> q = test::placed_point(p, ex, ey);
            // Relative to the rect of the placed instance on the target.
            lo_x = std::min(lo_x, q[0] - placed.x);
            hi_x = std::max(hi_x, q[0] - placed.x);
            lo_y = std::min(lo_y, q[1] - placed.y);
            hi_y = std::max(hi_y, q[1] - placed.y);
        }
        const double tolerance = 1.0 / 128;  // the key's quantization moves corners by less
        EXPECT_GE(lo_x, kGlyphPadding - tolerance);
        EXPECT_GE(lo_y, kGlyphPadding - tolerance);
        EXPECT_LE(hi_x, rect.width - kGlyphPadding + tolerance);
        EXPECT_LE(hi_y, rect.height - kGlyphPadding + tolerance);
        // And no wider than the corners' pixels and padding.
        EXPECT_LT(lo_x, kGlyphPadding + 1 + tolerance);
        EXPECT_GT(hi_x, rect.width - kGlyphPadding - 1 - tolerance);
        EXPECT_EQ(placed.width, rect.width);
        EXPECT_EQ(placed.height, rect.height);
    }
    // A corner behind the eye: an empty rect.
    GlyphPlacement behind = projective;
    behind.perspective[0] = -2.0;
    GlyphInstance placed;
    ASSERT_TRUE(place(laid, behind, kStillTransformSteps, placed));
    EXPECT_EQ(glyph_rect(g, placed.key).width, 0u);
    EXPECT_EQ(placed.width, 0u);
}

std::array<double, 2> apply(const Projective& map, double x, double y) {
    const double* m = map.m;
    const double w = m[6] * x + m[7] * y + m[8];
    return {(m[0] * x + m[1] * y + m[2]) / w, (m[3] * x + m[4] * y + m[5]) / w};
}

TEST(TransformPlacement, EmToTexelAndItsInverseRoundTrip) {
    const GlyphInstance laid = laid_out('A', kSize, 20.4f, 30.6f);
    const GlyphRecord& g = record_of(laid);
    GlyphPlacement projective = transformed(laid, rotation(-63.0, 1.7));
    projective.perspective[0] = 0.3;
    projective.perspective[1] = 0.15;
    for (const GlyphPlacement& p : {transformed(laid, rotation(37.0)), projective}) {
        GlyphInstance placed;
        ASSERT_TRUE(place(laid, p, kStillTransformSteps, placed));
        const GlyphRect rect = glyph_rect(g, placed.key);
        const Projective to_texel = em_to_texel(rect, placed.key), to_em = inverse(to_texel);
        for (const auto& e : {std::array<double, 2>{0.0, 0.0}, {0.25, 0.6}, {-0.1, 0.9}, {0.7, -0.2}}) {
            const std::array<double, 2> t = apply(to_texel, e[0], e[1]);
            const std::array<double, 2> back = apply(to_em, t[0], t[1]);
            EXPECT_NEAR(back[0], e[0], 1e-12);
            EXPECT_NEAR(back[1], e[1], 1e-12);
            // The texel is the placed point relative to the rect (within the key's quantization).
            const std::array<double, 2> q = test::placed_point(p, e[0], e[1]);
            EXPECT_NEAR(t[0], q[0] - placed.x, 0.01);
            EXPECT_NEAR(t[1], q[1] - placed.y, 0.01);
        }
    }
    // Axis-aligned keys: em_to_texel() is texel_to_em()'s inverse.
    const GlyphRect rect = glyph_rect(g, laid.key);
    const TexelToEm map = texel_to_em(rect, laid.key);
    const std::array<double, 2> t =
        apply(em_to_texel(rect, laid.key), static_cast<double>(map.offset_x + 3.0f * map.scale_x),
              static_cast<double>(map.offset_y + 5.0f * map.scale_y));
    EXPECT_NEAR(t[0], 3.0, 1e-5);
    EXPECT_NEAR(t[1], 5.0, 1e-5);
    // A singular map inverts to the identity.
    Projective singular;
    singular.m[0] = singular.m[4] = singular.m[8] = 0.0;
    const Projective identity = inverse(singular);
    EXPECT_EQ(identity.m[0], 1.0);
    EXPECT_EQ(identity.m[1], 0.0);
    EXPECT_EQ(identity.m[4], 1.0);
}

// The largest distance between `place` and the plane's exact projection over the glyph's bbox
// (its corners and edge midpoints).
double distance_from_projection(const TextPlane& plane, const GlyphRecord& g, const GlyphPlacement& place, double pen_x,
                                double pen_y, double size) {
    double worst = 0.0;
    for (const double fx : {0.0, 0.5, 1.0}) {
        for (const double fy : {0.0, 0.5, 1.0}) {
            const std::array<double, 4> box = test::bbox_of(g);
            const double ex = box[0] + fx * (box[2] - box[0]), ey = box[1] + fy * (box[3] - box[1]);
            const std::array<double, 3> exact =
                test::project(plane, test::plane_point(plane, pen_x + size * ex, pen_y - size * ey));
            const std::array<double, 2> q = test::placed_point(place, ex, ey);
            worst = std::max(worst, std::hypot(q[0] - exact[0], q[1] - exact[1]));
        }
    }
    return worst;
}

TEST(TransformPlane, AFarPlaneIsLocallyAffineAndAGrazingOrNearOneProjective) {
    const GlyphInstance laid = laid_out('A', 16.0f, 0.0f, 0.0f);
    const GlyphRecord& g = record_of(laid);
    const struct {
        const char* what;
        test::Vec3 eye;
        float scale;  // world units per layout pixel
        double pen_x;
        bool projective;
        double max_error;  // of an affine one: the local affine's error is below it
    } cases[] = {
        {"a little off-axis", {0.0, 0.0, 10.0}, 0.02f, 40.0, false, kMaxLocalAffineError},
        {"a little tilted, 20 px", {3.0, 2.0, 100.0}, 0.2f, 40.0, false, kMaxLocalAffineError},
        // The error grows as the square of the glyph's size on screen: (3 / 20)^2 of the last one's.
        {"far, tilted, 3 px", {3.0, 2.0, 100.0}, 0.03f, 40.0, false, 2e-4},
        {"grazing", {0.0, -9.0, 0.6}, 0.02f, 40.0, true, 0.0},
        {"near", {0.4, 0.0, 0.35}, 0.02f, 10.0, true, 0.0},
    };
    for (const auto& c : cases) {
        const TextPlane plane = test::plane_seen_from(c.eye, {0.5, -0.1, 0.0}, c.scale, 800.0f, 600.0f);
        const double size = 16.0;
        const PlanePlacement on = place_on_plane(plane, g, c.pen_x, -5.0, size, size);
        ASSERT_TRUE(on.visible) << c.what;
        std::printf("[ transform ] plane %s: local-affine error %.3g px, %s\n", c.what, on.affine_error,
                    on.projective ? "projective" : "affine");
        EXPECT_EQ(on.projective, c.projective) << c.what << ": error " << on.affine_error;
        EXPECT_EQ(on.projective, on.affine_error > kMaxLocalAffineError) << c.what;
        const double off = distance_from_projection(plane, g, on.place, c.pen_x, -5.0, size);
        if (on.projective) {
            EXPECT_LT(off, 1e-6) << c.what;  // the exact projective placement
        } else {
            // The local affine: as far off as it says, within the bound (floats of the plane).
            EXPECT_LE(off, kMaxLocalAffineError + 1e-6) << c.what;
            EXPECT_LT(on.affine_error, c.max_error) << c.what;
            EXPECT_LE(off, on.affine_error + 1e-6) << c.what;
            EXPECT_EQ(on.place.perspective[0], 0.0);
            EXPECT_EQ(on.place.perspective[1], 0.0);
        }
        // Depth: the NDC z of the bbox centre's world point.
        const std::array<double, 4> box = test::bbox_of(g);
        const double cx = 0.5 * (box[0] + box[2]), cy = 0.5 * (box[1] + box[3]);
        const test::Vec3 centre = test::plane_point(plane, c.pen_x + size * cx, -5.0 - size * cy);
        const float world[3] = {static_cast<float>(centre[0]), static_cast<float>(centre[1]),
                                static_cast<float>(centre[2])};
        const std::optional<float> depth = depth_from_view_projection(plane.view_projection.data(), world);
        ASSERT_TRUE(depth) << c.what;
        EXPECT_NEAR(on.depth, *depth, 1e-6) << c.what;
    }
    // Facing the camera squarely, the projection is affine: no error at all but rounding.
    const TextPlane facing = test::plane_seen_from({0.0, 0.0, 10.0}, {0.0, 0.0, 0.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_LT(place_on_plane(facing, g, 0.0, 0.0, 16.0, 16.0).affine_error, 1e-6);
}

TEST(TransformPlane, GlyphsBehindTheEyeOrPastTheDepthRangeAreInvisible) {
    const GlyphInstance laid = laid_out('A', 16.0f, 0.0f, 0.0f);
    const GlyphRecord& g = record_of(laid);
    // Looking away from the plane.
    const TextPlane away = test::plane_seen_from({0.0, 0.0, 10.0}, {0.0, 0.0, 20.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_FALSE(place_on_plane(away, g, 0.0, 0.0, 16.0, 16.0).visible);
    // The eye in the plane of the text, a glyph crossing the eye plane: some corner behind it.
    const TextPlane across = test::plane_seen_from({0.0, 0.0, 0.05}, {0.0, 0.0, 0.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_FALSE(place_on_plane(across, g, 0.0, -8.0, 16.0, 16.0).visible);
    // Beyond the far plane (1000 world units).
    const TextPlane far = test::plane_seen_from({0.0, 0.0, 2000.0}, {0.0, 0.0, 0.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_FALSE(place_on_plane(far, g, 0.0, 0.0, 16.0, 16.0).visible);
    // And the same glyph in front is seen.
    const TextPlane front = test::plane_seen_from({0.0, 0.0, 10.0}, {0.0, 0.0, 0.0}, 0.02f, 800.0f, 600.0f);
    EXPECT_TRUE(place_on_plane(front, g, 0.0, 0.0, 16.0, 16.0).visible);
}

TEST(TransformKeys, HashesDifferForDifferentLinearParts) {
    GlyphKey a = test::key_at(3, 14, 0, 0);
    a.linear[0] = 3584;
    a.linear[3] = -3584;
    a.linear[1] = 100;
    a.linear[2] = -50;
    const GlyphKeyHash hash;
    const size_t base = hash(a);
    for (int i = 0; i < 4; ++i) {
        GlyphKey b = a;
        b.linear[i] += 1;
        EXPECT_NE(hash(b), base) << i;
        b = a;
        b.linear[i] = -b.linear[i];
        EXPECT_NE(hash(b), base) << i;
    }
    for (int i = 0; i < 2; ++i) {
        GlyphKey b = a;
        b.perspective[i] = 1;
        EXPECT_NE(hash(b), base) << i;
    }
    // Two rotations of one glyph at one size share sizes but not hashes.
    GlyphKey r1 = a, r2 = a;
    r1.linear[1] = 1200;
    r1.linear[2] = -1200;
    r2.linear[1] = -1200;
    r2.linear[2] = 1200;
    EXPECT_NE(hash(r1), hash(r2));
}

TEST(TransformKeys, FlatCurveWordsListTheFlatLinesOfEAndNotThePads) {
    const GlyphInstance e = laid_out('E', kSize, 0.0f, 0.0f);
    const GlyphRecord& g = record_of(e);
    const FontAsset& asset = font().asset();
    const std::vector<uint32_t> flat = flat_curve_words(asset, g);
    ASSERT_EQ(flat.size(), g.band_words);
    uint32_t flagged = 0, pads = 0;
    for (uint32_t slot = 0; slot < g.curve_count; ++slot) {
        const Point* p = &asset.points[size_t{g.point_offset} + 2 * size_t{slot}];
        const bool is_flat = ((flat[slot / 32] >> (slot % 32)) & 1u) != 0;
        const bool pad = p[1].x == p[0].x && p[1].y == p[0].y;
        if (pad) ++pads;
        if (!is_flat) continue;
        ++flagged;
        EXPECT_FALSE(pad) << slot;
        EXPECT_EQ(p[0].y, p[2].y) << slot;
        EXPECT_EQ(p[1].y, p[0].y) << slot;
        EXPECT_NE(p[0].x, p[2].x) << slot;
    }
    // E's outline: 12 corners, 6 horizontal edges.
    EXPECT_EQ(flagged, 6u);
    // B's three contours are joined by pad slots (their start repeated), which have three points
    // of one y too: none is listed, each of its flat lines is.
    const GlyphRecord& b = record_of(laid_out('B', kSize, 0.0f, 0.0f));
    const std::vector<uint32_t> b_flat = flat_curve_words(asset, b);
    ASSERT_EQ(b_flat.size(), b.band_words);
    uint32_t b_pads = 0, b_lines = 0;
    for (uint32_t slot = 0; slot < b.curve_count; ++slot) {
        const Point* p = &asset.points[size_t{b.point_offset} + 2 * size_t{slot}];
        const bool is_flat = ((b_flat[slot / 32] >> (slot % 32)) & 1u) != 0;
        const bool pad = p[1].x == p[0].x && p[1].y == p[0].y;
        const bool line = !pad && p[0].y == p[1].y && p[1].y == p[2].y;
        b_pads += pad ? 1u : 0u;
        b_lines += line ? 1u : 0u;
        EXPECT_EQ(is_flat, line) << "B slot " << slot;
    }
    EXPECT_GT(b_pads, 0u);
    EXPECT_GE(b_lines, 4u);
    // 'o' has none: its curves only touch horizontal at their ends.
    EXPECT_TRUE(flat_curve_words(asset, record_of(laid_out('o', kSize, 0.0f, 0.0f))).empty());
    std::printf("[ transform ] E: %u flat lines, %u pad slots of %u\n", flagged, pads, g.curve_count);
}

TEST(TransformKeys, ARotatedGlyphsCurveTestsArePositiveAndNearTheAxisAlignedOnes) {
    const GlyphInstance laid = laid_out('A', 20.0f, 10.0f, 30.0f);
    const GlyphRecord& g = record_of(laid);
    const FontAsset& asset = font().asset();
    const uint64_t upright = curve_tests_per_sample(asset, g, laid.key);
    ASSERT_GT(upright, 0u);
    for (const double degrees : {0.5, 37.0, 90.0, 180.0, 271.3}) {
        GlyphInstance placed;
        ASSERT_TRUE(place(laid, transformed(laid, rotation(degrees)), kStillTransformSteps, placed));
        ASSERT_TRUE(is_transformed(placed.key));
        const uint64_t turned = curve_tests_per_sample(asset, g, placed.key);
        std::printf("[ transform ] curve tests per sample of A at 20 px, %.1f degrees: %llu (upright %llu)\n", degrees,
                    static_cast<unsigned long long>(turned), static_cast<unsigned long long>(upright));
        EXPECT_GT(turned, upright / 2) << degrees;
        EXPECT_LT(turned, upright * 8) << degrees;
    }
    // And it grows with the rect: 4 times the size, at least 4 times the tests.
    GlyphInstance large;
    ASSERT_TRUE(place(laid, transformed(laid, rotation(37.0, 4.0)), kStillTransformSteps, large));
    GlyphInstance small;
    ASSERT_TRUE(place(laid, transformed(laid, rotation(37.0)), kStillTransformSteps, small));
    EXPECT_GT(curve_tests_per_sample(asset, g, large.key), 4 * curve_tests_per_sample(asset, g, small.key));
}

}  // namespace
}  // namespace crisp
