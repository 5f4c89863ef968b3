// crisp-bench --suite frame-cpu (formerly crisp-bench-frame): the CPU time one frame of a game's
// UI text costs on the calling thread. Eight labels (health, ammo, a name, coordinates, an FPS
// counter, ...) are laid out once; every frame three of them get a new string and are laid out
// again with a Layouter, all eight are drawn with DrawOptions, and the renderer's and the
// compositor's (tile path) record() fill the frame's command buffer, with 2 frames in flight.
// Timed with a steady clock, per phase, and with the thread's CPU clock: begin_frame() through the
// end of compositor.record(). docs/benchmarks-cpu.md.
#include "bench.hpp"
#include "cli.hpp"
#include "gpu_tools.hpp"
#include "json_writer.hpp"
#include "vk/barriers.hpp"
#include "vk/resources.hpp"
#include "headless_context.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

constexpr uint32_t kFramesInFlight = 2;

// The CPU time the calling thread has run, in µs: unlike the steady clock it stops while the
// thread waits for a core, so another process (or lavapipe's own threads) taking the core does
// not count.
double thread_cpu_us() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
}
constexpr VkFormat kTargetFormat = VK_FORMAT_R8G8B8A8_UNORM;

[[noreturn]] void fail(const std::string& message) {
    crisp::bench::fail("frame-cpu", message);
}

// ---- Options

struct Args {
    std::string font = crisp::bench::data_file("fonts/DejaVuSans.ttf");
    uint32_t width = 1920, height = 1080;
    float size = 16.0f;
    uint32_t warmup = 100;
    uint32_t frames = 1000;
    std::vector<std::string> variants = {"static", "changed", "moving"};
    bool validate = false;
};

// ---- The scene

// What a label shows. The counters change every frame in the changed and moving variants.
enum class Counter { none, position, fps, clock };

struct LabelSpec {
    const char* text;  // counters: written by write_counter instead
    float x, y;        // the first pen, on the baseline, as fractions of the canvas
    Counter counter;
};

constexpr std::array<LabelSpec, 8> kLabels = {{
    {"Health 100", 0.02f, 0.05f, Counter::none},
    {"Ammo 30/90", 0.88f, 0.95f, Counter::none},
    {"Ada Lovelace", 0.47f, 0.40f, Counter::none},
    {nullptr, 0.02f, 0.95f, Counter::position},
    {nullptr, 0.92f, 0.05f, Counter::fps},
    {nullptr, 0.45f, 0.05f, Counter::clock},
    {"Quest: find the lighthouse keeper", 0.02f, 0.10f, Counter::none},
    {"Press E to open the door", 0.42f, 0.70f, Counter::none},
}};

// A counter's text at `frame` (a 60 Hz clock), into `out`.
std::string_view write_counter(Counter counter, uint64_t frame, std::array<char, 64>& out) {
    const double t = static_cast<double>(frame);
    int n = 0;
    switch (counter) {
        case Counter::position:
            n = std::snprintf(out.data(), out.size(), "X %.2f  Y %.2f  Z %.2f", 1024.25 + 0.37 * t,
                              64.0 + 2.0 * std::sin(0.05 * t), -311.75 - 0.21 * t);
            break;
        case Counter::fps:
            n = std::snprintf(out.data(), out.size(), "FPS %.1f", 144.0 + 20.0 * std::sin(0.1 * t));
            break;
        case Counter::clock: {
            const uint64_t ms = frame * 1000 / 60;
            n = std::snprintf(
                out.data(), out.size(), "Time %02llu:%02llu.%03llu", static_cast<unsigned long long>(ms / 60000 % 100),
                static_cast<unsigned long long>(ms / 1000 % 60), static_cast<unsigned long long>(ms % 1000));
            break;
        }
        case Counter::none:
            break;
    }
    return {out.data(), static_cast<size_t>(std::clamp(n, 0, static_cast<int>(out.size()) - 1))};
}

struct Variant {
    const char* name;
    const char* description;
    bool change_strings;
    bool move;
};

constexpr Variant kVariants[] = {
    {"static", "8 labels, nothing changes", false, false},
    {"changed", "3 of the 8 strings change every frame and are laid out again", true, false},
    {"moving", "as changed, and all 8 labels move every frame (offsets, named draws)", true, true},
};

