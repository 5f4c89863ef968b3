// crisp-render: renders text with the GPU renderer until it converges, reads the atlas back and
// composites on the CPU into a PNG and, on request, a PFM of the text's coverage.
#include "cli.hpp"
#include "image_io.hpp"
#include "json.hpp"

#include <crisp/asset.hpp>
#include <crisp/atlas.hpp>
#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/glyph.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>
#include <crisp/vulkan_context.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_set>
#include <utility>
#include <vector>

namespace {

// Exit codes, documented in --help and docs/crisp-render.md.
enum ExitCode : int {
    kExitOk = 0,
    kExitInternal = 1,  // a bug, or glyphs the renderer could not draw
    kExitUsage = 2,     // bad command line
    kExitFont = 3,      // a font asset cannot be loaded
    kExitOutput = 4,    // an output file cannot be written
    kExitVulkan = 5,    // no usable Vulkan device, a Vulkan failure, or validation messages
    kExitLayout = 6,    // --layout is neither a preset nor a valid layout file
};

constexpr uint32_t kDefaultSamples = 512;
constexpr uint32_t kMaxCanvas = 16384;
// The default schedule reaches kMaxRendererSamples in about 1030 frames; far more means the
// renderer stopped making progress.
constexpr uint64_t kMaxFrames = 100000;
// Smallest atlas side the tool asks for; it grows to hold every glyph of the text at once.
constexpr uint32_t kMinAtlasSide = 256;
constexpr uint32_t kAtlasTexelBytes = 8;  // R16G16B16A16_UINT

constexpr const char* kUsage = R"(usage: crisp-render --font A.crisp [--font B.crisp ...] --text UTF8 --size PX
                    --origin X,Y --canvas W,H -o OUT.png [options]

Renders text with crisp's GPU rasterizer, frame after frame until every glyph holds its samples,
then reads the glyph atlas back and composites the glyphs on the CPU, in linear light.

required:
  --font FILE.crisp        a font asset (crisp-bake makes them); repeat for a fallback chain
  --text UTF8              the text; line breaks start new lines
  --size PX                pixels per em, in (0, 4096]
  --origin X,Y             pen position of the first glyph on its baseline, canvas pixels, y down;
                           fractional values are kept (quantized to 1/256 px), never rounded
  --canvas W,H             image size in pixels, each 1..16384
  -o, --output OUT.png     the composited image, 8-bit sRGB

options:
  --layout NAME|FILE.json  subpixel layout: gray, rgb, bgr, vrgb, vbgr, qd-oled, woled, pentile,
                           or a layout file (default: rgb)
  --samples N              samples per glyph texel and channel, 1..1023 (default 512)
  --color R,G,B[,A]        text colour, sRGB components in [0, 1], straight alpha (default 0,0,0,1)
  --background R,G,B[,A]   background, the same way (default 1,1,1,1); with alpha below 1 the PNG
                           has an alpha channel
  --coverage-out OUT.pfm   the text's linear coverage per channel as a PFM image
  --json                   print the report as one JSON object on stdout
  --validate               turn on the Vulkan validation layer (always on in debug builds); any
                           warning or error it reports fails the run (exit 5)
  --device NAME            use the Vulkan device whose name contains NAME
  -h, --help               this text

exit codes:
  0 success   2 usage error   3 font asset cannot be loaded   4 output not writable
  5 Vulkan unavailable or failed, or validation messages   6 bad --layout   1 internal error
)";

struct Arguments {
    std::vector<std::string> fonts;
    std::optional<std::string> text;
    std::optional<float> size;
    std::optional<std::array<float, 2>> origin;
    std::optional<std::array<uint32_t, 2>> canvas;
    std::string layout = "rgb";
    uint32_t samples = kDefaultSamples;
    std::array<float, 4> color = {0.0f, 0.0f, 0.0f, 1.0f};
    std::array<float, 4> background = {1.0f, 1.0f, 1.0f, 1.0f};
    std::string output;
    std::string coverage_output;
    bool json = false;
#ifdef NDEBUG
    bool validate = false;
#else
    bool validate = true;  // debug builds run with the validation layer on
#endif
    std::string device;
};

[[noreturn]] void usage_error(const std::string& message) {
    std::fprintf(stderr, "crisp-render: %s\n(run crisp-render --help for usage)\n", message.c_str());
    std::exit(kExitUsage);
}

[[noreturn]] void fail(int code, const std::string& message) {
    std::fprintf(stderr, "crisp-render: %s\n", message.c_str());
    std::exit(code);
}

