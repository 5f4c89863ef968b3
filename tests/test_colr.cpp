// The COLR/CPAL reader and the bake of colour glyphs, on crisp's colour test fonts
// (tests/fonts/colour/README.md lists what each glyph holds).
#include "test_support.hpp"
#include "bake/colr.hpp"
#include "core/file_io.hpp"
#include "core/limits.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <hb.h>

#include <array>
#include <cmath>
#include <numbers>

namespace crisp {
namespace {

const std::string kColourFonts = test::source_path("tests/fonts/colour/");
constexpr uint32_t kSquare = 1, kCircle = 2, kRing = 3, kBar = 4;
constexpr uint32_t kFaceGlyphs = 67;  // colrv1.ttf
constexpr float kEps = 1e-6f;

Result<BakeResult> bake_colour(const std::string& font, BakeOptions options = {}) {
    return bake_font_file(kColourFonts + font, options);
}

BakeOptions subset(std::vector<uint32_t> codepoints) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = std::move(codepoints);
    return options;
}

uint32_t glyph_of(const FontAsset& asset, uint32_t codepoint) {
    hb_blob_t* blob =
        hb_blob_create(reinterpret_cast<const char*>(asset.font_bytes.data()),
                       static_cast<unsigned>(asset.font_bytes.size()), HB_MEMORY_MODE_READONLY, nullptr, nullptr);
    hb_face_t* face = hb_face_create(blob, 0);
    hb_font_t* font = hb_font_create(face);
    hb_codepoint_t glyph = 0;
    hb_font_get_nominal_glyph(font, codepoint, &glyph);
    hb_font_destroy(font);
    hb_face_destroy(face);
    hb_blob_destroy(blob);
    return glyph;
}

// The layers of the colour glyph `codepoint` maps to; empty (and a failure) when it has none.
std::span<const ColourLayer> layers_of(const FontAsset& asset, uint32_t codepoint) {
    const ColourGlyph* colour = asset.colour_glyph(glyph_of(asset, codepoint));
    EXPECT_NE(colour, nullptr) << "U+" << std::hex << codepoint << " has no colour glyph";
    if (!colour) return {};
    return std::span(asset.layers).subspan(colour->first_layer, colour->layer_count);
}

std::span<const ColourStop> stops_of(const FontAsset& asset, const Paint& paint) {
    return std::span(asset.stops).subspan(paint.first_stop, paint.stop_count);
}

void expect_solid(const FontAsset& asset, const ColourLayer& layer, uint32_t glyph, uint32_t palette_index,
                  float alpha) {
    EXPECT_EQ(layer.glyph, glyph);
    const Paint& paint = asset.paints[layer.paint];
    EXPECT_EQ(paint.kind, PaintKind::solid);
    EXPECT_EQ(paint.to_paint, Affine{});
    ASSERT_EQ(paint.stop_count, 1u);
    EXPECT_EQ(stops_of(asset, paint)[0], (ColourStop{0.0f, palette_index, alpha}));
}

struct Solid {
    uint32_t glyph;
    uint32_t palette_index;
    float alpha;
};

// The colour glyph of `codepoint` is these solid layers, back to front.
void expect_solids(const FontAsset& asset, uint32_t codepoint, std::initializer_list<Solid> expected) {
    SCOPED_TRACE("U+" + std::to_string(codepoint));
    const auto layers = layers_of(asset, codepoint);
    ASSERT_EQ(layers.size(), expected.size());
    for (size_t i = 0; const Solid& solid : expected) {
        expect_solid(asset, layers[i++], solid.glyph, solid.palette_index, solid.alpha);
    }
}

// The stops every gradient of colrv1.ttf has: red, yellow at half alpha, blue.
void expect_red_blue(const FontAsset& asset, const Paint& paint) {
    const std::vector<ColourStop> expected = {{0.0f, 0, 1.0f}, {0.5f, 3, 0.5f}, {1.0f, 2, 1.0f}};
    EXPECT_EQ(std::vector<ColourStop>(stops_of(asset, paint).begin(), stops_of(asset, paint).end()), expected);
}

// The paint of the one layer of `codepoint` on `glyph`: a gradient of `kind` and `extend` with
// the red-blue stops; null (and a failure) otherwise.
const Paint* gradient_of(const FontAsset& asset, uint32_t codepoint, uint32_t glyph, PaintKind kind,
                         PaintExtend extend) {
    SCOPED_TRACE("U+" + std::to_string(codepoint));
    const auto layers = layers_of(asset, codepoint);
    EXPECT_EQ(layers.size(), 1u);
    if (layers.size() != 1) return nullptr;
    EXPECT_EQ(layers[0].glyph, glyph);
    const Paint& paint = asset.paints[layers[0].paint];
    EXPECT_EQ(paint.kind, kind);
    EXPECT_EQ(paint.extend, extend);
    expect_red_blue(asset, paint);
    return &paint;
}

struct Map {  // x' = xx x + xy y + dx, y' = yx x + yy y + dy
    double xx = 1, yx = 0, xy = 0, yy = 1, dx = 0, dy = 0;
    Point operator()(Point p) const {
        const auto x = static_cast<double>(p.x), y = static_cast<double>(p.y);
        return {static_cast<float>(xx * x + xy * y + dx), static_cast<float>(yx * x + yy * y + dy)};
    }
    Map then(const Map& outer) const {  // outer after this
        return {outer.xx * xx + outer.xy * yx,
                outer.yx * xx + outer.yy * yx,
                outer.xx * xy + outer.xy * yy,
                outer.yx * xy + outer.yy * yy,
                outer.xx * dx + outer.xy * dy + outer.dx,
                outer.yx * dx + outer.yy * dy + outer.dy};
    }
};

Map about(Map m, double cx, double cy) {  // m around the centre (cx, cy)
    return Map{1, 0, 0, 1, -cx, -cy}.then(m).then(Map{1, 0, 0, 1, cx, cy});
}

Map rotation(double f2dot14_units) {
    const double a = f2dot14_units / 16384.0 * std::numbers::pi;
    return {std::cos(a), std::sin(a), -std::sin(a), std::cos(a), 0, 0};
}

Point apply(const Affine& a, Point p) {
    return {a.xx * p.x + a.xy * p.y + a.dx, a.yx * p.x + a.yy * p.y + a.dy};
}

bool near(Point a, Point b, float eps = 1e-5f) {
    return std::fabs(a.x - b.x) <= eps && std::fabs(a.y - b.y) <= eps;
}

// The points of glyph record `glyph` holds `p` (within float rounding).
bool has_point(const FontAsset& asset, uint32_t glyph, Point p) {
    const GlyphRecord& record = asset.glyphs[glyph];
    const auto points = std::span(asset.points).subspan(record.point_offset, 2 * size_t{record.curve_count} + 1);
    return std::any_of(points.begin(), points.end(), [&](Point q) { return near(p, q); });
}

// The one layer of colrv1.ttf's glyph `codepoint`: a synthetic outline of the square under `m`
// (font units), whose gradient's mapping undoes m.
void expect_square_under(const FontAsset& asset, uint32_t codepoint, const Map& units) {
    const auto layers = layers_of(asset, codepoint);
    ASSERT_EQ(layers.size(), 1u);
    const uint32_t synthetic = layers[0].glyph;
    ASSERT_GE(synthetic, kFaceGlyphs);
    EXPECT_EQ(asset.glyphs[synthetic].flags, kGlyphBaked | kGlyphSynthetic);
    Map em = units;
    em.dx /= 1000.0;
    em.dy /= 1000.0;
    for (Point corner : {Point{0.1f, 0.0f}, Point{0.9f, 0.8f}, Point{0.1f, 0.8f}}) {
        EXPECT_TRUE(has_point(asset, synthetic, em(corner)))
            << "U+" << std::hex << codepoint << ": corner " << corner.x << "," << corner.y << " -> " << em(corner).x
            << "," << em(corner).y;
        const Paint& paint = asset.paints[layers[0].paint];
        if (paint.kind != PaintKind::solid) {
            EXPECT_TRUE(near(apply(paint.to_paint, em(corner)), corner));
        }
    }
}

TEST(Colr, V0LayersPalettesAndTheForegroundIndex) {
    auto baked = bake_colour("colrv0.ttf");
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    EXPECT_EQ(asset.palette_size, 7u);
    EXPECT_EQ(asset.palette_count(), 2u);
    EXPECT_EQ(asset.palette_colours[0], 0xFF0000FFu);      // red: r in the low byte
    EXPECT_EQ(asset.palette_colours[4], 0x80FF00FFu);      // magenta at alpha 128
    EXPECT_EQ(asset.palette_colours[7 + 1], 0xFF800080u);  // palette 1, entry 1: 800080ff

    expect_solids(asset, 0xE000, {{kSquare, 0, 1.0f}, {kCircle, 1, 1.0f}});
    expect_solids(asset, 0xE001, {{kSquare, kForegroundPaletteIndex, 1.0f}, {kRing, 2, 1.0f}});
    expect_solids(asset, 0xE002, {{kSquare, 0, 1.0f}, {kCircle, 1, 1.0f}, {kRing, 2, 1.0f}, {kBar, 3, 1.0f}});
    expect_solids(asset, 0xE003, {{kCircle, 4, 1.0f}});
    EXPECT_EQ(layers_of(asset, 0xE000)[0].paint, layers_of(asset, 0xE002)[0].paint);  // equal paints are shared

    // Four PUA glyphs and nine emoji; COLRv0 has neither transforms nor clip boxes.
    EXPECT_EQ(baked->report.colour_glyphs, 13u);
    EXPECT_EQ(baked->report.colour_layers, asset.layers.size());
    EXPECT_EQ(baked->report.synthetic_glyphs, 0u);
    EXPECT_EQ(baked->report.colour_fallbacks, 0u);
    EXPECT_EQ(asset.face_glyph_count(), asset.glyphs.size());
    for (const ColourGlyph& colour : asset.colour_glyphs) EXPECT_EQ(colour.flags, 0u);

    auto loaded = load_asset(serialize_asset(asset));
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_EQ(*loaded, asset);
}

TEST(Colr, SubsetBakesTheLayerGlyphsOfTheColourGlyphsItKeeps) {
    auto baked = bake_colour("colrv0.ttf", subset({0xE002}));
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    ASSERT_EQ(asset.colour_glyphs.size(), 1u);
    for (uint32_t glyph : {kSquare, kCircle, kRing, kBar}) EXPECT_NE(asset.glyphs[glyph].flags & kGlyphBaked, 0u);
    EXPECT_EQ(asset.glyphs[5].flags, 0u);  // "small": no layer of U+E002
    EXPECT_GT(asset.glyphs[kRing].curve_count, 0u);

    // A flag is a ligature of two regional indicators: the closure brings it, with its layers.
    auto flag = bake_colour("colrv1.ttf", subset({0x1F1FA, 0x1F1F8}));
    ASSERT_TRUE(flag) << flag.error().message;
    EXPECT_EQ(flag->asset.colour_glyphs.size(), 3u);            // ri_u, ri_s, flag_us
    EXPECT_NE(flag->asset.glyphs[11].flags & kGlyphBaked, 0u);  // stripe_lo, a layer of flag_us only
}

TEST(Colr, V1FillsAndExtendModes) {
    auto baked = bake_colour("colrv1.ttf");
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    EXPECT_EQ(asset.palette_count(), 2u);

    expect_solids(asset, 0xE000, {{kSquare, 0, 1.0f}, {kCircle, 1, 0.5f}});
    expect_solids(asset, 0xE001, {{kRing, 2, 0.75f}});

    const PaintExtend extends[] = {PaintExtend::pad, PaintExtend::repeat, PaintExtend::reflect};
    for (uint32_t i = 0; i < 3; ++i) {
        SCOPED_TRACE(static_cast<int>(i));
        const Paint* linear = gradient_of(asset, 0xE002 + 3 * i, kSquare, PaintKind::linear, extends[i]);
        ASSERT_NE(linear, nullptr);
        const Paint& l = *linear;
        EXPECT_EQ(l.to_paint, Affine{});
        // p0 100,100; p1 500,100 moved onto the normal of p0->p2 (100,400): p1 - p0 loses its
        // part along (100,400), 400 * 100 / 170000 of it.
        const double along = 40000.0 / 170000.0;
        EXPECT_NEAR(l.geometry[0], 0.1, kEps);
        EXPECT_NEAR(l.geometry[1], 0.1, kEps);
        EXPECT_NEAR(l.geometry[2], 0.1 + (400.0 - along * 100.0) / 1000.0, kEps);
        EXPECT_NEAR(l.geometry[3], 0.1 - along * 400.0 / 1000.0, kEps);
        EXPECT_NEAR((l.geometry[2] - l.geometry[0]) * 0.1f + (l.geometry[3] - l.geometry[1]) * 0.4f, 0.0f, kEps);

        const Paint* radial = gradient_of(asset, 0xE003 + 3 * i, kCircle, PaintKind::radial, extends[i]);
        ASSERT_NE(radial, nullptr);
        const float radial_geometry[6] = {0.45f, 0.35f, 0.05f, 0.5f, 0.4f, 0.3f};
        for (int k = 0; k < 6; ++k) EXPECT_NEAR(radial->geometry[k], radial_geometry[k], kEps);

        const Paint* sweep = gradient_of(asset, 0xE004 + 3 * i, kCircle, PaintKind::sweep, extends[i]);
        ASSERT_NE(sweep, nullptr);
        // 45 to 270 degrees: 1/8 to 3/4 turn (the table's angles are biased by 180 degrees).
        const float sweep_geometry[4] = {0.5f, 0.4f, 0.125f, 0.75f};
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(sweep->geometry[k], sweep_geometry[k], kEps);
    }

    auto foreground = layers_of(asset, 0xE00B);
    ASSERT_EQ(foreground.size(), 1u);
    const auto stops = stops_of(asset, asset.paints[foreground[0].paint]);
    ASSERT_EQ(stops.size(), 2u);
    EXPECT_EQ(stops[0], (ColourStop{0.0f, kForegroundPaletteIndex, 0.5f}));
    EXPECT_EQ(stops[1], (ColourStop{1.0f, 1, 1.0f}));

    // PaintColrGlyph: the linear glyph's layer, its paint shared.
    auto colr_glyph = layers_of(asset, 0xE00C);
    ASSERT_EQ(colr_glyph.size(), 2u);
    expect_solid(asset, colr_glyph[0], kCircle, 3, 1.0f);
    EXPECT_EQ(colr_glyph[1], layers_of(asset, 0xE002)[0]);

    // The Var* fills at their default values.
    expect_solids(asset, 0xE01F, {{kSquare, 1, 0.5f}});
    const Paint& var_linear = asset.paints[layers_of(asset, 0xE020)[0].paint];
    const Paint& linear = asset.paints[layers_of(asset, 0xE005)[0].paint];
    EXPECT_EQ(var_linear, linear);  // repeat, the same geometry and stops: one paint
    EXPECT_EQ(layers_of(asset, 0xE021)[0], layers_of(asset, 0xE009)[0]);  // radial, reflect
    EXPECT_EQ(layers_of(asset, 0xE022)[0], layers_of(asset, 0xE007)[0]);  // sweep, repeat
}

TEST(Colr, V1TransformsFoldIntoSyntheticOutlinesAndPaintMappings) {
    auto baked = bake_colour("colrv1.ttf");
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    EXPECT_EQ(asset.face_glyph_count(), kFaceGlyphs);
    EXPECT_EQ(baked->report.synthetic_glyphs, asset.glyphs.size() - kFaceGlyphs);
    EXPECT_EQ(baked->report.synthetic_glyphs, 14u);

    expect_square_under(asset, 0xE00D, {0.5, 0.25, -0.25, 0.75, 100, 50});
    expect_square_under(asset, 0xE010, {0.5, 0, 0, 1.5, 0, 0});
    expect_square_under(asset, 0xE011, about({0.5, 0, 0, 1.5, 0, 0}, 500, 400));
    expect_square_under(asset, 0xE012, {0.5, 0, 0, 0.5, 0, 0});
    expect_square_under(asset, 0xE013, about({0.5, 0, 0, 0.5, 0, 0}, 500, 400));
    expect_square_under(asset, 0xE014, rotation(2731));  // 30 degrees, as F2DOT14 holds it
    expect_square_under(asset, 0xE015, about(rotation(8192), 500, 400));
    // Skews lean the y axis towards -x by the x angle, the x axis towards +y by the y angle.
    const auto skew = [](double x, double y) {
        return Map{1, std::tan(y / 16384.0 * std::numbers::pi), -std::tan(x / 16384.0 * std::numbers::pi), 1, 0, 0};
    };
    expect_square_under(asset, 0xE016, skew(2731, -1365));
    expect_square_under(asset, 0xE017, about(skew(2731, 0), 500, 400));
    // The Var* transforms, innermost first.
    expect_square_under(asset, 0xE023,
                        about({0.75, 0, 0, 1.25, 0, 0}, 500, 400)
                            .then({1.25, 0, 0, 0.75, 0, 0})
                            .then({1, 0, 0, 1, 20, -30})
                            .then({1, 0, 0.125, 1, 0, 0}));
    expect_square_under(asset, 0xE024,
                        about(rotation(4096), 500, 400)
                            .then(rotation(-4096))
                            .then(about({0.5, 0, 0, 0.5, 0, 0}, 500, 400))
                            .then({1.5, 0, 0, 1.5, 0, 0}));
    expect_square_under(asset, 0xE025, about(skew(-1820, 910), 500, 400).then(skew(910, 0)));

    // A translate above the PaintGlyph moves the outline and the gradient alike.
    auto translated = layers_of(asset, 0xE00E);
    ASSERT_EQ(translated.size(), 1u);
    const GlyphRecord& moved = asset.glyphs[translated[0].glyph];
    const GlyphRecord& circle = asset.glyphs[kCircle];
    EXPECT_GE(translated[0].glyph, kFaceGlyphs);
    EXPECT_NEAR(moved.bbox_min_x, circle.bbox_min_x + 0.1f, kEps);
    EXPECT_NEAR(moved.bbox_max_y, circle.bbox_max_y - 0.05f, kEps);
    EXPECT_EQ(moved.curve_count, circle.curve_count);
    const Affine undo{1.0f, 0.0f, 0.0f, 1.0f, -0.1f, 0.05f};
    EXPECT_TRUE(near(apply(asset.paints[translated[0].paint].to_paint, {0.6f, 0.35f}), apply(undo, {0.6f, 0.35f})));
    // Below it, only the gradient moves.
    auto paint_only = layers_of(asset, 0xE00F);
    ASSERT_EQ(paint_only.size(), 1u);
    EXPECT_EQ(paint_only[0].glyph, kCircle);
    EXPECT_EQ(asset.paints[paint_only[0].paint].to_paint, asset.paints[translated[0].paint].to_paint);

    // Two layers of one glyph under one transform share one synthetic outline.
    auto shared = layers_of(asset, 0xE026);
    ASSERT_EQ(shared.size(), 2u);
    EXPECT_GE(shared[0].glyph, kFaceGlyphs);
    EXPECT_EQ(shared[0].glyph, shared[1].glyph);
    EXPECT_NE(shared[0].paint, shared[1].paint);

    auto loaded = load_asset(serialize_asset(asset));
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_EQ(*loaded, asset);
}

TEST(Colr, V1CompositeModesClipBoxesAndFallbacks) {
    auto baked = bake_colour("colrv1.ttf");
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    // Source a blue circle, backdrop a red square.
    const Solid red_square{kSquare, 0, 1.0f}, blue_circle{kCircle, 2, 1.0f};
    expect_solids(asset, 0xE018, {red_square, blue_circle});  // src_over
    expect_solids(asset, 0xE019, {blue_circle, red_square});  // dest_over
    expect_solids(asset, 0xE01A, {blue_circle});              // src
    expect_solids(asset, 0xE01B, {red_square});               // dest
    // Clear draws nothing: one transparent layer on the base glyph.
    expect_solids(asset, 0xE01C, {{glyph_of(asset, 0xE01C), kForegroundPaletteIndex, 0.0f}});

    // Multiply falls back to the glyph's COLRv0 layers; the nested clip, with none, to its outline.
    expect_solids(asset, 0xE01D, {{kRing, 1, 1.0f}, {kBar, 3, 1.0f}});
    EXPECT_EQ(asset.colour_glyph(glyph_of(asset, 0xE01E)), nullptr);
    EXPECT_EQ(baked->report.colour_fallbacks, 2u);
    EXPECT_EQ(baked->report.first_colour_fallback,
              "glyph 43: COLRv1: the PaintComposite at offset 817: composite mode multiply (23) is not supported");
    auto nested = bake_colour("colrv1.ttf", subset({0xE01E}));
    ASSERT_TRUE(nested) << nested.error().message;
    EXPECT_EQ(nested->report.colour_fallbacks, 1u);
    EXPECT_NE(nested->report.first_colour_fallback.find("inside another PaintGlyph: a nested clip"), std::string::npos)
        << nested->report.first_colour_fallback;

    // COLRv1 wins over COLRv0 (a red circle) for a glyph with both.
    expect_solids(asset, 0xE029, {{kSquare, 1, 1.0f}});

    const ColourGlyph* clipped = asset.colour_glyph(glyph_of(asset, 0xE027));
    ASSERT_NE(clipped, nullptr);
    EXPECT_EQ(clipped->flags, kColourClipped);
    EXPECT_EQ((std::array{clipped->clip_min_x, clipped->clip_min_y, clipped->clip_max_x, clipped->clip_max_y}),
              (std::array{0.2f, 0.1f, 0.8f, 0.7f}));
    const ColourGlyph* clipped_var = asset.colour_glyph(glyph_of(asset, 0xE028));
    ASSERT_NE(clipped_var, nullptr);
    EXPECT_EQ(clipped_var->flags, kColourClipped);
    EXPECT_EQ(clipped_var->clip_max_x, 0.5f);
    EXPECT_EQ(clipped_var->clip_max_y, 0.4f);
    EXPECT_EQ(asset.colour_glyph(glyph_of(asset, 0xE000))->flags, 0u);
}

TEST(Colr, ACollectionsFaceAndAVariableFontsDefaultInstance) {
    BakeOptions second;
    second.face_index = 1;
    auto collection = bake_colour("colr_collection.ttc", second);
    auto single = bake_colour("colrv1.ttf");
    ASSERT_TRUE(collection) << collection.error().message;
    ASSERT_TRUE(single) << single.error().message;
    EXPECT_EQ(collection->asset.colour_glyphs, single->asset.colour_glyphs);
    EXPECT_EQ(collection->asset.layers, single->asset.layers);
    EXPECT_EQ(collection->asset.paints, single->asset.paints);
    EXPECT_EQ(collection->asset.palette_colours, single->asset.palette_colours);
    auto first = bake_colour("colr_collection.ttc");
    ASSERT_TRUE(first) << first.error().message;
    EXPECT_EQ(first->asset.colour_glyphs.size(), 13u);  // colrv0.ttf's

    // The delta is not applied at wght 700, and the report says so; at the default it has nothing to say.
    BakeOptions heavy;
    heavy.variations = {{make_tag("wght"), 700.0f}};
    auto varied = bake_colour("colrv1_variable.ttf", heavy);
    ASSERT_TRUE(varied) << varied.error().message;
    expect_solids(varied->asset, 0xE000, {{kSquare, 0, 1.0f}});
    ASSERT_EQ(varied->report.colour_notes.size(), 1u);
    EXPECT_EQ(varied->report.colour_notes[0],
              "COLR varies, but its deltas are not applied: the colour glyphs are those of the default instance");
    auto plain = bake_colour("colrv1_variable.ttf");
    ASSERT_TRUE(plain) << plain.error().message;
    EXPECT_TRUE(plain->report.colour_notes.empty());
}

TEST(Colr, HostileGraphsAreRefusedNamingTheReason) {
    struct Case {
        const char* font;
        uint32_t codepoint;
        const char* reason;
    };
    const Case cases[] = {
        {"colr_cycle.ttf", 0xE000, "a cycle in the paint graph: the PaintColrGlyph at offset"},
        {"colr_cycle.ttf", 0xE002, "a cycle in the paint graph: the PaintColrLayers at offset"},
        {"colr_deep.ttf", 0xE000, "nests deeper than 64 paints (kMaxPaintDepth)"},
        {"colr_deep.ttf", 0xE001, "nests deeper than 64 paints (kMaxPaintDepth)"},
        {"colr_wide.ttf", 0xE000, "more than 1024 layers once flattened (kMaxColourLayers)"},
        {"colr_bad_palette.ttf", 0xE000, "the PaintSolid at offset 76: palette index 40 is past the 7 entries of CPAL"},
        {"colr_bad_palette.ttf", 0xE001, "stop 1 of the PaintLinearGradient"},
        {"colr_bad_palette.ttf", 0xE003, "COLRv0: layer 1: palette index 9 is past the 7 entries of CPAL"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.font) + " " + std::to_string(c.codepoint));
        auto failed = bake_colour(c.font, subset({c.codepoint}));
        ASSERT_FALSE(failed);
        EXPECT_EQ(failed.error().code, ErrorCode::glyph_failed);
        EXPECT_NE(failed.error().message.find("1 of 1 colour glyphs are malformed; first: glyph "), std::string::npos)
            << failed.error().message;
        EXPECT_NE(failed.error().message.find(c.reason), std::string::npos) << failed.error().message;

        // With allow_failed the glyph draws as its plain outline, counted.
        BakeOptions options = subset({c.codepoint});
        options.allow_failed = true;
        auto baked = bake_colour(c.font, options);
        ASSERT_TRUE(baked) << baked.error().message;
        EXPECT_TRUE(baked->asset.colour_glyphs.empty());
        EXPECT_EQ(baked->report.colour_fallbacks, 1u);
        EXPECT_NE(baked->report.first_colour_fallback.find(c.reason), std::string::npos);
    }

