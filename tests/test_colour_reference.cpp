// The CPU reference of colour glyphs (support/colour_reference.hpp): each paint against values
// worked out by hand, the reference image's compositing against what layers must give, and
// FreeType's own blending of COLRv0 layers (FT_LOAD_COLOR) as an outside check.
#include "colour_reference.hpp"
#include "coverage.hpp"
#include "freetype_reference.hpp"
#include "image_io.hpp"
#include "test_support.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace crisp {
namespace {

using colour::LinearRgba;
using colour::Painter;
using colour::Srgba;
using test::key_at;

constexpr Srgba kBlack = {0.0, 0.0, 0.0, 1.0};

uint32_t rgba8(uint32_t r, uint32_t g, uint32_t b, uint32_t a) {
    return r | g << 8 | b << 16 | a << 24;
}

void expect_colour(const LinearRgba& got, const LinearRgba& want, const std::string& where, double tolerance = 1e-12) {
    EXPECT_NEAR(got.r, want.r, tolerance) << where;
    EXPECT_NEAR(got.g, want.g, tolerance) << where;
    EXPECT_NEAR(got.b, want.b, tolerance) << where;
    EXPECT_NEAR(got.a, want.a, tolerance) << where;
}

// An asset holding only paints' stops and two palettes of four entries: black, white, red opaque,
// blue at alpha 0x80; then white, black, green opaque, transparent white.
struct PaintAsset {
    FontAsset asset;

    PaintAsset() {
        asset.palette_size = 4;
        asset.palette_colours = {rgba8(0, 0, 0, 255),   rgba8(255, 255, 255, 255), rgba8(255, 0, 0, 255),
                                 rgba8(0, 0, 255, 128), rgba8(255, 255, 255, 255), rgba8(0, 0, 0, 255),
                                 rgba8(0, 255, 0, 255), rgba8(255, 255, 255, 0)};
    }

    Paint paint(PaintKind kind, PaintExtend extend, std::vector<ColourStop> stops, std::vector<float> geometry = {}) {
        Paint made;
        made.kind = kind;
        made.extend = extend;
        made.first_stop = static_cast<uint32_t>(asset.stops.size());
        made.stop_count = static_cast<uint32_t>(stops.size());
        asset.stops.insert(asset.stops.end(), stops.begin(), stops.end());
        std::copy(geometry.begin(), geometry.end(), made.geometry);
        return made;
    }

    // A colour line from black (t = 0) to white (t = 1): its premultiplied sRGB value is t itself.
    Paint ramp(PaintKind kind, PaintExtend extend, std::vector<float> geometry) {
        return paint(kind, extend, {{0.0f, 0, 1.0f}, {1.0f, 1, 1.0f}}, std::move(geometry));
    }

