// crisp: the GPU compositor. It draws the glyphs a Renderer rasterized this frame as quads whose
// fragments read the atlas accumulators, and blends them over a background into a target image,
// with order-independent transparency (docs/compositing.md).
//
// Per fragment and channel: coverage k = sum / (kCoverageOne * count) from the atlas, opacity
// o = a * k, transmittance T = 1 - o and premultiplied light L = c * o, with c the glyph's linear
// colour and a its alpha. Smaller depth is nearer; at equal depth the later paint order is in front.
//
// A frame, after the renderer's record() in the same command buffer (or a later one):
//
//     compositor.record(command_buffer, renderer.drawn(), renderer.atlas_view(), params);
//     ... the target image (output_image()) is ready for shaders, transfers or presentation ...
//
// Like the Renderer, the compositor never submits, and the caller must not have more than
// CompositorCreateInfo::frames_in_flight of its recorded command buffers pending at once.
#pragma once

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
    layered,   // the K nearest fragments per pixel, sorted by key; the rest estimated (the default)
    unsorted,  // premultiplied "over" in submission order: what no OIT gives
    wboit,     // weighted blended OIT (McGuire and Bavoil 2013), equation (10)
    exact,     // per-pixel linked lists, sorted: the ground truth
};
// "layered", "unsorted", "wboit", "exact".
const char* composite_mode_name(CompositeMode mode);
// The mode of that name; nullopt for any other string.
std::optional<CompositeMode> parse_composite_mode(std::string_view name);

// The most layers a layered pipeline keeps per pixel.
inline constexpr uint32_t kMaxCompositeLayers = 8;
// CompositeParams::layers: size K from the largest per-pixel overlap the compositor measured in
// its last completed frame (at most kMaxCompositeLayers; kMaxCompositeLayers until it has one).
inline constexpr uint32_t kAutoLayers = 0;
// The most fragments the exact mode sorts per pixel; more are dropped and counted.
inline constexpr uint32_t kMaxExactFragmentsPerPixel = 64;

// How the layered keys are built.
enum class KeyFormat {
    automatic,  // mono for a gray subpixel layout, rgb where the device allows it, else mono
    rgb,        // 64-bit keys: 32-bit depth, 8-bit paint order, 8-bit T per channel
    mono,       // 32-bit keys: 16-bit depth, 8-bit paint order, one 8-bit T for the three channels
};

struct CompositorCreateInfo {
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    const VkAllocationCallbacks* allocator = nullptr;
    // The device must have been created with fragmentStoresAndAtomics and dualSrcBlend enabled.
    // Say here whether shaderInt64 and shaderBufferInt64Atomics were enabled too: without them
    // layered compositing uses mono keys (and warnings() says so).
    bool int64_atomics = false;
    uint32_t width = 0;  // the target image, each 1..16384
    uint32_t height = 0;
    uint32_t frames_in_flight = 2;  // 1 to 8
    KeyFormat key_format = KeyFormat::automatic;
    bool gray_layout = false;  // the renderer's subpixel layout samples one rect for all channels
    // Layers the layer buffers are sized for: layered frames may use K up to this. 1..8.
    uint32_t max_layers = kMaxCompositeLayers;
    // The exact mode's node pool, in nodes per target pixel on average (each node 36 bytes);
    // 0 makes no pool and the exact mode unavailable. At most 64.
    uint32_t exact_nodes_per_pixel = 16;
    // Caps the size of one layer buffer below the device's maxStorageBufferRange (0: no cap), so
    // that tests can make the layer buffers split on a small target.
    uint64_t max_layer_buffer_bytes = 0;
};

// How the quad passes of the layered, wboit and exact modes run (unsorted is always rasterized:
// it needs the blend unit's submission order).
enum class QuadPath {
    raster,   // quads drawn, one fragment per pixel, early fragment tests (the seed's way)
    compute,  // one compute invocation per pixel of each 8 x 8 tile of each quad: no rasterizer
};
// "raster", "compute".
const char* quad_path_name(QuadPath path);
// The path of that name; nullopt for any other string.
std::optional<QuadPath> parse_quad_path(std::string_view name);

struct CompositeParams {
    CompositeMode mode = CompositeMode::layered;
    QuadPath path = QuadPath::raster;
    uint32_t layers = kAutoLayers;  // layered: 1..max_layers, or kAutoLayers
    // Linear colour and straight alpha of the background behind all glyphs.
    float background[4] = {1.0f, 1.0f, 1.0f, 1.0f};
};

