#include "raster/requests.hpp"

#include "text/blur_kernel.hpp"
#include "text/effect_code.hpp"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <iterator>
#include <numeric>

namespace crisp::raster {

bool moved(const FontAsset* asset, GlyphInstance& glyph, double dx, double dy) {
    if (dx == 0.0 && dy == 0.0) return true;
    if (!asset) return true;  // admit() counts it
    if (glyph.key.glyph >= asset->glyphs.size()) return true;
    return moved(asset->glyphs[glyph.key.glyph], glyph, dx, dy);
}

bool moved(const GlyphRecord& record, GlyphInstance& glyph, double dx, double dy) {
    if (dx == 0.0 && dy == 0.0) return true;
    const GlyphRect old_rect = glyph_rect(record, glyph.key);
    const double pens[2] = {static_cast<double>(glyph.pen_x) + dx, static_cast<double>(glyph.pen_y) + dy};
    int32_t whole[2] = {glyph.x - old_rect.x, glyph.y - old_rect.y};
    uint8_t* offsets[2] = {&glyph.key.subpixel_x, &glyph.key.subpixel_y};
    const double deltas[2] = {dx, dy};
    for (int axis = 0; axis < 2; ++axis) {
        if (deltas[axis] == 0.0) continue;
        constexpr double kMaxPen = 16777216.0;  // 2^24 px
        if (!(std::abs(pens[axis]) <= kMaxPen)) return false;
        double base = std::floor(pens[axis]);
        double step = std::round((pens[axis] - base) * kSubpixelSteps);
        if (step >= kSubpixelSteps) {
            base += 1.0;
            step = 0.0;
        }
        whole[axis] = static_cast<int32_t>(base);
        *offsets[axis] = static_cast<uint8_t>(step);
    }
    const GlyphRect rect = glyph_rect(record, glyph.key);
    glyph.x = whole[0] + rect.x;
    glyph.y = whole[1] + rect.y;
    glyph.width = rect.width;
    glyph.height = rect.height;
    glyph.pen_x = static_cast<float>(pens[0]);
    glyph.pen_y = static_cast<float>(pens[1]);
    return true;
}

void MotionTracker::begin_frame() {
    ++frames_begun_;
    if (frames_begun_ % kForgetMotionFrames == 0) {
        std::erase_if(motions_, [&](const auto& m) { return frames_begun_ - m.second.seen > kForgetMotionFrames; });
    }
    undo_.clear();
}

bool MotionTracker::moving(uint64_t id, double x, double y, uint64_t shape) {
    auto [it, added] = motions_.try_emplace(id, Motion{x, y, shape, 0, frames_begun_});
    Motion& m = it->second;
    if (added) {
        undo_.emplace_back(id, std::nullopt);
    } else if (m.seen != frames_begun_) {  // its first draw this frame
        undo_.emplace_back(id, m);
    }
    if (!added && (m.pen_x != x || m.pen_y != y || m.shape != shape)) {
        m.moved = frames_begun_;
        m.pen_x = x;
        m.pen_y = y;
        m.shape = shape;
    }
    m.seen = frames_begun_;
    return m.moved != 0 && frames_begun_ - m.moved < kMotionSettleFrames;
}

void MotionTracker::abandon_frame() {
    for (auto it = undo_.rbegin(); it != undo_.rend(); ++it) {
        if (it->second) {
            motions_[it->first] = *it->second;
        } else {
            motions_.erase(it->first);
        }
    }
    undo_.clear();
    --frames_begun_;
}

namespace {

// Whether `glyph` is a further layer of the colour glyph `previous` is a layer of: the same colour
// glyph at the same pen and cluster (two of one emoji side by side differ in both).
bool same_colour_glyph(const GlyphInstance* previous, const GlyphInstance& glyph) {
    return previous && previous->colour_glyph == glyph.colour_glyph && previous->key.font == glyph.key.font &&
           previous->cluster == glyph.cluster && std::memcmp(&previous->pen_x, &glyph.pen_x, sizeof(float)) == 0 &&
           std::memcmp(&previous->pen_y, &glyph.pen_y, sizeof(float)) == 0;
}

// A fingerprint of a draw's transform or plane: any change of a value changes it (0: none).
uint64_t shape_of(const DrawOptions& options) {
    uint64_t h = 0;
    const auto add = [&](float v) {
        uint32_t bits = 0;
        std::memcpy(&bits, &v, sizeof bits);
        h = (h ^ bits) * 0x100000001B3ull + 0x9E3779B97F4A7C15ull;
    };
    if (options.transform) {
        for (float v : {options.transform->a, options.transform->b, options.transform->c, options.transform->d,
                        options.transform->pivot_x, options.transform->pivot_y})
            add(v);
    }
    if (options.plane) {
        for (const auto* v : {&options.plane->origin, &options.plane->axis_x, &options.plane->axis_y}) {
            for (float f : *v) add(f);
        }
        for (float f : options.plane->view_projection) add(f);
        for (float f : options.plane->viewport) add(f);
    }
    return h;
}

}  // namespace

FrameRequests::FrameRequests(GlyphAtlas& atlas, HeldFonts& fonts, Coarsening& coarsening, RendererStats& stats)
    : atlas_(atlas), fonts_(fonts), coarsening_(coarsening), stats_(stats) {}

void FrameRequests::begin_frame() {
    pending_.clear();
    clipped_.clear();
    requests_.clear();
    effects_.clear();
    atlas_full_ = 0;
    unplaceable_ = 0;
    drawn_.clear();
    converged_ = true;
}

void FrameRequests::add(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps) {
    add(glyph, visible, steps, contrast_);
}

void FrameRequests::add(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps,
                        const TextContrast& contrast) {
    const GlyphContrast resolved = resolve_contrast(contrast, static_cast<float>(glyph.key.size_x) / 256.0f);
    requests_.push_back({glyph, visible != nullptr, visible ? *visible : VkRect2D{}, steps, resolved, kNoEffects});
    request(glyph, visible, steps, resolved, kNoEffects);
}

void FrameRequests::add(std::span<const GlyphInstance> glyphs, const DrawOptions& options, MotionTracker& motion) {
    if (glyphs.empty()) return;
    const double dx = static_cast<double>(options.offset_x), dy = static_cast<double>(options.offset_y);
    const bool bad_transform = (options.transform && !valid_transform(*options.transform)) ||
                               (options.plane && !valid_plane(*options.plane)) || (options.transform && options.plane);
    if (!std::isfinite(dx) || !std::isfinite(dy) || bad_transform ||
        (options.contrast && !validate_text_contrast(*options.contrast)) ||
        (options.effects && !validate_text_effects(*options.effects))) {
        const auto count = static_cast<uint32_t>(std::min<size_t>(glyphs.size(), UINT32_MAX));
        stats_.skipped_glyphs += count;
        unplaceable_ += count;
        return;
    }
    float color[4] = {};
    if (options.color) {
        for (int c = 0; c < 4; ++c) {
            const float v = (*options.color)[static_cast<size_t>(c)];
            color[c] = v == v ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
            if (c < 3) color[c] = srgb_to_linear(color[c]);
        }
    }
    uint32_t steps = kSubpixelSteps;
    TransformSteps transform_steps = kStillTransformSteps;
    if (options.id != 0) {
        const GlyphInstance& first = glyphs.front();
        if (motion.moving(options.id, static_cast<double>(first.pen_x) + dx, static_cast<double>(first.pen_y) + dy,
                          shape_of(options))) {
            steps = kMovingSubpixelSteps;
            transform_steps = kMovingTransformSteps;
            stats_.moving_glyphs += static_cast<uint32_t>(std::min<size_t>(glyphs.size(), UINT32_MAX));
        }
    }
    const VkRect2D* visible = options.visible ? &*options.visible : nullptr;
    uint32_t effects = kNoEffects;
    if (options.effects) {
        // Layers under the draw's glyphs take its first paint order, those over them its last.
        DrawEffects fx{*options.effects, UINT32_MAX, 0, {}, {}};
        for (const GlyphInstance& g : glyphs) {
            fx.first_order = std::min(fx.first_order, g.paint_order);
            fx.last_order = std::max(fx.last_order, g.paint_order);
        }
        const auto linear = [](const std::array<float, 4>& c, std::array<float, 4>& out) {
            for (size_t i = 0; i < 3; ++i) out[i] = srgb_to_linear(c[i]);
            out[3] = c[3];
        };
        if (fx.effects.outline) linear(fx.effects.outline->color, fx.outline_color);
        if (fx.effects.shadow) linear(fx.effects.shadow->color, fx.shadow_color);
        if (fx.effects.glow) linear(fx.effects.glow->color, fx.glow_color);
        effects = static_cast<uint32_t>(effects_.size());
        effects_.push_back(fx);
    }
    // A colour glyph's layers follow each other: the first of them drawn carries the effect
    // layers of its silhouette.
    const GlyphInstance* previous = nullptr;
    bool silhouette_due = false;
    for (const GlyphInstance& asked : glyphs) {
        if (asked.colour_glyph != kNoColourGlyph && !same_colour_glyph(previous, asked)) silhouette_due = true;
        previous = &asked;
        GlyphInstance glyph = asked;
        float depth = glyph.depth;
        const Placed placed = place(glyph, options, transform_steps, dx, dy, depth);
        if (placed == Placed::culled) {
            ++stats_.culled_glyphs;
            continue;
        }
        if (placed == Placed::refused) {
            ++stats_.skipped_glyphs;
            ++unplaceable_;
            continue;
        }
        glyph.depth = depth;
        if (options.color) std::copy(std::begin(color), std::end(color), std::begin(glyph.color));
        if (options.depth) glyph.depth = *options.depth;
        if (options.palette) glyph.palette = *options.palette;
        const GlyphContrast contrast = resolve_contrast(options.contrast ? *options.contrast : contrast_,
                                                        static_cast<float>(glyph.key.size_x) / 256.0f);
        const bool silhouette = silhouette_due && glyph.colour_glyph != kNoColourGlyph;
        if (silhouette) silhouette_due = false;
        requests_.push_back(
            {glyph, visible != nullptr, visible ? *visible : VkRect2D{}, steps, contrast, effects, silhouette});
        request(glyph, visible, steps, contrast, effects, silhouette);
    }
}

// `glyph` moved by (dx, dy), or placed at the draw's transform or on its plane (depth: the glyph's
// on the plane).
FrameRequests::Placed FrameRequests::place(GlyphInstance& glyph, const DrawOptions& options,
                                           const TransformSteps& steps, double dx, double dy, float& depth) {
    const FontAsset* asset = fonts_.asset(glyph.key.font);
    if (!options.transform && !options.plane) return moved(asset, glyph, dx, dy) ? Placed::placed : Placed::refused;
    if (!asset || glyph.key.glyph >= asset->glyphs.size()) return Placed::placed;  // admit() counts it
    // Transforms apply to glyphs as laid out: one already transformed is refused.
    if (is_transformed(glyph.key)) return Placed::refused;
    const GlyphRecord& record = asset->glyphs[glyph.key.glyph];
    const double sx = static_cast<double>(glyph.key.size_x) / kSizeOne,
                 sy = static_cast<double>(glyph.key.size_y) / kSizeOne;
    const double pen_x = static_cast<double>(glyph.pen_x), pen_y = static_cast<double>(glyph.pen_y);
    GlyphPlacement placement;
    if (options.transform) {
        placement = place_transformed(*options.transform, pen_x, pen_y, sx, sy, dx, dy);
    } else {
        const PlanePlacement on_plane = place_on_plane(*options.plane, record, pen_x + dx, pen_y + dy, sx, sy);
        if (!on_plane.visible) return Placed::culled;
        placement = on_plane.place;
        depth = on_plane.depth;
        if (on_plane.projective) {
            ++stats_.projective_glyphs;
        } else {
            stats_.max_affine_error = std::max(stats_.max_affine_error, static_cast<float>(on_plane.affine_error));
        }
    }
    ++stats_.transformed_glyphs;
    GlyphInstance out = glyph;
    out.key.subpixel_x = out.key.subpixel_y = 0;
    if (!place_glyph(record, placement, {steps.linear, steps.perspective, steps.subpixel}, out)) return Placed::refused;
    if (record.curve_count != 0 && (out.width == 0 || out.height == 0)) return Placed::culled;
    glyph = out;
    return Placed::placed;
}

// One draw()n instance: at the frame's subpixel steps, then culled, admitted whole, or kept
// for admit_clipped() with its visible part.
void FrameRequests::request(const GlyphInstance& asked, const VkRect2D* visible, uint32_t steps,
                            const GlyphContrast& contrast, uint32_t effects, bool silhouette) {
    const uint32_t frame_steps = std::min(coarsening_.steps(), steps);
    const GlyphInstance glyph = coarsened(fonts_.asset(asked.key.font), asked, frame_steps);
    if (glyph.key != asked.key) ++stats_.coarsened_glyphs;
    if (effects == kNoEffects) {
        submit(glyph, visible, contrast, kStackGlyph);
    } else {
        request_effects(glyph, visible, frame_steps, contrast, effects_[effects], silhouette);
    }
}

namespace {

// The effect code of (S(half_width px) op G) at `size` px per em; 0 where the stroke is empty.
uint32_t effect_code(StrokeOp op, LineJoin join, float miter_limit, double half_width, double size) {
    if (!(half_width > 0.0)) return 0;
    EffectShape shape;
    shape.op = op;
    shape.join = static_cast<StrokeJoin>(join);
    shape.miter_limit = static_cast<double>(miter_limit);
    shape.half_width = half_width / size;
    return encode_effect(shape);
}

// GlyphKey::blur of a radius of `radius` px (validated: 0 to kMaxEffectBlur), to 1/64 px.
uint16_t blur_code(float radius) {
    return static_cast<uint16_t>(std::lround(static_cast<double>(radius) / kBlurUnit));
}
static_assert(static_cast<double>(kMaxEffectBlur) / kBlurUnit <= UINT16_MAX);

static_assert(static_cast<int>(LineJoin::round) == static_cast<int>(StrokeJoin::round) &&
              static_cast<int>(LineJoin::miter) == static_cast<int>(StrokeJoin::miter) &&
              static_cast<int>(LineJoin::bevel) == static_cast<int>(StrokeJoin::bevel));

}  // namespace

// A glyph of a draw with effects: its shadow, its outline and its face (weighted), each a layer.
// A colour glyph's layers are each weighted as a face; its shadow, glow and outline are of its
// silhouette (kSilhouetteGlyph), made at its first drawn layer (`silhouette`).
void FrameRequests::request_effects(const GlyphInstance& glyph, const VkRect2D* visible, uint32_t steps,
                                    const GlyphContrast& contrast, const DrawEffects& fx, bool silhouette) {
    const TextEffects& e = fx.effects;
    const HeldGlyph own = fonts_.glyph(glyph.key);
    if (!own.record || glyph.width == 0 || glyph.height == 0) {
        submit(glyph, visible, contrast, kStackGlyph);  // admit() counts it
        return;
    }
    const FontAsset* asset = fonts_.asset(glyph.key.font);
    const bool coloured = glyph.colour_glyph != kNoColourGlyph;
    const ColourGlyph* colour = coloured && asset && glyph.colour_glyph < asset->colour_glyphs.size()
                                    ? &asset->colour_glyphs[glyph.colour_glyph]
                                    : nullptr;
    const bool bitmap = glyph.paint != kNoPaint && asset && glyph.paint < asset->paints.size() &&
                        asset->paints[glyph.paint].kind == PaintKind::image;
    // A bitmap glyph (and a layer without its colour glyph) is drawn as it is, counted once.
    if (bitmap || (coloured && !colour) || (glyph.paint != kNoPaint && !coloured)) {
        if (silhouette || !coloured) ++stats_.failed_effects;
        submit(glyph, visible, contrast, kStackGlyph);
        return;
    }
    const double size = std::sqrt(static_cast<double>(glyph.key.size_x) * glyph.key.size_y) / kSizeOne;
    const double reach_limit = static_cast<double>(kMaxEffectReachEm) * size;
    const double weight = static_cast<double>(e.weight), grown = std::max(weight, 0.0);
    const uint32_t face = std::abs(weight) <= reach_limit
                              ? effect_code(weight > 0.0 ? StrokeOp::a_or_b : StrokeOp::b_not_a, LineJoin::miter, 4.0f,
                                            std::abs(weight), size)
                              : 0;
    if (face == 0 && weight != 0.0 && std::abs(weight) > reach_limit && (silhouette || !coloured)) {
        ++stats_.failed_effects;
    }
    if (!coloured || silhouette) {
        // The layers around the glyph: of its own outline, or of the colour glyph's silhouette
        // (whose face, unweighted, is the silhouette itself: S(0) or B).
        const uint32_t source = coloured ? kSilhouetteGlyph | colour->glyph : glyph.key.glyph;
        const uint32_t own_face = face != 0 || !coloured ? face : encode_effect({StrokeOp::a_or_b});
        // The outline's layer, and the shadow's source: the face with its outline.
        uint32_t outline = 0, shadow = own_face;
        uint32_t outline_stack = kStackOutlineUnder;
        if (const auto& o = e.outline) {
            double r = 0.0;
            StrokeOp op = StrokeOp::a;
            switch (o->placement) {
                case OutlinePlacement::outside:
                    r = static_cast<double>(o->width) + grown;
                    op = StrokeOp::a_not_b;
                    break;
                case OutlinePlacement::inside:
                    r = static_cast<double>(o->width);
                    op = StrokeOp::a_and_b;
                    outline_stack = kStackOutlineOver;
                    break;
                case OutlinePlacement::centred:
                    r = static_cast<double>(o->width) / 2.0;
                    op = StrokeOp::a;
                    outline_stack = kStackOutlineOver;
                    break;
            }
            if (r > reach_limit) {
                ++stats_.failed_effects;
            } else {
                outline = effect_code(op, o->join, o->miter_limit, r, size);
                if (o->placement != OutlinePlacement::inside && outline != 0) {
                    shadow = effect_code(StrokeOp::a_or_b, o->join, o->miter_limit, std::max(r, grown), size);
                }
            }
        }
        if (const auto& sh = e.shadow) {
            // The offset on the glyph's subpixel grid, so that the shadow takes the glyph's steps.
            const double dx = std::round(static_cast<double>(sh->offset_x) * steps) / steps;
            const double dy = std::round(static_cast<double>(sh->offset_y) * steps) / steps;
            submit_layer(glyph, {source, shadow, blur_code(sh->blur)}, fx.shadow_color, fx.first_order, kStackShadow,
                         dx, dy, visible, contrast);
        }
        // The glow: the shadow's source, unmoved and blurred.
        if (const auto& g = e.glow) {
            submit_layer(glyph, {source, shadow, blur_code(g->radius)}, fx.glow_color, fx.first_order, kStackGlow, 0.0,
                         0.0, visible, contrast);
        }
        if (outline != 0) {
            const uint32_t order = outline_stack == kStackOutlineUnder ? fx.first_order : fx.last_order;
            submit_layer(glyph, {source, outline}, fx.outline_color, order, outline_stack, 0.0, 0.0, visible, contrast);
        }
    }
    if (face == 0) {
        submit(glyph, visible, contrast, kStackGlyph);
    } else {
        const std::array<float, 4> colour_of{glyph.color[0], glyph.color[1], glyph.color[2], glyph.color[3]};
        submit_layer(glyph, {glyph.key.glyph, face}, colour_of, glyph.paint_order, kStackGlyph, 0.0, 0.0, visible,
                     contrast);
    }
}

// A layer of `glyph` of the outline `shape` names, in `colour`, at `order` and `stack`, moved by
// (dx, dy) pixels. Layers around the glyph are flat: filled with `colour`, not the glyph's paint.
void FrameRequests::submit_layer(const GlyphInstance& glyph, const LayerShape& shape,
                                 const std::array<float, 4>& colour, uint32_t order, uint32_t stack, double dx,
                                 double dy, const VkRect2D* visible, const GlyphContrast& contrast) {
    const HeldGlyph own = fonts_.glyph(glyph.key);
    GlyphInstance layer = glyph;
    layer.key.glyph = shape.glyph;
    layer.key.effect = shape.effect;
    layer.key.blur = shape.blur;
    if (stack != kStackGlyph) {
        layer.paint = kNoPaint;
        layer.colour_glyph = kNoColourGlyph;
    }
    if (shape.effect != 0 && !fonts_.derive(layer.key)) {
        ++stats_.failed_effects;
        return;
    }
    const HeldGlyph held = shape.effect != 0 ? fonts_.glyph(layer.key) : own;
    if (!held.record) {
        ++stats_.failed_effects;
        return;
    }
    // The derived outline's rect about the same pen.
    const GlyphRect own_rect = glyph_rect(*own.record, glyph.key), rect = glyph_rect(*held.record, layer.key);
    layer.x = glyph.x - own_rect.x + rect.x;
    layer.y = glyph.y - own_rect.y + rect.y;
    layer.width = rect.width;
    layer.height = rect.height;
    if (!moved(*held.record, layer, dx, dy)) {
        ++stats_.failed_effects;
        return;
    }
    std::copy(colour.begin(), colour.end(), std::begin(layer.color));
    layer.paint_order = order;
    submit(layer, visible, contrast, stack);
}

// One instance at its final key: culled, admitted whole, or kept for admit_clipped() with its
// visible part.
void FrameRequests::submit(const GlyphInstance& glyph, const VkRect2D* visible, const GlyphContrast& contrast,
                           uint32_t stack) {
    if (!visible) {
        admit(glyph, TexelRect{0, 0, glyph.width, glyph.height}, contrast, stack);
        return;
    }
    if (glyph.width == 0 || glyph.height == 0) return;
    // The visible texels of the glyph's rect.
    const int64_t vx0 = visible->offset.x, vy0 = visible->offset.y;
    const int64_t vx1 = vx0 + visible->extent.width, vy1 = vy0 + visible->extent.height;
    const int64_t x0 = std::max<int64_t>(vx0 - glyph.x, 0), y0 = std::max<int64_t>(vy0 - glyph.y, 0);
    const int64_t x1 = std::min<int64_t>(vx1 - glyph.x, glyph.width);
    const int64_t y1 = std::min<int64_t>(vy1 - glyph.y, glyph.height);
    if (x0 >= x1 || y0 >= y1) {
        ++stats_.culled_glyphs;
        return;
    }
    const TexelRect part{static_cast<uint32_t>(x0), static_cast<uint32_t>(y0), static_cast<uint32_t>(x1 - x0),
                         static_cast<uint32_t>(y1 - y0)};
    if (part.width == glyph.width && part.height == glyph.height) {
        admit(glyph, part, contrast, stack);
    } else {
        ++stats_.clipped_glyphs;
        clipped_.push_back({glyph, part, contrast, stack});
    }
}

// Finds or places `glyph` in the atlas with `part` of its rect visible and adds it to the
// frame's pending glyphs.
// `shown` (within `part`; nullptr: all the atlas holds) is what drawn() reports of it: a
// clipped glyph shows only its visible texels, though the atlas holds a margin around them.
void FrameRequests::admit(const GlyphInstance& glyph, const TexelRect& part, const GlyphContrast& contrast,
                          uint32_t stack, const TexelRect* shown) {
    if (glyph.width == 0 || glyph.height == 0) return;
    const HeldGlyph outline = fonts_.glyph(glyph.key);
    if (!outline.record) {
        if (!fonts_.find(glyph.key.font)) ++stats_.unknown_fonts;
        ++stats_.skipped_glyphs;
        return;
    }
    const AtlasLookup lookup = look_up_or_place(*outline.font->asset, *outline.record, glyph, part);
    if (lookup.status == AtlasStatus::placed) {
        const TexelRect& held = lookup.part;
        TexelRect show = held;
        if (shown) {  // the visible texels, within what the atlas holds
            const uint32_t x0 = std::max(shown->x, held.x), y0 = std::max(shown->y, held.y);
            const uint32_t x1 = std::min(shown->x + shown->width, held.x + held.width);
            const uint32_t y1 = std::min(shown->y + shown->height, held.y + held.height);
            if (x0 >= x1 || y0 >= y1) return;
            show = {x0, y0, x1 - x0, y1 - y0};
        }
        DrawnGlyph placed{glyph,   lookup.x + (show.x - held.x), lookup.y + (show.y - held.y), 0, show.x, show.y,
                          contrast};
        placed.stack = stack;
        placed.instance.x += static_cast<int32_t>(show.x);
        placed.instance.y += static_cast<int32_t>(show.y);
        placed.instance.width = show.width;
        placed.instance.height = show.height;
        pending_.push_back({placed, lookup.entry});
    } else if (lookup.status == AtlasStatus::atlas_full || lookup.status == AtlasStatus::too_large) {
        ++stats_.failed_glyphs;
        ++stats_.skipped_glyphs;
        if (lookup.status == AtlasStatus::atlas_full) ++atlas_full_;
    }
}

// GlyphAtlas::acquire for one instance whose `part` is visible, with the curve tests it costs
// where the atlas may place it anew.
AtlasLookup FrameRequests::look_up_or_place(const FontAsset& asset, const GlyphRecord& record,
                                            const GlyphInstance& glyph, const TexelRect& part) {
    // Only a glyph the atlas may place anew needs its cost: a new one, or one held in part.
    uint64_t cost = 0;
    const AtlasEntry* resident = atlas_.entry(atlas_.find(glyph.key));
    if (!resident || resident->part.width != resident->width || resident->part.height != resident->height)
        cost = curve_tests_per_sample(asset, record, glyph.key);
    return atlas_.acquire(glyph.key, glyph.width, glyph.height, cost, part);
}

// Admits the glyphs drawn in part, each glyph once for the bounding box of its parts.
void FrameRequests::admit_clipped() {
    if (clipped_.empty()) return;
    // The instances of one key, together (sorted: a map of the keys would allocate a node each),
    // each group's parts bounded by one rect.
    clipped_order_.resize(clipped_.size());
    std::iota(clipped_order_.begin(), clipped_order_.end(), 0u);
    std::sort(clipped_order_.begin(), clipped_order_.end(), [&](uint32_t a, uint32_t b) {
        const int order = compare_keys(clipped_[a].glyph.key, clipped_[b].glyph.key);
        return order != 0 ? order < 0 : a < b;
    });
    clipped_parts_.resize(clipped_.size());
    for (size_t first = 0, end = 0; first < clipped_order_.size(); first = end) {
        const GlyphKey& key = clipped_[clipped_order_[first]].glyph.key;
        TexelRect box = clipped_[clipped_order_[first]].part;
        for (end = first + 1; end < clipped_order_.size() && clipped_[clipped_order_[end]].glyph.key == key; ++end) {
            const TexelRect& part = clipped_[clipped_order_[end]].part;
            const uint32_t x1 = std::max(box.x + box.width, part.x + part.width);
            const uint32_t y1 = std::max(box.y + box.height, part.y + part.height);
            box.x = std::min(box.x, part.x);
            box.y = std::min(box.y, part.y);
            box.width = x1 - box.x;
            box.height = y1 - box.y;
        }
        for (size_t i = first; i < end; ++i) clipped_parts_[clipped_order_[i]] = box;
    }
    for (size_t i = 0; i < clipped_.size(); ++i) {
        admit(clipped_[i].glyph, clipped_parts_[i], clipped_[i].contrast, clipped_[i].stack, &clipped_[i].part);
    }
    clipped_.clear();
}

void FrameRequests::settle(const AtlasLimits& limits) {
    admit_clipped();
    while (atlas_full_ > 0) {
        if (limits.can_grow(atlas_.config())) {
            atlas_.grow();  // record() makes the larger image and copies the old one into it
            ++stats_.atlas_grown;
        } else if (!coarsening_.coarsen()) {
            break;
        }
        atlas_.begin_frame();
        pending_.clear();
        clipped_.clear();
        // The requests count again; what draw() counted before them stays.
        const RendererStats asked = stats_;
        stats_ = {};
        stats_.moving_glyphs = asked.moving_glyphs;
        stats_.transformed_glyphs = asked.transformed_glyphs;
        stats_.projective_glyphs = asked.projective_glyphs;
        stats_.max_affine_error = asked.max_affine_error;
        stats_.atlas_grown = asked.atlas_grown;
        stats_.skipped_glyphs = unplaceable_;
        atlas_full_ = 0;
        for (const Request& r : requests_) {
            request(r.glyph, r.has_visible ? &r.visible : nullptr, r.steps, r.contrast, r.effects, r.silhouette);
        }
        admit_clipped();
    }
    stats_.subpixel_steps = coarsening_.steps();
    stats_.atlas_width = atlas_.config().width;
    stats_.atlas_height = atlas_.config().height;
    const AtlasStats now = atlas_.stats();
    coarsening_.end_frame(atlas_full_ == 0 && now.pinned_cells < now.usable_cells / 4);
}

// The glyphs this frame draws: those whose texels hold samples once the frame's work has run.
void FrameRequests::collect_drawn() {
    for (Pending& p : pending_) {
        DrawnGlyph& d = p.glyph;
        const AtlasEntry* entry = atlas_.entry(p.entry);
        d.samples = entry ? entry->samples : 0;
        if (entry && entry->samples < atlas_.config().max_samples) converged_ = false;
        if (d.samples > 0) {
            drawn_.push_back(d);
            ++stats_.drawn_glyphs;
            if (d.stack != kStackGlyph || d.instance.key.effect != 0) {
                ++stats_.effect_layers;
                stats_.effect_texels += uint64_t{d.instance.width} * d.instance.height;
            }
        } else {
            ++stats_.skipped_glyphs;
        }
    }
}

void FrameRequests::abandon_frame() {
    drawn_.clear();
    converged_ = false;
}

}  // namespace crisp::raster
