// Private: the renderer's draw requests, from draw() to the frame's drawn glyphs: pen offsets,
// visible and clipped parts (a glyph drawn in parts acquired once, for their bounding box), the
// motion of named draws, and the frame started over at coarser steps where the atlas is full.
// CPU only: it runs, and is tested, without a device.
#pragma once

#include "raster/coarsening.hpp"
#include "raster/held_fonts.hpp"

#include <crisp/atlas.hpp>
#include <crisp/effects.hpp>
#include <crisp/renderer.hpp>
#include <crisp/transform.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace crisp::raster {

// `glyph` with its pen moved by (dx, dy) pixels: its key's subpixel offsets, rect and position
// follow on each axis that moves. False when the new pen is not finite or out of range. `asset`
// is its font's; null (a font not held) or a glyph the asset does not have: true, unmoved.
bool moved(const FontAsset* asset, GlyphInstance& glyph, double dx, double dy);
// The same for a glyph whose outline is `record` (an effect layer's derived one).
bool moved(const GlyphRecord& record, GlyphInstance& glyph, double dx, double dy);

// Where each named draw (DrawOptions::id) was, to tell moving text from static text.
class MotionTracker {
public:
    // Named draws not seen for this many frames are forgotten.
    static constexpr uint64_t kForgetMotionFrames = 256;

    void begin_frame();
    // Whether the named draw whose first glyph's pen is (x, y) this frame, drawn at a transform
    // whose fingerprint is `shape` (0: none), moved or changed its transform lately.
    bool moving(uint64_t id, double x, double y, uint64_t shape = 0);
    // The named draws as they were before this frame's begin_frame(), as if it never began.
    void abandon_frame();

private:
    struct Motion {
        double pen_x = 0.0, pen_y = 0.0;  // a named draw's first glyph's pen, offset included
        uint64_t shape = 0;               // its transform's fingerprint
        uint64_t moved = 0;               // the frame its pen last changed (0: never seen move)
        uint64_t seen = 0;                // the frame it was last drawn
    };
    std::unordered_map<uint64_t, Motion> motions_;
    uint64_t frames_begun_ = 0;  // begin_frame() calls, the clock of `motions_`
    // The named draws this frame changed, as they were before it (nullopt: new this frame).
    std::vector<std::pair<uint64_t, std::optional<Motion>>> undo_;
};

// A frame's draw()n instances, as asked, and the atlas entries they acquire. The atlas, fonts,
// coarsening and stats are the renderer's, and outlive it.
class FrameRequests {
public:
    FrameRequests(GlyphAtlas& atlas, HeldFonts& fonts, Coarsening& coarsening, RendererStats& stats);

    void begin_frame();
    // One draw()n instance, at the frame's subpixel steps or `steps` (moving text: fewer) where
    // fewer; `visible` (null: all) is what of the target can be seen.
    void add(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps);
    void add(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps, const TextContrast& contrast);
    // draw(glyphs, options): moved, recoloured and at their depth; named draws' motion in `motion`.
    void add(std::span<const GlyphInstance> glyphs, const DrawOptions& options, MotionTracker& motion);
    // After the frame's draws: where the atlas had no room for some glyph, the frame starts over
    // with every glyph at the next coarser subpixel steps (a quarter pixel, then a whole one), as
    // long as there is a coarser one; the steps stay coarse until the atlas has been mostly empty
    // for a while. A visible glyph is dropped only when even whole-pixel positions do not fit.
    void settle(const AtlasLimits& limits);
    // The glyphs this frame draws, once the atlas has scheduled the frame's work.
    void collect_drawn();
    // The frame's drawn glyphs are forgotten, and the next frame is not converged.
    void abandon_frame();

    // The contrast of draws whose options give none (RendererCreateInfo::contrast; valid).
    void set_contrast(const TextContrast& contrast) { contrast_ = contrast; }
    const TextContrast& contrast() const { return contrast_; }

