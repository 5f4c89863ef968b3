// The tile path (Compositor::record) and the draw path (Compositor::record_draw) on lavapipe with
// validation and synchronization validation on: every target format against a CPU computation
// over a non-uniform background, per channel; bit-identical images for shuffled submission;
// coplanar ties by paint order; overflowing tiles taking the layered way; the caller's rect.
#include "composite_fixture.hpp"
#include "gpu_tools.hpp"
#include "headless_context.hpp"
#include "shared.h"

#include <crisp/compositor.hpp>
#include <crisp/layout.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace crisp {
namespace {

using namespace compositing_test;
using Rgba = std::array<float, 4>;

// ---- Texel encodings of the target formats -----------------------------------------------------

float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linear_to_srgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

uint16_t float_to_half(float value) {
    // Round to nearest even through the float's bits; the test values are finite and in [0, 1].
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    const uint32_t sign = (bits >> 16) & 0x8000u;
    const int exponent = static_cast<int>((bits >> 23) & 0xFF) - 127 + 15;
    uint32_t mantissa = bits & 0x7FFFFFu;
    if (exponent <= 0) {
        if (exponent < -10) return static_cast<uint16_t>(sign);
        mantissa |= 0x800000u;
        const int shift = 14 - exponent;
        uint32_t half = mantissa >> shift;
        const uint32_t rest = mantissa & ((1u << shift) - 1), mid = 1u << (shift - 1);
        if (rest > mid || (rest == mid && (half & 1u))) ++half;
        return static_cast<uint16_t>(sign | half);
    }
    uint32_t half = (static_cast<uint32_t>(exponent) << 10) | (mantissa >> 13);
    const uint32_t rest = mantissa & 0x1FFFu;
    if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;
    return static_cast<uint16_t>(sign | half);
}

float half_to_float(uint16_t half) {
    const uint32_t sign = (half & 0x8000u) << 16;
    const uint32_t exponent = (half >> 10) & 0x1Fu, mantissa = half & 0x3FFu;
    if (exponent == 0) return std::ldexp(static_cast<float>(mantissa), -24) * (sign ? -1.0f : 1.0f);
    return std::bit_cast<float>(sign | ((exponent - 15 + 127) << 23) | (mantissa << 13));
}

bool is_8bit(VkFormat format) {
    return format == VK_FORMAT_R8G8B8A8_UNORM || format == VK_FORMAT_B8G8R8A8_UNORM ||
           format == VK_FORMAT_R8G8B8A8_SRGB || format == VK_FORMAT_B8G8R8A8_SRGB;
}
bool is_bgra(VkFormat format) {
    return format == VK_FORMAT_B8G8R8A8_UNORM || format == VK_FORMAT_B8G8R8A8_SRGB;
}

// Linear RGBA (alpha as is) to the bytes of one texel; 8-bit formats hold sRGB colour.
void encode(VkFormat format, const Rgba& linear, std::byte* out) {
    if (is_8bit(format)) {
        uint8_t texel[4];
        for (size_t c = 0; c < 4; ++c) {
            const float v = c < 3 ? linear_to_srgb(linear[c]) : std::clamp(linear[c], 0.0f, 1.0f);
            texel[c] = static_cast<uint8_t>(std::lround(v * 255.0f));
        }
        if (is_bgra(format)) std::swap(texel[0], texel[2]);
        std::memcpy(out, texel, 4);
    } else if (format == VK_FORMAT_R16G16B16A16_SFLOAT) {
        uint16_t texel[4];
        for (size_t c = 0; c < 4; ++c) texel[c] = float_to_half(linear[c]);
        std::memcpy(out, texel, 8);
    } else {
        std::memcpy(out, linear.data(), 16);
    }
}

Rgba decode(VkFormat format, const std::byte* in) {
    Rgba linear{};
    if (is_8bit(format)) {
        uint8_t texel[4];
        std::memcpy(texel, in, 4);
        if (is_bgra(format)) std::swap(texel[0], texel[2]);
        for (int c = 0; c < 4; ++c) {
            const float v = static_cast<float>(texel[c]) / 255.0f;
            linear[static_cast<size_t>(c)] = c < 3 ? srgb_to_linear(v) : v;
        }
    } else if (format == VK_FORMAT_R16G16B16A16_SFLOAT) {
        uint16_t texel[4];
        std::memcpy(texel, in, 8);
        for (int c = 0; c < 4; ++c) linear[static_cast<size_t>(c)] = half_to_float(texel[c]);
    } else {
        std::memcpy(linear.data(), in, 16);
    }
    return linear;
}

// ---- Targets -----------------------------------------------------------------------------------

// A non-uniform scene behind the text: a colour ramp across, another down, diagonal stripes in
// blue and a checkered alpha.
Rgba backdrop(uint32_t x, uint32_t y, uint32_t width, uint32_t height) {
    const float u = static_cast<float>(x) / static_cast<float>(width - 1);
    const float v = static_cast<float>(y) / static_cast<float>(height - 1);
    const float stripe = ((x + 2 * y) / 5) % 2 == 0 ? 0.85f : 0.15f;
    return {0.1f + 0.8f * u, 0.9f - 0.7f * v, stripe, (x + y) % 2 == 0 ? 1.0f : 0.6f};
}

struct Target {
    Image image;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkFormat view_format = VK_FORMAT_UNDEFINED;  // the view's, where it differs
    uint32_t width = 0, height = 0;
    std::vector<std::byte> initial;  // the backdrop as uploaded
};

Target make_target(VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage,
                   VkFormat view_format = VK_FORMAT_UNDEFINED) {
    HeadlessContext& context = *fixture().context;
    Target t;
    t.format = format;
    t.view_format = view_format;
    t.width = width;
    t.height = height;
    auto image =
        context.create_image({format, width, height,
                              usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, view_format});
    EXPECT_TRUE(image) << (image ? "" : image.error().message);
    if (!image) return t;
    t.image = std::move(*image);
    const uint32_t texel = format_texel_size(format);
    t.initial.resize(size_t{width} * height * texel);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            encode(format, backdrop(x, y, width, height), &t.initial[(size_t{y} * width + x) * texel]);
        }
    }
    EXPECT_TRUE(context.upload(t.image, t.initial, VK_IMAGE_LAYOUT_GENERAL));
    return t;
}

std::vector<std::byte> read_target(const Target& t) {
    auto bytes = fixture().context->read_image(t.image, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_TRUE(bytes);
    return bytes ? *bytes : std::vector<std::byte>{};
}

CompositorCreateInfo tile_info(uint32_t frames_in_flight = 2) {
    Fixture& f = fixture();
    CompositorCreateInfo info = compositor_create_info(*f.context);
    info.frames_in_flight = frames_in_flight;
    return info;
}

// Composites `glyphs` into the target with the tile path, rect at `origin` with the scene's size.
void composite_tiles(Compositor& compositor, const Scene& scene, std::span<const DrawnGlyph> glyphs, Target& t,
                     VkOffset2D origin = {0, 0}) {
    CompositeTarget target;
    target.view = t.image.view();
    target.format = t.format;
    target.view_format = t.view_format;
    target.extent = {t.width, t.height};
    target.rect = {origin, {kWidth, kHeight}};
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) {
        const Status s = compositor.record(cb, scene.renderer->drawn_frame().with_glyphs(glyphs), target);
        EXPECT_TRUE(s) << (s ? "" : s.error().message);
    }));
}

