// The layout editor's model (tools/layout_editor/editor_model.hpp): edits, bounds, undo and redo,
// the monitor's contrast settings, and the --export forms (export.hpp), without a window.
#include "editor_model.hpp"
#include "export.hpp"

#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace {

using crisp::ContrastMode;
using crisp::SampleRect;
using crisp::SubpixelLayout;
using crisp::TextContrast;
using crisp::editor::ContrastParameter;
using crisp::editor::Handle;
using crisp::editor::kEditStep;
using crisp::editor::kMinRectSize;
using crisp::editor::LayoutModel;

SubpixelLayout preset(const char* name) {
    return *crisp::subpixel_preset(name);
}

TEST(LayoutEditorModel, DragMovesOneEdgeSnappedToTheStepAsOneUndoStep) {
    LayoutModel model(preset("rgb"));
    const uint64_t revision = model.revision();
    model.begin_drag(2, Handle::left);
    model.drag_to(-0.05f, 0.4f);           // the vertical part is ignored by a left edge
    model.drag_to(-10.3f * kEditStep, 0);  // snapped to -10 steps
    model.end_drag();
    const SampleRect b = model.layout().channels[2];
    EXPECT_FLOAT_EQ(b.x0, 2.0f / 3.0f - 10 * kEditStep);
    EXPECT_FLOAT_EQ(b.x1, 1.0f);
    EXPECT_FLOAT_EQ(b.y0, 0.0f);
    EXPECT_FLOAT_EQ(b.y1, 1.0f);
    EXPECT_EQ(model.selected(), 2);
    EXPECT_GT(model.revision(), revision);
    EXPECT_EQ(model.layout().name, "rgb-edited");
    EXPECT_TRUE(model.modified());
    ASSERT_TRUE(model.undo());
    EXPECT_EQ(model.layout(), preset("rgb"));
    EXPECT_FALSE(model.undo());  // the whole drag was one step
    ASSERT_TRUE(model.redo());
    EXPECT_FLOAT_EQ(model.layout().channels[2].x0, 2.0f / 3.0f - 10 * kEditStep);
}

TEST(LayoutEditorModel, DragStopsAtTheBoundsAndTheMinimumSize) {
    LayoutModel model(preset("rgb"));
    model.begin_drag(0, Handle::right);
    model.drag_to(-5.0f, 0);  // past the left edge: stops kMinRectSize from it
    EXPECT_FLOAT_EQ(model.layout().channels[0].x1, kMinRectSize);
    model.drag_to(+9.0f, 0);  // past the padding
    EXPECT_FLOAT_EQ(model.layout().channels[0].x1, 1.0f + crisp::kGlyphPadding);
    model.end_drag();
    model.begin_drag(1, Handle::body);
    model.drag_to(-7.0f, 7.0f);  // the whole rectangle, its size kept
    model.end_drag();
    const SampleRect g = model.layout().channels[1];
    EXPECT_FLOAT_EQ(g.x0, -static_cast<float>(crisp::kGlyphPadding));
    EXPECT_NEAR(g.x1 - g.x0, 1.0f / 3.0f, 1e-6f);
    EXPECT_FLOAT_EQ(g.y1, 1.0f + crisp::kGlyphPadding);
    EXPECT_TRUE(crisp::validate_subpixel_layout(model.layout()).ok());
}

TEST(LayoutEditorModel, NudgeMovesTheSelectedRectangleOneStep) {
    LayoutModel model(preset("vrgb"));
    model.select(1);
    model.nudge(-1, 0);
    model.nudge(0, 2);
    const SampleRect g = model.layout().channels[1];
    EXPECT_FLOAT_EQ(g.x0, -kEditStep);
    EXPECT_FLOAT_EQ(g.x1, 1.0f - kEditStep);
    EXPECT_FLOAT_EQ(g.y0, 1.0f / 3.0f + 2 * kEditStep);
    ASSERT_TRUE(model.undo());
    ASSERT_TRUE(model.undo());
    EXPECT_EQ(model.layout(), preset("vrgb"));
    model.select(7);  // ignored
    EXPECT_EQ(model.selected(), 1);
}

TEST(LayoutEditorModel, TypedNumbersAreValidatedByCrisp) {
    LayoutModel model(preset("rgb"));
    EXPECT_TRUE(model.set_coordinate(0, 3, 0.5f).ok());
    EXPECT_FLOAT_EQ(model.layout().channels[0].y1, 0.5f);
    const SubpixelLayout before = model.layout();
    const crisp::Status inverted = model.set_coordinate(0, 1, 0.75f);  // y0 past y1
    ASSERT_FALSE(inverted.ok());
    EXPECT_NE(inverted.error().message.find("channel r"), std::string::npos) << inverted.error().message;
    EXPECT_FALSE(model.set_coordinate(1, 0, -3.0f).ok());  // past the padding
    EXPECT_EQ(model.layout(), before);
    EXPECT_FALSE(model.set_coordinate(3, 0, 0.0f).ok());
}