    std::span<const DrawnGlyph> drawn() const { return drawn_; }
    // The same, for the pass that resolves colour layers' fills in place (raster/paints).
    std::span<DrawnGlyph> drawn_to_fill() { return drawn_; }
    bool converged() const { return converged_; }

private:
    static constexpr uint32_t kNoEffects = 0xFFFFFFFFu;
    // A draw's effects (DrawOptions::effects): their colours in linear light, and the paint orders
    // of the layers under and over its glyphs.
    struct DrawEffects {
        TextEffects effects;
        uint32_t first_order = 0;
        uint32_t last_order = 0;
        std::array<float, 4> outline_color{};
        std::array<float, 4> shadow_color{};
        std::array<float, 4> glow_color{};
    };
    struct Request {
        GlyphInstance glyph;  // moved, recoloured and at its depth as the draw's options asked
        bool has_visible = false;
        VkRect2D visible{};
        uint32_t steps = kSubpixelSteps;  // the finest subpixel steps it may take (moving text: fewer)
        GlyphContrast contrast;           // the draw's, resolved for the glyph's size
        uint32_t effects = kNoEffects;    // its draw's in effects_
        bool silhouette = false;          // the first drawn layer of a colour glyph: its effects' layers
    };
    // An effect layer's outline: GlyphKey::glyph, ::effect (0: the glyph's own) and ::blur.
    struct LayerShape {
        uint32_t glyph = 0;
        uint32_t effect = 0;
        uint16_t blur = 0;
    };
    struct Pending {
        DrawnGlyph glyph;
        uint32_t entry = kNoAtlasEntry;
    };
    struct Clipped {
        GlyphInstance glyph;
        TexelRect part;  // visible texels of its rect
        GlyphContrast contrast;
        uint32_t stack = kStackGlyph;
    };

    enum class Placed { placed, refused, culled };
    Placed place(GlyphInstance& glyph, const DrawOptions& options, const TransformSteps& steps, double dx, double dy,
                 float& depth);
    void request(const GlyphInstance& asked, const VkRect2D* visible, uint32_t steps, const GlyphContrast& contrast,
                 uint32_t effects, bool silhouette = false);
    void request_effects(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps,
                         const GlyphContrast& contrast, const DrawEffects& fx, bool silhouette);
    void submit_layer(const GlyphInstance& glyph, const LayerShape& shape, const std::array<float, 4>& colour,
                      uint32_t order, uint32_t stack, double dx, double dy, const VkRect2D* visible,
                      const GlyphContrast& contrast);
    void submit(const GlyphInstance& glyph, const VkRect2D* visible, const GlyphContrast& contrast, uint32_t stack);
    void admit(const GlyphInstance& glyph, const TexelRect& part, const GlyphContrast& contrast, uint32_t stack,
               const TexelRect* shown = nullptr);
    AtlasLookup look_up_or_place(const FontAsset& asset, const GlyphRecord& record, const GlyphInstance& glyph,
                                 const TexelRect& part);
    void admit_clipped();

    GlyphAtlas& atlas_;
    HeldFonts& fonts_;
    Coarsening& coarsening_;
    RendererStats& stats_;
    std::vector<Request> requests_;     // this frame's draw()n instances, as asked
    std::vector<DrawEffects> effects_;  // this frame's draws' effects
    std::vector<Pending> pending_;      // draw()n this frame, before record() knows their samples
    std::vector<Clipped> clipped_;      // draw()n partly visible, admitted in record()
    // Scratch of admit_clipped(), kept so that a warm frame allocates nothing: clipped_ indices in
    // key order, and each clipped instance's bounding part (over every instance of its key).
    std::vector<uint32_t> clipped_order_;
    std::vector<TexelRect> clipped_parts_;
    std::vector<DrawnGlyph> drawn_;
    bool converged_ = true;
    TextContrast contrast_;
    uint32_t atlas_full_ = 0;   // instances refused as atlas_full this frame
    uint32_t unplaceable_ = 0;  // instances draw() could not move (a pen out of range)
};

}  // namespace crisp::raster