    Painter painter(uint32_t palette = 0, const Srgba& foreground = kBlack) const {
        Result<Painter> made = Painter::create(asset, palette, foreground);
        EXPECT_TRUE(made.ok()) << made.error().message;
        return std::move(*made);
    }
};

// The encoded grey the black-to-white ramp gives at t, as the final linear colour.
LinearRgba grey_at(double t) {
    const double v = colour::srgb_to_linear(t);
    return {v, v, v, 1.0};
}

double t_at(const Paint& paint, double x, double y) {
    const std::optional<double> t = colour::gradient_t(paint, {x, y});
    EXPECT_TRUE(t.has_value()) << "no t at (" << x << ", " << y << ")";
    return t.value_or(-1e9);
}

TEST(ColourReference, SrgbTransferAndLinearizing) {
    EXPECT_EQ(colour::srgb_to_linear(0.0), 0.0);
    EXPECT_EQ(colour::srgb_to_linear(1.0), 1.0);
    EXPECT_NEAR(colour::srgb_to_linear(0.5), 0.21404114048223255, 1e-15);
    EXPECT_NEAR(colour::srgb_to_linear(0.04045), 0.04045 / 12.92, 1e-15);
    EXPECT_EQ(colour::srgb_to_linear(std::nan("")), 0.0);
    EXPECT_NEAR(linear_to_srgb(colour::srgb_to_linear(0.3)), 0.3, 1e-12);
    // Premultiplied 0.25 at alpha 0.5 is straight 0.5: linearized, then premultiplied again.
    expect_colour(colour::linearize({0.25, 0.5, 0.0, 0.5}), {0.5 * 0.21404114048223255, 0.5, 0.0, 0.5}, "half");
    expect_colour(colour::linearize({0.3, 0.3, 0.3, 0.0}), {}, "no alpha");
}

TEST(ColourReference, LinearGradientT) {
    PaintAsset p;
    const Paint linear = p.ramp(PaintKind::linear, PaintExtend::pad, {1.0f, 1.0f, 3.0f, 1.0f});
    EXPECT_DOUBLE_EQ(t_at(linear, 1.0, 1.0), 0.0);
    EXPECT_DOUBLE_EQ(t_at(linear, 2.0, 7.0), 0.5);  // lines of equal colour are perpendicular to p0 -> p1
    EXPECT_DOUBLE_EQ(t_at(linear, 3.0, -2.0), 1.0);
    EXPECT_DOUBLE_EQ(t_at(linear, 0.5, 0.0), -0.25);
    // to_paint maps em first: em (1, 0.5) is paint (2, 1) under a scale of 2.
    Paint scaled = linear;
    scaled.to_paint = {2.0f, 0.0f, 0.0f, 2.0f, 0.0f, 0.0f};
    EXPECT_DOUBLE_EQ(t_at(scaled, 1.0, 0.5), 0.5);
    expect_colour(*p.painter().evaluate(scaled, {1.0, 0.5}), grey_at(0.5), "scaled");
    // Degenerate: p1 == p0 defines no colour.
    const Paint point = p.ramp(PaintKind::linear, PaintExtend::pad, {1.0f, 1.0f, 1.0f, 1.0f});
    EXPECT_FALSE(colour::gradient_t(point, {0.0, 0.0}).has_value());
    expect_colour(*p.painter().evaluate(point, {0.0, 0.0}), {}, "degenerate");
}

TEST(ColourReference, LinearGradientCorrectedForP2) {
    // COLRv1's p0 (0, 0), p1 (2, 1), p2 (1, 1): lines of equal colour run parallel to p0 -> p2, so
    // the baker stores p1' = p0 + the part of p1 - p0 perpendicular to p2 - p0: (2, 1) - 1.5 (1, 1)
    // = (0.5, -0.5). The colour is the first stop's all along p0 -> p2 and the last stop's at p1.
    PaintAsset p;
    const Paint linear = p.ramp(PaintKind::linear, PaintExtend::pad, {0.0f, 0.0f, 0.5f, -0.5f});
    EXPECT_NEAR(t_at(linear, 1.0, 1.0), 0.0, 1e-15);
    EXPECT_NEAR(t_at(linear, -3.0, -3.0), 0.0, 1e-15);
    EXPECT_NEAR(t_at(linear, 2.0, 1.0), 1.0, 1e-15);
    EXPECT_NEAR(t_at(linear, 2.5, 1.5), 1.0, 1e-15);  // p1 + (p2 - p0)/2
    EXPECT_NEAR(t_at(linear, 1.0, 0.5), 0.5, 1e-15);
}

TEST(ColourReference, ExtendModes) {
    struct Case {
        PaintExtend extend;
        double expected[4];  // at t = -0.25, 0.5, 1.25, 2.5
    };
    const Case cases[] = {{PaintExtend::pad, {0.0, 0.5, 1.0, 1.0}},
                          {PaintExtend::repeat, {0.75, 0.5, 0.25, 0.5}},
                          {PaintExtend::reflect, {0.25, 0.5, 0.75, 0.5}}};
    const double ts[4] = {-0.25, 0.5, 1.25, 2.5};
    PaintAsset p;
    for (const Case& c : cases) {
        const Paint ramp = p.ramp(PaintKind::linear, c.extend, {0.0f, 0.0f, 1.0f, 0.0f});
        const Painter painter = p.painter();
        for (size_t i = 0; i < 4; ++i) {
            const std::string where =
                "extend " + std::to_string(static_cast<int>(c.extend)) + " t " + std::to_string(ts[i]);
            EXPECT_DOUBLE_EQ(colour::extend_t(c.extend, 0.0, 1.0, ts[i]), c.expected[i]) << where;
            // The ramp's encoded grey is the extended t; along x, t is x.
            expect_colour(*painter.evaluate(ramp, {ts[i], 3.0}), grey_at(c.expected[i]), where);
        }
    }
    // A line from 0.2 to 0.6: each mode works on that span.
    EXPECT_DOUBLE_EQ(colour::extend_t(PaintExtend::pad, 0.2, 0.6, 0.7), 0.6);
    EXPECT_NEAR(colour::extend_t(PaintExtend::repeat, 0.2, 0.6, 0.7), 0.3, 1e-15);
    EXPECT_NEAR(colour::extend_t(PaintExtend::reflect, 0.2, 0.6, 0.7), 0.5, 1e-15);
    EXPECT_NEAR(colour::extend_t(PaintExtend::reflect, 0.2, 0.6, 0.1), 0.3, 1e-15);
    // Repeat wraps into [first, last): the last offset reads as the first.
    EXPECT_DOUBLE_EQ(colour::extend_t(PaintExtend::repeat, 0.0, 1.0, 1.0), 0.0);
    // First == last is pad whatever the mode says.
    EXPECT_DOUBLE_EQ(colour::extend_t(PaintExtend::repeat, 0.5, 0.5, 3.0), 0.5);
    EXPECT_DOUBLE_EQ(colour::extend_t(PaintExtend::reflect, 0.5, 0.5, -3.0), 0.5);
}

TEST(ColourReference, ColourLineInterpolatesPremultipliedEncodedColours) {
    PaintAsset p;
    const Painter painter = p.painter();
    // Black to white at t = 0.5 is encoded 0.5, linear 0.214: not linear 0.5.
    const Paint ramp = p.ramp(PaintKind::linear, PaintExtend::pad, {0.0f, 0.0f, 1.0f, 0.0f});
    expect_colour(*painter.evaluate(ramp, {0.5, 0.0}),
                  {0.21404114048223255, 0.21404114048223255, 0.21404114048223255, 1.0}, "grey");
    // Red to transparent white (palette 1's last entry has alpha 0; here in palette 0 use a stop
    // alpha of 0 on white): premultiplied, the transparent end adds no white, so halfway is red at
    // alpha 0.5, where straight interpolation would give pink.
    const Paint fade =
        p.paint(PaintKind::linear, PaintExtend::pad, {{0.0f, 2, 1.0f}, {1.0f, 1, 0.0f}}, {0.0f, 0.0f, 1.0f, 0.0f});
    expect_colour(*painter.evaluate(fade, {0.5, 0.0}), {0.5, 0.0, 0.0, 0.5}, "fade");
    // Ties: at t on the tie the later stop, either side the stops around it.
    const Paint tie =
        p.paint(PaintKind::linear, PaintExtend::pad,
                {{0.0f, 0, 1.0f}, {0.5f, 1, 1.0f}, {0.5f, 2, 1.0f}, {1.0f, 0, 1.0f}}, {0.0f, 0.0f, 1.0f, 0.0f});
    expect_colour(*painter.evaluate(tie, {0.5, 0.0}), {1.0, 0.0, 0.0, 1.0}, "on the tie");
    expect_colour(*painter.evaluate(tie, {0.25, 0.0}), grey_at(0.5), "before the tie");
    const double red = colour::srgb_to_linear(0.5);
    expect_colour(*painter.evaluate(tie, {0.75, 0.0}), {red, 0.0, 0.0, 1.0}, "after the tie");
    // One stop: its colour everywhere, whatever t.
    const Paint single = p.paint(PaintKind::linear, PaintExtend::repeat, {{0.3f, 2, 1.0f}}, {0.0f, 0.0f, 1.0f, 0.0f});
    expect_colour(*painter.evaluate(single, {7.0, 0.0}), {1.0, 0.0, 0.0, 1.0}, "single");
}

TEST(ColourReference, RadialGradientT) {
    PaintAsset p;
    // Concentric, r0 = 1 to r1 = 3: |q| = 1 + 2 t. Inside r0, t < 0 while r(t) >= 0.
    const Paint concentric = p.ramp(PaintKind::radial, PaintExtend::pad, {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 3.0f});
    EXPECT_NEAR(t_at(concentric, 2.0, 0.0), 0.5, 1e-15);
    EXPECT_NEAR(t_at(concentric, 0.0, -3.0), 1.0, 1e-15);
    EXPECT_NEAR(t_at(concentric, 0.3, 0.4), -0.25, 1e-15);
    EXPECT_NEAR(t_at(concentric, 0.0, 0.0), -0.5, 1e-15);  // r(-0.5) = 0: the centre itself
    EXPECT_NEAR(t_at(concentric, 5.0, 0.0), 2.0, 1e-15);
    const Paint reflected = p.ramp(PaintKind::radial, PaintExtend::reflect, {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 3.0f});
    expect_colour(*p.painter().evaluate(reflected, {0.0, 0.5}), grey_at(0.25), "reflect inside r0");
    expect_colour(*p.painter().evaluate(concentric, {0.0, 0.5}), grey_at(0.0), "pad inside r0");

    // A cone: c0 (0, 0) r0 0 to c1 (2, 0) r1 1, its apex outside the far circle. On the axis at x
    // = 2 the circles of t = 2/3 and t = 2 both pass: the larger wins. Points off the cone, and
    // behind its apex, no circle reaches: transparent.
    const Paint cone = p.ramp(PaintKind::radial, PaintExtend::pad, {0.0f, 0.0f, 0.0f, 2.0f, 0.0f, 1.0f});
    EXPECT_NEAR(t_at(cone, 2.0, 0.0), 2.0, 1e-15);
    EXPECT_NEAR(t_at(cone, 3.0, 0.0), 3.0, 1e-15);
    EXPECT_FALSE(colour::gradient_t(cone, {0.0, 1.0}).has_value());
    EXPECT_FALSE(colour::gradient_t(cone, {-1.0, 0.0}).has_value());
    expect_colour(*p.painter().evaluate(cone, {0.0, 1.0}), {}, "off the cone");

    // Non-concentric with r0 > 0, the circles internally tangent (|c1 - c0| = r1 - r0): the
    // quadratic degenerates to a line. c0 (0, 0) r0 1, c1 (1, 0) r1 2.
    const Paint tangent = p.ramp(PaintKind::radial, PaintExtend::pad, {0.0f, 0.0f, 1.0f, 1.0f, 0.0f, 2.0f});
    EXPECT_NEAR(t_at(tangent, 2.0, 0.0), 0.5, 1e-15);                    // the circle at (0.5, 0) of radius 1.5
    EXPECT_NEAR(t_at(tangent, 0.0, 1.0), 0.0, 1e-15);                    // on the first circle
    EXPECT_FALSE(colour::gradient_t(tangent, {-3.0, 0.0}).has_value());  // only t = -2, radius -1
    // Non-concentric, neither inside the other: c0 (0, 0) r0 1, c1 (4, 0) r1 1 (a cylinder).
    const Paint tube = p.ramp(PaintKind::radial, PaintExtend::pad, {0.0f, 0.0f, 1.0f, 4.0f, 0.0f, 1.0f});
    EXPECT_NEAR(t_at(tube, 3.0, 0.0), 1.0, 1e-15);  // circles of t = 0.5 and 1 pass through
    EXPECT_NEAR(t_at(tube, 2.0, 0.6), 0.7, 1e-15);  // x = 4 t +- 0.8
    EXPECT_FALSE(colour::gradient_t(tube, {2.0, 1.5}).has_value());
    // One circle for every t defines nothing.
    const Paint same = p.ramp(PaintKind::radial, PaintExtend::pad, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f});
    EXPECT_FALSE(colour::gradient_t(same, {2.0, 1.0}).has_value());
}

