// The renderer's public face (include/crisp/renderer.hpp): the frame contract over its parts,
// the fonts on the GPU (raster/font_store), the draw requests (raster/requests) at the frame's
// subpixel steps (raster/coarsening), the atlas image (raster/atlas_image), the rasterizer's work
// items and dispatch (raster/raster), and what waits for the GPU to finish (raster/retired).
#include "raster/atlas_image.hpp"
#include "raster/bitmaps.hpp"
#include "raster/coarsening.hpp"
#include "raster/font_store.hpp"
#include "raster/paints.hpp"
#include "raster/raster.hpp"
#include "raster/requests.hpp"
#include "raster/retired.hpp"
#include "vk/context.hpp"

#include <crisp/renderer.hpp>

#include <bit>
#include <memory>
#include <string>
#include <utility>

namespace crisp {

struct CRISP_HIDDEN Renderer::State {
    std::unique_ptr<vk::Context> context;  // every part's functions and memory: declared first, destroyed last
    uint32_t frames_in_flight = 2;
    SampleKind sample_kind = SampleKind::rows;
    raster::AtlasLimits limits;

    GlyphAtlas atlas;
    SubpixelLayout subpixel;
    RendererStats stats;
    raster::Coarsening coarsening;
    raster::Coarsening coarsening_begun;  // as it was at begin_frame(), for abandon_frame()
    raster::FontStore fonts;
    raster::MotionTracker motion;
    raster::FrameRequests requests;
    raster::RetireLists retired;
    raster::AtlasImage image;
    raster::RasterPass raster;
    raster::FramePaints paints;
    raster::BitmapLayers bitmaps;

    uint64_t frame = 0;
    bool recorded = false;      // record() since begin_frame(): abandon_frame() has a frame to take back
    bool begun = false;         // begin_frame() since the last record() or abandon_frame(): record() may run
    uint64_t frame_number = 0;  // frame(): begin_frame()s so far

    State(std::unique_ptr<vk::Context> vk_context, GlyphAtlas glyph_atlas, SubpixelLayout subpixel_layout,
          const RendererCreateInfo& info)
        : context(std::move(vk_context)),
          frames_in_flight(info.frames_in_flight),
          sample_kind(info.sample_kind),
          limits{context->properties.limits.maxImageDimension2D, info.atlas_memory_budget},
          atlas(std::move(glyph_atlas)),
          subpixel(std::move(subpixel_layout)),
          fonts(context->ref, context->properties.limits.maxStorageBufferRange),
          requests(atlas, fonts, coarsening, stats),
          image(context->ref),
          raster(context->ref, {info.frames_in_flight, info.shared_row_roots, info.sample_kind}),
          bitmaps(context->ref, info.bitmap_layers, info.bitmap_layer_side, info.frames_in_flight) {
        requests.set_contrast(info.contrast);
    }

