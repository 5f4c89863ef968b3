// crisp: subpixel layouts, the sample area of each colour channel within a pixel.
//
// A layout is one rectangle per channel (red, green, blue) in pixel units relative to the pixel's
// top-left corner, y down. Rectangles may overlap and may reach up to kGlyphPadding pixels past
// the pixel (light bleeds into neighbouring pixels). The rasterizer places each channel's samples
// in its rectangle, so fitting the rectangles to a monitor's real subpixels is what subpixel
// anti-aliasing fitted to that monitor means. The library, crisp-render and the layout editor
// share the JSON form:
//
//     {"name": "rgb", "r": [0, 0, 0.333, 1], "g": [0.333, 0, 0.667, 1], "b": [0.667, 0, 1, 1]}
//
// A layout file may also carry the monitor's contrast settings (TextContrast), every member
// optional, the rest taking TextContrast's defaults:
//
//     "contrast": {"mode": "corrected", "gamma": 2.2, "contrast": 0.5, "stem_darkening": 0}
//
// The renderer samples with the rectangles only: RendererCreateInfo::contrast and
// Renderer::set_contrast() decide how text is composited. Tools that read a layout file
// (crisp-render --layout, the layout editor) draw with the file's contrast unless told otherwise.
#pragma once

#include <crisp/export.hpp>

#include <crisp/contrast.hpp>
#include <crisp/result.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace crisp {

struct SampleRect {
    float x0 = 0.0f, y0 = 0.0f, x1 = 1.0f, y1 = 1.0f;
    friend bool operator==(const SampleRect&, const SampleRect&) = default;
};

struct SubpixelLayout {
    std::string name;
    std::array<SampleRect, 3> channels;  // red, green, blue
    // The monitor's contrast settings, when its layout file gives them; none in the presets.
    std::optional<TextContrast> contrast;
    friend bool operator==(const SubpixelLayout&, const SubpixelLayout&) = default;
};

// The preset names: gray, rgb, bgr, vrgb, vbgr, qd-oled, woled, pentile (docs/subpixel.md
// describes each).
CRISP_API std::span<const std::string_view> subpixel_preset_names();

// A preset by name; an unknown name is ErrorCode::invalid_argument listing the known ones.
CRISP_API Result<SubpixelLayout> subpixel_preset(std::string_view name);

// Checks a layout: every coordinate finite, x0 < x1 and y0 < y1, and every rectangle within
// [-kGlyphPadding, 1 + kGlyphPadding], and the contrast settings, when given, pass
// validate_text_contrast(). Returns ErrorCode::invalid_argument naming the fault.
CRISP_API Status validate_subpixel_layout(const SubpixelLayout& layout);

// Parses the JSON form; "name" is optional. Safe for untrusted input: syntax errors name their
// line and column, other faults name the member ("g[2]: ..."); all are ErrorCode::invalid_argument.
CRISP_API Result<SubpixelLayout> parse_subpixel_layout(std::string_view json);

// Reads and parses a layout file (ErrorCode::io when unreadable; messages name the path).
CRISP_API Result<SubpixelLayout> load_subpixel_layout_file(const std::filesystem::path& path);

// The JSON form of a layout (one line, numbers in their shortest exact form). A layout without
// contrast settings is written as before they existed.
CRISP_API std::string subpixel_layout_to_json(const SubpixelLayout& layout);

// Writes the JSON form atomically, as save_asset_file writes an asset. The layout must be valid.
CRISP_API Status save_subpixel_layout_file(const SubpixelLayout& layout, const std::filesystem::path& path);

// A preset name, or else a layout file: what crisp-render's --layout takes.
CRISP_API Result<SubpixelLayout> resolve_subpixel_layout(std::string_view name_or_path);

// True when all three channels sample the same rows (equal y0 and y1): stripe layouts, where one
// set of ray roots serves the three channels.
CRISP_API bool shares_sample_rows(const SubpixelLayout& layout);

}  // namespace crisp
