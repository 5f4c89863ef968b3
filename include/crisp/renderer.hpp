// crisp: the GPU renderer. It rasterizes glyph outlines into the atlas image with a compute shader,
// adding samples per subpixel channel for as long as a glyph stays on screen: row samples (a
// segment across the channel's sample rectangle whose covered length is exact) by default, or
// point samples.
//
// A Renderer is created from the caller's Vulkan objects and records its work into command buffers
// the caller gives; it never submits on its own. A frame whose command buffer is not submitted
// after all must be abandoned (abandon_frame()). A frame:
//
//     renderer.begin_frame();
//     renderer.draw(layout.glyphs);             // any number of times: acquires atlas entries
//     renderer.record(command_buffer);          // uploads, then one compute dispatch
//     ... the caller submits; the atlas image is ready for shaders (or copies) after it ...
//
// The caller must not have more than RendererCreateInfo::frames_in_flight recorded command buffers
// pending on the GPU at once: the renderer reuses its per-frame resources after that many frames.
//
// The atlas image (RendererCreateInfo::atlas sets its size) is VK_FORMAT_R16G16B16A16_UINT, kept in
// VK_IMAGE_LAYOUT_GENERAL. Each texel holds the coverage of its red, green and blue samples in units
// of kCoverageOne per fully covered sample, and its sample count in alpha: a channel's coverage is
// value / (kCoverageOne * alpha). After record() the image is made visible to fragment and compute
// shader reads and to transfer reads.
#pragma once

#include <crisp/export.hpp>

#include <crisp/atlas.hpp>
#include <crisp/contrast.hpp>
#include <crisp/device_features.hpp>
#include <crisp/effects.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>
#include <crisp/transform.hpp>

#include <vulkan/vulkan.h>

#include <array>
#include <memory>
#include <optional>
#include <span>