TEST(ColourReference, SweepGradientT) {
    PaintAsset p;
    // A full turn from +x, counter-clockwise in y-up.
    const Paint full = p.ramp(PaintKind::sweep, PaintExtend::pad, {0.0f, 0.0f, 0.0f, 1.0f});
    EXPECT_NEAR(t_at(full, 0.0, 1.0), 0.25, 1e-15);
    EXPECT_NEAR(t_at(full, -1.0, 0.0), 0.5, 1e-15);
    EXPECT_NEAR(t_at(full, 0.0, -1.0), 0.75, 1e-15);
    // The seam at angle 0: just above it t is near 0, just below near 1.
    EXPECT_NEAR(t_at(full, 1.0, 1e-9), 0.0, 1e-9);
    EXPECT_NEAR(t_at(full, 1.0, -1e-9), 1.0, 1e-9);
    EXPECT_EQ(t_at(full, 1.0, 0.0), 0.0);
    // A sweep across the seam, from -1/4 to 1/4 turn: angles are wrapped into [0, 1) before t, so
    // the quadrant below +x (angle 7/8) is t = 2.25, not 0.25: pad shows the last stop there,
    // repeat wraps it to 0.25.
    const Paint across = p.ramp(PaintKind::sweep, PaintExtend::pad, {0.0f, 0.0f, -0.25f, 0.25f});
    EXPECT_NEAR(t_at(across, 1.0, 1.0), 0.75, 1e-15);
    EXPECT_NEAR(t_at(across, 1.0, -1.0), 2.25, 1e-15);
    expect_colour(*p.painter().evaluate(across, {1.0, -1.0}), grey_at(1.0), "pad below the seam");
    const Paint across_repeat = p.ramp(PaintKind::sweep, PaintExtend::repeat, {0.0f, 0.0f, -0.25f, 0.25f});
    expect_colour(*p.painter().evaluate(across_repeat, {1.0, -1.0}), grey_at(0.25), "repeat below the seam", 1e-12);
    // start > end runs clockwise: from 3/4 turn down to 1/4.
    const Paint backwards = p.ramp(PaintKind::sweep, PaintExtend::pad, {1.0f, 2.0f, 0.75f, 0.25f});
    EXPECT_NEAR(t_at(backwards, 1.0, 3.0), 1.0, 1e-15);  // angle 1/4 about the centre (1, 2)
    EXPECT_NEAR(t_at(backwards, 0.0, 2.0), 0.5, 1e-15);  // 1/2
    EXPECT_NEAR(t_at(backwards, 1.0, 1.0), 0.0, 1e-15);  // 3/4
    EXPECT_NEAR(t_at(backwards, 2.0, 2.0), 1.5, 1e-15);  // 0
    EXPECT_NEAR(t_at(backwards, 2.0, 2.0 + 1e-9), 1.5, 1e-8);
    // start == end defines nothing.
    const Paint none = p.ramp(PaintKind::sweep, PaintExtend::pad, {0.0f, 0.0f, 0.5f, 0.5f});
    EXPECT_FALSE(colour::gradient_t(none, {1.0, 1.0}).has_value());
}

TEST(ColourReference, SolidPaintsPalettesAlphaAndTheForeground) {
    PaintAsset p;
    const double half = colour::srgb_to_linear(0.5);
    // Palette entry alpha (0x80) times the stop's alpha (0.5).
    const Paint blue = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, 3, 0.5f}});
    const double a = 128.0 / 255.0 * 0.5;
    expect_colour(*p.painter().evaluate(blue, {0.0, 0.0}), {0.0, 0.0, a, a}, "palette 0 alpha");
    // The same index in palette 1 is transparent white.
    expect_colour(*p.painter(1).evaluate(blue, {0.0, 0.0}), {}, "palette 1");
    const Paint green = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, 2, 1.0f}});
    expect_colour(*p.painter(1).evaluate(green, {0.0, 0.0}), {0.0, 1.0, 0.0, 1.0}, "palette 1 green");

    // The foreground entry: the text colour's rgb (sRGB, straight) times the stop's alpha; the text
    // alpha then scales every paint once, its own entries included.
    const Srgba text = {0.5, 0.25, 1.0, 0.5};
    const Paint foreground = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, kForegroundPaletteIndex, 0.5f}});
    const double quarter = colour::srgb_to_linear(0.25);
    expect_colour(*p.painter(0, text).evaluate(foreground, {0.0, 0.0}), {half * 0.25, quarter * 0.25, 0.25, 0.25},
                  "foreground");
    expect_colour(*p.painter(0, text).evaluate(green, {0.0, 0.0}), {0.5, 0.0, 0.0, 0.5}, "text alpha on red");
    const Paint white = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, 1, 1.0f}});
    expect_colour(*p.painter(0, text).evaluate(white, {0.0, 0.0}), {0.5, 0.5, 0.5, 0.5}, "text alpha on white");
    // A gradient from the foreground to red, halfway: the encoded premultiplied mean.
    const Paint mixed = p.paint(PaintKind::linear, PaintExtend::pad,
                                {{0.0f, kForegroundPaletteIndex, 1.0f}, {1.0f, 2, 1.0f}}, {0.0f, 0.0f, 1.0f, 0.0f});
    const Srgba opaque_text = {0.5, 0.25, 1.0, 1.0};
    expect_colour(*p.painter(0, opaque_text).evaluate(mixed, {0.5, 0.0}),
                  {colour::srgb_to_linear(0.75), colour::srgb_to_linear(0.125), half, 1.0}, "foreground to red");
}