    // At the limits, not past them: 1024 layers; a good glyph beside bad ones.
    auto wide = bake_colour("colr_wide.ttf", subset({0xE001}));
    ASSERT_TRUE(wide) << wide.error().message;
    ASSERT_EQ(wide->asset.colour_glyphs.size(), 1u);
    EXPECT_EQ(wide->asset.colour_glyphs[0].layer_count, kMaxColourLayers);
    EXPECT_EQ(wide->asset.paints.size(), 2u);
    auto good = bake_colour("colr_bad_palette.ttf", subset({0xE002}));
    ASSERT_TRUE(good) << good.error().message;
    expect_solids(good->asset, 0xE002, {{kSquare, 6, 1.0f}});

    // The whole font: every bad glyph counted, the first named.
    auto all = bake_colour("colr_bad_palette.ttf");
    ASSERT_FALSE(all);
    EXPECT_EQ(all.error().message.substr(0, 43), "3 of 4 colour glyphs are malformed; first: ");
}

TEST(Colr, AColourGlyphWhoseSyntheticOutlineFailsIsDropped) {
    auto failed = bake_colour("colr_far.ttf");
    ASSERT_FALSE(failed);
    EXPECT_EQ(failed.error().code, ErrorCode::glyph_failed);
    EXPECT_EQ(failed.error().message,
              "a layer's outline failed in 1 colour glyphs; first: glyph 14: the outline of its layer 0 (glyph 1 "
              "under the layer's transform) failed: coordinates beyond +-64 em");

    // Allowed, the far glyph draws as its outline; the near one keeps its outline, renumbered.
    BakeOptions options;
    options.allow_failed = true;
    auto baked = bake_colour("colr_far.ttf", options);
    ASSERT_TRUE(baked) << baked.error().message;
    const FontAsset& asset = baked->asset;
    EXPECT_EQ(asset.colour_glyph(glyph_of(asset, 0xE000)), nullptr);
    auto near_layers = layers_of(asset, 0xE001);
    ASSERT_EQ(near_layers.size(), 1u);
    EXPECT_EQ(near_layers[0].glyph, asset.face_glyph_count());
    EXPECT_EQ(asset.glyphs.size(), asset.face_glyph_count() + 1);
    EXPECT_NEAR(asset.glyphs[near_layers[0].glyph].bbox_min_x, asset.glyphs[kCircle].bbox_min_x + 0.01f, kEps);
    EXPECT_EQ(baked->report.synthetic_glyphs, 1u);
    EXPECT_EQ(baked->report.colour_fallbacks, 1u);
    EXPECT_EQ(baked->report.failed_glyphs, 0u);
    EXPECT_EQ(baked->report.first_colour_fallback,
              failed.error().message.substr(failed.error().message.find("glyph 14")));
}

