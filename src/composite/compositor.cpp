// The GPU compositor's public face (docs/compositing.md): the tile path (tiles.cpp), the draw path
// (draw.cpp) and the reference modes (reference.cpp) over one set of quads (quads.cpp).
#include "composite/draw.hpp"
#include "composite/paints.hpp"
#include "composite/quads.hpp"
#include "composite/reference.hpp"
#include "composite/tiles.hpp"
#include "vk/context.hpp"

#include <crisp/compositor.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace crisp {

namespace {

constexpr uint32_t kMaxTargetSide = 16384;
constexpr uint32_t kMaxNodesPerPixel = 64;
static_assert(kMaxTileCapacity == gpu::kTileMaxCapacity);
static_assert(CompositorCreateInfo{}.tile_capacity == gpu::kTileDefaultCapacity);
static_assert(CompositorCreateInfo{}.tile_bin_pairs == gpu::kTileDefaultBinPairs);

std::string rect_string(const VkRect2D& rect) {
    return std::to_string(rect.extent.width) + "x" + std::to_string(rect.extent.height) + " at (" +
           std::to_string(rect.offset.x) + ", " + std::to_string(rect.offset.y) + ")";
}

// A rect of 1..16384 pixels a side inside [0, extent); empty extents mean the whole image.
Result<VkRect2D> checked_rect(VkRect2D rect, VkExtent2D extent) {
    if (rect.extent.width == 0 && rect.extent.height == 0) rect = {{0, 0}, extent};
    const int64_t right = int64_t{rect.offset.x} + rect.extent.width;
    const int64_t bottom = int64_t{rect.offset.y} + rect.extent.height;
    if (rect.extent.width == 0 || rect.extent.height == 0 || rect.extent.width > kMaxTargetSide ||
        rect.extent.height > kMaxTargetSide || rect.offset.x < 0 || rect.offset.y < 0 || right > extent.width ||
        bottom > extent.height) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: the rect " + rect_string(rect) + " is empty, above 16384 a side, or outside the " +
                         std::to_string(extent.width) + "x" + std::to_string(extent.height) + " image"};
    }
    return rect;
}

Status check_create_info(const CompositorCreateInfo& info) {
    auto invalid = [](const std::string& message) {
        return Status(Error{ErrorCode::invalid_argument, "compositor: " + message});
    };
    if (!info.instance || !info.device || !info.physical_device) {
        return invalid("an instance, a physical device and a device are required");
    }
    if (Status s = vk::check_instance_version(info.instance_api_version, "compositor"); !s) return s;
    if (info.frames_in_flight < 1 || info.frames_in_flight > 8) return invalid("frames_in_flight must be 1 to 8");
    if (info.tile_capacity < 4 || info.tile_capacity > kMaxTileCapacity || !std::has_single_bit(info.tile_capacity)) {
        return invalid("tile_capacity must be a power of two from 4 to " + std::to_string(kMaxTileCapacity));
    }
    if (info.tile_layers < 1 || info.tile_layers > kMaxCompositeLayers) return invalid("tile_layers must be 1 to 8");
    if (info.tile_bin_pairs == 0) return invalid("tile_bin_pairs must be at least 1");
    if (!info.reference_modes) return {};
    if (info.width < 1 || info.width > kMaxTargetSide || info.height < 1 || info.height > kMaxTargetSide) {
        return invalid("the target size " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                       " is outside 1..16384 per side");
    }
    if (info.exact_nodes_per_pixel > kMaxNodesPerPixel) return invalid("exact_nodes_per_pixel must be at most 64");
    return {};
}

Status no_reference_modes() {
    return Error{ErrorCode::invalid_argument,
                 "compositor: the reference modes were not made (CompositorCreateInfo::reference_modes)"};
}

Status check_frame(const DrawnFrame& frame) {
    if (!frame.atlas) return Error{ErrorCode::invalid_argument, "compositor: the frame has no atlas view"};
    if (!frame.images) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: the frame has no bitmap images view (Renderer::drawn_frame() gives one)"};
    }
    return {};
}

}  // namespace

