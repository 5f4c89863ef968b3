#include "raster/retired.hpp"

#include "raster/font_store.hpp"

#include <algorithm>
#include <utility>

namespace crisp::raster {

void RetireLists::release_finished(uint64_t this_frame, uint32_t frames_in_flight, FontStore& fonts) {
    const auto done = [&](uint64_t retired_at) { return retired_at + frames_in_flight <= this_frame; };
    std::erase_if(buffers, [&](RetiredBuffer& r) {
        if (!done(r.frame)) return false;
        r.buffer.reset();
        return true;
    });
    std::erase_if(images, [&](RetiredImage& r) {
        if (!done(r.frame)) return false;
        r.image.reset();
        return true;
    });
    std::erase_if(ranges, [&](const RetiredRanges& r) {
        if (!done(r.frame)) return false;
        fonts.give_back(r);
        return true;
    });
}

std::optional<vk::DeviceBuffer> RetireLists::take_back(VkBuffer buffer, uint64_t frame) {
    const auto retired = std::find_if(buffers.begin(), buffers.end(), [&](const RetiredBuffer& r) {
        return r.frame == frame && r.buffer.buffer == buffer;
    });
    if (retired == buffers.end()) return std::nullopt;
    std::optional<vk::DeviceBuffer> taken = std::move(retired->buffer);
    buffers.erase(retired);
    return taken;
}

std::optional<vk::DeviceImage> RetireLists::take_back(VkImage image) {
    const auto old =
        std::find_if(images.begin(), images.end(), [&](const RetiredImage& r) { return r.image.image == image; });
    if (old == images.end()) return std::nullopt;
    std::optional<vk::DeviceImage> taken = std::move(old->image);
    images.erase(old);
    return taken;
}

}  // namespace crisp::raster