TEST(Colr, UnreadableTablesFailTheBakeUnlessAllowed) {
    auto failed = bake_colour("colr_truncated.ttf");
    ASSERT_FALSE(failed);
    EXPECT_EQ(failed.error().code, ErrorCode::font_unreadable);
    EXPECT_EQ(failed.error().message, "COLR: the LayerList at offset 1203 lies past the table's end (598 bytes)");
    BakeOptions options;
    options.allow_failed = true;
    auto baked = bake_colour("colr_truncated.ttf", options);
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_TRUE(baked->asset.colour_glyphs.empty());
    EXPECT_EQ(baked->asset.palette_size, 0u);
    ASSERT_EQ(baked->report.colour_notes.size(), 1u);
    EXPECT_EQ(baked->report.colour_notes[0], failed.error().message + "; no colour glyphs baked");
}

TEST(Colr, FontsWithoutColourTablesBakeNoColour) {
    auto baked = bake_font_file(test::kDejaVuSans, subset({'A', 'g'}));
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_TRUE(baked->asset.colour_glyphs.empty());
    EXPECT_TRUE(baked->asset.palette_colours.empty());
    EXPECT_EQ(baked->asset.face_glyph_count(), baked->asset.glyphs.size());
    EXPECT_EQ(baked->report.colour_glyphs + baked->report.colour_fallbacks + baked->report.synthetic_glyphs, 0u);
    EXPECT_TRUE(baked->report.colour_notes.empty());
}

