// Everything the example does with crisp: a font (and an emoji font after it), one Renderer (the glyph atlas and its
// rasterizer) and one Compositor (the tile path), the HUD and the world-space labels. This is the
// part of the example an engine programmer copies; docs/integration.md walks through it.
//
// A frame, in order (App::record_frame):
//   draw()                 renderer.begin_frame(), layouts of what changed, renderer.draw()s
//   record_rasterization() renderer.record(cb): uploads and the rasterizer's compute dispatch
//   ... the engine's scene pass, which also draws the panels draw() returned ...
//   record_composite()     compositor.record(cb, ...) into the scene target, in GENERAL
//   frame_submitted() or abandon_frame()
#pragma once

#include "device.hpp"
#include "scene.hpp"
#include "swapchain.hpp"
#include "text_field.hpp"

#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace engine {

// The emoji at the end of the HUD's title when there is an emoji font (U+1F600 grinning face).
inline constexpr uint32_t kHudEmoji = 0x1F600;

// Where a piece of text was drawn this frame, in window pixels (for --report and its test).
struct TextBox {
    std::string name;  // "hud", "paragraph", "counter", "list", "label:Cube", "spinner", "sign"
    // The spinner: its layout box before the turn, centred on the point it turns about; the sign:
    // the bounds of `quad`.
    float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
    bool hovered = false;                        // labels: drawn in the hover colour
    float anchor_x = 0.0f, anchor_y = 0.0f;      // labels: the projected point they point at
    float angle = 0.0f;                          // the spinner: degrees clockwise on screen, 0 to 360
    std::array<std::array<float, 2>, 4> quad{};  // the sign: its face's corners on screen
};

// Glyphs of the last submitted frame (Renderer::stats() and the keys of Renderer::drawn_frame()).
struct GlyphCounts {
    uint32_t drawn = 0;
    uint32_t moving = 0;
    uint32_t transformed = 0;  // keys with a linear part: the spinner's and the sign's glyphs
    uint32_t projective = 0;   // of those, keys that kept their perspective (one affine map was not enough)
};

// What one frame of text needs from the scene pass (panels under the text), and where it went.
struct OverlayFrame {
    std::vector<Panel> panels;
    std::vector<TextBox> boxes;
};

class TextOverlay {
public:
    // Creates the renderer and compositor on `device` (whose feature chain crisp checks) and lays
    // out the text that never changes. `fonts`: the text font, then optionally a colour font whose
    // kHudEmoji ends the HUD's title. Errors: crisp's, when the device lacks what it needs or the
    // compositor cannot store to the scene target's format. `caret_blink_ms`: the text field's
    // (TextField).
    static crisp::Result<std::unique_ptr<TextOverlay>> create(const Device& device, std::vector<crisp::Font> fonts,
                                                              uint32_t caret_blink_ms);
    TextOverlay(const TextOverlay&) = delete;
    TextOverlay& operator=(const TextOverlay&) = delete;

    // The HUD's right edge in window pixels: the scene is centred in the rest.
    float hud_right() const { return hud_.x + hud_.width; }

    // Starts crisp's frame and issues this frame's draws: the HUD's static text, its counter (laid
    // out again every frame), the list rows (moved and clipped to the list box), the spinner below
    // the HUD (turned about its centre by a transform), one label per shape (moved to its
    // projected anchor, at its depth, hover colour as a draw option) and the sign on the cube's
    // face (on a plane seen through the camera), and the text field at the bottom.
    const OverlayFrame& draw(uint64_t frame, VkExtent2D extent, const SceneState& scene);
    // The text field, for the window's input callbacks.
    TextField& field() { return *field_; }
    const TextField& field() const { return *field_; }
    // renderer.record(): outside any render pass, before anything reads the atlas.
    crisp::Status record_rasterization(VkCommandBuffer command_buffer);
    // compositor.record() into `targets.color`, which must be in GENERAL with the scene pass's
    // writes visible to compute shader reads and writes. Its writes are at COMPUTE_SHADER.
    crisp::Status record_composite(VkCommandBuffer command_buffer, const RenderTargets& targets);
    // The frame recorded since draw() will never be submitted: take it back in crisp's objects.
    void abandon_frame();
    // The frame was submitted: its renderer statistics go into the next frames' counter line.
    void frame_submitted();
    // What the last draw() drew.
    const OverlayFrame& frame() const { return frame_; }
    const GlyphCounts& submitted_glyphs() const { return submitted_glyphs_; }

private:
    TextOverlay(std::vector<crisp::Font> fonts, uint32_t caret_blink_ms);
    crisp::Status lay_out_static();
    crisp::Status lay_out(std::string_view text, const crisp::TextStyle& style, const crisp::LayoutOptions& options,
                          crisp::TextLayout& out);
    void draw_hud(uint64_t frame, VkExtent2D extent);
    void draw_list(uint64_t frame);
    void draw_spinner(uint64_t frame);
    void draw_labels(VkExtent2D extent, const SceneState& scene);
    void draw_sign(VkExtent2D extent, const SceneState& scene);
    void draw_field(VkExtent2D extent);
    TextBox box_of(const char* name, const crisp::TextLayout& layout, float dx, float dy) const;

    // The text font first, the fallback chain of every layout; declared before the renderer, which
    // keeps pointers to them (the vector is never resized).
    std::vector<crisp::Font> fonts_;
    std::vector<const crisp::Font*> font_chain_;
    std::optional<crisp::Renderer> renderer_;
    std::optional<crisp::Compositor> compositor_;
    crisp::Layouter layouter_;
    Panel hud_;
    Panel list_box_;
    VkRect2D list_clip_{};  // the list box in whole pixels: the rows' visible rect (crisp clips to it)
    crisp::TextLayout title_;
    crisp::TextLayout paragraph_;
    crisp::TextLayout counter_;  // laid out again every frame
    float counter_y_ = 0.0f;
    std::vector<crisp::TextLayout> rows_;
    std::array<crisp::TextLayout, kShapeCount> labels_;
    crisp::TextLayout spinner_;
    Panel spinner_panel_;  // a square the spinner turns in, whatever its angle
    crisp::TextLayout sign_;
    // After the fonts and the layouter, which it uses.
    std::optional<TextField> field_;
    crisp::RendererStats last_submitted_{};
    GlyphCounts submitted_glyphs_;
    bool have_stats_ = false;
    OverlayFrame frame_;
};

}  // namespace engine
