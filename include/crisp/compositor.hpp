// crisp: the GPU compositor. It composites the glyphs a Renderer rasterized this frame, reading
// their coverage from the atlas, with order-independent transparency (docs/compositing.md).
//
// Per fragment and channel: coverage k = sum / (kCoverageOne * count) from the atlas, opacity
// o = a * k, transmittance T = 1 - o and premultiplied light L = c * o, with c the glyph's linear
// colour and a its alpha. Smaller depth is nearer; at equal depth the later paint order is in front.
//
// Three ways to put text on screen, per frame:
//   - record(): the tile path (the default of every tool). Into the caller's storage image, in
//     compute: quads binned into 16 x 16 screen tiles on the GPU, each tile composited front to
//     back, exactly, in workgroup memory, per channel over whatever the image holds.
//   - record_draw(): inside the caller's render pass (dynamic rendering), for targets that cannot
//     be storage images (an sRGB swapchain image): quads sorted on the CPU, drawn back to front
//     with dual-source blending per channel.
//   - record_reference(): the comparison modes (unsorted, WBOIT and the exact per-pixel linked
//     lists) into the compositor's own RGBA32F image over a flat background; made only when
//     CompositorCreateInfo::reference_modes asks for them.
//
// A frame, after the renderer's record() in the same command buffer (or a later one):
//
//     compositor.record(command_buffer, renderer.drawn_frame(), target);
//
// Like the Renderer, the compositor never submits, and the caller must not have more than
// CompositorCreateInfo::frames_in_flight of its recorded command buffers pending at once; each
// record*() call takes one frame slot, in turn, the slot of the call frames_in_flight calls before.
// The frame-slot rule, which the compositor checks: an engine that paces its frames by the
// renderer's (waiting for frame F - frames_in_flight before recording frame F) may reuse a slot
// only when the renderer frame it last held is at least frames_in_flight frames back. A record
// call for DrawnFrame::frame F whose slot last held frame P with P < F < P + frames_in_flight
// (more than frames_in_flight record calls within frames_in_flight renderer frames: two calls in
// one frame, say) is refused with invalid_argument, recording nothing, since P's composite may
// still be on the GPU. Compositing one renderer frame again (F equal to P: several modes, repeated
// timing) is allowed, and the caller must have waited for the earlier calls then; frames of 0 (a
// DrawnFrame made by hand) are not checked.
#pragma once

#include <crisp/export.hpp>

#include <crisp/renderer.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace crisp {

enum class CompositeMode {
    tiled,     // record(): screen tiles in workgroup memory, into the caller's image
    draw,      // record_draw(): sorted quads blended inside the caller's render pass
    unsorted,  // reference: premultiplied "over" in submission order: what no OIT gives
    wboit,     // reference: weighted blended OIT (McGuire and Bavoil 2013), equation (10)
    exact,     // reference: per-pixel linked lists, sorted: the ground truth
};
// "tiled", "draw", "unsorted", "wboit", "exact".
CRISP_API const char* composite_mode_name(CompositeMode mode);
// The mode of that name; nullopt for any other string.
CRISP_API std::optional<CompositeMode> parse_composite_mode(std::string_view name);

// The most layers the tile path's layered way keeps per pixel (CompositorCreateInfo::tile_layers).
inline constexpr uint32_t kMaxCompositeLayers = 8;
// The most fragments the exact mode sorts per pixel; more are dropped and counted.
inline constexpr uint32_t kMaxExactFragmentsPerPixel = 64;

