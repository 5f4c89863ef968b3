// Private: first-fit placement of byte ranges in a span of fixed size: the blocks of a
// vk::MemoryArena and the buffers of the renderer's font pages place their ranges with it.
#pragma once

#include <cstdint>
#include <map>
#include <optional>

namespace crisp {

class RangeAllocator {
public:
    RangeAllocator() = default;  // no room at all
    explicit RangeAllocator(uint64_t capacity);

    // The offset of `size` bytes at a multiple of `alignment` (0 and 1: any offset) in the lowest
    // free run that holds them (first fit), now taken; nullopt when no run does. A zero size takes
    // nothing and is at offset 0.
    std::optional<uint64_t> take(uint64_t size, uint64_t alignment);
    // Gives back a range take() returned (a zero size: nothing).
    void give(uint64_t offset, uint64_t size);
    // Whether every range taken has been given back (true for one with no room at all).
    bool all_free() const;

private:
    std::map<uint64_t, uint64_t> free_;  // offset -> size, neighbours merged
    uint64_t capacity_ = 0;
};

}  // namespace crisp
