// Private: the tile compositor (docs/compositing.md). The frame's quads, sorted front to back on
// the CPU, are binned into 16 x 16 screen tiles on the GPU (count, prefix sum, scatter), and one
// workgroup per non-empty tile composites its pixels into the caller's storage image: exactly
// where the tile's list fits in workgroup memory, with the K nearest layers per pixel where not.
// Nothing per pixel lives in global memory.
#pragma once

#include "composite/paints.hpp"

#include "shared.h"
#include "vk/resources.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp::composite {

// The tile pass's pipelines: an image format seen through a view format.
struct TileVariant {
    VkFormat image;
    VkFormat view;
    const char* shader;
};
inline constexpr std::array<TileVariant, 5> kTileVariants = {{
    {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, "tiles_pass_rgba8.comp"},
    {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, "tiles_pass_rgba8.comp"},  // red and blue swap
    {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM, "tiles_pass_any.comp"},    // storage_without_format
    {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT, "tiles_pass_rgba16f.comp"},
    {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT, "tiles_pass_rgba32f.comp"},
}};

struct TileConfig {
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    uint32_t frames_in_flight = 2;
    uint32_t layers = gpu::kCompositeMaxLayers;      // K of tiles whose list overflows
    uint32_t capacity = gpu::kTileDefaultCapacity;   // quads a tile's list holds in workgroup memory
    bool storage_without_format = false;             // B8G8R8A8 targets allowed
    bool reuse_static_bins = true;                   // skip binning when the quads did not change
    uint32_t bin_pairs = gpu::kTileDefaultBinPairs;  // (quad, tile) pairs binned at once: a batch's most
};

// Where the tile pass draws: glyph pixel (0, 0) is `origin` in the image; `size` pixels from there.
struct TileTarget {
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;       // the image's
    VkFormat view_format = VK_FORMAT_UNDEFINED;  // the view's
    VkOffset2D origin{};
    VkExtent2D size{};
};

// What the GPU counted in one frame (TileHeader).
struct TileCounts {
    uint32_t busy_tiles = 0;
    uint32_t exact_tiles = 0;
    uint32_t layered_tiles = 0;
    uint32_t max_overlap = 0;
    uint32_t tail_pixels = 0;
    uint32_t pairs = 0;
    uint32_t lost_pairs = 0;
    uint32_t empty_pairs = 0;   // left out: the quad's texels under the tile hold no coverage
    uint32_t hidden_pairs = 0;  // left out: behind an opaque quad full over the tile
};

class TileCompositor {
public:
    TileCompositor() = default;
    TileCompositor(const TileCompositor&) = delete;
    TileCompositor& operator=(const TileCompositor&) = delete;
    ~TileCompositor();

    // Pipelines for every format of kTileFormats the device can store to (B8G8R8A8 only with
    // storage_without_format), and one descriptor set per frame in flight. Errors: vulkan.
    Status create(const vk::DeviceRef& device, const TileConfig& config);

    // True when an image of `format` seen through a view of `view_format` can be a target.
    bool supports(VkFormat format, VkFormat view_format) const;

    // Records the frame: `quads` sorted front to back (sort_front_to_back for target.size).
    // Returns the buffer bytes the frame used; `measured` gets the counts of the frame that last
    // used this frame slot, if it has not been read yet (`measured_frame` says which). `reused`
    // says whether the slot's bins already held these quads (static text), so that the frame
    // skipped the upload and the binning passes.
    Result<uint64_t> record(VkCommandBuffer command_buffer, std::span<const gpu::CompositeQuad> quads,
                            VkImageView atlas_view, const PaintInputs& paints, const TileTarget& target,
                            TileCounts& measured, uint64_t& measured_frame, bool& reused);
    // Takes back the last record() (its command buffer will not be submitted): the slot's bins,
    // if that record() binned, no longer count as holding its quads, its counts are not read,
    // and the frame does not count towards frames in flight.
    void abandon_frame();
    // The batches the last record() binned and composited, back to front: 1 unless its (quad,
    // tile) pairs passed the bins' budget (TileConfig::bin_pairs, at least the rect's tiles).
    uint32_t batches() const { return static_cast<uint32_t>(batches_.size()); }

private:
    struct Slot {
        vk::DeviceBuffer quads;   // host-visible CompositeQuad[]
        vk::DeviceBuffer tiles;   // three planes of tile words
        vk::DeviceBuffer bins;    // TileBinEntry lists
        vk::DeviceBuffer header;  // host-visible: TileHeader, then the busy tiles' entries
        VkDescriptorSet set = VK_NULL_HANDLE;
        bool pending = false;
        uint64_t frame = 0;
        // What the bins hold: the quads and the rect size they were binned for.
        std::vector<gpu::CompositeQuad> binned;
        uint32_t binned_width = 0, binned_height = 0;
        bool bins_valid = false;
        // A frame of several batches: each batch's TileHeader, copied there after its passes
        // (host-visible), since the next batch starts the header again.
        vk::DeviceBuffer batch_headers;
        uint32_t batches = 1;  // of the frame that last used the slot
        // A classified frame's atlas blocks and each quad's (host-visible; a stand-in of 256 bytes
        // otherwise, so that the descriptor set is whole).
        vk::DeviceBuffer blocks;       // TileBlock[]
        vk::DeviceBuffer quad_blocks;  // TileQuadBlocks[]
    };
    // Consecutive quads (front to back) binned and composited together.
    struct Batch {
        uint32_t first = 0;
        uint32_t count = 0;
        uint64_t pairs = 0;
    };