// Draws `glyphs` into the target inside a dynamic-rendering pass that loads what it holds.
void composite_draw(Compositor& compositor, const Scene& scene, std::span<const DrawnGlyph> glyphs, Target& t) {
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) {
        tools::begin_rendering_over(cb, t.image.view(), {{0, 0}, {t.width, t.height}});
        const Status s =
            compositor.record_draw(cb, scene.renderer->drawn_frame().with_glyphs(glyphs), {{0, 0}, {kWidth, kHeight}});
        EXPECT_TRUE(s) << (s ? "" : s.error().message);
        vkCmdEndRendering(cb);
    }));
}

// The CPU computation: each pixel's fragments front to back (depth ascending, later paint order
// in front) in double precision over the backdrop as stored, per channel; alpha is "over" with
// each fragment's largest opacity: 1 - (1 - a) * prod(1 - max o).
// Also returns how many fragments each pixel had.
std::vector<Rgba> expected_image(const Scene& scene, const Target& t, VkOffset2D origin, std::vector<size_t>* counts) {
    const uint32_t texel = format_texel_size(t.format);
    std::vector<Rgba> out(size_t{t.width} * t.height);
    if (counts) counts->assign(out.size(), 0);
    for (uint32_t y = 0; y < t.height; ++y) {
        for (uint32_t x = 0; x < t.width; ++x) {
            const size_t at = size_t{y} * t.width + x;
            const Rgba back = decode(t.format, &t.initial[at * texel]);
            out[at] = back;
            const int64_t sx = int64_t{x} - origin.x, sy = int64_t{y} - origin.y;
            if (sx < 0 || sy < 0 || sx >= kWidth || sy >= kHeight) continue;
            std::vector<oit::Fragment> list = scene.pixels[static_cast<size_t>(sy) * kWidth + static_cast<size_t>(sx)];
            std::stable_sort(list.begin(), list.end(), [](const oit::Fragment& a, const oit::Fragment& b) {
                return a.depth != b.depth ? a.depth < b.depth : a.paint_order > b.paint_order;
            });
            if (counts) (*counts)[at] = list.size();
            if (list.empty()) continue;
            double light[3] = {}, transmittance[3] = {1, 1, 1}, coverage_transmittance = 1.0;
            for (const oit::Fragment& f : list) {
                for (int c = 0; c < 3; ++c) {
                    light[c] += transmittance[c] * double{f.light[c]};
                    transmittance[c] *= double{f.transmittance[c]};
                }
                coverage_transmittance *=
                    double{std::min({f.transmittance[0], f.transmittance[1], f.transmittance[2]})};
            }
            for (size_t c = 0; c < 3; ++c)
                out[at][c] = static_cast<float>(light[c] + transmittance[c] * double{back[c]});
            out[at][3] = static_cast<float>(1.0 - (1.0 - double{back[3]}) * coverage_transmittance);
        }
    }
    return out;
}

// The largest difference between the image and the expectation: in 8-bit codes of the stored
// encoding for 8-bit formats, in linear units otherwise.
double worst_difference(const Target& t, const std::vector<std::byte>& bytes, const std::vector<Rgba>& expected) {
    const uint32_t texel = format_texel_size(t.format);
    double worst = 0.0;
    for (size_t i = 0; i < expected.size(); ++i) {
        const Rgba got = decode(t.format, &bytes[i * texel]);
        for (size_t c = 0; c < 4; ++c) {
            double d = std::abs(double{got[c]} - double{expected[i][c]});
            if (is_8bit(t.format)) {
                const auto code = [&](float v) {
                    return double{c < 3 ? linear_to_srgb(v) : std::clamp(v, 0.0f, 1.0f)} * 255.0;
                };
                d = std::abs(code(got[c]) - code(expected[i][c]));
            }
            worst = std::max(worst, d);
        }
    }
    return worst;
}

// The tolerance of a format: one code of 8 bits; half a unit in the last place of a half near 1
// plus the walk's early exit; float: the early exit (T below 2^-16 stops it).
double tolerance(VkFormat format) {
    if (is_8bit(format)) return 1.0;
    if (format == VK_FORMAT_R16G16B16A16_SFLOAT) return 1.0 / 1024.0;
    return 4e-5;
}

std::vector<TextRun> dense_runs(float alpha) {
    std::vector<TextRun> runs = overlapping_runs(alpha);
    const std::vector<TextRun> more = {
        {"fonts@&", 0.3f, 17.6f, {0.8f, 0.7f, 0.1f, alpha}, 0.5f},
        {"Hamburgefo", -2.1f, 27.9f, {0.5f, 0.1f, 0.6f, alpha}, 0.1f},
        {"stivHam", 5.2f, 31.3f, {0.1f, 0.5f, 0.5f, alpha}, 0.7f},
    };
    runs.insert(runs.end(), more.begin(), more.end());
    return runs;
}

// Image and view formats: B8G8R8A8 through an R8G8B8A8 view of a MUTABLE_FORMAT image (lavapipe has
// no shaderStorageImageReadWithoutFormat for a B8G8R8A8 view).
struct TileFormat {
    VkFormat image, view;
};
constexpr TileFormat kTileFormats[] = {
    {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_UNDEFINED},
    {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM},
    {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_UNDEFINED},
    {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_UNDEFINED},
};
constexpr VkFormat kDrawFormats[] = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R16G16B16A16_SFLOAT,
                                     VK_FORMAT_R32G32B32A32_SFLOAT};

// ---- Tests -------------------------------------------------------------------------------------

TEST(TileCompositor, EveryFormatMatchesTheCpuComputationPerChannel) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    auto compositor = Compositor::create(tile_info());
    ASSERT_TRUE(compositor) << compositor.error().message;
    for (const TileFormat& tile_format : kTileFormats) {
        const VkFormat format = tile_format.image;
        SCOPED_TRACE("VkFormat " + std::to_string(format) + " view " + std::to_string(tile_format.view));
        ASSERT_TRUE(compositor->supports_target_format(format, tile_format.view));
        Target t = make_target(format, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT, tile_format.view);
        composite_tiles(*compositor, scene, scene.drawn, t);
        const std::vector<std::byte> bytes = read_target(t);
        EXPECT_LE(worst_difference(t, bytes, expected_image(scene, t, {0, 0}, nullptr)), tolerance(format));
        // Pixels without glyphs are never written: the backdrop's bytes stay.
        const uint32_t texel = format_texel_size(format);
        size_t untouched = 0, differing_channels = 0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            if (!scene.pixels[p].empty()) {
                const oit::Fragment& f = scene.pixels[p][0];
                if (f.transmittance[0] != f.transmittance[1] || f.transmittance[1] != f.transmittance[2]) {
                    ++differing_channels;
                }
                continue;
            }
            EXPECT_EQ(std::memcmp(&bytes[p * texel], &t.initial[p * texel], texel), 0) << "pixel " << p;
            ++untouched;
        }
        EXPECT_GT(untouched, 0u);
        EXPECT_GT(differing_channels, 0u);  // subpixel coverage: the channels do differ
    }
    const CompositorStats& stats = compositor->stats();
    EXPECT_EQ(stats.mode, CompositeMode::tiled);
    EXPECT_GT(stats.quads, 0u);  // the glyphs that reach the rect
    EXPECT_LE(stats.quads, scene.drawn.size());
    EXPECT_TRUE(stats.measured);
    EXPECT_GT(stats.busy_tiles, 0u);
    EXPECT_EQ(stats.exact_tiles, stats.busy_tiles);  // every list fits in workgroup memory
    EXPECT_EQ(stats.layered_tiles, 0u);
    EXPECT_EQ(stats.max_overlap, max_overlap(scene));
    expect_no_validation_messages();
}