TEST(LayoutEditorModel, PresetsAndLoadsAreUndoableAndAnEditClearsRedo) {
    LayoutModel model(preset("rgb"));
    EXPECT_TRUE(model.apply_preset("pentile").ok());
    EXPECT_EQ(model.layout(), preset("pentile"));
    EXPECT_FALSE(model.apply_preset("no-such").ok());
    SubpixelLayout bad = preset("rgb");
    bad.channels[2].x1 = -0.5f;
    EXPECT_FALSE(model.replace(bad).ok());
    EXPECT_EQ(model.layout(), preset("pentile"));
    ASSERT_TRUE(model.undo());
    EXPECT_EQ(model.layout(), preset("rgb"));
    EXPECT_TRUE(model.can_redo());
    model.nudge(1, 0);
    EXPECT_FALSE(model.can_redo());
    model.mark_saved();
    EXPECT_FALSE(model.modified());
}

TEST(LayoutEditorModel, ContrastStepsWithinItsRangeAsUndoableEditsOfTheLayout) {
    LayoutModel model(preset("rgb"));
    EXPECT_FALSE(model.layout().contrast);
    EXPECT_EQ(model.contrast(), TextContrast{});  // crisp's default until the layout has its own
    const uint64_t revision = model.revision();
    model.step_contrast(ContrastParameter::gamma, 1);
    ASSERT_TRUE(model.layout().contrast);
    EXPECT_EQ(model.layout().contrast->gamma, 2.3f);  // the float nearest 2.3, not 2.2f + 0.1f
    EXPECT_EQ(model.layout().channels, preset("rgb").channels);
    EXPECT_GT(model.revision(), revision);
    EXPECT_EQ(model.layout().name, "rgb-edited");
    EXPECT_TRUE(model.modified());
    model.step_contrast(ContrastParameter::gamma, -100);
    EXPECT_EQ(model.contrast().gamma, 1.0f);  // stops at the range
    model.step_contrast(ContrastParameter::contrast, 3);
    model.step_contrast(ContrastParameter::stem_darkening, -1);  // already at 0: no change, no step
    EXPECT_FLOAT_EQ(model.contrast().contrast, 0.3f);
    EXPECT_EQ(model.contrast().stem_darkening, 0.0f);
    model.toggle_contrast_mode();
    EXPECT_EQ(model.contrast().mode, ContrastMode::linear);
    EXPECT_TRUE(crisp::validate_subpixel_layout(model.layout()).ok());
    ASSERT_TRUE(model.undo());  // the mode
    ASSERT_TRUE(model.undo());  // contrast
    EXPECT_EQ(model.contrast().contrast, 0.0f);
    ASSERT_TRUE(model.undo());  // gamma down
    ASSERT_TRUE(model.undo());  // gamma up
    EXPECT_FALSE(model.can_undo());
    EXPECT_EQ(model.layout(), preset("rgb"));
}

TEST(LayoutEditorModel, TypedContrastIsValidatedByCrispAndResetDropsIt) {
    SubpixelLayout start = preset("bgr");
    start.name = "monitor";
    start.contrast = TextContrast{ContrastMode::corrected, 1.8f, 0.5f, 0.0f};
    LayoutModel model(start);
    EXPECT_EQ(model.contrast().gamma, 1.8f);  // the layout's own
    EXPECT_TRUE(model.set_contrast_parameter(ContrastParameter::stem_darkening, 1.0f).ok());
    EXPECT_EQ(model.layout().contrast->stem_darkening, 1.0f);
    EXPECT_EQ(model.layout().name, "monitor");  // not a preset: the name stays
    const SubpixelLayout before = model.layout();
    const crisp::Status refused = model.set_contrast_parameter(ContrastParameter::gamma, 0.5f);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("gamma"), std::string::npos) << refused.error().message;
    EXPECT_FALSE(model.set_contrast_parameter(ContrastParameter::contrast, std::nanf("")).ok());
    EXPECT_EQ(model.layout(), before);
    EXPECT_TRUE(model.set_contrast(std::nullopt).ok());
    EXPECT_FALSE(model.layout().contrast);
    EXPECT_EQ(model.contrast(), TextContrast{});
    ASSERT_TRUE(model.undo());
    EXPECT_EQ(model.layout(), before);
}

TEST(LayoutEditorModel, TheLayoutArgumentIsAPresetOrAFileAndAMissingOneNamesThePresets) {
    ASSERT_TRUE(crisp::editor::load_layout_argument("vbgr"));
    EXPECT_EQ(*crisp::editor::load_layout_argument("vbgr"), preset("vbgr"));
    const crisp::Result<SubpixelLayout> missing = crisp::editor::load_layout_argument("nosuchpreset");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, crisp::ErrorCode::io);
    for (const std::string_view name : crisp::subpixel_preset_names()) {
        EXPECT_NE(missing.error().message.find(name), std::string::npos) << missing.error().message;
    }
    // A file that exists but does not load keeps crisp's message alone: it was meant as a file.
    const crisp::Result<SubpixelLayout> directory = crisp::editor::load_layout_argument(CRISP_SOURCE_DIR);
    ASSERT_FALSE(directory);
    EXPECT_EQ(directory.error().message.find("qd-oled"), std::string::npos) << directory.error().message;
}