template <class T>
T parse_number(std::string_view option, std::string_view text) {
    const std::optional<T> value = crisp::cli::parse_number<T>(text);
    if (!value) usage_error(std::string(option) + ": '" + std::string(text) + "' is not a finite number");
    return *value;
}

template <class T>
std::vector<T> parse_list(std::string_view option, std::string_view text) {
    std::vector<T> values;
    for (;;) {
        const size_t comma = text.find(',');
        values.push_back(parse_number<T>(option, text.substr(0, comma)));
        if (comma == std::string_view::npos) break;
        text.remove_prefix(comma + 1);
    }
    return values;
}

std::array<float, 4> parse_color(std::string_view option, std::string_view text) {
    const std::vector<float> values = parse_list<float>(option, text);
    if (values.size() != 3 && values.size() != 4) {
        usage_error(std::string(option) + " takes R,G,B or R,G,B,A, not '" + std::string(text) + "'");
    }
    std::array<float, 4> color = {0.0f, 0.0f, 0.0f, 1.0f};
    for (size_t i = 0; i < values.size(); ++i) {
        if (!(values[i] >= 0.0f && values[i] <= 1.0f)) {
            usage_error(std::string(option) + ": components are in [0, 1] (sRGB, straight alpha); '" +
                        std::string(text) + "' is not");
        }
        color[i] = values[i];
    }
    return color;
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments args;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        auto value = [&]() -> std::string_view {
            if (i + 1 >= argc) usage_error(std::string(arg) + " needs a value");
            return argv[++i];
        };
        if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            std::exit(kExitOk);
        } else if (arg == "--font") {
            args.fonts.emplace_back(value());
        } else if (arg == "--text") {
            args.text = std::string(value());
        } else if (arg == "--size") {
            const auto size = parse_number<float>(arg, value());
            if (!(size > 0.0f && size <= crisp::kMaxTextSize)) usage_error("--size must be in (0, 4096] pixels per em");
            args.size = size;
        } else if (arg == "--origin") {
            const std::string_view text = value();
            const std::vector<float> xy = parse_list<float>(arg, text);
            if (xy.size() != 2) usage_error("--origin takes X,Y, not '" + std::string(text) + "'");
            args.origin = std::array<float, 2>{xy[0], xy[1]};
        } else if (arg == "--canvas") {
            const std::string_view text = value();
            const std::vector<uint32_t> wh = parse_list<uint32_t>(arg, text);
            if (wh.size() != 2) usage_error("--canvas takes W,H, not '" + std::string(text) + "'");
            if (wh[0] < 1 || wh[0] > kMaxCanvas || wh[1] < 1 || wh[1] > kMaxCanvas) {
                usage_error("--canvas: width and height are each 1..16384, not '" + std::string(text) + "'");
            }
            args.canvas = std::array<uint32_t, 2>{wh[0], wh[1]};
        } else if (arg == "--layout") {
            args.layout = value();
        } else if (arg == "--samples") {
            args.samples = parse_number<uint32_t>(arg, value());
            if (args.samples < 1 || args.samples > crisp::kMaxRendererSamples) {
                usage_error("--samples must be in 1.." + std::to_string(crisp::kMaxRendererSamples));
            }
        } else if (arg == "--color") {
            args.color = parse_color(arg, value());
        } else if (arg == "--background") {
            args.background = parse_color(arg, value());
        } else if (arg == "-o" || arg == "--output") {
            args.output = value();
        } else if (arg == "--coverage-out") {
            args.coverage_output = value();
        } else if (arg == "--json") {
            args.json = true;
        } else if (arg == "--validate") {
            args.validate = true;
        } else if (arg == "--device") {
            args.device = value();
        } else {
            usage_error("unexpected argument '" + std::string(arg) + "'");
        }
    }
    if (args.fonts.empty()) usage_error("no --font given");
    if (args.fonts.size() > crisp::kMaxRendererFonts) {
        usage_error("at most " + std::to_string(crisp::kMaxRendererFonts) + " fonts, not " +
                    std::to_string(args.fonts.size()));
    }
    if (!args.text) usage_error("no --text given");
    if (!args.size) usage_error("no --size given");
    if (!args.origin) usage_error("no --origin given");
    if (!args.canvas) usage_error("no --canvas given");
    if (args.output.empty()) usage_error("no output given (-o OUT.png)");
    if (!args.coverage_output.empty() && std::filesystem::path(args.coverage_output).lexically_normal() ==
                                             std::filesystem::path(args.output).lexically_normal()) {
        usage_error("-o and --coverage-out name the same file");
    }
    return args;
}