TEST(ColourReference, RefusesWhatTheAssetDoesNotHold) {
    PaintAsset p;
    Result<Painter> past = Painter::create(p.asset, 2, kBlack);
    ASSERT_FALSE(past.ok());
    EXPECT_NE(past.error().message.find("palette 2"), std::string::npos) << past.error().message;
    EXPECT_FALSE(Painter::create(p.asset, 0, {0.0, 0.0, 1.5, 1.0}).ok());
    EXPECT_FALSE(Painter::create(p.asset, 0, {0.0, std::nan(""), 0.0, 1.0}).ok());
    const Paint bad_index = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, 4, 1.0f}});
    Result<LinearRgba> refused = p.painter().evaluate(bad_index, {0.0, 0.0});
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("palette index 4"), std::string::npos) << refused.error().message;
    Paint bad_stops = p.paint(PaintKind::solid, PaintExtend::pad, {{0.0f, 0, 1.0f}});
    bad_stops.first_stop = 1000;
    EXPECT_FALSE(p.painter().evaluate(bad_stops, {0.0, 0.0}).ok());
    bad_stops.first_stop = 0;
    bad_stops.stop_count = 0;
    EXPECT_FALSE(p.painter().evaluate(bad_stops, {0.0, 0.0}).ok());
    Paint bad_image;
    bad_image.kind = PaintKind::image;
    bad_image.image = 0;
    EXPECT_FALSE(p.painter().evaluate(bad_image, {0.0, 0.0}).ok());
    // An asset without palettes takes palette 0, and only the foreground entry.
    FontAsset bare;
    EXPECT_TRUE(Painter::create(bare, 0, kBlack).ok());
    EXPECT_FALSE(Painter::create(bare, 1, kBlack).ok());
}

// A zlib stream (RFC 1950) of stored deflate blocks (RFC 1951): no compression, so the test needs
// no zlib of its own.
std::vector<std::byte> zlib_stored(const std::vector<uint8_t>& data) {
    std::vector<uint8_t> out = {0x78, 0x01};
    size_t at = 0;
    do {
        const size_t count = std::min<size_t>(65535, data.size() - at);
        out.push_back(at + count == data.size() ? 1 : 0);
        for (const size_t value : {count, count ^ 0xFFFF}) {
            out.push_back(static_cast<uint8_t>(value & 0xFF));
            out.push_back(static_cast<uint8_t>(value >> 8 & 0xFF));
        }
        out.insert(out.end(), data.begin() + static_cast<ptrdiff_t>(at),
                   data.begin() + static_cast<ptrdiff_t>(at + count));
        at += count;
    } while (at < data.size());
    uint32_t a = 1, b = 0;
    for (const uint8_t byte : data) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    const uint32_t adler = b << 16 | a;
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(adler >> shift & 0xFF));
    std::vector<std::byte> bytes(out.size());
    std::transform(out.begin(), out.end(), bytes.begin(), [](uint8_t v) { return std::byte{v}; });
    return bytes;
}

// A 2 x 2 image: opaque red, half-transparent white (premultiplied 128), transparent, opaque grey
// (sRGB code 188); an image paint whose unit square is em [0, 1]^2 (y down from em y = 1).
struct ImageAsset {
    FontAsset asset;
    Paint paint;
    LinearRgba texels[4];

    ImageAsset() {
        const std::vector<uint8_t> pixels = {255, 0, 0, 255, 128, 128, 128, 128, 0, 0, 0, 0, 188, 188, 188, 255};
        asset.image_bytes = zlib_stored(pixels);
        asset.images = {{2, 2, 0, static_cast<uint32_t>(asset.image_bytes.size())}};
        paint.kind = PaintKind::image;
        paint.to_paint = {1.0f, 0.0f, 0.0f, -1.0f, 0.0f, 1.0f};  // u = x, v = 1 - y
        const double a = 128.0 / 255.0, grey = colour::srgb_to_linear(188.0 / 255.0);
        texels[0] = {1.0, 0.0, 0.0, 1.0};
        texels[1] = {a, a, a, a};
        texels[2] = {};
        texels[3] = {grey, grey, grey, 1.0};
    }
};

LinearRgba weighted(const LinearRgba* texels, std::initializer_list<double> weights) {
    LinearRgba sum;
    size_t i = 0;
    for (const double w : weights) {
        sum = {sum.r + w * texels[i].r, sum.g + w * texels[i].g, sum.b + w * texels[i].b, sum.a + w * texels[i].a};
        ++i;
    }
    return sum;
}

TEST(ColourReference, ImagePaints) {
    ImageAsset image;
    Result<Painter> made = Painter::create(image.asset, 0, {0.0, 0.0, 0.0, 1.0});
    ASSERT_TRUE(made.ok()) << made.error().message;
    const Painter& painter = *made;
    // Nearest: the texel under the point; em y up, image rows down.
    expect_colour(*painter.evaluate(image.paint, {0.25, 0.75}), image.texels[0], "top left");
    expect_colour(*painter.evaluate(image.paint, {0.75, 0.75}), image.texels[1], "top right");
    expect_colour(*painter.evaluate(image.paint, {0.25, 0.25}), image.texels[2], "bottom left");
    expect_colour(*painter.evaluate(image.paint, {0.75, 0.25}), image.texels[3], "bottom right");
    expect_colour(*painter.evaluate(image.paint, {1.5, 0.5}), {}, "outside");
    expect_colour(*painter.evaluate(image.paint, {0.5, -0.01}), {}, "below");

    // The exact box mean over a footprint (em corners in order).
    const auto mean = [&](std::array<Vec2, 4> corners) {
        Result<LinearRgba> got = painter.image_mean(image.paint, corners);
        EXPECT_TRUE(got.ok()) << got.error().message;
        return got.ok() ? *got : LinearRgba{};
    };
    const LinearRgba all = weighted(image.texels, {0.25, 0.25, 0.25, 0.25});
    expect_colour(mean({Vec2{0, 0}, {1, 0}, {1, 1}, {0, 1}}), all, "whole image");
    expect_colour(mean({Vec2{0.25, 0.25}, {0.75, 0.25}, {0.75, 0.75}, {0.25, 0.75}}), all, "centre");
    // Half outside the image, over its right column: the part inside, (texel 1 + texel 3) / 2.
    expect_colour(mean({Vec2{0.5, 0}, {1.5, 0}, {1.5, 1}, {0.5, 1}}), weighted(image.texels, {0, 0.5, 0, 0.5}),
                  "half outside");
    expect_colour(mean({Vec2{1.5, 0}, {2.5, 0}, {2.5, 1}, {1.5, 1}}), {}, "all outside");
    // Nearest, clamped into the image: its edge texels outside it.
    expect_colour(*painter.image_nearest(image.paint, {1.5, 0.75}), image.texels[1], "clamped right");
    expect_colour(*painter.image_nearest(image.paint, {-0.5, -0.5}), image.texels[2], "clamped below left");
    expect_colour(*painter.image_nearest(image.paint, {0.75, 0.25}), image.texels[3], "clamped inside");
    // A triangle (one corner twice) below the image's diagonal from top-left to bottom-right in
    // image space: half of texels 0 and 3, all of texel 1, of an area of 2 texels.
    expect_colour(mean({Vec2{0, 1}, {1, 1}, {1, 0}, {1, 0}}), weighted(image.texels, {0.25, 0.5, 0, 0.25}), "triangle");
    // A diamond, rotated 45 degrees: every texel's half nearest the centre.
    expect_colour(mean({Vec2{0.5, 0}, {1, 0.5}, {0.5, 1}, {0, 0.5}}), all, "diamond");
    expect_colour(mean({Vec2{0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}}), {}, "no area");
    // The text alpha scales images too.
    Result<Painter> faded = Painter::create(image.asset, 0, {0.0, 0.0, 0.0, 0.5});
    ASSERT_TRUE(faded.ok());
    expect_colour(*faded->evaluate(image.paint, {0.25, 0.75}), {0.5, 0.0, 0.0, 0.5}, "text alpha");

    // Bytes that do not inflate are refused, naming the image.
    image.asset.image_bytes[3] = std::byte{0x77};
    Result<Painter> broken = Painter::create(image.asset, 0, kBlack);
    ASSERT_TRUE(broken.ok());
    Result<LinearRgba> refused = broken->evaluate(image.paint, {0.25, 0.75});
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ErrorCode::asset_invalid);
    EXPECT_NE(refused.error().message.find("image 0"), std::string::npos) << refused.error().message;
    Paint solid;
    EXPECT_FALSE(broken->image_mean(solid, {}).ok());
    EXPECT_FALSE(broken->image_nearest(solid, {}).ok());
}