// The COLR and CPAL tables of a font of the test set.
std::pair<std::vector<std::byte>, std::vector<std::byte>> colour_tables(const std::string& font) {
    auto bytes = read_file(kColourFonts + font, limits::kFontFileBytes);
    EXPECT_TRUE(bytes);
    if (!bytes) return {};
    auto colr = find_sfnt_table(*bytes, 0, make_tag("COLR"));
    auto cpal = find_sfnt_table(*bytes, 0, make_tag("CPAL"));
    EXPECT_TRUE(colr && cpal);
    if (!colr || !cpal) return {};
    return {{colr->begin(), colr->end()}, {cpal->begin(), cpal->end()}};
}

// Every base glyph of every prefix of colrv1.ttf's COLR table, and of the table with each byte
// set to 0xFF: read or refused, never a crash (the sanitizer build checks the reads).
TEST(Colr, TruncatedAndCorruptedTablesNeverCrash) {
    const auto [colr, cpal] = colour_tables("colrv1.ttf");
    ASSERT_EQ(colr.size(), 1495u);
    const auto read_all = [&](std::span<const std::byte> table, uint32_t& colour, uint32_t& refused) {
        auto reader = ColrReader::open(table, cpal, kFaceGlyphs, 1000);
        if (!reader) return false;
        for (uint32_t glyph : reader->base_glyphs()) {
            const ColrOutcome outcome = reader->flatten(glyph);
            colour += outcome.colour;
            refused += outcome.refusal == ColrRefusal::malformed;
        }
        return true;
    };
    uint32_t opened = 0, colour = 0, refused = 0;
    for (size_t size = 0; size <= colr.size(); ++size) opened += read_all(std::span(colr).first(size), colour, refused);
    EXPECT_GT(opened, 0u);
    EXPECT_GT(refused, 0u);  // prefixes that cut paints off mid-graph
    EXPECT_FALSE(ColrReader::open(std::span(colr).first(33), cpal, kFaceGlyphs, 1000));

    std::vector<std::byte> corrupt = colr;
    for (size_t i = 0; i < corrupt.size(); ++i) {
        const std::byte kept = corrupt[i];
        corrupt[i] = std::byte{0xFF};
        read_all(corrupt, colour, refused);
        corrupt[i] = kept;
    }
    uint32_t whole_colour = 0, whole_refused = 0;
    ASSERT_TRUE(read_all(colr, whole_colour, whole_refused));
    EXPECT_EQ(whole_refused, 0u);
    EXPECT_EQ(whole_colour, 50u);  // all but the nested clip (multiply falls back to COLRv0)
}

