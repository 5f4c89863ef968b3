#include "scene.hpp"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>

namespace crisp {
namespace {

// A valid scene whose one run is `run`.
std::string with_run(const std::string& run) {
    return R"({"fonts": ["a.crisp"], "canvas": [64, 32], "runs": [)" + run + "]}";
}

TEST(Scene, ParsesEveryMember) {
    auto scene = parse_scene(R"({
        "fonts": ["fonts/a.crisp", "/abs/b.crisp"],
        "canvas": [640, 200],
        "background": [0.1, 0.2, 0.3, 0.5],
        "layout": "qd-oled",
        "runs": [
            {"font": 1, "text": "Héllo, 世界", "size": 48.5, "origin": [10.25, -20], "color": [1, 0.5, 0, 0.75],
             "depth": 0.125},
            {"text": "", "size": 4096, "origin": [0, 0], "depth": 1},
            {"size": 0.5, "origin": [3e38, -3e38], "text": "x", "font": 0, "depth": 0, "color": [0, 0, 1]}
        ]
    })");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->fonts, (std::vector<std::string>{"fonts/a.crisp", "/abs/b.crisp"}));
    EXPECT_EQ(scene->width, 640u);
    EXPECT_EQ(scene->height, 200u);
    EXPECT_EQ(scene->background[0], 0.1f);
    EXPECT_EQ(scene->background[1], 0.2f);
    EXPECT_EQ(scene->background[2], 0.3f);
    EXPECT_EQ(scene->background[3], 0.5f);
    EXPECT_EQ(scene->layout, "qd-oled");
    ASSERT_EQ(scene->runs.size(), 3u);
    const SceneRun& first = scene->runs[0];
    EXPECT_EQ(first.font, 1u);
    EXPECT_EQ(first.text, "H\xC3\xA9llo, \xE4\xB8\x96\xE7\x95\x8C");
    EXPECT_EQ(first.size, 48.5f);
    EXPECT_EQ(first.origin_x, 10.25f);
    EXPECT_EQ(first.origin_y, -20.0f);
    EXPECT_EQ(first.color[0], 1.0f);
    EXPECT_EQ(first.color[1], 0.5f);
    EXPECT_EQ(first.color[2], 0.0f);
    EXPECT_EQ(first.color[3], 0.75f);
    EXPECT_EQ(first.depth, 0.125f);
    EXPECT_EQ(scene->runs[1].text, "");
    EXPECT_EQ(scene->runs[1].size, 4096.0f);
    EXPECT_EQ(scene->runs[1].depth, 1.0f);
    const SceneRun& third = scene->runs[2];
    EXPECT_EQ(third.size, 0.5f);
    EXPECT_EQ(third.origin_x, 3e38f);
    EXPECT_EQ(third.origin_y, -3e38f);
    EXPECT_EQ(third.depth, 0.0f);
    EXPECT_EQ(third.color[2], 1.0f);
    EXPECT_EQ(third.color[3], 1.0f);  // three components: opaque
}

TEST(Scene, DefaultsFillWhatIsLeftOut) {
    auto scene = parse_scene(R"({"fonts": ["a.crisp"], "canvas": [1, 16384],
                                 "runs": [{"text": "a", "size": 12, "origin": [1, 2]}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->width, 1u);
    EXPECT_EQ(scene->height, 16384u);
    for (const float c : scene->background) EXPECT_EQ(c, 1.0f);  // opaque white
    EXPECT_EQ(scene->layout, "rgb");
    ASSERT_EQ(scene->runs.size(), 1u);
    const SceneRun& run = scene->runs[0];
    EXPECT_EQ(run.font, 0u);
    EXPECT_EQ(run.color[0], 0.0f);  // opaque black
    EXPECT_EQ(run.color[1], 0.0f);
    EXPECT_EQ(run.color[2], 0.0f);
    EXPECT_EQ(run.color[3], 1.0f);
    EXPECT_EQ(run.depth, 0.5f);
    EXPECT_EQ(run.palette, 0u);
    EXPECT_EQ(parse_scene(R"({"fonts": ["a"], "canvas": [8, 8], "runs": []})")->runs.size(), 0u);
}

TEST(Scene, RunsTakeTheScenePaletteUnlessTheyGiveTheirOwn) {
    auto scene = parse_scene(R"({"fonts": ["a"], "canvas": [8, 8], "palette": 2, "runs": [
        {"text": "a", "size": 9, "origin": [0, 0]}, {"text": "b", "size": 9, "origin": [0, 0], "palette": 255},
        {"text": "c", "size": 9, "origin": [0, 0], "palette": 0}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->palette, 2u);
    ASSERT_EQ(scene->runs.size(), 3u);
    EXPECT_EQ(scene->runs[0].palette, 2u);
    EXPECT_EQ(scene->runs[1].palette, 255u);
    EXPECT_EQ(scene->runs[2].palette, 0u);
}

TEST(Scene, ARunsTransformIsItsTwoByTwo) {
    auto scene = parse_scene(R"({"fonts": ["a"], "canvas": [8, 8], "runs": [
        {"text": "a", "size": 9, "origin": [0, 0], "transform": [0, -1, 1, 0]},
        {"text": "b", "size": 9, "origin": [0, 0], "transform": [-1, 0.5, -0.25, 65536]},
        {"text": "c", "size": 9, "origin": [0, 0]}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->runs.size(), 3u);
    EXPECT_EQ(scene->runs[0].transform, (std::array<float, 4>{0.0f, -1.0f, 1.0f, 0.0f}));
    EXPECT_EQ(scene->runs[1].transform, (std::array<float, 4>{-1.0f, 0.5f, -0.25f, 65536.0f}));
    EXPECT_FALSE(scene->runs[2].transform);
}

TEST(Scene, BadTransformsNameTheRunAndTheLimit) {
    const struct {
        const char* transform;
        const char* fragment;
    } cases[] = {
        {"[1, 0, 0]", "scene: runs[0].transform: expected [a, b, c, d], numbers in [-65536, 65536]"},
        {"[1, 0, 0, 1, 0]", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"[]", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"\"0,1,-1,0\"", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"{\"a\": 1}", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"[1, \"0\", 0, 1]", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"[1, null, 0, 1]", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"[1, 0, 0, 65537]", "scene: runs[0].transform: expected [a, b, c, d], numbers in [-65536, 65536]"},
        {"[-1e300, 0, 0, 1]", "scene: runs[0].transform: expected [a, b, c, d]"},
        {"[0, 0, 0, 0]", "scene: runs[0].transform: is singular: |a d - b c| must be at least 2^-16"},
        {"[1, 2, 2, 4]", "scene: runs[0].transform: is singular"},
        {"[0.001, 0, 0, 0.001]", "scene: runs[0].transform: is singular"},
    };
    for (const auto& c : cases) {
        auto scene = parse_scene(
            with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "transform": )" + std::string(c.transform) + "}"));
        ASSERT_FALSE(scene) << c.transform;
        EXPECT_EQ(scene.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(scene.error().message.find(c.fragment), std::string::npos)
            << "message: " << scene.error().message << "\nexpected: " << c.fragment;
    }
    // A run's unknown member lists transform among the known ones.
    auto scene = parse_scene(with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "transfrom": [1, 0, 0, 1]})"));
    ASSERT_FALSE(scene);
    EXPECT_NE(scene.error().message.find("palette, transform, weight"), std::string::npos) << scene.error().message;
}

TEST(Scene, ARunsEffectsAreItsWeightOutlineShadowAndGlow) {
    auto scene = parse_scene(with_run(
        R"({"text": "a", "size": 20, "origin": [0, 0], "weight": -0.5,
            "outline": {"width": 2, "placement": "centred", "join": "miter", "miter_limit": 8, "color": [1, 0, 0]},
            "shadow": {"offset": [3, -1.5], "color": [0, 0, 1, 0.25], "blur": 2.5},
            "glow": {"radius": 6, "color": [1, 1, 0, 0.5]}},
           {"text": "b", "size": 20, "origin": [0, 0], "outline": {"width": 1}, "glow": {}},
           {"text": "c", "size": 20, "origin": [0, 0]})"));
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->runs.size(), 3u);
    const std::optional<TextEffects>& e = scene->runs[0].effects;
    ASSERT_TRUE(e && e->outline && e->shadow);
    EXPECT_EQ(e->weight, -0.5f);
    EXPECT_EQ(e->outline->width, 2.0f);
    EXPECT_EQ(e->outline->placement, OutlinePlacement::centred);
    EXPECT_EQ(e->outline->join, LineJoin::miter);
    EXPECT_EQ(e->outline->miter_limit, 8.0f);
    EXPECT_EQ(e->outline->color, (std::array<float, 4>{1.0f, 0.0f, 0.0f, 1.0f}));
    EXPECT_EQ(e->shadow->offset_x, 3.0f);
    EXPECT_EQ(e->shadow->offset_y, -1.5f);
    EXPECT_EQ(e->shadow->color, (std::array<float, 4>{0.0f, 0.0f, 1.0f, 0.25f}));
    EXPECT_EQ(e->shadow->blur, 2.5f);
    ASSERT_TRUE(e->glow);
    EXPECT_EQ(e->glow->radius, 6.0f);
    EXPECT_EQ(e->glow->color, (std::array<float, 4>{1.0f, 1.0f, 0.0f, 0.5f}));
    // Defaults: outside, round, black; a glow of 4 px in white at 0.75; no effects at all where a
    // run names none.
    const std::optional<TextEffects>& b = scene->runs[1].effects;
    ASSERT_TRUE(b && b->outline);
    EXPECT_EQ(b->outline->placement, OutlinePlacement::outside);
    EXPECT_EQ(b->outline->join, LineJoin::round);
    EXPECT_FALSE(b->shadow);
    ASSERT_TRUE(b->glow);
    EXPECT_EQ(*b->glow, TextGlow{});
    EXPECT_FALSE(scene->runs[2].effects);

