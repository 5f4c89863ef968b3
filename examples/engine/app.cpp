#include "app.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstring>

namespace engine {
namespace {

VkExtent2D framebuffer_extent(GLFWwindow* window) {
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    return {static_cast<uint32_t>(std::max(width, 0)), static_cast<uint32_t>(std::max(height, 0))};
}

bool operator==(VkExtent2D a, VkExtent2D b) {
    return a.width == b.width && a.height == b.height;
}

}  // namespace

App::App(Device& device) : device_(device) {}

crisp::Result<std::unique_ptr<App>> App::create(Device& device, std::vector<crisp::Font> fonts,
                                                uint32_t caret_blink_ms) {
    std::unique_ptr<App> app(new App(device));
    app->depth_format_ = choose_depth_format(device.physical_device());
    crisp::Result<Scene> scene = Scene::create(device, app->depth_format_);
    if (!scene) return scene.error();
    app->scene_.emplace(std::move(*scene));
    crisp::Result<std::unique_ptr<TextOverlay>> text = TextOverlay::create(device, std::move(fonts), caret_blink_ms);
    if (!text) return text.error();
    app->text_ = std::move(*text);
    if (crisp::Status s = app->create_frame_slots(); !s) return s.error();
    // A window that starts minimized (0 x 0) gets its swapchain once it has a size.
    const VkExtent2D extent = framebuffer_extent(device.window());
    if (extent.width > 0 && extent.height > 0) {
        if (crisp::Status s = app->recreate_swapchain(extent); !s) return s.error();
        app->report_.recreations = 0;  // the first swapchain is not a re-creation
    }
    GLFWwindow* window = device.window();
    glfwSetWindowUserPointer(window, app.get());
    glfwSetKeyCallback(window, on_key);
    glfwSetCharCallback(window, on_char);
    glfwSetMouseButtonCallback(window, on_mouse_button);
    glfwSetCursorPosCallback(window, on_cursor);
    return app;
}

App::~App() {
    GLFWwindow* window = device_.window();
    glfwSetKeyCallback(window, nullptr);
    glfwSetCharCallback(window, nullptr);
    glfwSetMouseButtonCallback(window, nullptr);
    glfwSetCursorPosCallback(window, nullptr);
    glfwSetWindowUserPointer(window, nullptr);
    // crisp's objects, like the engine's, may only go once the GPU is done with them. On a lost
    // device this returns an error, and destroying is still valid.
    vkDeviceWaitIdle(device_.device());
}

// The field takes the keys it knows while it has the focus; the example's own keys come after.
void App::on_key(GLFWwindow* window, int key, int, int action, int mods) {
    auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
    if (!app || (action != GLFW_PRESS && action != GLFW_REPEAT)) return;
    if (app->text_->field().key(key, mods)) return;
    if (key == GLFW_KEY_Q && (mods & GLFW_MOD_CONTROL)) glfwSetWindowShouldClose(window, GLFW_TRUE);
    if (key == GLFW_KEY_F9 && action == GLFW_PRESS && app->snapshots_enabled_) app->snapshot_requested_ = true;
}

void App::on_char(GLFWwindow* window, unsigned int codepoint) {
    auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
    if (app) app->text_->field().type(codepoint);
}

void App::on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
    auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
    if (!app || button != GLFW_MOUSE_BUTTON_LEFT) return;
    TextField& field = app->text_->field();
    if (action == GLFW_RELEASE) {
        field.release();
        return;
    }
    const std::array<float, 2> at = app->to_pixels(app->cursor_x_, app->cursor_y_);
    field.press(at[0], at[1], (mods & GLFW_MOD_SHIFT) != 0);
}

void App::on_cursor(GLFWwindow* window, double x, double y) {
    auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
    if (!app) return;
    app->cursor_x_ = x;
    app->cursor_y_ = y;
    const std::array<float, 2> at = app->to_pixels(x, y);
    app->text_->field().drag(at[0], at[1]);
}

