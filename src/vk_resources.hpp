// Private helpers shared by the Vulkan sources: error values and memory-type choice.
#pragma once

#include <crisp/result.hpp>

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace crisp::vk {

// ErrorCode::vulkan with "`call` failed: VK_ERROR_..." as the message.
Error vulkan_error(std::string_view call, VkResult result);

// The index of a memory type allowed by `type_bits` (VkMemoryRequirements::memoryTypeBits) that
// has every `required` flag, preferring one that also has every `preferred` flag; nullopt if none.
std::optional<uint32_t> find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, uint32_t type_bits,
                                         VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred);

// "1.3.230".
std::string version_string(uint32_t version);

}  // namespace crisp::vk