TEST(LayoutEditorModel, TypedNumbersAreDecimalsOrFractions) {
    using crisp::editor::parse_typed_number;
    EXPECT_EQ(parse_typed_number("0.25"), 0.25f);
    EXPECT_EQ(parse_typed_number("1/3"), static_cast<float>(1.0 / 3.0));
    EXPECT_EQ(parse_typed_number("-2/3"), static_cast<float>(-2.0 / 3.0));
    EXPECT_EQ(parse_typed_number("2 / 96"), static_cast<float>(2.0 / 96.0));
    EXPECT_EQ(parse_typed_number("0.5/2"), 0.25f);
    std::string why;
    EXPECT_FALSE(parse_typed_number("1/0", &why));
    EXPECT_EQ(why, "divides by zero");
    EXPECT_FALSE(parse_typed_number("1/x", &why));
    EXPECT_NE(why.find("denominator 'x' is not a number"), std::string::npos) << why;
    EXPECT_FALSE(parse_typed_number("/3", &why));
    EXPECT_NE(why.find("numerator"), std::string::npos) << why;
    EXPECT_FALSE(parse_typed_number("1/2/3", &why));
    EXPECT_FALSE(parse_typed_number("1e300/1e-300", &why));
    EXPECT_NE(why.find("out of range"), std::string::npos) << why;
    EXPECT_FALSE(parse_typed_number("third", &why));
    EXPECT_EQ(why, "is not a number");
    // Issue 29, item 8: a typed 1e308 was "expected a number"; it is a number, out of range.
    EXPECT_FALSE(parse_typed_number("1e308", &why));
    EXPECT_NE(why.find("out of range"), std::string::npos) << why;
    EXPECT_EQ(why.find("not a number"), std::string::npos) << why;
}

using crisp::editor::export_form;
using crisp::editor::export_layout;
using crisp::editor::ExportForm;
using crisp::editor::fontconfig_rgba;
using crisp::editor::freetype_lcd_geometry;

size_t occurrences(const std::string& text, const std::string& needle) {
    size_t count = 0;
    for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++count;
    return count;
}

std::string rgba_of(const SubpixelLayout& layout, std::vector<std::string>* notes = nullptr) {
    std::vector<std::string> own;
    return fontconfig_rgba(layout, notes ? *notes : own);
}