    struct {
        const char* members;
        const char* fragment;
    } cases[] = {
        {R"("weight": "1")", "scene: runs[0].weight: expected a number of pixels in [-4096, 4096]"},
        {R"("weight": 5000)", "scene: runs[0].weight: expected a number"},
        {R"("outline": 2)", "scene: runs[0].outline: expected an object"},
        {R"("outline": {})", "scene: runs[0].outline: the \"width\" member is missing"},
        {R"("outline": {"width": -1})", "scene: runs[0].outline.width: expected pixels in [0, 4096]"},
        {R"("outline": {"width": 1, "join": "square"})", "scene: runs[0].outline.join: expected \"round\""},
        {R"("outline": {"width": 1, "placement": 0})", "scene: runs[0].outline.placement: expected \"outside\""},
        {R"("outline": {"width": 1, "miter_limit": 0.5})", "scene: runs[0].outline.miter_limit: expected a number"},
        {R"("outline": {"width": 1, "color": [2, 0, 0]})", "scene: runs[0].outline.color[0]: expected a number"},
        {R"("outline": {"width": 1, "blur": 2})", "scene: runs[0].outline: unknown member \"blur\""},
        {R"("outline": {"width": 81})", "scene: runs[0]: outline width 81 px reaches past 4 em at 20 px per em"},
        {R"("shadow": {"offset": [1]})", "scene: runs[0].shadow.offset: expected [dx, dy]"},
        {R"("shadow": {"offset": [1, 1e9]})", "scene: runs[0].shadow.offset: expected [dx, dy]"},
        {R"("shadow": {"spread": 3})", "scene: runs[0].shadow: unknown member \"spread\" (known: offset, color, blur)"},
        {R"("shadow": {"blur": -1})", "scene: runs[0].shadow.blur: expected a radius of pixels in [0, 128]"},
        {R"("shadow": {"blur": 129})", "scene: runs[0].shadow.blur: expected a radius"},
        {R"("glow": 4)", "scene: runs[0].glow: expected an object"},
        {R"("glow": {"radius": 0})", "scene: runs[0].glow.radius: expected a radius of pixels in (0, 128]"},
        {R"("glow": {"radius": 2, "offset": [1, 1]})", "scene: runs[0].glow: unknown member \"offset\""},
        {R"("glow": {"color": [0, 2, 0]})", "scene: runs[0].glow.color[1]: expected a number"},
    };
    for (const auto& c : cases) {
        auto bad =
            parse_scene(with_run(R"({"text": "a", "size": 20, "origin": [0, 0], )" + std::string(c.members) + "}"));
        ASSERT_FALSE(bad) << c.members;
        EXPECT_NE(bad.error().message.find(c.fragment), std::string::npos)
            << "message: " << bad.error().message << "\nexpected: " << c.fragment;
    }
}