// ---- The colour glyph reference image, on the outlines of tests/fonts/colour/colrv0.ttf.

const std::string kColrV0 = test::source_path("tests/fonts/colour/colrv0.ttf");

// What colrv0.ttf's COLR holds (tests/fonts/colour/README.md; fontTools' ttx prints the same):
// base glyph, then its layers back to front as (outline glyph, palette index).
struct ColrV0Glyph {
    uint32_t glyph;
    std::vector<std::pair<uint32_t, uint32_t>> layers;
};
const ColrV0Glyph kColrV0Glyphs[] = {
    {14, {{1, 0}, {2, 1}}},                        // two_layers: square, circle
    {15, {{1, kForegroundPaletteIndex}, {3, 2}}},  // foreground: square in the text colour, ring
    {16, {{1, 0}, {2, 1}, {3, 2}, {4, 3}}},        // four_layers: square, circle, ring, bar
    {17, {{2, 4}}},                                // alpha_layer: a circle at alpha 0x80 (0x40)
    {18, {{2, 3}, {6, 6}, {7, 6}, {8, 6}}},        // smile: circle, eyes, mouth
    {28, {{1, 5}, {11, 0}, {12, 0}, {13, 2}}},     // flag_us: square, stripes, canton
};
constexpr uint32_t kTwoLayers = 0, kForeground = 1, kFourLayers = 2, kAlphaLayer = 3;

// colrv0.ttf's outlines as the baker bakes them, with its COLR and CPAL filled in by hand from
// kColrV0Glyphs and the palettes: one solid paint per layer.
FontAsset colrv0_asset() {
    BakeOptions options;
    Result<BakeResult> baked = bake_font_file(kColrV0, options);
    EXPECT_TRUE(baked.ok()) << baked.error().message;
    if (!baked) return {};
    FontAsset asset = std::move(baked->asset);
    // The baker reads the font's COLR too; the table here is the font's, written out, so that the
    // reference is not held to what the baker reads.
    asset.colour_glyphs.clear();
    asset.layers.clear();
    asset.paints.clear();
    asset.stops.clear();
    asset.palette_size = 7;
    asset.palette_colours = {
        rgba8(0xff, 0x00, 0x00, 0xff), rgba8(0x00, 0x80, 0x00, 0xff), rgba8(0x00, 0x00, 0xff, 0xff),
        rgba8(0xff, 0xcc, 0x00, 0xff), rgba8(0xff, 0x00, 0xff, 0x80), rgba8(0xff, 0xff, 0xff, 0xff),
        rgba8(0x00, 0x00, 0x00, 0xff), rgba8(0x00, 0xff, 0xff, 0xff), rgba8(0x80, 0x00, 0x80, 0xff),
        rgba8(0xff, 0x80, 0x00, 0xff), rgba8(0x40, 0x40, 0x40, 0xff), rgba8(0x00, 0x00, 0x80, 0x40),
        rgba8(0x10, 0x20, 0x30, 0xff), rgba8(0xfa, 0xfa, 0xfa, 0xff)};
    for (const ColrV0Glyph& entry : kColrV0Glyphs) {
        ColourGlyph glyph;
        glyph.glyph = entry.glyph;
        glyph.first_layer = static_cast<uint32_t>(asset.layers.size());
        glyph.layer_count = static_cast<uint32_t>(entry.layers.size());
        for (const auto& [outline, index] : entry.layers) {
            Paint paint;
            paint.first_stop = static_cast<uint32_t>(asset.stops.size());
            paint.stop_count = 1;
            asset.stops.push_back({0.0f, index, 1.0f});
            asset.layers.push_back({outline, static_cast<uint32_t>(asset.paints.size())});
            asset.paints.push_back(paint);
        }
        asset.colour_glyphs.push_back(glyph);
    }
    const Status valid = validate_asset(asset);
    EXPECT_TRUE(valid.ok()) << valid.error().message;
    return asset;
}

SubpixelLayout preset(const char* name) {
    Result<SubpixelLayout> layout = subpixel_preset(name);
    EXPECT_TRUE(layout.ok());
    return layout.ok() ? *layout : SubpixelLayout{};
}

colour::ColourImage render(const FontAsset& asset, uint32_t colour_glyph, const GlyphKey& key,
                           const SubpixelLayout& layout, const Srgba& foreground = kBlack,
                           const std::array<double, 3>& background = {0.2, 0.4, 0.6}, uint32_t palette = 0) {
    Result<colour::ColourImage> image =
        colour::render_colour_reference(asset, colour_glyph, key, layout, palette, foreground, background);
    EXPECT_TRUE(image.ok()) << image.error().message;
    return image.ok() ? std::move(*image) : colour::ColourImage{};
}

// The exact coverage of a pixel's square (pen-relative pixel x, y) by a glyph at `key`.
double pixel_coverage(const ExactCoverage& exact, const GlyphKey& key, int32_t x, int32_t y) {
    const double size = static_cast<double>(key.size_x) / kSizeOne;
    const double sub_x = key.subpixel_x / 256.0, sub_y = key.subpixel_y / 256.0;
    return exact.coverage((x - sub_x) / size, (sub_y - y - 1) / size, (x + 1 - sub_x) / size, (sub_y - y) / size);
}

TEST(ColourReference, TwoOpaqueLayersShowTheFrontWhereItCovers) {
    const FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    const GlyphKey key = key_at(14, 40, 64, 160);
    const SubpixelLayout gray = preset("gray");
    const colour::ColourImage both = render(asset, kTwoLayers, key, gray);
    FontAsset front_only = asset;  // the circle alone
    front_only.colour_glyphs[kTwoLayers].first_layer += 1;
    front_only.colour_glyphs[kTwoLayers].layer_count = 1;
    const colour::ColourImage front = render(front_only, kTwoLayers, key, gray);
    // The square and the circle share a bbox, so a rect; it is glyph_rect()'s.
    const GlyphRect square = glyph_rect(asset.glyphs[1], key);
    EXPECT_EQ(both.rect.x, square.x);
    EXPECT_EQ(both.rect.y, square.y);
    ASSERT_EQ(both.rect.width, front.rect.width);
    ASSERT_EQ(both.rect.height, front.rect.height);
    const ExactCoverage square_exact(asset, asset.glyphs[1]);
    uint32_t covered = 0, corners = 0;
    for (uint32_t j = 0; j < both.rect.height; ++j) {
        for (uint32_t i = 0; i < both.rect.width; ++i) {
            const bool front_covers = front.alpha_at(i, j, 0) > 1.0 - 1e-12;
            const bool only_square = front.alpha_at(i, j, 0) == 0.0 &&
                                     pixel_coverage(square_exact, key, both.rect.x + static_cast<int32_t>(i),
                                                    both.rect.y + static_cast<int32_t>(j)) > 1.0 - 1e-12;
            covered += front_covers;
            corners += only_square;
            for (uint32_t c = 0; c < 3; ++c) {
                if (front_covers) {
                    EXPECT_NEAR(both.at(i, j, c), front.at(i, j, c), 1e-9) << i << ", " << j;
                    EXPECT_NEAR(both.at(i, j, c), c == 1 ? colour::srgb_to_linear(128.0 / 255.0) : 0.0, 1e-9);
                }
                if (only_square) {
                    EXPECT_NEAR(both.at(i, j, c), c == 0 ? 1.0 : 0.0, 1e-9) << i << ", " << j;
                }
            }
        }
    }
    EXPECT_GT(covered, 400u);  // a circle of radius 16 px
    EXPECT_GT(corners, 20u);
}