TEST(TileCompositor, DrawPathMatchesTheCpuComputationPerChannel) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    for (VkFormat format : kDrawFormats) {
        SCOPED_TRACE("VkFormat " + std::to_string(format));
        CompositorCreateInfo info = tile_info();
        info.draw_format = format;
        auto compositor = Compositor::create(info);
        ASSERT_TRUE(compositor) << compositor.error().message;
        Target t = make_target(format, kWidth, kHeight, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
        composite_draw(*compositor, scene, scene.drawn, t);
        // Each blend rounds to the attachment: a code per overlapping layer on 8-bit targets.
        const double allowed = is_8bit(format) ? static_cast<double>(max_overlap(scene)) : tolerance(format);
        EXPECT_LE(worst_difference(t, read_target(t), expected_image(scene, t, {0, 0}, nullptr)), allowed);
    }
    expect_no_validation_messages();
}

// A depth attachment of the test's own (D32_SFLOAT), in DEPTH_ATTACHMENT_OPTIMAL after create().
struct DepthImage {
    VkDevice device = VK_NULL_HANDLE;
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    ~DepthImage() {
        if (view) vkDestroyImageView(device, view, nullptr);
        if (image) vkDestroyImage(device, image, nullptr);
        if (memory) vkFreeMemory(device, memory, nullptr);
    }
    bool create(HeadlessContext& context, uint32_t width, uint32_t height) {
        device = context.device();
        VkImageCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = VK_FORMAT_D32_SFLOAT;
        info.extent = {width, height, 1};
        info.mipLevels = info.arrayLayers = 1;
        info.samples = VK_SAMPLE_COUNT_1_BIT;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
        if (vkCreateImage(device, &info, nullptr, &image) != VK_SUCCESS) return false;
        VkMemoryRequirements needs{};
        vkGetImageMemoryRequirements(device, image, &needs);
        VkPhysicalDeviceMemoryProperties memory_properties{};
        vkGetPhysicalDeviceMemoryProperties(context.physical_device(), &memory_properties);
        VkMemoryAllocateInfo allocate{};
        allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        allocate.allocationSize = needs.size;
        allocate.memoryTypeIndex = static_cast<uint32_t>(std::countr_zero(needs.memoryTypeBits));
        if (vkAllocateMemory(device, &allocate, nullptr, &memory) != VK_SUCCESS) return false;
        if (vkBindImageMemory(device, image, memory, 0) != VK_SUCCESS) return false;
        VkImageViewCreateInfo view_info{};
        view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
        view_info.image = image;
        view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view_info.format = info.format;
        view_info.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
        if (vkCreateImageView(device, &view_info, nullptr, &view) != VK_SUCCESS) return false;
        return static_cast<bool>(context.submit_and_wait([&](VkCommandBuffer cb) {
            VkImageMemoryBarrier barrier{};
            barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
            barrier.dstAccessMask =
                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
            barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            barrier.newLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
            barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            barrier.image = image;
            barrier.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
            vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, 0,
                                 0, nullptr, 0, nullptr, 1, &barrier);
        }));
    }
};

// World-space text among the caller's geometry: with draw_depth_format, glyphs behind the
// depth attachment's surface are hidden and the others drawn as without it, bit for bit.
TEST(TileCompositor, DrawPathTestsGlyphsAgainstTheCallersDepth) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
    constexpr float kWall = 0.45f;  // the surface's depth over the left half
    std::vector<DrawnGlyph> nearer;
    for (const DrawnGlyph& g : scene.drawn) {
        if (g.instance.depth <= kWall) nearer.push_back(g);
    }
    ASSERT_FALSE(nearer.empty());
    ASSERT_LT(nearer.size(), scene.drawn.size());
    CompositorCreateInfo plain_info = tile_info();
    plain_info.draw_format = kFormat;
    auto plain = Compositor::create(plain_info);
    ASSERT_TRUE(plain) << plain.error().message;
    CompositorCreateInfo depth_info = plain_info;
    depth_info.draw_depth_format = VK_FORMAT_D32_SFLOAT;
    auto tested = Compositor::create(depth_info);
    ASSERT_TRUE(tested) << tested.error().message;

    Target all = make_target(kFormat, kWidth, kHeight, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    composite_draw(*plain, scene, scene.drawn, all);
    Target near_only = make_target(kFormat, kWidth, kHeight, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    composite_draw(*plain, scene, nearer, near_only);
    Target walled = make_target(kFormat, kWidth, kHeight, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    DepthImage depth;
    ASSERT_TRUE(depth.create(*fixture().context, kWidth, kHeight));
    const uint32_t half = kWidth / 2;
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) {
        VkRenderingAttachmentInfo color{};
        color.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        color.imageView = walled.image.view();
        color.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
        color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
        color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        VkRenderingAttachmentInfo depth_attachment{};
        depth_attachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        depth_attachment.imageView = depth.view;
        depth_attachment.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
        depth_attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth_attachment.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth_attachment.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo rendering{};
        rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
        rendering.renderArea = {{0, 0}, {kWidth, kHeight}};
        rendering.layerCount = 1;
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachments = &color;
        rendering.pDepthAttachment = &depth_attachment;
        vkCmdBeginRendering(cb, &rendering);
        // The wall: the left half's depth.
        VkClearAttachment clear{};
        clear.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        clear.clearValue.depthStencil = {kWall, 0};
        const VkClearRect rect{{{0, 0}, {half, kHeight}}, 0, 1};
        vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
        const Status s = tested->record_draw(cb, scene.renderer->drawn_frame().with_glyphs(scene.drawn),
                                             {{0, 0}, {kWidth, kHeight}});
        EXPECT_TRUE(s) << (s ? "" : s.error().message);
        vkCmdEndRendering(cb);
    }));
    const std::vector<std::byte> got = read_target(walled), want_left = read_target(near_only),
                                 want_right = read_target(all);
    const size_t row = size_t{kWidth} * format_texel_size(kFormat), split = size_t{half} * format_texel_size(kFormat);
    size_t hidden = 0;  // left-half texels where the wall hid something
    for (uint32_t y = 0; y < kHeight; ++y) {
        const size_t at = y * row;
        EXPECT_EQ(std::memcmp(&got[at], &want_left[at], split), 0) << "row " << y << ", left of the wall's edge";
        EXPECT_EQ(std::memcmp(&got[at + split], &want_right[at + split], row - split), 0) << "row " << y;
        hidden += std::memcmp(&want_left[at], &want_right[at], split) != 0;
    }
    EXPECT_GT(hidden, 0u);  // the wall did hide glyphs
    // A format that cannot be a depth attachment is refused.
    depth_info.draw_depth_format = VK_FORMAT_R8G8B8A8_UNORM;
    EXPECT_FALSE(Compositor::create(depth_info));
    expect_no_validation_messages();
}