namespace crisp {

// Fixed-point units of one covered sample in the atlas accumulators. A row sample adds its covered
// fraction times kCoverageOne, dithered to a whole unit; a point sample adds 0 or kCoverageOne.
inline constexpr uint32_t kCoverageOne = 64;
// The most samples a texel can hold: 65535 / kCoverageOne.
inline constexpr uint32_t kMaxRendererSamples = 1023;
// Font pages: fonts' curves and bands are suballocated from at most this many pairs of buffers,
// each at most maxStorageBufferRange bytes (a new page holds at least 4 MiB of points, 1 MiB of
// bands, and twice the font that makes it). A renderer holds any number of fonts that fit them.
inline constexpr uint32_t kRendererFontPages = 8;

// Device memory a renderer or compositor holds: how many VkDeviceMemory objects (counting towards
// maxMemoryAllocationCount) and their bytes.
struct DeviceMemoryUse {
    uint32_t allocations = 0;
    uint64_t bytes = 0;
};

// What one sample of a texel's channel is (docs/rasterizer.md, "Row samples").
enum class SampleKind : uint32_t {
    // A horizontal segment across the channel's sample rectangle, at a height stratified over the
    // samples (van der Corput): its covered length under the nonzero rule is exact, so only y is
    // sampled. The default: at 8 and 64 samples its error is a fraction of points'.
    rows = 0,
    // A point (R2 sequence), covered or not: the seed's sample, kept to compare against.
    points = 1,
};

struct RendererCreateInfo {
    // Required: the instance `device` belongs to. crisp loads every Vulkan function it calls
    // through it, with this entry point; null: the system loader's (libvulkan.so.1, opened on
    // first use). An engine that loads Vulkan itself (volk, a dispatch table of its own) passes
    // its vkGetInstanceProcAddr, and crisp then calls exactly the functions the engine does; crisp
    // itself references no Vulkan symbol. A required function the loader does not give fails
    // create() (vulkan), naming it.
    VkInstance instance = VK_NULL_HANDLE;
    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
    // Required: the VkApplicationInfo::apiVersion `instance` was created with. crisp's shaders are
    // SPIR-V for Vulkan 1.2, which an instance of an older apiVersion may not use whatever the
    // device offers: below VK_API_VERSION_1_2, or 0 (not given), create() fails (invalid_argument).
    uint32_t instance_api_version = 0;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    uint32_t queue_family = 0;  // the family of the queue the caller submits crisp's work on
    // Required: the feature chain `device` was created with (the VkPhysicalDeviceFeatures2 its
    // VkDeviceCreateInfo::pNext held; with pEnabledFeatures, a VkPhysicalDeviceFeatures2 holding
    // those). crisp checks its needs against it, not against what the GPU offers: a feature the
    // GPU has but the device did not enable is not there. Vulkan 1.1/1.2/1.3 feature structures
    // in the chain are read, others skipped; read during create() only. add_crisp_features()
    // (device_features.hpp) fills one in before device creation.
    const VkPhysicalDeviceFeatures2* enabled_features = nullptr;
    const VkAllocationCallbacks* allocator = nullptr;
    // The caller's pipeline cache: crisp creates its pipelines through it (at create() only), so
    // that a program that saves the cache's data starts without compiling them again. Optional.
    VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
    uint32_t frames_in_flight = 2;  // 1 to 8
    AtlasConfig atlas;              // max_samples at most kMaxRendererSamples
    // Bytes the atlas image may grow to (8 a texel). When a frame's glyphs do not fit, the atlas
    // doubles on both axes (entries keep their places; the image is copied into a larger one),
    // while the larger image fits this budget and the device's maxImageDimension2D; past it,
    // glyphs take coarser subpixel steps (RendererStats::subpixel_steps). 0, or less than twice
    // the initial size: the atlas never grows. The atlas never shrinks.
    uint64_t atlas_memory_budget = 0;
    SubpixelLayout layout;  // default: rgb
    // Where the three channels sample the same rows (stripe layouts), solve each curve's roots
    // once for all three. Off only to measure what it saves.
    bool shared_row_roots = true;
    // Row samples by default; points to measure against. Any other value: create() returns
    // invalid_argument.
    SampleKind sample_kind = SampleKind::rows;
    // How the compositor blends the glyphs' coverage over what is behind them (contrast.hpp): the
    // contrast model by default, ContrastMode::linear for coverage as it is. It changes no atlas
    // texel. A setting validate_text_contrast() refuses fails create() (invalid_argument).
    TextContrast contrast;
    // Bitmap glyphs (CBDT, sbix): each image drawn is box-filtered into one layer of an array image of
    // bitmap_layers layers of bitmap_layer_side texels a side (a power of two, 16..1024), with its
    // mips, made at the first bitmap glyph drawn. A frame that draws more images than there are
    // layers draws the rest without their image (RendererStats::bitmap_misses). 1..4096 layers.
    uint32_t bitmap_layers = 256;
    uint32_t bitmap_layer_side = 128;
};

// How one draw() call shows its glyphs, without a new layout: where, in which colour, at which depth,
// and whether they move. Every field at its default draws the glyphs as laid out.
struct DrawOptions {
    // Pixels added to every glyph's pen (y down). A label that follows an object is drawn again
    // with a new offset, not laid out again: the glyphs' subpixel positions and rects follow (at
    // kSubpixelSteps per pixel, coarser where the frame or motion says so). A zero offset keeps the
    // layout's positions and keys as they are, so a snapped layout stays snapped under whole-pixel
    // offsets. Non-finite offsets, or pens moved beyond 2^24 px, draw nothing (skipped_glyphs).
    float offset_x = 0.0f;
    float offset_y = 0.0f;
    // A colour for every glyph instead of its layout's: sRGB, straight alpha, as TextStyle::color
    // (clamped to [0, 1]; NaN reads as 0). A hover colour is a draw option, not a layout.
    std::optional<std::array<float, 4>> color;
    // A depth for every glyph instead of its layout's (for world-space labels:
    // depth_from_view_projection()). Not finite: the compositor clamps it, as any depth.
    std::optional<float> depth;
    // Where the glyphs can be seen, as draw(glyphs, visible); nullopt: everywhere.
    std::optional<VkRect2D> visible;
    // The caller's name for what these glyphs are (a label, a list row), the same every frame; 0
    // for none. The renderer remembers where each named draw's first glyph was: a draw whose text
    // moved within the last kMotionSettleFrames frames is moving text, and its glyphs take
    // quarter-pixel subpixel steps (kMovingSubpixelSteps), so that a label gliding a fraction of a
    // pixel a frame reuses at most 4 x 4 atlas entries per glyph and keeps gathering samples
    // instead of starting over in a new entry every frame. A draw whose transform or plane changed
    // lately is moving too, and its keys take kMovingTransformSteps. Once it rests, it returns to
    // the fine steps. Counted in RendererStats::moving_glyphs.
    uint64_t id = 0;
    // Contrast settings for these glyphs instead of the renderer's (set_contrast()). A setting
    // validate_text_contrast() refuses draws nothing (skipped_glyphs).
    std::optional<TextContrast> contrast;
    // The CPAL palette of colour glyphs instead of their layout's (TextStyle::palette). A palette
    // past a font's palettes draws with its palette 0.
    std::optional<uint32_t> palette;
    // Rotated, scaled, sheared or mirrored text (transform.hpp, docs/transforms.md): every glyph's
    // pen and outline mapped about the pivot, then moved by the offset. Each glyph stays an
    // axis-aligned rect of the target whose texels hold the coverage of its transformed outline,
    // keyed by the transform's linear part quantized to 1/256 px per em (1/4 px per em while a named
    // draw's transform changes: see `id`). Animate with an id: a transform that changes every
    // frame without one makes every glyph a new atlas entry every frame (docs/transforms.md: a 4K
    // screen of text, 27 ms of GPU time a frame unnamed, 0.54 ms named, on an H200). A transform
    // valid_transform() refuses (not finite, a determinant below 2^-16) draws nothing
    // (skipped_glyphs).
    std::optional<TextTransform> transform;
    // Text on a plane in world space seen through a view-projection (transform.hpp): each glyph at
    // the local affine map of the projection at its centre, or exactly projective where that
    // would be more than kMaxLocalAffineError px off, at its centre's depth (unless `depth` is
    // given). The offset moves the text within the plane, in layout pixels. Glyphs with a bbox
    // corner behind the eye or outside the depth range are culled (culled_glyphs). A plane
    // valid_plane() refuses, or a plane together with a transform, draws nothing (skipped_glyphs).
    // Glyphs already transformed (a key with a linear part) are not transformed again: skipped.
    std::optional<TextPlane> plane;
    // An outline, a hard drop shadow and a weight for every glyph (effects.hpp, docs/effects.md):
    // each a layer of the glyph at its depth, under or over it (DrawnGlyph::stack), its outline
    // derived from the glyph's on the CPU and cached per glyph and shape in em until its font is
    // removed. Effects validate_text_effects() refuses draw nothing (skipped_glyphs); a glyph whose
    // effect reaches past kMaxEffectReachEm, or whose stroke passes limits::kMaxStrokeCurves, is
    // drawn without that layer (failed_effects). A colour glyph's shadow, glow and outline are of
    // its silhouette, the union of its layers (kSilhouetteGlyph), each of its layers weighted; a
    // bitmap glyph has no outline: it is drawn as it is, and counts once in failed_effects.
    std::optional<TextEffects> effects;
};

// Subpixel steps per pixel of moving text (DrawOptions::id).
inline constexpr uint32_t kMovingSubpixelSteps = 4;
// Frames a named draw must rest before its text counts as static again.
inline constexpr uint32_t kMotionSettleFrames = 8;

// How a layer of a colour glyph is filled this frame (the renderer resolves each layer's Paint of
// the asset for the draw's palette, colour and the glyph's place): DrawnFrame::paints. Layers filled
// with one solid colour and no clip box need none: their instance's colour is that colour.
struct FramePaint {
    PaintKind kind = PaintKind::solid;
    PaintExtend extend = PaintExtend::pad;
    uint32_t first_stop = 0;  // in DrawnFrame::stops
    uint32_t stop_count = 0;
    // From the target's pixels (x right, y down, pixel centres at + 0.5, the glyphs' pixel space) to
    // the paint's own space: q.x = to_paint[0] x + to_paint[1] y + to_paint[2], q.y = to_paint[3] x +
    // to_paint[4] y + to_paint[5].
    float to_paint[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    float geometry[6] = {};  // as Paint::geometry
    // The clip box in pixels (x0, y0, x1, y1): coverage is multiplied by the part of each pixel inside.
    float clip[4] = {-1.0e30f, -1.0e30f, 1.0e30f, 1.0e30f};
    uint32_t image_layer = 0;              // image paints: the layer of DrawnFrame::images
    float image_extent[2] = {1.0f, 1.0f};  // the part of the layer (u, v) the image fills
    float opacity = 1.0f;                  // the text colour's alpha, times every stop's colour
};

// A stop of a FramePaint's colour line: its colour premultiplied and sRGB-encoded (gradients
// interpolate in that space, then decode), and its offset.
struct FrameStop {
    float colour[4] = {};
    float offset = 0.0f;
};

// DrawnGlyph::stack, back to front: at equal depth and paint order a layer of a smaller stack lies
// behind one of a larger.
inline constexpr uint32_t kStackShadow = 0;        // a drop shadow (TextEffects::shadow)
inline constexpr uint32_t kStackGlow = 1;          // a glow (TextEffects::glow)
inline constexpr uint32_t kStackOutlineUnder = 2;  // an outside outline
inline constexpr uint32_t kStackGlyph = 3;         // the glyph (or its colour layers), weighted or not
inline constexpr uint32_t kStackOutlineOver = 4;   // an inside or centred outline

// A glyph drawn this frame whose rect holds samples: where its texels are in the atlas.
// A glyph drawn clipped (draw() with a visible rect) shows only the texels inside that rect:
// `instance` then describes that part (x, y, width and height narrowed to it), and part_x, part_y
// say where the part starts in the glyph's whole rect. The compositor draws exactly that, so a
// draw's visible rect clips its text to the pixel (the atlas holds a margin around the part, so
// that text scrolling within the rect keeps its samples).
struct DrawnGlyph {
    GlyphInstance instance;
    uint32_t atlas_x = 0;  // texel of the (part's) top-left corner in the atlas image
    uint32_t atlas_y = 0;
    uint32_t samples = 0;  // samples every texel holds once this frame's work has run (texels of
                           // a split sample in progress hold one more)
    uint32_t part_x = 0;
    uint32_t part_y = 0;
    // How the compositor blends its coverage (RendererCreateInfo::contrast, DrawOptions::contrast),
    // resolved for its size; a DrawnGlyph made by hand is linear unless it says otherwise.
    GlyphContrast contrast;
    // A colour layer's fill: an index in DrawnFrame::paints; kNoPaint: instance.color.
    uint32_t paint = kNoPaint;
    // Where it lies among the layers of its depth and paint order (kStack*): effect layers under
    // their glyph take the paint order of their draw's first glyph, those over it its last, so
    // that every shadow and outside outline of a draw lies under every glyph of it.
    uint32_t stack = kStackGlyph;
};

// What a recorded frame hands the compositor (Renderer::drawn_frame(), Compositor::record()): the
// glyphs drawn with their atlas places, and the atlas they are read from. Tools and tests may make
// their own (a subset of the glyphs, say) over the same atlas.
struct DrawnFrame {
    std::span<const DrawnGlyph> glyphs;
    // The renderer's atlas image (R16G16B16A16_UINT accumulators, see record_atlas_readback) in
    // VK_IMAGE_LAYOUT_GENERAL. The barrier at the end of Renderer::record() makes this frame's
    // writes to it readable by compute and fragment shaders; the compositor records none on it.
    VkImageView atlas = VK_NULL_HANDLE;
    // The fills of colour layers (DrawnGlyph::paint) and their stops.
    std::span<const FramePaint> paints;
    std::span<const FrameStop> stops;
    // Bitmap glyphs' images: a 2D array view of R8G8B8A8_SRGB layers with their mips (premultiplied),
    // in VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL once Renderer::record()'s commands have run.
    // Required by the compositor (a renderer always has one, a single blank layer until it draws a
    // bitmap glyph).
    VkImageView images = VK_NULL_HANDLE;
    // The renderer's frame these come from (Renderer::frame()), which Compositor::abandon_frame()
    // names; 0 for a DrawnFrame made by hand.
    uint64_t frame = 0;