// Refuses an output whose directory does not exist, or that is a directory, before any rendering.
void check_output_path(const std::string& path) {
    const std::filesystem::path file(path);
    std::filesystem::path directory = file.parent_path();
    if (directory.empty()) directory = ".";
    std::error_code error;
    if (!std::filesystem::is_directory(directory, error)) {
        fail(kExitOutput, "cannot write " + path + ": " + directory.string() + " is not a directory");
    }
    if (std::filesystem::is_directory(file, error)) fail(kExitOutput, "cannot write " + path + ": it is a directory");
}

// ---- JSON, by hand

std::string json_string(std::string_view s) {
    std::string out;
    crisp::json::append_string(out, s);
    return out;
}

std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", v);
    return buffer;
}

std::string json_uint(uint64_t v) {
    return std::to_string(v);
}

// ---- Rendering

int exit_code_for_vulkan(const crisp::Error& error) {
    return error.code == crisp::ErrorCode::vulkan ? kExitVulkan : kExitInternal;
}

// What the renderer's compute shader needs enabled on the device (renderer.hpp: Renderer::create).
struct DeviceRequirements {
    VkPhysicalDeviceFeatures2 features{};
};

void require_renderer_features(DeviceRequirements& requirements, crisp::HeadlessContextOptions& options) {
    requirements.features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    requirements.features.features.shaderStorageBufferArrayDynamicIndexing = VK_TRUE;
    options.required_features = &requirements.features;
    options.required_compute_subgroup_operations = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
}

// The atlas block a rect takes (see atlas.hpp): cells rounded up to powers of two per axis, then
// square or twice as tall as wide.
std::pair<uint32_t, uint32_t> block_cells(uint32_t width, uint32_t height) {
    uint32_t w = std::bit_ceil((width + crisp::kAtlasCellSize - 1) / crisp::kAtlasCellSize);
    uint32_t h = std::bit_ceil((height + crisp::kAtlasCellSize - 1) / crisp::kAtlasCellSize);
    if (w > h) h = w;
    if (h > 2 * w) w = h / 2;
    return {w, h};
}

// The side of a square atlas that holds every distinct glyph of the text at once, with room to
// spare for the allocator's alignment.
uint32_t atlas_side_for(std::span<const crisp::GlyphInstance> glyphs) {
    std::unordered_set<crisp::GlyphKey, crisp::GlyphKeyHash> keys;
    uint64_t cells = 0;
    uint32_t widest = 1, tallest = 1;
    for (const crisp::GlyphInstance& glyph : glyphs) {
        if (glyph.width == 0 || glyph.height == 0 || !keys.insert(glyph.key).second) continue;
        const auto [w, h] = block_cells(glyph.width, glyph.height);
        cells += uint64_t{w} * h;
        widest = std::max(widest, w);
        tallest = std::max(tallest, h);
    }
    uint32_t side = kMinAtlasSide;
    while (side < crisp::kAtlasMaxSize &&
           (side / crisp::kAtlasCellSize < std::max(widest, tallest) ||
            uint64_t{side / crisp::kAtlasCellSize} * (side / crisp::kAtlasCellSize) < 2 * cells)) {
        side *= 2;
    }
    return side;
}

