// Private: a pass's descriptor bindings, declared once in a table that gives both its set layout
// and each frame's descriptor writes, so that the two cannot disagree on a binding's number, type
// or count.
#pragma once

#include "vk/resources.hpp"

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace crisp::vk {

// One binding of a pass's descriptor set, as its shaders declare it.
struct Binding {
    uint32_t number = 0;  // from shaders/shared.h
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    uint32_t count = 1;  // above 1: an array in the shaders
};

// The most bindings a table holds: DescriptorWrites keeps room for every one on the stack.
inline constexpr size_t kMaxBindings = 12;

// A pass's descriptor set: its bindings (a constant array in the pass's file, which must outlive
// the table), all visible to `stages`.
struct BindingTable {
    std::span<const Binding> bindings;
    VkShaderStageFlags stages = 0;

    // The table's bindings for vkCreateDescriptorSetLayout, in its order.
    std::vector<VkDescriptorSetLayoutBinding> layout_bindings() const;
    // Where binding `number` is in `bindings`; it must be there.
    size_t index_of(uint32_t number) const;
};

// create_descriptor_sets (vk/resources.hpp) for `table`'s bindings, with the push-constant range
// visible to the same stages.
Status create_descriptor_sets(const DeviceRef& device, const BindingTable& table, uint32_t push_bytes,
                              uint32_t set_count, const char* what, DescriptorSets& out);

// The writes of one descriptor set of `table`, every binding once, applied by one
// vkUpdateDescriptorSets in the table's order. Made on the stack for each update: it allocates
// nothing and keeps the single descriptors' infos itself, so it is neither copied nor moved.
// Debug builds assert that each write is to a binding of the table, with its type and count, and
// that update() finds every binding written exactly once.
class DescriptorWrites {
public:
    DescriptorWrites(const BindingTable& table, VkDescriptorSet set);
    DescriptorWrites(const DescriptorWrites&) = delete;
    DescriptorWrites& operator=(const DescriptorWrites&) = delete;

    // `view` as the one storage image of `binding`, in `layout` when the set is used.
    DescriptorWrites& storage_image(uint32_t binding, VkImageView view, VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL);
    // `range` bytes of `buffer` from `offset` as the one storage buffer of `binding`.
    DescriptorWrites& storage_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset = 0,
                                     VkDeviceSize range = VK_WHOLE_SIZE);
    // `view` and `sampler` as the one combined image sampler of `binding`, in `layout`.
    DescriptorWrites& sampled_image(uint32_t binding, VkImageView view, VkSampler sampler,
                                    VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    // Every element of an array binding: `infos` (one per descriptor the table declares) stay the
    // caller's, and must live until update().
    DescriptorWrites& storage_buffers(uint32_t binding, std::span<const VkDescriptorBufferInfo> infos);

    void update(const DeviceRef& device) const;

private:
    // Marks the write of `binding` written and returns its index, asserting that the binding is
    // declared with `type` and `count` and was not written before.
    size_t write(uint32_t binding, VkDescriptorType type, uint32_t count);
    // The one image descriptor of `binding`, of `type`.
    DescriptorWrites& image(uint32_t binding, VkDescriptorType type, const VkDescriptorImageInfo& info);

    const BindingTable& table_;
    std::array<VkWriteDescriptorSet, kMaxBindings> writes_{};  // at their bindings' places in the table
    std::array<VkDescriptorImageInfo, kMaxBindings> images_{};
    std::array<VkDescriptorBufferInfo, kMaxBindings> buffers_{};
};

}  // namespace crisp::vk