// The image formats record() composites into (as storage images). 8-bit ones hold sRGB-encoded
// colour, which the shader decodes and encodes; float ones hold linear colour. A B8G8R8A8_UNORM
// image is seen either through a view of its own format (the device needs
// shaderStorageImageReadWithoutFormat and WriteWithoutFormat: storage_without_format) or through
// an R8G8B8A8_UNORM view of an image made with VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT (any device
// that stores R8G8B8A8; CompositeTarget::view_format says so).
inline constexpr VkFormat kTileTargetFormats[] = {
    VK_FORMAT_R8G8B8A8_UNORM,
    VK_FORMAT_B8G8R8A8_UNORM,
    VK_FORMAT_R16G16B16A16_SFLOAT,
    VK_FORMAT_R32G32B32A32_SFLOAT,
};
// The most quads a screen tile's list holds in workgroup memory (CompositorCreateInfo::tile_capacity).
inline constexpr uint32_t kMaxTileCapacity = 1024;

struct CompositorCreateInfo {
    // Required: the instance `device` belongs to, and the entry point crisp loads its Vulkan
    // functions through, as RendererCreateInfo::instance and get_instance_proc_addr (null: the
    // system loader's).
    VkInstance instance = VK_NULL_HANDLE;
    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
    // Required: the apiVersion `instance` was created with, as RendererCreateInfo's: below
    // VK_API_VERSION_1_2, or 0, create() fails (invalid_argument).
    uint32_t instance_api_version = 0;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    const VkAllocationCallbacks* allocator = nullptr;
    // The caller's pipeline cache, as RendererCreateInfo::pipeline_cache. Optional.
    VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
    uint32_t frames_in_flight = 2;  // 1 to 8
    // Required: the feature chain `device` was created with, as RendererCreateInfo::enabled_features.
    // What each path needs is checked against it, never against what the GPU offers.
    const VkPhysicalDeviceFeatures2* enabled_features = nullptr;

    // ---- The tile path (record()). It needs no device feature beyond the renderer's; where the
    // device was created with shaderStorageImageReadWithoutFormat and
    // shaderStorageImageWriteWithoutFormat it also takes B8G8R8A8_UNORM views.
    // Quads a tile's list holds in workgroup memory (8 bytes each): a power of two, 4 to
    // kMaxTileCapacity. A longer list takes the layered way with K = tile_layers.
    uint32_t tile_capacity = 256;
    uint32_t tile_layers = 8;  // 1..kMaxCompositeLayers
    // Static text: where a frame's glyphs are those the same frame slot binned frames_in_flight
    // frames ago (same rects, atlas positions, colours, depths and order, same rect size), skip
    // the upload and the binning passes and composite from the bins it has. Off only to measure
    // what binning costs.
    bool reuse_static_bins = true;
    // The most (glyph, tile) pairs a frame bins at once, 32 bytes each (default 2^22: 128 MiB),
    // at most what the device's maxStorageBufferRange reaches and at least the target's tiles. A
    // frame with more (thousands of glyphs each covering much of the target) is binned and
    // composited in batches of consecutive glyphs, back to front, each over the image the ones
    // behind it left: the same image up to the target format's rounding between batches (and
    // static text's bins are then not reused). So the bins' memory stays within this bound
    // whatever the glyphs cover. 0 is refused.
    uint32_t tile_bin_pairs = 1u << 22;

    // ---- The draw path (record_draw()): the colour attachment format of the caller's render
    // pass; VK_FORMAT_UNDEFINED makes no draw pipeline. The device must have been created with
    // dynamicRendering and dualSrcBlend, and the format must blend. Blending is linear only where the format
    // is _SRGB or floating point.
    VkFormat draw_format = VK_FORMAT_UNDEFINED;
    // The depth attachment format of that render pass, for world-space text among the caller's
    // geometry: each glyph is depth-tested at its depth (GlyphInstance::depth, e.g. from
    // depth_from_view_projection()) against the pass's depth attachment, LESS_OR_EQUAL, and never
    // writes it, so a label behind a wall is hidden by the wall. VK_FORMAT_UNDEFINED (the
    // default): the pass has no depth attachment and text is drawn over everything. A format
    // that cannot be a depth attachment is refused (vulkan).
    VkFormat draw_depth_format = VK_FORMAT_UNDEFINED;