// Every target format of both paths: the image does not depend on the submission order.
TEST(TileCompositor, ShuffledSubmissionGivesBitIdenticalImages) {
    const Scene scene = render_scene(overlapping_runs(0.6f));
    std::mt19937 random(7);
    std::vector<std::vector<DrawnGlyph>> orders(3, scene.drawn);
    for (std::vector<DrawnGlyph>& order : orders) std::shuffle(order.begin(), order.end(), random);
    auto tiles = Compositor::create(tile_info());
    ASSERT_TRUE(tiles);
    for (const TileFormat& format : kTileFormats) {
        auto image = [&](std::span<const DrawnGlyph> glyphs) {
            Target t = make_target(format.image, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT, format.view);
            composite_tiles(*tiles, scene, glyphs, t);
            return read_target(t);
        };
        const std::vector<std::byte> first = image(scene.drawn);
        for (const std::vector<DrawnGlyph>& order : orders) {
            EXPECT_EQ(image(order), first) << "tile path, VkFormat " << format.image;
        }
    }
    for (VkFormat format : kDrawFormats) {
        CompositorCreateInfo info = tile_info();
        info.draw_format = format;
        auto draw = Compositor::create(info);
        ASSERT_TRUE(draw);
        auto image = [&](std::span<const DrawnGlyph> glyphs) {
            Target t = make_target(format, kWidth, kHeight, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
            composite_draw(*draw, scene, glyphs, t);
            return read_target(t);
        };
        const std::vector<std::byte> first = image(scene.drawn);
        for (const std::vector<DrawnGlyph>& order : orders) {
            EXPECT_EQ(image(order), first) << "draw path, VkFormat " << format;
        }
    }
    expect_no_validation_messages();
}

// Two runs on one plane over each other, both paths: the later paint order is in front, and
// swapping the runs' paint orders swaps which shows.
TEST(TileCompositor, CoplanarGlyphsResolveByPaintOrder) {
    const std::vector<TextRun> runs = {
        {"Hamburg", 1.0f, 24.0f, {0.9f, 0.1f, 0.1f, 0.9f}, 0.5f},
        {"Hamburg", 2.5f, 25.5f, {0.1f, 0.1f, 0.9f, 0.9f}, 0.5f},
    };
    const Scene scene = render_scene(runs);
    std::vector<DrawnGlyph> swapped = scene.drawn;
    const uint32_t first_blue = static_cast<uint32_t>(scene.drawn.size() / 2);
    for (DrawnGlyph& g : swapped) {
        g.instance.paint_order = g.instance.paint_order >= first_blue ? g.instance.paint_order - first_blue
                                                                      : g.instance.paint_order + first_blue;
    }
    constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
    CompositorCreateInfo info = tile_info();
    info.draw_format = kFormat;
    auto compositor = Compositor::create(info);
    ASSERT_TRUE(compositor);
    for (bool draw : {false, true}) {
        SCOPED_TRACE(draw ? "draw path" : "tile path");
        auto image = [&](std::span<const DrawnGlyph> glyphs, Target& t) {
            t = make_target(kFormat, kWidth, kHeight,
                            draw ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT : VK_IMAGE_USAGE_STORAGE_BIT);
            if (draw) {
                composite_draw(*compositor, scene, glyphs, t);
            } else {
                composite_tiles(*compositor, scene, glyphs, t);
            }
            return read_target(t);
        };
        Target t, s;
        const std::vector<std::byte> bytes = image(scene.drawn, t);
        EXPECT_LE(worst_difference(t, bytes, expected_image(scene, t, {0, 0}, nullptr)), tolerance(kFormat));
        // The same glyphs with the paint orders of the two runs swapped put red in front instead.
        const std::vector<std::byte> other = image(swapped, s);
        double most_red_gain = 0.0;
        for (size_t p = 0; p < scene.pixels.size(); ++p) {
            const Rgba before = decode(kFormat, &bytes[p * 16]), after = decode(kFormat, &other[p * 16]);
            most_red_gain = std::max(most_red_gain, static_cast<double>(after[0] - before[0]));
        }
        EXPECT_GT(most_red_gain, 0.3);
    }
    expect_no_validation_messages();
}

TEST(TileCompositor, OverflowingTilesTakeTheLayeredWayWithinOneCodeOfExact) {
    const Scene scene = render_scene(dense_runs(0.5f));
    CompositorCreateInfo info = tile_info(1);  // stats of a frame come back at the next record()
    info.tile_capacity = 4;
    auto exact = Compositor::create(tile_info(1));
    ASSERT_TRUE(exact);
    for (uint32_t layers : {8u, 2u}) {
        SCOPED_TRACE("K = " + std::to_string(layers));
        info.tile_layers = layers;
        auto compositor = Compositor::create(info);
        ASSERT_TRUE(compositor);
        Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*compositor, scene, scene.drawn, t);
        Target again = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*compositor, scene, scene.drawn, again);
        const CompositorStats& stats = compositor->stats();
        ASSERT_TRUE(stats.measured);
        EXPECT_GT(stats.layered_tiles, 0u);
        EXPECT_EQ(stats.exact_tiles + stats.layered_tiles, stats.busy_tiles);
        const bool tail = max_overlap(scene) > layers;
        EXPECT_EQ(stats.tail_pixels > 0, tail);

        Target e = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*exact, scene, scene.drawn, e);
        std::vector<size_t> counts;
        const std::vector<Rgba> expected = expected_image(scene, t, {0, 0}, &counts);
        const std::vector<std::byte> got = read_target(t), exact_bytes = read_target(e);
        double within = 0.0, past = 0.0;
        size_t identical = 0, fitting = 0;
        for (size_t p = 0; p < expected.size(); ++p) {
            const Rgba g = decode(t.format, &got[p * 16]);
            double d = 0.0;
            for (size_t c = 0; c < 4; ++c) d = std::max(d, std::abs(double{g[c]} - double{expected[p][c]}));
            if (counts[p] <= layers) {
                within = std::max(within, d);
                ++fitting;
                identical += std::memcmp(&got[p * 16], &exact_bytes[p * 16], 16) == 0;
            } else {
                past = std::max(past, d);
            }
        }
        // Where the overlap fits K the layered way is the exact way, bit for bit.
        EXPECT_LE(within, 1.0 / 255.0);
        EXPECT_EQ(identical, fitting);
        if (tail) {
            EXPECT_GT(past, 0.0);  // past K the tail is an estimate
            EXPECT_LT(past, 0.25);
        }
    }
    expect_no_validation_messages();
}

// Tiles whose lists pass the 64 quads staged at a time: the walk goes on chunk after chunk.
TEST(TileCompositor, LongListsAreWalkedChunkAfterChunk) {
    std::vector<TextRun> runs;
    for (int i = 0; i < 72; ++i) {  // whole-pixel offsets: the same atlas entries serve every run
        const float f = static_cast<float>(i);
        runs.push_back({"Hamburg",
                        0.5f + static_cast<float>(i % 6),
                        22.0f + static_cast<float>(i / 6),
                        {0.2f + 0.01f * f, 0.5f, 0.9f - 0.01f * f, 0.08f},
                        0.013f * f});
    }
    const Scene scene = render_scene(runs);
    auto compositor = Compositor::create(tile_info(1));
    ASSERT_TRUE(compositor);
    Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    composite_tiles(*compositor, scene, scene.drawn, t);
    Target again = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    composite_tiles(*compositor, scene, scene.drawn, again);
    EXPECT_LE(worst_difference(t, read_target(t), expected_image(scene, t, {0, 0}, nullptr)), tolerance(t.format));
    const CompositorStats& stats = compositor->stats();
    ASSERT_TRUE(stats.measured);
    EXPECT_EQ(stats.exact_tiles, stats.busy_tiles);
    EXPECT_EQ(stats.max_overlap, max_overlap(scene));
    // Some 16 x 16 tile's list holds more than one 64-quad chunk.
    size_t longest = 0;
    for (uint32_t ty = 0; ty * 16 < kHeight; ++ty) {
        for (uint32_t tx = 0; tx * 16 < kWidth; ++tx) {
            size_t quads = 0;
            for (const DrawnGlyph& g : scene.drawn) {
                const GlyphInstance& i = g.instance;
                quads += i.x < int32_t(tx * 16 + 16) && i.y < int32_t(ty * 16 + 16) &&
                         i.x + int32_t(i.width) > int32_t(tx * 16) && i.y + int32_t(i.height) > int32_t(ty * 16);
            }
            longest = std::max(longest, quads);
        }
    }
    EXPECT_GT(longest, 64u);
    expect_no_validation_messages();
}