// The 8 labels' text and layouts, kept from frame to frame as an engine keeps them.
struct Labels {
    std::array<crisp::LayoutOptions, kLabels.size()> placement;
    std::array<std::array<char, 64>, kLabels.size()> counter_text{};
    std::array<std::string_view, kLabels.size()> text;
    std::array<crisp::TextLayout, kLabels.size()> laid;
    std::vector<size_t> counters;  // the labels whose text changes

    Labels(uint32_t width, uint32_t height) {
        for (size_t i = 0; i < kLabels.size(); ++i) {
            placement[i].origin_x = kLabels[i].x * static_cast<float>(width);
            placement[i].origin_y = kLabels[i].y * static_cast<float>(height);
            if (kLabels[i].counter == Counter::none) {
                text[i] = kLabels[i].text;
            } else {
                counters.push_back(i);
            }
        }
        write_counters(0);
    }
    void write_counters(uint64_t frame) {
        for (size_t i : counters) text[i] = write_counter(kLabels[i].counter, frame, counter_text[i]);
    }
    void lay_out(crisp::Layouter& layouter, std::span<const crisp::Font* const> fonts, const crisp::TextStyle& style,
                 size_t i) {
        if (crisp::Status s = layouter.layout(fonts, text[i], style, placement[i], laid[i]); !s)
            fail(s.error().message);
    }
};

// What a label draws with this frame: where a moving label is (a fraction of a pixel further
// every frame, within a few pixels), the health's warning colour, the name's world-space depth.
crisp::DrawOptions draw_options(size_t label, uint64_t frame, bool move, const VkRect2D& visible) {
    crisp::DrawOptions options;
    options.id = label + 1;
    options.visible = visible;
    if (move) {
        const double t = static_cast<double>(frame), phase = static_cast<double>(label);
        options.offset_x = static_cast<float>(6.0 * std::sin(0.05 * t + phase));
        options.offset_y = static_cast<float>(3.0 * std::cos(0.037 * t + phase));
    }
    if (label == 0) options.color = std::array<float, 4>{1.0f, 0.35f, 0.25f, 1.0f};
    if (label == 2) options.depth = 0.25f;
    return options;
}

// ---- Frames in flight: per-frame command buffers and fences, as an engine keeps them.

class FrameSlots {
public:
    static crisp::Result<FrameSlots> create(const crisp::HeadlessContext& context) {
        FrameSlots slots;
        slots.device_ = context.device();
        slots.queue_ = context.queue();
        VkCommandPoolCreateInfo pool_info{};
        pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pool_info.queueFamilyIndex = context.queue_family();
        if (VkResult r = vkCreateCommandPool(slots.device_, &pool_info, nullptr, &slots.pool_); r != VK_SUCCESS) {
            return failure("vkCreateCommandPool", r);
        }
        VkCommandBufferAllocateInfo allocate{};
        allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        allocate.commandPool = slots.pool_;
        allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        allocate.commandBufferCount = kFramesInFlight;
        if (VkResult r = vkAllocateCommandBuffers(slots.device_, &allocate, slots.command_buffers_.data());
            r != VK_SUCCESS) {
            return failure("vkAllocateCommandBuffers", r);
        }
        VkFenceCreateInfo fence_info{};
        fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
        for (VkFence& fence : slots.fences_) {
            if (VkResult r = vkCreateFence(slots.device_, &fence_info, nullptr, &fence); r != VK_SUCCESS) {
                return failure("vkCreateFence", r);
            }
        }
        return slots;
    }
    FrameSlots(FrameSlots&& other) noexcept { *this = std::move(other); }
    FrameSlots& operator=(FrameSlots&& other) noexcept {
        std::swap(device_, other.device_);
        std::swap(queue_, other.queue_);
        std::swap(pool_, other.pool_);
        std::swap(command_buffers_, other.command_buffers_);
        std::swap(fences_, other.fences_);
        return *this;
    }
    FrameSlots(const FrameSlots&) = delete;
    FrameSlots& operator=(const FrameSlots&) = delete;
    ~FrameSlots() {
        if (!device_) return;
        (void)wait_all();
        for (VkFence fence : fences_) {
            if (fence) vkDestroyFence(device_, fence, nullptr);
        }
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    }