TEST(LayoutEditorModel, NudgesAndDragsStayOnTheGridAndSaveItsShortestForm) {
    LayoutModel model(preset("rgb"));
    ASSERT_TRUE(model.set_coordinate(0, 2, 0.5f).ok());
    model.select(0);
    for (int i = 0; i < 3; ++i) model.nudge(1, 0);
    // 0.5 + 3/96, exactly (float steps added up would be 0.53125006).
    EXPECT_EQ(model.layout().channels[0].x1, 0.53125f);
    EXPECT_EQ(model.layout().channels[0].x0, 3.0f / 96.0f);
    model.begin_drag(1, Handle::right);
    model.drag_to(5.0f * kEditStep, 0.0f);
    model.end_drag();
    EXPECT_EQ(model.layout().channels[1].x1, static_cast<float>(69.0 / 96.0));  // 2/3 + 5/96
    ASSERT_TRUE(model.set_coordinate(2, 1, 0.95f).ok());
    const std::string text = crisp::editor::layout_file_text(model.layout());
    EXPECT_NE(text.find("[0.03125, 0, 0.53125, 1]"), std::string::npos) << text;
    EXPECT_NE(text.find("0.95"), std::string::npos) << text;
    EXPECT_EQ(text.find("0.9499"), std::string::npos) << text;
    EXPECT_EQ(text.find("0.53125006"), std::string::npos) << text;
    // The file reads back as the same layout.
    const std::filesystem::path path = std::filesystem::temp_directory_path() / "crisp_editor_grid_test.json";
    ASSERT_TRUE(crisp::editor::save_layout_file(model.layout(), path).ok());
    const crisp::Result<SubpixelLayout> loaded = crisp::load_subpixel_layout_file(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_EQ(*loaded, model.layout());
    // A value off the grid is kept as it is.
    EXPECT_EQ(crisp::editor::snap_to_grid_if_near(0.3f), 0.3f);
    EXPECT_EQ(crisp::editor::snap_to_grid_if_near(0.5f + 3 * kEditStep), 0.53125f);
    EXPECT_EQ(crisp::editor::format_number(0.95f), "0.95");
    EXPECT_EQ(crisp::editor::format_number(-0.0001f), "-0.0001");
    EXPECT_EQ(crisp::editor::format_number(0.0f), "0");
    // Float's largest values in fixed notation (39 digits) still fit, and read back.
    EXPECT_EQ(std::strtof(crisp::editor::format_number(-3e38f).c_str(), nullptr), -3e38f);
}

TEST(LayoutEditorModel, ChoosingAPresetIsNoModificationButAnEditAwayIs) {
    LayoutModel model(preset("rgb"));
    ASSERT_TRUE(model.apply_preset("bgr").ok());
    EXPECT_FALSE(model.modified());
    model.nudge(1, 0);
    EXPECT_TRUE(model.modified());
    ASSERT_TRUE(model.apply_preset("woled").ok());
    EXPECT_FALSE(model.modified());
}

TEST(LayoutEditorModel, NumbersFitTheirFieldsAndMessagesWrapWithinTheirWidth) {
    using crisp::editor::estimated_text_width;
    const std::string shown = crisp::editor::fitted_number(-1.0f / 12.0f, 56.0f, 12.0f);
    EXPECT_EQ(shown, "-0.08333");
    EXPECT_EQ(crisp::editor::fitted_number(-1.0f / 12.0f, 50.0f, 12.0f), "-0.0833");
    EXPECT_LE(estimated_text_width(shown, 12.0f), 56.0f);
    EXPECT_EQ(crisp::editor::fitted_number(0.53125f, 60.0f, 12.0f), "0.53125");
    EXPECT_EQ(crisp::editor::fitted_number(2.5f, 60.0f, 12.0f), "2.5");
    const std::string message =
        "x0 0.95 refused: channel r: the rectangle [0.95, 0, 0.333333, 1] is empty or inverted (x1 must "
        "exceed x0, y1 must exceed y0)";
    const std::vector<std::string> lines = crisp::editor::wrap_text(message, 330.0f, 11.0f);
    ASSERT_GE(lines.size(), 3u);
    std::string joined;
    for (const std::string& line : lines) {
        EXPECT_LE(estimated_text_width(line, 11.0f), 330.0f) << line;
        joined += (joined.empty() ? "" : " ") + line;
    }
    EXPECT_EQ(joined, message);
    // A word longer than the width is broken within it; nothing is lost.
    const std::vector<std::string> broken = crisp::editor::wrap_text(std::string(80, 'W'), 100.0f, 10.0f);
    ASSERT_EQ(broken.size(), 8u);
    for (const std::string& line : broken) EXPECT_EQ(line.size(), 10u);
    EXPECT_TRUE(crisp::editor::wrap_text("", 100.0f, 10.0f).empty());
}

TEST(LayoutEditorExport, StripesMapToFontconfigsRgbaAndTwoDimensionalLayoutsToNoneWithANote) {
    for (const char* name : {"rgb", "bgr", "vrgb", "vbgr"}) {
        std::vector<std::string> notes;
        EXPECT_EQ(rgba_of(preset(name), &notes), name);
        EXPECT_TRUE(notes.empty()) << name << ": " << notes.front();
    }
    std::vector<std::string> notes;
    EXPECT_EQ(rgba_of(preset("gray"), &notes), "none");
    EXPECT_TRUE(notes.empty());
    for (const char* name : {"qd-oled", "pentile"}) {
        notes.clear();
        EXPECT_EQ(rgba_of(preset(name), &notes), "none") << name;
        ASSERT_EQ(notes.size(), 1u) << name;
        EXPECT_NE(notes[0].find("neither side by side nor stacked"), std::string::npos) << notes[0];
    }
    // WOLED's stripes run red, blue, green: no fontconfig constant has that order.
    notes.clear();
    EXPECT_EQ(rgba_of(preset("woled"), &notes), "none");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("red, blue, green left to right"), std::string::npos) << notes[0];
}

TEST(LayoutEditorExport, StripesOfOtherShapesKeepTheirOrderAndSayWhatIsLost) {
    SubpixelLayout narrow = preset("rgb");
    narrow.channels[0] = {0.0f, 0.0f, 0.25f, 1.0f};  // a narrower red stripe
    std::vector<std::string> notes;
    EXPECT_EQ(rgba_of(narrow, &notes), "rgb");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("widths"), std::string::npos) << notes[0];

    SubpixelLayout short_blue = preset("bgr");
    short_blue.channels[2].y1 = 0.5f;  // blue's stripe half the height: per-channel heights
    notes.clear();
    EXPECT_EQ(rgba_of(short_blue, &notes), "bgr");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("per-channel heights"), std::string::npos) << notes[0];

    // Stripes that overlap a little (light bleeding) are still stripes; by half, they are not.
    SubpixelLayout bleeding = preset("vrgb");
    bleeding.channels[0].y1 += 0.05f;
    bleeding.channels[1].y0 -= 0.05f;
    EXPECT_EQ(rgba_of(bleeding), "vrgb");
    bleeding.channels[1].y0 = 0.1f;
    EXPECT_EQ(rgba_of(bleeding), "none");
}

TEST(LayoutEditorExport, FreetypePositionsAreTheCentresIn64thsFromThePixelCentreYUp) {
    // FreeType's own examples: {{-21, 0}, {0, 0}, {21, 0}} is RGB, {{0, 21}, {0, 0}, {0, -21}} vertical RGB.
    using Positions = std::array<std::array<long, 2>, 3>;
    EXPECT_EQ(freetype_lcd_geometry(preset("rgb")), (Positions{{{-21, 0}, {0, 0}, {21, 0}}}));
    EXPECT_EQ(freetype_lcd_geometry(preset("bgr")), (Positions{{{21, 0}, {0, 0}, {-21, 0}}}));
    EXPECT_EQ(freetype_lcd_geometry(preset("vrgb")), (Positions{{{0, 21}, {0, 0}, {0, -21}}}));
    // QD-OLED: green above the centre, red below left, blue below right.
    EXPECT_EQ(freetype_lcd_geometry(preset("qd-oled")), (Positions{{{-16, -16}, {0, 16}, {16, -16}}}));
    EXPECT_EQ(freetype_lcd_geometry(preset("gray")), Positions{});
}