TEST(Scene, RunsTakeSpansAndParagraphs) {
    auto scene = parse_scene(R"({"fonts": ["a", "b"], "canvas": [8, 8], "runs": [
        {"text": "plain caf\u00e9 bold", "size": 20, "origin": [0, 0], "color": [0, 0, 1], "underline": true,
         "features": {"liga": 0}, "wrap_width": 300, "align": "center", "line_height": 30, "line_spacing": 1.5,
         "max_lines": 2, "trimming": "middle", "scale": 1.5, "tab_stops": [40, 90],
         "spans": [{"begin": 6, "end": 11, "color": [1, 0, 0], "letter_spacing": 2, "skip_ink": false},
                   {"begin": 12, "end": 16, "font": 1, "size": 24, "baseline_shift": -3, "strikethrough": true,
                    "features": {"smcp": 1, "ss01": 2}}]}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    const SceneRun& run = scene->runs[0];
    EXPECT_TRUE(run.style.underline);
    ASSERT_EQ(run.style.features.size(), 1u);
    EXPECT_EQ(run.style.features[0].tag, (std::array<char, 4>{'l', 'i', 'g', 'a'}));
    EXPECT_EQ(run.style.features[0].value, 0u);
    EXPECT_EQ(run.wrap_width, 300.0f);
    EXPECT_EQ(run.align, Align::center);
    EXPECT_EQ(run.line_height, 30.0f);
    EXPECT_EQ(run.line_spacing, 1.5f);
    EXPECT_EQ(run.max_lines, 2u);
    EXPECT_EQ(run.trimming, Trimming::middle);
    EXPECT_EQ(run.scale, 1.5f);
    EXPECT_EQ(run.tab_stops, (std::vector<float>{40.0f, 90.0f}));
    ASSERT_EQ(run.spans.size(), 2u);
    // A span takes the run's members where it gives none.
    const SceneSpan& red = run.spans[0];
    EXPECT_EQ(red.begin, 6u);
    EXPECT_EQ(red.end, 11u);
    EXPECT_EQ(red.font, 0u);
    EXPECT_EQ(red.size, 20.0f);
    EXPECT_EQ(red.color[0], 1.0f);
    EXPECT_EQ(red.color[2], 0.0f);
    EXPECT_TRUE(red.style.underline);
    EXPECT_FALSE(red.style.skip_ink);
    EXPECT_EQ(red.style.letter_spacing, 2.0f);
    EXPECT_EQ(red.style.features, run.style.features);
    const SceneSpan& bold = run.spans[1];
    EXPECT_EQ(bold.font, 1u);
    EXPECT_EQ(bold.size, 24.0f);
    EXPECT_EQ(bold.color[2], 1.0f);
    EXPECT_EQ(bold.style.baseline_shift, -3.0f);
    EXPECT_TRUE(bold.style.strikethrough);
    ASSERT_EQ(bold.style.features.size(), 2u);
    EXPECT_EQ(bold.style.features[1].tag, (std::array<char, 4>{'s', 's', '0', '1'}));
    EXPECT_EQ(bold.style.features[1].value, 2u);
}

TEST(Scene, BadSpansNameTheirFault) {
    const auto fault = [](const std::string& members) {
        auto scene =
            parse_scene(with_run(R"({"text": "caf\u00e9 au lait", "size": 9, "origin": [0, 0], )" + members + "}"));
        return scene ? std::string("accepted") : scene.error().message;
    };
    const struct {
        const char* members;
        const char* message;
    } cases[] = {
        {R"("spans": [{"begin": 0, "end": 4}])",
         "scene: runs[0].spans[0].end: byte 4 is inside a UTF-8 sequence of the run's text"},
        {R"("spans": [{"begin": 0, "end": 3}, {"begin": 2, "end": 6}])",
         "scene: runs[0].spans[1]: begins at byte 2, inside the span before it (which ends at byte 3)"},
        {R"("spans": [{"begin": 0, "end": 14}])",
         "scene: runs[0].spans[0].end: expected a byte offset into the run's text, an integer from 0 to 13"},
        {R"("spans": [{"begin": 5, "end": 2}])", "scene: runs[0].spans[0]: ends before it begins"},
        {R"("spans": [{"end": 2}])", "scene: runs[0].spans[0]: the \"begin\" member is missing"},
        {R"("spans": [{"begin": 0, "end": 2, "colour": [1, 0, 0]}])",
         "scene: runs[0].spans[0]: unknown member \"colour\""},
        {R"("spans": [{"begin": 0, "end": 2, "font": 3}])",
         "scene: runs[0].spans[0].font: index 3 is out of range (the scene has 1 font)"},
        {R"("spans": [{"begin": 0, "end": 2, "letter_spacing": 10}])",
         "scene: runs[0].spans[0].letter_spacing: expected a number in [-9, 9], got 10"},
        {R"("spans": {"begin": 0})", "scene: runs[0].spans: expected an array of span objects"},
        {R"("features": {"toolong": 1})", "scene: runs[0].features.toolong: a feature tag is 1 to 4 printable"},
        {R"("features": {"liga": -1})", "scene: runs[0].features.liga: expected 0 (off), 1 (on)"},
        {R"("underline": 1)", "scene: runs[0].underline: expected true or false, got a number"},
        {R"("trimming": "both")",
         "scene: runs[0].trimming: expected one of \"none\", \"end\", \"start\", \"middle\", got \"both\""},
        {R"("max_lines": 1.5)", "scene: runs[0].max_lines: expected a whole number of lines"},
        {R"("tab_stops": [10, 5])", "scene: runs[0].tab_stops[1]: expected a number of pixels past the stop before it"},
        {R"("scale": 1000)", "scene: runs[0].scale: expected a number in [0.015625, 64], got 1000"},
    };
    for (const auto& c : cases) {
        const std::string message = fault(c.members);
        EXPECT_NE(message.find(c.message), std::string::npos) << c.members << "\n  got: " << message;
    }
}

TEST(Scene, MemberOrderDoesNotMatter) {
    auto a = parse_scene(R"({"fonts": ["a", "b"], "canvas": [9, 7], "layout": "bgr", "runs": [
        {"font": 1, "text": "t", "size": 3, "origin": [1, 2], "depth": 0.25}]})");
    auto b = parse_scene(R"({"runs": [{"depth": 0.25, "origin": [1, 2], "size": 3, "text": "t", "font": 1}],
        "layout": "bgr", "canvas": [9, 7], "fonts": ["a", "b"]})");
    ASSERT_TRUE(a) << a.error().message;
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_EQ(*a, *b);
}