    // ---- The reference modes (record_reference()): off unless asked for, since they hold
    // per-pixel buffers over the whole target (36 bytes a pixel, and the exact node pool).
    bool reference_modes = false;
    // The reference target's size, each 1..16384 (ignored without reference_modes).
    uint32_t width = 0;
    uint32_t height = 0;
    // The device must have been created with fragmentStoresAndAtomics and dualSrcBlend enabled.
    // The exact mode's node pool, in nodes per target pixel on average (each node 36 bytes);
    // 0 makes no pool and the exact mode unavailable. At most 64.
    uint32_t exact_nodes_per_pixel = 16;
};

// How the quad passes of the wboit and exact reference modes run (unsorted is always rasterized:
// it needs the blend unit's submission order).
enum class QuadPath {
    raster,   // quads drawn, one fragment per pixel, early fragment tests (the seed's way)
    compute,  // one compute invocation per pixel of each 8 x 8 tile of each quad: no rasterizer
};
// "raster", "compute".
CRISP_API const char* quad_path_name(QuadPath path);
// The path of that name; nullopt for any other string.
CRISP_API std::optional<QuadPath> parse_quad_path(std::string_view name);

// The caller's image the tile path composites into.
struct CompositeTarget {
    // A 2D view of one mip level and layer, of `format`, of an image made with
    // VK_IMAGE_USAGE_STORAGE_BIT. When the command buffer reaches crisp's commands the image must
    // be in VK_IMAGE_LAYOUT_GENERAL with earlier writes made visible to
    // VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT (VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    // crisp reads and writes it at that stage, leaves it in GENERAL and records no barrier on it:
    // the caller's next use needs a barrier from COMPUTE_SHADER / SHADER_WRITE.
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;  // the image's: one of kTileTargetFormats
    // The view's format where it differs from the image's (R8G8B8A8_UNORM over B8G8R8A8_UNORM);
    // VK_FORMAT_UNDEFINED: the same.
    VkFormat view_format = VK_FORMAT_UNDEFINED;
    VkExtent2D extent{};  // the image's size
    // Where text lands: glyph pixel (0, 0) is rect.offset, and nothing outside the rect is read
    // or written. An extent of 0 x 0 means the whole image.
    VkRect2D rect{};
};

struct CompositeParams {
    CompositeMode mode = CompositeMode::exact;  // a reference mode
    QuadPath path = QuadPath::raster;
    // Linear colour and straight alpha of the background behind all glyphs.
    float background[4] = {1.0f, 1.0f, 1.0f, 1.0f};
};

struct CompositorStats {
    // This frame (known when record*() returns):
    CompositeMode mode = CompositeMode::tiled;
    QuadPath path = QuadPath::raster;  // the path this frame's quad passes took
    uint32_t tiles = 0;                // compute path: 8 x 8 tiles dispatched
    bool bins_reused = false;          // tiled: the glyphs were unchanged, binning was skipped
    uint32_t tile_batches = 0;         // tiled: batches binned (1 unless the pairs passed tile_bin_pairs)
    uint32_t quads = 0;                // glyph quads drawn
    uint64_t buffer_bytes = 0;         // buffers this frame used: tiled and draw: quads and bins;
                                       // reference modes: their per-pixel buffers over the whole target
    // From the last frame whose GPU work has completed (frames_in_flight frames ago), if any:
    bool measured = false;
    uint64_t measured_frame = 0;    // which frame (1 = the first record())
    uint32_t max_overlap = 0;       // tiled and exact: most fragments one pixel had
    uint32_t tail_pixels = 0;       // tiled: pixels with fragments past K (the layered way)
    uint64_t exact_lost_nodes = 0;  // exact: fragments the node pool could not hold
    uint64_t exact_dropped = 0;     // exact: fragments past kMaxExactFragmentsPerPixel
    // tiled: the last completed tiled frame's tiles with quads, how many took the exact way (their
    // list fit) and the layered way, the (quad, tile) pairs binned; max_overlap and tail_pixels
    // above count for it too. A batched frame's (tile_batches above 1) are summed over its
    // batches, a tile counted once in each batch it is busy in; max_overlap is the most of one batch.
    uint32_t busy_tiles = 0;
    uint32_t exact_tiles = 0;
    uint32_t layered_tiles = 0;
    uint32_t tile_pairs = 0;
    // tiled: pairs left out of the bins because the glyph's atlas texels under the tile hold no
    // coverage (empty), or because an opaque glyph in front (alpha 1, no fill of its own) covers the
    // whole tile with full coverage (hidden). Only deep frames are classified so (more pairs than 64
    // a tile of the rect, or batched): hundreds of copies of a large glyph would otherwise cost every
    // pixel of their gaps, and of the batches behind, a read per copy. The image is the same; such a
    // frame's bins are never reused; max_overlap no longer counts the hidden fragments.
    uint32_t tile_empty_pairs = 0;
    uint32_t tile_hidden_pairs = 0;
};