TEST(LayoutEditorExport, TheFormsCarryTheirValuesAndNotesAndOnlyKnownNamesAreForms) {
    EXPECT_EQ(export_form("fontconfig"), ExportForm::fontconfig);
    EXPECT_EQ(export_form("freetype"), ExportForm::freetype);
    EXPECT_FALSE(export_form("xft"));
    EXPECT_FALSE(export_form(""));

    const crisp::editor::Exported rgb = export_layout(preset("rgb"), ExportForm::fontconfig);
    EXPECT_TRUE(rgb.notes.empty());
    EXPECT_NE(rgb.text.find("<match target=\"font\">"), std::string::npos) << rgb.text;
    EXPECT_NE(rgb.text.find("<edit name=\"rgba\" mode=\"assign\"><const>rgb</const></edit>"), std::string::npos);
    EXPECT_NE(rgb.text.find("<edit name=\"lcdfilter\" mode=\"assign\"><const>lcddefault</const></edit>"),
              std::string::npos);

    SubpixelLayout monitor = preset("qd-oled");
    monitor.name = "my--monitor */";  // neither may end the comment that names it
    monitor.contrast = TextContrast{ContrastMode::corrected, 1.8f, 0.5f, 0.0f};
    const crisp::editor::Exported fontconfig = export_layout(monitor, ExportForm::fontconfig);
    ASSERT_EQ(fontconfig.notes.size(), 2u);  // the triangle, the contrast
    EXPECT_NE(fontconfig.notes[1].find("gamma 1.8, contrast 0.5"), std::string::npos) << fontconfig.notes[1];
    EXPECT_NE(fontconfig.text.find("<const>none</const>"), std::string::npos);
    EXPECT_NE(fontconfig.text.find("<const>lcdnone</const>"), std::string::npos);
    EXPECT_NE(fontconfig.text.find("<!-- Not expressed: " + fontconfig.notes[0] + " -->"), std::string::npos);
    const crisp::editor::Exported freetype = export_layout(monitor, ExportForm::freetype);
    ASSERT_EQ(freetype.notes.size(), 2u);  // the rectangles' sizes, the contrast
    EXPECT_NE(freetype.text.find("FT_Vector sub[3] = {{-16, -16}, {0, 16}, {16, -16}};"), std::string::npos)
        << freetype.text;
    EXPECT_NE(fontconfig.text.find("\"my-_monitor __\""), std::string::npos) << fontconfig.text;
    EXPECT_NE(freetype.text.find("\"my-_monitor __\""), std::string::npos) << freetype.text;
    // As many comments closed as opened: the name closed none early.
    EXPECT_EQ(occurrences(fontconfig.text, "-->"), occurrences(fontconfig.text, "<!--"));
    EXPECT_EQ(occurrences(fontconfig.text, "--"), 2 * occurrences(fontconfig.text, "<!--"));
    EXPECT_EQ(occurrences(freetype.text, "*/"), occurrences(freetype.text, "/*"));
}

}  // namespace