TEST(Scene, BadScenesNameTheirFault) {
    const std::string nine_fonts = R"({"fonts": ["1","2","3","4","5","6","7","8","9"], "canvas": [8, 8], "runs": []})";
    const struct {
        std::string text;
        const char* fragment;
    } cases[] = {
        // The document.
        {"", "scene: line 1, column"},
        {"{\"fonts\": [\"a\"],\n \"canvas\": [1, 1]", "scene: line 2, column"},
        {R"({"fonts": ["a"], "fonts": ["b"], "canvas": [1, 1], "runs": []})", "scene: line 1"},  // duplicate
        {"[]", "scene: expected an object, got an array"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "runs": [], "colour": 1})",
         "scene: unknown member \"colour\" (known: fonts, canvas, background, layout, contrast, palette, runs)"},
        // fonts
        {R"({"canvas": [8, 8], "runs": []})", "scene: the \"fonts\" member is missing"},
        {R"({"fonts": "a.crisp", "canvas": [8, 8], "runs": []})", "scene: fonts: expected a non-empty array"},
        {R"({"fonts": [], "canvas": [8, 8], "runs": []})", "scene: fonts: expected a non-empty array"},
        {nine_fonts, "scene: fonts: at most 8 fonts, got 9"},
        {R"({"fonts": ["a", ""], "canvas": [8, 8], "runs": []})", "scene: fonts[1]: expected a non-empty path string"},
        {R"({"fonts": [1], "canvas": [8, 8], "runs": []})", "scene: fonts[0]: expected a non-empty path string"},
        {R"({"fonts": ["a\u0000b"], "canvas": [8, 8], "runs": []})", "scene: fonts[0]: expected a non-empty path"},
        // canvas
        {R"({"fonts": ["a"], "runs": []})", "scene: the \"canvas\" member is missing"},
        {R"({"fonts": ["a"], "canvas": [0, 8], "runs": []})",
         "scene: canvas: expected [width, height] integers from 1 to 16384"},
        {R"({"fonts": ["a"], "canvas": [8, 16385], "runs": []})", "scene: canvas: expected [width, height]"},
        {R"({"fonts": ["a"], "canvas": [8.5, 8], "runs": []})", "scene: canvas: expected [width, height]"},
        {R"({"fonts": ["a"], "canvas": [8], "runs": []})", "scene: canvas: expected [width, height]"},
        {R"({"fonts": ["a"], "canvas": [8, 8, 8], "runs": []})", "scene: canvas: expected [width, height]"},
        {R"({"fonts": ["a"], "canvas": ["8", 8], "runs": []})", "scene: canvas: expected [width, height]"},
        {R"({"fonts": ["a"], "canvas": "640x480", "runs": []})", "scene: canvas: expected [width, height]"},
        // background
        {R"({"fonts": ["a"], "canvas": [8, 8], "background": [1, 1], "runs": []})",
         "scene: background: expected [r, g, b] or [r, g, b, a]"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "background": [1, 1, 1, 1, 1], "runs": []})",
         "scene: background: expected [r, g, b] or [r, g, b, a]"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "background": [1, 1, 1, 2], "runs": []})",
         "scene: background[3]: expected a number from 0 to 1"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "background": [1, -0.01, 1], "runs": []})",
         "scene: background[1]: expected a number from 0 to 1"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "background": "white", "runs": []})",
         "scene: background: expected [r, g, b]"},
        // layout
        {R"({"fonts": ["a"], "canvas": [8, 8], "layout": 3, "runs": []})",
         "scene: layout: expected a subpixel preset name or a layout file path"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "layout": "", "runs": []})", "scene: layout: expected a subpixel"},
        // runs
        {R"({"fonts": ["a"], "canvas": [8, 8]})", "scene: the \"runs\" member is missing"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "runs": {}})",
         "scene: runs: expected an array of run objects, got an object"},
        {with_run("5"), "scene: runs[0]: expected an object, got a number"},
        {with_run(
             R"({"text": "a", "size": 9, "origin": [0, 0]}, {"text": "a", "size": 9, "origin": [0, 0], "colour": [0, 0, 0]})"),
         "scene: runs[1]: unknown member \"colour\" (known: font, text, size, origin, color, depth, contrast, "
         "palette, transform, weight, outline, shadow, glow, features, letter_spacing, baseline_shift, underline, "
         "strikethrough, skip_ink, spans, wrap_width, align, line_height, line_spacing, max_lines, trimming, scale, "
         "tab_stops)"},
        // runs[].font
        {with_run(R"({"font": -1, "text": "a", "size": 9, "origin": [0, 0]})"),
         "scene: runs[0].font: expected an index into fonts (an integer from 0)"},
        {with_run(R"({"font": 0.5, "text": "a", "size": 9, "origin": [0, 0]})"),
         "scene: runs[0].font: expected an index"},
        {with_run(R"({"font": "0", "text": "a", "size": 9, "origin": [0, 0]})"),
         "scene: runs[0].font: expected an index"},
        {with_run(R"({"font": 1, "text": "a", "size": 9, "origin": [0, 0]})"),
         "scene: runs[0].font: index 1 is out of range (the scene has 1 font)"},
        {with_run(R"({"font": 1e300, "text": "a", "size": 9, "origin": [0, 0]})"), "scene: runs[0].font: index 1e+300"},
        // runs[].text
        {with_run(R"({"size": 9, "origin": [0, 0]})"), "scene: runs[0]: the \"text\" member is missing"},
        {with_run(R"({"text": 5, "size": 9, "origin": [0, 0]})"),
         "scene: runs[0].text: expected a string, got a number"},
        // runs[].size
        {with_run(R"({"text": "a", "origin": [0, 0]})"), "scene: runs[0]: the \"size\" member is missing"},
        {with_run(R"({"text": "a", "size": "9", "origin": [0, 0]})"), "scene: runs[0].size: expected a number"},
        {with_run(R"({"text": "a", "size": 0, "origin": [0, 0]})"), "scene: runs[0].size: must be in (0, 4096]"},
        {with_run(R"({"text": "a", "size": -1, "origin": [0, 0]})"), "scene: runs[0].size: must be in (0, 4096]"},
        {with_run(R"({"text": "a", "size": 4096.001, "origin": [0, 0]})"), "scene: runs[0].size: must be in (0, 4096]"},
        {with_run(R"({"text": "a", "size": 1e-50, "origin": [0, 0]})"), "scene: runs[0].size: must be in (0, 4096]"},
        // runs[].origin
        {with_run(R"({"text": "a", "size": 9})"), "scene: runs[0]: the \"origin\" member is missing"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0]})"),
         "scene: runs[0].origin: expected [x, y], finite numbers"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, "1"]})"), "scene: runs[0].origin: expected [x, y]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [1e39, 0]})"), "scene: runs[0].origin: expected [x, y]"},
        {with_run(R"({"text": "a", "size": 9, "origin": {"x": 0, "y": 0}})"), "scene: runs[0].origin: expected [x, y]"},
        // runs[].color
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "color": [0, 0]})"),
         "scene: runs[0].color: expected [r, g, b] or [r, g, b, a]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "color": [0, 0, 255]})"),
         "scene: runs[0].color[2]: expected a number from 0 to 1"},
        // runs[].depth
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "depth": 1.5})"),
         "scene: runs[0].depth: expected a number from 0 (nearest) to 1 (farthest)"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "depth": -0.1})"), "scene: runs[0].depth: expected"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "depth": "near"})"), "scene: runs[0].depth: expected"},
        // palette, at the top level and in runs
        {R"({"fonts": ["a"], "canvas": [8, 8], "palette": 256, "runs": []})",
         "scene: palette: expected a palette index, an integer from 0 to 255"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "palette": "1", "runs": []})", "scene: palette: expected a palette"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "palette": 1.5})"),
         "scene: runs[0].palette: expected a palette index"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "palette": -1})"),
         "scene: runs[0].palette: expected a palette index"},
        // contrast, at the top level and in runs: the member's path and the value
        {R"({"fonts": ["a"], "canvas": [8, 8], "contrast": "linear", "runs": []})",
         "scene: contrast: expected an object, got a string"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "contrast": {"gama": 2}, "runs": []})",
         "scene: contrast: unknown member \"gama\" (known: mode, gamma, contrast, stem_darkening)"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "contrast": {"gamma": 0.5}, "runs": []})",
         "scene: contrast.gamma: 0.5 is not in [1, 4]"},
        {R"({"fonts": ["a"], "canvas": [8, 8], "contrast": {"mode": "srgb"}, "runs": []})",
         "scene: contrast.mode: expected \"linear\" or \"corrected\", got \"srgb\""},
        {R"({"fonts": ["a"], "canvas": [8, 8], "contrast": {"mode": 1}, "runs": []})",
         "scene: contrast.mode: expected \"linear\" or \"corrected\", got a number"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"gamma": 4.5}})"),
         "scene: runs[0].contrast.gamma: 4.5 is not in [1, 4]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"gamma": -2.2}})"),
         "scene: runs[0].contrast.gamma: -2.2 is not in [1, 4]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"gamma": "2.2"}})"),
         "scene: runs[0].contrast.gamma: expected a number in [1, 4], got a string"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"contrast": -0.25}})"),
         "scene: runs[0].contrast.contrast: -0.25 is not in [0, 4]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"contrast": 1e300}})"),
         "scene: runs[0].contrast.contrast: 1e+300 is not in [0, 4]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"stem_darkening": 5}})"),
         "scene: runs[0].contrast.stem_darkening: 5 is not in [0, 4]"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"stem_darkening": null}})"),
         "scene: runs[0].contrast.stem_darkening: expected a number in [0, 4], got null"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": []})"),
         "scene: runs[0].contrast: expected an object, got an array"},
        {with_run(R"({"text": "a", "size": 9, "origin": [0, 0], "contrast": {"mode": "linear", "level": 1}})"),
         "scene: runs[0].contrast: unknown member \"level\" (known: mode, gamma, contrast, stem_darkening)"},
    };
    for (const auto& c : cases) {
        auto scene = parse_scene(c.text);
        ASSERT_FALSE(scene) << c.text;
        EXPECT_EQ(scene.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(scene.error().message.find(c.fragment), std::string::npos)
            << "message: " << scene.error().message << "\nexpected: " << c.fragment;
    }
}

