#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace crisp {
namespace {

TEST(Subpixel, EveryPresetIsValidAndRoundTripsThroughJson) {
    for (const std::string_view name : subpixel_preset_names()) {
        auto layout = subpixel_preset(name);
        ASSERT_TRUE(layout) << name;
        EXPECT_EQ(layout->name, name);
        EXPECT_TRUE(validate_subpixel_layout(*layout)) << name;
        auto parsed = parse_subpixel_layout(subpixel_layout_to_json(*layout));
        ASSERT_TRUE(parsed) << parsed.error().message;
        EXPECT_EQ(*parsed, *layout);
    }
    EXPECT_FALSE(subpixel_preset("crt"));
}

TEST(Subpixel, PresetsHaveTheirGeometry) {
    const SubpixelLayout rgb = *subpixel_preset("rgb");
    EXPECT_LT(rgb.channels[0].x1, rgb.channels[1].x1);  // red left of green
    EXPECT_LT(rgb.channels[1].x1, rgb.channels[2].x1);
    EXPECT_TRUE(shares_sample_rows(rgb));
    const SubpixelLayout bgr = *subpixel_preset("bgr");
    EXPECT_EQ(bgr.channels[0], rgb.channels[2]);
    const SubpixelLayout vrgb = *subpixel_preset("vrgb");
    EXPECT_FALSE(shares_sample_rows(vrgb));
    EXPECT_LT(vrgb.channels[0].y1, vrgb.channels[2].y1);  // red above blue (y down)
    const SubpixelLayout triad = *subpixel_preset("qd-oled");
    EXPECT_LT(triad.channels[1].y1, triad.channels[0].y1);  // green above red
    EXPECT_TRUE(shares_sample_rows(*subpixel_preset("gray")));
}

TEST(Subpixel, ParsesCustomLayoutsThatOverlapAndReachPastThePixel) {
    auto layout = parse_subpixel_layout(
        R"({"name": "mine", "r": [-0.25, 0, 0.5, 1], "g": [0.2, -0.1, 0.8, 1.1], "b": [0.5, 0, 1.25, 1]})");
    ASSERT_TRUE(layout) << layout.error().message;
    EXPECT_EQ(layout->name, "mine");
    EXPECT_EQ(layout->channels[0].x0, -0.25f);
    EXPECT_EQ(layout->channels[2].x1, 1.25f);
    EXPECT_TRUE(parse_subpixel_layout(R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1]})"));  // name optional
}

TEST(Subpixel, BadLayoutsNameTheirFault) {
    const struct {
        const char* text;
        const char* fragment;
    } cases[] = {
        {"[]", "expected an object"},
        {R"({"r": [0,0,1,1], "g": [0,0,1,1]})", "\"b\" rectangle is missing"},
        {R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1]})", "b: expected [x0, y0, x1, y1]"},
        {R"({"r": [0,0,1,1], "g": [0,"x",1,1], "b": [0,0,1,1]})", "g[1]: expected a number"},
        {R"({"r": [0.5,0,0.5,1], "g": [0,0,1,1], "b": [0,0,1,1]})", "channel r: needs x0 < x1"},
        {R"({"r": [0,0,1,1], "g": [0,0,3,1], "b": [0,0,1,1]})", "channel g: reaches more than 1 pixel"},
        {R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1], "w": [0,0,1,1]})", "unknown member \"w\""},
        {R"({"name": 5, "r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1]})", "name: expected a string"},
        {R"({"r": [0,0,1,1e300], "g": [0,0,1,1], "b": [0,0,1,1]})", "r[3]: expected a number"},
        {"{\"r\": [0,0,1,1],\n \"g\": [0,0,1,1]", "line 2, column"},
    };
    for (const auto& c : cases) {
        auto layout = parse_subpixel_layout(c.text);
        ASSERT_FALSE(layout) << c.text;
        EXPECT_NE(layout.error().message.find(c.fragment), std::string::npos) << layout.error().message;
    }
}

TEST(Subpixel, PresetsCarryNoContrastAndSaveAsBeforeContrastExisted) {
    // The bytes subpixel_layout_to_json wrote before layouts could carry contrast settings.
    EXPECT_EQ(subpixel_layout_to_json(*subpixel_preset("rgb")),
              "{\"name\": \"rgb\", \"r\": [0, 0, 0.3333333432674408, 1], \"g\": [0.3333333432674408, 0, "
              "0.6666666865348816, 1], \"b\": [0.6666666865348816, 0, 1, 1]}\n");
    for (const std::string_view name : subpixel_preset_names()) {
        EXPECT_FALSE(subpixel_preset(name)->contrast) << name;
        EXPECT_EQ(subpixel_layout_to_json(*subpixel_preset(name)).find("contrast"), std::string::npos) << name;
    }
    auto parsed = parse_subpixel_layout(R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1]})");
    ASSERT_TRUE(parsed);
    EXPECT_FALSE(parsed->contrast);
}