    // Waits for the last submission of `frame`'s slot, then begins its command buffer.
    crisp::Result<VkCommandBuffer> begin(uint64_t frame) {
        const size_t slot = frame % kFramesInFlight;
        if (VkResult r = vkWaitForFences(device_, 1, &fences_[slot], VK_TRUE, UINT64_MAX); r != VK_SUCCESS) {
            return failure("vkWaitForFences", r);
        }
        if (VkResult r = vkResetFences(device_, 1, &fences_[slot]); r != VK_SUCCESS) return failure("vkResetFences", r);
        const VkCommandBuffer cb = command_buffers_[slot];
        if (VkResult r = vkResetCommandBuffer(cb, 0); r != VK_SUCCESS) return failure("vkResetCommandBuffer", r);
        VkCommandBufferBeginInfo begin_info{};
        begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        if (VkResult r = vkBeginCommandBuffer(cb, &begin_info); r != VK_SUCCESS) {
            return failure("vkBeginCommandBuffer", r);
        }
        return cb;
    }

    // Ends `frame`'s command buffer and submits it with its slot's fence.
    crisp::Status submit(uint64_t frame) {
        const size_t slot = frame % kFramesInFlight;
        if (VkResult r = vkEndCommandBuffer(command_buffers_[slot]); r != VK_SUCCESS) {
            return failure("vkEndCommandBuffer", r);
        }
        VkSubmitInfo submit_info{};
        submit_info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        submit_info.commandBufferCount = 1;
        submit_info.pCommandBuffers = &command_buffers_[slot];
        if (VkResult r = vkQueueSubmit(queue_, 1, &submit_info, fences_[slot]); r != VK_SUCCESS) {
            return failure("vkQueueSubmit", r);
        }
        return {};
    }

    // Waits until every submitted frame has completed.
    crisp::Status wait_all() {
        if (VkResult r = vkWaitForFences(device_, kFramesInFlight, fences_.data(), VK_TRUE, UINT64_MAX);
            r != VK_SUCCESS) {
            return failure("vkWaitForFences", r);
        }
        return {};
    }

private:
    FrameSlots() = default;
    static crisp::Error failure(const char* call, VkResult r) {
        return crisp::Error{crisp::ErrorCode::vulkan, std::string(call) + " failed: " + crisp::vk_result_name(r), r};
    }
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::array<VkCommandBuffer, kFramesInFlight> command_buffers_{};
    std::array<VkFence, kFramesInFlight> fences_{};
};

// ---- Measuring

// The timed phases of a frame, in order.
enum Phase : size_t { kLayout, kDraws, kRendererRecord, kCompositorRecord, kPhaseCount };
constexpr std::array<const char*, kPhaseCount> kPhaseNames = {"begin_frame + 3 layouts", "8 draws", "renderer.record",
                                                              "compositor.record"};
constexpr std::array<const char*, kPhaseCount> kPhaseKeys = {"layout", "draws", "renderer_record", "compositor_record"};

struct Summary {
    double median = 0.0, p90 = 0.0, p99 = 0.0, max = 0.0, mean = 0.0;
};

// Nearest-rank percentiles of `values` (not empty).
Summary summarize(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const auto rank = [&](double p) {
        const auto r = static_cast<size_t>(std::ceil(p * static_cast<double>(values.size())));
        return values[std::clamp<size_t>(r, 1, values.size()) - 1];
    };
    Summary s;
    s.median = rank(0.5);
    s.p90 = rank(0.9);
    s.p99 = rank(0.99);
    s.max = values.back();
    for (double v : values) s.mean += v;
    s.mean /= static_cast<double>(values.size());
    return s;
}

struct VariantResult {
    const Variant* variant = nullptr;
    std::array<std::vector<double>, kPhaseCount> phase_us;  // per timed frame
    std::vector<double> total_us;
    std::vector<double> thread_cpu_us;                              // the same region's thread CPU time
    std::vector<double> total_us_with_work, total_us_without_work;  // by whether the frame had raster work
    // Per timed frame, summed: what the renderer and the compositor did.
    uint64_t drawn_glyphs = 0;
    uint64_t moving_glyphs = 0;
    uint64_t work_items = 0;
    uint32_t frames_with_work = 0;
    uint32_t frames_bins_reused = 0;
    uint64_t quads = 0;
    size_t label_glyphs = 0;  // glyph instances of the 8 labels in the first frame
};