    // The same frame with other glyphs (a subset of these, say): the atlas, paints and images kept.
    DrawnFrame with_glyphs(std::span<const DrawnGlyph> other) const {
        DrawnFrame same = *this;
        same.glyphs = other;
        return same;
    }
};

struct RendererStats {
    uint32_t drawn_glyphs = 0;    // draw()n glyphs with outlines this frame
    uint32_t skipped_glyphs = 0;  // not drawable this frame: no samples yet, atlas full or too large
    uint32_t failed_glyphs = 0;   // not drawn: too_large, or atlas_full even at whole-pixel positions
                                  // (atlas().stats() counts every refused request)
    // Instances drawn at a coarser subpixel position than their layout's because the atlas had no
    // room for all of them (see subpixel_steps): the pen moves by at most half a step.
    uint32_t coarsened_glyphs = 0;
    // The subpixel steps per pixel glyphs were drawn at this frame (after record()): kSubpixelSteps
    // (the layouts' own), or 4 or 1 after a frame the atlas could not hold at the finer steps. A
    // frame that finds the atlas full starts over at the next coarser steps, so visible glyphs are
    // not dropped; the steps get finer again once the frames' glyphs have taken under a quarter of
    // the atlas for 120 frames (twice as long each time the finer steps then did not fit, up to
    // 7680 frames).
    uint32_t subpixel_steps = kSubpixelSteps;
    // The atlas's size after this frame, and how many times it doubled this frame to hold the
    // frame's glyphs (RendererCreateInfo::atlas_memory_budget).
    uint32_t atlas_width = 0;
    uint32_t atlas_height = 0;
    uint32_t atlas_grown = 0;
    uint32_t moving_glyphs = 0;  // instances of moving named draws (DrawOptions::id), at kMovingSubpixelSteps
    // Instances draw() placed at a transform or on a plane (DrawOptions::transform, ::plane), those of
    // a plane whose key kept its perspective (their local affine map was more than
    // kMaxLocalAffineError off), and the largest local-affine error (px) among the others.
    uint32_t transformed_glyphs = 0;
    uint32_t projective_glyphs = 0;
    float max_affine_error = 0.0f;
    uint32_t unknown_fonts = 0;   // instances whose FontId was never added
    uint32_t culled_glyphs = 0;   // instances wholly outside draw()'s visible rect
    uint32_t clipped_glyphs = 0;  // instances partly outside it: only their visible part is rasterized
    uint32_t colour_layers =
        0;                      // drawn glyphs that are layers of colour glyphs (DrawnGlyph::paint or a palette colour)
    uint32_t frame_paints = 0;  // DrawnFrame::paints this frame
    uint32_t bitmap_uploads = 0;  // bitmap glyph images decoded and uploaded this frame
    uint32_t bitmap_misses = 0;   // image layers drawn without their image (no room, or a bad image)
    uint32_t work_items = 0;      // glyphs given samples this frame
    uint32_t workgroups = 0;      // compute workgroups dispatched
    uint64_t samples = 0;         // samples scheduled this frame (all channels count once)
    uint64_t curve_tests = 0;     // the atlas's estimate of this frame's curve tests (at most the
                                  // atlas frame_budget, or one texel's sample)
    uint64_t upload_bytes = 0;    // bytes copied into GPU buffers while recording this frame
    // Effects (DrawOptions::effects): the effect layers drawn this frame (among drawn_glyphs) and
    // the atlas texels their rects take; layers not drawn (past kMaxEffectReachEm, a stroke past
    // limits::kMaxStrokeCurves, a bitmap glyph, a silhouette past limits::kMaxSilhouetteCurves);
    // and the derived outlines held for them,
    // those made this frame and their bytes on the GPU.
    uint32_t effect_layers = 0;
    uint64_t effect_texels = 0;
    uint32_t failed_effects = 0;
    uint32_t derived_glyphs = 0;
    uint32_t derived_made = 0;
    uint64_t derived_bytes = 0;
};

class CRISP_API Renderer {
public:
    // Creates the atlas image, buffers and the compute pipeline. Fails with ErrorCode::vulkan when
    // the device is below Vulkan 1.2 or lacks what the rasterizer needs (named in the message:
    // shaderStorageBufferArrayDynamicIndexing, storage images of R16G16B16A16_UINT,
    // 2 + 2 * kRendererFontPages storage buffers per stage), and with
    // ErrorCode::invalid_argument for a bad atlas config (see GlyphAtlas::create), max_samples above
    // kMaxRendererSamples, frames_in_flight outside 1..8, an invalid layout, or a sample_kind
    // that is neither rows nor points.
    static Result<Renderer> create(const RendererCreateInfo& info);

    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;
    // Destroys every object the renderer made. The caller makes sure the GPU is done with them
    // (e.g. vkDeviceWaitIdle) first.
    ~Renderer();

