// Private: what the renderer frees only once the GPU is done with it. Buffers, atlas images and
// font page ranges retired at a frame are freed frames_in_flight frames later; a frame that is
// abandoned takes back what it retired.
#pragma once

#include "vk/resources.hpp"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace crisp::raster {

class FontStore;

// A byte range of a font page's buffer.
struct Range {
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
};

struct RetiredBuffer {
    vk::DeviceBuffer buffer;
    uint64_t frame = 0;  // free once frames_in_flight frames have been recorded after this one
};

struct RetiredImage {
    vk::DeviceImage image;
    uint64_t frame = 0;
};

// A removed font's page ranges, free once the frames that may read them are done.
struct RetiredRanges {
    uint32_t page = 0;
    Range points, bands;
    uint64_t frame = 0;
};

struct RetireLists {
    std::vector<RetiredBuffer> buffers;
    std::vector<RetiredImage> images;  // smaller atlas images, until the GPU is done
    std::vector<RetiredRanges> ranges;

    // Frees the buffers, images and font ranges (given back to `fonts`) the GPU is done with
    // (frames_in_flight frames old).
    void release_finished(uint64_t this_frame, uint32_t frames_in_flight, FontStore& fonts);
    // The buffer `buffer` retired at `frame`, out of the list again; nullopt where there is none.
    std::optional<vk::DeviceBuffer> take_back(VkBuffer buffer, uint64_t frame);
    // The retired image `image`, out of the list again; nullopt where there is none.
    std::optional<vk::DeviceImage> take_back(VkImage image);
};

}  // namespace crisp::raster