// The thread and wall-clock times of one frame's phases.
struct FrameTimes {
    std::array<double, kPhaseCount> phase_us{};
    double thread_cpu_us = 0.0;
};

// A variant's renderer and the compositor of its tile path.
struct Engine {
    crisp::Renderer renderer;
    crisp::Compositor compositor;
};

struct Bench {
    const Args& args;
    crisp::HeadlessContext& context;
    const crisp::Font& font;
    FrameSlots& slots;
    const crisp::Image& target;

    Engine make_engine() const {
        crisp::RendererCreateInfo renderer_info = crisp::renderer_create_info(context);
        renderer_info.frames_in_flight = kFramesInFlight;
        auto renderer = crisp::Renderer::create(renderer_info);
        if (!renderer) fail(renderer.error().message);
        if (crisp::Status s = renderer->add_font(font); !s) fail(s.error().message);
        crisp::CompositorCreateInfo compositor_info = crisp::compositor_create_info(context);
        compositor_info.frames_in_flight = kFramesInFlight;
        auto compositor = crisp::Compositor::create(compositor_info);
        if (!compositor) fail(compositor.error().message);
        if (!compositor->supports_target_format(kTargetFormat)) fail("the device cannot store to R8G8B8A8_UNORM");
        return Engine{std::move(*renderer), std::move(*compositor)};
    }

    // The timed part of a frame: begin_frame and the changed labels' layouts, the draws, and both
    // record() calls into `cb`.
    static FrameTimes time_frame(Engine& engine, crisp::Layouter& layouter, Labels& labels,
                                 std::span<const crisp::Font* const> fonts, const crisp::TextStyle& style,
                                 bool change_strings, std::span<const crisp::DrawOptions> options,
                                 const crisp::CompositeTarget& composite_target, VkCommandBuffer cb) {
        std::array<Clock::time_point, kPhaseCount + 1> stamps;
        const double cpu_start = thread_cpu_us();
        stamps[0] = Clock::now();
        engine.renderer.begin_frame();
        if (change_strings) {
            for (size_t i : labels.counters) labels.lay_out(layouter, fonts, style, i);
        }
        stamps[1] = Clock::now();
        for (size_t i = 0; i < kLabels.size(); ++i) engine.renderer.draw(labels.laid[i].glyphs, options[i]);
        stamps[2] = Clock::now();
        if (crisp::Status s = engine.renderer.record(cb); !s) fail(s.error().message);
        stamps[3] = Clock::now();
        if (crisp::Status s = engine.compositor.record(cb, engine.renderer.drawn_frame(), composite_target); !s) {
            fail(s.error().message);
        }
        stamps[4] = Clock::now();
        FrameTimes times;
        times.thread_cpu_us = thread_cpu_us() - cpu_start;
        for (size_t p = 0; p < kPhaseCount; ++p) {
            times.phase_us[p] = std::chrono::duration<double, std::micro>(stamps[p + 1] - stamps[p]).count();
        }
        return times;
    }

    // Adds a timed frame's times and what the renderer and compositor did in it.
    static void tally(VariantResult& result, const FrameTimes& times, const Engine& engine) {
        double total = 0.0;
        for (size_t p = 0; p < kPhaseCount; ++p) {
            result.phase_us[p].push_back(times.phase_us[p]);
            total += times.phase_us[p];
        }
        result.total_us.push_back(total);
        result.thread_cpu_us.push_back(times.thread_cpu_us);
        const crisp::RendererStats& stats = engine.renderer.stats();
        (stats.work_items > 0 ? result.total_us_with_work : result.total_us_without_work).push_back(total);
        result.drawn_glyphs += stats.drawn_glyphs;
        result.moving_glyphs += stats.moving_glyphs;
        result.work_items += stats.work_items;
        result.frames_with_work += stats.work_items > 0 ? 1u : 0u;
        result.frames_bins_reused += engine.compositor.stats().bins_reused ? 1u : 0u;
        result.quads += engine.compositor.stats().quads;
    }

