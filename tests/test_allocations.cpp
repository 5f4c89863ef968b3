// A warm frame allocates nothing (README, "Engine contract"): the C++ heap allocations that
// crisp's frame calls make, counted by replacing the global operator new in this program of its
// own. The validation layer, which is C++ and would be counted too, stays off; lavapipe allocates
// through malloc, which is not counted.
#include "test_support.hpp"

#include <crisp/compositor.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <new>

namespace {

std::atomic<uint64_t> g_allocations{0};

void* allocate(std::size_t bytes, std::size_t alignment) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (bytes == 0) bytes = 1;
    void* p = alignment > alignof(std::max_align_t)
                  ? std::aligned_alloc(alignment, (bytes + alignment - 1) / alignment * alignment)
                  : std::malloc(bytes);
    if (!p) throw std::bad_alloc();
    return p;
}

}  // namespace

void* operator new(std::size_t bytes) {
    return allocate(bytes, 0);
}
void* operator new[](std::size_t bytes) {
    return allocate(bytes, 0);
}
void* operator new(std::size_t bytes, std::align_val_t alignment) {
    return allocate(bytes, static_cast<std::size_t>(alignment));
}
void* operator new[](std::size_t bytes, std::align_val_t alignment) {
    return allocate(bytes, static_cast<std::size_t>(alignment));
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
    std::free(p);
}

namespace crisp {
namespace {

using namespace test;

constexpr uint32_t kWidth = 96, kHeight = 48;

// Frames of text drawn the ways an engine draws it (plain, clipped by a visible rect that cuts
// glyphs, moving under a name, rotated), each composited by the tile path; returns the operator
// new calls the renderer's and compositor's frame calls made over frames [first, last).
uint64_t allocations_of_frames(uint32_t first, uint32_t last) {
    HeadlessContextOptions options;
    options.crisp_needs = CrispFeatureNeeds{};
    auto context = HeadlessContext::create(options);
    EXPECT_TRUE(context) << (context ? "" : context.error().message);
    if (!context) return ~uint64_t{0};
    const std::unique_ptr<Font> font = bake_test_font("Hamburgefonts 0123");
    RendererCreateInfo info = renderer_create_info(*context);
    info.atlas.width = info.atlas.height = 256;
    info.atlas.max_samples = 64;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << (renderer ? "" : renderer.error().message);
    auto compositor = Compositor::create(compositor_create_info(*context));
    EXPECT_TRUE(compositor) << (compositor ? "" : compositor.error().message);
    if (!renderer || !compositor || !renderer->add_font(*font)) return ~uint64_t{0};
    auto image = context->create_image({VK_FORMAT_R8G8B8A8_UNORM, kWidth, kHeight, VK_IMAGE_USAGE_STORAGE_BIT});
    EXPECT_TRUE(image);
    if (!image) return ~uint64_t{0};
    const Font* fonts[] = {font.get()};
    const TextLayout layout = layout_or_fail({fonts[0]}, "Hamburgefonts 0123", TextStyle{.size = 14.0f},
                                             LayoutOptions{.origin_x = 1.0f, .origin_y = 14.0f});
    CompositeTarget target;
    target.view = image->view();
    target.format = VK_FORMAT_R8G8B8A8_UNORM;
    target.extent = {kWidth, kHeight};
    target.rect = {{0, 0}, {kWidth, kHeight}};
    const VkRect2D cut{{0, 0}, {kWidth / 2, kHeight}};  // cuts glyphs in two
    const TextTransform turned{0.8f, -0.6f, 0.6f, 0.8f, 10.0f, 30.0f};
    uint64_t counted = 0;
    for (uint32_t frame = 0; frame < last; ++frame) {
        const uint64_t before = g_allocations.load();
        renderer->begin_frame();
        renderer->draw(layout.glyphs);
        DrawOptions clipped;
        clipped.offset_y = 16.0f;
        clipped.visible = cut;
        renderer->draw(layout.glyphs, clipped);
        DrawOptions moving;
        moving.id = 7;
        moving.offset_x = 0.37f * static_cast<float>(frame % 5);
        moving.offset_y = 30.0f;
        renderer->draw(layout.glyphs, moving);
        DrawOptions rotated;
        rotated.transform = turned;
        rotated.offset_y = 8.0f;
        renderer->draw(layout.glyphs, rotated);
        uint64_t in_frame = g_allocations.load() - before;
        const Status submitted = context->submit_and_wait([&](VkCommandBuffer cb) {
            const uint64_t start = g_allocations.load();
            EXPECT_TRUE(renderer->record(cb));
            EXPECT_TRUE(compositor->record(cb, renderer->drawn_frame(), target));
            in_frame += g_allocations.load() - start;
        });
        EXPECT_TRUE(submitted);
        if (frame >= first) counted += in_frame;
    }
    return counted;
}

TEST(Allocations, AWarmFrameAllocatesNothing) {
    // The first frames make the scratch vectors' room (and the moving draw's entries); from
    // frame 64 on the text holds its samples or keeps to the same keys.
    const uint64_t allocations = allocations_of_frames(64, 264);
    std::printf("[ allocations ] 200 warm frames: %llu operator new calls\n",
                static_cast<unsigned long long>(allocations));
    EXPECT_EQ(allocations, 0u);
}

}  // namespace
}  // namespace crisp