// A COLR with no glyphs and a CPAL of `palettes` palettes of `entries` entries.
std::pair<std::vector<std::byte>, std::vector<std::byte>> palette_tables(uint32_t palettes, uint32_t entries) {
    std::vector<std::byte> colr(14, std::byte{0});
    std::vector<std::byte> cpal;
    const auto put16 = [&](uint32_t v) {
        cpal.push_back(static_cast<std::byte>(v >> 8));
        cpal.push_back(static_cast<std::byte>(v & 0xFF));
    };
    const uint32_t records = entries;  // every palette reuses the same records
    put16(0);
    put16(entries);
    put16(palettes);
    put16(records);
    put16(0);
    put16(12 + 2 * palettes);  // colour records after the palette starts
    for (uint32_t i = 0; i < palettes; ++i) put16(0);
    for (uint32_t i = 0; i < records; ++i) {
        for (uint32_t c : {0x30u, 0x20u, 0x10u, 0xFFu}) cpal.push_back(static_cast<std::byte>(c));  // b, g, r, a
    }
    return {colr, cpal};
}

TEST(Colr, PalettesPastTheLimitsAreKeptOrRefused) {
    const auto [colr, cpal] = palette_tables(kMaxPalettes + 44, 2);
    auto reader = ColrReader::open(colr, cpal, 10, 1000);
    ASSERT_TRUE(reader) << reader.error().message;
    EXPECT_EQ(reader->table_palettes(), kMaxPalettes + 44);
    EXPECT_EQ(reader->palette_colours().size(), size_t{kMaxPalettes} * 2);
    EXPECT_EQ(reader->palette_colours()[0], 0xFF302010u);

    const auto [colr2, big] = palette_tables(1, kMaxPaletteSize + 1);
    auto refused = ColrReader::open(colr2, big, 10, 1000);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::font_unreadable);
    EXPECT_EQ(refused.error().message,
              "CPAL: 4097 entries per palette, more than crisp's limit of 4096 (kMaxPaletteSize)");

    std::vector<std::byte> short_cpal(cpal.begin(), cpal.begin() + 11);
    auto truncated = ColrReader::open(colr, short_cpal, 10, 1000);
    ASSERT_FALSE(truncated);
    EXPECT_EQ(truncated.error().message, "CPAL: 11 bytes, shorter than its 12-byte header");
}

}  // namespace
}  // namespace crisp