    // One variant: a new renderer and compositor, the labels laid out, warm-up frames, timed frames.
    VariantResult run(const Variant& variant) {
        Engine engine = make_engine();
        const crisp::Font* fonts[] = {&font};
        crisp::TextStyle style;
        style.size = args.size;
        style.color[0] = style.color[1] = style.color[2] = 0.95f;
        const VkRect2D visible{{0, 0}, {args.width, args.height}};
        const crisp::CompositeTarget composite_target{target.view(), kTargetFormat, VK_FORMAT_UNDEFINED, visible.extent,
                                                      visible};
        crisp::Layouter layouter;
        Labels labels(args.width, args.height);
        for (size_t i = 0; i < kLabels.size(); ++i) labels.lay_out(layouter, fonts, style, i);

        VariantResult result;
        result.variant = &variant;
        for (const crisp::TextLayout& l : labels.laid) result.label_glyphs += l.glyphs.size();
        for (std::vector<double>& v : result.phase_us) v.reserve(args.frames);
        result.total_us.reserve(args.frames);
        result.thread_cpu_us.reserve(args.frames);
        std::array<crisp::DrawOptions, kLabels.size()> options;
        const uint64_t frame_count = uint64_t{args.warmup} + args.frames;
        for (uint64_t frame = 0; frame < frame_count; ++frame) {
            crisp::Result<VkCommandBuffer> cb = slots.begin(frame);
            if (!cb) fail(cb.error().message);
            // The caller's side, untimed: last frame's compositing into the target before this
            // frame's, the new strings and the labels' draw options.
            crisp::vk::memory_barrier(context.functions(), *cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                      crisp::vk::kShaderAccess, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                      crisp::vk::kShaderAccess);
            if (variant.change_strings) labels.write_counters(frame);
            for (size_t i = 0; i < kLabels.size(); ++i) options[i] = draw_options(i, frame, variant.move, visible);
            const FrameTimes times = time_frame(engine, layouter, labels, fonts, style, variant.change_strings, options,
                                                composite_target, *cb);
            if (crisp::Status s = slots.submit(frame); !s) fail(s.error().message);
            if (frame >= args.warmup) tally(result, times, engine);
        }
        // The renderer and the compositor go once the GPU is done with them.
        if (crisp::Status s = slots.wait_all(); !s) fail(s.error().message);
        return result;
    }
};

// ---- Output

struct Header {
    std::string device, driver, api, cpu, build;
    double cpu_clock_read_us = 0.0;  // what one thread_cpu_us() call costs
};

// The mean cost of reading the thread CPU clock, in µs.
double thread_cpu_clock_cost_us() {
    constexpr int kReads = 10000;
    const Clock::time_point start = Clock::now();
    double sink = 0.0;
    for (int i = 0; i < kReads; ++i) sink += thread_cpu_us();
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
    return sink > 0.0 ? us / kReads : 0.0;
}

double per_frame(uint64_t sum, uint32_t frames) {
    return static_cast<double>(sum) / static_cast<double>(frames);
}

// The median as a table cell, "-" for no frames.
std::string median_cell(const std::vector<double>& values) {
    if (values.empty()) return "-";
    char cell[32];
    std::snprintf(cell, sizeof cell, "%.1f", summarize(values).median);
    return cell;
}

void print_summary_cells(std::FILE* out, const Summary& s) {
    std::fprintf(out, "%.1f | %.1f | %.1f | %.1f | %.1f |", s.median, s.p90, s.p99, s.max, s.mean);
}