// Glyphs whose rect misses the canvas change no pixel: they are not drawn.
bool touches_canvas(const crisp::GlyphInstance& glyph, uint32_t width, uint32_t height) {
    const int64_t x0 = glyph.x, y0 = glyph.y;
    const int64_t x1 = x0 + glyph.width, y1 = y0 + glyph.height;
    return glyph.width > 0 && glyph.height > 0 && x1 > 0 && y1 > 0 && x0 < int64_t{width} && y0 < int64_t{height};
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

struct RenderReport {
    uint64_t frames = 0;
    bool converged = false;
    std::vector<double> frame_ms;
    double render_ms = 0.0;
    double readback_ms = 0.0;
    uint32_t min_samples = 0;  // over the glyphs drawn in the last frame
    uint32_t max_samples = 0;
    crisp::RendererStats last_frame;
    uint64_t total_samples = 0;
    uint64_t total_curve_tests = 0;
    crisp::AtlasStats atlas;
    uint32_t atlas_side = 0;
    std::vector<crisp::DrawnGlyph> drawn;  // the last frame's, in paint order
    std::vector<uint16_t> texels;          // RGBA16 of every drawn glyph's rect, at texel_offset[i]
    std::vector<size_t> texel_offset;      // per drawn glyph, in uint16_t units
};

int render(crisp::HeadlessContext& context, const Arguments& args, const crisp::SubpixelLayout& layout,
           std::span<const crisp::Font> fonts, std::span<const crisp::GlyphInstance> glyphs, RenderReport& report) {
    crisp::RendererCreateInfo info;
    info.instance = context.instance();
    info.physical_device = context.physical_device();
    info.device = context.device();
    info.queue_family = context.queue_family();
    info.allocator = context.allocation_callbacks();
    info.layout = layout;
    info.atlas.max_samples = args.samples;
    for (uint32_t& samples : info.atlas.ramp) samples = std::min(samples, args.samples);
    report.atlas_side = atlas_side_for(glyphs);
    info.atlas.width = info.atlas.height = report.atlas_side;

    crisp::Result<crisp::Renderer> created = crisp::Renderer::create(info);
    if (!created) {
        std::fprintf(stderr, "crisp-render: cannot create the renderer: %s\n", created.error().message.c_str());
        return exit_code_for_vulkan(created.error());
    }
    crisp::Renderer& renderer = *created;
    for (const crisp::Font& font : fonts) {
        if (crisp::Status status = renderer.add_font(font); !status) {
            std::fprintf(stderr, "crisp-render: cannot add font %u (%s): %s\n", font.id(),
                         args.fonts[font.id() - 1].c_str(), status.error().message.c_str());
            return exit_code_for_vulkan(status.error());
        }
    }

    const auto render_start = std::chrono::steady_clock::now();
    do {
        if (report.frames == kMaxFrames) {
            std::fprintf(stderr, "crisp-render: the renderer did not converge in %llu frames\n",
                         static_cast<unsigned long long>(kMaxFrames));
            return kExitInternal;
        }
        const auto frame_start = std::chrono::steady_clock::now();
        renderer.begin_frame();
        renderer.draw(glyphs);
        crisp::Status recorded;
        const crisp::Status submitted = context.submit_and_wait(
            [&](VkCommandBuffer command_buffer) { recorded = renderer.record(command_buffer); });
        report.frame_ms.push_back(milliseconds_since(frame_start));
        ++report.frames;
        if (!recorded) {
            std::fprintf(stderr, "crisp-render: frame %llu: %s\n", static_cast<unsigned long long>(report.frames),
                         recorded.error().message.c_str());
            return exit_code_for_vulkan(recorded.error());
        }
        if (!submitted) {
            std::fprintf(stderr, "crisp-render: frame %llu: %s\n", static_cast<unsigned long long>(report.frames),
                         submitted.error().message.c_str());
            return exit_code_for_vulkan(submitted.error());
        }
        report.total_samples += renderer.stats().samples;
        report.total_curve_tests += renderer.stats().curve_tests;
    } while (!renderer.converged());
    report.render_ms = milliseconds_since(render_start);
    report.converged = true;
    report.last_frame = renderer.stats();
    report.atlas = renderer.atlas().stats();

    report.drawn.assign(renderer.drawn().begin(), renderer.drawn().end());
    std::stable_sort(report.drawn.begin(), report.drawn.end(),
                     [](const crisp::DrawnGlyph& a, const crisp::DrawnGlyph& b) {
                         return a.instance.paint_order < b.instance.paint_order;
                     });
    if (!report.drawn.empty()) {
        report.min_samples = UINT32_MAX;
        for (const crisp::DrawnGlyph& glyph : report.drawn) {
            report.min_samples = std::min(report.min_samples, glyph.samples);
            report.max_samples = std::max(report.max_samples, glyph.samples);
        }
    }
    if (report.drawn.empty()) return kExitOk;

    // Read back each atlas rect once: glyphs with equal keys share one.
    const auto readback_start = std::chrono::steady_clock::now();
    std::map<std::pair<uint32_t, uint32_t>, size_t> rect_offset;
    std::vector<VkBufferImageCopy> regions;
    size_t texel_count = 0;
    report.texel_offset.resize(report.drawn.size());
    for (size_t i = 0; i < report.drawn.size(); ++i) {
        const crisp::DrawnGlyph& glyph = report.drawn[i];
        const auto [it, inserted] = rect_offset.try_emplace({glyph.atlas_x, glyph.atlas_y}, texel_count);
        report.texel_offset[i] = it->second * 4;
        if (!inserted) continue;
        VkBufferImageCopy region{};
        region.bufferOffset = texel_count * kAtlasTexelBytes;
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageOffset = {static_cast<int32_t>(glyph.atlas_x), static_cast<int32_t>(glyph.atlas_y), 0};
        region.imageExtent = {glyph.instance.width, glyph.instance.height, 1};
        regions.push_back(region);
        texel_count += size_t{glyph.instance.width} * glyph.instance.height;
    }
    crisp::Result<crisp::Buffer> buffer = context.create_buffer(
        texel_count * kAtlasTexelBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, crisp::MemoryUsage::readback);
    if (!buffer) {
        std::fprintf(stderr, "crisp-render: cannot make the readback buffer: %s\n", buffer.error().message.c_str());
        return exit_code_for_vulkan(buffer.error());
    }
    const VkImage atlas_image = renderer.atlas_image();
    const crisp::Status copied = context.submit_and_wait([&](VkCommandBuffer command_buffer) {
        // record() made the atlas readable by transfers; this barrier also orders the copy after
        // the last frame's dispatch (an earlier submission) and moves the atlas to the layout
        // copies are fast in, and the next one returns it to GENERAL, where the renderer keeps it.
        VkImageMemoryBarrier image_barriers[2]{};
        for (VkImageMemoryBarrier& barrier : image_barriers) {
            barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
            barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.image = atlas_image;
            barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        }
        VkImageMemoryBarrier& to_copy = image_barriers[0];
        to_copy.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        to_copy.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        to_copy.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
        to_copy.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        VkImageMemoryBarrier& to_general = image_barriers[1];
        to_general.srcAccessMask = 0;  // the copy only read
        to_general.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        to_general.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        to_general.newLayout = VK_IMAGE_LAYOUT_GENERAL;
        vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &to_copy);
        vkCmdCopyImageToBuffer(command_buffer, atlas_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer->handle(),
                               static_cast<uint32_t>(regions.size()), regions.data());
        vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                             nullptr, 0, nullptr, 1, &to_general);
        VkBufferMemoryBarrier to_host{};
        to_host.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
        to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_host.buffer = buffer->handle();
        to_host.offset = 0;
        to_host.size = VK_WHOLE_SIZE;
        vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr,
                             1, &to_host, 0, nullptr);
    });
    if (!copied) {
        std::fprintf(stderr, "crisp-render: reading the atlas back: %s\n", copied.error().message.c_str());
        return exit_code_for_vulkan(copied.error());
    }
    report.texels.resize(texel_count * 4);
    std::memcpy(report.texels.data(), buffer->mapped().data(), texel_count * kAtlasTexelBytes);
    report.readback_ms = milliseconds_since(readback_start);
    return kExitOk;
}