TEST(Subpixel, ContrastRoundTripsThroughJson) {
    SubpixelLayout layout = *subpixel_preset("bgr");
    layout.name = "my-monitor";
    layout.contrast = TextContrast{ContrastMode::corrected, 1.8f, 0.5f, 1.25f};
    const std::string json = subpixel_layout_to_json(layout);
    EXPECT_NE(json.find(R"("contrast": {"mode": "corrected", "gamma": 1.8, "contrast": 0.5, "stem_darkening": 1.25})"),
              std::string::npos)
        << json;
    auto parsed = parse_subpixel_layout(json);
    ASSERT_TRUE(parsed) << parsed.error().message;
    EXPECT_EQ(*parsed, layout);
    layout.contrast = TextContrast{ContrastMode::linear, 2.2f, 0.0f, 0.0f};
    parsed = parse_subpixel_layout(subpixel_layout_to_json(layout));
    ASSERT_TRUE(parsed);
    EXPECT_EQ(*parsed, layout);
    // Members left out take TextContrast's defaults.
    parsed = parse_subpixel_layout(R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1], "contrast": {"gamma": 2}})");
    ASSERT_TRUE(parsed) << parsed.error().message;
    ASSERT_TRUE(parsed->contrast);
    EXPECT_EQ(*parsed->contrast, (TextContrast{ContrastMode::corrected, 2.0f, 0.0f, 0.0f}));
    parsed = parse_subpixel_layout(R"({"r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1], "contrast": {}})");
    ASSERT_TRUE(parsed);
    EXPECT_EQ(parsed->contrast, TextContrast{});
}

TEST(Subpixel, BadContrastNamesItsField) {
    const std::string rects = R"("r": [0,0,1,1], "g": [0,0,1,1], "b": [0,0,1,1])";
    const struct {
        const char* contrast;
        const char* fragment;
    } cases[] = {
        {"5", "contrast: expected an object"},
        {R"({"mode": "srgb"})", "contrast.mode: expected \"linear\" or \"corrected\""},
        {R"({"mode": 1})", "contrast.mode: expected"},
        {R"({"gamma": "2.2"})", "contrast.gamma: expected a number"},
        {R"({"stem_darkening": 1e300})", "contrast.stem_darkening: expected a number"},
        {R"({"level": 1})", "contrast: unknown member \"level\""},
        {R"({"gamma": 0.5})", "contrast: gamma 0.500000 is not in [1, 4]"},
        {R"({"contrast": -1})", "contrast: contrast -1.000000 is not in [0, 4]"},
        {R"({"stem_darkening": 4.5})", "contrast: stem_darkening 4.500000 is not in [0, 4]"},
    };
    for (const auto& c : cases) {
        auto layout = parse_subpixel_layout("{" + rects + ", \"contrast\": " + c.contrast + "}");
        ASSERT_FALSE(layout) << c.contrast;
        EXPECT_EQ(layout.error().code, ErrorCode::invalid_argument);
        EXPECT_NE(layout.error().message.find(c.fragment), std::string::npos) << layout.error().message;
    }
    SubpixelLayout layout = *subpixel_preset("rgb");
    layout.contrast = TextContrast{ContrastMode::corrected, std::nanf(""), 0.0f, 0.0f};
    Status status = validate_subpixel_layout(layout);
    ASSERT_FALSE(status);
    EXPECT_NE(status.error().message.find("subpixel layout: contrast: gamma nan"), std::string::npos)
        << status.error().message;
    const std::filesystem::path path = std::filesystem::temp_directory_path() / "crisp_subpixel_bad_contrast.json";
    std::filesystem::remove(path);
    EXPECT_FALSE(save_subpixel_layout_file(layout, path));
    EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(Subpixel, FilesSaveLoadAndResolve) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crisp_subpixel_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const SubpixelLayout triad = *subpixel_preset("qd-oled");
    ASSERT_TRUE(save_subpixel_layout_file(triad, dir / "triad.json"));
    auto loaded = load_subpixel_layout_file(dir / "triad.json");
    ASSERT_TRUE(loaded);
    EXPECT_EQ(*loaded, triad);
    auto resolved = resolve_subpixel_layout((dir / "triad.json").string());
    ASSERT_TRUE(resolved);
    EXPECT_EQ(*resolved, triad);
    EXPECT_EQ(resolve_subpixel_layout("bgr")->name, "bgr");
    auto missing = resolve_subpixel_layout((dir / "missing.json").string());
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::io);
    std::ofstream(dir / "bad.json") << "{\"r\": [0,0,1,1]}";
    auto bad = load_subpixel_layout_file(dir / "bad.json");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("bad.json"), std::string::npos);
    SubpixelLayout invalid = triad;
    invalid.channels[0].x1 = -5.0f;
    EXPECT_FALSE(save_subpixel_layout_file(invalid, dir / "invalid.json"));
    EXPECT_FALSE(std::filesystem::exists(dir / "invalid.json"));
    SubpixelLayout monitor = triad;
    monitor.contrast = TextContrast{ContrastMode::corrected, 2.4f, 1.0f, 0.0f};
    ASSERT_TRUE(save_subpixel_layout_file(monitor, dir / "monitor.json"));
    auto monitor_loaded = resolve_subpixel_layout((dir / "monitor.json").string());
    ASSERT_TRUE(monitor_loaded) << monitor_loaded.error().message;
    EXPECT_EQ(*monitor_loaded, monitor);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace crisp