std::array<float, 2> App::to_pixels(double x, double y) const {
    int window_width = 0, window_height = 0;
    glfwGetWindowSize(device_.window(), &window_width, &window_height);
    const VkExtent2D pixels = framebuffer_extent(device_.window());
    const double scale_x = window_width > 0 ? pixels.width / static_cast<double>(window_width) : 1.0;
    const double scale_y = window_height > 0 ? pixels.height / static_cast<double>(window_height) : 1.0;
    return {static_cast<float>(x * scale_x), static_cast<float>(y * scale_y)};
}

crisp::Status App::create_frame_slots() {
    const VkDevice device = device_.device();
    for (FrameSlot& slot : slots_) {
        VkCommandPoolCreateInfo pool_info{};
        pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
        pool_info.queueFamilyIndex = device_.queue_family();
        VkCommandPool pool = VK_NULL_HANDLE;
        if (crisp::Status s = check("vkCreateCommandPool", vkCreateCommandPool(device, &pool_info, nullptr, &pool)); !s)
            return s;
        slot.pool = OwnedCommandPool(device, pool);
        VkCommandBufferAllocateInfo allocate{};
        allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        allocate.commandPool = pool;
        allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        allocate.commandBufferCount = 1;
        if (crisp::Status s =
                check("vkAllocateCommandBuffers", vkAllocateCommandBuffers(device, &allocate, &slot.command_buffer));
            !s) {
            return s;
        }
        VkFenceCreateInfo fence_info{};
        fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;  // nothing in flight yet
        VkFence fence = VK_NULL_HANDLE;
        if (crisp::Status s = check("vkCreateFence", vkCreateFence(device, &fence_info, nullptr, &fence)); !s) return s;
        slot.done = OwnedFence(device, fence);
        VkSemaphoreCreateInfo semaphore_info{};
        semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
        VkSemaphore semaphore = VK_NULL_HANDLE;
        if (crisp::Status s =
                check("vkCreateSemaphore", vkCreateSemaphore(device, &semaphore_info, nullptr, &semaphore));
            !s) {
            return s;
        }
        slot.acquired = OwnedSemaphore(device, semaphore);
    }
    return {};
}

// A resize makes a new swapchain and new targets of its size; crisp's renderer and compositor
// stay as they are (the compositor takes the target's size with every record()).
crisp::Status App::recreate_swapchain(VkExtent2D extent) {
    if (crisp::Status s = check("vkDeviceWaitIdle", vkDeviceWaitIdle(device_.device())); !s) return s;
    made_for_ = extent;
    crisp::Result<Swapchain> swapchain =
        Swapchain::create(device_, extent, swapchain_ ? swapchain_->handle() : VK_NULL_HANDLE);
    if (!swapchain) return swapchain.error();
    swapchain_.emplace(std::move(*swapchain));  // the old one is destroyed after the new one exists
    crisp::Result<RenderTargets> targets = create_render_targets(device_.memory(), swapchain_->extent(), depth_format_);
    if (!targets) return targets.error();
    targets_ = std::move(*targets);
    ++report_.recreations;
    report_.swapchain_format = swapchain_->format();
    return {};
}