// ---- Compositing

struct Composite {
    std::vector<float> image;  // linear, straight alpha; 3 or 4 channels
    uint32_t channels = 3;
    std::vector<float> coverage;  // linear per-channel coverage, RGB; empty unless asked for
};

Composite composite(const Arguments& args, const RenderReport& report) {
    const uint32_t width = (*args.canvas)[0], height = (*args.canvas)[1];
    const size_t pixels = size_t{width} * height;
    const float background_alpha = args.background[3];
    const bool opaque = background_alpha >= 1.0f;
    const bool want_coverage = !args.coverage_output.empty();

    // Premultiplied colour and one alpha per channel: subpixel coverage differs between channels.
    std::vector<float> colour(pixels * 3), alpha;
    float background[3];
    for (size_t c = 0; c < 3; ++c) background[c] = crisp::srgb_to_linear(args.background[c]) * background_alpha;
    for (size_t p = 0; p < pixels; ++p) std::copy(background, background + 3, &colour[p * 3]);
    if (!opaque) alpha.assign(pixels * 3, background_alpha);
    std::vector<float> uncovered;  // product of (1 - coverage) over the glyphs
    if (want_coverage) uncovered.assign(pixels * 3, 1.0f);

    for (size_t g = 0; g < report.drawn.size(); ++g) {
        const crisp::DrawnGlyph& glyph = report.drawn[g];
        const crisp::GlyphInstance& instance = glyph.instance;
        const uint16_t* texels = report.texels.data() + report.texel_offset[g];
        for (uint32_t j = 0; j < instance.height; ++j) {
            const int64_t y = int64_t{instance.y} + j;
            if (y < 0 || y >= int64_t{height}) continue;
            for (uint32_t i = 0; i < instance.width; ++i) {
                const int64_t x = int64_t{instance.x} + i;
                if (x < 0 || x >= int64_t{width}) continue;
                const uint16_t* texel = texels + (size_t{j} * instance.width + i) * 4;
                if (texel[3] == 0) continue;
                const float full = static_cast<float>(crisp::kCoverageOne) * static_cast<float>(texel[3]);
                const size_t p = (static_cast<size_t>(y) * width + static_cast<size_t>(x)) * 3;
                for (size_t c = 0; c < 3; ++c) {
                    const float covered = std::min(static_cast<float>(texel[c]) / full, 1.0f);
                    const float opacity = instance.color[3] * covered;
                    colour[p + c] = instance.color[c] * opacity + colour[p + c] * (1.0f - opacity);
                    if (!opaque) alpha[p + c] = opacity + alpha[p + c] * (1.0f - opacity);
                    if (want_coverage) uncovered[p + c] *= 1.0f - covered;
                }
            }
        }
    }

    Composite out;
    if (opaque) {
        out.image = std::move(colour);
    } else {
        // One alpha for the pixel: the largest of the channels', so no colour exceeds 1 when it
        // is un-premultiplied. Exact for the gray layout, where the three are equal.
        out.channels = 4;
        out.image.resize(pixels * 4);
        for (size_t p = 0; p < pixels; ++p) {
            const float a = std::max({alpha[p * 3], alpha[p * 3 + 1], alpha[p * 3 + 2]});
            for (size_t c = 0; c < 3; ++c) out.image[p * 4 + c] = a > 0.0f ? colour[p * 3 + c] / a : 0.0f;
            out.image[p * 4 + 3] = a;
        }
    }
    if (want_coverage) {
        out.coverage = std::move(uncovered);
        for (float& value : out.coverage) value = 1.0f - value;
    }
    return out;
}

