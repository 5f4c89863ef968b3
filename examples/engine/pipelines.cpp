#include "pipelines.hpp"

#include <cstddef>
#include <cstdint>
#include <span>

// SPIR-V compiled at build time from shaders/ (CMakeLists.txt: glslangValidator --vn).
#include "panel_frag.h"
#include "panel_vert.h"
#include "scene_frag.h"
#include "scene_vert.h"

namespace engine {
namespace {

struct PipelineDescription {
    std::span<const uint32_t> vertex_code;
    std::span<const uint32_t> fragment_code;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkFormat color_format = VK_FORMAT_UNDEFINED;
    VkFormat depth_format = VK_FORMAT_UNDEFINED;
    bool lit_shapes = false;  // vertex input, triangle list, depth test and write; else a blended strip
};

crisp::Result<OwnedShaderModule> create_module(VkDevice device, std::span<const uint32_t> code) {
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = code.size_bytes();
    info.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreateShaderModule", vkCreateShaderModule(device, &info, nullptr, &module)); !s) {
        return s.error();
    }
    return OwnedShaderModule(device, module);
}

crisp::Result<OwnedPipelineLayout> create_layout(VkDevice device, uint32_t push_bytes) {
    VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, push_bytes};
    VkPipelineLayoutCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    info.pushConstantRangeCount = 1;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreatePipelineLayout", vkCreatePipelineLayout(device, &info, nullptr, &layout));
        !s) {
        return s.error();
    }
    return OwnedPipelineLayout(device, layout);
}

VkPipelineColorBlendAttachmentState blend_state(bool blend) {
    VkPipelineColorBlendAttachmentState state{};
    state.colorWriteMask =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    if (!blend) return state;
    state.blendEnable = VK_TRUE;  // straight alpha "over"
    state.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    state.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    state.colorBlendOp = VK_BLEND_OP_ADD;
    state.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    state.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    state.alphaBlendOp = VK_BLEND_OP_ADD;
    return state;
}

crisp::Result<OwnedPipeline> create_pipeline(VkDevice device, const PipelineDescription& d) {
    crisp::Result<OwnedShaderModule> vertex = create_module(device, d.vertex_code);
    if (!vertex) return vertex.error();
    crisp::Result<OwnedShaderModule> fragment = create_module(device, d.fragment_code);
    if (!fragment) return fragment.error();
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vertex->get();
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fragment->get();
    stages[1].pName = "main";

    const VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
    const VkVertexInputAttributeDescription attributes[] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
        {2, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color)},
    };
    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    if (d.lit_shapes) {
        vertex_input.vertexBindingDescriptionCount = 1;
        vertex_input.pVertexBindingDescriptions = &binding;
        vertex_input.vertexAttributeDescriptionCount = 3;
        vertex_input.pVertexAttributeDescriptions = attributes;
    }
    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = d.lit_shapes ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
    VkPipelineViewportStateCreateInfo viewport{};
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = d.lit_shapes ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = d.lit_shapes ? VK_TRUE : VK_FALSE;
    depth.depthWriteEnable = d.lit_shapes ? VK_TRUE : VK_FALSE;
    depth.depthCompareOp = VK_COMPARE_OP_LESS;
    const VkPipelineColorBlendAttachmentState attachment = blend_state(!d.lit_shapes);
    VkPipelineColorBlendStateCreateInfo blend{};
    blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blend.attachmentCount = 1;
    blend.pAttachments = &attachment;
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{};
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamic_states;
    VkPipelineRenderingCreateInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachmentFormats = &d.color_format;
    rendering.depthAttachmentFormat = d.depth_format;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = d.layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (crisp::Status s = check("vkCreateGraphicsPipelines",
                                vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
        !s) {
        return s.error();
    }
    return OwnedPipeline(device, pipeline);
}

}  // namespace

crisp::Result<Pipelines> create_pipelines(VkDevice device, VkFormat color_format, VkFormat depth_format) {
    Pipelines out;
    crisp::Result<OwnedPipelineLayout> scene_layout = create_layout(device, sizeof(ScenePush));
    if (!scene_layout) return scene_layout.error();
    out.scene_layout = std::move(*scene_layout);
    crisp::Result<OwnedPipelineLayout> panel_layout = create_layout(device, sizeof(PanelPush));
    if (!panel_layout) return panel_layout.error();
    out.panel_layout = std::move(*panel_layout);

    PipelineDescription scene{kSceneVert, kSceneFrag, out.scene_layout.get(), color_format, depth_format, true};
    crisp::Result<OwnedPipeline> scene_pipeline = create_pipeline(device, scene);
    if (!scene_pipeline) return scene_pipeline.error();
    out.scene = std::move(*scene_pipeline);
    PipelineDescription panel{kPanelVert, kPanelFrag, out.panel_layout.get(), color_format, depth_format, false};
    crisp::Result<OwnedPipeline> panel_pipeline = create_pipeline(device, panel);
    if (!panel_pipeline) return panel_pipeline.error();
    out.panel = std::move(*panel_pipeline);
    return out;
}

}  // namespace engine