    // Makes a font drawable. The renderer keeps a pointer: the Font must outlive it (or its
    // removal). Its curves and bands get ranges of a font page and are copied to the GPU by the
    // next record(). Errors: invalid_argument when a font with the same id is held (or removed
    // but not yet gone: add it after the next begin_frame()), or the font pages have no room for
    // it; vulkan when its buffers cannot be made or it exceeds maxStorageBufferRange (the message
    // says which). A failed add_font() changes nothing.
    Status add_font(const Font& font);

    // Removes a font at the next begin_frame(): its atlas entries are evicted, its page ranges
    // are freed once the frames that may read them are done (frames_in_flight), and its id may be
    // added again. A font page that no font uses then frees its buffers; of its memory the
    // renderer keeps at most one block of up to 64 MiB per memory type for the
    // next buffers, and none made for one larger buffer (device_memory() shows it). The frame already drawn or recorded
    // still shows it; from the next one on its instances count as unknown_fonts. After that begin_frame() the Font may
    // be destroyed. Errors: invalid_argument for an id not held (or already being removed); nothing changes.
    Status remove_font(FontId id);

    // Replaces the subpixel layout. Every accumulated sample is invalidated: glyphs restart their
    // sample schedule. An invalid layout is refused (invalid_argument) and the old one stays.
    Status set_subpixel_layout(const SubpixelLayout& layout);
    const SubpixelLayout& subpixel_layout() const;
    // What each sample is (RendererCreateInfo::sample_kind), fixed at create().
    SampleKind sample_kind() const;
    // Replaces the contrast settings of draws whose options give none, from the next draw() on.
    // The atlas is untouched: only compositing changes. A setting validate_text_contrast() refuses
    // is refused (invalid_argument) and the old one stays.
    Status set_contrast(const TextContrast& contrast);
    const TextContrast& contrast() const;