// ---- Report

struct Summary {
    const Arguments* args = nullptr;
    const crisp::HeadlessContext* context = nullptr;
    const crisp::SubpixelLayout* layout = nullptr;
    const crisp::TextLayout* text = nullptr;
    const RenderReport* render = nullptr;
    uint32_t culled_glyphs = 0;
    double composite_ms = 0.0;
    double write_ms = 0.0;
    double total_ms = 0.0;
    crisp::ValidationMessages validation;
};

void print_json(const Summary& s) {
    const Arguments& args = *s.args;
    const RenderReport& r = *s.render;
    std::string frame_ms = "[";
    for (size_t i = 0; i < r.frame_ms.size(); ++i) frame_ms += (i ? ", " : "") + json_number(r.frame_ms[i]);
    frame_ms += "]";
    double frame_total = 0.0;
    for (const double ms : r.frame_ms) frame_total += ms;
    const crisp::RendererStats& last = r.last_frame;
    std::string out = "{";
    out += "\"frames\": " + json_uint(r.frames);
    out += ", \"converged\": " + std::string(r.converged ? "true" : "false");
    out += ", \"samples\": {\"target\": " + json_uint(args.samples) + ", \"min\": " + json_uint(r.min_samples) +
           ", \"max\": " + json_uint(r.max_samples) + "}";
    out += ", \"glyphs\": {\"laid_out\": " + json_uint(s.text->glyphs.size()) +
           ", \"culled\": " + json_uint(s.culled_glyphs) + ", \"drawn\": " + json_uint(last.drawn_glyphs) +
           ", \"skipped\": " + json_uint(last.skipped_glyphs) + ", \"failed\": " + json_uint(last.failed_glyphs) +
           ", \"unknown_fonts\": " + json_uint(last.unknown_fonts) +
           ", \"missing\": " + json_uint(s.text->missing_glyphs) + ", \"blank\": " + json_uint(s.text->blank_glyphs) +
           ", \"out_of_range\": " + json_uint(s.text->out_of_range_glyphs) + "}";
    out += ", \"total_samples\": " + json_uint(r.total_samples);
    out += ", \"total_curve_tests\": " + json_uint(r.total_curve_tests);
    out += ", \"timings\": {\"frame_ms\": " + frame_ms + ", \"frames_ms\": " + json_number(frame_total) +
           ", \"mean_frame_ms\": " + json_number(r.frames ? frame_total / static_cast<double>(r.frames) : 0.0) +
           ", \"readback_ms\": " + json_number(r.readback_ms) + ", \"composite_ms\": " + json_number(s.composite_ms) +
           ", \"write_ms\": " + json_number(s.write_ms) + ", \"total_ms\": " + json_number(s.total_ms) + "}";
    out += ", \"atlas\": {\"width\": " + json_uint(r.atlas_side) + ", \"height\": " + json_uint(r.atlas_side) +
           ", \"occupancy\": " + json_number(static_cast<double>(r.atlas.occupancy)) +
           ", \"resident\": " + json_uint(r.atlas.resident_glyphs) +
           ", \"allocations\": " + json_uint(r.atlas.total.allocations) +
           ", \"evictions\": " + json_uint(r.atlas.total.evictions) +
           ", \"failed_full\": " + json_uint(r.atlas.total.failed_full) +
           ", \"failed_too_large\": " + json_uint(r.atlas.total.failed_too_large) +
           ", \"budget_overruns\": " + json_uint(r.atlas.total.budget_overruns) + "}";
    out += ", \"device\": {\"name\": " + json_string(s.context->device_name()) +
           ", \"driver\": " + json_string(s.context->driver_name()) +
           ", \"driver_info\": " + json_string(s.context->driver_info()) + "}";
    out += ", \"layout\": " + json_string(s.layout->name);
    out += ", \"size\": " + json_number(static_cast<double>(*args.size));
    out += ", \"origin\": [" + json_number(static_cast<double>((*args.origin)[0])) + ", " +
           json_number(static_cast<double>((*args.origin)[1])) + "]";
    out += ", \"canvas\": {\"width\": " + json_uint((*args.canvas)[0]) +
           ", \"height\": " + json_uint((*args.canvas)[1]) + "}";
    out += ", \"outputs\": {\"png\": " + json_string(args.output) +
           ", \"coverage\": " + (args.coverage_output.empty() ? "null" : json_string(args.coverage_output)) + "}";
    if (args.validate) {
        out += ", \"validation\": {\"warnings\": " + json_uint(s.validation.warnings) +
               ", \"errors\": " + json_uint(s.validation.errors) + "}";
    }
    out += "}\n";
    std::fputs(out.c_str(), stdout);
}

