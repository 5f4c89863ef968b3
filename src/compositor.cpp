// The GPU compositor: glyph quads over the atlas, composited by one of four modes
// (docs/compositing.md). Every pass reads or writes per-pixel storage buffers; only the unsorted
// mode blends into the target as a colour attachment, the others write it from a compute pass.
#include "shared.h"
#include "vk_resources.hpp"

#include <crisp/compositor.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace crisp {

namespace {

constexpr VkFormat kTargetFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr uint32_t kMaxTargetSide = 16384;
constexpr uint32_t kMaxNodesPerPixel = 64;
constexpr VkDeviceSize kWord = 4;
static_assert(kMaxCompositeLayers == gpu::kCompositeMaxLayers);
static_assert(kMaxExactFragmentsPerPixel == gpu::kCompositeExactMaxPerPixel);

// Bindings of the one descriptor set layout every pipeline shares.
enum Binding : uint32_t {
    kBindAtlas = 0,
    kBindQuads = 1,
    kBindLayers = 2,  // kCompositeMaxLayerBuffers descriptors
    kBindAccumulators = 3,
    kBindNodes = 4,
    kBindStats = 5,
    kBindTarget = 6,
    kBindTiles = 7,
};
constexpr uint32_t kBindingCount = 8;

float clamp01(float value) {
    return value >= 0.0f ? std::min(value, 1.0f) : 0.0f;  // NaN -> 0
}

// The key's depth bits, as oit::pack_layer_key: floor(d * 2^bits), saturated below the largest
// value so that no key equals the empty slot.
uint32_t depth_bits(float depth, int bits) {
    const float full = std::ldexp(1.0f, bits);
    const float scaled = clamp01(depth) * full;
    const float saturate = full - 2.0f;
    return scaled >= saturate ? static_cast<uint32_t>(saturate) : static_cast<uint32_t>(scaled);
}

struct FrameSlot {
    vk::DeviceBuffer quads;  // host-visible CompositeQuad[]
    uint32_t quad_capacity = 0;
    vk::DeviceBuffer tiles;  // host-visible uvec2[]: the compute path's tiles
    uint32_t tile_capacity = 0;
    vk::DeviceBuffer stats;  // host-visible copy of the stats words
    VkDescriptorSet set = VK_NULL_HANDLE;
    bool pending = false;  // recorded, its stats not read yet
    uint64_t frame = 0;
    CompositeMode mode = CompositeMode::layered;
};

struct LayeredPipelines {
    VkPipeline build = VK_NULL_HANDLE;
    VkPipeline composite = VK_NULL_HANDLE;
    VkPipeline resolve = VK_NULL_HANDLE;
    VkPipeline build_compute = VK_NULL_HANDLE;  // the quad passes as compute dispatches
    VkPipeline composite_compute = VK_NULL_HANDLE;
};

}  // namespace

