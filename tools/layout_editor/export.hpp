// crisp-layout-editor: a subpixel layout in the forms other software reads (--export), fontconfig's
// rgba and lcdfilter, and FreeType's FT_Library_SetLcdGeometry sample positions.
// No window, no GPU: tests/test_layout_editor_model.cpp checks it directly.
#pragma once

#include <crisp/subpixel.hpp>

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace crisp::editor {

enum class ExportForm : uint8_t { fontconfig, freetype };

// The forms by name ("fontconfig", "freetype"), in the order --help lists them.
std::span<const std::string_view> export_form_names();
// The form named `name`; nullopt for any other name.
std::optional<ExportForm> export_form(std::string_view name);

struct Exported {
    // What goes on stdout: the form's text, with the notes also in it as comments.
    std::string text;
    // What the form cannot express of the layout (a triangle arrangement, per-channel heights,
    // the contrast settings), one sentence each.
    std::vector<std::string> notes;
};

// fontconfig's rgba constant for the layout: rgb or bgr where the three rectangles are side by
// side left to right in that order, sharing some rows; vrgb or vbgr where they are stacked top
// to bottom; none for gray (three equal rectangles) and for every other arrangement, with a note.
std::string fontconfig_rgba(const SubpixelLayout& layout, std::vector<std::string>& notes);

// FreeType's subpixel positions: the red, green and blue rectangles' centres as offsets from the
// pixel's centre in 1/64 pixel, rounded, y up (FreeType's outline axes; crisp's layouts run y
// down), as FT_Library_SetLcdGeometry takes them.
std::array<std::array<long, 2>, 3> freetype_lcd_geometry(const SubpixelLayout& layout);

// The layout in `form`. Any layout (validated or not) gives a form: what it cannot express is a
// note, never a failure.
Exported export_layout(const SubpixelLayout& layout, ExportForm form);

}  // namespace crisp::editor