// Issue 28, item 16: 2000 runs of a 4096 px 'W' on 1024 x 1024 took 48 s a composite frame on
// lavapipe, most of it in the W's gaps, where every pixel read the texel of every copy and found no
// coverage. A deep frame (more pairs than kTileCullDepth a tile) leaves out of its bins the pairs
// whose atlas blocks under the tile hold no coverage, and those behind an opaque glyph full over
// the tile: the image stays the CPU computation's, and the pairs binned and left out add up to the
// geometry's.
// Opaque glyphs (alpha 1) whose texels are all full over a whole tile hide what lies behind them
// there: those pairs are left out too, the image unchanged.
std::vector<TextRun> deep_stack(float alpha, float baseline) {
    std::vector<TextRun> runs;
    for (int i = 0; i < 240; ++i) {  // whole-pixel offsets: a few atlas entries serve every run
        const float f = static_cast<float>(i);
        runs.push_back({"i",
                        2.5f + static_cast<float>(i % 40),
                        baseline + static_cast<float>(i / 80),
                        {0.9f - 0.003f * f, 0.3f, 0.1f + 0.003f * f, alpha},
                        0.004f * f});
    }
    return runs;
}

TEST(TileCompositor, DeepStacksLeaveTheirEmptyPairsOutOfTheBins) {
    // 160 px: the target shows the top of the stem and the gap above it, up to the dot.
    const Scene scene = render_scene(deep_stack(0.04f, 118.0f), "rgb", 160.0f);
    const auto pairs_of = [](const Scene& s) {
        uint64_t pairs = 0;
        for (const DrawnGlyph& g : s.drawn) {
            const GlyphInstance& i = g.instance;
            for (uint32_t ty = 0; ty * 16 < kHeight; ++ty) {
                for (uint32_t tx = 0; tx * 16 < kWidth; ++tx) {
                    pairs += i.x < int32_t(tx * 16 + 16) && i.y < int32_t(ty * 16 + 16) &&
                             i.x + int32_t(i.width) > int32_t(tx * 16) && i.y + int32_t(i.height) > int32_t(ty * 16);
                }
            }
        }
        return pairs;
    };
    const uint64_t geometric = pairs_of(scene);
    const uint32_t tiles = ((kWidth + 15) / 16) * ((kHeight + 15) / 16);
    ASSERT_GT(geometric, uint64_t{gpu::kTileCullDepth} * tiles);  // deep: classified
    auto compositor = Compositor::create(tile_info(1));
    ASSERT_TRUE(compositor);
    std::vector<std::vector<std::byte>> images;
    for (int frame = 0; frame < 3; ++frame) {  // each frame reads the one before's counts
        Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*compositor, scene, scene.drawn, t);
        images.push_back(read_target(t));
        EXPECT_LE(worst_difference(t, images.back(), expected_image(scene, t, {0, 0}, nullptr)), tolerance(t.format));
        EXPECT_FALSE(compositor->stats().bins_reused);  // the next frame's samples may fill an empty block
    }
    EXPECT_EQ(images[1], images[0]);
    EXPECT_EQ(images[2], images[0]);
    const CompositorStats& stats = compositor->stats();
    ASSERT_TRUE(stats.measured);
    EXPECT_GT(stats.tile_empty_pairs, 0u);
    EXPECT_EQ(stats.tile_hidden_pairs, 0u);  // nothing is opaque
    EXPECT_EQ(uint64_t{stats.tile_pairs} + stats.tile_empty_pairs, geometric);
    EXPECT_EQ(stats.max_overlap, max_overlap(scene));
    EXPECT_EQ(stats.exact_tiles, stats.busy_tiles);

    // 320 px: the target shows only the stem, wide enough for whole blocks of full coverage.
    const Scene opaque = render_scene(deep_stack(1.0f, 100.0f), "rgb", 320.0f);
    for (int frame = 0; frame < 2; ++frame) {
        Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*compositor, opaque, opaque.drawn, t);
        EXPECT_LE(worst_difference(t, read_target(t), expected_image(opaque, t, {0, 0}, nullptr)), tolerance(t.format));
    }
    ASSERT_TRUE(compositor->stats().measured);
    EXPECT_GT(compositor->stats().tile_hidden_pairs, 0u);
    EXPECT_EQ(uint64_t{compositor->stats().tile_pairs} + compositor->stats().tile_empty_pairs +
                  compositor->stats().tile_hidden_pairs,
              pairs_of(opaque));
    expect_no_validation_messages();
}

// Static text: a frame slot that binned these very glyphs skips the binning, with the same image;
// any change bins again.
TEST(TileCompositor, StaticTextReusesItsBins) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    auto compositor = Compositor::create(tile_info(2));
    ASSERT_TRUE(compositor);
    std::vector<std::vector<std::byte>> images;
    std::vector<bool> reused;
    std::vector<DrawnGlyph> glyphs = scene.drawn;
    for (int frame = 0; frame < 5; ++frame) {
        if (frame == 3) glyphs[0].instance.color[0] = 0.5f;  // a hover colour: the quads change
        Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*compositor, scene, glyphs, t);
        images.push_back(read_target(t));
        reused.push_back(compositor->stats().bins_reused);
        if (frame == 2) {
            EXPECT_TRUE(compositor->stats().measured);
            EXPECT_EQ(compositor->stats().max_overlap, max_overlap(scene));  // frame 0's, binned
        }
    }
    // Two slots: frames 0 and 1 bin, one slot each; frame 2 finds slot 0 holding its glyphs; frame 3
    // changed a colour; frame 4 finds slot 0 holding the old glyphs: both bin.
    EXPECT_EQ(reused, (std::vector<bool>{false, false, true, false, false}));
    EXPECT_EQ(images[2], images[0]);
    EXPECT_NE(images[3], images[0]);
    EXPECT_EQ(images[4], images[3]);
    EXPECT_EQ(compositor->stats().max_overlap, max_overlap(scene));  // frame 2's: reused bins count right
    CompositorCreateInfo info = tile_info(2);
    info.reuse_static_bins = false;
    auto always = Compositor::create(info);
    ASSERT_TRUE(always);
    for (int frame = 0; frame < 3; ++frame) {
        Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
        composite_tiles(*always, scene, scene.drawn, t);
        EXPECT_FALSE(always->stats().bins_reused);
        EXPECT_EQ(read_target(t), images[0]);
    }
    expect_no_validation_messages();
}

