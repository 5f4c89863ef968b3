#include "gpu_frame.hpp"
#include "headless_context.hpp"

#include "vk/barriers.hpp"

#include <algorithm>
#include <utility>

namespace crisp::editor {
namespace {

using vk::create_buffer;
using vk::create_image;

using vk::image_barrier;

AtlasConfig atlas_config(uint32_t size) {
    AtlasConfig config;
    config.width = size;
    config.height = size;
    config.ramp = {8, 4, 2};
    config.steady = 4;
    config.max_samples = kPreviewMaxSamples;
    return config;
}

}  // namespace

GpuFrame::GpuFrame(VulkanWindow& window) : window_(window) {}

GpuFrame::~GpuFrame() {
    vkDeviceWaitIdle(window_.device());
    candidate_compositors_.clear();
    candidate_renderers_.clear();
    preview_compositor_.reset();
    interface_compositor_.reset();
    preview_renderer_.reset();
    interface_renderer_.reset();
    if (timestamps_) vkDestroyQueryPool(device_.device, timestamps_, nullptr);
    if (fence_) vkDestroyFence(device_.device, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_.device, pool_, nullptr);
    readback_.reset();
    upload_.reset();
    canvas_.reset();
}

Result<std::unique_ptr<GpuFrame>> GpuFrame::create(VulkanWindow& window, const Font& font,
                                                   const SubpixelLayout& preview_layout,
                                                   const TextContrast& preview_contrast) {
    std::unique_ptr<GpuFrame> self(new GpuFrame(window));
    if (Status s = vk::load_functions(vkGetInstanceProcAddr, window.instance(), window.device(), self->functions_);
        !s) {
        return s.error();
    }
    self->device_ =
        vk::make_device_ref(self->functions_, window.physical_device(), window.device(), nullptr, VK_NULL_HANDLE);
    if (Status s = self->create_images(window.width(), window.height()); !s) return s.error();
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = window.queue_family();
    if (VkResult r = vkCreateCommandPool(window.device(), &pool_info, nullptr, &self->pool_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateCommandPool", r);
    }
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = self->pool_;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    if (VkResult r = vkAllocateCommandBuffers(window.device(), &allocate, &self->command_buffer_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkAllocateCommandBuffers", r);
    }
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if (VkResult r = vkCreateFence(window.device(), &fence_info, nullptr, &self->fence_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFence", r);
    }
    if (window.timestamp_valid_bits() > 0) {
        VkQueryPoolCreateInfo query_info{};
        query_info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        query_info.queryCount = 2;
        if (VkResult r = vkCreateQueryPool(window.device(), &query_info, nullptr, &self->timestamps_);
            r != VK_SUCCESS) {
            return vk::vulkan_error("vkCreateQueryPool", r);
        }
    }

    // The interface's text: the neutral gray subpixel layout, whatever is being edited.
    RendererCreateInfo renderer_info;
    renderer_info.instance = window.instance();
    renderer_info.instance_api_version = window.instance_api_version();
    renderer_info.physical_device = window.physical_device();
    renderer_info.device = window.device();
    renderer_info.queue_family = window.queue_family();
    renderer_info.enabled_features = window.enabled_features();
    renderer_info.frames_in_flight = 1;
    renderer_info.atlas = atlas_config(1024);
    Result<SubpixelLayout> gray = subpixel_preset("gray");
    if (!gray) return gray.error();
    renderer_info.layout = *gray;
    Result<Renderer> interface_renderer = Renderer::create(renderer_info);
    if (!interface_renderer) return interface_renderer.error();
    self->interface_renderer_.emplace(std::move(*interface_renderer));
    renderer_info.atlas = atlas_config(2048);
    renderer_info.layout = preview_layout;
    renderer_info.contrast = preview_contrast;
    Result<Renderer> preview_renderer = Renderer::create(renderer_info);
    if (!preview_renderer) return preview_renderer.error();
    self->preview_renderer_.emplace(std::move(*preview_renderer));
    for (Renderer* renderer : {&*self->interface_renderer_, &*self->preview_renderer_}) {
        if (Status s = renderer->add_font(font); !s) return s.error();
    }

    CompositorCreateInfo compositor_info;
    compositor_info.instance = window.instance();
    compositor_info.instance_api_version = window.instance_api_version();
    compositor_info.physical_device = window.physical_device();
    compositor_info.device = window.device();
    compositor_info.frames_in_flight = 1;
    compositor_info.enabled_features = window.enabled_features();
    for (std::optional<Compositor>* slot : {&self->interface_compositor_, &self->preview_compositor_}) {
        Result<Compositor> compositor = Compositor::create(compositor_info);
        if (!compositor) return compositor.error();
        slot->emplace(std::move(*compositor));
    }
    self->font_ = &font;
    self->renderer_info_ = renderer_info;
    self->compositor_info_ = compositor_info;
    if (!self->preview_compositor_->supports_target_format(VK_FORMAT_R8G8B8A8_UNORM)) {
        return Error{ErrorCode::vulkan, "the compositor cannot write R8G8B8A8_UNORM storage images on this device"};
    }
    return self;
}

Status GpuFrame::create_images(uint32_t width, uint32_t height) {
    readback_.reset();
    upload_.reset();
    canvas_.reset();
    width_ = width;
    height_ = height;
    has_previous_ = false;
    const VkDeviceSize bytes = VkDeviceSize{width} * height * 4;
    if (Status s =
            create_image(device_, VK_FORMAT_R8G8B8A8_UNORM, width, height,
                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                         "canvas", canvas_);
        !s) {
        return s;
    }
    if (Status s = create_buffer(device_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "editor upload", upload_);
        !s) {
        return s;
    }
    return create_buffer(device_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "editor readback", readback_);
}

Status GpuFrame::match_window() {
    if (window_.width() == width_ && window_.height() == height_) return {};
    if (Status s = wait(); !s) return s;
    return create_images(window_.width(), window_.height());
}

Status GpuFrame::wait() {
    if (!in_flight_) return {};
    if (VkResult r = vkWaitForFences(device_.device, 1, &fence_, VK_TRUE, UINT64_MAX); r != VK_SUCCESS) {
        return vk::vulkan_error("vkWaitForFences", r);
    }
    vkResetFences(device_.device, 1, &fence_);
    in_flight_ = false;
    has_previous_ = true;
    gpu_ms_.reset();
    if (timestamps_) {
        uint64_t stamps[2] = {};
        if (vkGetQueryPoolResults(device_.device, timestamps_, 0, 2, sizeof stamps, stamps, sizeof(uint64_t),
                                  VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
            const uint32_t bits = window_.timestamp_valid_bits();
            const uint64_t mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
            gpu_ms_ = static_cast<double>((stamps[1] - stamps[0]) & mask) *
                      static_cast<double>(window_.properties().limits.timestampPeriod) * 1e-6;
        }
    }
    return {};
}

std::span<uint8_t> GpuFrame::canvas() {
    return {static_cast<uint8_t*>(upload_.mapped), static_cast<size_t>(upload_.size)};
}

std::span<const uint8_t> GpuFrame::previous_frame() const {
    if (!has_previous_) return {};
    return {static_cast<const uint8_t*>(readback_.mapped), static_cast<size_t>(readback_.size)};
}

Status GpuFrame::set_preview_layout(const SubpixelLayout& layout) {
    return preview_renderer_->set_subpixel_layout(layout);
}

Status GpuFrame::set_preview_contrast(const TextContrast& contrast) {
    return preview_renderer_->set_contrast(contrast);
}

Status GpuFrame::set_candidates(std::span<const SubpixelLayout> layouts, const TextContrast& contrast) {
    candidate_count_ = 0;
    for (size_t i = 0; i < layouts.size(); ++i) {
        if (i == candidate_renderers_.size()) {
            // A small atlas: the candidates show one short paragraph at a few sizes, and four of
            // them converge together on lavapipe.
            RendererCreateInfo info = renderer_info_;
            info.atlas = atlas_config(512);
            info.layout = layouts[i];
            info.contrast = contrast;
            Result<Renderer> renderer = Renderer::create(info);
            if (!renderer) return renderer.error();
            if (Status s = renderer->add_font(*font_); !s) return s.error();
            Result<Compositor> compositor = Compositor::create(compositor_info_);
            if (!compositor) return compositor.error();
            candidate_renderers_.push_back(std::move(*renderer));
            candidate_compositors_.push_back(std::move(*compositor));
            candidate_layouts_.push_back(layouts[i]);
            candidate_contrasts_.push_back(contrast);
        }
        if (candidate_layouts_[i].channels != layouts[i].channels) {
            if (Status s = candidate_renderers_[i].set_subpixel_layout(layouts[i]); !s) return s;
            candidate_layouts_[i] = layouts[i];
        }
        if (candidate_contrasts_[i] != contrast) {
            if (Status s = candidate_renderers_[i].set_contrast(contrast); !s) return s;
            candidate_contrasts_[i] = contrast;
        }
        candidate_count_ = i + 1;
    }
    return {};
}

Status GpuFrame::render(const VulkanWindow::Acquired& target, std::span<const GlyphInstance> interface_glyphs,
                        std::span<const GlyphInstance> preview_glyphs,
                        std::span<const std::vector<GlyphInstance>> candidate_glyphs) {
    const uint32_t width = width_, height = height_;
    const VkRect2D whole{{0, 0}, {width, height}};
    const size_t candidates = std::min(candidate_count_, candidate_glyphs.size());
    interface_renderer_->begin_frame();
    interface_renderer_->draw(interface_glyphs, whole);
    preview_renderer_->begin_frame();
    preview_renderer_->draw(preview_glyphs, whole);
    for (size_t i = 0; i < candidates; ++i) {
        candidate_renderers_[i].begin_frame();
        candidate_renderers_[i].draw(candidate_glyphs[i], whole);
    }

    VkCommandBuffer cb = command_buffer_;
    vkResetCommandBuffer(cb, 0);
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(cb, &begin);
    if (timestamps_) {
        vkCmdResetQueryPool(cb, timestamps_, 0, 2);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_, 0);
    }

    // The CPU-drawn canvas into the image (its old contents, last read by transfers, are dropped).
    image_barrier(functions_, cb, canvas_.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {width, height, 1};
    vkCmdCopyBufferToImage(cb, upload_.buffer, canvas_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    image_barrier(functions_, cb, canvas_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);

    // crisp: rasterize, then composite the interface's text and the preview's over the canvas.
    // A failed record leaves a frame that is never submitted: the renderers take theirs back.
    auto fail = [&](const Error& error) -> Status {
        vkEndCommandBuffer(cb);
        // Each renderer's current frame: never refused.
        (void)interface_renderer_->abandon_frame(interface_renderer_->frame());
        (void)preview_renderer_->abandon_frame(preview_renderer_->frame());
        for (size_t i = 0; i < candidates; ++i) {
            (void)candidate_renderers_[i].abandon_frame(candidate_renderers_[i].frame());
        }
        return error;
    };
    if (Status s = interface_renderer_->record(cb); !s) return fail(s.error());
    if (Status s = preview_renderer_->record(cb); !s) return fail(s.error());
    for (size_t i = 0; i < candidates; ++i) {
        if (Status s = candidate_renderers_[i].record(cb); !s) return fail(s.error());
    }
    CompositeTarget composite_target;
    composite_target.view = canvas_.view;
    composite_target.format = VK_FORMAT_R8G8B8A8_UNORM;
    composite_target.extent = {width, height};
    composite_target.rect = whole;
    if (Status s = interface_compositor_->record(cb, interface_renderer_->drawn_frame(), composite_target); !s) {
        return fail(s.error());
    }
    image_barrier(functions_, cb, canvas_.image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    if (Status s = preview_compositor_->record(cb, preview_renderer_->drawn_frame(), composite_target); !s) {
        return fail(s.error());
    }
    // Each candidate's text over the canvas, in its own panel (its glyphs are placed there).
    for (size_t i = 0; i < candidates; ++i) {
        image_barrier(functions_, cb, canvas_.image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        if (Status s = candidate_compositors_[i].record(cb, candidate_renderers_[i].drawn_frame(), composite_target);
            !s) {
            return fail(s.error());
        }
    }
    image_barrier(functions_, cb, canvas_.image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT);

    // Back to the host (the magnified view, screenshots) and on to the swapchain image.
    vkCmdCopyImageToBuffer(cb, canvas_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1, &copy);
    VkBufferMemoryBarrier to_host{};
    to_host.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.buffer = readback_.buffer;
    to_host.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &to_host, 0,
                         nullptr);
    image_barrier(functions_, cb, target.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {static_cast<int32_t>(width), static_cast<int32_t>(height), 1};
    blit.dstSubresource = blit.srcSubresource;
    blit.dstOffsets[1] = blit.srcOffsets[1];
    vkCmdBlitImage(cb, canvas_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target.image,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
    image_barrier(functions_, cb, target.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT,
                  0);
    if (timestamps_) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, 1);
    if (VkResult r = vkEndCommandBuffer(cb); r != VK_SUCCESS) return vk::vulkan_error("vkEndCommandBuffer", r);

    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &target.ready;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &target.rendered;
    if (VkResult r = vkQueueSubmit(window_.queue(), 1, &submit, fence_); r != VK_SUCCESS) {
        return vk::vulkan_error("vkQueueSubmit", r);
    }
    in_flight_ = true;
    return {};
}

}  // namespace crisp::editor