// The depth of a world-space label for CompositeParams/TextStyle::depth: the clip-space z / w of
// `position` (x, y, z, in world units) under `view_projection` (column-major 4x4, Vulkan clip
// space with depth in [0, 1], as glm::perspectiveRH_ZO makes). nullopt when the point is behind
// the eye (w <= 0), outside the depth range, or any input is not finite.
CRISP_API std::optional<float> depth_from_view_projection(const float view_projection[16], const float position[3]);

class CRISP_API Compositor {
public:
    // Creates the tile path's pipelines (for each of kTileTargetFormats the device can store to),
    // the draw path's pipeline when draw_format is set, and the reference modes' target (R32G32B32A32_SFLOAT,
    // premultiplied linear colour, kept in VK_IMAGE_LAYOUT_GENERAL), per-pixel buffers and
    // pipelines when reference_modes is set. Errors: invalid_argument for a missing device,
    // frames_in_flight outside 1..8, tile_capacity not a power of two in 4..kMaxTileCapacity,
    // tile_layers outside 1..8, with reference_modes a size outside 1..16384 or
    // exact_nodes_per_pixel above 64; vulkan when the
    // device cannot store to any of kTileTargetFormats, draw_format cannot be a blended colour
    // attachment, the reference modes lack fragmentStoresAndAtomics or dualSrcBlend, their per-pixel
    // accumulators (36 bytes a pixel) would pass maxStorageBufferRange (the
    // message names it), or a Vulkan call fails. A node pool larger than the range is cut to it,
    // with a warning.
    static Result<Compositor> create(const CompositorCreateInfo& info);

    Compositor(Compositor&&) noexcept;
    Compositor& operator=(Compositor&&) noexcept;
    Compositor(const Compositor&) = delete;
    Compositor& operator=(const Compositor&) = delete;
    // The caller makes sure the GPU is done with the compositor's objects first.
    ~Compositor();

    // The tile path: records one frame compositing `frame`'s glyphs (Renderer::drawn_frame(): each
    // instance's rect, colour, depth and paint order, and where its texels are in the atlas) into
    // `target`, per channel: out.rgb = light + T * image.rgb, out.a = 1 - (1 - image.a) * min(T),
    // in linear colour. Pixels no glyph covers are neither read nor written. The atlas was written
    // before this by earlier commands (the renderer's barrier makes it readable). The command
    // buffer must be recording, outside a render pass.
    // Errors: invalid_argument for a frame without an atlas view, a null target view, a format
    // this compositor cannot store to (the
    // message says why), a rect outside the image or with a side above 16384, or a frame whose
    // bins (32 bytes a (glyph, 16 x 16 tile) pair) or glyph list (64 bytes a glyph) pass the
    // device's maxStorageBufferRange; vulkan for a failed allocation; either leaves no commands
    // recorded. Non-finite colours or depths are
    // clamped into range; a glyph whose rect does not lie in the atlas draws nothing where it
    // misses it; rects over 65535 texels a side draw nothing.
    Status record(VkCommandBuffer command_buffer, const DrawnFrame& frame, const CompositeTarget& target);