const char* composite_mode_name(CompositeMode mode) {
    switch (mode) {
        case CompositeMode::tiled:
            return "tiled";
        case CompositeMode::draw:
            return "draw";
        case CompositeMode::unsorted:
            return "unsorted";
        case CompositeMode::wboit:
            return "wboit";
        case CompositeMode::exact:
            return "exact";
    }
    return "?";
}

const char* quad_path_name(QuadPath path) {
    return path == QuadPath::compute ? "compute" : "raster";
}

std::optional<QuadPath> parse_quad_path(std::string_view name) {
    if (name == "raster") return QuadPath::raster;
    if (name == "compute") return QuadPath::compute;
    return std::nullopt;
}

std::optional<CompositeMode> parse_composite_mode(std::string_view name) {
    for (CompositeMode mode : {CompositeMode::tiled, CompositeMode::draw, CompositeMode::unsorted, CompositeMode::wboit,
                               CompositeMode::exact}) {
        if (name == composite_mode_name(mode)) return mode;
    }
    return std::nullopt;
}

std::optional<float> depth_from_view_projection(const float view_projection[16], const float position[3]) {
    const float* m = view_projection;
    for (int i = 0; i < 16; ++i) {
        if (!std::isfinite(m[i])) return std::nullopt;
    }
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(position[i])) return std::nullopt;
    }
    // Rows 2 and 3 of the column-major matrix times (x, y, z, 1).
    const float z = m[2] * position[0] + m[6] * position[1] + m[10] * position[2] + m[14];
    const float w = m[3] * position[0] + m[7] * position[1] + m[11] * position[2] + m[15];
    if (!(w > 0.0f)) return std::nullopt;
    const float depth = z / w;
    if (!(depth >= 0.0f && depth <= 1.0f)) return std::nullopt;
    return depth;
}

struct CRISP_HIDDEN Compositor::State {
    // The caller's Vulkan entry points (CompositorCreateInfo::get_instance_proc_addr) and every
    // buffer's memory; outlives the paths below.
    std::unique_ptr<vk::Context> context;
    bool storage_without_format = false;
    composite::PaintInputs paints;  // every path's colour-layer fills
    composite::TileCompositor tiles;
    std::unique_ptr<composite::DrawCompositor> draw;            // with draw_format
    std::unique_ptr<composite::ReferenceCompositor> reference;  // with reference_modes
    uint32_t width = 0, height = 0;
    CompositorStats stats;
    std::vector<std::string> warnings;
    std::vector<gpu::CompositeQuad> quads;
    enum class Last { none, tiles, draw, reference };
    Last last = Last::none;   // the path of the last record call, until abandon_frame()
    uint64_t last_frame = 0;  // the DrawnFrame::frame it composited
    // The frame-slot rule (compositor.hpp): the DrawnFrame::frame of each of the last
    // frames_in_flight record calls, at records % frames_in_flight, and what the last call replaced
    // there (for abandon_frame()).
    std::vector<uint64_t> slot_frames;
    uint64_t records = 0;
    uint64_t replaced_frame = 0;

    // invalid_argument when the next record call's slot may still be pending: see compositor.hpp.
    Status check_slot(uint64_t frame) const;
    void took_slot(uint64_t frame);

    void take(const composite::TileCounts& counts, uint64_t frame);
};

Status Compositor::State::check_slot(uint64_t frame) const {
    const auto in_flight = static_cast<uint64_t>(slot_frames.size());
    const uint64_t previous = slot_frames[records % in_flight];
    if (frame == 0 || previous == 0 || frame <= previous || frame >= previous + in_flight) return {};
    return Error{ErrorCode::invalid_argument,
                 "compositor: frame " + std::to_string(frame) + " refused: its frame slot holds frame " +
                     std::to_string(previous) + "'s composite, which may still be on the GPU (more than " +
                     std::to_string(in_flight) + " record calls (frames_in_flight) within " +
                     std::to_string(in_flight) + " renderer frames: one record call a renderer frame)"};
}

