#include "core/range_allocator.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <utility>
#include <vector>

namespace crisp {
namespace {

TEST(RangeAllocator, FirstFitAlignedAndMerged) {
    RangeAllocator ranges(100);
    EXPECT_EQ(ranges.take(10, 1), 0u);
    EXPECT_EQ(ranges.take(10, 8), 16u);  // aligned up past the first range
    EXPECT_EQ(ranges.take(0, 8), 0u);    // nothing taken
    EXPECT_EQ(ranges.take(30, 1), 26u);
    EXPECT_EQ(ranges.take(44, 1), 56u);  // the last byte too
    EXPECT_FALSE(ranges.take(1, 128));   // no room at any aligned offset
    ranges.give(16, 10);
    EXPECT_EQ(ranges.take(16, 1), 10u);  // the gap 10..26, merged from the alignment gap and the range given back
    ranges.give(0, 10);
    ranges.give(10, 16);
    ranges.give(26, 30);
    EXPECT_EQ(ranges.take(56, 1), 0u);  // all of 0..56 in one run again
    EXPECT_FALSE(RangeAllocator().take(1, 1));
}

// Against a map of bytes: a range goes to the lowest aligned offset with `size` free bytes.
TEST(RangeAllocator, TakesTheLowestAlignedOffsetThatFits) {
    constexpr uint64_t kCapacity = 512;
    std::mt19937 rng(22);
    RangeAllocator ranges(kCapacity);
    std::vector<bool> taken(kCapacity, false);
    std::vector<std::pair<uint64_t, uint64_t>> held;
    for (int step = 0; step < 20000; ++step) {
        if (!held.empty() && rng() % 3 == 0) {
            const size_t pick = rng() % held.size();
            const auto [offset, size] = held[pick];
            ranges.give(offset, size);
            for (uint64_t b = offset; b < offset + size; ++b) taken[b] = false;
            held.erase(held.begin() + static_cast<std::ptrdiff_t>(pick));
            continue;
        }
        const uint64_t size = 1 + rng() % 48;
        const uint64_t alignment = uint64_t{1} << (rng() % 5);
        std::optional<uint64_t> expected;
        for (uint64_t at = 0; at + size <= kCapacity && !expected; at += alignment) {
            bool free = true;
            for (uint64_t b = at; b < at + size && free; ++b) free = !taken[b];
            if (free) expected = at;
        }
        ASSERT_EQ(ranges.take(size, alignment), expected) << step;
        if (!expected) continue;
        for (uint64_t b = *expected; b < *expected + size; ++b) taken[b] = true;
        held.emplace_back(*expected, size);
    }
}

}  // namespace
}  // namespace crisp