namespace {

using crisp::editor::TextEdit;

// Ten pixels a byte: positions in tests are easy to state.
float ten_per_byte(std::string_view text, float) {
    return 10.0f * static_cast<float>(text.size());
}

TEST(LayoutEditorTextEdit, TypingInsertsAtTheCursorAndTheKeysMoveAndDeleteAroundIt) {
    TextEdit edit("layout.json");
    EXPECT_EQ(edit.cursor(), 11u);
    EXPECT_FALSE(edit.has_selection());
    edit.home();
    edit.insert("my-");
    EXPECT_EQ(edit.text(), "my-layout.json");
    EXPECT_EQ(edit.cursor(), 3u);
    edit.end();
    edit.backspace();
    edit.backspace();
    edit.backspace();
    edit.backspace();
    edit.insert("txt");
    EXPECT_EQ(edit.text(), "my-layout.txt");
    edit.home();
    edit.right();
    edit.right();
    edit.erase();  // the '-'
    EXPECT_EQ(edit.text(), "mylayout.txt");
    edit.left();
    edit.insert("_");
    EXPECT_EQ(edit.text(), "m_ylayout.txt");
    // At the ends, the keys that would leave the text do nothing.
    edit.home();
    edit.left();
    edit.backspace();
    EXPECT_EQ(edit.cursor(), 0u);
    edit.end();
    edit.right();
    edit.erase();
    EXPECT_EQ(edit.text(), "m_ylayout.txt");
    // A field holds one line: control characters typed or pasted are left out.
    edit.insert("a\nb\tc\x7f");
    EXPECT_EQ(edit.text(), "m_ylayout.txtabc");
}

TEST(LayoutEditorTextEdit, SelectAllIsReplacedByTypingAndShiftArrowsExtendASelection) {
    TextEdit edit("0.33333");
    edit.select_all();
    EXPECT_EQ(edit.selection(), (std::pair<size_t, size_t>{0, 7}));
    edit.insert("1/3");
    EXPECT_EQ(edit.text(), "1/3");
    EXPECT_FALSE(edit.has_selection());
    edit.home();
    edit.right(true);
    edit.right(true);
    EXPECT_EQ(edit.selection(), (std::pair<size_t, size_t>{0, 2}));
    edit.backspace();  // deletes the selection only
    EXPECT_EQ(edit.text(), "3");
    edit.select_all();
    edit.left();  // collapses to the selection's start
    EXPECT_EQ(edit.cursor(), 0u);
    EXPECT_FALSE(edit.has_selection());
    edit.select_all();
    edit.right();
    EXPECT_EQ(edit.cursor(), 1u);
    edit.select_all();
    edit.erase();
    EXPECT_EQ(edit.text(), "");
}

TEST(LayoutEditorTextEdit, TheCursorStepsOverWholeUtf8Characters) {
    TextEdit edit("a\xC3\xA9\xE2\x80\x94z");  // a, e acute (2 bytes), em dash (3 bytes), z
    edit.left();
    edit.left();
    EXPECT_EQ(edit.cursor(), 3u);
    edit.backspace();
    EXPECT_EQ(edit.text(), "a\xE2\x80\x94z");
    edit.move_to(2);  // inside the dash: moved to its start
    EXPECT_EQ(edit.cursor(), 1u);
    edit.erase();
    EXPECT_EQ(edit.text(), "az");
    edit.insert_codepoint(0x2014);
    edit.insert_codepoint(0xD800);    // a surrogate: not a character
    edit.insert_codepoint(0x110000);  // past Unicode
    EXPECT_EQ(edit.text(), "a\xE2\x80\x94z");
}

TEST(LayoutEditorTextEdit, AClickFindsTheNearestCaretAndTheFieldScrollsToKeepTheCursorInView) {
    TextEdit edit("abcdefghij");
    EXPECT_EQ(edit.offset_at(-5.0f, 12.0f, ten_per_byte), 0u);
    EXPECT_EQ(edit.offset_at(14.0f, 12.0f, ten_per_byte), 1u);
    EXPECT_EQ(edit.offset_at(16.0f, 12.0f, ten_per_byte), 2u);
    EXPECT_EQ(edit.offset_at(500.0f, 12.0f, ten_per_byte), 10u);
    EXPECT_EQ(edit.offset_at(16.0f, 12.0f, ten_per_byte, 4), 6u);  // scrolled by 4 bytes
    // 40 pixels hold four bytes: the cursor at the end shows the last four.
    EXPECT_EQ(edit.visible(40.0f, 12.0f, ten_per_byte, 0), (std::pair<size_t, size_t>{6, 10}));
    edit.home();
    EXPECT_EQ(edit.visible(40.0f, 12.0f, ten_per_byte, 6), (std::pair<size_t, size_t>{0, 4}));
    edit.move_to(5);
    EXPECT_EQ(edit.visible(40.0f, 12.0f, ten_per_byte, 3), (std::pair<size_t, size_t>{3, 7}));
    EXPECT_EQ(edit.visible(400.0f, 12.0f, ten_per_byte, 0), (std::pair<size_t, size_t>{0, 10}));
}

// XDG_CONFIG_HOME set for the test's length, as the editor's tests set it.
class ScopedConfigHome {
public:
    explicit ScopedConfigHome(const std::filesystem::path& dir) {
        if (const char* old = std::getenv("XDG_CONFIG_HOME")) old_ = old;
        setenv("XDG_CONFIG_HOME", dir.c_str(), 1);
    }
    ~ScopedConfigHome() {
        if (old_) {
            setenv("XDG_CONFIG_HOME", old_->c_str(), 1);
        } else {
            unsetenv("XDG_CONFIG_HOME");
        }
    }

private:
    std::optional<std::string> old_;
};

void write_text(const std::filesystem::path& path, std::string_view text) {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    ASSERT_NE(file, nullptr);
    std::fwrite(text.data(), 1, text.size(), file);
    std::fclose(file);
}

TEST(LayoutEditorRecentFiles, KeptNewestFirstOnceEachAtMostEightAbsoluteAndReadBack) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crisp-layout-editor-recent-test";
    std::filesystem::remove_all(dir);
    const ScopedConfigHome config(dir);
    const std::filesystem::path file = crisp::editor::recent_files_path();
    EXPECT_EQ(file, dir / "crisp" / "layout-editor-recent");
    // None yet: an empty list, not an error.
    crisp::Result<std::vector<std::string>> read = crisp::editor::read_recent_files(file);
    ASSERT_TRUE(read) << read.error().message;
    EXPECT_TRUE(read->empty());
    std::vector<std::string> recent;
    for (int i = 0; i < 10; ++i) recent = crisp::editor::add_recent_file(recent, "/layouts/" + std::to_string(i));
    recent = crisp::editor::add_recent_file(recent, "/layouts/5");
    recent = crisp::editor::add_recent_file(recent, "relative.json");
    recent = crisp::editor::add_recent_file(recent, "/bad\nname");  // not one line: not kept
    ASSERT_EQ(recent.size(), 8u);
    EXPECT_EQ(recent[0], (std::filesystem::current_path() / "relative.json").string());
    EXPECT_EQ(recent[1], "/layouts/5");
    EXPECT_EQ(recent[2], "/layouts/9");
    EXPECT_EQ(recent[7], "/layouts/3");
    ASSERT_TRUE(crisp::editor::write_recent_files(file, recent));  // makes the directory
    read = crisp::editor::read_recent_files(file);
    ASSERT_TRUE(read) << read.error().message;
    EXPECT_EQ(*read, recent);
    std::filesystem::remove_all(dir);
}