void Compositor::State::took_slot(uint64_t frame) {
    uint64_t& slot = slot_frames[records % slot_frames.size()];
    replaced_frame = slot;
    slot = frame;
    ++records;
}

void Compositor::State::take(const composite::TileCounts& counts, uint64_t frame) {
    stats.measured = true;
    stats.measured_frame = frame;
    stats.busy_tiles = counts.busy_tiles;
    stats.exact_tiles = counts.exact_tiles;
    stats.layered_tiles = counts.layered_tiles;
    stats.tile_pairs = counts.pairs;
    stats.tile_empty_pairs = counts.empty_pairs;
    stats.tile_hidden_pairs = counts.hidden_pairs;
    stats.max_overlap = counts.max_overlap;
    stats.tail_pixels = counts.tail_pixels;
}

Compositor::Compositor(std::unique_ptr<State> state) : state_(std::move(state)) {}
Compositor::Compositor(Compositor&&) noexcept = default;
Compositor& Compositor::operator=(Compositor&&) noexcept = default;
Compositor::~Compositor() = default;

Result<Compositor> Compositor::create(const CompositorCreateInfo& info) {
    if (Status s = check_create_info(info); !s) return s.error();
    Result<std::unique_ptr<vk::Context>> context =
        vk::Context::create({info.instance, info.get_instance_proc_addr, info.physical_device, info.device,
                             info.allocator, info.pipeline_cache, info.enabled_features, 0, "compositor"});
    if (!context) return context.error();
    const vk::DeviceFeatures& enabled = (*context)->enabled;
    const VkPhysicalDeviceFeatures& core = enabled.features2.features;
    // What each asked-for path needs, against what the device was created with.
    const auto lacks = [](const char* path, const char* feature) {
        return Error{ErrorCode::vulkan,
                     std::string("compositor: ") + path + " needs " + feature +
                         ", and the device was created without it (add_crisp_features() enables it)"};
    };
    if (info.draw_format != VK_FORMAT_UNDEFINED && !enabled.vulkan13.dynamicRendering) {
        return lacks("the draw path (draw_format)", "dynamicRendering");
    }
    if (info.draw_format != VK_FORMAT_UNDEFINED && !core.dualSrcBlend) {
        return lacks("the draw path (draw_format)", "dualSrcBlend");
    }
    if (info.reference_modes && !core.fragmentStoresAndAtomics) {
        return lacks("the reference modes", "fragmentStoresAndAtomics");
    }
    if (info.reference_modes && !core.dualSrcBlend) return lacks("the reference modes", "dualSrcBlend");
    const bool storage_without_format =
        core.shaderStorageImageReadWithoutFormat && core.shaderStorageImageWriteWithoutFormat;
    auto state = std::make_unique<State>();
    state->context = std::move(*context);
    state->slot_frames.assign(info.frames_in_flight, 0);
    const vk::DeviceRef& ref = state->context->ref;
    state->storage_without_format = storage_without_format;
    composite::TileConfig tiles;
    tiles.physical_device = info.physical_device;
    tiles.frames_in_flight = info.frames_in_flight;
    tiles.layers = info.tile_layers;
    tiles.capacity = info.tile_capacity;
    tiles.storage_without_format = storage_without_format;
    tiles.reuse_static_bins = info.reuse_static_bins;
    tiles.bin_pairs = info.tile_bin_pairs;
    if (Status s = state->paints.create(ref, info.frames_in_flight); !s) return s.error();
    if (Status s = state->tiles.create(ref, tiles); !s) return s.error();
    if (!std::any_of(std::begin(kTileTargetFormats), std::end(kTileTargetFormats),
                     [&](VkFormat format) { return state->tiles.supports(format, format); })) {
        return Error{ErrorCode::vulkan, "compositor: the device can store to none of the tile path's formats"};
    }
    if (info.draw_format != VK_FORMAT_UNDEFINED) {
        state->draw = std::make_unique<composite::DrawCompositor>();
        if (Status s = state->draw->create(ref, info.physical_device, info.draw_format, info.draw_depth_format,
                                           info.frames_in_flight);
            !s) {
            return s.error();
        }
    }
    if (info.reference_modes) {
        state->width = info.width;
        state->height = info.height;
        state->reference = std::make_unique<composite::ReferenceCompositor>();
        if (Status s = state->reference->create(ref, info, state->warnings); !s) return s.error();
    }
    return Compositor(std::move(state));
}