TEST(TileCompositor, DrawsOnlyInsideTheCallersRect) {
    const Scene scene = render_scene(overlapping_runs(0.8f));
    auto compositor = Compositor::create(tile_info());
    ASSERT_TRUE(compositor);
    const uint32_t width = kWidth + 21, height = kHeight + 13;
    const VkOffset2D origin{9, 5};
    Target t = make_target(VK_FORMAT_R8G8B8A8_UNORM, width, height, VK_IMAGE_USAGE_STORAGE_BIT);
    composite_tiles(*compositor, scene, scene.drawn, t, origin);
    const std::vector<std::byte> bytes = read_target(t);
    EXPECT_LE(worst_difference(t, bytes, expected_image(scene, t, origin, nullptr)), 1.0);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const bool inside = x >= 9 && y >= 5 && x < 9 + kWidth && y < 5 + kHeight;
            if (inside) continue;
            const size_t at = (size_t{y} * width + x) * 4;
            EXPECT_EQ(std::memcmp(&bytes[at], &t.initial[at], 4), 0) << x << ", " << y;
        }
    }
    expect_no_validation_messages();
}

// A target of several thousand tiles: the prefix sum runs over several blocks, and copies of the
// scene in the first, middle and last of them land where they should.
TEST(TileCompositor, ScansTileCountsAcrossBlocks) {
    const Scene scene = render_scene(overlapping_runs(0.7f));
    auto compositor = Compositor::create(tile_info());
    ASSERT_TRUE(compositor);
    const uint32_t width = 1200, height = 700;  // 75 x 44 tiles: 4 blocks of 1024
    const VkOffset2D offsets[] = {{0, 0}, {610, 330}, {width - kWidth, height - kHeight}};
    std::vector<DrawnGlyph> copies;
    uint32_t paint_base = 0;
    for (const VkOffset2D& o : offsets) {
        for (DrawnGlyph g : scene.drawn) {
            g.instance.x += o.x;
            g.instance.y += o.y;
            g.instance.paint_order += paint_base;
            copies.push_back(g);
        }
        paint_base += 1000;
    }
    Target t = make_target(VK_FORMAT_R16G16B16A16_SFLOAT, width, height, VK_IMAGE_USAGE_STORAGE_BIT);
    CompositeTarget target{t.image.view(), t.format, VK_FORMAT_UNDEFINED, {width, height}, {}};
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) {
        EXPECT_TRUE(compositor->record(cb, scene.renderer->drawn_frame().with_glyphs(copies), target));
    }));
    const std::vector<std::byte> bytes = read_target(t);
    // Each copy's kWidth x kHeight region is what scene.pixels describes (glyph rects reach a
    // little past it); far from every copy nothing is written.
    const uint32_t texel = format_texel_size(t.format);
    for (const VkOffset2D& o : offsets) {
        const std::vector<Rgba> part = expected_image(scene, t, o, nullptr);
        double worst = 0.0;
        for (uint32_t y = 0; y < kHeight; ++y) {
            for (uint32_t x = 0; x < kWidth; ++x) {
                const size_t at = (size_t{y} + static_cast<size_t>(o.y)) * width + x + static_cast<size_t>(o.x);
                const Rgba got = decode(t.format, &bytes[at * texel]);
                for (size_t c = 0; c < 4; ++c) worst = std::max(worst, std::abs(double{got[c]} - double{part[at][c]}));
            }
        }
        EXPECT_LE(worst, tolerance(t.format)) << "copy at " << o.x << ", " << o.y;
    }
    size_t far_pixels = 0;
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            bool far = true;
            for (const VkOffset2D& o : offsets) {
                far = far && (int64_t{x} + 32 < o.x || int64_t{x} > o.x + int64_t{kWidth} + 32 ||
                              int64_t{y} + 32 < o.y || int64_t{y} > o.y + int64_t{kHeight} + 32);
            }
            if (!far) continue;
            ++far_pixels;
            const size_t at = (size_t{y} * width + x) * texel;
            ASSERT_EQ(std::memcmp(&bytes[at], &t.initial[at], texel), 0) << x << ", " << y;
        }
    }
    EXPECT_GT(far_pixels, size_t{width} * height / 2);
    expect_no_validation_messages();
}

TEST(TileCompositor, RefusesWhatItCannotDraw) {
    const Scene scene = render_scene({{"Ham", 2.0f, 20.0f, {0.1f, 0.1f, 0.1f, 1.0f}, 0.5f}});
    CompositorCreateInfo info = tile_info();
    info.tile_capacity = 100;  // not a power of two
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = tile_info();
    info.tile_layers = 0;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    info = tile_info();
    auto compositor = Compositor::create(info);
    ASSERT_TRUE(compositor);
    EXPECT_FALSE(compositor->supports_target_format(VK_FORMAT_B8G8R8A8_UNORM));
    EXPECT_FALSE(compositor->supports_target_format(VK_FORMAT_R8G8B8A8_SRGB));
    Target t = make_target(VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    CompositeTarget target{t.image.view(), VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_UNDEFINED, {kWidth, kHeight}, {}};
    const crisp::DrawnFrame frame = scene.renderer->drawn_frame().with_glyphs(scene.drawn);
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) {
        const Status wrong_format = compositor->record(cb, frame, target);
        ASSERT_FALSE(wrong_format);
        EXPECT_NE(wrong_format.error().message.find("storage_without_format"), std::string::npos);
        target.format = VK_FORMAT_R8G8B8A8_UNORM;
        crisp::DrawnFrame no_atlas = frame;
        no_atlas.atlas = VK_NULL_HANDLE;
        EXPECT_EQ(compositor->record(cb, no_atlas, target).error().code, ErrorCode::invalid_argument);
        target.rect = {{10, 0}, {kWidth, kHeight}};  // past the right edge
        EXPECT_EQ(compositor->record(cb, frame, target).error().code, ErrorCode::invalid_argument);
        EXPECT_EQ(compositor->record_draw(cb, frame, {{0, 0}, {8, 8}}).error().code,
                  ErrorCode::invalid_argument);  // no draw_format
        CompositeParams params;
        EXPECT_EQ(compositor->record_reference(cb, frame, params).error().code,
                  ErrorCode::invalid_argument);  // no reference_modes
    }));
    // Untouched: every refusal recorded nothing.
    EXPECT_EQ(read_target(t), t.initial);
    expect_no_validation_messages();
}

// Issue 28 item 16: the bins hold a 32-byte entry per (glyph, tile) pair. A frame with more pairs
// than tile_bin_pairs is binned and composited in batches, back to front, each over the image the
// ones behind it left: the image is the one pass's (the CPU computation's), the bins hold one batch.
// Batches are also cut where a tile's list would pass the capacity, so that every tile is exact.
TEST(TileCompositor, PairsPastTheBinBudgetAreCompositedInBatches) {
    const Scene scene = render_scene(dense_runs(0.5f));
    auto whole = Compositor::create(tile_info(1));
    ASSERT_TRUE(whole);
    CompositorCreateInfo info = tile_info(1);
    info.tile_bin_pairs = 16;  // the target's 15 tiles and one more: a glyph or a few a batch
    info.tile_capacity = 4;    // one pass would take the layered way in the busiest tiles
    auto batched = Compositor::create(info);
    ASSERT_TRUE(batched);
    std::vector<std::vector<std::byte>> images;
    for (Compositor* compositor : {&*whole, &*batched}) {
        for (int frame = 0; frame < 2; ++frame) {  // the second frame reads the first one's counts
            Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
            composite_tiles(*compositor, scene, scene.drawn, t);
            EXPECT_LE(worst_difference(t, read_target(t), expected_image(scene, t, {0, 0}, nullptr)),
                      tolerance(t.format));
            if (frame == 1) images.push_back(read_target(t));
        }
    }
    const CompositorStats &one = whole->stats(), &many = batched->stats();
    EXPECT_EQ(one.tile_batches, 1u);
    EXPECT_GT(many.tile_batches, 4u);
    EXPECT_FALSE(many.bins_reused);  // a batched frame's bins hold its front batch only
    ASSERT_TRUE(one.measured && many.measured);
    // Counted over every batch (the batched frame, deep, leaves out pairs that hold no coverage).
    EXPECT_EQ(many.tile_pairs + many.tile_empty_pairs, one.tile_pairs + one.tile_empty_pairs);
    EXPECT_EQ(many.busy_tiles, many.exact_tiles);  // batches are cut where a list would pass the capacity
    EXPECT_GT(max_overlap(scene), 4u);
    EXPECT_LT(many.buffer_bytes, one.buffer_bytes);
    ASSERT_EQ(images.size(), 2u);
    double worst = 0.0;
    for (size_t p = 0; p < size_t{kWidth} * kHeight; ++p) {
        const Rgba a = decode(VK_FORMAT_R32G32B32A32_SFLOAT, &images[0][p * 16]);
        const Rgba b = decode(VK_FORMAT_R32G32B32A32_SFLOAT, &images[1][p * 16]);
        for (size_t c = 0; c < 4; ++c) {
            worst = std::max(worst, std::abs(static_cast<double>(a[c]) - static_cast<double>(b[c])));
        }
    }
    EXPECT_LE(worst, 1e-5);
    info.tile_bin_pairs = 0;
    EXPECT_EQ(Compositor::create(info).error().code, ErrorCode::invalid_argument);
    expect_no_validation_messages();
}