TEST(LayoutEditorRecentFiles, ABadListIsRefusedWithTheReasonAndARelativeConfigHomeIsIgnored) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crisp-layout-editor-recent-bad";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / "recent";
    const std::pair<std::string_view, std::string_view> bad[] = {
        {std::string_view("/a\0/b\n", 6), "NUL"},
        {"/a\xff\n", "UTF-8"},
        {"/a\nrelative/b\n", "line 2"},
        {"/1\n/2\n/3\n/4\n/5\n/6\n/7\n/8\n/9\n", "more than 8"},
    };
    for (const auto& [text, why] : bad) {
        write_text(file, text);
        const crisp::Result<std::vector<std::string>> read = crisp::editor::read_recent_files(file);
        ASSERT_FALSE(read) << why;
        EXPECT_NE(read.error().message.find(why), std::string::npos) << read.error().message;
    }
    // A directory where the file should be: an error, not a crash.
    EXPECT_FALSE(crisp::editor::read_recent_files(dir));
    {
        const ScopedConfigHome config("relative/dir");  // not absolute: ignored, HOME's used
        const char* home = std::getenv("HOME");
        if (home && home[0] != '\0') {
            EXPECT_EQ(crisp::editor::recent_files_path(),
                      std::filesystem::path(home) / ".config" / "crisp" / "layout-editor-recent");
        }
    }
    std::filesystem::remove_all(dir);
}

TEST(LayoutEditorPreview, SizesAreReadFromSpacesOrCommasAndBadOnesSayWhy) {
    std::string why;
    const std::optional<std::vector<float>> sizes = crisp::editor::parse_preview_sizes(" 9, 11 13.5\t20 ", &why);
    ASSERT_TRUE(sizes) << why;
    EXPECT_EQ(*sizes, (std::vector<float>{9.0f, 11.0f, 13.5f, 20.0f}));
    EXPECT_EQ(crisp::editor::format_preview_sizes(*sizes), "9 11 13.5 20");
    const std::pair<const char*, const char*> bad[] = {
        {"", "has no sizes"},
        {" , ", "has no sizes"},
        {"9 x 13", "'x'"},
        {"9 200", "200 is outside 4 to 72 pixels"},
        {"3", "3 is outside"},
        {"nan", "'nan'"},
        {"9 10 11 12 13 14 15 16 17", "more than 8 sizes"},
    };
    for (const auto& [text, want] : bad) {
        EXPECT_FALSE(crisp::editor::parse_preview_sizes(text, &why)) << text;
        EXPECT_NE(why.find(want), std::string::npos) << text << ": " << why;
    }
}

TEST(LayoutEditorPreview, ColoursAreTwoHexColoursOrAPresetAndBadOnesSayWhy) {
    using crisp::editor::Color;
    std::string why;
    std::optional<crisp::editor::PreviewColours> colours =
        crisp::editor::parse_preview_colours("#141418 on #faF8F0", &why);
    ASSERT_TRUE(colours) << why;
    EXPECT_EQ(colours->foreground, (Color{0x14, 0x14, 0x18}));
    EXPECT_EQ(colours->background, (Color{0xFA, 0xF8, 0xF0}));
    EXPECT_EQ(crisp::editor::format_preview_colours(*colours), "#141418 on #FAF8F0");
    colours = crisp::editor::parse_preview_colours("FFFFFF/000000", &why);
    ASSERT_TRUE(colours) << why;
    EXPECT_EQ(colours->background, (Color{0, 0, 0}));
    for (const auto& [name, preset] : crisp::editor::preview_colour_presets()) {
        colours = crisp::editor::parse_preview_colours(name, &why);
        ASSERT_TRUE(colours) << name;
        EXPECT_EQ(*colours, preset);
        // Formatted, a preset reads back as itself.
        EXPECT_EQ(crisp::editor::parse_preview_colours(crisp::editor::format_preview_colours(preset)), preset);
    }
    const std::pair<const char*, const char*> bad[] = {
        {"", "is not two colours"},
        {"#123456", "is not two colours"},
        {"#12345 #000000", "'#12345' is not a colour: expected #RRGGBB"},
        {"#12345G #000000", "'#12345G' is not a colour"},
        {"#102030 on #102030", "the same colour"},
        {"red on blue", "'red' is not a colour"},
        {"dark-on-lite", "nor a preset (dark-on-light, light-on-dark, yellow-on-blue)"},
    };
    for (const auto& [text, want] : bad) {
        EXPECT_FALSE(crisp::editor::parse_preview_colours(text, &why)) << text;
        EXPECT_NE(why.find(want), std::string::npos) << text << ": " << why;
    }
}

}  // namespace

