// A pass's descriptor bindings, declared once (vk/bindings.hpp).
#include "vk/bindings.hpp"

#include <algorithm>
#include <cassert>

namespace crisp::vk {

std::vector<VkDescriptorSetLayoutBinding> BindingTable::layout_bindings() const {
    std::vector<VkDescriptorSetLayoutBinding> out;
    out.reserve(bindings.size());
    for (const Binding& binding : bindings) {
        out.push_back({binding.number, binding.type, binding.count, stages, nullptr});
    }
    return out;
}

size_t BindingTable::index_of(uint32_t number) const {
    const auto found = std::find_if(bindings.begin(), bindings.end(),
                                    [&](const Binding& binding) { return binding.number == number; });
    assert(found != bindings.end() && "the binding is not in the pass's table");
    return static_cast<size_t>(found - bindings.begin());
}

Status create_descriptor_sets(const DeviceRef& device, const BindingTable& table, uint32_t push_bytes,
                              uint32_t set_count, const char* what, DescriptorSets& out) {
    const std::vector<VkDescriptorSetLayoutBinding> bindings = table.layout_bindings();
    return create_descriptor_sets(device, bindings, table.stages, push_bytes, set_count, what, out);
}

// Each write starts as the table declares its binding; write() sets its sType, which marks it written.
DescriptorWrites::DescriptorWrites(const BindingTable& table, VkDescriptorSet set) : table_(table) {
    assert(table.bindings.size() <= kMaxBindings && "a table of more bindings than DescriptorWrites holds");
    for (size_t i = 0; i < table.bindings.size(); ++i) {
        writes_[i].dstSet = set;
        writes_[i].dstBinding = table.bindings[i].number;
        writes_[i].descriptorType = table.bindings[i].type;
        writes_[i].descriptorCount = table.bindings[i].count;
    }
}

size_t DescriptorWrites::write(uint32_t binding, [[maybe_unused]] VkDescriptorType type,
                               [[maybe_unused]] uint32_t count) {
    const size_t index = table_.index_of(binding);
    VkWriteDescriptorSet& write = writes_[index];
    assert(write.sType != VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET && "the binding is written twice");
    assert(write.descriptorType == type && "the binding is declared with another descriptor type");
    assert(write.descriptorCount == count && "the binding is declared with another descriptor count");
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    return index;
}

DescriptorWrites& DescriptorWrites::image(uint32_t binding, VkDescriptorType type, const VkDescriptorImageInfo& info) {
    const size_t i = write(binding, type, 1);
    images_[i] = info;
    writes_[i].pImageInfo = &images_[i];
    return *this;
}

DescriptorWrites& DescriptorWrites::storage_image(uint32_t binding, VkImageView view, VkImageLayout layout) {
    return image(binding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, {VK_NULL_HANDLE, view, layout});
}

DescriptorWrites& DescriptorWrites::sampled_image(uint32_t binding, VkImageView view, VkSampler sampler,
                                                  VkImageLayout layout) {
    return image(binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, {sampler, view, layout});
}

DescriptorWrites& DescriptorWrites::storage_buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset,
                                                   VkDeviceSize range) {
    const size_t i = write(binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1);
    buffers_[i] = {buffer, offset, range};
    writes_[i].pBufferInfo = &buffers_[i];
    return *this;
}

DescriptorWrites& DescriptorWrites::storage_buffers(uint32_t binding, std::span<const VkDescriptorBufferInfo> infos) {
    const size_t i = write(binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, static_cast<uint32_t>(infos.size()));
    writes_[i].pBufferInfo = infos.data();
    return *this;
}

void DescriptorWrites::update(const DeviceRef& device) const {
    const uint32_t count = static_cast<uint32_t>(table_.bindings.size());
    assert(std::all_of(writes_.begin(), writes_.begin() + count,
                       [](const VkWriteDescriptorSet& write) {
                           return write.sType == VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
                       }) &&
           "a binding of the table is not written");
    device.fn->vkUpdateDescriptorSets(device.device, count, writes_.data(), 0, nullptr);
}

}  // namespace crisp::vk
