// Scene files: what crisp-render's --scene draws, many runs of text in several fonts on one canvas.
//
//     {"fonts": ["a.crisp"], "canvas": [640, 200], "background": [1, 1, 1],
//      "runs": [{"text": "Hello", "size": 48, "origin": [20, 80], "color": [0, 0, 0, 1]}]}
//
// docs/scene-format.md describes every member, its default and its limits. Safe for untrusted
// input: every fault is ErrorCode::invalid_argument with a message that names the member's path
// ("scene: runs[2].size: must be in (0, 4096]"); a parsed Scene always satisfies the limits.
#pragma once

#include <crisp/contrast.hpp>
#include <crisp/effects.hpp>
#include <crisp/layout.hpp>
#include <crisp/result.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace crisp {

// Limits a parsed scene keeps; docs/scene-format.md explains each.
inline constexpr uint32_t kMaxSceneFonts = 8;        // a fallback chain of at most 8 faces
inline constexpr uint32_t kMaxSceneCanvas = 16384;   // crisp-render's --canvas limit, per side
inline constexpr float kMaxSceneTextSize = 4096.0f;  // pixels per em, crisp-render's --size limit
// Runs one scene may hold (docs/limits.md): a screen of UI text is hundreds.
inline constexpr uint32_t kMaxSceneRuns = 65536;

// Spans one run may hold: a paragraph with a style change every few words is hundreds.
inline constexpr uint32_t kMaxSceneSpans = 65536;

// An OpenType feature of a run or span: "features": {"liga": 0, "smcp": 1}.
struct SceneFeature {
    std::array<char, 4> tag{' ', ' ', ' ', ' '};  // 1 to 4 printable ASCII characters, padded with spaces
    uint32_t value = 1;                           // 0 off, 1 on, or an alternate's index, up to 65535
    friend bool operator==(const SceneFeature&, const SceneFeature&) = default;
};

// What a run or span styles beyond its font, size, colour and palette (crisp::TextStyle).
struct SceneTextStyle {
    std::vector<SceneFeature> features;
    float letter_spacing = 0.0f;  // pixels, within the size either way
    float baseline_shift = 0.0f;  // pixels up, within four sizes either way
    bool underline = false;
    bool strikethrough = false;
    bool skip_ink = true;
    friend bool operator==(const SceneTextStyle&, const SceneTextStyle&) = default;
};

// A styled byte range of a run's text (crisp::TextSpan): the members it gives over the run's.
struct SceneSpan {
    uint32_t begin = 0, end = 0;  // bytes of the run's text, on code point boundaries, in order, not overlapping
    uint32_t font = 0;            // index into Scene::fonts: that font first, the others as fallbacks
    float size = 0.0f;
    float color[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    uint32_t palette = 0;
    SceneTextStyle style;
    friend bool operator==(const SceneSpan&, const SceneSpan&) = default;
};

struct SceneRun {
    uint32_t font = 0;                          // index into Scene::fonts
    std::string text;                           // UTF-8, valid (the JSON reader checks it); may be empty
    float size = 0.0f;                          // pixels per em, in (0, kMaxSceneTextSize]
    float origin_x = 0.0f, origin_y = 0.0f;     // pen position on the baseline, canvas pixels, y down
    float color[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // sRGB-encoded, straight alpha, each in [0, 1]
    float depth = 0.5f;                         // in [0, 1]; smaller is nearer, as Vulkan's depth
    // How the run's coverage is blended (DrawOptions::contrast): its own "contrast" member over the
    // scene's, field by field; nullopt where neither says, for the drawer's default.
    std::optional<TextContrast> contrast;
    // CPAL palette of its colour glyphs (TextStyle::palette): its own "palette" or the scene's.
    uint32_t palette = 0;
    // The 2x2 linear part of a transform applied about the run's origin (y down: x' = a x + b y,
    // y' = c x + d y; DrawOptions::transform): "transform": [a, b, c, d]. nullopt: none.
    std::optional<std::array<float, 4>> transform;
    // Its effects (DrawOptions::effects): "weight" (pixels), "outline" {"width", "placement",
    // "join", "miter_limit", "color"}, "shadow" {"offset": [dx, dy], "color", "blur"} and "glow"
    // {"radius", "color"}; nullopt: none.
    std::optional<TextEffects> effects;
    SceneTextStyle style;          // "features", "letter_spacing", "baseline_shift", "underline", ...
    std::vector<SceneSpan> spans;  // "spans": at most kMaxSceneSpans
    // The paragraph (crisp::LayoutOptions): "wrap_width", "align", "line_height", "line_spacing",
    // "max_lines", "trimming", "scale", "tab_stops".
    float wrap_width = 0.0f;
    Align align = Align::left;
    float line_height = 0.0f;
    float line_spacing = 1.0f;
    uint32_t max_lines = 0;
    Trimming trimming = Trimming::none;
    float scale = 1.0f;
    std::vector<float> tab_stops;
    friend bool operator==(const SceneRun&, const SceneRun&) = default;
};

struct Scene {
    std::vector<std::string> fonts;                  // 1..kMaxSceneFonts asset paths, none empty
    uint32_t width = 0, height = 0;                  // each in 1..kMaxSceneCanvas
    float background[4] = {1.0f, 1.0f, 1.0f, 1.0f};  // sRGB-encoded, straight alpha, each in [0, 1]
    std::string layout = "rgb";                      // a subpixel preset name or a layout file path
    std::optional<TextContrast> contrast;            // the runs' default, as written; valid
    uint32_t palette = 0;                            // the runs' default palette, below kMaxPalettes
    std::vector<SceneRun> runs;                      // drawn in this (file) order
    friend bool operator==(const Scene&, const Scene&) = default;
};

// Parses a scene. Font and layout paths are kept as written. Syntax errors name their line and
// column; all faults are ErrorCode::invalid_argument with a message starting "scene: ".
Result<Scene> parse_scene(std::string_view json);

// Reads and parses a scene file; relative font paths become paths relative to the scene file's
// directory (absolute ones are kept; the layout string is kept as written). An unreadable file is
// ErrorCode::io; every message names the path.
Result<Scene> load_scene_file(const std::filesystem::path& path);

}  // namespace crisp