TEST(ColourReference, EmptyLayersChangeNothing) {
    FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    const GlyphKey key = key_at(14, 23, 200, 30);
    const SubpixelLayout rgb = preset("rgb");
    const colour::ColourImage plain = render(asset, kTwoLayers, key, rgb);
    // Between the two layers a layer of no outline, after them the small square in a paint of
    // alpha 0: a copy of the glyph at the end of the layers.
    GlyphRecord empty;
    empty.flags = kGlyphBaked;
    const auto empty_glyph = static_cast<uint32_t>(asset.glyphs.size());
    asset.glyphs.push_back(empty);
    Paint clear;
    clear.first_stop = static_cast<uint32_t>(asset.stops.size());
    clear.stop_count = 1;
    asset.stops.push_back({0.0f, 2, 0.0f});
    const auto clear_paint = static_cast<uint32_t>(asset.paints.size());
    asset.paints.push_back(clear);
    const ColourGlyph& two = asset.colour_glyphs[kTwoLayers];
    ColourGlyph padded = two;
    padded.first_layer = static_cast<uint32_t>(asset.layers.size());
    padded.layer_count = 4;
    const std::vector<ColourLayer> layers = {
        asset.layers[two.first_layer], {empty_glyph, 0}, asset.layers[two.first_layer + 1], {5, clear_paint}};
    asset.layers.insert(asset.layers.end(), layers.begin(), layers.end());
    asset.colour_glyphs.push_back(padded);
    const colour::ColourImage same = render(asset, static_cast<uint32_t>(asset.colour_glyphs.size() - 1), key, rgb);
    EXPECT_EQ(same.rect.x, plain.rect.x);
    EXPECT_EQ(same.rect.y, plain.rect.y);
    EXPECT_EQ(same.rgb, plain.rgb);
    EXPECT_EQ(same.alpha, plain.alpha);
    EXPECT_FALSE(plain.rgb.empty());
}

TEST(ColourReference, ChannelsAreIndependentUnderRgb) {
    const FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    const GlyphKey key = key_at(16, 19, 100, 0);
    const SubpixelLayout rgb = preset("rgb");
    const colour::ColourImage image = render(asset, kFourLayers, key, rgb);
    uint32_t differing = 0;
    for (uint32_t c = 0; c < 3; ++c) {
        // Channel c alone: a layout of three copies of its rectangle.
        SubpixelLayout alone = rgb;
        alone.channels = {rgb.channels[c], rgb.channels[c], rgb.channels[c]};
        const colour::ColourImage one = render(asset, kFourLayers, key, alone);
        ASSERT_EQ(one.rgb.size(), image.rgb.size());
        for (size_t p = 0; p < image.rgb.size() / 3; ++p) {
            EXPECT_EQ(image.rgb[p * 3 + c], one.rgb[p * 3 + c]) << "channel " << c << " pixel " << p;
            EXPECT_EQ(image.alpha[p * 3 + c], one.alpha[p * 3 + c]) << "channel " << c << " pixel " << p;
            if (c == 0) differing += std::fabs(image.alpha[p * 3] - image.alpha[p * 3 + 2]) > 0.05;
        }
    }
    EXPECT_GT(differing, 20u);  // the thirds do see different edges
}

TEST(ColourReference, CoverageClipAndTheForegroundLayer) {
    FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    const GlyphKey key = key_at(17, 30, 128, 64);
    const SubpixelLayout gray = preset("gray");
    const std::array<double, 3> background = {0.2, 0.4, 0.6};
    // One translucent layer over the background: alpha 0x80 times the pixel's exact coverage.
    const colour::ColourImage circle = render(asset, kAlphaLayer, key, gray, kBlack, background);
    const ExactCoverage circle_exact(asset, asset.glyphs[2]);
    const double a = 128.0 / 255.0;
    double largest = 0.0;
    for (uint32_t j = 0; j < circle.rect.height; ++j) {
        for (uint32_t i = 0; i < circle.rect.width; ++i) {
            const double k = pixel_coverage(circle_exact, key, circle.rect.x + static_cast<int32_t>(i),
                                            circle.rect.y + static_cast<int32_t>(j));
            largest = std::max(largest, k);
            EXPECT_NEAR(circle.alpha_at(i, j, 1), a * k, 1e-12);
            EXPECT_NEAR(circle.at(i, j, 0), a * k + (1 - a * k) * background[0], 1e-12);
            EXPECT_NEAR(circle.at(i, j, 1), (1 - a * k) * background[1], 1e-12);
        }
    }
    EXPECT_EQ(largest, 1.0);

    // Clipped to em x <= 0.5, at 30 px and an offset of half a pixel: pixel x = 15.5. Pixels left
    // of it are as unclipped, right of it the background, and pixel 15 half of its coverage.
    ColourGlyph& clipped = asset.colour_glyphs[kAlphaLayer];
    clipped.flags = kColourClipped;
    clipped.clip_min_x = -1.0f;
    clipped.clip_min_y = -1.0f;
    clipped.clip_max_x = 0.5f;
    clipped.clip_max_y = 2.0f;
    const colour::ColourImage half = render(asset, kAlphaLayer, key, gray, kBlack, background);
    ASSERT_EQ(half.rgb.size(), circle.rgb.size());
    for (uint32_t j = 0; j < half.rect.height; ++j) {
        for (uint32_t i = 0; i < half.rect.width; ++i) {
            const int32_t x = half.rect.x + static_cast<int32_t>(i);
            const double expected = x < 15 ? circle.alpha_at(i, j, 0) : x == 15 ? circle.alpha_at(i, j, 0) / 2 : 0.0;
            EXPECT_NEAR(half.alpha_at(i, j, 0), expected, 1e-12) << x;
        }
    }

    // A layer of the text colour draws as monochrome text does: its alpha is the text's alpha
    // times the coverage, once.
    const Srgba text = {0.1, 0.5, 0.9, 0.5};
    FontAsset foreground_only = colrv0_asset();
    foreground_only.colour_glyphs[kForeground].layer_count = 1;  // the square in the text colour
    const colour::ColourImage mono = render(foreground_only, kForeground, key, gray, text, background);
    const ExactCoverage square_exact(asset, asset.glyphs[1]);
    for (uint32_t j = 0; j < mono.rect.height; ++j) {
        for (uint32_t i = 0; i < mono.rect.width; ++i) {
            const double k = pixel_coverage(square_exact, key, mono.rect.x + static_cast<int32_t>(i),
                                            mono.rect.y + static_cast<int32_t>(j));
            for (uint32_t c = 0; c < 3; ++c) {
                EXPECT_NEAR(mono.alpha_at(i, j, c), 0.5 * k, 1e-12);
                EXPECT_NEAR(mono.at(i, j, c), colour::srgb_to_linear(text[c]) * 0.5 * k + (1 - 0.5 * k) * background[c],
                            1e-12);
            }
        }
    }
}

