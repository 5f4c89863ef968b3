// The layout editor's model (tools/layout_editor/editor_model.hpp): edits, bounds, undo and redo,
// the monitor's contrast settings, without a window.
#include "editor_model.hpp"

#include <crisp/glyph.hpp>
#include <crisp/subpixel.hpp>

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
