// The glyph-quad graphics pipeline shared by the draw path and the rasterized reference passes.
#include "composite/quad_pipeline.hpp"

#include <string>

namespace crisp::composite {

bool has_stencil(VkFormat format) {
    return format == VK_FORMAT_D16_UNORM_S8_UINT || format == VK_FORMAT_D24_UNORM_S8_UINT ||
           format == VK_FORMAT_D32_SFLOAT_S8_UINT || format == VK_FORMAT_S8_UINT;
}

// Longer than most functions here on purpose: one VkGraphicsPipelineCreateInfo and the state
// structures it points to, filled in the order Vulkan lists them; split up, the pieces would only
// be passed back and forth.
Result<VkPipeline> create_quad_pipeline(const vk::DeviceRef& device, const QuadPipeline& desc) {
    VkPipelineShaderStageCreateInfo stages[2]{};
    for (VkPipelineShaderStageCreateInfo& stage : stages) {
        stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stage.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = desc.vertex;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = desc.fragment;
    stages[1].pSpecializationInfo = desc.specialization;

    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
    VkPipelineViewportStateCreateInfo viewport{};
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineColorBlendAttachmentState attachment{};
    attachment.blendEnable = VK_TRUE;
    attachment.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    attachment.dstColorBlendFactor = VK_BLEND_FACTOR_SRC1_COLOR;  // the second output is T
    attachment.colorBlendOp = VK_BLEND_OP_ADD;
    attachment.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    attachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_SRC1_ALPHA;
    attachment.alphaBlendOp = VK_BLEND_OP_ADD;
    attachment.colorWriteMask =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blend{};
    blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blend.attachmentCount = desc.blend_over ? 1 : 0;
    blend.pAttachments = desc.blend_over ? &attachment : nullptr;
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{};
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamic_states;
    VkPipelineDepthStencilStateCreateInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = desc.depth_format != VK_FORMAT_UNDEFINED;
    depth.depthWriteEnable = VK_FALSE;  // text covers nothing: the scene's depth stays the scene's
    depth.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    VkPipelineRenderingCreateInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    rendering.colorAttachmentCount = desc.blend_over ? 1 : 0;
    rendering.pColorAttachmentFormats = &desc.color_format;
    rendering.depthAttachmentFormat = desc.depth_format;
    if (has_stencil(desc.depth_format)) rendering.stencilAttachmentFormat = desc.depth_format;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.pNext = desc.render_pass ? nullptr : &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pColorBlendState = &blend;
    info.pDepthStencilState = desc.depth_format != VK_FORMAT_UNDEFINED ? &depth : nullptr;
    info.pDynamicState = &dynamic;
    info.layout = desc.layout;
    info.renderPass = desc.render_pass;
    info.flags = vk::pipeline_create_flags(device);
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (VkResult r = device.fn->vkCreateGraphicsPipelines(device.device, device.pipeline_cache, 1, &info,
                                                          device.allocator, &pipeline);
        r != VK_SUCCESS) {
        return vk::vulkan_error(std::string("vkCreateGraphicsPipelines (") + desc.what + ")", r);
    }
    vk::name_object(device, VK_OBJECT_TYPE_PIPELINE, pipeline, desc.what);
    vk::collect_statistics(device, pipeline, desc.what);
    return pipeline;
}

void set_viewport(const vk::Functions& fn, VkCommandBuffer command_buffer, const VkRect2D& rect) {
    const VkViewport viewport{static_cast<float>(rect.offset.x),
                              static_cast<float>(rect.offset.y),
                              static_cast<float>(rect.extent.width),
                              static_cast<float>(rect.extent.height),
                              0.0f,
                              1.0f};
    fn.vkCmdSetViewport(command_buffer, 0, 1, &viewport);
    fn.vkCmdSetScissor(command_buffer, 0, 1, &rect);
}

}  // namespace crisp::composite