    // The draw path: records draws of `frame`'s glyphs, back to front, into the caller's render pass,
    // which must be active (begun with vkCmdBeginRendering) with one colour attachment of
    // CompositorCreateInfo::draw_format. `rect` is where text lands, as in CompositeTarget::rect
    // (the viewport and scissor are set to it); crisp sets the pipeline, descriptor set, push
    // constants, viewport and scissor. The atlas must already be readable by fragment shaders
    // (the renderer's record() does that, outside the render pass). Errors: invalid_argument
    // without a draw pipeline, for a frame without an atlas view, or for an empty rect or one
    // with a side above 16384; vulkan for a failed allocation (no commands recorded).
    Status record_draw(VkCommandBuffer command_buffer, const DrawnFrame& frame, const VkRect2D& rect);

    // The reference modes: records one frame composited by params.mode over params.background
    // into the compositor's own target. Same contract as record() for glyphs and atlas; after
    // it the target is readable by fragment and compute shaders and transfers. Errors:
    // invalid_argument without reference_modes, for a frame without an atlas view, for a mode that
    // is not a reference mode, or exact with no node pool; vulkan for a failed Vulkan call; either
    // leaves no commands recorded. On the compute path a rect over 65535 texels a side draws
    // nothing.
    Status record_reference(VkCommandBuffer command_buffer, const DrawnFrame& frame, const CompositeParams& params);

    // Takes back the most recent record(), record_draw() or record_reference() when its command
    // buffer will not be submitted (a dropped frame): the bins it made do not count as made, its
    // statistics are not waited for, the reference target's first layout change is recorded
    // again, and it does not count towards frames_in_flight. Call it before the next record
    // call and discard the command buffer unsubmitted; only the most recent call can be taken
    // back. `frame` is the renderer's frame being dropped (Renderer::frame(), DrawnFrame::frame):
    // the most recent call is taken back only when it composited that frame. Errors:
    // invalid_argument, taking nothing back, when it composited another frame (a frame dropped
    // before it reached the compositor: the one it did composite may be on the GPU) or was taken
    // back already, or there was none. (Renderer::abandon_frame() is the same for the renderer;
    // a dropped frame needs both, the compositor's only where it recorded the frame.)
    Status abandon_frame(uint64_t frame);

    // True when record() can composite into an image of `format` seen through a view of
    // `view_format` (VK_FORMAT_UNDEFINED: the same format).
    bool supports_target_format(VkFormat format, VkFormat view_format = VK_FORMAT_UNDEFINED) const;

    // Records a copy of the reference target into `buffer` (offset 0, width * height * 4 floats,
    // row-major, premultiplied linear RGBA), with barriers; the buffer is ready for host reads
    // once the command buffer completes. Does nothing without reference_modes.
    void record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const;

    // The reference target (VK_NULL_HANDLE without reference_modes) and its size.
    VkImage target_image() const;
    VkImageView target_view() const;
    uint32_t width() const;
    uint32_t height() const;
    const CompositorStats& stats() const;
    // The VkDeviceMemory objects the compositor holds now and their bytes (its buffers' blocks, as
    // the renderer's, and the reference modes' target image).
    DeviceMemoryUse device_memory() const;
    // The driver's statistics of the compositor's compiled shaders, every pass of every path it
    // made: see ShaderStatistic for when there are any; empty otherwise.
    const std::vector<ShaderStatistic>& shader_statistics() const;
    // What the compositor chose that the caller may want to know ("exact mode:
    // maxStorageBufferRange holds N of the M list nodes asked for").
    const std::vector<std::string>& warnings() const;

private:
    struct State;
    explicit Compositor(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

}  // namespace crisp
