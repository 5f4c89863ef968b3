// The compositor's reference modes (docs/compositing.md): unsorted,
// weighted blended OIT and the exact per-pixel linked lists, into the compositor's own RGBA32F
// target over a flat background. Every pass but unsorted reads or writes per-pixel storage
// buffers; unsorted blends into the target as a colour attachment.
#include "composite/reference.hpp"

#include "composite/quad_pipeline.hpp"
#include "composite/quads.hpp"
#include "vk/barriers.hpp"
#include "vk/bindings.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

namespace crisp::composite {

using vk::image_barrier;
using vk::kShaderAccess;
using vk::kShaderStages;
using vk::memory_barrier;

namespace {

constexpr VkFormat kTargetFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkDeviceSize kWord = 4;
static_assert(kMaxCompositeLayers == gpu::kCompositeMaxLayers);
static_assert(kMaxExactFragmentsPerPixel == gpu::kCompositeExactMaxPerPixel);

constexpr VkShaderStageFlags kPushStages =
    VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT | VK_SHADER_STAGE_COMPUTE_BIT;
// The one descriptor set layout every pipeline shares, visible to the push constants' stages.
constexpr vk::Binding kBindings[] = {
    {gpu::kCompositeBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kCompositeBindQuads, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindAccumulators, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindNodes, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindStats, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindTarget, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
    {gpu::kCompositeBindTiles, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindPaints, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindStops, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
    {gpu::kCompositeBindImages, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
};
constexpr vk::BindingTable kTable{kBindings, kPushStages};

}  // namespace

ReferenceCompositor::~ReferenceCompositor() = default;

Result<VkShaderModule> ReferenceCompositor::module(const char* name) {
    if (auto it = modules.find(name); it != modules.end()) return it->second;
    Result<VkShaderModule> made = vk::create_embedded_shader(ref, name);
    if (made) modules.emplace(name, objects.keep(ref, *made));
    return made;
}

Result<VkPipeline> ReferenceCompositor::graphics_pipeline(const char* fragment,
                                                          const VkSpecializationInfo* specialization, bool blend) {
    Result<VkShaderModule> vertex_module = module("quad_pipeline.vert");
    if (!vertex_module) return vertex_module.error();
    Result<VkShaderModule> fragment_module = module(fragment);
    if (!fragment_module) return fragment_module.error();
    QuadPipeline desc;
    desc.vertex = *vertex_module;
    desc.fragment = *fragment_module;
    desc.specialization = specialization;
    desc.layout = descriptors.pipeline_layout;
    desc.blend_over = blend;  // unsorted
    desc.render_pass = blend ? color_pass : empty_pass;
    desc.what = fragment;
    Result<VkPipeline> made = create_quad_pipeline(ref, desc);
    if (made) objects.keep(ref, *made);
    return made;
}

Result<VkPipeline> ReferenceCompositor::compute_pipeline(const char* shader,
                                                         const VkSpecializationInfo* specialization) {
    Result<VkShaderModule> compute_module = module(shader);
    if (!compute_module) return compute_module.error();
    Result<VkPipeline> made =
        vk::create_compute_pipeline(ref, *compute_module, descriptors.pipeline_layout, specialization, shader);
    if (made) objects.keep(ref, *made);
    return made;
}

// Per-pixel buffers: the accumulators (plane-major), the exact mode's node pool and the stats.
Status ReferenceCompositor::create_buffers(const CompositorCreateInfo& info, std::vector<std::string>& warnings) {
    VkPhysicalDeviceProperties properties{};
    ref.fn->vkGetPhysicalDeviceProperties(info.physical_device, &properties);
    const VkDeviceSize range = properties.limits.maxStorageBufferRange;
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    static_assert(gpu::kWboitWords >= gpu::kExactWords);
    const VkDeviceSize accumulator_bytes = VkDeviceSize{pixels} * gpu::kWboitWords * kWord;
    if (accumulator_bytes > range) {
        return Error{ErrorCode::vulkan, "compositor: the per-pixel accumulators of a " + std::to_string(width) + "x" +
                                            std::to_string(height) + " target need " +
                                            std::to_string(accumulator_bytes) +
                                            " bytes, above maxStorageBufferRange (" + std::to_string(range) + ")"};
    }
    if (Status s = vk::create_buffer(ref, accumulator_bytes, storage, false, "reference accumulators", accumulators);
        !s)
        return s;
    const VkDeviceSize node_bytes = gpu::kCompositeNodeWords * kWord;
    VkDeviceSize wanted_nodes = VkDeviceSize{pixels} * info.exact_nodes_per_pixel;
    if (wanted_nodes * node_bytes > range) {
        const VkDeviceSize fitting = range / node_bytes;
        warnings.push_back("exact mode: maxStorageBufferRange holds " + std::to_string(fitting) + " of the " +
                           std::to_string(wanted_nodes) + " list nodes asked for");
        wanted_nodes = fitting;
    }
    node_capacity = static_cast<uint32_t>(std::min<VkDeviceSize>(wanted_nodes, 0xFFFFFFFEu));
    if (Status s = vk::create_buffer(ref, std::max<VkDeviceSize>(node_capacity, 1) * node_bytes,
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "exact node pool", nodes);
        !s) {
        return s;
    }
    if (Status s = vk::create_buffer(ref, gpu::kStatWords * kWord, storage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false,
                                     "reference statistics", stats_words);
        !s) {
        return s;
    }

    return {};
}

// Render passes: none of crisp's passes needs a barrier inside one; the pipeline barriers
// around them order every access.
Status ReferenceCompositor::create_passes() {
    const VkDevice device = ref.device;
    const VkAllocationCallbacks* allocator = ref.allocator;
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VkRenderPassCreateInfo pass_info{};
    pass_info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    pass_info.subpassCount = 1;
    pass_info.pSubpasses = &subpass;
    if (VkResult r = ref.fn->vkCreateRenderPass(device, &pass_info, allocator, &empty_pass); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateRenderPass (compositor)", r);
    }
    objects.keep(ref, empty_pass);
    VkAttachmentDescription attachment{};
    attachment.format = kTargetFormat;
    attachment.samples = VK_SAMPLE_COUNT_1_BIT;
    attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // to the background
    attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachment.initialLayout = VK_IMAGE_LAYOUT_GENERAL;
    attachment.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
    const VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_GENERAL};
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &reference;
    pass_info.attachmentCount = 1;
    pass_info.pAttachments = &attachment;
    if (VkResult r = ref.fn->vkCreateRenderPass(device, &pass_info, allocator, &color_pass); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateRenderPass (compositor)", r);
    }
    objects.keep(ref, color_pass);
    VkFramebufferCreateInfo framebuffer{};
    framebuffer.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    framebuffer.renderPass = empty_pass;
    framebuffer.width = width;
    framebuffer.height = height;
    framebuffer.layers = 1;
    if (VkResult r = ref.fn->vkCreateFramebuffer(device, &framebuffer, allocator, &empty_framebuffer);
        r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFramebuffer (compositor)", r);
    }
    objects.keep(ref, empty_framebuffer);
    framebuffer.renderPass = color_pass;
    framebuffer.attachmentCount = 1;
    framebuffer.pAttachments = &target_.view;
    if (VkResult r = ref.fn->vkCreateFramebuffer(device, &framebuffer, allocator, &color_framebuffer);
        r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFramebuffer (compositor)", r);
    }
    objects.keep(ref, color_framebuffer);

    return {};
}

Status ReferenceCompositor::create(const vk::DeviceRef& device, const CompositorCreateInfo& info,
                                   std::vector<std::string>& warnings) {
    ref = device;
    width = info.width;
    height = info.height;
    pixels = info.width * info.height;
    frames_in_flight = info.frames_in_flight;
    VkPhysicalDeviceProperties properties{};
    ref.fn->vkGetPhysicalDeviceProperties(info.physical_device, &properties);
    VkFormatProperties format{};
    ref.fn->vkGetPhysicalDeviceFormatProperties(info.physical_device, kTargetFormat, &format);
    const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                        VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT |
                                        VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    if ((format.optimalTilingFeatures & needed) != needed) {
        return Error{ErrorCode::vulkan, std::string("compositor: ") + properties.deviceName +
                                            " cannot blend, store to and copy R32G32B32A32_SFLOAT images"};
    }

    // The target image.
    if (Status s = vk::create_image(ref, kTargetFormat, width, height,
                                    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                        VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                    "compositor target", target_);
        !s) {
        return s;
    }

    if (Status s = create_buffers(info, warnings); !s) return s;
    if (Status s = create_descriptors(); !s) return s;
    if (Status s = create_passes(); !s) return s;
    return create_pipelines();
}

// The descriptor set layout every pipeline shares, one set and one stats read-back per frame slot.
Status ReferenceCompositor::create_descriptors() {
    if (Status s = vk::create_descriptor_sets(ref, kTable, sizeof(gpu::CompositePushConstants), frames_in_flight,
                                              "compositor", descriptors);
        !s) {
        return s;
    }
    slots.resize(frames_in_flight);
    for (uint32_t i = 0; i < frames_in_flight; ++i) {
        FrameSlot& slot = slots[i];
        slot.set = descriptors.sets[i];
        if (Status s = vk::create_buffer(ref, gpu::kStatWords * kWord, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true,
                                         "reference statistics readback", slot.stats);
            !s) {
            return s;
        }
    }
    return {};
}

// The fixed pipelines; the compute quad passes are made on first use.
Status ReferenceCompositor::create_pipelines() {
    struct Made {
        VkPipeline* pipeline;
        Result<VkPipeline> result;
    };
    Made made[] = {
        {&unsorted, graphics_pipeline("draw.frag", nullptr, true)},
        {&wboit, graphics_pipeline("reference_wboit.frag", nullptr, false)},
        {&exact, graphics_pipeline("reference_exact.frag", nullptr, false)},
        {&wboit_resolve, compute_pipeline("reference_wboit_resolve.comp", nullptr)},
        {&exact_resolve, compute_pipeline("reference_exact_resolve.comp", nullptr)},
    };
    for (Made& m : made) {
        if (m.result) *m.pipeline = *m.result;
    }
    for (Made& m : made) {
        if (!m.result) return m.result.error();
    }
    return {};
}

void ReferenceCompositor::abandon_frame() {
    if (!recorded) return;
    recorded = false;
    --frame;
    slots[frame % frames_in_flight].pending = false;  // its stats will never be written
    target_initialized = target_was_initialized;
}

void ReferenceCompositor::read_back_stats(FrameSlot& slot, CompositorStats& stats) {
    if (!slot.pending) return;
    slot.pending = false;
    uint32_t words[gpu::kStatWords];
    std::memcpy(words, slot.stats.mapped, sizeof(words));
    stats.measured = true;
    stats.measured_frame = slot.frame;
    stats.max_overlap = words[gpu::kStatMaxOverlap];
    stats.exact_lost_nodes = slot.mode == CompositeMode::exact && words[gpu::kStatNodesUsed] > node_capacity
                                 ? words[gpu::kStatNodesUsed] - node_capacity
                                 : 0;
    stats.exact_dropped = words[gpu::kStatListOverflow];
}

void ReferenceCompositor::build_tiles() {
    tile_data.clear();
    const int64_t tile = gpu::kCompositeTile;
    for (uint32_t i = 0; i < quad_data.size(); ++i) {
        const gpu::CompositeQuad& q = quad_data[i];
        // Tiles are 8 x 8 blocks of the rect from its corner, their origins in the rect 16 bits
        // each: a rect past 65536 texels a side (the renderer's are at most a few thousand) is
        // not drawn. Only the tiles that reach the target are listed.
        if (q.width > 0xFFFFu || q.height > 0xFFFFu) continue;
        const int64_t x0 = std::max<int64_t>(0, -int64_t{q.x}), y0 = std::max<int64_t>(0, -int64_t{q.y});
        const int64_t x1 = std::min<int64_t>(q.width, int64_t{width} - q.x);
        const int64_t y1 = std::min<int64_t>(q.height, int64_t{height} - q.y);
        for (int64_t y = y0 / tile * tile; y < y1; y += tile) {
            for (int64_t x = x0 / tile * tile; x < x1; x += tile) {
                tile_data.push_back(i);
                tile_data.push_back(static_cast<uint32_t>(x | (y << 16)));
            }
        }
    }
}

Status ReferenceCompositor::upload(vk::DeviceBuffer& buffer, uint32_t& capacity, const void* data, uint32_t count,
                                   size_t size) {
    if (count > capacity || !buffer.buffer) {
        // The slot's last use is done (the frames-in-flight contract), so its buffer can go.
        buffer.reset();
        capacity = 0;
        const uint32_t grown = std::max<uint32_t>(64, std::bit_ceil(std::max(count, 1u)));
        if (Status s = vk::create_buffer(ref, VkDeviceSize{grown} * size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                                         "reference quads", buffer);
            !s) {
            return s;
        }
        capacity = grown;
    }
    if (count > 0) std::memcpy(buffer.mapped, data, count * size);
    return {};
}

void ReferenceCompositor::write_descriptors(const FrameSlot& slot, VkImageView atlas_view, const PaintInputs& paints) {
    vk::DescriptorWrites writes(kTable, slot.set);
    paints.write(writes, gpu::kCompositeBindPaints, gpu::kCompositeBindStops, gpu::kCompositeBindImages);
    writes.storage_image(gpu::kCompositeBindAtlas, atlas_view)
        .storage_buffer(gpu::kCompositeBindQuads, slot.quads.buffer)
        .storage_buffer(gpu::kCompositeBindAccumulators, accumulators.buffer)
        .storage_buffer(gpu::kCompositeBindNodes, nodes.buffer)
        .storage_buffer(gpu::kCompositeBindStats, stats_words.buffer)
        .storage_image(gpu::kCompositeBindTarget, target_.view)
        .storage_buffer(gpu::kCompositeBindTiles, slot.tiles.buffer)
        .update(ref);
}

Status ReferenceCompositor::check(const CompositeParams& params) const {
    if (params.mode == CompositeMode::tiled || params.mode == CompositeMode::draw) {
        return Error{ErrorCode::invalid_argument, std::string("compositor: ") + composite_mode_name(params.mode) +
                                                      " is not a reference mode (record() and record_draw() take it)"};
    }
    if (params.mode == CompositeMode::exact && node_capacity == 0) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: the exact mode needs a node pool (exact_nodes_per_pixel)"};
    }
    return {};
}

Result<bool> ReferenceCompositor::compute_pass_for(const CompositeParams& params) {
    const bool compute = params.path == QuadPath::compute && params.mode != CompositeMode::unsorted;
    if (compute) {
        const bool is_wboit = params.mode == CompositeMode::wboit;
        VkPipeline& pipeline = is_wboit ? wboit_compute : exact_compute;
        if (!pipeline) {
            Result<VkPipeline> made =
                compute_pipeline(is_wboit ? "reference_wboit_quads.comp" : "reference_exact_quads.comp", nullptr);
            if (!made) return made.error();
            pipeline = *made;
        }
    }
    return compute;
}

gpu::CompositePushConstants ReferenceCompositor::push_constants(const CompositeParams& params) const {
    gpu::CompositePushConstants push{};
    const float alpha = clamp01(params.background[3]);
    push.background = {clamp01(params.background[0]) * alpha, clamp01(params.background[1]) * alpha,
                       clamp01(params.background[2]) * alpha, alpha};
    push.width = width;
    push.height = height;
    push.pixels = pixels;
    push.node_capacity = node_capacity;
    push.tile_count = static_cast<uint32_t>(tile_data.size() / 2);
    push.quad_count = static_cast<uint32_t>(quad_data.size());
    return push;
}

// The target's first use takes it from UNDEFINED to GENERAL, where the compositor keeps it.
void ReferenceCompositor::record_target_init(VkCommandBuffer command_buffer) {
    if (target_initialized) return;
    image_barrier(*ref.fn, command_buffer, target_.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                  VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                  VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    target_initialized = true;
}

// Every earlier use of the buffers and the target (this compositor's last frames, the caller's
// reads of the target) before this frame's clears; then the mode's clears. Returns the bytes of
// per-pixel buffers the mode uses.
uint64_t ReferenceCompositor::record_clears(VkCommandBuffer command_buffer, CompositeMode mode) {
    constexpr VkPipelineStageFlags stages =
        kShaderStages | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    memory_barrier(*ref.fn, command_buffer, stages,
                   kShaderAccess | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                   stages,
                   kShaderAccess | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    const VkDeviceSize pixel_words = VkDeviceSize{pixels} * kWord;
    ref.fn->vkCmdFillBuffer(command_buffer, stats_words.buffer, 0, VK_WHOLE_SIZE, 0);
    uint64_t buffer_bytes = 0;
    switch (mode) {
        case CompositeMode::wboit:
            ref.fn->vkCmdFillBuffer(command_buffer, accumulators.buffer, 0, pixel_words * gpu::kWboitWords, 0);
            buffer_bytes = pixel_words * gpu::kWboitWords;
            break;
        case CompositeMode::exact:
            ref.fn->vkCmdFillBuffer(command_buffer, accumulators.buffer, 0, pixel_words * gpu::kExactWords,
                                    gpu::kCompositeNoNode);
            buffer_bytes =
                pixel_words * gpu::kExactWords + VkDeviceSize{node_capacity} * gpu::kCompositeNodeWords * kWord;
            break;
        case CompositeMode::unsorted:  // the colour pass clears the target to the background
        case CompositeMode::tiled:
        case CompositeMode::draw:
            break;
    }
    memory_barrier(*ref.fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   kShaderStages | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   kShaderAccess | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    return buffer_bytes;
}

// The quads through a render pass: with the target as colour attachment (unsorted), or none.
void ReferenceCompositor::record_draw(VkCommandBuffer command_buffer, const FrameSlot& slot, VkPipeline pipeline,
                                      bool color, const gpu::CompositePushConstants& push) {
    VkRenderPassBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    begin.renderPass = color ? color_pass : empty_pass;
    begin.framebuffer = color ? color_framebuffer : empty_framebuffer;
    begin.renderArea = {{0, 0}, {width, height}};
    const VkClearValue clear{{{push.background.x, push.background.y, push.background.z, push.background.w}}};
    begin.clearValueCount = color ? 1 : 0;
    begin.pClearValues = &clear;
    ref.fn->vkCmdBeginRenderPass(command_buffer, &begin, VK_SUBPASS_CONTENTS_INLINE);
    if (push.quad_count > 0) {
        ref.fn->vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        set_viewport(*ref.fn, command_buffer, begin.renderArea);
        ref.fn->vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, descriptors.pipeline_layout, 0,
                                        1, &slot.set, 0, nullptr);
        ref.fn->vkCmdPushConstants(command_buffer, descriptors.pipeline_layout, kPushStages, 0, sizeof(push), &push);
        ref.fn->vkCmdDraw(command_buffer, 4, push.quad_count, 0, 0);
    }
    ref.fn->vkCmdEndRenderPass(command_buffer);
}

void ReferenceCompositor::record_dispatch(VkCommandBuffer command_buffer, const FrameSlot& slot, VkPipeline pipeline,
                                          uint32_t x, uint32_t y, const gpu::CompositePushConstants& push) {
    if (x == 0 || y == 0) return;
    ref.fn->vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    ref.fn->vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, descriptors.pipeline_layout, 0, 1,
                                    &slot.set, 0, nullptr);
    ref.fn->vkCmdPushConstants(command_buffer, descriptors.pipeline_layout, kPushStages, 0, sizeof(push), &push);
    ref.fn->vkCmdDispatch(command_buffer, x, y, 1);
}

// The mode's quad passes (rasterized, or compute over the frame's 8 x 8 tiles, one workgroup
// each in rows of kRasterDispatchWidth) and its per-pixel resolve; then the stats for the host.
void ReferenceCompositor::record_passes(VkCommandBuffer command_buffer, const FrameSlot& slot, CompositeMode mode,
                                        bool compute, const gpu::CompositePushConstants& push) {
    const uint32_t rows = std::min(push.tile_count, gpu::kRasterDispatchWidth);
    auto quads = [&](VkPipeline raster, VkPipeline computed) {
        if (compute) {
            record_dispatch(command_buffer, slot, computed, rows, rows == 0 ? 0 : (push.tile_count + rows - 1) / rows,
                            push);
        } else {
            record_draw(command_buffer, slot, raster, false, push);
        }
    };
    const VkPipelineStageFlags quad_stage =
        compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    auto quads_to = [&](VkPipelineStageFlags stage) {
        memory_barrier(*ref.fn, command_buffer, quad_stage, VK_ACCESS_SHADER_WRITE_BIT, stage, kShaderAccess);
    };
    auto resolve = [&](VkPipeline pipeline) {
        quads_to(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
        record_dispatch(command_buffer, slot, pipeline, (width + gpu::kCompositeTile - 1) / gpu::kCompositeTile,
                        (height + gpu::kCompositeTile - 1) / gpu::kCompositeTile, push);
    };
    VkPipelineStageFlags last_stage = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    VkAccessFlags last_access = VK_ACCESS_SHADER_WRITE_BIT;
    switch (mode) {
        case CompositeMode::wboit:
            quads(wboit, wboit_compute);
            resolve(wboit_resolve);
            break;
        case CompositeMode::exact:
            quads(exact, exact_compute);
            resolve(exact_resolve);
            break;
        case CompositeMode::unsorted:
            record_draw(command_buffer, slot, unsorted, true, push);
            last_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
            last_access = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
            break;
        case CompositeMode::tiled:
        case CompositeMode::draw:
            break;  // refused by check()
    }
    // The target for the caller; the stats words for the host.
    memory_barrier(*ref.fn, command_buffer, last_stage, last_access, kShaderStages | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy copy{0, 0, gpu::kStatWords * kWord};
    ref.fn->vkCmdCopyBuffer(command_buffer, stats_words.buffer, slot.stats.buffer, 1, &copy);
    memory_barrier(*ref.fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

Status ReferenceCompositor::record(VkCommandBuffer command_buffer, const DrawnFrame& drawn, const PaintInputs& paints,
                                   const CompositeParams& params, CompositorStats& stats) {
    if (Status s = check(params); !s) return s;
    FrameSlot& slot = slots[frame % frames_in_flight];
    read_back_stats(slot, stats);
    Result<bool> compute = compute_pass_for(params);
    if (!compute) return compute.error();

    rank_quads(drawn.glyphs, drawn.paints.size(), quad_data);
    if (*compute) {
        build_tiles();
    } else {
        tile_data.clear();
    }
    const uint32_t tile_count = static_cast<uint32_t>(tile_data.size() / 2);
    if (Status s = upload(slot.quads, slot.quad_capacity, quad_data.data(), static_cast<uint32_t>(quad_data.size()),
                          sizeof(gpu::CompositeQuad));
        !s) {
        return s;
    }
    if (Status s = upload(slot.tiles, slot.tile_capacity, tile_data.data(), tile_count, 2 * sizeof(uint32_t)); !s) {
        return s;
    }
    write_descriptors(slot, drawn.atlas, paints);

    const gpu::CompositePushConstants push = push_constants(params);
    target_was_initialized = target_initialized;
    recorded = true;
    record_target_init(command_buffer);
    const uint64_t buffer_bytes = record_clears(command_buffer, params.mode);
    record_passes(command_buffer, slot, params.mode, *compute, push);

    ++frame;
    slot.pending = true;
    slot.frame = frame;
    slot.mode = params.mode;
    stats.mode = params.mode;
    stats.path = *compute ? QuadPath::compute : QuadPath::raster;
    stats.tiles = tile_count;
    stats.quads = push.quad_count;
    stats.buffer_bytes = buffer_bytes;
    return {};
}

void ReferenceCompositor::record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const {
    // To the layout copies are fast in and back to GENERAL, where the compositor keeps the target.
    constexpr VkPipelineStageFlags kUsers = kShaderStages | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    image_barrier(*ref.fn, command_buffer, target_.image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  kUsers, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    ref.fn->vkCmdCopyImageToBuffer(command_buffer, target_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1,
                                   &region);
    // The copy only read: nothing to make available, only the layout back.
    image_barrier(*ref.fn, command_buffer, target_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, 0, kUsers, kShaderAccess | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    memory_barrier(*ref.fn, command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

}  // namespace crisp::composite
