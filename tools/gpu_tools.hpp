// Shared by crisp's GPU tools: the support harness's context (what the renderer and the compositor
// need, docs/vulkan.md), dynamic rendering over an image, and a GPU timer from timestamp queries.
#pragma once

#include "harness.hpp"
#include "headless_context.hpp"

#include <crisp/device_features.hpp>
#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace crisp::tools {

using harness::create_context;  // the context every GPU tool makes (support/harness.hpp)

// Begins dynamic rendering into one colour attachment, `view` in GENERAL layout, keeping what it
// holds (loadOp LOAD) and storing the result: where crisp's draw path composites, as an
// application's render pass would. End it with vkCmdEndRendering.
inline void begin_rendering_over(VkCommandBuffer command_buffer, VkImageView view, const VkRect2D& area) {
    VkRenderingAttachmentInfo attachment{};
    attachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    attachment.imageView = view;
    attachment.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
    attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    rendering.renderArea = area;
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &attachment;
    vkCmdBeginRendering(command_buffer, &rendering);
}

// Prints the driver's statistics of compiled shaders (Renderer::shader_statistics()) to `out` as a
// Markdown table: one row per shader and executable, one column per statistic; a line saying there
// are none where the device reports none.
inline void print_shader_statistics(std::FILE* out, const std::vector<ShaderStatistic>& statistics) {
    if (statistics.empty()) {
        std::fprintf(out,
                     "\nShader statistics: none (the device does not offer VK_KHR_pipeline_executable_properties).\n");
        return;
    }
    std::vector<std::string> names;
    for (const ShaderStatistic& s : statistics) {
        if (std::find(names.begin(), names.end(), s.name) == names.end()) names.push_back(s.name);
    }
    std::fprintf(out, "\nShader statistics (VK_KHR_pipeline_executable_properties):\n\n| shader | executable |");
    for (const std::string& name : names) std::fprintf(out, " %s |", name.c_str());
    std::fprintf(out, "\n|---|---|");
    for (size_t i = 0; i < names.size(); ++i) std::fprintf(out, "---:|");
    for (size_t i = 0; i < statistics.size();) {
        const ShaderStatistic& first = statistics[i];
        std::fprintf(out, "\n| %s | %s |", first.shader.c_str(), first.executable.c_str());
        size_t end = i;
        while (end < statistics.size() && statistics[end].shader == first.shader &&
               statistics[end].executable == first.executable) {
            ++end;
        }
        for (const std::string& name : names) {
            auto found = std::find_if(statistics.begin() + static_cast<std::ptrdiff_t>(i),
                                      statistics.begin() + static_cast<std::ptrdiff_t>(end),
                                      [&](const ShaderStatistic& s) { return s.name == name; });
            if (found == statistics.begin() + static_cast<std::ptrdiff_t>(end))
                std::fprintf(out, "  |");
            else
                std::fprintf(out, " %.6g |", found->value);
        }
        i = end;
    }
    std::fprintf(out, "\n");
}

// The GPU time between two points of a command buffer, from a pool of two timestamp queries.
// Move-only; destroy it before its context.
class GpuTimer {
public:
    static Result<GpuTimer> create(const HeadlessContext& context) {
        uint32_t family_count = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(context.physical_device(), &family_count, nullptr);
        std::vector<VkQueueFamilyProperties> families(family_count);
        vkGetPhysicalDeviceQueueFamilyProperties(context.physical_device(), &family_count, families.data());
        const uint32_t bits = families.at(context.queue_family()).timestampValidBits;
        if (bits == 0) return Error{ErrorCode::vulkan, "the queue has no timestamps"};
        GpuTimer timer;
        timer.device_ = context.device();
        timer.period_ns_ = static_cast<double>(context.properties().limits.timestampPeriod);
        timer.mask_ = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
        VkQueryPoolCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        info.queryCount = 2;
        if (VkResult r = vkCreateQueryPool(timer.device_, &info, nullptr, &timer.pool_); r != VK_SUCCESS) {
            return Error{ErrorCode::vulkan, "vkCreateQueryPool failed: " + vk_result_name(r), r};
        }
        return timer;
    }
    GpuTimer(GpuTimer&& other) noexcept { *this = std::move(other); }
    GpuTimer& operator=(GpuTimer&& other) noexcept {
        std::swap(device_, other.device_);
        std::swap(pool_, other.pool_);
        period_ns_ = other.period_ns_;
        mask_ = other.mask_;
        return *this;
    }
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;
    ~GpuTimer() {
        if (pool_) vkDestroyQueryPool(device_, pool_, nullptr);
    }

    // Around the work to time, in one command buffer.
    // `after_earlier_work`: the start is stamped once the commands before it have completed (they
    // are not counted), rather than when the GPU reaches this point (they may still be running).
    void begin(VkCommandBuffer command_buffer, bool after_earlier_work = false) const {
        vkCmdResetQueryPool(command_buffer, pool_, 0, 2);
        vkCmdWriteTimestamp(
            command_buffer,
            after_earlier_work ? VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT : VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, 0);
    }
    void end(VkCommandBuffer command_buffer) const {
        vkCmdWriteTimestamp(command_buffer, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 1);
    }
    // Once that command buffer has completed: the milliseconds between begin and end.
    Result<double> milliseconds() const {
        uint64_t stamps[2] = {};
        const VkResult r = vkGetQueryPoolResults(device_, pool_, 0, 2, sizeof stamps, stamps, sizeof(uint64_t),
                                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        if (r != VK_SUCCESS) return Error{ErrorCode::vulkan, "vkGetQueryPoolResults failed: " + vk_result_name(r), r};
        return static_cast<double>((stamps[1] - stamps[0]) & mask_) * period_ns_ * 1e-6;
    }

private:
    GpuTimer() = default;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueryPool pool_ = VK_NULL_HANDLE;
    double period_ns_ = 1.0;
    uint64_t mask_ = ~uint64_t{0};
};

}  // namespace crisp::tools
