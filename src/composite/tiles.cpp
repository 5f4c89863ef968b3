// The tile compositor: binning on the GPU, then one workgroup per non-empty tile.
#include "composite/tiles.hpp"

#include "composite/quads.hpp"
#include "vk/barriers.hpp"
#include "vk/bindings.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>
#include <string_view>
#include <tuple>

namespace crisp::composite {

namespace {

constexpr VkDeviceSize kWord = 4;
// The most atlas blocks a frame classifies (16 MiB of TileBlock, the texels of a 4096 x 4096
// atlas): past it the frame is binned whole, as it was before classification.
constexpr size_t kMaxClassifiedBlocks = size_t{1} << 20;

// The descriptor set of every pass of the tile compositor (tiles_common.glsl declares it).
constexpr vk::Binding kBindings[] = {
    {gpu::kTileBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kTileBindQuads, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindTiles, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindBins, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindHeader, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindTarget, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kTileBindPaints, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindStops, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindImages, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
    {gpu::kTileBindBlocks, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kTileBindQuadBlocks, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
};
static_assert(std::size(kBindings) == gpu::kTileBindingCount);
constexpr vk::BindingTable kTable{kBindings, VK_SHADER_STAGE_COMPUTE_BIT};

size_t variant_index(VkFormat format, VkFormat view_format) {
    const auto found = std::find_if(kTileVariants.begin(), kTileVariants.end(),
                                    [&](const TileVariant& v) { return v.image == format && v.view == view_format; });
    return static_cast<size_t>(found - kTileVariants.begin());
}

bool is_srgb_encoded(VkFormat format) {
    return format == VK_FORMAT_R8G8B8A8_UNORM || format == VK_FORMAT_B8G8R8A8_UNORM;
}

// Words of the header buffer: TileHeader, the busy tiles' entries, the tiles handed to the layered
// pass.
VkDeviceSize header_words(uint32_t tiles) {
    return gpu::kTileHeaderWords + (gpu::kTileBusyEntryWords + 1) * VkDeviceSize{tiles};
}

// Words of the tiles buffer: count, start and cursor per tile, two words per scan block, and a
// classified frame's occluder per tile (tiles_common.glsl, occluder_word).
VkDeviceSize occluder_words_start(uint32_t tiles) {
    return VkDeviceSize{tiles} * 3 + 2 * VkDeviceSize{(tiles + gpu::kTileScanBlock - 1) / gpu::kTileScanBlock};
}
VkDeviceSize tile_words(uint32_t tiles) {
    return occluder_words_start(tiles) + tiles;
}

// Workgroups for `count` invocations in groups of `size`, as a 2D grid of rows of
// kRasterDispatchWidth (the shaders index gl_WorkGroupID.y * gl_NumWorkGroups.x + x).
VkExtent2D grid(uint32_t count, uint32_t size) {
    const uint32_t groups = (count + size - 1) / size;
    const uint32_t width = std::min(groups, gpu::kRasterDispatchWidth);
    return {width, width == 0 ? 0 : (groups + width - 1) / width};
}

}  // namespace

TileCompositor::~TileCompositor() = default;

Status TileCompositor::create(const vk::DeviceRef& device, const TileConfig& config) {
    ref_ = device;
    config_ = config;
    VkPhysicalDeviceProperties device_properties{};
    ref_.fn->vkGetPhysicalDeviceProperties(config.physical_device, &device_properties);
    max_buffer_range_ = device_properties.limits.maxStorageBufferRange;
    // The tile pass reduces its statistics per subgroup.
    if (!vk::has_compute_subgroup_arithmetic(*ref_.fn, config.physical_device)) {
        return Error{ErrorCode::vulkan, "compositor: the device has no subgroup arithmetic in compute shaders"};
    }
    if (Status s = vk::create_descriptor_sets(ref_, kTable, sizeof(gpu::TilePushConstants), config.frames_in_flight,
                                              "tile compositor", descriptors_);
        !s) {
        return s;
    }
    slots_.resize(config.frames_in_flight);
    for (uint32_t i = 0; i < config.frames_in_flight; ++i) slots_[i].set = descriptors_.sets[i];

    const uint32_t scatter = 1;
    const VkSpecializationMapEntry scatter_entry{0, 0, 4};
    const VkSpecializationInfo scatter_info{1, &scatter_entry, 4, &scatter};
    if (Status s = make_pipeline("tiles_bin.comp", nullptr, "tiles_bin.comp (count)", count_); !s) return s;
    if (Status s = make_pipeline("tiles_bin.comp", &scatter_info, "tiles_bin.comp (scatter)", scatter_); !s) return s;
    const uint32_t occluders = 2;
    const VkSpecializationInfo occluders_info{1, &scatter_entry, 4, &occluders};
    if (Status s = make_pipeline("tiles_bin.comp", &occluders_info, "tiles_bin.comp (occluders)", occluders_); !s) {
        return s;
    }
    if (Status s = make_pipeline("tiles_classify.comp", nullptr, "tiles_classify.comp", classify_); !s) return s;
    for (uint32_t phase = 0; phase < scan_.size(); ++phase) {
        const VkSpecializationMapEntry phase_entry{0, 0, 4};
        const VkSpecializationInfo phase_info{1, &phase_entry, 4, &phase};
        constexpr const char* kPhases[] = {"reduce", "blocks", "down"};
        if (Status s = make_pipeline("tiles_scan.comp", &phase_info,
                                     std::string("tiles_scan.comp (") + kPhases[phase] + ")", scan_[phase]);
            !s)
            return s;
    }

    for (size_t i = 0; i < kTileVariants.size(); ++i) {
        const TileVariant& variant = kTileVariants[i];
        VkFormatProperties properties{};
        ref_.fn->vkGetPhysicalDeviceFormatProperties(config.physical_device, variant.view, &properties);
        if ((properties.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) == 0) continue;
        if (std::string_view(variant.shader) == "tiles_pass_any.comp" && !config.storage_without_format) continue;
        if (Status s = make_tile_passes(i, 0, tile_pipelines_[i][0]); !s) return s;
    }
    return {};
}

Status TileCompositor::make_pipeline(const char* shader, const VkSpecializationInfo* specialization,
                                     const std::string& label, VkPipeline& out) {
    Result<VkShaderModule> module = vk::create_embedded_shader(ref_, shader);
    if (!module) return module.error();
    objects_.keep(ref_, *module);
    Result<VkPipeline> made =
        vk::create_compute_pipeline(ref_, *module, descriptors_.pipeline_layout, specialization, label.c_str());
    if (!made) return made.error();
    out = objects_.keep(ref_, *made);
    return {};
}

Status TileCompositor::make_tile_passes(size_t index, uint32_t features, std::array<VkPipeline, 2>& out) {
    const TileVariant& variant = kTileVariants[index];
    // constant_id 0: K; 1: the target's encoding; 2: the list capacity; 3: red and blue swap;
    // 4: the pass (exact, layered); 5: the contrast model; 6: colour layers' fills.
    const uint32_t contrast = (features & kTileContrast) != 0 ? 1u : 0u;
    const uint32_t paints = (features & kTilePaints) != 0 ? 1u : 0u;
    for (uint32_t pass = 0; pass < 2; ++pass) {
        const uint32_t constants[7] = {config_.layers,
                                       is_srgb_encoded(variant.image) ? gpu::kTileEncodeSrgb : gpu::kTileEncodeLinear,
                                       config_.capacity,
                                       variant.image != variant.view ? 1u : 0u,
                                       pass,
                                       contrast,
                                       paints};
        const VkSpecializationMapEntry entries[7] = {{0, 0, 4},  {1, 4, 4},  {2, 8, 4}, {3, 12, 4},
                                                     {4, 16, 4}, {5, 20, 4}, {6, 24, 4}};
        const VkSpecializationInfo specialization{7, entries, sizeof(constants), constants};
        const std::string label = std::string(variant.shader) + (pass == 0 ? " (exact pass)" : " (layered pass)") +
                                  (variant.image != variant.view ? ", red and blue swapped" : "") +
                                  (contrast != 0 ? ", contrast" : "") + (paints != 0 ? ", paints" : "");
        if (Status s = make_pipeline(variant.shader, &specialization, label, out[pass]); !s) return s;
    }
    return {};
}

bool TileCompositor::supports(VkFormat format, VkFormat view_format) const {
    const size_t i = variant_index(format, view_format);
    return i < kTileVariants.size() && tile_pipelines_[i][0][0] != VK_NULL_HANDLE;
}

Status TileCompositor::grow(vk::DeviceBuffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage, bool host_visible,
                            const char* what) {
    if (buffer.buffer && buffer.size >= bytes) return {};
    // The slot's last use is done (the frames-in-flight contract), so its buffer can go. Doubled
    // sizes, so that growing text reallocates rarely, but never past what a descriptor can reach
    // (record() refuses more than that).
    buffer.reset();
    const VkDeviceSize size = std::max(bytes, std::min(std::bit_ceil(bytes), max_buffer_range_));
    return vk::create_buffer(ref_, std::max<VkDeviceSize>(256, size), usage, host_visible, what, buffer);
}

Status TileCompositor::prepare_slot(Slot& slot, std::span<const gpu::CompositeQuad> quads, uint32_t tiles,
                                    uint64_t pairs) {
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    constexpr VkBufferUsageFlags transfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    const VkDeviceSize quad_bytes = quads.size_bytes();
    if (Status s = grow(slot.quads, quad_bytes, storage, true, "tile quads"); !s) return s;
    if (Status s = grow(slot.tiles, tile_words(tiles) * kWord, storage | transfer, false, "tile counts"); !s) return s;
    if (Status s = grow(slot.bins, pairs * sizeof(gpu::TileBinEntry), storage, false, "tile bins"); !s) return s;
    // Host-visible, so that the host reads the frame's counts straight from it once the frame is done.
    if (Status s = grow(slot.header, header_words(tiles) * kWord,
                        storage | transfer | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, true, "tile header");
        !s) {
        return s;
    }
    // Host-visible: classify() writes them here, and the classification pass its marks.
    const std::span<const std::byte> blocks = std::as_bytes(std::span(blocks_));
    const std::span<const std::byte> quad_blocks = std::as_bytes(std::span(quad_blocks_));
    if (Status s = grow(slot.blocks, blocks.size(), storage, true, "tile blocks"); !s) return s;
    if (Status s = grow(slot.quad_blocks, quad_blocks.size(), storage, true, "tile quad blocks"); !s) return s;
    if (quad_bytes > 0) std::memcpy(slot.quads.mapped, quads.data(), quad_bytes);
    if (!blocks.empty()) std::memcpy(slot.blocks.mapped, blocks.data(), blocks.size());
    if (!quad_blocks.empty()) std::memcpy(slot.quad_blocks.mapped, quad_blocks.data(), quad_blocks.size());
    return {};
}

bool TileCompositor::classify(std::span<const gpu::CompositeQuad> quads, uint32_t width, uint32_t height) {
    blocks_.clear();
    quad_blocks_.assign(quads.size(), {gpu::kTileNoBlocks, 0});
    // The quads that reach the rect, grouped by the atlas rect they show: one entry's blocks serve
    // every copy of it.
    by_entry_.clear();
    for (uint32_t i = 0; i < quads.size(); ++i) {
        if (quad_tile_pairs(quads[i], width, height) > 0) by_entry_.push_back(i);
    }
    const auto entry = [&](uint32_t i) {
        const gpu::CompositeQuad& q = quads[i];
        return std::tuple(q.atlas_x, q.atlas_y, q.width, q.height);
    };
    std::sort(by_entry_.begin(), by_entry_.end(), [&](uint32_t a, uint32_t b) { return entry(a) < entry(b); });
    constexpr uint32_t side = gpu::kTileBlockSide;
    for (size_t i = 0; i < by_entry_.size();) {
        const gpu::CompositeQuad& q = quads[by_entry_[i]];
        const uint32_t across = (q.width + side - 1) / side, down = (q.height + side - 1) / side;
        if (blocks_.size() + size_t{across} * down > kMaxClassifiedBlocks) {
            blocks_.clear();
            quad_blocks_.clear();
            return false;
        }
        const gpu::TileQuadBlocks blocks{static_cast<uint32_t>(blocks_.size()), across};
        for (uint32_t by = 0; by < down; ++by) {
            for (uint32_t bx = 0; bx < across; ++bx) {
                const uint32_t w = std::min(side, q.width - bx * side), h = std::min(side, q.height - by * side);
                blocks_.push_back({q.atlas_x + bx * side, q.atlas_y + by * side, w | h << 16, 0});
            }
        }
        const auto key = entry(by_entry_[i]);
        for (; i < by_entry_.size() && entry(by_entry_[i]) == key; ++i) quad_blocks_[by_entry_[i]] = blocks;
    }
    return true;
}

uint64_t TileCompositor::make_batches(std::span<const gpu::CompositeQuad> quads, uint32_t width, uint32_t height,
                                      uint64_t budget) {
    batches_.clear();
    Batch batch;
    uint64_t most = 0;
    for (size_t i = 0; i < quads.size(); ++i) {
        const uint64_t pairs = quad_tile_pairs(quads[i], width, height);
        if (batch.count > 0 && batch.pairs + pairs > budget) {
            batches_.push_back(batch);
            batch = {static_cast<uint32_t>(i), 0, 0};
        }
        ++batch.count;
        batch.pairs += pairs;
        most = std::max(most, batch.pairs);
    }
    batches_.push_back(batch);
    if (batches_.size() == 1) return most;

    // Batched anyway: cut also where a tile's list would pass the capacity, so that every batch's
    // tiles take the exact way (sorted, walked front to back with its early exit) rather than the
    // layered way, which walks every quad of its tile for each pixel, twice for those past K.
    const int64_t side = gpu::kTileSide;
    const uint32_t tiles_x = (width + gpu::kTileSide - 1) / gpu::kTileSide;
    const uint32_t tiles = tiles_x * ((height + gpu::kTileSide - 1) / gpu::kTileSide);
    tile_batch_.assign(tiles, UINT32_MAX);
    tile_count_.assign(tiles, 0);
    batches_.clear();
    batch = {};
    most = 0;
    uint32_t number = 0;
    for (size_t i = 0; i < quads.size(); ++i) {
        const gpu::CompositeQuad& q = quads[i];
        const uint64_t pairs = quad_tile_pairs(q, width, height);
        uint32_t tx0 = 0, ty0 = 0, tx1 = 0, ty1 = 0;  // the tiles it reaches: [tx0, tx1) x [ty0, ty1)
        if (pairs > 0) {
            tx0 = static_cast<uint32_t>(std::max<int64_t>(q.x, 0) / side);
            ty0 = static_cast<uint32_t>(std::max<int64_t>(q.y, 0) / side);
            tx1 = static_cast<uint32_t>((std::min<int64_t>(int64_t{q.x} + q.width, width) - 1) / side + 1);
            ty1 = static_cast<uint32_t>((std::min<int64_t>(int64_t{q.y} + q.height, height) - 1) / side + 1);
        }
        bool full = false;
        for (uint32_t ty = ty0; ty < ty1 && !full; ++ty) {
            for (uint32_t tx = tx0; tx < tx1 && !full; ++tx) {
                const uint32_t t = ty * tiles_x + tx;
                full = tile_batch_[t] == number && tile_count_[t] >= config_.capacity;
            }
        }
        if (batch.count > 0 && (full || batch.pairs + pairs > budget)) {
            batches_.push_back(batch);
            batch = {static_cast<uint32_t>(i), 0, 0};
            ++number;
        }
        for (uint32_t ty = ty0; ty < ty1; ++ty) {
            for (uint32_t tx = tx0; tx < tx1; ++tx) {
                const uint32_t t = ty * tiles_x + tx;
                if (tile_batch_[t] != number) {
                    tile_batch_[t] = number;
                    tile_count_[t] = 0;
                }
                ++tile_count_[t];
            }
        }
        ++batch.count;
        batch.pairs += pairs;
        most = std::max(most, batch.pairs);
    }
    batches_.push_back(batch);
    return most;
}

TileCounts TileCompositor::read_counts(const Slot& slot) const {
    TileCounts counts;
    for (uint32_t i = 0; i < slot.batches; ++i) {
        gpu::TileHeader header{};
        const void* from = slot.batches > 1 ? static_cast<const char*>(slot.batch_headers.mapped) + i * sizeof(header)
                                            : slot.header.mapped;
        std::memcpy(&header, from, sizeof(header));
        counts.busy_tiles += header.busy_tiles;
        counts.exact_tiles += header.busy_tiles - header.layered_tiles;
        counts.layered_tiles += header.layered_tiles;
        counts.max_overlap = std::max(counts.max_overlap, header.max_overlap);
        counts.tail_pixels += header.tail_pixels;
        counts.pairs += header.pairs;
        counts.lost_pairs += header.lost_pairs;
        counts.empty_pairs += header.empty_pairs;
        counts.hidden_pairs += header.hidden_pairs;
    }
    return counts;
}

void TileCompositor::write_descriptors(const Slot& slot, VkImageView atlas_view, const PaintInputs& paints,
                                       VkImageView target_view) {
    vk::DescriptorWrites writes(kTable, slot.set);
    paints.write(writes, gpu::kTileBindPaints, gpu::kTileBindStops, gpu::kTileBindImages);
    writes.storage_image(gpu::kTileBindAtlas, atlas_view)
        .storage_buffer(gpu::kTileBindQuads, slot.quads.buffer)
        .storage_buffer(gpu::kTileBindTiles, slot.tiles.buffer)
        .storage_buffer(gpu::kTileBindBins, slot.bins.buffer)
        .storage_buffer(gpu::kTileBindHeader, slot.header.buffer)
        .storage_image(gpu::kTileBindTarget, target_view)
        .storage_buffer(gpu::kTileBindBlocks, slot.blocks.buffer)
        .storage_buffer(gpu::kTileBindQuadBlocks, slot.quad_blocks.buffer)
        .update(ref_);
}

// Count, prefix sum, scatter: the frame's quads into the slot's bins. The descriptor set and push
// constants are bound.
void TileCompositor::record_binning(VkCommandBuffer cb, const gpu::TilePushConstants& push) {
    constexpr VkPipelineStageFlags compute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    constexpr VkAccessFlags shader = vk::kShaderAccess;
    const uint32_t tiles = push.tiles_x * push.tiles_y;
    const VkExtent2D quad_groups = grid(push.quad_count, gpu::kTileBinInvocations);
    auto bin = [&](VkPipeline pipeline) {
        if (quad_groups.width == 0) return;
        ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        ref_.fn->vkCmdDispatch(cb, quad_groups.width, quad_groups.height, 1);
    };
    bin(count_);
    // The prefix sum: block sums, their scan in one workgroup, the blocks' own scans.
    const VkExtent2D blocks = grid(tiles, gpu::kTileScanBlock);
    for (uint32_t phase = 0; phase < scan_.size(); ++phase) {
        vk::memory_barrier(*ref_.fn, cb, compute, shader, compute, shader);
        ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, scan_[phase]);
        if (phase == 1) {
            ref_.fn->vkCmdDispatch(cb, 1, 1, 1);
        } else {
            ref_.fn->vkCmdDispatch(cb, blocks.width, blocks.height, 1);
        }
    }
    vk::memory_barrier(*ref_.fn, cb, compute, shader, compute, shader);
    bin(scatter_);
    vk::memory_barrier(*ref_.fn, cb, compute, shader, compute | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       shader | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
}

// The frame's counters start again, written through the header's mapping: the slot's last frame
// is done (the frames-in-flight contract), and submitting the command buffer makes host writes
// before it visible to the GPU. So static text's frame carries no clear and no transfer barrier.
// Binning anew, the whole TileHeader starts at zero (the scan writes the dispatches); with the
// bins reused, the busy list and the exact pass's dispatch stand, and the tile passes' counts and
// the layered dispatch start again.
void TileCompositor::reset_header(const Slot& slot, bool reuse_bins) {
    if (reuse_bins) {
        constexpr uint32_t reset[] = {0, 0, 0, 0, 0, 1, 1};  // layered tiles .. layered dispatch z
        static_assert(offsetof(gpu::TileHeader, layered_dispatch_z) - offsetof(gpu::TileHeader, layered_tiles) ==
                      sizeof(reset) - kWord);
        std::memcpy(static_cast<char*>(slot.header.mapped) + offsetof(gpu::TileHeader, layered_tiles), reset,
                    sizeof(reset));
    } else {
        const gpu::TileHeader zero{};
        std::memcpy(slot.header.mapped, &zero, sizeof(zero));
    }
}

void TileCompositor::record_passes(VkCommandBuffer cb, const Slot& slot, const std::array<VkPipeline, 2>& tile_passes,
                                   const gpu::TilePushConstants& push, bool reuse_bins) {
    constexpr VkPipelineStageFlags compute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    constexpr VkPipelineStageFlags transfer = VK_PIPELINE_STAGE_TRANSFER_BIT;
    constexpr VkPipelineStageFlags indirect = VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
    constexpr VkAccessFlags shader = vk::kShaderAccess;
    const uint32_t tiles = push.tiles_x * push.tiles_y;
    // This slot's buffers were last used by a frame the caller has waited for; the barrier orders
    // them for the validation layer and for callers who recycle command buffers early.
    vk::memory_barrier(*ref_.fn, cb, compute | transfer | indirect,
                       shader | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT,
                       compute | transfer | indirect,
                       shader | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
    reset_header(slot, reuse_bins);
    if (!reuse_bins) {
        ref_.fn->vkCmdFillBuffer(cb, slot.tiles.buffer, 0, VkDeviceSize{tiles} * kWord, 0);
        if (push.block_count > 0) {
            ref_.fn->vkCmdFillBuffer(cb, slot.tiles.buffer, occluder_words_start(tiles) * kWord,
                                     VkDeviceSize{tiles} * kWord, gpu::kTileNoQuad);
        }
        vk::memory_barrier(*ref_.fn, cb, transfer, VK_ACCESS_TRANSFER_WRITE_BIT, compute, shader);
    }

    ref_.fn->vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, descriptors_.pipeline_layout, 0, 1, &slot.set,
                                     0, nullptr);
    if (push.block_count > 0) {
        // The atlas blocks first, then each tile's occluder over all the frame's quads: every
        // batch's binning reads both.
        ref_.fn->vkCmdPushConstants(cb, descriptors_.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push),
                                    &push);
        const VkExtent2D groups = grid(push.block_count, 1);
        ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, classify_);
        ref_.fn->vkCmdDispatch(cb, groups.width, groups.height, 1);
        vk::memory_barrier(*ref_.fn, cb, compute, shader, compute, shader);
        const VkExtent2D quad_groups = grid(push.quad_count, gpu::kTileBinInvocations);
        if (quad_groups.width > 0) {
            ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, occluders_);
            ref_.fn->vkCmdDispatch(cb, quad_groups.width, quad_groups.height, 1);
            vk::memory_barrier(*ref_.fn, cb, compute, shader, compute, shader);
        }
    }
    // Batches back to front, each composited over what the ones behind it left in the image: the
    // tile passes blend over the image, so the result is the one pass's (up to the target format's
    // rounding between batches).
    const bool batched = batches_.size() > 1;
    for (size_t k = batches_.size(); k-- > 0;) {
        const Batch& batch = batches_[k];
        gpu::TilePushConstants batch_push = push;
        batch_push.quad_first = batch.first;
        batch_push.quad_count = batch.count;
        batch_push.bin_capacity = static_cast<uint32_t>(batch.pairs);
        if (k + 1 < batches_.size()) {
            // The batch behind is done with the header and the tile words: they start again.
            vk::memory_barrier(*ref_.fn, cb, compute | indirect | transfer,
                               shader | VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT, transfer,
                               VK_ACCESS_TRANSFER_WRITE_BIT);
            ref_.fn->vkCmdFillBuffer(cb, slot.header.buffer, 0, sizeof(gpu::TileHeader), 0);
            ref_.fn->vkCmdFillBuffer(cb, slot.tiles.buffer, 0, VkDeviceSize{tiles} * kWord, 0);
            vk::memory_barrier(*ref_.fn, cb, transfer, VK_ACCESS_TRANSFER_WRITE_BIT, compute | indirect,
                               shader | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
        }
        ref_.fn->vkCmdPushConstants(cb, descriptors_.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                    sizeof(batch_push), &batch_push);
        if (!reuse_bins) record_binning(cb, batch_push);
        ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, tile_passes[0]);
        ref_.fn->vkCmdDispatchIndirect(cb, slot.header.buffer, 0);
        // The tiles the exact pass handed on; usually none, and then an empty dispatch.
        vk::memory_barrier(*ref_.fn, cb, compute, shader, compute | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                           shader | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
        ref_.fn->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, tile_passes[1]);
        ref_.fn->vkCmdDispatchIndirect(cb, slot.header.buffer, gpu::kTileLayeredDispatchOffset);
        if (batched) {
            // The batch's counts, kept for the host before the next batch starts the header again.
            vk::memory_barrier(*ref_.fn, cb, compute, VK_ACCESS_SHADER_WRITE_BIT, transfer,
                               VK_ACCESS_TRANSFER_READ_BIT);
            const VkBufferCopy copy{0, k * sizeof(gpu::TileHeader), sizeof(gpu::TileHeader)};
            ref_.fn->vkCmdCopyBuffer(cb, slot.header.buffer, slot.batch_headers.buffer, 1, &copy);
        }
    }
    // The frame's counts for the host.
    vk::memory_barrier(*ref_.fn, cb, compute | transfer, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

void TileCompositor::abandon_frame() {
    if (!recorded_) return;
    recorded_ = false;
    --frame_;
    Slot& slot = slots_[frame_ % slots_.size()];
    slot.pending = false;
    if (last_binned_) slot.bins_valid = false;
}

Result<uint64_t> TileCompositor::record(VkCommandBuffer command_buffer, std::span<const gpu::CompositeQuad> quads,
                                        VkImageView atlas_view, const PaintInputs& paints, const TileTarget& target,
                                        TileCounts& measured, uint64_t& measured_frame, bool& reused) {
    Slot& slot = slots_[frame_ % slots_.size()];
    if (slot.pending) {
        measured = read_counts(slot);
        measured_frame = slot.frame;
        slot.pending = false;
    }
    gpu::TilePushConstants push{};
    push.origin_x = target.origin.x;
    push.origin_y = target.origin.y;
    push.width = target.size.width;
    push.height = target.size.height;
    push.tiles_x = (push.width + gpu::kTileSide - 1) / gpu::kTileSide;
    push.tiles_y = (push.height + gpu::kTileSide - 1) / gpu::kTileSide;
    push.quad_count = static_cast<uint32_t>(quads.size());
    const uint32_t tiles = push.tiles_x * push.tiles_y;
    if (quads.size_bytes() > max_buffer_range_) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: " + std::to_string(quads.size()) + " glyphs need " +
                         std::to_string(quads.size_bytes()) +
                         " bytes of quads, more than the device's maxStorageBufferRange (" +
                         std::to_string(max_buffer_range_) + ") lets a shader reach"};
    }
    // The bins hold one batch's pairs: at most the budget, and at least one quad's (the rect's tiles).
    const uint64_t budget =
        std::max<uint64_t>(std::min<uint64_t>(config_.bin_pairs, max_buffer_range_ / sizeof(gpu::TileBinEntry)), tiles);
    const uint64_t pairs = make_batches(quads, push.width, push.height, budget);
    const bool batched = batches_.size() > 1;
    push.bin_capacity = static_cast<uint32_t>(pairs);
    // A deep frame's empty pairs are left out (shared.h, kTileCullDepth). Its bins are never
    // reused: more samples may give an empty texel coverage by the next frame.
    uint64_t all_pairs = 0;
    for (const Batch& batch : batches_) all_pairs += batch.pairs;
    const bool classified =
        (batched || all_pairs > uint64_t{gpu::kTileCullDepth} * tiles) && classify(quads, push.width, push.height);
    if (!classified) {
        blocks_.clear();
        quad_blocks_.clear();
    }
    push.block_count = static_cast<uint32_t>(blocks_.size());
    // Static text: the slot's bins already hold these very quads for a rect of this size.
    reused = config_.reuse_static_bins && slot.bins_valid && !batched && !classified &&
             slot.binned_width == push.width && slot.binned_height == push.height &&
             slot.binned.size() == quads.size() &&
             (quads.empty() || std::memcmp(slot.binned.data(), quads.data(), quads.size_bytes()) == 0);
    if (!reused) {
        slot.bins_valid = false;
        if (Status s = prepare_slot(slot, quads, tiles, pairs); !s) return s.error();
        if (batched) {
            if (Status s = grow(slot.batch_headers, batches_.size() * sizeof(gpu::TileHeader),
                                VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "tile batch headers");
                !s) {
                return s.error();
            }
        } else if (!classified) {
            // The bins of a batched frame hold its front batch only, a classified frame's the
            // coverage of its frame: neither is reused.
            slot.binned.assign(quads.begin(), quads.end());
            slot.binned_width = push.width;
            slot.binned_height = push.height;
            slot.bins_valid = true;
        }
    }
    // The contrast model's passes only for frames that correct some glyph, the fills' only for
    // frames with colour layers: plain linear text keeps the passes, registers and speed it had
    // without them.
    const size_t variant = variant_index(target.format, target.view_format);
    uint32_t features = 0;
    for (const gpu::CompositeQuad& q : quads) {
        if (q.contrast_gamma != 1.0f || q.contrast_k != 0.0f || q.contrast_darkening != 1.0f) features |= kTileContrast;
        if (q.paint != gpu::kNoQuadPaint) features |= kTilePaints;
    }
    std::array<VkPipeline, 2>& passes = tile_pipelines_[variant][features];
    if (passes[0] == VK_NULL_HANDLE) {
        if (Status s = make_tile_passes(variant, features, passes); !s) return s.error();
    }
    write_descriptors(slot, atlas_view, paints, target.view);
    record_passes(command_buffer, slot, passes, push, reused);
    ++frame_;
    slot.pending = true;
    slot.frame = frame_;
    slot.batches = static_cast<uint32_t>(batches_.size());
    recorded_ = true;
    last_binned_ = !reused;
    return quads.size_bytes() + tile_words(tiles) * kWord + pairs * sizeof(gpu::TileBinEntry) +
           header_words(tiles) * kWord + (batched ? batches_.size() * sizeof(gpu::TileHeader) : 0);
}

}  // namespace crisp::composite