    // Starts a frame: unpins the atlas and forgets last frame's drawn glyphs. The frame gets the
    // next number (frame()).
    void begin_frame();
    // The number of the frame begin_frame() started last: 1, 2, ... (0 before the first). Each
    // begin_frame() takes a new one, an abandoned frame's included: it names the frame to
    // abandon_frame() here and, through DrawnFrame::frame, to Compositor::abandon_frame().
    uint64_t frame() const;

    // Draws glyph instances this frame: finds or places each in the atlas and pins it (the
    // instances are copied). Where the atlas has no room for every glyph of the frame, record()
    // starts the frame over at coarser subpixel steps (RendererStats::subpixel_steps) rather than
    // drop any. Instances of unknown fonts, glyphs too large for the atlas and glyphs that do not
    // fit even at whole-pixel positions are counted in stats() and skipped, never a crash.
    void draw(std::span<const GlyphInstance> glyphs);

    // The same for a target of which only `visible` can be seen, in the glyphs' pixel space (for
    // the compositor: {{0, 0}, CompositeTarget::rect.extent}). A glyph wholly outside it is not
    // drawn (culled_glyphs); one partly outside gets samples only for its visible part and a
    // margin (kAtlasPartMargin texels a side; clipped_glyphs), so a 2000 px glyph on a 200 px
    // target costs what 200 px of it cost, and fits an atlas too small for all of it. The part
    // is decided in record(), over all of the frame's draws of the same glyph. An empty
    // `visible` culls everything.
    void draw(std::span<const GlyphInstance> glyphs, const VkRect2D& visible);

