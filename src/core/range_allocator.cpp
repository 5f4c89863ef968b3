#include "core/range_allocator.hpp"

#include <iterator>

namespace crisp {

RangeAllocator::RangeAllocator(uint64_t capacity) : capacity_(capacity) {
    if (capacity > 0) free_.emplace(0, capacity);
}

bool RangeAllocator::all_free() const {
    return capacity_ == 0 || (free_.size() == 1 && free_.begin()->first == 0 && free_.begin()->second == capacity_);
}

// First fit: the lowest free run that holds the aligned request.
std::optional<uint64_t> RangeAllocator::take(uint64_t size, uint64_t alignment) {
    if (size == 0) return uint64_t{0};
    for (auto it = free_.begin(); it != free_.end(); ++it) {
        const uint64_t start = alignment <= 1 ? it->first : (it->first + alignment - 1) / alignment * alignment;
        const uint64_t end = it->first + it->second;
        if (start > end || end - start < size) continue;
        const uint64_t run_start = it->first;
        free_.erase(it);
        if (start > run_start) free_.emplace(run_start, start - run_start);
        if (end > start + size) free_.emplace(start + size, end - start - size);
        return start;
    }
    return std::nullopt;
}

void RangeAllocator::give(uint64_t offset, uint64_t size) {
    if (size == 0) return;
    // Back into the free list, merged with the runs on either side.
    uint64_t start = offset;
    auto next = free_.lower_bound(start);
    if (next != free_.end() && next->first == start + size) {
        size += next->second;
        next = free_.erase(next);
    }
    if (next != free_.begin()) {
        auto previous = std::prev(next);
        if (previous->first + previous->second == start) {
            start = previous->first;
            size += previous->second;
            free_.erase(previous);
        }
    }
    free_.emplace(start, size);
}

}  // namespace crisp