Status Compositor::record(VkCommandBuffer command_buffer, const DrawnFrame& frame, const CompositeTarget& target) {
    State& s = *state_;
    if (Status checked = check_frame(frame); !checked) return checked;
    if (Status checked = s.check_slot(frame.frame); !checked) return checked;
    if (!target.view) return Error{ErrorCode::invalid_argument, "compositor: the target has no image view"};
    const VkFormat view_format = target.view_format != VK_FORMAT_UNDEFINED ? target.view_format : target.format;
    if (!s.tiles.supports(target.format, view_format)) {
        const bool bgra = target.format == VK_FORMAT_B8G8R8A8_UNORM && view_format == target.format;
        return Error{ErrorCode::invalid_argument,
                     "compositor: cannot composite into VkFormat " + std::to_string(target.format) + " through a " +
                         std::to_string(view_format) + " view" +
                         (bgra && !s.storage_without_format
                              ? ": a B8G8R8A8_UNORM view needs storage_without_format (or use an R8G8B8A8_UNORM "
                                "view of a MUTABLE_FORMAT image)"
                              : ": the tile path takes R8G8B8A8_UNORM, B8G8R8A8_UNORM, R16G16B16A16_SFLOAT and "
                                "R32G32B32A32_SFLOAT where the device can store to them")};
    }
    Result<VkRect2D> rect = checked_rect(target.rect, target.extent);
    if (!rect) return rect.error();
    composite::sort_front_to_back(frame.glyphs, frame.paints.size(), rect->extent.width, rect->extent.height, s.quads);
    composite::TileCounts counts;
    uint64_t measured_frame = 0;
    bool reused = false;
    const composite::TileTarget tile_target{target.view, target.format, view_format, rect->offset, rect->extent};
    if (Status p = s.paints.upload(frame); !p) return p;
    Result<uint64_t> bytes =
        s.tiles.record(command_buffer, s.quads, frame.atlas, s.paints, tile_target, counts, measured_frame, reused);
    if (!bytes) {
        s.paints.abandon_frame();
        return bytes.error();
    }
    if (measured_frame != 0) s.take(counts, measured_frame);
    s.took_slot(frame.frame);
    s.last = State::Last::tiles;
    s.last_frame = frame.frame;
    s.stats.mode = CompositeMode::tiled;
    s.stats.path = QuadPath::compute;
    s.stats.quads = static_cast<uint32_t>(s.quads.size());
    s.stats.tiles = 0;
    s.stats.buffer_bytes = *bytes;
    s.stats.bins_reused = reused;
    s.stats.tile_batches = s.tiles.batches();
    return {};
}

Status Compositor::abandon_frame(uint64_t frame) {
    State& s = *state_;
    if (s.last == State::Last::none || s.last_frame != frame) {
        return Error{
            ErrorCode::invalid_argument,
            "compositor: abandon_frame(" + std::to_string(frame) + "): " +
                (s.last == State::Last::none ? std::string("no record to take back")
                                             : "its last record was of frame " + std::to_string(s.last_frame)) +
                ": nothing taken back"};
    }
    switch (s.last) {
        case State::Last::tiles:
            s.tiles.abandon_frame();
            break;
        case State::Last::draw:
            s.draw->abandon_frame();
            break;
        case State::Last::reference:
            s.reference->abandon_frame();
            break;
        case State::Last::none:
            break;
    }
    s.paints.abandon_frame();
    s.last = State::Last::none;
    --s.records;
    s.slot_frames[s.records % s.slot_frames.size()] = s.replaced_frame;
    return {};
}