TEST(ColourReference, RefusesBadArguments) {
    const FontAsset asset = colrv0_asset();
    const SubpixelLayout gray = preset("gray");
    const GlyphKey key = key_at(14, 20, 0, 0);
    const auto refused = [&](uint32_t colour_glyph, const GlyphKey& k, const SubpixelLayout& layout, uint32_t palette) {
        return !colour::render_colour_reference(asset, colour_glyph, k, layout, palette, kBlack, {0, 0, 0}).ok();
    };
    EXPECT_TRUE(refused(static_cast<uint32_t>(asset.colour_glyphs.size()), key, gray, 0));
    EXPECT_TRUE(refused(0, key_at(14, 0, 0, 0), gray, 0));
    EXPECT_TRUE(refused(0, key_at(14, 8000, 0, 0), gray, 0));  // past kMaxReferencePixels
    EXPECT_TRUE(refused(0, key, gray, 2));
    SubpixelLayout inverted = gray;
    inverted.channels[1] = {1.0f, 0.0f, 0.0f, 1.0f};
    EXPECT_TRUE(refused(0, key, inverted, 0));
    FontAsset broken = asset;
    broken.layers[0].paint = 9999;
    EXPECT_FALSE(colour::render_colour_reference(broken, 0, key, gray, 0, kBlack, {0, 0, 0}).ok());
}

TEST(ColourReference, ImageLayersNearestAndBoxFiltered) {
    // The 2 x 2 image over colrv0.ttf's square (em 0.1 - 0.9 x 0 - 0.8) as its layer's outline: at
    // 20 px a texel is 8 px; an offset of (0.625, 0.5) px puts the square at x 2.625 - 18.625, y
    // -15.5 - 0.5, and the texels' shared edges at x 10.625 and y -7.5.
    FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    const ImageAsset image;
    asset.image_bytes = image.asset.image_bytes;
    asset.images = image.asset.images;
    Paint paint = image.paint;
    paint.to_paint = {1.25f, 0.0f, 0.0f, -1.25f, -0.125f, 1.0f};  // u = (x - 0.1) / 0.8, v = (0.8 - y) / 0.8
    asset.layers.push_back({1, static_cast<uint32_t>(asset.paints.size())});
    asset.paints.push_back(paint);
    ColourGlyph bitmap;
    bitmap.glyph = 29;
    bitmap.first_layer = static_cast<uint32_t>(asset.layers.size() - 1);
    bitmap.layer_count = 1;
    asset.colour_glyphs.push_back(bitmap);
    const auto index = static_cast<uint32_t>(asset.colour_glyphs.size() - 1);
    const GlyphKey key = key_at(29, 20, 160, 128);
    const SubpixelLayout gray = preset("gray");
    Result<colour::ColourImage> nearest =
        colour::render_colour_reference(asset, index, key, gray, 0, kBlack, {0.0, 0.0, 0.0});
    Result<colour::ColourImage> box = colour::render_colour_reference(asset, index, key, gray, 0, kBlack,
                                                                      {0.0, 0.0, 0.0}, colour::ImageSampling::box);
    ASSERT_TRUE(nearest.ok()) << nearest.error().message;
    ASSERT_TRUE(box.ok()) << box.error().message;
    const auto pixel = [](const colour::ColourImage& from, int32_t x, int32_t y) {
        const auto i = static_cast<uint32_t>(x - from.rect.x), j = static_cast<uint32_t>(y - from.rect.y);
        return LinearRgba{from.at(i, j, 0), from.at(i, j, 1), from.at(i, j, 2), from.alpha_at(i, j, 0)};
    };
    // Inside one texel both read it.
    expect_colour(pixel(*nearest, 5, -13), image.texels[0], "nearest, texel 0");
    expect_colour(pixel(*box, 5, -13), image.texels[0], "box, texel 0");
    expect_colour(pixel(*nearest, 14, -3), image.texels[3], "nearest, texel 3");
    expect_colour(pixel(*box, 14, -3), image.texels[3], "box, texel 3");
    // Across the shared edges: nearest reads the texel under the centre (10.5, -12.5), the box
    // filter each texel by its part of the pixel.
    expect_colour(pixel(*nearest, 10, -13), image.texels[0], "nearest across the edge");
    expect_colour(pixel(*box, 10, -13), weighted(image.texels, {0.625, 0.375}), "box across the edge");
    expect_colour(pixel(*box, 10, -8), weighted(image.texels, {0.3125, 0.1875, 0.3125, 0.1875}),
                  "box across both edges");
    // At the outline's edge (x = 2.625) the coverage, 0.375, fades the pixel, not the image: its
    // centre (2.5) lies outside the image, and both read texel 0. (The outline's 0.1 em is a float:
    // the coverage is 3e-8 short.)
    expect_colour(pixel(*nearest, 2, -13), weighted(image.texels, {0.375}), "nearest at the outline's edge", 1e-7);
    expect_colour(pixel(*box, 2, -13), weighted(image.texels, {0.375}), "box at the outline's edge", 1e-7);
}

TEST(ColourReference, FreeTypeColourLayersRefuseWhatTheyCannotDraw) {
    Result<freetype::Face> colr = freetype::Face::open_file(kColrV0);
    ASSERT_TRUE(colr.ok()) << colr.error().message;
    const std::array<uint8_t, 4> text = {0, 0, 0, 255};
    Result<freetype::ColourBitmap> drawn = freetype::render_colour_layers(*colr, key_at(14, 20, 0, 0), 1, text);
    ASSERT_TRUE(drawn.ok()) << drawn.error().message;
    EXPECT_GT(drawn->width, 0u);
    EXPECT_EQ(drawn->bgra.size(), size_t{drawn->width} * drawn->height * 4);
    Result<freetype::ColourBitmap> past = freetype::render_colour_layers(*colr, key_at(14, 20, 0, 0), 2, text);
    ASSERT_FALSE(past.ok());
    EXPECT_EQ(past.error().code, ErrorCode::invalid_argument);
    Result<freetype::ColourBitmap> plain = freetype::render_colour_layers(*colr, key_at(1, 20, 0, 0), 0, text);
    ASSERT_FALSE(plain.ok());  // the square has no layers
    EXPECT_EQ(plain.error().code, ErrorCode::glyph_failed);
    EXPECT_FALSE(freetype::render_colour_layers(*colr, key_at(9999, 20, 0, 0), 0, text).ok());
    // COLRv1 paints FreeType 2.12 does not blend.
    Result<freetype::Face> v1 = freetype::Face::open_file(test::source_path("tests/fonts/colour/colrv1.ttf"));
    ASSERT_TRUE(v1.ok()) << v1.error().message;
    Result<freetype::ColourBitmap> v1_solid = freetype::render_colour_layers(*v1, key_at(15, 20, 0, 0), 0, text);
    ASSERT_FALSE(v1_solid.ok());
    EXPECT_EQ(v1_solid.error().code, ErrorCode::glyph_failed);
    Result<freetype::Face> dejavu = freetype::Face::open_file(test::kDejaVuSans);
    ASSERT_TRUE(dejavu.ok());
    Result<freetype::ColourBitmap> no_cpal = freetype::render_colour_layers(*dejavu, key_at(36, 20, 0, 0), 0, text);
    ASSERT_FALSE(no_cpal.ok());
    EXPECT_EQ(no_cpal.error().code, ErrorCode::font_unsupported);
}