crisp::Status App::run(const Options& options, const SnapshotWriter& snapshot) {
    GLFWwindow* window = device_.window();
    snapshots_enabled_ = !options.snapshots.empty() && snapshot;
    while (!glfwWindowShouldClose(window) && (options.frames == 0 || frame_ < options.frames)) {
        glfwPollEvents();
        apply_scripted_events(options);
        if (minimized()) {
            glfwWaitEventsTimeout(0.010);  // draw nothing, and do not spin
            ++report_.minimized_polls;
            continue;
        }
        if (!swapchain_ || !(framebuffer_extent(window) == made_for_)) {
            if (crisp::Status s = recreate_swapchain(framebuffer_extent(window)); !s) return s;
        }
        ++attempts_;
        const bool drop = options.drop_every != 0 && attempts_ % options.drop_every == 0;
        const bool last = !options.screenshot.empty() && frame_ + 1 == options.frames;
        const bool snapshot_now = snapshot_requested_ && !drop;
        crisp::Result<Outcome> outcome = render_frame(drop, last || snapshot_now);
        if (!outcome) return outcome.error();
        if (*outcome == Outcome::dropped) ++report_.dropped;
        if (*outcome == Outcome::out_of_date) ++report_.out_of_date;
        if (*outcome == Outcome::presented && snapshot_now) {
            if (crisp::Status s = take_snapshot(snapshot); !s) return s;
        }
    }
    if (crisp::Status s = check("vkDeviceWaitIdle", vkDeviceWaitIdle(device_.device())); !s) return s;
    if (screenshot_recorded_) keep_screenshot();
    return {};
}

// --resize-at and --minimize-at, at the frame they name. A resize waits (up to 5 s) until the
// window system reports the new size, so that frame F is drawn at it in every run; one that never
// arrives is not counted in the report.
void App::apply_scripted_events(const Options& options) {
    GLFWwindow* window = device_.window();
    while (next_resize_ < options.resizes.size() && options.resizes[next_resize_].frame <= frame_) {
        const ResizeAt& resize = options.resizes[next_resize_++];
        const VkExtent2D wanted{resize.width, resize.height};
        glfwSetWindowSize(window, static_cast<int>(resize.width), static_cast<int>(resize.height));
        for (int i = 0; i < 500 && !(framebuffer_extent(window) == wanted); ++i) glfwWaitEventsTimeout(0.010);
        if (framebuffer_extent(window) == wanted) ++report_.resizes;
    }
    while (next_minimize_ < options.minimizes.size() && options.minimizes[next_minimize_].frame <= frame_) {
        glfwIconifyWindow(window);
        minimized_polls_left_ = options.minimizes[next_minimize_++].polls;
    }
}

// A minimized window draws nothing: Windows reports a 0 x 0 framebuffer, X11 an iconified window.
// Without a window manager (Xvfb) the iconify request goes unanswered, so --minimize-at's count
// of polls stands in for it.
bool App::minimized() {
    GLFWwindow* window = device_.window();
    const VkExtent2D extent = framebuffer_extent(window);
    if (minimized_polls_left_ > 0) {
        if (--minimized_polls_left_ == 0) glfwRestoreWindow(window);
        return true;
    }
    return glfwGetWindowAttrib(window, GLFW_ICONIFIED) || extent.width == 0 || extent.height == 0;
}

crisp::Result<App::Outcome> App::render_frame(bool drop, bool screenshot) {
    FrameSlot& slot = slots_[frame_ % kFramesInFlight];
    const VkDevice device = device_.device();
    // The slot's previous submission must be done before its command buffer is reused; crisp's
    // per-frame resources follow the same count (frames_in_flight).
    const VkFence done = slot.done.get();
    if (crisp::Status s = check("vkWaitForFences", vkWaitForFences(device, 1, &done, VK_TRUE, UINT64_MAX)); !s) {
        return s.error();
    }
    if (crisp::Status s = check("vkResetCommandPool", vkResetCommandPool(device, slot.pool.get(), 0)); !s)
        return s.error();
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    const VkCommandBuffer cb = slot.command_buffer;
    if (crisp::Status s = check("vkBeginCommandBuffer", vkBeginCommandBuffer(cb, &begin)); !s) return s.error();
    if (crisp::Status s = record_scene_and_text(cb); !s) {
        text_->abandon_frame();  // whatever crisp recorded before the failure
        return s.error();
    }

    // From here on the frame is recorded, and crisp has committed to it: a frame that is not
    // submitted must be taken back, or the atlas would count samples that were never drawn.
    if (drop) {
        text_->abandon_frame();
        return Outcome::dropped;
    }
    uint32_t image_index = 0;
    const VkResult acquired = vkAcquireNextImageKHR(device, swapchain_->handle(), UINT64_MAX, slot.acquired.get(),
                                                    VK_NULL_HANDLE, &image_index);
    if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
        text_->abandon_frame();
        if (crisp::Status s = recreate_swapchain(framebuffer_extent(device_.window())); !s) return s.error();
        return Outcome::out_of_date;
    }
    if (acquired != VK_SUCCESS && acquired != VK_SUBOPTIMAL_KHR) {
        text_->abandon_frame();
        return vulkan_error("vkAcquireNextImageKHR", acquired);
    }
    record_present_copy(cb, image_index, screenshot);
    bool stale = acquired == VK_SUBOPTIMAL_KHR;
    if (crisp::Status s = submit_and_present(slot, image_index, stale); !s) return s.error();
    if (stale) {
        if (crisp::Status s = recreate_swapchain(framebuffer_extent(device_.window())); !s) return s.error();
    }
    return Outcome::presented;
}