    // The same with per-draw options: an offset, a colour, a depth, a visible rect and a name that
    // lets moving text take coarser subpixel steps (see DrawOptions). drawn() reports the glyphs
    // as drawn: moved, recoloured (in linear colour, as GlyphInstance::color) and at their depth.
    void draw(std::span<const GlyphInstance> glyphs, const DrawOptions& options);

    // Records this frame's work into `command_buffer` (which must be recording, outside a render
    // pass, on a queue of RendererCreateInfo::queue_family): pending font uploads, the work list,
    // one compute dispatch, and a barrier that makes the atlas readable. Call once per frame after
    // the draws. Errors: invalid_argument for a record() without begin_frame() before it (also
    // after abandon_frame()) or a second one in a frame, recording nothing and changing nothing;
    // vulkan, which leaves the command buffer without crisp's commands.
    Status record(VkCommandBuffer command_buffer);

    // Takes back what record() committed for a frame that will never be submitted (a swapchain out
    // of date, a minimized window, any frame an engine drops): font uploads wait for the next
    // record(), the atlas image's first layout change is recorded again, and the atlas forgets the
    // samples and the turn this frame scheduled (see GlyphAtlas::abandon_frame). `frame` is the
    // frame to take back (frame()): call it after record() and before the next begin_frame(), and
    // discard the command buffer unsubmitted. The abandoned frame does not count towards
    // frames_in_flight. For the current frame without a record() since begin_frame(), or already
    // taken back, it does nothing. Errors: invalid_argument, taking nothing back, for any other
    // frame (an earlier one, which may be on the GPU). A frame neither abandoned nor submitted
    // is a programmer error: its samples count as if they were in the atlas image, and their
    // texels stay wrong.
    Status abandon_frame(uint64_t frame);

