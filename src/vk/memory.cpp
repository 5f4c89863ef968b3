#include "vk/memory.hpp"

#include "vk/resources.hpp"

#include <algorithm>
#include <cassert>
#include <optional>
#include <string>

namespace crisp::vk {

MemoryArena::MemoryArena(const Functions& fn, VkDevice device, const VkAllocationCallbacks* allocator,
                         const VkPhysicalDeviceMemoryProperties& properties)
    : fn_(fn), device_(device), allocator_(allocator), properties_(properties) {}

MemoryArena::~MemoryArena() {
    for (const Block& block : blocks_) {
        assert(block.ranges == 0 && "a buffer outlived the arena its memory came from");
        fn_.vkFreeMemory(device_, block.memory, allocator_);  // also unmaps
    }
}

VkDeviceSize MemoryArena::block_bytes() const {
    VkDeviceSize bytes = 0;
    for (const Block& block : blocks_) bytes += block.size;
    return bytes;
}

bool MemoryArena::take(Block& block, const VkMemoryRequirements& requirements, VkDeviceSize& offset) {
    const std::optional<VkDeviceSize> at = block.free.take(requirements.size, requirements.alignment);
    if (!at) return false;
    offset = *at;
    ++block.ranges;
    return true;
}

Result<MemoryArena::Block*> MemoryArena::add_block(VkDeviceSize least, uint32_t type, const char* what) {
    const auto same_type =
        std::count_if(blocks_.begin(), blocks_.end(), [&](const Block& b) { return b.type == type; });
    const VkDeviceSize growing = std::min(kLargestMemoryBlock, kFirstMemoryBlock << std::min<long>(same_type, 8));
    Block block;
    block.type = type;
    // At least the request; one larger than half the largest block gets a block of its own, sized
    // to it, rather than one that would mostly stay empty.
    block.size = least > kLargestMemoryBlock / 2 ? least : std::max(growing, least);
    VkMemoryAllocateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    info.allocationSize = block.size;
    info.memoryTypeIndex = type;
    if (VkResult r = fn_.vkAllocateMemory(device_, &info, allocator_, &block.memory); r != VK_SUCCESS) {
        return vulkan_error(std::string("vkAllocateMemory (a memory block of ") + std::to_string(block.size) +
                                " bytes for the " + what + ")",
                            r);
    }
    if (properties_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
        void* mapped = nullptr;
        if (VkResult r = fn_.vkMapMemory(device_, block.memory, 0, VK_WHOLE_SIZE, 0, &mapped); r != VK_SUCCESS) {
            fn_.vkFreeMemory(device_, block.memory, allocator_);
            return vulkan_error(std::string("vkMapMemory (a memory block for the ") + what + ")", r);
        }
        block.mapped = static_cast<std::byte*>(mapped);
    }
    block.free = RangeAllocator(block.size);
    blocks_.push_back(std::move(block));
    return &blocks_.back();
}

Result<MemoryArena::Range> MemoryArena::allocate(const VkMemoryRequirements& requirements, uint32_t type,
                                                 const char* what) {
    VkDeviceSize offset = 0;
    Block* chosen = nullptr;
    for (Block& block : blocks_) {
        if (block.type == type && take(block, requirements, offset)) {
            chosen = &block;
            break;
        }
    }
    if (chosen == nullptr) {
        Result<Block*> added = add_block(requirements.size, type, what);
        if (!added) return added.error();
        chosen = *added;
        if (!take(*chosen, requirements, offset)) {  // a new block starts at offset 0: it always fits
            return Error{ErrorCode::vulkan, std::string("memory arena: a new block does not hold the ") + what};
        }
    }
    Range range;
    range.memory = chosen->memory;
    range.offset = offset;
    range.size = requirements.size;
    range.mapped = chosen->mapped != nullptr ? chosen->mapped + offset : nullptr;
    return range;
}

void MemoryArena::free(const Range& range) {
    if (range.memory == VK_NULL_HANDLE) return;
    auto block = std::find_if(blocks_.begin(), blocks_.end(), [&](const Block& b) { return b.memory == range.memory; });
    assert(block != blocks_.end() && "a range from another arena");
    if (block == blocks_.end()) return;
    block->free.give(range.offset, range.size);
    --block->ranges;
    // An empty block goes back to the driver, unless it is the last of its type and no larger than
    // kLargestMemoryBlock (the next buffer of that type, a frame later, would only allocate it
    // again): a block made for one large buffer (a CJK font's page) leaves with it.
    const uint32_t type = block->type;
    if (block->ranges == 0 &&
        (block->size > kLargestMemoryBlock ||
         std::count_if(blocks_.begin(), blocks_.end(), [&](const Block& b) { return b.type == type; }) > 1)) {
        fn_.vkFreeMemory(device_, block->memory, allocator_);
        blocks_.erase(block);
    }
}

}  // namespace crisp::vk