// Past maxStorageBufferRange (128 MiB on lavapipe), which one pass's bins could not be reached
// through, a frame used to be refused ("bins need 262 MB" for 2000 runs of one 4096 px glyph on a
// 1024 x 1024 canvas). Now it is batched, and its bins stay within the default budget. Glyph rects
// covering the whole target make the pairs cheaply; recorded, not run (every pixel would walk them
// all), and dropped. Cut where a tile's list would pass its capacity, each batch takes the exact way.
TEST(TileCompositor, BinsPastTheStorageBufferRangeAreBatched) {
    const VkDeviceSize range = fixture().context->properties().limits.maxStorageBufferRange;
    const uint64_t tiles =
        uint64_t{(kWidth + gpu::kTileSide - 1) / gpu::kTileSide} * ((kHeight + gpu::kTileSide - 1) / gpu::kTileSide);
    const uint64_t glyphs = range / (sizeof(gpu::TileBinEntry) * tiles) + 1;
    if (glyphs > (uint64_t{1} << 20)) GTEST_SKIP() << "a range of " << range << " bytes takes too many glyphs";
    const Scene scene = render_scene({{"H", 2.0f, 20.0f, {0.1f, 0.1f, 0.1f, 1.0f}, 0.5f}});
    ASSERT_FALSE(scene.drawn.empty());
    DrawnGlyph whole = scene.drawn[0];
    whole.instance.x = whole.instance.y = 0;
    whole.instance.width = kWidth;
    whole.instance.height = kHeight;
    const std::vector<DrawnGlyph> many(glyphs, whole);
    auto compositor = Compositor::create(tile_info());
    ASSERT_TRUE(compositor);
    Target t = make_target(VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    const CompositeTarget target{t.image.view(), t.format, VK_FORMAT_UNDEFINED, {kWidth, kHeight}, {}};
    test::UnsubmittedCommandBuffer dropped(*fixture().context);
    ASSERT_TRUE(dropped.ok());
    EXPECT_TRUE(dropped.record_and_drop([&](VkCommandBuffer cb) {
        const Status s = compositor->record(cb, scene.renderer->drawn_frame().with_glyphs(many), target);
        EXPECT_TRUE(s) << (s ? "" : s.error().message);
    }));
    const CompositorStats& stats = compositor->stats();
    // Every glyph reaches every tile: a batch is a list's capacity of them.
    EXPECT_EQ(stats.tile_batches, (glyphs + gpu::kTileDefaultCapacity - 1) / gpu::kTileDefaultCapacity);
    const uint64_t quad_bytes = glyphs * sizeof(gpu::CompositeQuad);
    EXPECT_LE(stats.buffer_bytes - quad_bytes, uint64_t{gpu::kTileDefaultBinPairs} * sizeof(gpu::TileBinEntry) + 4096);
    EXPECT_TRUE(compositor->abandon_frame(scene.renderer->frame()));
    expect_no_validation_messages();
}

// Issue 9: frames an engine records and then drops. A run that drops frames at random (the first
// one, and frames whose glyphs or quads are new among them; some after the renderer, before the
// compositor) and abandons them must end with the image of the run that dropped none, bit for bit. The atlas is tiny,
// so glyphs evict each other and new ones land in cells that held others; the text changes every few frames, so the
// tile path's bins are made and reused across dropped frames.
std::vector<std::byte> run_with_drops(const std::vector<bool>& drops, uint32_t& frames) {
    Fixture& f = fixture();
    HeadlessContext& context = *f.context;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 64;  // 16 cells
    info.atlas.max_samples = kSamples;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer);
    if (!renderer) return {};
    EXPECT_TRUE(renderer->add_font(*f.font));
    auto compositor = Compositor::create(tile_info());
    EXPECT_TRUE(compositor);
    if (!compositor) return {};
    Target t = make_target(VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    CompositeTarget target{
        t.image.view(), t.format, VK_FORMAT_UNDEFINED, {kWidth, kHeight}, {{0, 0}, {kWidth, kHeight}}};

    const char* texts[] = {"Hamburg", "fonstiv", "Hamb@&1", "vitsnof"};
    std::vector<TextLayout> layouts;
    const Font* fonts[] = {f.font.get()};
    for (const char* text : texts) {
        TextStyle style;
        style.size = 13.0f;
        auto laid = layout_text(fonts, text, style, LayoutOptions{.origin_x = 2.3f, .origin_y = 20.0f});
        EXPECT_TRUE(laid);
        if (laid) layouts.push_back(std::move(*laid));
    }
    if (layouts.size() != 4) return {};

    test::UnsubmittedCommandBuffer dropped(context);
    EXPECT_TRUE(dropped.ok());

    const auto record = [&](VkCommandBuffer cb) {
        EXPECT_TRUE(renderer->record(cb));
        EXPECT_TRUE(compositor->record(cb, renderer->drawn_frame(), target));
    };
    frames = 0;
    for (size_t i = 0;; ++i) {
        const bool scripted = i < drops.size();
        const TextLayout& layout = layouts[scripted ? (i / 3) % layouts.size() : 0];
        if (!scripted && renderer->converged()) break;
        if (i > drops.size() + 200) break;
        renderer->begin_frame();
        renderer->draw(layout.glyphs, VkRect2D{{0, 0}, {kWidth, kHeight}});
        if (!scripted && renderer->converged()) {
            // The last frame starts from the backdrop, so that the image depends on it alone.
            EXPECT_TRUE(context.upload(t.image, t.initial, VK_IMAGE_LAYOUT_GENERAL));
        }
        if (scripted && drops[i]) {
            // Every other drop comes between the renderer and the compositor: the compositor is told
            // of a frame it never recorded, and refuses, keeping the record of the frame the GPU
            // may still run. An earlier frame is refused by the renderer too.
            const bool before_compositor = i % 2 == 1;
            if (before_compositor) {
                EXPECT_TRUE(dropped.record_and_drop([&](VkCommandBuffer cb) { EXPECT_TRUE(renderer->record(cb)); }));
            } else {
                EXPECT_TRUE(dropped.record_and_drop(record));
            }
            EXPECT_FALSE(renderer->abandon_frame(renderer->frame() - 1));
            EXPECT_TRUE(renderer->abandon_frame(renderer->frame()));
            EXPECT_EQ(compositor->abandon_frame(renderer->frame()).ok(), !before_compositor);
            continue;
        }
        EXPECT_TRUE(context.submit_and_wait(record));
        ++frames;
    }
    // One more frame of the final text over the backdrop, now that it has converged.
    EXPECT_TRUE(context.upload(t.image, t.initial, VK_IMAGE_LAYOUT_GENERAL));
    renderer->begin_frame();
    renderer->draw(layouts[0].glyphs, VkRect2D{{0, 0}, {kWidth, kHeight}});
    EXPECT_TRUE(context.submit_and_wait(record));
    EXPECT_TRUE(renderer->converged());
    return read_target(t);
}

TEST(Frames, DroppedFramesLeaveTheImageOfTheRunThatDroppedNone) {
    ASSERT_TRUE(fixture().context);
    constexpr size_t kScripted = 24;
    uint32_t frames = 0;
    const std::vector<std::byte> reference = run_with_drops(std::vector<bool>(kScripted, false), frames);
    ASSERT_FALSE(reference.empty());
    // Text is there: the image is not the backdrop.
    Target backdrop = make_target(VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    ASSERT_NE(reference, backdrop.initial);
    for (uint32_t seed : {1u, 2u, 3u}) {
        std::mt19937 rng(seed);
        std::vector<bool> drops(kScripted);
        for (size_t i = 0; i < kScripted; ++i) drops[i] = i == 0 || i % 3 == 0 || rng() % 3 == 0;
        uint32_t submitted = 0;
        const std::vector<std::byte> image = run_with_drops(drops, submitted);
        EXPECT_EQ(image, reference) << "seed " << seed;
    }
    expect_no_validation_messages();
}

// Every earlier command's memory accesses before every later one's.
void full_barrier(VkCommandBuffer cb) {
    VkMemoryBarrier all{};
    all.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    all.srcAccessMask = all.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &all, 0,
                         nullptr, 0, nullptr);
}

// Frames in flight on the context's queue as an engine has them: frame i is recorded into command
// buffer i % 2 once the fence of frame i - 2 has signalled, and submitted without a wait. Each
// command buffer starts with a full barrier, so that the caller's own images (a target written by
// consecutive frames) are ordered; the compositor's resources are the compositor's to keep apart.
class FramesInFlight {
public:
    explicit FramesInFlight(const HeadlessContext& context) : device_(context.device()), queue_(context.queue()) {
        ok_ = test::create_command_buffers(context, pool_, buffers_.data(), 2);
        VkFenceCreateInfo fence_info{};
        fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
        for (VkFence& fence : fences_) ok_ = ok_ && vkCreateFence(device_, &fence_info, nullptr, &fence) == VK_SUCCESS;
    }
    FramesInFlight(const FramesInFlight&) = delete;
    FramesInFlight& operator=(const FramesInFlight&) = delete;
    ~FramesInFlight() {
        wait_idle();
        for (VkFence fence : fences_) vkDestroyFence(device_, fence, nullptr);
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    }
    bool ok() const { return ok_; }

    // True when every call succeeded.
    template <typename Commands>
    bool frame(Commands&& commands) {
        const size_t i = next_++ % 2;
        bool ok = vkWaitForFences(device_, 1, &fences_[i], VK_TRUE, UINT64_MAX) == VK_SUCCESS;
        ok = ok && vkResetFences(device_, 1, &fences_[i]) == VK_SUCCESS;
        ok = ok && vkResetCommandBuffer(buffers_[i], 0) == VK_SUCCESS;
        VkCommandBufferBeginInfo begin{};
        begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        ok = ok && vkBeginCommandBuffer(buffers_[i], &begin) == VK_SUCCESS;
        full_barrier(buffers_[i]);
        commands(buffers_[i]);
        ok = ok && vkEndCommandBuffer(buffers_[i]) == VK_SUCCESS;
        VkSubmitInfo submit{};
        submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &buffers_[i];
        return ok && vkQueueSubmit(queue_, 1, &submit, fences_[i]) == VK_SUCCESS;
    }
    void wait_idle() {
        if (ok_) vkWaitForFences(device_, 2, fences_.data(), VK_TRUE, UINT64_MAX);
    }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::array<VkCommandBuffer, 2> buffers_{};
    std::array<VkFence, 2> fences_{};
    size_t next_ = 0;
    bool ok_ = false;
};

// Issue 28, item 1: Compositor::record() twice in a frame, with two frames in flight, made the next
// frame reuse a frame slot whose composite was still pending (12 validation errors). The rule of
// compositor.hpp refuses the record calls of the frame after (and only those), so the validation
// layer has nothing to report; compositing one frame again once it is done stays allowed.
TEST(Frames, RecordTwiceInAFrameIsRefusedWhereItsSlotMayStillBePending) {
    HeadlessContext& context = *fixture().context;
    Scene scene = render_scene(overlapping_runs(0.7f));
    ASSERT_TRUE(scene.renderer);
    std::vector<GlyphInstance> glyphs;
    for (const DrawnGlyph& drawn : scene.drawn) glyphs.push_back(drawn.instance);
    auto compositor = Compositor::create(tile_info(2));
    ASSERT_TRUE(compositor) << compositor.error().message;
    Target t = make_target(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT);
    CompositeTarget target;
    target.view = t.image.view();
    target.format = t.format;
    target.extent = {t.width, t.height};
    target.rect = {{0, 0}, {kWidth, kHeight}};
    std::vector<std::pair<uint64_t, std::string>> refused;  // renderer frame, message
    {
        FramesInFlight frames(context);
        ASSERT_TRUE(frames.ok());
        for (int frame = 0; frame < 6; ++frame) {
            ASSERT_TRUE(frames.frame([&](VkCommandBuffer cb) {
                scene.renderer->begin_frame();
                scene.renderer->draw(glyphs, VkRect2D{{0, 0}, {kWidth, kHeight}});
                EXPECT_TRUE(scene.renderer->record(cb));
                for (int twice = 0; twice < 2; ++twice) {
                    const Status s = compositor->record(cb, scene.renderer->drawn_frame(), target);
                    if (!s) refused.emplace_back(scene.renderer->frame(), s.error().message);
                    full_barrier(cb);  // the caller orders its own target's writes
                }
            }));
        }
    }
    // Frames 1, 3 and 5 of the six composite twice; frames 2, 4 and 6 would reuse a slot of the
    // frame before, still in flight, and are refused both times.
    EXPECT_EQ(refused.size(), 6u);
    for (size_t i = 0; i < refused.size(); ++i) {
        EXPECT_EQ(refused[i].first % 2, refused[0].first % 2) << refused[i].second;
        EXPECT_NE(refused[i].second.find("may still be on the GPU"), std::string::npos) << refused[i].second;
    }
    // Once the GPU is done, a later renderer frame composites, and again as often as a caller asks.
    scene.renderer->begin_frame();
    scene.renderer->draw(glyphs, VkRect2D{{0, 0}, {kWidth, kHeight}});
    ASSERT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) { EXPECT_TRUE(scene.renderer->record(cb)); }));
    for (int again = 0; again < 3; ++again) composite_tiles(*compositor, scene, scene.renderer->drawn(), t);
    expect_no_validation_messages();
}

}  // namespace
}  // namespace crisp