TEST(Scene, ContrastIsPerRunOverTheScenesDefault) {
    auto scene = parse_scene(R"({"fonts": ["a"], "canvas": [8, 8],
        "contrast": {"gamma": 1.8, "contrast": 0.5},
        "runs": [
            {"text": "a", "size": 9, "origin": [0, 0]},
            {"text": "b", "size": 9, "origin": [0, 0], "contrast": {"mode": "linear"}},
            {"text": "c", "size": 9, "origin": [0, 0], "contrast": {"gamma": 4, "stem_darkening": 1}},
            {"text": "d", "size": 9, "origin": [0, 0], "contrast": {}}
        ]})");
    ASSERT_TRUE(scene) << scene.error().message;
    const TextContrast defaults{ContrastMode::corrected, 1.8f, 0.5f, 0.0f};
    EXPECT_EQ(scene->contrast, defaults);
    ASSERT_EQ(scene->runs.size(), 4u);
    EXPECT_EQ(scene->runs[0].contrast, defaults);  // none of its own: the scene's
    EXPECT_EQ(scene->runs[1].contrast, (TextContrast{ContrastMode::linear, 1.8f, 0.5f, 0.0f}));
    EXPECT_EQ(scene->runs[2].contrast, (TextContrast{ContrastMode::corrected, 4.0f, 0.5f, 1.0f}));
    EXPECT_EQ(scene->runs[3].contrast, defaults);
    for (const SceneRun& run : scene->runs) EXPECT_TRUE(validate_text_contrast(*run.contrast)) << run.text;
}