    Status prepare_atlas_image(VkCommandBuffer command_buffer, uint64_t this_frame);
};

Result<Renderer> Renderer::create(const RendererCreateInfo& info) {
    if (!info.instance || !info.device || !info.physical_device) {
        return Error{ErrorCode::invalid_argument, "renderer: an instance, a physical device and a device are required"};
    }
    if (Status s = vk::check_instance_version(info.instance_api_version, "renderer"); !s) return s.error();
    if (info.frames_in_flight < 1 || info.frames_in_flight > 8) {
        return Error{ErrorCode::invalid_argument, "renderer: frames_in_flight must be 1 to 8"};
    }
    if (info.atlas.max_samples > kMaxRendererSamples) {
        return Error{ErrorCode::invalid_argument, "renderer: max_samples " + std::to_string(info.atlas.max_samples) +
                                                      " is above the " + std::to_string(kMaxRendererSamples) +
                                                      " the 16-bit accumulators hold"};
    }
    if (info.sample_kind != SampleKind::rows && info.sample_kind != SampleKind::points) {
        return Error{ErrorCode::invalid_argument, "renderer: sample_kind " +
                                                      std::to_string(static_cast<uint32_t>(info.sample_kind)) +
                                                      " is neither rows (0) nor points (1)"};
    }
    if (Status s = validate_text_contrast(info.contrast); !s) {
        return Error{ErrorCode::invalid_argument, "renderer: " + s.error().message};
    }
    if (info.bitmap_layers < 1 || info.bitmap_layers > 4096 || info.bitmap_layer_side < 16 ||
        info.bitmap_layer_side > 1024 || !std::has_single_bit(info.bitmap_layer_side)) {
        return Error{ErrorCode::invalid_argument, "renderer: bitmap_layers " + std::to_string(info.bitmap_layers) +
                                                      " (1..4096) or bitmap_layer_side " +
                                                      std::to_string(info.bitmap_layer_side) +
                                                      " (a power of two, 16..1024) is out of range"};
    }
    SubpixelLayout subpixel = info.layout;
    if (subpixel.name.empty() && subpixel == SubpixelLayout{}) subpixel = *subpixel_preset("rgb");
    if (Status s = validate_subpixel_layout(subpixel); !s) return s.error();
    auto atlas = GlyphAtlas::create(info.atlas);
    if (!atlas) return atlas.error();

    Result<std::unique_ptr<vk::Context>> context = vk::Context::create(
        {info.instance, info.get_instance_proc_addr, info.physical_device, info.device, info.allocator,
         info.pipeline_cache, info.enabled_features, VK_API_VERSION_1_2, "renderer"});
    if (!context) return context.error();
    const vk::Context& vulkan = **context;
    if (!vulkan.enabled.features2.features.shaderStorageBufferArrayDynamicIndexing) {
        return Error{ErrorCode::vulkan,
                     "renderer: the device was created without shaderStorageBufferArrayDynamicIndexing (enable it; "
                     "add_crisp_features() does)"};
    }
    const uint32_t buffers_needed = 2 + 2 * kRendererFontPages;
    if (vulkan.properties.limits.maxPerStageDescriptorStorageBuffers < buffers_needed) {
        return Error{ErrorCode::vulkan,
                     "renderer: the device offers " +
                         std::to_string(vulkan.properties.limits.maxPerStageDescriptorStorageBuffers) +
                         " storage buffers per shader stage (maxPerStageDescriptorStorageBuffers); "
                         "crisp needs " +
                         std::to_string(buffers_needed)};
    }
    VkFormatProperties format{};
    vulkan.fn.vkGetPhysicalDeviceFormatProperties(info.physical_device, raster::kAtlasFormat, &format);
    if (!(format.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)) {
        return Error{ErrorCode::vulkan, "renderer: the device lacks storage images of R16G16B16A16_UINT"};
    }

    auto state = std::make_unique<State>(std::move(*context), std::move(*atlas), std::move(subpixel), info);
    const AtlasConfig& config = state->atlas.config();
    if (Status s = state->image.create(config); !s) return s.error();
    if (Status s = state->bitmaps.create(); !s) return s.error();
    if (Status s = state->raster.create(state->atlas.stats().usable_cells, uint64_t{config.width} * config.height,
                                        state->retired);
        !s) {
        return s.error();
    }
    return Renderer(std::move(state));
}

Renderer::Renderer(std::unique_ptr<State> state) : state_(std::move(state)) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

Status Renderer::add_font(const Font& font) {
    return state_->fonts.add(font);
}

Status Renderer::remove_font(FontId id) {
    return state_->fonts.remove(id);
}

Status Renderer::set_subpixel_layout(const SubpixelLayout& subpixel) {
    if (Status s = validate_subpixel_layout(subpixel); !s) return s;
    state_->subpixel = subpixel;
    state_->atlas.invalidate_samples();
    return {};
}

const SubpixelLayout& Renderer::subpixel_layout() const {
    return state_->subpixel;
}

SampleKind Renderer::sample_kind() const {
    return state_->sample_kind;
}

Status Renderer::set_contrast(const TextContrast& contrast) {
    if (Status s = validate_text_contrast(contrast); !s) return s;
    state_->requests.set_contrast(contrast);
    return {};
}

const TextContrast& Renderer::contrast() const {
    return state_->requests.contrast();
}

Status Renderer::abandon_frame(uint64_t frame) {
    State& s = *state_;
    if (frame != s.frame_number || s.frame_number == 0) {
        return Error{ErrorCode::invalid_argument, "renderer: abandon_frame(" + std::to_string(frame) +
                                                      ") for a frame that is not the current one (" +
                                                      std::to_string(s.frame_number) + "): nothing taken back"};
    }
    if (!s.recorded) return {};
    s.recorded = false;
    s.atlas.abandon_frame();
    s.image.abandon_frame(s.retired);
    s.bitmaps.abandon_frame();
    // Motion and the subpixel-step level go back to what they were, as if the frame never began.
    s.motion.abandon_frame();
    s.coarsening = s.coarsening_begun;
    // The fonts' uploads go back to waiting, with their staging buffers.
    s.fonts.abandon_uploads(s.retired, s.frame - 1);
    --s.frame;  // an abandoned frame does not count towards frames_in_flight
    s.requests.abandon_frame();
    return {};
}

void Renderer::begin_frame() {
    State& s = *state_;
    s.motion.begin_frame();
    s.recorded = false;
    s.begun = true;
    ++s.frame_number;
    s.coarsening_begun = s.coarsening;
    s.atlas.begin_frame();  // unpins last frame's glyphs, so that removed fonts' entries can go
    for (FontId id : s.fonts.pending_removals()) s.bitmaps.forget_font(id);
    s.fonts.apply_removals(s.atlas, s.retired, s.frame);
    s.fonts.begin_frame(s.retired, s.frame);
    s.bitmaps.begin_frame(s.frame);
    s.requests.begin_frame();
    s.stats = {};
}

void Renderer::draw(std::span<const GlyphInstance> glyphs) {
    for (const GlyphInstance& glyph : glyphs) state_->requests.add(glyph, nullptr, kSubpixelSteps);
}

void Renderer::draw(std::span<const GlyphInstance> glyphs, const VkRect2D& visible) {
    for (const GlyphInstance& glyph : glyphs) state_->requests.add(glyph, &visible, kSubpixelSteps);
}

void Renderer::draw(std::span<const GlyphInstance> glyphs, const DrawOptions& options) {
    state_->requests.add(glyphs, options, state_->motion);
}

// The atlas image at the atlas's size (grown where the atlas grew) and in GENERAL.
Status Renderer::State::prepare_atlas_image(VkCommandBuffer command_buffer, uint64_t this_frame) {
    image.begin_record();
    const AtlasConfig& config = atlas.config();
    if (!image.holds(config)) {
        // The atlas grew (GlyphAtlas::grow): a larger image takes the old one's texels at its top-left,
        // and the old one is freed once the frames that read it are done. The work items grow with it.
        vk::DeviceImage grown;
        if (Status s = image.make(config, grown); !s) return s;
        const uint64_t texels = uint64_t{config.width} * config.height;
        if (Status s = raster.fit(atlas.stats().usable_cells, texels, this_frame, retired); !s) return s;
        image.record_growth(command_buffer, std::move(grown), config, this_frame, retired);
    }
    image.record_first_layout(command_buffer);
    return {};
}

Status Renderer::record(VkCommandBuffer command_buffer) {
    State& s = *state_;
    // Misuse the renderer can see: its frame counter and the atlas's turn would move on twice, and
    // the second command buffer would reuse the first's per-frame resources.
    if (s.recorded) {
        return Error{
            ErrorCode::invalid_argument,
            "renderer: record() called twice in one frame: call begin_frame() and draw() before each record()"};
    }
    if (!s.begun) {
        return Error{ErrorCode::invalid_argument,
                     "renderer: record() without begin_frame(): call begin_frame() and draw() before each record()"};
    }
    s.begun = false;
    s.requests.settle(s.limits);
    const std::span<const RasterWork> work = s.atlas.schedule();
    s.requests.collect_drawn();
    s.stats.derived_glyphs = s.fonts.derived_glyphs();
    s.stats.derived_made = s.fonts.derived_made();
    s.stats.derived_bytes = s.fonts.derived_bytes();
    s.paints.resolve(s.requests.drawn_to_fill(), s.fonts, &s.bitmaps, s.stats);

    s.recorded = true;
    const uint64_t frame = s.frame++;
    s.retired.release_finished(frame, s.frames_in_flight, s.fonts);
    const bool fonts_uploaded = s.fonts.record_uploads(command_buffer, frame, s.retired, s.stats);
    if (Status prepared = s.prepare_atlas_image(command_buffer, frame); !prepared) return prepared;
    if (Status images = s.bitmaps.record(command_buffer, frame, s.retired, s.stats); !images) return images;
    s.raster.build(work, s.fonts, s.atlas, s.stats);
    if (Status made = s.raster.prepare_pipelines(); !made) return made;
    s.raster.record_upload(command_buffer, frame, fonts_uploaded, s.stats);
    if (s.raster.has_items()) {
        s.raster.record_dispatch(command_buffer, frame, s.image.image().view, s.fonts.pages(), s.subpixel);
    }
    return {};
}

void Renderer::record_atlas_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const {
    state_->image.record_readback(command_buffer, buffer, state_->atlas.config());
}

std::span<const DrawnGlyph> Renderer::drawn() const {
    return state_->requests.drawn();
}
DrawnFrame Renderer::drawn_frame() const {
    return DrawnFrame{drawn(),
                      atlas_view(),
                      state_->paints.paints(),
                      state_->paints.stops(),
                      state_->bitmaps.view(),
                      state_->frame_number};
}
uint64_t Renderer::frame() const {
    return state_->frame_number;
}
bool Renderer::converged() const {
    return state_->requests.converged();
}
const RendererStats& Renderer::stats() const {
    return state_->stats;
}
const std::vector<ShaderStatistic>& Renderer::shader_statistics() const {
    return state_->context->shader_statistics;
}
DeviceMemoryUse Renderer::device_memory() const {
    const State& s = *state_;
    DeviceMemoryUse use{s.context->arena.block_count(), s.context->arena.block_bytes()};
    const DeviceMemoryUse images = s.bitmaps.memory();
    use.allocations += images.allocations;
    use.bytes += images.bytes;
    for (const vk::DeviceImage* image : {&s.image.image()}) {
        use.allocations += image->memory != VK_NULL_HANDLE ? 1 : 0;
        use.bytes += image->memory_size;
    }
    for (const raster::RetiredImage& r : s.retired.images) {
        ++use.allocations;
        use.bytes += r.image.memory_size;
    }
    return use;
}
const GlyphAtlas& Renderer::atlas() const {
    return state_->atlas;
}
VkImage Renderer::atlas_image() const {
    return state_->image.image().image;
}
VkImageView Renderer::atlas_view() const {
    return state_->image.image().view;
}

}  // namespace crisp