// The frame's passes, in order: crisp rasterizes (compute), the engine draws its scene and panels
// (graphics), crisp composites the text into the scene target (compute), and the target goes to
// the blit.
crisp::Status App::record_scene_and_text(VkCommandBuffer cb) {
    const VkExtent2D extent = swapchain_->extent();
    const SceneState state = Scene::animate(frame_, extent, text_->hud_right());
    const OverlayFrame& overlay = text_->draw(frame_, extent, state);
    if (crisp::Status s = text_->record_rasterization(cb); !s) return s;
    scene_->record(cb, targets_, state, overlay.panels);
    record_barrier(cb, {targets_.color.image.get(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                        VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT});
    if (crisp::Status s = text_->record_composite(cb, targets_); !s) return s;
    record_barrier(cb, {targets_.color.image.get(), VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT});
    return {};
}

// The scene target to the swapchain image: the blit encodes the linear colour as sRGB.
void App::record_present_copy(VkCommandBuffer cb, uint32_t image_index, bool screenshot) {
    const VkImage image = swapchain_->image(image_index);
    // The acquire semaphore is waited on at TRANSFER: the layout change chains after it.
    record_barrier(
        cb, {image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
             VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT});
    const VkExtent2D extent = swapchain_->extent();
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {static_cast<int32_t>(extent.width), static_cast<int32_t>(extent.height), 1};
    blit.dstSubresource = blit.srcSubresource;
    blit.dstOffsets[1] = blit.srcOffsets[1];
    vkCmdBlitImage(cb, targets_.color.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
    screenshot_recorded_ = screenshot && record_screenshot_copy(cb, image);
    // Presentation needs no access mask: the present semaphore orders it (BOTTOM_OF_PIPE). After the
    // screenshot's copy the last access was a read, which needs no making available.
    const VkAccessFlags written = screenshot_recorded_ ? VkAccessFlags{0} : VkAccessFlags{VK_ACCESS_TRANSFER_WRITE_BIT};
    record_barrier(
        cb, {image, screenshot_recorded_ ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
             VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, written,
             VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0});
}

// The swapchain image as it will be presented, into a host buffer, for --screenshot. False (and
// nothing recorded) where the surface's images cannot be transfer sources or the buffer cannot be
// made; the image is left in TRANSFER_SRC_OPTIMAL otherwise.
bool App::record_screenshot_copy(VkCommandBuffer cb, VkImage image) {
    const VkExtent2D extent = swapchain_->extent();
    const VkDeviceSize bytes = VkDeviceSize{extent.width} * extent.height * 4;
    if (!swapchain_->can_copy_from()) return false;
    if (screenshot_.size != bytes) {
        screenshot_ = {};
        crisp::Result<Buffer> buffer = create_host_buffer(device_.memory(), bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        if (!buffer) return false;
        screenshot_ = std::move(*buffer);
    }
    record_barrier(cb, {image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                        VK_ACCESS_TRANSFER_READ_BIT});
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {extent.width, extent.height, 1};
    vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, screenshot_.buffer.get(), 1, &copy);
    VkMemoryBarrier to_host{};
    to_host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0,
                         nullptr);
    return true;
}

crisp::Status App::submit_and_present(FrameSlot& slot, uint32_t image_index, bool& stale) {
    const VkDevice device = device_.device();
    const VkCommandBuffer cb = slot.command_buffer;
    if (crisp::Status s = check("vkEndCommandBuffer", vkEndCommandBuffer(cb)); !s) return s;
    // Images in flight: the image may still be drawn by the other slot's frame (the swapchain
    // can hand images back in any order), so wait for whichever frame last used it.
    VkFence& image_fence = swapchain_->image_fence(image_index);
    if (image_fence != VK_NULL_HANDLE && image_fence != slot.done.get()) {
        if (crisp::Status s = check("vkWaitForFences", vkWaitForFences(device, 1, &image_fence, VK_TRUE, UINT64_MAX));
            !s) {
            return s;
        }
    }
    image_fence = slot.done.get();
    const VkFence done = slot.done.get();
    if (crisp::Status s = check("vkResetFences", vkResetFences(device, 1, &done)); !s) return s;
    const VkSemaphore acquired = slot.acquired.get(), rendered = swapchain_->rendered(image_index);
    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // the blit is the first write
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &acquired;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &rendered;
    if (crisp::Status s = check("vkQueueSubmit", vkQueueSubmit(device_.queue(), 1, &submit, done)); !s) return s;
    // Submitted: crisp's frame counts, and so does the frame for the animation.
    text_->frame_submitted();
    report_.boxes = text_->frame().boxes;
    report_.field = text_->field().report();
    report_.glyphs = text_->submitted_glyphs();
    report_.extent = swapchain_->extent();
    ++report_.presented;
    ++frame_;
    const VkSwapchainKHR swapchain = swapchain_->handle();
    VkPresentInfoKHR present{};
    present.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
    present.waitSemaphoreCount = 1;
    present.pWaitSemaphores = &rendered;
    present.swapchainCount = 1;
    present.pSwapchains = &swapchain;
    present.pImageIndices = &image_index;
    const VkResult presented = vkQueuePresentKHR(device_.queue(), &present);
    if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR) {
        stale = true;
        return {};
    }
    return check("vkQueuePresentKHR", presented);
}