struct CompositorStats {
    // This frame (known when record() returns):
    CompositeMode mode = CompositeMode::layered;
    QuadPath path = QuadPath::raster;  // the path this frame's quad passes took
    uint32_t tiles = 0;                // compute path: 8 x 8 tiles dispatched
    uint32_t layers = 0;           // layered: the K this frame used
    bool mono_keys = false;        // layered: 32-bit keys
    uint32_t quads = 0;            // glyph quads drawn
    uint32_t paint_order_blocks = 0;  // most 256-wide paint-order blocks one depth plane needed
    uint64_t buffer_bytes = 0;     // per-pixel buffers this mode reads and writes, whole target
    // From the last frame whose GPU work has completed (frames_in_flight frames ago), if any:
    bool measured = false;
    uint64_t measured_frame = 0;      // which frame (1 = the first record())
    uint32_t max_overlap = 0;         // layered and exact: most fragments one pixel had
    uint32_t tail_pixels = 0;         // layered: pixels with fragments past K
    uint64_t exact_lost_nodes = 0;    // exact: fragments the node pool could not hold
    uint64_t exact_dropped = 0;       // exact: fragments past kMaxExactFragmentsPerPixel
};

// The depth of a world-space label for CompositeParams/TextStyle::depth: the clip-space z / w of
// `position` (x, y, z, in world units) under `view_projection` (column-major 4x4, Vulkan clip
// space with depth in [0, 1], as glm::perspectiveRH_ZO makes). nullopt when the point is behind
// the eye (w <= 0), outside the depth range, or any input is not finite.
std::optional<float> depth_from_view_projection(const float view_projection[16], const float position[3]);

class Compositor {
public:
    // Creates the target image (VK_FORMAT_R32G32B32A32_SFLOAT, premultiplied linear colour, kept in
    // VK_IMAGE_LAYOUT_GENERAL), the per-pixel buffers and the pipelines. Errors: invalid_argument
    // for a size outside 1..16384, frames_in_flight outside 1..8, max_layers outside 1..8,
    // exact_nodes_per_pixel above 64, or key_format rgb without int64_atomics; vulkan when the
    // device lacks fragmentStoresAndAtomics or dualSrcBlend, cannot blend, store to and copy the
    // target format, one layer of keys or the per-pixel accumulators (44 bytes a pixel) would pass
    // maxStorageBufferRange (the message names it; layers are split across up to 8 buffers, the
    // accumulators are not: 128 MiB on lavapipe holds 3 million pixels), or a Vulkan call fails.
    // A node pool larger than the range is cut to it, with a warning.
    static Result<Compositor> create(const CompositorCreateInfo& info);

    Compositor(Compositor&&) noexcept;
    Compositor& operator=(Compositor&&) noexcept;
    Compositor(const Compositor&) = delete;
    Compositor& operator=(const Compositor&) = delete;
    // The caller makes sure the GPU is done with the compositor's objects first.
    ~Compositor();

    // Records one frame: `glyphs` (Renderer::drawn(): each instance's rect, colour, depth and paint
    // order, and where its texels are in the atlas) composited over params.background into the
    // target. `atlas_view` is Renderer::atlas_view(), in GENERAL layout, written before this by
    // earlier commands (the renderer's barrier makes it readable). The command buffer must be
    // recording, outside a render pass. After it the target is readable by fragment and compute
    // shaders and transfers. Errors: invalid_argument for layers above max_layers, or exact with
    // no node pool; vulkan for a failed Vulkan call; either leaves no commands recorded.
    // Non-finite colours or depths are clamped into range, never undefined behaviour; a glyph whose
    // rect does not lie in the atlas draws nothing where it misses it, and on the compute path a
    // rect over 65535 texels a side draws nothing (the renderer's are at most a few thousand).
    Status record(VkCommandBuffer command_buffer, std::span<const DrawnGlyph> glyphs, VkImageView atlas_view,
                  const CompositeParams& params);

    // Builds every pipeline the layered mode can use on `path` (K = 1 to max_layers), so that a
    // frame whose K changes (kAutoLayers follows the overlap) does not compile one mid-frame. Without
    // it each K's pipelines are built by the first record() that uses them. Errors: vulkan.
    Status prepare_layered(QuadPath path);

    // Records a copy of the target into `buffer` (offset 0, width * height * 4 floats, row-major,
    // premultiplied linear RGBA), with barriers; the buffer is ready for host reads once the
    // command buffer completes.
    void record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const;

    VkImage target_image() const;
    VkImageView target_view() const;
    uint32_t width() const;
    uint32_t height() const;
    const CompositorStats& stats() const;
    // What the compositor chose that the caller may want to know ("no 64-bit buffer atomics:
    // layered keys are mono").
    const std::vector<std::string>& warnings() const;

private:
    struct State;
    explicit Compositor(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

}  // namespace crisp