void print_markdown(std::FILE* out, const Args& args, const Header& header, const std::vector<VariantResult>& results) {
    std::fprintf(out, "Device: %s, driver %s; Vulkan %s. CPU: %s, %u hardware threads. Build: %s.\n\n",
                 header.device.c_str(), header.driver.c_str(), header.api.c_str(), header.cpu.c_str(),
                 std::thread::hardware_concurrency(), header.build.c_str());
    std::fprintf(
        out,
        "Scene: 8 labels of %s at %g px (%zu glyphs), each laid out once; drawn with DrawOptions (offset, a colour, "
        "a depth, the target as the visible rect, an id per label) into a %ux%u R8G8B8A8_UNORM storage image by the "
        "tile path; %u frames in flight. Changing labels: coordinates, an FPS counter and a clock.\n",
        args.font.c_str(), static_cast<double>(args.size), results.empty() ? size_t{0} : results[0].label_glyphs,
        args.width, args.height, kFramesInFlight);
    std::fprintf(
        out,
        "Timed on the calling thread with std::chrono::steady_clock: begin_frame() through the end of "
        "compositor.record(); not timed: writing the strings, vkBeginCommandBuffer, vkEndCommandBuffer, barriers, "
        "vkQueueSubmit and fence waits. CPU time: the thread's CPU time over the same region "
        "(CLOCK_THREAD_CPUTIME_ID), which leaves out time the thread waited for a core; one reading of that clock "
        "(%.2f µs) falls in the region. Per variant a new renderer and compositor, %u warm-up frames, then %u timed "
        "frames.%s\n",
        header.cpu_clock_read_us, args.warmup, args.frames,
        args.validate ? " The validation layer was on: these times are not the library's." : "");

    std::fprintf(
        out,
        "\n| variant | median µs | p90 µs | p99 µs | max µs | mean µs | CPU time: median µs | p99 µs | max µs |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const VariantResult& r : results) {
        std::fprintf(out, "| %s: %s | ", r.variant->name, r.variant->description);
        print_summary_cells(out, summarize(r.total_us));
        const Summary cpu = summarize(r.thread_cpu_us);
        std::fprintf(out, " %.1f | %.1f | %.1f |\n", cpu.median, cpu.p99, cpu.max);
    }

    std::fprintf(out,
                 "\nWhere the time goes:\n\n| variant | phase | median µs | p90 µs | p99 µs | max µs | mean µs |\n"
                 "|---|---|---:|---:|---:|---:|---:|\n");
    for (const VariantResult& r : results) {
        for (size_t p = 0; p < kPhaseCount; ++p) {
            std::fprintf(out, "| %s | %s | ", r.variant->name, kPhaseNames[p]);
            print_summary_cells(out, summarize(r.phase_us[p]));
            std::fprintf(out, "\n");
        }
    }

    std::fprintf(out,
                 "\nWhat the renderer and the compositor did, per timed frame:\n\n"
                 "| variant | glyphs drawn | moving glyphs | frames with raster work | raster work items | "
                 "frames with bins reused | quads | median µs, frames with raster work | median µs, frames without |\n"
                 "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const VariantResult& r : results) {
        std::fprintf(out, "| %s | %.1f | %.1f | %u of %u | %.2f | %u of %u | %.1f | %s | %s |\n", r.variant->name,
                     per_frame(r.drawn_glyphs, args.frames), per_frame(r.moving_glyphs, args.frames),
                     r.frames_with_work, args.frames, per_frame(r.work_items, args.frames), r.frames_bins_reused,
                     args.frames, per_frame(r.quads, args.frames), median_cell(r.total_us_with_work).c_str(),
                     median_cell(r.total_us_without_work).c_str());
    }
}

void write_summary(crisp::JsonWriter& json, std::string_view key, const std::vector<double>& values) {
    const Summary s = summarize(values);
    json.key(key).begin_object();
    json.field("median", s.median).field("p90", s.p90).field("p99", s.p99).field("max", s.max).field("mean", s.mean);
    json.end_object();
}

void write_variant(crisp::JsonWriter& json, const Args& args, const VariantResult& r) {
    json.begin_object()
        .field("name", r.variant->name)
        .field("description", r.variant->description)
        .field("label_glyphs", r.label_glyphs);
    write_summary(json, "total_us", r.total_us);
    write_summary(json, "thread_cpu_us", r.thread_cpu_us);
    for (size_t p = 0; p < kPhaseCount; ++p) write_summary(json, std::string(kPhaseKeys[p]) + "_us", r.phase_us[p]);
    json.key("per_frame").begin_object();
    json.field("drawn_glyphs", per_frame(r.drawn_glyphs, args.frames))
        .field("moving_glyphs", per_frame(r.moving_glyphs, args.frames))
        .field("work_items", per_frame(r.work_items, args.frames))
        .field("quads", per_frame(r.quads, args.frames))
        .end_object();
    json.field("frames_with_raster_work", r.frames_with_work);
    if (!r.total_us_with_work.empty()) write_summary(json, "total_us_frames_with_raster_work", r.total_us_with_work);
    if (!r.total_us_without_work.empty()) {
        write_summary(json, "total_us_frames_without_raster_work", r.total_us_without_work);
    }
    json.field("frames_with_bins_reused", r.frames_bins_reused);
    json.key("frame_us").begin_array();
    for (const double us : r.total_us) json.value(std::round(us * 1000.0) / 1000.0);
    json.end_array().end_object();
}