    Status grow(vk::DeviceBuffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage, bool host_visible,
                const char* what);
    Status prepare_slot(Slot& slot, std::span<const gpu::CompositeQuad> quads, uint32_t tiles, uint64_t pairs);
    // Cuts `quads` into batches_ of at most `budget` pairs each, and where that makes more than
    // one, of at most the list capacity in any tile; returns the most pairs of one.
    uint64_t make_batches(std::span<const gpu::CompositeQuad> quads, uint32_t width, uint32_t height, uint64_t budget);
    // Fills blocks_ and quad_blocks_ for a deep frame (shared.h, kTileCullDepth): the distinct atlas
    // entries its quads reaching the width x height rect show, cut into blocks. False, leaving them empty, where the
    // blocks would pass kMaxClassifiedBlocks: the frame is then binned whole, as any other.
    bool classify(std::span<const gpu::CompositeQuad> quads, uint32_t width, uint32_t height);
    // The counts of the frame that last used `slot`, summed over its batches.
    TileCounts read_counts(const Slot& slot) const;
    void write_descriptors(const Slot& slot, VkImageView atlas_view, const PaintInputs& paints,
                           VkImageView target_view);
    void record_binning(VkCommandBuffer command_buffer, const gpu::TilePushConstants& push);
    void reset_header(const Slot& slot, bool reuse_bins);
    void record_passes(VkCommandBuffer command_buffer, const Slot& slot, const std::array<VkPipeline, 2>& tile_passes,
                       const gpu::TilePushConstants& push, bool reuse_bins);
    // `label` names the pipeline in errors and shader statistics: the shader, and which of its
    // specializations where it has several.
    Status make_pipeline(const char* shader, const VkSpecializationInfo* specialization, const std::string& label,
                         VkPipeline& out);
    // What a frame's tile passes are specialized for (a set of these bits).
    static constexpr uint32_t kTileContrast = 1;  // some quad's coverage is corrected
    static constexpr uint32_t kTilePaints = 2;    // some quad is a colour layer with a fill
    // The exact and layered passes of variant `variant`, for `features`.
    Status make_tile_passes(size_t variant, uint32_t features, std::array<VkPipeline, 2>& out);

    vk::DeviceRef ref_;
    TileConfig config_;
    VkDeviceSize max_buffer_range_ = 0;  // maxStorageBufferRange: the largest buffer a descriptor reaches
    vk::DescriptorSets descriptors_;
    vk::DeviceObjects objects_;  // shader modules and pipelines
    VkPipeline count_ = VK_NULL_HANDLE, scatter_ = VK_NULL_HANDLE, classify_ = VK_NULL_HANDLE,
               occluders_ = VK_NULL_HANDLE;
    std::array<VkPipeline, 3> scan_{};  // reduce, blocks, down
    // Per variant and features, the exact and layered passes: those without features made by
    // create(), the others at the first frame that needs them.
    std::array<std::array<std::array<VkPipeline, 2>, 4>, kTileVariants.size()> tile_pipelines_{};
    std::vector<Slot> slots_;
    std::vector<Batch> batches_;  // the last record()'s, front to back (recorded from the last)
    // A batched frame's tiles: the batch that last counted a quad there, and how many it counted.
    std::vector<uint32_t> tile_batch_, tile_count_;
    // A classified frame's blocks and per-quad entries, and the quads sorted by entry to find them.
    std::vector<gpu::TileBlock> blocks_;
    std::vector<gpu::TileQuadBlocks> quad_blocks_;
    std::vector<uint32_t> by_entry_;
    uint64_t frame_ = 0;
    bool recorded_ = false;     // record() since the last abandon_frame()
    bool last_binned_ = false;  // the last record() binned anew
};

}  // namespace crisp::composite
