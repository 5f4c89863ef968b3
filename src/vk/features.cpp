#include "vk/features.hpp"

#include <cstddef>
#include <cstring>
#include <iterator>
#include <span>

namespace crisp::vk {

namespace {

// Every VkBool32 member of each structure, so that a missing feature can be named. The
// static_asserts below fail when a newer header adds members the lists lack.
// clang-format off
#define CRISP_CORE_FEATURES(X) \
    X(robustBufferAccess) X(fullDrawIndexUint32) X(imageCubeArray) X(independentBlend) X(geometryShader) \
    X(tessellationShader) X(sampleRateShading) X(dualSrcBlend) X(logicOp) X(multiDrawIndirect) \
    X(drawIndirectFirstInstance) X(depthClamp) X(depthBiasClamp) X(fillModeNonSolid) X(depthBounds) X(wideLines) \
    X(largePoints) X(alphaToOne) X(multiViewport) X(samplerAnisotropy) X(textureCompressionETC2) \
    X(textureCompressionASTC_LDR) X(textureCompressionBC) X(occlusionQueryPrecise) X(pipelineStatisticsQuery) \
    X(vertexPipelineStoresAndAtomics) X(fragmentStoresAndAtomics) X(shaderTessellationAndGeometryPointSize) \
    X(shaderImageGatherExtended) X(shaderStorageImageExtendedFormats) X(shaderStorageImageMultisample) \
    X(shaderStorageImageReadWithoutFormat) X(shaderStorageImageWriteWithoutFormat) \
    X(shaderUniformBufferArrayDynamicIndexing) X(shaderSampledImageArrayDynamicIndexing) \
    X(shaderStorageBufferArrayDynamicIndexing) X(shaderStorageImageArrayDynamicIndexing) X(shaderClipDistance) \
    X(shaderCullDistance) X(shaderFloat64) X(shaderInt64) X(shaderInt16) X(shaderResourceResidency) \
    X(shaderResourceMinLod) X(sparseBinding) X(sparseResidencyBuffer) X(sparseResidencyImage2D) \
    X(sparseResidencyImage3D) X(sparseResidency2Samples) X(sparseResidency4Samples) X(sparseResidency8Samples) \
    X(sparseResidency16Samples) X(sparseResidencyAliased) X(variableMultisampleRate) X(inheritedQueries)

#define CRISP_VULKAN11_FEATURES(X) \
    X(storageBuffer16BitAccess) X(uniformAndStorageBuffer16BitAccess) X(storagePushConstant16) \
    X(storageInputOutput16) X(multiview) X(multiviewGeometryShader) X(multiviewTessellationShader) \
    X(variablePointersStorageBuffer) X(variablePointers) X(protectedMemory) X(samplerYcbcrConversion) \
    X(shaderDrawParameters)

#define CRISP_VULKAN12_FEATURES(X) \
    X(samplerMirrorClampToEdge) X(drawIndirectCount) X(storageBuffer8BitAccess) \
    X(uniformAndStorageBuffer8BitAccess) X(storagePushConstant8) X(shaderBufferInt64Atomics) \
    X(shaderSharedInt64Atomics) X(shaderFloat16) X(shaderInt8) X(descriptorIndexing) \
    X(shaderInputAttachmentArrayDynamicIndexing) X(shaderUniformTexelBufferArrayDynamicIndexing) \
    X(shaderStorageTexelBufferArrayDynamicIndexing) X(shaderUniformBufferArrayNonUniformIndexing) \
    X(shaderSampledImageArrayNonUniformIndexing) X(shaderStorageBufferArrayNonUniformIndexing) \
    X(shaderStorageImageArrayNonUniformIndexing) X(shaderInputAttachmentArrayNonUniformIndexing) \
    X(shaderUniformTexelBufferArrayNonUniformIndexing) X(shaderStorageTexelBufferArrayNonUniformIndexing) \
    X(descriptorBindingUniformBufferUpdateAfterBind) X(descriptorBindingSampledImageUpdateAfterBind) \
    X(descriptorBindingStorageImageUpdateAfterBind) X(descriptorBindingStorageBufferUpdateAfterBind) \
    X(descriptorBindingUniformTexelBufferUpdateAfterBind) X(descriptorBindingStorageTexelBufferUpdateAfterBind) \
    X(descriptorBindingUpdateUnusedWhilePending) X(descriptorBindingPartiallyBound) \
    X(descriptorBindingVariableDescriptorCount) X(runtimeDescriptorArray) X(samplerFilterMinmax) \
    X(scalarBlockLayout) X(imagelessFramebuffer) X(uniformBufferStandardLayout) X(shaderSubgroupExtendedTypes) \
    X(separateDepthStencilLayouts) X(hostQueryReset) X(timelineSemaphore) X(bufferDeviceAddress) \
    X(bufferDeviceAddressCaptureReplay) X(bufferDeviceAddressMultiDevice) X(vulkanMemoryModel) \
    X(vulkanMemoryModelDeviceScope) X(vulkanMemoryModelAvailabilityVisibilityChains) X(shaderOutputViewportIndex) \
    X(shaderOutputLayer) X(subgroupBroadcastDynamicId)

#define CRISP_VULKAN13_FEATURES(X) \
    X(robustImageAccess) X(inlineUniformBlock) X(descriptorBindingInlineUniformBlockUpdateAfterBind) \
    X(pipelineCreationCacheControl) X(privateData) X(shaderDemoteToHelperInvocation) X(shaderTerminateInvocation) \
    X(subgroupSizeControl) X(computeFullSubgroups) X(synchronization2) X(textureCompressionASTC_HDR) \
    X(shaderZeroInitializeWorkgroupMemory) X(dynamicRendering) X(shaderIntegerDotProduct) X(maintenance4)
// clang-format on

struct FeatureField {
    size_t offset;
    const char* name;
};

#define CRISP_CORE_FIELD(member) FeatureField{offsetof(VkPhysicalDeviceFeatures, member), #member},
#define CRISP_VULKAN11_FIELD(member) FeatureField{offsetof(VkPhysicalDeviceVulkan11Features, member), #member},
#define CRISP_VULKAN12_FIELD(member) FeatureField{offsetof(VkPhysicalDeviceVulkan12Features, member), #member},
#define CRISP_VULKAN13_FIELD(member) FeatureField{offsetof(VkPhysicalDeviceVulkan13Features, member), #member},

constexpr FeatureField kCoreFields[] = {CRISP_CORE_FEATURES(CRISP_CORE_FIELD)};
constexpr FeatureField kVulkan11Fields[] = {CRISP_VULKAN11_FEATURES(CRISP_VULKAN11_FIELD)};
constexpr FeatureField kVulkan12Fields[] = {CRISP_VULKAN12_FEATURES(CRISP_VULKAN12_FIELD)};
constexpr FeatureField kVulkan13Fields[] = {CRISP_VULKAN13_FEATURES(CRISP_VULKAN13_FIELD)};

#undef CRISP_CORE_FEATURES
#undef CRISP_VULKAN11_FEATURES
#undef CRISP_VULKAN12_FEATURES
#undef CRISP_VULKAN13_FEATURES
#undef CRISP_CORE_FIELD
#undef CRISP_VULKAN11_FIELD
#undef CRISP_VULKAN12_FIELD
#undef CRISP_VULKAN13_FIELD

// The structures hold nothing but VkBool32 members after sType and pNext (and tail padding to
// pointer alignment). A list must name them all: if a newer header adds members, the sizes stop
// matching (unless one new member exactly fills the padding).
constexpr size_t kChainHeader = offsetof(VkPhysicalDeviceVulkan11Features, storageBuffer16BitAccess);

template <class T, size_t N>
constexpr bool names_every_member(const FeatureField (&fields)[N], size_t header) {
    const size_t listed = header + N * sizeof(VkBool32);
    if (listed > sizeof(T) || sizeof(T) - listed >= alignof(T)) return false;
    for (size_t i = 0; i < N; ++i) {
        if (fields[i].offset < header || fields[i].offset >= listed) return false;
        for (size_t j = 0; j < i; ++j) {
            if (fields[i].offset == fields[j].offset) return false;
        }
    }
    return true;
}
static_assert(names_every_member<VkPhysicalDeviceFeatures>(kCoreFields, 0));
static_assert(names_every_member<VkPhysicalDeviceVulkan11Features>(kVulkan11Fields, kChainHeader));
static_assert(names_every_member<VkPhysicalDeviceVulkan12Features>(kVulkan12Fields, kChainHeader));
static_assert(names_every_member<VkPhysicalDeviceVulkan13Features>(kVulkan13Fields, kChainHeader));

VkBool32 read_field(const void* structure, size_t offset) {
    VkBool32 value = VK_FALSE;
    std::memcpy(&value, static_cast<const std::byte*>(structure) + offset, sizeof(value));
    return value;
}

void append_missing(const void* required, const void* offered, std::span<const FeatureField> fields,
                    std::vector<std::string>& missing) {
    for (const FeatureField& field : fields) {
        if (read_field(required, field.offset) && !read_field(offered, field.offset)) missing.emplace_back(field.name);
    }
}

bool any_field(const void* structure, std::span<const FeatureField> fields) {
    for (const FeatureField& field : fields) {
        if (read_field(structure, field.offset)) return true;
    }
    return false;
}

// Copies one caller structure over ours, keeping our sType and dropping the caller's pNext.
template <class T>
void copy_members(T& destination, const void* source) {
    void* next = destination.pNext;
    std::memcpy(&destination, source, sizeof(T));
    destination.pNext = next;
}

}  // namespace

DeviceFeatures::DeviceFeatures() : features2{}, vulkan11{}, vulkan12{}, vulkan13{} {
    features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    vulkan11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    vulkan12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
}

VkPhysicalDeviceFeatures2* DeviceFeatures::link(bool with_vulkan13) {
    features2.pNext = &vulkan11;
    vulkan11.pNext = &vulkan12;
    vulkan12.pNext = with_vulkan13 ? &vulkan13 : nullptr;
    vulkan13.pNext = nullptr;
    return &features2;
}

bool DeviceFeatures::any_vulkan13() const {
    return any_field(&vulkan13, kVulkan13Fields);
}

Result<DeviceFeatures> copy_required_features(const VkPhysicalDeviceFeatures2* chain, uint32_t api_version) {
    DeviceFeatures required;
    if (chain == nullptr) return required;
    if (chain->sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
        return Error{ErrorCode::invalid_argument,
                     "required_features must start with a VkPhysicalDeviceFeatures2 (sType " +
                         std::to_string(static_cast<int>(chain->sType)) + ")"};
    }
    required.features2.features = chain->features;
    bool seen11 = false, seen12 = false, seen13 = false;
    for (auto* next = static_cast<const VkBaseInStructure*>(chain->pNext); next != nullptr; next = next->pNext) {
        bool* seen = nullptr;
        switch (next->sType) {
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES:
                seen = &seen11;
                copy_members(required.vulkan11, next);
                break;
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES:
                seen = &seen12;
                copy_members(required.vulkan12, next);
                break;
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES:
                seen = &seen13;
                copy_members(required.vulkan13, next);
                break;
            default:
                return Error{ErrorCode::invalid_argument,
                             "required_features: unsupported structure in the pNext chain (sType " +
                                 std::to_string(static_cast<int>(next->sType)) +
                                 "); use VkPhysicalDeviceVulkan11Features, VkPhysicalDeviceVulkan12Features or "
                                 "VkPhysicalDeviceVulkan13Features"};
        }
        if (*seen) {
            return Error{ErrorCode::invalid_argument, "required_features: the same structure appears twice (sType " +
                                                          std::to_string(static_cast<int>(next->sType)) + ")"};
        }
        *seen = true;
    }
    if (required.any_vulkan13() && api_version < VK_API_VERSION_1_3) {
        return Error{ErrorCode::invalid_argument,
                     "required_features asks for Vulkan 1.3 features but api_version is below 1.3"};
    }
    return required;
}

Result<DeviceFeatures> read_enabled_features(const VkPhysicalDeviceFeatures2* chain, const char* who) {
    if (chain == nullptr || chain->sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
        return Error{ErrorCode::invalid_argument,
                     std::string(who) +
                         ": enabled_features must point at the VkPhysicalDeviceFeatures2 chain the "
                         "device was created with (crisp checks what the device enabled, not what "
                         "the GPU offers)"};
    }
    DeviceFeatures enabled;
    enabled.features2.features = chain->features;
    for (auto* next = static_cast<const VkBaseInStructure*>(chain->pNext); next != nullptr; next = next->pNext) {
        switch (next->sType) {
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES:
                copy_members(enabled.vulkan11, next);
                break;
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES:
                copy_members(enabled.vulkan12, next);
                break;
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES:
                copy_members(enabled.vulkan13, next);
                break;
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES: {
                VkPhysicalDeviceDynamicRenderingFeatures dynamic{};
                std::memcpy(&dynamic, next, sizeof(dynamic));
                if (dynamic.dynamicRendering) enabled.vulkan13.dynamicRendering = VK_TRUE;
                break;
            }
            case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR: {
                VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable{};
                std::memcpy(&executable, next, sizeof(executable));
                enabled.pipeline_executable_info = executable.pipelineExecutableInfo == VK_TRUE;
                break;
            }
            default:
                break;  // an extension's structure: not crisp's business
        }
    }
    return enabled;
}

DeviceFeatures query_features(const Functions& fn, VkPhysicalDevice device, bool with_vulkan13) {
    DeviceFeatures offered;
    fn.vkGetPhysicalDeviceFeatures2(device, offered.link(with_vulkan13));
    // The result is copied out; pointers into this local would dangle.
    offered.features2.pNext = nullptr;
    offered.vulkan11.pNext = nullptr;
    offered.vulkan12.pNext = nullptr;
    return offered;
}

std::vector<std::string> missing_features(const DeviceFeatures& required, const DeviceFeatures& offered) {
    std::vector<std::string> missing;
    append_missing(&required.features2.features, &offered.features2.features, kCoreFields, missing);
    append_missing(&required.vulkan11, &offered.vulkan11, kVulkan11Fields, missing);
    append_missing(&required.vulkan12, &offered.vulkan12, kVulkan12Fields, missing);
    append_missing(&required.vulkan13, &offered.vulkan13, kVulkan13Fields, missing);
    return missing;
}

}  // namespace crisp::vk