void print_human(const Summary& s) {
    const Arguments& args = *s.args;
    const RenderReport& r = *s.render;
    double frame_total = 0.0;
    for (const double ms : r.frame_ms) frame_total += ms;
    std::printf("%s (%ux%u)%s%s\n", args.output.c_str(), (*args.canvas)[0], (*args.canvas)[1],
                args.coverage_output.empty() ? "" : ", coverage in ", args.coverage_output.c_str());
    std::printf("  device   %s (%s, %s)\n", s.context->device_name().c_str(), s.context->driver_name().c_str(),
                s.context->driver_info().c_str());
    std::printf("  layout   %s, %u samples per texel and channel\n", s.layout->name.c_str(), args.samples);
    std::printf("  glyphs   %u drawn, %zu laid out (%u outside the canvas), %u missing, %u failed\n",
                r.last_frame.drawn_glyphs, s.text->glyphs.size(), s.culled_glyphs, s.text->missing_glyphs,
                r.last_frame.failed_glyphs);
    std::printf("  frames   %llu, %.1f ms (%.2f ms per frame); readback %.1f ms, composite %.1f ms\n",
                static_cast<unsigned long long>(r.frames), frame_total,
                r.frames ? frame_total / static_cast<double>(r.frames) : 0.0, r.readback_ms, s.composite_ms);
    std::printf("  atlas    %ux%u, %.1f%% occupied, %u resident, %llu allocations, %llu evictions\n", r.atlas_side,
                r.atlas_side, 100.0 * static_cast<double>(r.atlas.occupancy), r.atlas.resident_glyphs,
                static_cast<unsigned long long>(r.atlas.total.allocations),
                static_cast<unsigned long long>(r.atlas.total.evictions));
}