TEST(Scene, ContrastLeftOutIsTheDrawersAndTextContrastsDefaultsFillARun) {
    auto scene = parse_scene(R"({"fonts": ["a"], "canvas": [8, 8], "runs": [
        {"text": "a", "size": 9, "origin": [0, 0]},
        {"text": "b", "size": 9, "origin": [0, 0], "contrast": {"stem_darkening": 0.5}},
        {"text": "c", "size": 9, "origin": [0, 0], "contrast": {"mode": "corrected", "gamma": 1, "contrast": 0,
                                                                "stem_darkening": 0}}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_FALSE(scene->contrast);
    EXPECT_FALSE(scene->runs[0].contrast);
    TextContrast darkened;
    darkened.stem_darkening = 0.5f;
    EXPECT_EQ(scene->runs[1].contrast, darkened);  // gamma 2.2, contrast 0, corrected
    EXPECT_EQ(scene->runs[2].contrast, (TextContrast{ContrastMode::corrected, 1.0f, 0.0f, 0.0f}));
    // The ends of each range are in it.
    EXPECT_TRUE(parse_scene(with_run(R"({"text": "a", "size": 9, "origin": [0, 0],
        "contrast": {"gamma": 4, "contrast": 4, "stem_darkening": 4}})")));
}

TEST(Scene, TheFirstContrastFaultIsTheScenesThenTheRunsInOrder) {
    auto scene = parse_scene(R"({"runs": [{"text": "a", "size": 9, "origin": [0, 0], "contrast": {"gamma": 0}}],
        "contrast": {"stem_darkening": -1, "gamma": 9}, "fonts": ["a"], "canvas": [8, 8]})");
    ASSERT_FALSE(scene);
    EXPECT_EQ(scene.error().message, "scene: contrast.gamma: 9 is not in [1, 4]");
}

TEST(Scene, TheThirdRunsFaultNamesItsIndex) {
    auto scene = parse_scene(R"({"fonts": ["a"], "canvas": [8, 8], "runs": [
        {"text": "a", "size": 9, "origin": [0, 0]}, {"text": "b", "size": 9, "origin": [0, 0]},
        {"text": "c", "size": 5000, "origin": [0, 0]}]})");
    ASSERT_FALSE(scene);
    EXPECT_EQ(scene.error().message, "scene: runs[2].size: must be in (0, 4096]");
}