void to_json(crisp::JsonWriter& json, const Args& args, const Header& header,
             const std::vector<VariantResult>& results) {
    json.begin_object()
        .field("device", header.device)
        .field("driver", header.driver)
        .field("api_version", header.api)
        .field("cpu", header.cpu)
        .field("hardware_threads", std::thread::hardware_concurrency())
        .field("thread_cpu_clock_read_us", header.cpu_clock_read_us)
        .field("build", header.build)
        .field("font", args.font)
        .field("size", args.size);
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.field("frames_in_flight", kFramesInFlight)
        .field("warmup_frames", args.warmup)
        .field("timed_frames", args.frames)
        .field("validation", args.validate);
    json.key("variants").begin_array();
    for (const VariantResult& r : results) write_variant(json, args, r);
    json.end_array().end_object();
}

// The suite's arguments: the options given, else its defaults (smaller with --quick or on a
// CPU device).
Args args_from(const crisp::bench::Session& session) {
    const crisp::bench::Options& o = session.options;
    Args args;
    if (!o.fonts.empty()) args.font = o.fonts.front();
    args.size = o.size.value_or(args.size);
    args.width = o.width.value_or(o.quick ? 256 : session.cpu_device ? 640 : args.width);
    args.height = o.height.value_or(o.quick ? 128 : session.cpu_device ? 360 : args.height);
    args.warmup = o.warmup.value_or(o.quick ? 2 : args.warmup);
    args.frames = o.frames.value_or(o.quick ? 20 : args.frames);
    args.variants = o.variants;
    args.validate = o.validate;
    return args;
}

}  // namespace

void crisp::bench::run_frame_cpu(Session& session) {
    const Args args = args_from(session);
    std::vector<const Variant*> variants;
    for (const std::string& name : args.variants) {
        const auto* found =
            std::find_if(std::begin(kVariants), std::end(kVariants), [&](const Variant& v) { return name == v.name; });
        variants.push_back(found);  // parse_options checked the names
    }
    crisp::HeadlessContext* context = session.context;
    crisp::BakeOptions bake;  // the labels are ASCII
    bake.all_glyphs = false;
    for (uint32_t c = 0x20; c < 0x7F; ++c) bake.codepoints.push_back(c);
    auto baked = crisp::bake_font_file(args.font, bake);
    if (!baked) {
        const std::string& why = baked.error().message;  // an unreadable file's names it
        ::fail(why.find(args.font) != std::string::npos ? why : crisp::cli::printable(args.font) + ": " + why);
    }
    auto font = crisp::Font::create(std::move(baked->asset), 1);
    if (!font) ::fail(crisp::cli::printable(args.font) + ": " + font.error().message);

    crisp::ImageDesc target_desc;
    target_desc.format = kTargetFormat;
    target_desc.width = args.width;
    target_desc.height = args.height;
    target_desc.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    auto target = context->create_image(target_desc);
    if (!target) ::fail(target.error().message);
    const crisp::Status to_general = context->submit_and_wait([&](VkCommandBuffer cb) {
        crisp::vk::image_barrier(context->functions(), cb, target->handle(), VK_IMAGE_LAYOUT_UNDEFINED,
                                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, crisp::vk::kShaderAccess);
    });
    if (!to_general) ::fail(to_general.error().message);
    auto slots = FrameSlots::create(*context);
    if (!slots) ::fail(slots.error().message);

    Bench bench{args, *context, *font, *slots, *target};
    std::vector<VariantResult> results;
    for (const Variant* variant : variants) {
        crisp::bench::progress("frame-cpu", std::string(variant->name) + ": " + std::to_string(args.warmup) + " + " +
                                                std::to_string(args.frames) + " frames");
        results.push_back(bench.run(*variant));
    }

    Header header;
    header.device = context->device_name();
    header.driver = context->driver_name() + " (" + context->driver_info() + ")";
    header.api = crisp::vk::version_string(context->api_version());
    header.cpu = crisp::bench::cpu_model();
    header.build = crisp::bench::build_description();
    header.cpu_clock_read_us = thread_cpu_clock_cost_us();
    print_markdown(session.md, args, header, results);
    to_json(session.json, args, header, results);
}