int run(const Arguments& args) {
    const auto start = std::chrono::steady_clock::now();
    check_output_path(args.output);
    if (!args.coverage_output.empty()) check_output_path(args.coverage_output);

    crisp::Result<crisp::SubpixelLayout> layout = crisp::resolve_subpixel_layout(args.layout);
    if (!layout) fail(kExitLayout, "--layout " + args.layout + ": " + layout.error().message);

    std::vector<crisp::Font> fonts;
    fonts.reserve(args.fonts.size());
    for (size_t i = 0; i < args.fonts.size(); ++i) {
        crisp::Result<crisp::FontAsset> asset = crisp::load_asset_file(args.fonts[i]);
        if (!asset) fail(kExitFont, args.fonts[i] + ": " + asset.error().message);
        crisp::Result<crisp::Font> font = crisp::Font::create(std::move(*asset), static_cast<crisp::FontId>(i + 1));
        if (!font) fail(kExitFont, args.fonts[i] + ": " + font.error().message);
        fonts.push_back(std::move(*font));
    }
    std::vector<const crisp::Font*> font_chain;
    for (const crisp::Font& font : fonts) font_chain.push_back(&font);

    crisp::TextStyle style;
    style.size = *args.size;
    std::copy(args.color.begin(), args.color.end(), style.color);
    crisp::LayoutOptions options;
    options.origin_x = (*args.origin)[0];
    options.origin_y = (*args.origin)[1];
    crisp::TextLayout text;
    crisp::Layouter layouter;
    if (crisp::Status status = layouter.layout(font_chain, *args.text, style, options, text); !status) {
        fail(status.error().code == crisp::ErrorCode::invalid_argument ? kExitUsage : kExitInternal,
             "cannot lay out the text: " + status.error().message);
    }
    const uint32_t width = (*args.canvas)[0], height = (*args.canvas)[1];
    std::vector<crisp::GlyphInstance> glyphs;
    for (const crisp::GlyphInstance& glyph : text.glyphs) {
        if (touches_canvas(glyph, width, height)) glyphs.push_back(glyph);
    }

    crisp::HeadlessContextOptions context_options;
    context_options.validation = args.validate;
    context_options.device_name_contains = args.device;
    DeviceRequirements requirements;
    require_renderer_features(requirements, context_options);
    crisp::Result<crisp::HeadlessContext> context = crisp::HeadlessContext::create(context_options);
    if (!context) fail(exit_code_for_vulkan(context.error()), "Vulkan: " + context.error().message);

    RenderReport report;
    if (const int code = render(*context, args, *layout, fonts, glyphs, report); code != kExitOk) return code;
    // The renderer is gone: every message the validation layer had for it has arrived.
    Summary summary;
    summary.validation = context->validation_messages();

    const auto composite_start = std::chrono::steady_clock::now();
    const Composite image = composite(args, report);
    summary.composite_ms = milliseconds_since(composite_start);
    report.texels = {};

    const auto write_start = std::chrono::steady_clock::now();
    if (crisp::Status status = crisp::write_png_srgb8(args.output, width, height, image.channels, image.image);
        !status) {
        fail(status.error().code == crisp::ErrorCode::io ? kExitOutput : kExitInternal, status.error().message);
    }
    if (!args.coverage_output.empty()) {
        if (crisp::Status status = crisp::write_pfm(args.coverage_output, width, height, image.coverage); !status) {
            fail(status.error().code == crisp::ErrorCode::io ? kExitOutput : kExitInternal, status.error().message);
        }
    }
    summary.write_ms = milliseconds_since(write_start);
    summary.total_ms = milliseconds_since(start);

    summary.args = &args;
    summary.context = &*context;
    summary.layout = &*layout;
    summary.text = &text;
    summary.render = &report;
    summary.culled_glyphs = static_cast<uint32_t>(text.glyphs.size() - glyphs.size());
    if (args.json) {
        print_json(summary);
    } else {
        print_human(summary);
    }

    int code = kExitOk;
    if (report.last_frame.failed_glyphs > 0 || report.last_frame.unknown_fonts > 0) {
        std::fprintf(stderr,
                     "crisp-render: %u glyphs could not be drawn (atlas full or glyph too large), %u had no font; "
                     "the image lacks them\n",
                     report.last_frame.failed_glyphs, report.last_frame.unknown_fonts);
        code = kExitInternal;
    }
    const crisp::ValidationMessages& validation = summary.validation;
    if (validation.warnings + validation.errors > 0) {
        std::fprintf(stderr, "crisp-render: the validation layer reported %u errors and %u warnings:\n",
                     validation.errors, validation.warnings);
        for (const std::string& message : validation.recent) std::fprintf(stderr, "  %s\n", message.c_str());
        code = kExitVulkan;
    }
    return code;
}

}  // namespace

int main(int argc, char** argv) {
    const Arguments args = parse_arguments(argc, argv);
    try {
        return run(args);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "crisp-render: out of memory\n");
        return kExitInternal;
    }
}