    // The glyphs draw()n this frame that hold samples once this frame's work has run, with their
    // atlas positions (valid after record()).
    std::span<const DrawnGlyph> drawn() const;
    // What the compositor takes for this frame: drawn() and the atlas view (valid after record(),
    // until the next begin_frame()).
    DrawnFrame drawn_frame() const;

    // True when every glyph drawn this frame holds max_samples: static text has converged and
    // record() schedules no work.
    bool converged() const;

    // Records a copy of the whole atlas image into `buffer` (at offset 0; width * height texels of
    // 4 uint16 each, row-major: red, green, blue hits in kCoverageOne units, then the sample
    // count), with the barriers and layout changes around it. For tools and tests that read the
    // accumulators back; call after record() in the same command buffer or a later one.
    void record_atlas_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const;

    const RendererStats& stats() const;
    // The VkDeviceMemory objects the renderer holds now and their bytes: its buffers share a few
    // blocks (4 MiB, growing to 64 MiB as more are needed), and the atlas image has its own.
    DeviceMemoryUse device_memory() const;
    // The driver's statistics of the rasterizer's compiled shader (registers, spills, ...): see
    // ShaderStatistic for when there are any; empty otherwise.
    const std::vector<ShaderStatistic>& shader_statistics() const;
    const GlyphAtlas& atlas() const;
    VkImage atlas_image() const;
    VkImageView atlas_view() const;

private:
    struct State;
    explicit Renderer(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

}  // namespace crisp