Status Compositor::record_draw(VkCommandBuffer command_buffer, const DrawnFrame& frame, const VkRect2D& rect) {
    State& s = *state_;
    if (Status checked = check_frame(frame); !checked) return checked;
    if (Status checked = s.check_slot(frame.frame); !checked) return checked;
    if (!s.draw) {
        return Error{ErrorCode::invalid_argument, "compositor: no draw pipeline (CompositorCreateInfo::draw_format)"};
    }
    if (rect.extent.width == 0 || rect.extent.height == 0 || rect.extent.width > kMaxTargetSide ||
        rect.extent.height > kMaxTargetSide || rect.offset.x < 0 || rect.offset.y < 0) {
        return Error{ErrorCode::invalid_argument, "compositor: the draw rect " + rect_string(rect) +
                                                      " is empty, above 16384 a side or at a negative offset"};
    }
    composite::sort_front_to_back(frame.glyphs, frame.paints.size(), rect.extent.width, rect.extent.height, s.quads);
    if (Status p = s.paints.upload(frame); !p) return p;
    Result<uint64_t> bytes = s.draw->record(command_buffer, s.quads, frame.atlas, s.paints, rect);
    if (!bytes) {
        s.paints.abandon_frame();
        return bytes.error();
    }
    s.took_slot(frame.frame);
    s.last = State::Last::draw;
    s.last_frame = frame.frame;
    s.stats.mode = CompositeMode::draw;
    s.stats.path = QuadPath::raster;
    s.stats.quads = static_cast<uint32_t>(s.quads.size());
    s.stats.buffer_bytes = *bytes;
    return {};
}

Status Compositor::record_reference(VkCommandBuffer command_buffer, const DrawnFrame& frame,
                                    const CompositeParams& params) {
    if (!state_->reference) return no_reference_modes();
    if (Status checked = check_frame(frame); !checked) return checked;
    State& s = *state_;
    if (Status checked = s.check_slot(frame.frame); !checked) return checked;
    if (Status p = s.paints.upload(frame); !p) return p;
    Status status = s.reference->record(command_buffer, frame, s.paints, params, s.stats);
    if (status) {
        s.took_slot(frame.frame);
        s.last = State::Last::reference;
        s.last_frame = frame.frame;
    } else {
        s.paints.abandon_frame();
    }
    return status;
}

bool Compositor::supports_target_format(VkFormat format, VkFormat view_format) const {
    return state_->tiles.supports(format, view_format != VK_FORMAT_UNDEFINED ? view_format : format);
}

void Compositor::record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const {
    if (state_->reference) state_->reference->record_target_readback(command_buffer, buffer);
}

VkImage Compositor::target_image() const {
    return state_->reference ? state_->reference->target().image : VK_NULL_HANDLE;
}
VkImageView Compositor::target_view() const {
    return state_->reference ? state_->reference->target().view : VK_NULL_HANDLE;
}
uint32_t Compositor::width() const {
    return state_->width;
}
uint32_t Compositor::height() const {
    return state_->height;
}
const CompositorStats& Compositor::stats() const {
    return state_->stats;
}
const std::vector<ShaderStatistic>& Compositor::shader_statistics() const {
    return state_->context->shader_statistics;
}
DeviceMemoryUse Compositor::device_memory() const {
    const State& s = *state_;
    DeviceMemoryUse use{s.context->arena.block_count(), s.context->arena.block_bytes()};
    if (s.reference) {
        const vk::DeviceImage& target = s.reference->target();
        use.allocations += target.memory != VK_NULL_HANDLE ? 1 : 0;
        use.bytes += target.memory_size;
    }
    return use;
}
const std::vector<std::string>& Compositor::warnings() const {
    return state_->warnings;
}

}  // namespace crisp