const char* composite_mode_name(CompositeMode mode) {
    switch (mode) {
        case CompositeMode::layered:
            return "layered";
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
    for (CompositeMode mode :
         {CompositeMode::layered, CompositeMode::unsorted, CompositeMode::wboit, CompositeMode::exact}) {
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

struct Compositor::State {
    vk::DeviceRef ref;
    uint32_t width = 0, height = 0, pixels = 0;
    uint32_t frames_in_flight = 2;
    uint32_t max_layers = kMaxCompositeLayers;
    bool mono = false;
    uint32_t layers_per_buffer = 1;
    uint32_t node_capacity = 0;

    vk::DeviceImage target;
    bool target_initialized = false;

    std::vector<vk::DeviceBuffer> layer_buffers;
    vk::DeviceBuffer accumulators;  // kLayeredWords (the most any mode uses) words per pixel
    vk::DeviceBuffer nodes;         // exact mode's pool; a stand-in of 16 bytes when there is none
    vk::DeviceBuffer stats_words;   // device-local kStatWords

    std::map<std::string, VkShaderModule> modules;
    vk::DescriptorSets descriptors;            // one set per frame in flight
    VkRenderPass empty_pass = VK_NULL_HANDLE;  // no attachments: the storage-only passes
    VkRenderPass color_pass = VK_NULL_HANDLE;  // the target as colour attachment: unsorted
    VkFramebuffer empty_framebuffer = VK_NULL_HANDLE;
    VkFramebuffer color_framebuffer = VK_NULL_HANDLE;
    VkPipeline unsorted = VK_NULL_HANDLE, wboit = VK_NULL_HANDLE, exact = VK_NULL_HANDLE;
    VkPipeline wboit_resolve = VK_NULL_HANDLE, exact_resolve = VK_NULL_HANDLE;
    VkPipeline wboit_compute = VK_NULL_HANDLE, exact_compute = VK_NULL_HANDLE;  // made on first use
    std::array<LayeredPipelines, kMaxCompositeLayers + 1> layered{};            // by K, made on first use

    std::vector<FrameSlot> slots;
    uint64_t frame = 0;
    bool have_overlap = false;
    uint32_t last_overlap = 0;
    CompositorStats stats;
    std::vector<std::string> warnings;
    std::vector<gpu::CompositeQuad> quad_data;
    std::vector<uint32_t> tile_data;  // pairs: quad index, tile origin in its rect (x | y << 16)

    ~State();
    Status create(const CompositorCreateInfo& info);
    Result<VkShaderModule> module(const char* name);
    Result<VkPipeline> graphics_pipeline(const char* fragment, const VkSpecializationInfo* specialization, bool blend);
    Result<VkPipeline> compute_pipeline(const char* shader, const VkSpecializationInfo* specialization);
    Result<LayeredPipelines*> layered_pipelines(uint32_t layers, bool compute);
    void read_back_stats(FrameSlot& slot);
    void build_quads(std::span<const DrawnGlyph> glyphs);
    void build_tiles();
    Status upload(vk::DeviceBuffer& buffer, uint32_t& capacity, const void* data, uint32_t count, size_t size);
    void write_descriptors(const FrameSlot& slot, VkImageView atlas_view);
};

Compositor::State::~State() {
    if (!ref.device) return;
    VkDevice device = ref.device;
    const VkAllocationCallbacks* allocator = ref.allocator;
    for (LayeredPipelines& p : layered) {
        for (VkPipeline pipeline : {p.build, p.composite, p.resolve, p.build_compute, p.composite_compute}) {
            if (pipeline) vkDestroyPipeline(device, pipeline, allocator);
        }
    }
    for (VkPipeline pipeline : {unsorted, wboit, exact, wboit_resolve, exact_resolve, wboit_compute, exact_compute}) {
        if (pipeline) vkDestroyPipeline(device, pipeline, allocator);
    }
    for (auto& [name, shader] : modules) vkDestroyShaderModule(device, shader, allocator);
    if (empty_framebuffer) vkDestroyFramebuffer(device, empty_framebuffer, allocator);
    if (color_framebuffer) vkDestroyFramebuffer(device, color_framebuffer, allocator);
    if (empty_pass) vkDestroyRenderPass(device, empty_pass, allocator);
    if (color_pass) vkDestroyRenderPass(device, color_pass, allocator);
    vk::destroy_descriptor_sets(ref, descriptors);
    for (FrameSlot& slot : slots) {
        vk::destroy_buffer(ref, slot.quads);
        vk::destroy_buffer(ref, slot.tiles);
        vk::destroy_buffer(ref, slot.stats);
    }
    for (vk::DeviceBuffer& buffer : layer_buffers) vk::destroy_buffer(ref, buffer);
    vk::destroy_buffer(ref, accumulators);
    vk::destroy_buffer(ref, nodes);
    vk::destroy_buffer(ref, stats_words);
    vk::destroy_image(ref, target);
}

Result<VkShaderModule> Compositor::State::module(const char* name) {
    if (auto it = modules.find(name); it != modules.end()) return it->second;
    Result<VkShaderModule> made = vk::create_embedded_shader(ref, name);
    if (made) modules.emplace(name, *made);
    return made;
}

Result<VkPipeline> Compositor::State::graphics_pipeline(const char* fragment,
                                                        const VkSpecializationInfo* specialization, bool blend) {
    Result<VkShaderModule> vertex_module = module("composite.vert");
    if (!vertex_module) return vertex_module.error();
    Result<VkShaderModule> fragment_module = module(fragment);
    if (!fragment_module) return fragment_module.error();
    VkPipelineShaderStageCreateInfo stages[2]{};
    for (VkPipelineShaderStageCreateInfo& stage : stages) {
        stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stage.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = *vertex_module;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = *fragment_module;
    stages[1].pSpecializationInfo = specialization;

    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
    const VkViewport viewport{0.0f, 0.0f, static_cast<float>(width), static_cast<float>(height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, {width, height}};
    VkPipelineViewportStateCreateInfo viewport_state{};
    viewport_state.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport_state.viewportCount = 1;
    viewport_state.pViewports = &viewport;
    viewport_state.scissorCount = 1;
    viewport_state.pScissors = &scissor;
    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    // Unsorted: dst = L + T * dst per channel (dual-source: the second output is T), and
    // dst.a = o + (1 - o) * dst.a.
    VkPipelineColorBlendAttachmentState attachment{};
    attachment.blendEnable = VK_TRUE;
    attachment.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    attachment.dstColorBlendFactor = VK_BLEND_FACTOR_SRC1_COLOR;
    attachment.colorBlendOp = VK_BLEND_OP_ADD;
    attachment.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    attachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_SRC1_ALPHA;
    attachment.alphaBlendOp = VK_BLEND_OP_ADD;
    attachment.colorWriteMask =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo color_blend{};
    color_blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    color_blend.attachmentCount = blend ? 1 : 0;
    color_blend.pAttachments = blend ? &attachment : nullptr;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport_state;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pColorBlendState = &color_blend;
    info.layout = descriptors.pipeline_layout;
    info.renderPass = blend ? color_pass : empty_pass;
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (VkResult r = vkCreateGraphicsPipelines(ref.device, VK_NULL_HANDLE, 1, &info, ref.allocator, &pipeline);
        r != VK_SUCCESS) {
        return vk::vulkan_error(std::string("vkCreateGraphicsPipelines (") + fragment + ")", r);
    }
    return pipeline;
}

Result<VkPipeline> Compositor::State::compute_pipeline(const char* shader, const VkSpecializationInfo* specialization) {
    Result<VkShaderModule> compute_module = module(shader);
    if (!compute_module) return compute_module.error();
    return vk::create_compute_pipeline(ref, *compute_module, descriptors.pipeline_layout, specialization, shader);
}

Result<LayeredPipelines*> Compositor::State::layered_pipelines(uint32_t layers, bool compute) {
    LayeredPipelines& p = layered[layers];
    // constant_id 0: K; 1: the pass (build, composite); 2: 64-bit keys (resolve).
    struct Constants {
        uint32_t layers, pass, key64;
    };
    const VkSpecializationMapEntry entries[3] = {
        {0, offsetof(Constants, layers), 4}, {1, offsetof(Constants, pass), 4}, {2, offsetof(Constants, key64), 4}};
    auto make = [&](VkPipeline& pipeline, uint32_t pass, const char* shader, bool graphics) -> Status {
        if (pipeline) return {};
        const Constants constants{layers, pass, mono ? 0u : 1u};
        VkSpecializationInfo specialization{};
        specialization.mapEntryCount = 3;
        specialization.pMapEntries = entries;
        specialization.dataSize = sizeof(constants);
        specialization.pData = &constants;
        Result<VkPipeline> made =
            graphics ? graphics_pipeline(shader, &specialization, false) : compute_pipeline(shader, &specialization);
        if (!made) return made.error();
        pipeline = *made;
        return {};
    };
    if (Status s = make(p.resolve, 2, "layered_resolve.comp", false); !s) return s.error();
    if (compute) {
        const char* shader = mono ? "layered32_quads.comp" : "layered64_quads.comp";
        if (Status s = make(p.build_compute, 0, shader, false); !s) return s.error();
        if (Status s = make(p.composite_compute, 1, shader, false); !s) return s.error();
    } else {
        const char* shader = mono ? "layered32.frag" : "layered64.frag";
        if (Status s = make(p.build, 0, shader, true); !s) return s.error();
        if (Status s = make(p.composite, 1, shader, true); !s) return s.error();
    }
    return &p;
}

Status Compositor::State::create(const CompositorCreateInfo& info) {
    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(info.physical_device, &properties);
    VkPhysicalDeviceFeatures features{};
    vkGetPhysicalDeviceFeatures(info.physical_device, &features);
    if (!features.fragmentStoresAndAtomics || !features.dualSrcBlend) {
        return Error{ErrorCode::vulkan,
                     std::string("compositor: ") + properties.deviceName + " lacks " +
                         (!features.fragmentStoresAndAtomics ? "fragmentStoresAndAtomics" : "dualSrcBlend")};
    }
    VkFormatProperties format{};
    vkGetPhysicalDeviceFormatProperties(info.physical_device, kTargetFormat, &format);
    const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                        VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT |
                                        VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    if ((format.optimalTilingFeatures & needed) != needed) {
        return Error{ErrorCode::vulkan, std::string("compositor: ") + properties.deviceName +
                                            " cannot blend, store to and copy R32G32B32A32_SFLOAT images"};
    }
    vkGetPhysicalDeviceMemoryProperties(info.physical_device, &ref.memory_properties);
    const VkDeviceSize range = properties.limits.maxStorageBufferRange;
    const VkDeviceSize layer_range =
        info.max_layer_buffer_bytes != 0 ? std::min<VkDeviceSize>(range, info.max_layer_buffer_bytes) : range;
    const VkDevice device = ref.device;
    const VkAllocationCallbacks* allocator = ref.allocator;

    // The target image.
    if (Status s = vk::create_image(ref, kTargetFormat, width, height,
                                    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                        VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                    "compositor target", target);
        !s) {
        return s;
    }

    // Per-pixel buffers. A layer lies whole in one buffer, layer-major (layer i of pixel p at
    // i * pixels + p), and layers are split across buffers where one would pass the range.
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    const VkDeviceSize key_bytes = mono ? 4 : 8;
    const VkDeviceSize layer_bytes = VkDeviceSize{pixels} * key_bytes;
    if (layer_bytes > layer_range) {
        return Error{ErrorCode::vulkan, "compositor: one layer of " + std::to_string(width) + "x" +
                                            std::to_string(height) + " keys is " + std::to_string(layer_bytes) +
                                            " bytes, above maxStorageBufferRange (" + std::to_string(layer_range) +
                                            ")"};
    }
    layers_per_buffer = static_cast<uint32_t>(std::min<VkDeviceSize>(max_layers, layer_range / layer_bytes));
    for (uint32_t first = 0; first < max_layers; first += layers_per_buffer) {
        const uint32_t count = std::min(layers_per_buffer, max_layers - first);
        vk::DeviceBuffer buffer;
        if (Status s = vk::create_buffer(ref, layer_bytes * count, storage, false, buffer); !s) return s;
        layer_buffers.push_back(buffer);
    }
    static_assert(gpu::kLayeredWords >= gpu::kWboitWords && gpu::kLayeredWords >= gpu::kExactWords);
    const VkDeviceSize accumulator_bytes = VkDeviceSize{pixels} * gpu::kLayeredWords * kWord;
    if (accumulator_bytes > range) {
        return Error{ErrorCode::vulkan, "compositor: the per-pixel accumulators of a " + std::to_string(width) + "x" +
                                            std::to_string(height) + " target need " +
                                            std::to_string(accumulator_bytes) +
                                            " bytes, above maxStorageBufferRange (" + std::to_string(range) + ")"};
    }
    if (Status s = vk::create_buffer(ref, accumulator_bytes, storage, false, accumulators); !s) return s;
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
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, nodes);
        !s) {
        return s;
    }
    if (Status s = vk::create_buffer(ref, gpu::kStatWords * kWord, storage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false,
                                     stats_words);
        !s) {
        return s;
    }

    // Descriptors and the pipeline layout.
    const VkShaderStageFlags stages =
        VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT | VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorSetLayoutBinding bindings[] = {
        {kBindAtlas, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, stages, nullptr},
        {kBindQuads, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {kBindLayers, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, gpu::kCompositeMaxLayerBuffers, stages, nullptr},
        {kBindAccumulators, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {kBindNodes, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {kBindStats, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {kBindTarget, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, stages, nullptr},
        {kBindTiles, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
    };
    static_assert(std::size(bindings) == kBindingCount);
    if (Status s = vk::create_descriptor_sets(ref, bindings, stages, sizeof(gpu::CompositePushConstants),
                                              frames_in_flight, "compositor", descriptors);
        !s) {
        return s;
    }
    slots.resize(frames_in_flight);
    for (uint32_t i = 0; i < frames_in_flight; ++i) {
        FrameSlot& slot = slots[i];
        slot.set = descriptors.sets[i];
        if (Status s =
                vk::create_buffer(ref, gpu::kStatWords * kWord, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, slot.stats);
            !s) {
            return s;
        }
    }

    // Render passes: none of crisp's passes needs a barrier inside one; the pipeline barriers
    // around them order every access.
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VkRenderPassCreateInfo pass_info{};
    pass_info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    pass_info.subpassCount = 1;
    pass_info.pSubpasses = &subpass;
    if (VkResult r = vkCreateRenderPass(device, &pass_info, allocator, &empty_pass); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateRenderPass (compositor)", r);
    }
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
    if (VkResult r = vkCreateRenderPass(device, &pass_info, allocator, &color_pass); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateRenderPass (compositor)", r);
    }
    VkFramebufferCreateInfo framebuffer{};
    framebuffer.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    framebuffer.renderPass = empty_pass;
    framebuffer.width = width;
    framebuffer.height = height;
    framebuffer.layers = 1;
    if (VkResult r = vkCreateFramebuffer(device, &framebuffer, allocator, &empty_framebuffer); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFramebuffer (compositor)", r);
    }
    framebuffer.renderPass = color_pass;
    framebuffer.attachmentCount = 1;
    framebuffer.pAttachments = &target.view;
    if (VkResult r = vkCreateFramebuffer(device, &framebuffer, allocator, &color_framebuffer); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFramebuffer (compositor)", r);
    }

    // The fixed pipelines; layered ones are made per K on first use.
    struct Made {
        VkPipeline* pipeline;
        Result<VkPipeline> result;
    };
    Made made[] = {
        {&unsorted, graphics_pipeline("unsorted.frag", nullptr, true)},
        {&wboit, graphics_pipeline("wboit.frag", nullptr, false)},
        {&exact, graphics_pipeline("exact.frag", nullptr, false)},
        {&wboit_resolve, compute_pipeline("wboit_resolve.comp", nullptr)},
        {&exact_resolve, compute_pipeline("exact_resolve.comp", nullptr)},
    };
    for (Made& m : made) {
        if (m.result) *m.pipeline = *m.result;
    }
    for (Made& m : made) {
        if (!m.result) return m.result.error();
    }
    return {};
}

void Compositor::State::read_back_stats(FrameSlot& slot) {
    if (!slot.pending) return;
    slot.pending = false;
    uint32_t words[gpu::kStatWords];
    std::memcpy(words, slot.stats.mapped, sizeof(words));
    stats.measured = true;
    stats.measured_frame = slot.frame;
    stats.max_overlap = words[gpu::kStatMaxOverlap];
    stats.tail_pixels = words[gpu::kStatTailPixels];
    stats.exact_lost_nodes = slot.mode == CompositeMode::exact && words[gpu::kStatNodesUsed] > node_capacity
                                 ? words[gpu::kStatNodesUsed] - node_capacity
                                 : 0;
    stats.exact_dropped = words[gpu::kStatListOverflow];
    if (slot.mode == CompositeMode::layered || slot.mode == CompositeMode::exact) {
        have_overlap = true;
        last_overlap = stats.max_overlap;
    }
}

void Compositor::State::build_quads(std::span<const DrawnGlyph> glyphs) {
    quad_data.clear();
    struct Order {
        uint32_t depth;
        uint32_t paint_order;
        uint32_t quad;
    };
    std::vector<Order> orders;
    orders.reserve(glyphs.size());
    for (const DrawnGlyph& glyph : glyphs) {
        const GlyphInstance& instance = glyph.instance;
        if (instance.width == 0 || instance.height == 0) continue;
        gpu::CompositeQuad q{};
        q.x = instance.x;
        q.y = instance.y;
        q.width = instance.width;
        q.height = instance.height;
        q.atlas_x = glyph.atlas_x;
        q.atlas_y = glyph.atlas_y;
        q.depth = clamp01(instance.depth);
        q.color = {clamp01(instance.color[0]), clamp01(instance.color[1]), clamp01(instance.color[2]),
                   clamp01(instance.color[3])};
        orders.push_back(
            {depth_bits(instance.depth, 32), instance.paint_order, static_cast<uint32_t>(quad_data.size())});
        quad_data.push_back(q);
    }
    // Paint orders become dense ranks within each depth plane, so that the key's 8 bits of paint
    // order hold 256 distinct ones per plane; each further block of 256 is one depth step nearer.
    std::sort(orders.begin(), orders.end(), [](const Order& a, const Order& b) {
        return std::tie(a.depth, a.paint_order) < std::tie(b.depth, b.paint_order);
    });
    uint32_t rank = 0;
    uint32_t blocks = 0;
    for (size_t i = 0; i < orders.size(); ++i) {
        const Order& o = orders[i];
        if (i == 0 || o.depth != orders[i - 1].depth) {
            rank = 0;
        } else if (o.paint_order != orders[i - 1].paint_order) {
            ++rank;
        }
        gpu::CompositeQuad& q = quad_data[o.quad];
        const uint32_t block = rank >> 8;
        blocks = std::max(blocks, block + 1);
        q.rank = rank;
        q.key_order = 255u - (rank & 255u);
        q.key_depth = o.depth - std::min(o.depth, block);
        const uint32_t depth16 = depth_bits(q.depth, 16);
        q.key_depth16 = depth16 - std::min(depth16, block);
    }
    stats.paint_order_blocks = blocks;
}

void Compositor::State::build_tiles() {
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

Status Compositor::State::upload(vk::DeviceBuffer& buffer, uint32_t& capacity, const void* data, uint32_t count,
                                 size_t size) {
    if (count > capacity || !buffer.buffer) {
        // The slot's last use is done (the frames-in-flight contract), so its buffer can go.
        vk::destroy_buffer(ref, buffer);
        capacity = 0;
        const uint32_t grown = std::max<uint32_t>(64, std::bit_ceil(std::max(count, 1u)));
        if (Status s =
                vk::create_buffer(ref, VkDeviceSize{grown} * size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, buffer);
            !s) {
            return s;
        }
        capacity = grown;
    }
    if (count > 0) std::memcpy(buffer.mapped, data, count * size);
    return {};
}

void Compositor::State::write_descriptors(const FrameSlot& slot, VkImageView atlas_view) {
    const VkDescriptorImageInfo atlas_info{VK_NULL_HANDLE, atlas_view, VK_IMAGE_LAYOUT_GENERAL};
    const VkDescriptorImageInfo target_info{VK_NULL_HANDLE, target.view, VK_IMAGE_LAYOUT_GENERAL};
    const VkDescriptorBufferInfo quads_info{slot.quads.buffer, 0, VK_WHOLE_SIZE};
    std::array<VkDescriptorBufferInfo, gpu::kCompositeMaxLayerBuffers> layer_infos{};
    for (uint32_t i = 0; i < layer_infos.size(); ++i) {
        // Unused entries repeat the first buffer; the shaders never index them.
        layer_infos[i] = {layer_buffers[i < layer_buffers.size() ? i : 0].buffer, 0, VK_WHOLE_SIZE};
    }
    const VkDescriptorBufferInfo accumulator_info{accumulators.buffer, 0, VK_WHOLE_SIZE};
    const VkDescriptorBufferInfo node_info{nodes.buffer, 0, VK_WHOLE_SIZE};
    const VkDescriptorBufferInfo stats_info{stats_words.buffer, 0, VK_WHOLE_SIZE};
    const VkDescriptorBufferInfo tiles_info{slot.tiles.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet writes[kBindingCount]{};
    for (uint32_t i = 0; i < kBindingCount; ++i) {
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = slot.set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
    writes[kBindAtlas].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    writes[kBindAtlas].pImageInfo = &atlas_info;
    writes[kBindQuads].pBufferInfo = &quads_info;
    writes[kBindLayers].descriptorCount = gpu::kCompositeMaxLayerBuffers;
    writes[kBindLayers].pBufferInfo = layer_infos.data();
    writes[kBindAccumulators].pBufferInfo = &accumulator_info;
    writes[kBindNodes].pBufferInfo = &node_info;
    writes[kBindStats].pBufferInfo = &stats_info;
    writes[kBindTarget].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    writes[kBindTarget].pImageInfo = &target_info;
    writes[kBindTiles].pBufferInfo = &tiles_info;
    vkUpdateDescriptorSets(ref.device, kBindingCount, writes, 0, nullptr);
}

namespace {

void memory_barrier(VkCommandBuffer command_buffer, VkPipelineStageFlags source, VkAccessFlags source_access,
                    VkPipelineStageFlags destination, VkAccessFlags destination_access) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = source_access;
    barrier.dstAccessMask = destination_access;
    vkCmdPipelineBarrier(command_buffer, source, destination, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

constexpr VkPipelineStageFlags kShaderStages =
    VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags kShaderAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;

}  // namespace

Compositor::Compositor(std::unique_ptr<State> state) : state_(std::move(state)) {}
Compositor::Compositor(Compositor&&) noexcept = default;
Compositor& Compositor::operator=(Compositor&&) noexcept = default;
Compositor::~Compositor() = default;

Result<Compositor> Compositor::create(const CompositorCreateInfo& info) {
    if (!info.device || !info.physical_device) {
        return Error{ErrorCode::invalid_argument, "compositor: a physical device and a device are required"};
    }
    if (info.width < 1 || info.width > kMaxTargetSide || info.height < 1 || info.height > kMaxTargetSide) {
        return Error{ErrorCode::invalid_argument, "compositor: the target size " + std::to_string(info.width) + "x" +
                                                      std::to_string(info.height) + " is outside 1..16384 per side"};
    }
    if (info.frames_in_flight < 1 || info.frames_in_flight > 8) {
        return Error{ErrorCode::invalid_argument, "compositor: frames_in_flight must be 1 to 8"};
    }
    if (info.max_layers < 1 || info.max_layers > kMaxCompositeLayers) {
        return Error{ErrorCode::invalid_argument, "compositor: max_layers must be 1 to 8"};
    }
    if (info.exact_nodes_per_pixel > kMaxNodesPerPixel) {
        return Error{ErrorCode::invalid_argument, "compositor: exact_nodes_per_pixel must be at most 64"};
    }
    if (info.key_format == KeyFormat::rgb && !info.int64_atomics) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: rgb keys need shaderInt64 and shaderBufferInt64Atomics (int64_atomics)"};
    }
    auto state = std::make_unique<State>();
    state->ref.device = info.device;
    state->ref.allocator = info.allocator;
    state->width = info.width;
    state->height = info.height;
    state->pixels = info.width * info.height;
    state->frames_in_flight = info.frames_in_flight;
    state->max_layers = info.max_layers;
    switch (info.key_format) {
        case KeyFormat::rgb:
            state->mono = false;
            break;
        case KeyFormat::mono:
            state->mono = true;
            break;
        case KeyFormat::automatic:
            state->mono = info.gray_layout || !info.int64_atomics;
            if (!info.gray_layout && !info.int64_atomics) {
                state->warnings.push_back(
                    "no 64-bit buffer atomics (shaderInt64, shaderBufferInt64Atomics): layered compositing uses mono "
                    "keys, one transmittance for the three subpixel channels");
            }
            break;
    }
    if (Status s = state->create(info); !s) return s.error();
    return Compositor(std::move(state));
}

Status Compositor::record(VkCommandBuffer command_buffer, std::span<const DrawnGlyph> glyphs, VkImageView atlas_view,
                          const CompositeParams& params) {
    State& s = *state_;
    if (params.layers > s.max_layers) {
        return Error{ErrorCode::invalid_argument, "compositor: " + std::to_string(params.layers) +
                                                      " layers asked for, the buffers hold " +
                                                      std::to_string(s.max_layers)};
    }
    if (params.mode == CompositeMode::exact && s.node_capacity == 0) {
        return Error{ErrorCode::invalid_argument,
                     "compositor: the exact mode needs a node pool (exact_nodes_per_pixel)"};
    }
    FrameSlot& slot = s.slots[s.frame % s.frames_in_flight];
    s.read_back_stats(slot);

    const bool compute = params.path == QuadPath::compute && params.mode != CompositeMode::unsorted;
    uint32_t layers = 0;
    LayeredPipelines* layered = nullptr;
    if (params.mode == CompositeMode::layered) {
        layers = params.layers != kAutoLayers
                     ? params.layers
                     : (s.have_overlap ? std::clamp(s.last_overlap, 1u, s.max_layers) : s.max_layers);
        Result<LayeredPipelines*> made = s.layered_pipelines(layers, compute);
        if (!made) return made.error();
        layered = *made;
    } else if (compute) {
        const bool wboit = params.mode == CompositeMode::wboit;
        VkPipeline& pipeline = wboit ? s.wboit_compute : s.exact_compute;
        if (!pipeline) {
            Result<VkPipeline> made = s.compute_pipeline(wboit ? "wboit_quads.comp" : "exact_quads.comp", nullptr);
            if (!made) return made.error();
            pipeline = *made;
        }
    }
    s.build_quads(glyphs);
    if (compute) {
        s.build_tiles();
    } else {
        s.tile_data.clear();
    }
    const uint32_t tile_count = static_cast<uint32_t>(s.tile_data.size() / 2);
    if (Status status = s.upload(slot.quads, slot.quad_capacity, s.quad_data.data(),
                                 static_cast<uint32_t>(s.quad_data.size()), sizeof(gpu::CompositeQuad));
        !status) {
        return status;
    }
    if (Status status = s.upload(slot.tiles, slot.tile_capacity, s.tile_data.data(), tile_count, 2 * sizeof(uint32_t));
        !status) {
        return status;
    }
    s.write_descriptors(slot, atlas_view);

    gpu::CompositePushConstants push{};
    const float alpha = clamp01(params.background[3]);
    push.background = {clamp01(params.background[0]) * alpha, clamp01(params.background[1]) * alpha,
                       clamp01(params.background[2]) * alpha, alpha};
    push.width = s.width;
    push.height = s.height;
    push.pixels = s.pixels;
    push.layers_per_buffer = s.layers_per_buffer;
    push.node_capacity = s.node_capacity;
    push.tile_count = tile_count;

    // Every earlier use of the buffers and the target (this compositor's last frames, the
    // caller's reads of the target) before this frame's clears and writes.
    if (!s.target_initialized) {
        VkImageMemoryBarrier barrier{};
        barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
        barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
        barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.image = s.target.image;
        barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                                 VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                             0, 0, nullptr, 0, nullptr, 1, &barrier);
        s.target_initialized = true;
    }
    memory_barrier(command_buffer,
                   kShaderStages | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   kShaderAccess | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                   kShaderStages | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   kShaderAccess | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);

    // Clears.
    const VkDeviceSize pixel_words = VkDeviceSize{s.pixels} * kWord;
    vkCmdFillBuffer(command_buffer, s.stats_words.buffer, 0, VK_WHOLE_SIZE, 0);
    uint64_t buffer_bytes = 0;
    switch (params.mode) {
        case CompositeMode::layered: {
            const VkDeviceSize layer_bytes = pixel_words * (s.mono ? 1 : 2);
            for (uint32_t first = 0; first < layers; first += s.layers_per_buffer) {
                const uint32_t count = std::min(s.layers_per_buffer, layers - first);
                vkCmdFillBuffer(command_buffer, s.layer_buffers[first / s.layers_per_buffer].buffer, 0,
                                layer_bytes * count, 0xFFFFFFFFu);
            }
            vkCmdFillBuffer(command_buffer, s.accumulators.buffer, 0, pixel_words * gpu::kLayeredWords, 0);
            buffer_bytes = layer_bytes * layers + pixel_words * gpu::kLayeredWords;
            break;
        }
        case CompositeMode::wboit:
            vkCmdFillBuffer(command_buffer, s.accumulators.buffer, 0, pixel_words * gpu::kWboitWords, 0);
            buffer_bytes = pixel_words * gpu::kWboitWords;
            break;
        case CompositeMode::exact:
            vkCmdFillBuffer(command_buffer, s.accumulators.buffer, 0, pixel_words * gpu::kExactWords,
                            gpu::kCompositeNoNode);
            buffer_bytes =
                pixel_words * gpu::kExactWords + VkDeviceSize{s.node_capacity} * gpu::kCompositeNodeWords * kWord;
            break;
        case CompositeMode::unsorted:
            break;  // the colour pass clears the target to the background
    }
    memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   kShaderStages | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   kShaderAccess | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);

    const uint32_t quad_count = static_cast<uint32_t>(s.quad_data.size());
    const VkShaderStageFlags push_stages =
        VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT | VK_SHADER_STAGE_COMPUTE_BIT;
    auto draw_quads = [&](VkPipeline pipeline, bool color) {
        VkRenderPassBeginInfo begin{};
        begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
        begin.renderPass = color ? s.color_pass : s.empty_pass;
        begin.framebuffer = color ? s.color_framebuffer : s.empty_framebuffer;
        begin.renderArea = {{0, 0}, {s.width, s.height}};
        const VkClearValue clear{{{push.background.x, push.background.y, push.background.z, push.background.w}}};
        begin.clearValueCount = color ? 1 : 0;
        begin.pClearValues = &clear;
        vkCmdBeginRenderPass(command_buffer, &begin, VK_SUBPASS_CONTENTS_INLINE);
        if (quad_count > 0) {
            vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_GRAPHICS, s.descriptors.pipeline_layout, 0,
                                    1, &slot.set, 0, nullptr);
            vkCmdPushConstants(command_buffer, s.descriptors.pipeline_layout, push_stages, 0, sizeof(push), &push);
            vkCmdDraw(command_buffer, 4, quad_count, 0, 0);
        }
        vkCmdEndRenderPass(command_buffer);
    };
    // The compute path: one workgroup per tile, in rows of kRasterDispatchWidth workgroups.
    auto dispatch_tiles = [&](VkPipeline pipeline) {
        if (tile_count == 0) return;
        vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, s.descriptors.pipeline_layout, 0, 1,
                                &slot.set, 0, nullptr);
        vkCmdPushConstants(command_buffer, s.descriptors.pipeline_layout, push_stages, 0, sizeof(push), &push);
        const uint32_t width = std::min(tile_count, gpu::kRasterDispatchWidth);
        vkCmdDispatch(command_buffer, width, (tile_count + width - 1) / width, 1);
    };
    auto quads = [&](VkPipeline raster, VkPipeline computed) {
        if (compute) {
            dispatch_tiles(computed);
        } else {
            draw_quads(raster, false);
        }
    };
    const VkPipelineStageFlags quad_stage =
        compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    auto fragment_to = [&](VkPipelineStageFlags stage) {
        memory_barrier(command_buffer, quad_stage, VK_ACCESS_SHADER_WRITE_BIT, stage, kShaderAccess);
    };
    auto resolve = [&](VkPipeline pipeline) {
        vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, s.descriptors.pipeline_layout, 0, 1,
                                &slot.set, 0, nullptr);
        vkCmdPushConstants(command_buffer, s.descriptors.pipeline_layout, push_stages, 0, sizeof(push), &push);
        vkCmdDispatch(command_buffer, (s.width + gpu::kCompositeTile - 1) / gpu::kCompositeTile,
                      (s.height + gpu::kCompositeTile - 1) / gpu::kCompositeTile, 1);
    };
    VkPipelineStageFlags last_stage = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    VkAccessFlags last_access = VK_ACCESS_SHADER_WRITE_BIT;
    switch (params.mode) {
        case CompositeMode::layered:
            quads(layered->build, layered->build_compute);
            fragment_to(quad_stage);
            quads(layered->composite, layered->composite_compute);
            fragment_to(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
            resolve(layered->resolve);
            break;
        case CompositeMode::wboit:
            quads(s.wboit, s.wboit_compute);
            fragment_to(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
            resolve(s.wboit_resolve);
            break;
        case CompositeMode::exact:
            quads(s.exact, s.exact_compute);
            fragment_to(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
            resolve(s.exact_resolve);
            break;
        case CompositeMode::unsorted:
            draw_quads(s.unsorted, true);
            last_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
            last_access = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
            break;
    }
    // The target for the caller; the stats words for the host.
    memory_barrier(command_buffer, last_stage, last_access, kShaderStages | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy copy{0, 0, gpu::kStatWords * kWord};
    vkCmdCopyBuffer(command_buffer, s.stats_words.buffer, slot.stats.buffer, 1, &copy);
    memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);

    ++s.frame;
    slot.pending = true;
    slot.frame = s.frame;
    slot.mode = params.mode;
    s.stats.mode = params.mode;
    s.stats.path = compute ? QuadPath::compute : QuadPath::raster;
    s.stats.tiles = tile_count;
    s.stats.layers = layers;
    s.stats.mono_keys = params.mode == CompositeMode::layered && s.mono;
    s.stats.quads = quad_count;
    s.stats.buffer_bytes = buffer_bytes;
    return {};
}

Status Compositor::prepare_layered(QuadPath path) {
    for (uint32_t layers = 1; layers <= state_->max_layers; ++layers) {
        Result<LayeredPipelines*> made = state_->layered_pipelines(layers, path == QuadPath::compute);
        if (!made) return made.error();
    }
    return {};
}

void Compositor::record_target_readback(VkCommandBuffer command_buffer, VkBuffer buffer) const {
    const State& s = *state_;
    // To the layout copies are fast in and back to GENERAL, where the compositor keeps the target.
    VkImageMemoryBarrier barriers[2]{};
    for (VkImageMemoryBarrier& barrier : barriers) {
        barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.image = s.target.image;
        barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    }
    barriers[0].srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    barriers[0].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    barriers[0].oldLayout = VK_IMAGE_LAYOUT_GENERAL;
    barriers[0].newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    barriers[1].srcAccessMask = 0;  // the copy only read
    barriers[1].dstAccessMask = kShaderAccess | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    barriers[1].oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    barriers[1].newLayout = VK_IMAGE_LAYOUT_GENERAL;
    vkCmdPipelineBarrier(command_buffer, kShaderStages | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &barriers[0]);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {s.width, s.height, 1};
    vkCmdCopyImageToBuffer(command_buffer, s.target.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         kShaderStages | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barriers[1]);
    memory_barrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

VkImage Compositor::target_image() const {
    return state_->target.image;
}
VkImageView Compositor::target_view() const {
    return state_->target.view;
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
const std::vector<std::string>& Compositor::warnings() const {
    return state_->warnings;
}

}  // namespace crisp