class SceneFile : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("crisp_scene_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_ / "scenes");
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path dir_;
};

TEST_F(SceneFile, RelativeFontPathsAreResolvedAgainstTheScenesDirectory) {
    const std::filesystem::path absolute = dir_ / "elsewhere" / "c.crisp";
    std::ofstream(dir_ / "scenes" / "scene.json") << R"({"fonts": ["a.crisp", "sub/b.crisp", "../up.crisp", )"
                                                  << "\"" << absolute.generic_string() << "\""
                                                  << R"(], "canvas": [8, 8], "layout": "my-layout.json", "runs": []})";
    auto scene = load_scene_file(dir_ / "scenes" / "scene.json");
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->fonts.size(), 4u);
    EXPECT_EQ(scene->fonts[0], (dir_ / "scenes" / "a.crisp").string());
    EXPECT_EQ(scene->fonts[1], (dir_ / "scenes" / "sub/b.crisp").string());
    EXPECT_EQ(scene->fonts[2], (dir_ / "scenes" / "../up.crisp").string());
    EXPECT_EQ(scene->fonts[3], absolute.generic_string());  // absolute: kept
    EXPECT_EQ(scene->layout, "my-layout.json");             // kept as written
    // parse_scene alone keeps every path as written.
    EXPECT_EQ(parse_scene(R"({"fonts": ["a.crisp"], "canvas": [8, 8], "runs": []})")->fonts[0], "a.crisp");
}

