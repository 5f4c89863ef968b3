// crisp support (not installed): what tools and tests both do with a renderer on a headless
// context: make the context with what crisp's parts need, draw until the text has converged, and
// read the atlas back.
#pragma once

#include "headless_context.hpp"

#include <crisp/renderer.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace crisp::harness {

// A context from `options` whose device has what crisp's renderer and every compositor path need
// (options.crisp_needs, filled in here: the draw path, the reference modes, and format-less
// storage images where the device offers them). `storage_without_format` says whether those are
// on (B8G8R8A8 tile targets through a view of their own format). Errors as HeadlessContext::create.
inline Result<HeadlessContext> create_context(HeadlessContextOptions options, bool& storage_without_format) {
    options.crisp_needs = CrispFeatureNeeds{.draw_path = true, .reference_modes = true, .storage_without_format = true};
    Result<HeadlessContext> context = HeadlessContext::create(options);
    storage_without_format = context && context->enabled_features()->features.shaderStorageImageWriteWithoutFormat;
    return context;
}

// Frames of `draw` (which calls the renderer's draw() after begin_frame()), each recorded and
// submitted on `context` and followed by `after()`, until the renderer converges, `max_frames`
// were rendered, or `after()` (where it returns bool) returns false: a caller's own bound, such
// as a time limit. Returns the frames rendered, or the first failure of a record() or submission.
template <class Draw, class After>
Result<uint32_t> render_until_converged(HeadlessContext& context, Renderer& renderer, uint32_t max_frames, Draw&& draw,
                                        After&& after) {
    uint32_t frames = 0;
    bool go_on = true;
    do {
        renderer.begin_frame();
        draw();
        Status recorded;
        const Status submitted = context.submit_and_wait([&](VkCommandBuffer cb) { recorded = renderer.record(cb); });
        if (!recorded) return recorded.error();
        if (!submitted) return submitted.error();
        if constexpr (std::is_same_v<std::invoke_result_t<After>, bool>) {
            go_on = after();
        } else {
            after();
        }
        ++frames;
    } while (go_on && !renderer.converged() && frames < max_frames);
    return frames;
}
template <class Draw>
Result<uint32_t> render_until_converged(HeadlessContext& context, Renderer& renderer, uint32_t max_frames,
                                        Draw&& draw) {
    return render_until_converged(context, renderer, max_frames, draw, [] {});
}

// One texel of the atlas as Renderer::record_atlas_readback() copies it: the red, green and blue
// hits in kCoverageOne units, then the sample count.
struct Texel {
    uint16_t r, g, b, count;
};

// The renderer's whole atlas, read back through `context`.
inline Result<std::vector<Texel>> read_atlas(HeadlessContext& context, const Renderer& renderer) {
    const AtlasConfig& config = renderer.atlas().config();
    const VkDeviceSize bytes = VkDeviceSize{config.width} * config.height * sizeof(Texel);
    auto readback = context.create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    if (!readback) return readback.error();
    const Status copied =
        context.submit_and_wait([&](VkCommandBuffer cb) { renderer.record_atlas_readback(cb, readback->handle()); });
    if (!copied) return copied.error();
    std::vector<Texel> texels(size_t{config.width} * config.height);
    std::memcpy(texels.data(), readback->mapped().data(), bytes);
    return texels;
}

}  // namespace crisp::harness
