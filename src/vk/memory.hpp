// Private: buffer memory suballocated from a few large blocks.
//
// Each renderer and compositor owns one MemoryArena. Its buffers take ranges of blocks, one list of
// blocks per memory type; a block is a single VkDeviceMemory, mapped once for good where the type
// is host-visible. Blocks grow as they are added (4, 8, 16, 32, then 64 MiB), so a small renderer
// holds a few MiB and a large one a handful of blocks; a request larger than half the largest
// block gets a block of its own. An emptied block is freed unless it is the last of its type.
// Images are not suballocated: the atlas is one large allocation already, and keeping images out of
// the blocks keeps bufferImageGranularity out of them too.
#pragma once

#include "core/range_allocator.hpp"
#include "vk/functions.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace crisp::vk {

inline constexpr VkDeviceSize kFirstMemoryBlock = VkDeviceSize{4} << 20;
inline constexpr VkDeviceSize kLargestMemoryBlock = VkDeviceSize{64} << 20;

class MemoryArena {
public:
    struct Range {
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkDeviceSize offset = 0;
        VkDeviceSize size = 0;
        void* mapped = nullptr;  // at `offset`; null where the type is not host-visible
    };

    MemoryArena(const Functions& fn, VkDevice device, const VkAllocationCallbacks* allocator,
                const VkPhysicalDeviceMemoryProperties& properties);
    MemoryArena(const MemoryArena&) = delete;
    MemoryArena& operator=(const MemoryArena&) = delete;
    ~MemoryArena();  // frees every block; every range must have been given back

    // A range of memory type `type` meeting `requirements` (size and alignment), from a block
    // that has room or a new one. Errors: vulkan (vkAllocateMemory or vkMapMemory failed, named
    // with `what`).
    Result<Range> allocate(const VkMemoryRequirements& requirements, uint32_t type, const char* what);
    // Gives `range` back (a default Range is ignored).
    void free(const Range& range);

    // VkDeviceMemory objects held, and their bytes.
    uint32_t block_count() const { return static_cast<uint32_t>(blocks_.size()); }
    VkDeviceSize block_bytes() const;

private:
    struct Block {
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkDeviceSize size = 0;
        uint32_t type = 0;
        std::byte* mapped = nullptr;
        RangeAllocator free;  // its free runs
        uint32_t ranges = 0;  // handed out and not yet given back
    };

    Result<Block*> add_block(VkDeviceSize least, uint32_t type, const char* what);
    static bool take(Block& block, const VkMemoryRequirements& requirements, VkDeviceSize& offset);

    const Functions& fn_;
    VkDevice device_;
    const VkAllocationCallbacks* allocator_;
    VkPhysicalDeviceMemoryProperties properties_;
    std::vector<Block> blocks_;
};

}  // namespace crisp::vk