TEST_F(SceneFile, UnreadableAndBadFilesNameThePath) {
    auto missing = load_scene_file(dir_ / "missing.json");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::io);
    EXPECT_NE(missing.error().message.find("missing.json"), std::string::npos) << missing.error().message;
    auto directory = load_scene_file(dir_ / "scenes");
    ASSERT_FALSE(directory);
    EXPECT_EQ(directory.error().code, ErrorCode::io);
    std::ofstream(dir_ / "bad.json") << R"({"fonts": ["a"], "canvas": [0, 0], "runs": []})";
    auto bad = load_scene_file(dir_ / "bad.json");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::invalid_argument);
    EXPECT_EQ(bad.error().message,
              (dir_ / "bad.json").string() + ": scene: canvas: expected [width, height] integers from 1 to 16384");
}

TEST(Scene, TenThousandRunsParse) {
    constexpr size_t kRuns = 10000;
    std::string text = R"({"fonts": ["a", "b", "c"], "canvas": [1920, 1080], "runs": [)";
    for (size_t i = 0; i < kRuns; ++i) {
        if (i) text += ",\n";
        text += R"({"font": )" + std::to_string(i % 3) + R"(, "text": "run )" + std::to_string(i) + R"(", "size": )" +
                std::to_string(8 + i % 64) + R"(, "origin": [)" + std::to_string(i % 1920) + ", " +
                std::to_string(i / 10) + R"(], "color": [0.5, 0.25, 1], "depth": 0.75})";
    }
    text += "]}";
    auto scene = parse_scene(text);
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->runs.size(), kRuns);
    for (const size_t i : {size_t{0}, size_t{4321}, kRuns - 1}) {
        const SceneRun& run = scene->runs[i];
        EXPECT_EQ(run.font, i % 3);
        EXPECT_EQ(run.text, "run " + std::to_string(i));
        EXPECT_EQ(run.size, static_cast<float>(8 + i % 64));
        EXPECT_EQ(run.origin_x, static_cast<float>(i % 1920));
        EXPECT_EQ(run.origin_y, static_cast<float>(i / 10));
        EXPECT_EQ(run.depth, 0.75f);
    }
}

}  // namespace
}  // namespace crisp