// The frame just presented, once the GPU is done with it, with its screenshot where the swapchain
// allows one (the writer decides what a missing one means).
crisp::Status App::take_snapshot(const SnapshotWriter& snapshot) {
    if (crisp::Status s = check("vkDeviceWaitIdle", vkDeviceWaitIdle(device_.device())); !s) return s;
    if (screenshot_recorded_) keep_screenshot();
    snapshot_requested_ = false;
    const crisp::Status written = snapshot(report_, ++snapshots_taken_);
    report_.screenshot.clear();
    return written;
}

// The last frame as presented, from the swapchain image's bytes (BGRA or RGBA) to RGB.
void App::keep_screenshot() {
    const VkExtent2D extent = report_.extent;
    const size_t pixels = size_t{extent.width} * extent.height;
    const auto* bytes = static_cast<const uint8_t*>(screenshot_.mapped);
    const bool bgra = report_.swapchain_format == VK_FORMAT_B8G8R8A8_SRGB;
    report_.screenshot.resize(pixels * 3);
    for (size_t i = 0; i < pixels; ++i) {
        report_.screenshot[i * 3 + 0] = bytes[i * 4 + (bgra ? 2 : 0)];
        report_.screenshot[i * 3 + 1] = bytes[i * 4 + 1];
        report_.screenshot[i * 3 + 2] = bytes[i * 4 + (bgra ? 0 : 2)];
    }
}

}  // namespace engine