// ---- FreeType's own COLRv0 blending (FT_LOAD_COLOR) as an outside check.

struct Difference {
    double sum = 0.0;
    double worst = 0.0;
    uint64_t count = 0;
    void add(double d) {
        sum += d;
        worst = std::max(worst, d);
        ++count;
    }
    double mean() const { return count ? sum / static_cast<double>(count) : 0.0; }
};

TEST(ColourReference, MatchesFreeTypeColrV0BlendingAwayFromEdges) {
    const FontAsset asset = colrv0_asset();
    ASSERT_EQ(asset.colour_glyphs.size(), std::size(kColrV0Glyphs));
    Result<freetype::Face> opened = freetype::Face::open_file(kColrV0);
    ASSERT_TRUE(opened.ok()) << opened.error().message;
    freetype::Face& face = *opened;
    const SubpixelLayout gray = preset("gray");
    // Opaque: FreeType gives the text's alpha to the foreground layers alone, crisp to every layer.
    const std::array<uint8_t, 4> text8 = {0x30, 0x90, 0xE0, 0xFF};
    const Srgba text = {text8[0] / 255.0, text8[1] / 255.0, text8[2] / 255.0, 1.0};

    std::printf("%-5s %3s %3s %23s %23s %23s %19s\n", "glyph", "px", "pal", "all: mean/max (codes)",
                "interior: mean/max", "edges: mean/max", "layer edge vs exact");
    Difference all_cases_interior, all_cases_edges, all_cases_coverage;
    for (uint32_t index = 0; index < asset.colour_glyphs.size(); ++index) {
        const ColourGlyph& glyph = asset.colour_glyphs[index];
        for (const uint32_t pixels : {17u, 48u}) {
            for (uint32_t palette = 0; palette < 2; ++palette) {
                // Offsets in 1/64 px, which FreeType's 26.6 pen holds exactly.
                const GlyphKey key = key_at(glyph.glyph, pixels, 64, 192);
                Result<freetype::ColourBitmap> theirs = freetype::render_colour_layers(face, key, palette, text8);
                ASSERT_TRUE(theirs.ok()) << theirs.error().message;
                Result<colour::ColourImage> ours =
                    colour::render_colour_reference(asset, index, key, gray, palette, text, {0.0, 0.0, 0.0});
                ASSERT_TRUE(ours.ok()) << ours.error().message;
                const GlyphRect& rect = ours->rect;
                // FreeType blends each layer's own gray rendering: those say where its edges are, and the
                // exact coverage where ours are.
                std::vector<std::vector<float>> their_layers;
                std::vector<ExactCoverage> our_layers;
                for (uint32_t l = 0; l < glyph.layer_count; ++l) {
                    GlyphKey layer_key = key;
                    layer_key.glyph = asset.layers[glyph.first_layer + l].glyph;
                    Result<freetype::PeerRender> peer =
                        freetype::render_peer(face, layer_key, rect, freetype::PeerMode::gray, 1);
                    ASSERT_TRUE(peer.ok()) << peer.error().message;
                    EXPECT_EQ(peer->lost_coverage, 0.0);
                    their_layers.push_back(peer->image.values);
                    our_layers.emplace_back(asset, asset.glyphs[layer_key.glyph]);
                }
                // Every pixel FreeType drew lies in our rect.
                EXPECT_GE(theirs->left, rect.x);
                EXPECT_GE(-theirs->top, rect.y);
                EXPECT_LE(theirs->left + static_cast<int64_t>(theirs->width),
                          rect.x + static_cast<int64_t>(rect.width));
                EXPECT_LE(-theirs->top + static_cast<int64_t>(theirs->height),
                          rect.y + static_cast<int64_t>(rect.height));

                Difference everywhere, interior, edges, coverage;
                for (uint32_t j = 0; j < rect.height; ++j) {
                    for (uint32_t i = 0; i < rect.width; ++i) {
                        const int32_t x = rect.x + static_cast<int32_t>(i), y = rect.y + static_cast<int32_t>(j);
                        // FreeType's premultiplied BGRA, as RGBA codes; 0 outside its bitmap.
                        double their[4] = {};
                        const int64_t column = int64_t{x} - theirs->left, row = int64_t{y} + theirs->top;
                        if (column >= 0 && column < theirs->width && row >= 0 && row < theirs->height) {
                            const uint8_t* bgra =
                                &theirs->bgra[(static_cast<size_t>(row) * theirs->width + static_cast<size_t>(column)) *
                                              4];
                            their[0] = bgra[2], their[1] = bgra[1], their[2] = bgra[0], their[3] = bgra[3];
                        }
                        // Ours over nothing: linear premultiplied light and alpha, to premultiplied sRGB.
                        const double alpha = ours->alpha_at(i, j, 0);
                        double our[4] = {0.0, 0.0, 0.0, 255.0 * alpha};
                        for (uint32_t c = 0; c < 3 && alpha > 0.0; ++c) {
                            our[c] = 255.0 * alpha * linear_to_srgb(std::min(1.0, ours->at(i, j, c) / alpha));
                        }
                        bool edge = false;
                        for (size_t l = 0; l < our_layers.size(); ++l) {
                            const double k = pixel_coverage(our_layers[l], key, x, y);
                            const double v = their_layers[l][(size_t{j} * rect.width + i) * 3];
                            const bool our_edge = k > 1e-9 && k < 1.0 - 1e-9;
                            const bool their_edge = v > 0.0 && v < 1.0;
                            edge = edge || our_edge || their_edge;
                            if (our_edge || their_edge) coverage.add(255.0 * std::fabs(v - k));
                        }
                        if (std::max({their[3], our[3]}) == 0.0) continue;
                        double worst = 0.0;
                        for (uint32_t c = 0; c < 4; ++c) worst = std::max(worst, std::fabs(their[c] - our[c]));
                        everywhere.add(worst);
                        (edge ? edges : interior).add(worst);
                        if (!edge) {
                            EXPECT_LE(worst, 2.0) << "glyph " << glyph.glyph << " at " << pixels << " px, palette "
                                                  << palette << ", pixel (" << x << ", " << y << ")";
                        }
                    }
                }
                EXPECT_GT(interior.count, uint64_t{pixels * pixels / 8});
                const auto cell = [](const Difference& d) {
                    char line[32];
                    std::snprintf(line, sizeof line, "%.3f/%.1f (%llu)", d.mean(), d.worst,
                                  static_cast<unsigned long long>(d.count));
                    return std::string(line);
                };
                std::printf("%-5u %3u %3u %23s %23s %23s %19s\n", glyph.glyph, pixels, palette,
                            cell(everywhere).c_str(), cell(interior).c_str(), cell(edges).c_str(),
                            cell(coverage).c_str());
                all_cases_interior.worst = std::max(all_cases_interior.worst, interior.worst);
                all_cases_edges.worst = std::max(all_cases_edges.worst, edges.worst);
                all_cases_coverage.worst = std::max(all_cases_coverage.worst, coverage.worst);
            }
        }
    }
    std::printf("worst: interior %.1f, edges %.1f codes; a layer's edge coverage %.1f codes off exact\n",
                all_cases_interior.worst, all_cases_edges.worst, all_cases_coverage.worst);
}

}  // namespace
}  // namespace crisp
