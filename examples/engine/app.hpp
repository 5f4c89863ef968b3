// The example engine's frame loop: frames in flight, the swapchain and its resizes, dropped and
// abandoned frames, minimized windows, and the order of one frame's passes.
#pragma once

#include "device.hpp"
#include "options.hpp"
#include "scene.hpp"
#include "swapchain.hpp"
#include "text_overlay.hpp"
#include "vk_objects.hpp"

#include <crisp/font.hpp>
#include <crisp/result.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

struct GLFWwindow;

namespace engine {

// What a run did, for --report.
struct RunReport {
    uint64_t presented = 0;        // frames submitted and presented
    uint64_t dropped = 0;          // recorded, then abandoned on purpose (--drop-every)
    uint64_t out_of_date = 0;      // recorded, then abandoned because the swapchain was out of date
    uint64_t recreations = 0;      // swapchains made after the first
    uint64_t minimized_polls = 0;  // loop turns spent minimized, drawing nothing
    uint64_t resizes = 0;          // --resize-at requests carried out
    VkExtent2D extent{};           // of the last presented frame
    VkFormat swapchain_format = VK_FORMAT_UNDEFINED;
    std::vector<TextBox> boxes;       // text of the last presented frame
    FieldReport field;                // the text field in the last presented frame
    GlyphCounts glyphs;               // of the last presented frame
    std::vector<uint8_t> screenshot;  // RGB8 of the last presented frame, when asked for
};

// Called with the report of a frame F9 asked for (its screenshot included) and the snapshot's
// number, 1 and up (--snapshots). An error ends the run.
using SnapshotWriter = std::function<crisp::Status(const RunReport& report, uint32_t number)>;

class App {
public:
    // Takes the window's input callbacks (keys, characters, the mouse) for the text field and the
    // example's keys; `caret_blink_ms` as Options::caret_blink_ms.
    static crisp::Result<std::unique_ptr<App>> create(Device& device, std::vector<crisp::Font> fonts,
                                                      uint32_t caret_blink_ms);
    App(const App&) = delete;
    App& operator=(const App&) = delete;
    // Waits for the GPU, gives the window's callbacks back, then destroys crisp's objects and the
    // engine's (the device outlives them).
    ~App();

    // Presents frames until the window closes (Ctrl+Q, or the window system's close) or
    // options.frames were presented. With options.snapshots, each F9 has `snapshot` called with
    // the next presented frame.
    crisp::Status run(const Options& options, const SnapshotWriter& snapshot = {});
    const RunReport& report() const { return report_; }

private:
    struct FrameSlot {
        OwnedCommandPool pool;
        VkCommandBuffer command_buffer = VK_NULL_HANDLE;  // freed with the pool
        OwnedFence done;                                  // signalled when the slot's last submission completed
        OwnedSemaphore acquired;                          // the swapchain image may be written
    };
    enum class Outcome { presented, dropped, out_of_date };

    explicit App(Device& device);
    crisp::Status create_frame_slots();
    crisp::Status recreate_swapchain(VkExtent2D extent);
    void apply_scripted_events(const Options& options);
    bool minimized();
    crisp::Result<Outcome> render_frame(bool drop, bool screenshot);
    crisp::Status record_scene_and_text(VkCommandBuffer command_buffer);
    void record_present_copy(VkCommandBuffer command_buffer, uint32_t image_index, bool screenshot);
    bool record_screenshot_copy(VkCommandBuffer command_buffer, VkImage image);
    crisp::Status submit_and_present(FrameSlot& slot, uint32_t image_index, bool& stale);
    void keep_screenshot();
    crisp::Status take_snapshot(const SnapshotWriter& snapshot);
    // GLFW's callbacks, which find the App through the window's user pointer.
    static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);
    static void on_char(GLFWwindow* window, unsigned int codepoint);
    static void on_mouse_button(GLFWwindow* window, int button, int action, int mods);
    static void on_cursor(GLFWwindow* window, double x, double y);
    // A point in the window's coordinates to framebuffer pixels (they differ on high-DPI screens).
    std::array<float, 2> to_pixels(double x, double y) const;

    Device& device_;
    VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
    // Declaration order is destruction order, reversed: crisp's objects go first.
    std::array<FrameSlot, kFramesInFlight> slots_;
    std::optional<Swapchain> swapchain_;
    VkExtent2D made_for_{};  // the framebuffer size the swapchain was made for
    RenderTargets targets_;
    Buffer screenshot_;
    std::optional<Scene> scene_;
    std::unique_ptr<TextOverlay> text_;
    uint64_t frame_ = 0;     // presented frames: the animation's clock and the frame slot's index
    uint64_t attempts_ = 0;  // frames begun, dropped ones included
    size_t next_resize_ = 0, next_minimize_ = 0;
    uint32_t minimized_polls_left_ = 0;
    bool screenshot_recorded_ = false;
    bool snapshots_enabled_ = false;
    bool snapshot_requested_ = false;  // F9 was pressed: the next presented frame is a snapshot
    uint32_t snapshots_taken_ = 0;
    // The pointer as the last cursor event put it, in window coordinates: a button event is at
    // that point (glfwGetCursorPos asks the window system for where the pointer is now, which
    // may be later than the event's time when the loop is slow).
    double cursor_x_ = 0.0, cursor_y_ = 0.0;
    RunReport report_;
};

}  // namespace engine
