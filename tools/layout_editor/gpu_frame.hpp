// crisp-layout-editor: one frame on the GPU. The CPU-drawn canvas is uploaded into an RGBA8
// image, crisp's renderers rasterize the interface's text (the gray subpixel layout) and the
// preview's text (the edited one), crisp's compositors composite both into the image (the tile
// path), and the image is copied back (for the magnified view and screenshots) and blitted to the
// swapchain.
// One frame in flight: wait() before touching the canvas or reading the previous frame.
#pragma once

#include "vulkan_window.hpp"

#include "vk/resources.hpp"

#include <crisp/compositor.hpp>
#include <crisp/renderer.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace crisp::editor {

// The preview's sample schedule: a few samples a frame, so an edit is seen converging.
inline constexpr uint32_t kPreviewMaxSamples = 256;

class GpuFrame {
public:
    // The canvas is window.width() x window.height() (match_window() follows a resize). `font`
    // must outlive the GpuFrame.
    static Result<std::unique_ptr<GpuFrame>> create(VulkanWindow& window, const Font& font,
                                                    const SubpixelLayout& preview_layout,
                                                    const TextContrast& preview_contrast);
    GpuFrame(const GpuFrame&) = delete;
    GpuFrame& operator=(const GpuFrame&) = delete;
    // Waits for the device, then destroys crisp's objects and its own.
    ~GpuFrame();

    // Waits for the frame in flight, if any; then the canvas may be written and previous_frame()
    // and gpu_milliseconds() describe it.
    Status wait();
    // After wait(): makes the canvas and the copies of the frame the window's size where it has
    // changed (previous_frame() is then empty until the next frame completes).
    Status match_window();
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    std::span<uint8_t> canvas();
    // The last completed frame as shown (RGBA8, sRGB, top row first); empty before the first.
    std::span<const uint8_t> previous_frame() const;
    // GPU time of the last completed frame; nullopt without timestamps.
    std::optional<double> gpu_milliseconds() const { return gpu_ms_; }

    // Restarts the preview's sample schedule with a new layout (crisp's error when invalid).
    Status set_preview_layout(const SubpixelLayout& layout);
    // The preview's contrast settings, from the next frame on (the samples stay).
    Status set_preview_contrast(const TextContrast& contrast);

    // Compare mode: one renderer (a small atlas, its own compositor) per candidate layout, made
    // on first use and kept; a changed layout restarts that renderer's samples. An empty span
    // leaves compare mode (the renderers stay, idle). crisp's error for an invalid layout or
    // contrast, or where a renderer cannot be made (the candidates before it stay in use).
    Status set_candidates(std::span<const SubpixelLayout> layouts, const TextContrast& contrast);
    size_t candidate_count() const { return candidate_count_; }
    const Renderer& candidate_renderer(size_t i) const { return candidate_renderers_[i]; }

    // Records and submits one frame into the acquired swapchain image. `candidate_glyphs[i]` is
    // drawn with candidate i's renderer (those past candidate_count() are ignored).
    Status render(const VulkanWindow::Acquired& target, std::span<const GlyphInstance> interface_glyphs,
                  std::span<const GlyphInstance> preview_glyphs,
                  std::span<const std::vector<GlyphInstance>> candidate_glyphs);

    const Renderer& preview_renderer() const { return *preview_renderer_; }
    const Renderer& interface_renderer() const { return *interface_renderer_; }

private:
    explicit GpuFrame(VulkanWindow& window);
    // The canvas image and the upload and readback buffers, width x height.
    Status create_images(uint32_t width, uint32_t height);

    VulkanWindow& window_;
    vk::Functions functions_;  // for crisp's private helpers (the editor itself calls the loader)
    vk::DeviceRef device_;
    vk::DeviceImage canvas_;
    vk::DeviceBuffer upload_;
    vk::DeviceBuffer readback_;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkQueryPool timestamps_ = VK_NULL_HANDLE;
    uint32_t width_ = 0, height_ = 0;
    bool in_flight_ = false;
    bool has_previous_ = false;
    std::optional<double> gpu_ms_;
    std::optional<Renderer> interface_renderer_;
    std::optional<Renderer> preview_renderer_;
    std::optional<Compositor> interface_compositor_;
    std::optional<Compositor> preview_compositor_;
    // Kept for making the candidates' renderers.
    const Font* font_ = nullptr;
    RendererCreateInfo renderer_info_;
    CompositorCreateInfo compositor_info_;
    std::vector<Renderer> candidate_renderers_;
    std::vector<Compositor> candidate_compositors_;
    std::vector<SubpixelLayout> candidate_layouts_;  // as each renderer has it
    std::vector<TextContrast> candidate_contrasts_;
    size_t candidate_count_ = 0;
};

}  // namespace crisp::editor