TEST(LayoutEditorCompare, CandidatesAreDistinctValidAndStartWithTheCurrentLayout) {
    for (const std::string_view name : crisp::subpixel_preset_names()) {
        SubpixelLayout current = *crisp::subpixel_preset(name);
        current.contrast = TextContrast{};
        const std::vector<crisp::editor::Candidate> candidates = crisp::editor::layout_candidates(current);
        ASSERT_GE(candidates.size(), 2u) << name;
        ASSERT_LE(candidates.size(), crisp::editor::kMaxCandidates) << name;
        EXPECT_EQ(candidates[0].layout, current) << name;
        for (size_t i = 0; i < candidates.size(); ++i) {
            EXPECT_TRUE(crisp::validate_subpixel_layout(candidates[i].layout)) << name << " " << i;
            EXPECT_EQ(candidates[i].layout.contrast, current.contrast) << name << " " << i;
            for (const SampleRect& rect : candidates[i].layout.channels) {
                for (const float v : {rect.x0, rect.y0, rect.x1, rect.y1}) {
                    EXPECT_EQ(v, crisp::editor::snap_to_grid_if_near(v)) << name << " " << i;
                }
            }
            for (size_t j = 0; j < i; ++j) {
                EXPECT_NE(candidates[i].layout.channels, candidates[j].layout.channels) << name << " " << i << j;
            }
        }
    }
    // rgb's candidates: itself, bgr (the order reversed, named after its preset), narrower, wider.
    const std::vector<crisp::editor::Candidate> rgb = crisp::editor::layout_candidates(preset("rgb"));
    ASSERT_EQ(rgb.size(), 4u);
    EXPECT_EQ(rgb[1].layout.channels, preset("bgr").channels);
    EXPECT_EQ(rgb[1].layout.name, "bgr");
    EXPECT_EQ(rgb[2].layout.name, "rgb-edited");
    EXPECT_FLOAT_EQ(rgb[2].layout.channels[1].x0, 1.0f / 3.0f + crisp::editor::kCandidateSteps * kEditStep);
    EXPECT_FLOAT_EQ(rgb[3].layout.channels[1].x1, 2.0f / 3.0f + crisp::editor::kCandidateSteps * kEditStep);
    // vrgb's stripes mirrored left to right are the same: its order reversed is top to bottom.
    const std::vector<crisp::editor::Candidate> vrgb = crisp::editor::layout_candidates(preset("vrgb"));
    ASSERT_GE(vrgb.size(), 2u);
    EXPECT_EQ(vrgb[1].label, "Order reversed");
    EXPECT_EQ(vrgb[1].layout.name, "vbgr");
    // Gray is its own mirror both ways: no "order reversed" candidate, three in all.
    const std::vector<crisp::editor::Candidate> gray = crisp::editor::layout_candidates(preset("gray"));
    EXPECT_EQ(gray.size(), 3u);
    for (const auto& candidate : gray) EXPECT_NE(candidate.label, "Order reversed");
    SubpixelLayout invalid = preset("rgb");
    invalid.channels[0].x1 = invalid.channels[0].x0;
    EXPECT_TRUE(crisp::editor::layout_candidates(invalid).empty());
}

TEST(LayoutEditorCompare, PickingACandidateMakesItCurrentAsOneUndoStepAndRefinesAroundIt) {
    LayoutModel model(preset("rgb"));
    const uint64_t revision = model.revision();
    std::vector<crisp::editor::Candidate> candidates = crisp::editor::layout_candidates(model.layout());
    ASSERT_TRUE(model.pick(candidates[0]));  // the current one: nothing changes
    EXPECT_FALSE(model.can_undo());
    EXPECT_EQ(model.revision(), revision);
    ASSERT_TRUE(model.pick(candidates[2]));  // narrower
    EXPECT_EQ(model.layout(), candidates[2].layout);
    EXPECT_GT(model.revision(), revision);
    // Picking only: narrower again from there, the candidates regenerated around the pick.
    candidates = crisp::editor::layout_candidates(model.layout());
    EXPECT_EQ(candidates[0].layout, model.layout());
    ASSERT_TRUE(model.pick(candidates[2]));
    EXPECT_FLOAT_EQ(model.layout().channels[1].x0, 1.0f / 3.0f + 2 * crisp::editor::kCandidateSteps * kEditStep);
    EXPECT_EQ(model.layout().name, "rgb-edited");
    ASSERT_TRUE(model.undo());
    ASSERT_TRUE(model.undo());
    EXPECT_EQ(model.layout(), preset("rgb"));
    EXPECT_FALSE(model.can_undo());
    crisp::editor::Candidate bad{"bad", preset("rgb")};
    bad.layout.channels[2].x0 = std::nanf("");
    EXPECT_FALSE(model.pick(bad));
    EXPECT_EQ(model.layout(), preset("rgb"));
}
