// Private: the graphics pipeline every rasterized glyph-quad pass uses (quad_pipeline.vert and a
// fragment shader), for a render pass or for dynamic rendering; viewport and scissor are dynamic.
#pragma once

#include "vk/resources.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

namespace crisp::composite {

struct QuadPipeline {
    VkShaderModule vertex = VK_NULL_HANDLE;
    VkShaderModule fragment = VK_NULL_HANDLE;
    const VkSpecializationInfo* specialization = nullptr;  // the fragment stage's
    VkPipelineLayout layout = VK_NULL_HANDLE;
    // Dual-source "over" into the one colour attachment, per channel: dst = L + T * dst, and
    // dst.a = o + (1 - o) * dst.a; without it the pass has no colour attachment.
    bool blend_over = false;
    VkRenderPass render_pass = VK_NULL_HANDLE;    // or, when null, dynamic rendering into:
    VkFormat color_format = VK_FORMAT_UNDEFINED;  // (with blend_over)
    // Dynamic rendering only: the pass's depth attachment, which quads are tested against at
    // their depth (LESS_OR_EQUAL, never written); VK_FORMAT_UNDEFINED: none.
    VkFormat depth_format = VK_FORMAT_UNDEFINED;
    const char* what = "";  // for the error message
};

Result<VkPipeline> create_quad_pipeline(const vk::DeviceRef& device, const QuadPipeline& desc);

// True for depth formats with a stencil aspect (a pass with one has a stencil attachment too).
bool has_stencil(VkFormat format);

// Sets the dynamic viewport and scissor to `rect`.
void set_viewport(const vk::Functions& fn, VkCommandBuffer command_buffer, const VkRect2D& rect);

}  // namespace crisp::composite
