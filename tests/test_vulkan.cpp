// HeadlessContext on a real Vulkan driver (Mesa lavapipe in CI): device choice, feature and
// extension checks, validation plumbing, transfers, and a compute shader using subgroup arithmetic.
// Every test that creates a context with validation on also asserts that the layer stayed silent.

#include "embedded_shaders.hpp"
#include "headless_context.hpp"
#include "shared.h"
#include "test_support.hpp"
#include "vk/features.hpp"
#include "vk/memory.hpp"
#include "vk/resources.hpp"

#include <crisp/compositor.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace crisp {
namespace {

using gpu::SelftestPushConstants;
using gpu::SelftestResult;

// True when the loader finds at least one physical device; the only reason a test here may skip.
bool vulkan_device_exists() {
    VkApplicationInfo application{};
    application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    application.apiVersion = VK_API_VERSION_1_0;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &application;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return false;
    uint32_t count = 0;
    const VkResult result = vkEnumeratePhysicalDevices(instance, &count, nullptr);
    vkDestroyInstance(instance, nullptr);
    return result == VK_SUCCESS && count > 0;
}

class VulkanTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (!vulkan_device_exists()) {
            GTEST_SKIP() << "no Vulkan device, not even a CPU one (Debian: apt install mesa-vulkan-drivers)";
        }
    }
};

HeadlessContextOptions validated_options() {
    HeadlessContextOptions options;
    options.validation = true;
    options.synchronization_validation = true;
    return options;
}

std::string describe(const ValidationMessages& messages) {
    std::string text = std::to_string(messages.errors) + " errors, " + std::to_string(messages.warnings) +
                       " warnings; the last messages:";
    for (const std::string& message : messages.recent) text += "\n  " + message;
    return text;
}

void expect_no_validation_messages(const HeadlessContext& context) {
    const ValidationMessages messages = context.validation_messages();
    EXPECT_EQ(messages.errors, 0u) << describe(messages);
    EXPECT_EQ(messages.warnings, 0u) << describe(messages);
}

// The Khronos validation layer of Debian 12 (1.3.239) leaks a few objects per device when
// synchronization validation is on. tests/lsan.supp suppresses them by the layer's module name,
// which LeakSanitizer can only resolve at exit if the layer is still mapped; the loader unloads it
// with the last instance, so it is pinned once it has been loaded. Not needed without sanitizers,
// and harmless there.
void keep_validation_layer_mapped() {
    static bool pinned = false;
    if (!pinned) pinned = dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE) != nullptr;
}

// Declares `name`, a HeadlessContext& created from `options`, or fails the test with the reason.
#define CRISP_CREATE_CONTEXT(name, options)                                   \
    Result<HeadlessContext> name##_result = HeadlessContext::create(options); \
    ASSERT_TRUE(name##_result.ok()) << name##_result.error().message;         \
    keep_validation_layer_mapped();                                           \
    HeadlessContext& name = name##_result.value()

template <class T>
std::span<const std::byte> as_bytes_of(const std::vector<T>& values) {
    return std::as_bytes(std::span<const T>(values));
}

// Matches lowbias32 in selftest.comp.
uint32_t lowbias32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// The objects of one compute pipeline with one storage buffer at binding 0 and push constants,
// made with the library's own helpers (vk/resources.hpp), destroyed in reverse order of creation.
struct ComputeKernel {
    vk::DeviceRef device;
    VkShaderModule module = VK_NULL_HANDLE;
    vk::DescriptorSets descriptors;  // one set
    VkPipeline pipeline = VK_NULL_HANDLE;

    ComputeKernel() = default;
    ComputeKernel(const ComputeKernel&) = delete;
    ComputeKernel& operator=(const ComputeKernel&) = delete;
    ~ComputeKernel() {
        if (device.device == VK_NULL_HANDLE) return;
        vkDestroyPipeline(device.device, pipeline, nullptr);
        descriptors.reset();
        vkDestroyShaderModule(device.device, module, nullptr);
    }
};

// Builds `kernel` for the test shader `name`, bound to `storage`.
Status create_kernel(ComputeKernel& kernel, const HeadlessContext& context, const char* name,
                     uint32_t push_constant_size, const Buffer& storage) {
    const test_shaders::EmbeddedShader* shader = test_shaders::find_embedded_shader(name);
    if (shader == nullptr) return Error{ErrorCode::vulkan, std::string(name) + " is not embedded"};
    kernel.device =
        vk::make_device_ref(context.functions(), context.physical_device(), context.device(), nullptr, VK_NULL_HANDLE);
    const VkDevice device = context.device();

    VkShaderModuleCreateInfo module_info{};
    module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    module_info.codeSize = shader->size;
    module_info.pCode = shader->code;
    if (VkResult r = vkCreateShaderModule(device, &module_info, nullptr, &kernel.module); r != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateShaderModule", r);
    }
    const VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                                               nullptr};
    if (Status s = vk::create_descriptor_sets(kernel.device, std::span(&binding, 1), VK_SHADER_STAGE_COMPUTE_BIT,
                                              push_constant_size, 1, name, kernel.descriptors);
        !s) {
        return s;
    }
    Result<VkPipeline> pipeline =
        vk::create_compute_pipeline(kernel.device, kernel.module, kernel.descriptors.pipeline_layout, nullptr, name);
    if (!pipeline) return pipeline.error();
    kernel.pipeline = *pipeline;

    VkDescriptorBufferInfo buffer_info{};
    buffer_info.buffer = storage.handle();
    buffer_info.range = VK_WHOLE_SIZE;
    VkWriteDescriptorSet write{};
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    write.dstSet = kernel.descriptors.sets[0];
    write.dstBinding = 0;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    write.pBufferInfo = &buffer_info;
    vkUpdateDescriptorSets(device, 1, &write, 0, nullptr);
    return {};
}

// Runs selftest.comp over `count` invocations and returns what it wrote (empty after a failure,
// which is recorded).
std::vector<SelftestResult> run_selftest(HeadlessContext& context, uint32_t count, uint32_t seed) {
    Result<Buffer> results = context.create_buffer(
        VkDeviceSize{count} * sizeof(SelftestResult),
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::device_local);
    if (!results) {
        ADD_FAILURE() << results.error().message;
        return {};
    }
    ComputeKernel kernel;
    if (Status s = create_kernel(kernel, context, "selftest.comp", sizeof(SelftestPushConstants), *results); !s) {
        ADD_FAILURE() << "creating the selftest pipeline: " << s.error().message;
        return {};
    }
    const SelftestPushConstants push{count, seed};
    Status ran = context.submit_and_wait([&](VkCommandBuffer commands) {
        vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.pipeline);
        vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.descriptors.pipeline_layout, 0, 1,
                                &kernel.descriptors.sets[0], 0, nullptr);
        vkCmdPushConstants(commands, kernel.descriptors.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push),
                           &push);
        vkCmdDispatch(commands, (count + gpu::kSelftestWorkgroupSize - 1) / gpu::kSelftestWorkgroupSize, 1, 1);
    });
    if (!ran) {
        ADD_FAILURE() << ran.error().message;
        return {};
    }
    Result<std::vector<std::byte>> bytes = context.read_buffer(*results, 0, results->size());
    if (!bytes) {
        ADD_FAILURE() << bytes.error().message;
        return {};
    }
    std::vector<SelftestResult> values(count);
    std::memcpy(values.data(), bytes->data(), bytes->size());
    return values;
}

// Recomputes on the CPU what selftest.comp wrote: every value, and each subgroup's min, max and
// active count, with subgroups identified by the keys the shader reported.
void check_selftest(const std::vector<SelftestResult>& results, uint32_t count, uint32_t seed, uint32_t subgroup_size) {
    ASSERT_EQ(results.size(), count);
    std::map<uint32_t, std::vector<uint32_t>> members;  // subgroup key -> invocation indices
    for (uint32_t i = 0; i < count; ++i) {
        ASSERT_EQ(results[i].value, lowbias32(i ^ seed)) << "invocation " << i;
        ASSERT_EQ(results[i].subgroup_size, subgroup_size) << "invocation " << i;
        members[results[i].subgroup_key].push_back(i);
    }
    // Subgroups are never wider than their size, so there are at least this many.
    EXPECT_GE(members.size(), (count + subgroup_size - 1) / subgroup_size);
    for (const auto& [key, indices] : members) {
        ASSERT_LE(indices.size(), subgroup_size) << "subgroup " << key;
        uint32_t low = UINT32_MAX;
        uint32_t high = 0;
        for (uint32_t i : indices) {
            low = std::min(low, results[i].value);
            high = std::max(high, results[i].value);
            // A subgroup never spans workgroups.
            ASSERT_EQ(i / gpu::kSelftestWorkgroupSize, indices.front() / gpu::kSelftestWorkgroupSize);
        }
        for (uint32_t i : indices) {
            ASSERT_EQ(results[i].subgroup_min, low) << "invocation " << i << ", subgroup " << key;
            ASSERT_EQ(results[i].subgroup_max, high) << "invocation " << i << ", subgroup " << key;
            ASSERT_EQ(results[i].active_count, indices.size()) << "invocation " << i << ", subgroup " << key;
        }
    }
}

// A count that leaves the last workgroup and its last subgroup partly idle.
constexpr uint32_t kSelftestCount = 1000;

TEST_F(VulkanTest, ContextDescribesItsDevice) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    EXPECT_NE(context.instance(), VK_NULL_HANDLE);
    EXPECT_NE(context.physical_device(), VK_NULL_HANDLE);
    EXPECT_NE(context.device(), VK_NULL_HANDLE);
    EXPECT_NE(context.queue(), VK_NULL_HANDLE);
    EXPECT_EQ(context.allocation_callbacks(), nullptr);
    EXPECT_FALSE(context.device_name().empty());
    EXPECT_FALSE(context.driver_name().empty());
    EXPECT_GE(context.api_version(), VK_API_VERSION_1_2);
    EXPECT_LE(VK_API_VERSION_MINOR(context.api_version()), 2u) << "capped at the requested api_version";
    EXPECT_GT(context.subgroup_properties().subgroupSize, 0u);
    EXPECT_TRUE(context.enabled_extensions().empty());
    std::printf("device: %s; driver: %s, %s (driver version 0x%x); Vulkan %u.%u; subgroup size %u\n",
                context.device_name().c_str(), context.driver_name().c_str(), context.driver_info().c_str(),
                context.driver_version(), VK_API_VERSION_MAJOR(context.properties().apiVersion),
                VK_API_VERSION_MINOR(context.properties().apiVersion), context.subgroup_properties().subgroupSize);
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, SelftestShaderComputesSubgroupMinMax) {
    HeadlessContextOptions options = validated_options();
    options.required_compute_subgroup_operations = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    CRISP_CREATE_CONTEXT(context, options);
    ASSERT_TRUE(context.supports_compute_subgroup_arithmetic());
    const uint32_t seed = 0x9e3779b9u;
    check_selftest(run_selftest(context, kSelftestCount, seed), kSelftestCount, seed,
                   context.subgroup_properties().subgroupSize);
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, BufferUploadAndReadback) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    // An odd size, so nothing lines up with a word or a page.
    std::vector<std::byte> bytes(1'000'003);
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::byte>(lowbias32(static_cast<uint32_t>(i)));

    Result<Buffer> buffer =
        context.create_buffer_with_data(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    ASSERT_TRUE(buffer.ok()) << buffer.error().message;
    EXPECT_TRUE(buffer->mapped().empty()) << "device-local buffers are not mapped";
    Result<std::vector<std::byte>> whole = context.read_buffer(*buffer, 0, buffer->size());
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    EXPECT_TRUE(*whole == bytes);

    // Overwrite a range in the middle, then read around it.
    const std::vector<std::byte> patch(777, std::byte{0xa5});
    ASSERT_TRUE(context.upload(*buffer, patch, 5000).ok());
    std::copy(patch.begin(), patch.end(), bytes.begin() + 5000);
    Result<std::vector<std::byte>> part = context.read_buffer(*buffer, 4000, 3000);
    ASSERT_TRUE(part.ok()) << part.error().message;
    EXPECT_TRUE(std::equal(part->begin(), part->end(), bytes.begin() + 4000));

    // Host-visible buffers are mapped and read back directly.
    Result<Buffer> readback = context.create_buffer(64, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::readback);
    ASSERT_TRUE(readback.ok()) << readback.error().message;
    ASSERT_EQ(readback->mapped().size(), 64u);
    ASSERT_TRUE(context
                    .submit_and_wait([&](VkCommandBuffer commands) {
                        vkCmdFillBuffer(commands, readback->handle(), 0, VK_WHOLE_SIZE, 0x01020304u);
                    })
                    .ok());
    Result<std::vector<std::byte>> filled = context.read_buffer(*readback, 60, 4);
    ASSERT_TRUE(filled.ok()) << filled.error().message;
    uint32_t word = 0;
    std::memcpy(&word, filled->data(), 4);
    EXPECT_EQ(word, 0x01020304u);

    // Ranges past the end are refused, not clamped.
    Result<std::vector<std::byte>> past_end = context.read_buffer(*buffer, buffer->size() - 1, 2);
    ASSERT_FALSE(past_end.ok());
    EXPECT_EQ(past_end.error().code, ErrorCode::invalid_argument);
    EXPECT_FALSE(context.upload(*buffer, patch, UINT64_MAX - 10).ok()) << "offset + size overflows";
    EXPECT_FALSE(context.create_buffer(0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::device_local).ok());
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, ImageUploadAndReadback) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    const VkImageUsageFlags usage =
        VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_STORAGE_BIT;

    // 8-bit RGBA, odd extent.
    Result<Image> rgba8 = context.create_image({VK_FORMAT_R8G8B8A8_UNORM, 37, 19, usage});
    ASSERT_TRUE(rgba8.ok()) << rgba8.error().message;
    EXPECT_NE(rgba8->view(), VK_NULL_HANDLE);
    std::vector<std::byte> texels(37 * 19 * 4);
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<std::byte>(i * 7 + 3);
    ASSERT_TRUE(context.upload(*rgba8, texels, VK_IMAGE_LAYOUT_GENERAL).ok());
    Result<std::vector<std::byte>> rgba8_back = context.read_image(*rgba8, VK_IMAGE_LAYOUT_GENERAL);
    ASSERT_TRUE(rgba8_back.ok()) << rgba8_back.error().message;
    EXPECT_TRUE(*rgba8_back == texels);

    // 32-bit float RGBA: bit patterns survive (negative, tiny, huge).
    Result<Image> rgba32f = context.create_image({VK_FORMAT_R32G32B32A32_SFLOAT, 5, 3, usage});
    ASSERT_TRUE(rgba32f.ok()) << rgba32f.error().message;
    std::vector<float> floats(5 * 3 * 4);
    for (size_t i = 0; i < floats.size(); ++i) floats[i] = (i % 2 ? -1.0f : 1.0f) * static_cast<float>(i) * 1e-3f;
    floats[7] = 3.0e38f;
    floats[8] = 1.0e-40f;  // subnormal
    ASSERT_TRUE(context.upload(*rgba32f, as_bytes_of(floats), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL).ok());
    Result<std::vector<std::byte>> rgba32f_back = context.read_image(*rgba32f, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    ASSERT_TRUE(rgba32f_back.ok()) << rgba32f_back.error().message;
    ASSERT_EQ(rgba32f_back->size(), floats.size() * sizeof(float));
    EXPECT_EQ(std::memcmp(rgba32f_back->data(), floats.data(), rgba32f_back->size()), 0);

    // A GPU write (a clear) is visible to the readback that follows.
    ASSERT_TRUE(context
                    .submit_and_wait([&](VkCommandBuffer commands) {
                        VkImageMemoryBarrier barrier{};
                        barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
                        barrier.srcAccessMask = 0;
                        barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
                        barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
                        barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                        barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                        barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                        barrier.image = rgba32f->handle();
                        barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                        vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                             0, 0, nullptr, 0, nullptr, 1, &barrier);
                        VkClearColorValue color{};
                        color.float32[0] = 0.25f;
                        color.float32[1] = -2.0f;
                        color.float32[2] = 1024.5f;
                        color.float32[3] = 1.0f;
                        vkCmdClearColorImage(commands, rgba32f->handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color,
                                             1, &barrier.subresourceRange);
                    })
                    .ok());
    Result<std::vector<std::byte>> cleared = context.read_image(*rgba32f, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    ASSERT_TRUE(cleared.ok()) << cleared.error().message;
    std::vector<float> cleared_floats(cleared->size() / sizeof(float));
    std::memcpy(cleared_floats.data(), cleared->data(), cleared->size());
    for (size_t i = 0; i < cleared_floats.size(); i += 4) {
        ASSERT_EQ(cleared_floats[i + 0], 0.25f);
        ASSERT_EQ(cleared_floats[i + 1], -2.0f);
        ASSERT_EQ(cleared_floats[i + 2], 1024.5f);
        ASSERT_EQ(cleared_floats[i + 3], 1.0f);
    }

    // Wrong sizes and missing usages are refused.
    EXPECT_FALSE(context.upload(*rgba8, std::span(texels).first(10), VK_IMAGE_LAYOUT_GENERAL).ok());
    Result<Image> sampled_only = context.create_image({VK_FORMAT_R8G8B8A8_UNORM, 4, 4, VK_IMAGE_USAGE_SAMPLED_BIT});
    ASSERT_TRUE(sampled_only.ok()) << sampled_only.error().message;
    EXPECT_FALSE(context.read_image(*sampled_only, VK_IMAGE_LAYOUT_GENERAL).ok());
    EXPECT_FALSE(context.create_image({VK_FORMAT_R8G8B8A8_UNORM, 0, 4, usage}).ok());
    EXPECT_FALSE(context.create_image({VK_FORMAT_D32_SFLOAT, 4, 4, usage}).ok());
    expect_no_validation_messages(context);
}

// A pointer to one VkBool32 member of the feature structures, with its name.
struct FeatureProbe {
    const char* name;
    VkBool32 VkPhysicalDeviceFeatures::*core = nullptr;
    VkBool32 VkPhysicalDeviceVulkan11Features::*vulkan11 = nullptr;
    VkBool32 VkPhysicalDeviceVulkan12Features::*vulkan12 = nullptr;
};

struct FeatureChain {
    VkPhysicalDeviceFeatures2 features2{};
    VkPhysicalDeviceVulkan11Features vulkan11{};
    VkPhysicalDeviceVulkan12Features vulkan12{};
    FeatureChain() {
        features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        vulkan11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
        vulkan12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
        features2.pNext = &vulkan11;
        vulkan11.pNext = &vulkan12;
    }
    FeatureChain(const FeatureChain&) = delete;
    FeatureChain& operator=(const FeatureChain&) = delete;
    VkBool32& operator[](const FeatureProbe& probe) {
        if (probe.core) return features2.features.*probe.core;
        if (probe.vulkan11) return vulkan11.*probe.vulkan11;
        return vulkan12.*probe.vulkan12;
    }
};

TEST_F(VulkanTest, AbsentFeatureIsNamed) {
    // What lavapipe (Mesa 22.3) reports false, one per structure; the test asks only for those the
    // device at hand lacks, on that device.
    const FeatureProbe probes[] = {
        {"sparseBinding", &VkPhysicalDeviceFeatures::sparseBinding, nullptr, nullptr},
        {"samplerYcbcrConversion", nullptr, &VkPhysicalDeviceVulkan11Features::samplerYcbcrConversion, nullptr},
        {"descriptorIndexing", nullptr, nullptr, &VkPhysicalDeviceVulkan12Features::descriptorIndexing},
    };
    CRISP_CREATE_CONTEXT(baseline, HeadlessContextOptions{});
    FeatureChain offered;
    vkGetPhysicalDeviceFeatures2(baseline.physical_device(), &offered.features2);

    int tested = 0;
    for (const FeatureProbe& probe : probes) {
        if (offered[probe]) continue;
        ++tested;
        FeatureChain required;
        required[probe] = VK_TRUE;
        HeadlessContextOptions options = validated_options();
        options.device_name_contains = baseline.device_name();
        options.required_features = &required.features2;
        Result<HeadlessContext> context = HeadlessContext::create(options);
        ASSERT_FALSE(context.ok()) << probe.name;
        EXPECT_EQ(context.error().code, ErrorCode::vulkan);
        EXPECT_NE(context.error().message.find(std::string("the device lacks ") + probe.name), std::string::npos)
            << context.error().message;
        EXPECT_NE(context.error().message.find(baseline.device_name()), std::string::npos) << context.error().message;
    }
    if (tested == 0) GTEST_SKIP() << baseline.device_name() << " offers every probed feature";
}

TEST_F(VulkanTest, OfferedFeaturesAreEnabled) {
    CRISP_CREATE_CONTEXT(baseline, HeadlessContextOptions{});
    FeatureChain offered;
    vkGetPhysicalDeviceFeatures2(baseline.physical_device(), &offered.features2);
    if (!offered.vulkan12.shaderBufferInt64Atomics || !offered.vulkan12.timelineSemaphore) {
        GTEST_SKIP() << baseline.device_name() << " lacks shaderBufferInt64Atomics or timelineSemaphore";
    }
    FeatureChain required;
    required.vulkan12.shaderBufferInt64Atomics = VK_TRUE;
    required.vulkan12.timelineSemaphore = VK_TRUE;
    HeadlessContextOptions options = validated_options();
    options.device_name_contains = baseline.device_name();
    options.required_features = &required.features2;
    CRISP_CREATE_CONTEXT(context, options);

    // The feature is usable: creating a timeline semaphore without it is a validation error.
    VkSemaphoreTypeCreateInfo type_info{};
    type_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO;
    type_info.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    semaphore_info.pNext = &type_info;
    VkSemaphore semaphore = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateSemaphore(context.device(), &semaphore_info, nullptr, &semaphore), VK_SUCCESS);
    vkDestroySemaphore(context.device(), semaphore, nullptr);
    expect_no_validation_messages(context);
}

// crisp_needs enables what add_crisp_features() adds for the chosen device, as an engine would get
// it: the parts asked for, storage_without_format only where offered, Vulkan 1.3 for the draw path.
TEST_F(VulkanTest, CrispNeedsAreEnabledAsAnEngineWould) {
    HeadlessContextOptions options = validated_options();
    options.crisp_needs = CrispFeatureNeeds{.draw_path = true, .reference_modes = true, .storage_without_format = true};
    CRISP_CREATE_CONTEXT(context, options);
    EXPECT_GE(context.api_version(), VK_API_VERSION_1_3);
    const VkPhysicalDeviceFeatures2* enabled = context.enabled_features();
    ASSERT_NE(enabled, nullptr);
    EXPECT_TRUE(enabled->features.shaderStorageBufferArrayDynamicIndexing);
    EXPECT_TRUE(enabled->features.dualSrcBlend);
    EXPECT_TRUE(enabled->features.fragmentStoresAndAtomics);
    bool dynamic_rendering = false;
    for (auto* next = static_cast<const VkBaseInStructure*>(enabled->pNext); next; next = next->pNext) {
        if (next->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES) {
            dynamic_rendering = reinterpret_cast<const VkPhysicalDeviceVulkan13Features*>(next)->dynamicRendering;
        }
    }
    EXPECT_TRUE(dynamic_rendering);
    VkPhysicalDeviceFeatures2 offered{};
    offered.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    vkGetPhysicalDeviceFeatures2(context.physical_device(), &offered);
    const bool without_format =
        offered.features.shaderStorageImageReadWithoutFormat && offered.features.shaderStorageImageWriteWithoutFormat;
    EXPECT_EQ(static_cast<bool>(enabled->features.shaderStorageImageWriteWithoutFormat), without_format);
    EXPECT_TRUE(context.supports_compute_subgroup_arithmetic());

    // What crisp itself checks: both accept the device as made.
    EXPECT_TRUE(Renderer::create(renderer_create_info(context)));
    CompositorCreateInfo compositor_info = compositor_create_info(context);
    compositor_info.draw_format = VK_FORMAT_R8G8B8A8_UNORM;
    EXPECT_TRUE(Compositor::create(compositor_info));
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, MalformedFeatureChainIsRefused) {
    // Vulkan 1.3 features with a 1.2 api_version.
    VkPhysicalDeviceVulkan13Features vulkan13{};
    vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    vulkan13.synchronization2 = VK_TRUE;
    VkPhysicalDeviceFeatures2 features2{};
    features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features2.pNext = &vulkan13;
    HeadlessContextOptions options;
    options.required_features = &features2;
    Result<HeadlessContext> too_new = HeadlessContext::create(options);
    ASSERT_FALSE(too_new.ok());
    EXPECT_EQ(too_new.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(too_new.error().message.find("1.3"), std::string::npos) << too_new.error().message;

    // A structure other than the core feature structures.
    VkPhysicalDeviceShaderAtomicInt64Features atomics{};
    atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
    features2.pNext = &atomics;
    Result<HeadlessContext> foreign = HeadlessContext::create(options);
    ASSERT_FALSE(foreign.ok());
    EXPECT_EQ(foreign.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(foreign.error().message.find("unsupported structure"), std::string::npos) << foreign.error().message;

    // The floor.
    options.required_features = nullptr;
    options.api_version = VK_API_VERSION_1_1;
    Result<HeadlessContext> too_old = HeadlessContext::create(options);
    ASSERT_FALSE(too_old.ok());
    EXPECT_EQ(too_old.error().code, ErrorCode::invalid_argument);
}

TEST_F(VulkanTest, AbsentExtensionIsNamed) {
    HeadlessContextOptions options = validated_options();
    options.required_extensions = {"VK_CRISP_no_such_extension"};
    Result<HeadlessContext> context = HeadlessContext::create(options);
    ASSERT_FALSE(context.ok());
    EXPECT_EQ(context.error().code, ErrorCode::vulkan);
    EXPECT_NE(context.error().message.find("the device lacks extension VK_CRISP_no_such_extension"), std::string::npos)
        << context.error().message;

    // A real extension lavapipe lacks (NVIDIA drivers have it; then there is nothing to test).
    CRISP_CREATE_CONTEXT(baseline, HeadlessContextOptions{});
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(baseline.physical_device(), nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(baseline.physical_device(), nullptr, &count, extensions.data());
    const bool has_ray_tracing = std::any_of(extensions.begin(), extensions.end(), [](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, VK_NV_RAY_TRACING_EXTENSION_NAME) == 0;
    });
    if (!has_ray_tracing) {
        options.device_name_contains = baseline.device_name();
        options.required_extensions = {VK_NV_RAY_TRACING_EXTENSION_NAME};
        Result<HeadlessContext> no_ray_tracing = HeadlessContext::create(options);
        ASSERT_FALSE(no_ray_tracing.ok());
        EXPECT_NE(no_ray_tracing.error().message.find(VK_NV_RAY_TRACING_EXTENSION_NAME), std::string::npos)
            << no_ray_tracing.error().message;
    }
}

TEST_F(VulkanTest, ExtensionsAreEnabledExactly) {
    CRISP_CREATE_CONTEXT(baseline, HeadlessContextOptions{});
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(baseline.physical_device(), nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(baseline.physical_device(), nullptr, &count, extensions.data());
    const bool has_push_descriptor =
        std::any_of(extensions.begin(), extensions.end(), [](const VkExtensionProperties& e) {
            return std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0;
        });
    if (!has_push_descriptor) GTEST_SKIP() << baseline.device_name() << " lacks " VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
    HeadlessContextOptions options = validated_options();
    options.device_name_contains = baseline.device_name();
    options.required_extensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    CRISP_CREATE_CONTEXT(context, options);
    ASSERT_EQ(context.enabled_extensions().size(), 1u);
    EXPECT_EQ(context.enabled_extensions()[0], VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    EXPECT_NE(vkGetDeviceProcAddr(context.device(), "vkCmdPushDescriptorSetKHR"), nullptr);
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, DeviceNameFilter) {
    CRISP_CREATE_CONTEXT(baseline, HeadlessContextOptions{});
    HeadlessContextOptions options;
    options.device_name_contains = baseline.device_name();
    Result<HeadlessContext> same = HeadlessContext::create(options);
    ASSERT_TRUE(same.ok()) << same.error().message;
    EXPECT_EQ(same->device_name(), baseline.device_name());

    options.device_name_contains = "no device is called this";
    Result<HeadlessContext> none = HeadlessContext::create(options);
    ASSERT_FALSE(none.ok());
    EXPECT_EQ(none.error().code, ErrorCode::vulkan);
    // The message lists the devices there are.
    EXPECT_NE(none.error().message.find(baseline.device_name()), std::string::npos) << none.error().message;
}

TEST_F(VulkanTest, VersionAboveTheDriverIsRefused) {
    HeadlessContextOptions options;
    options.api_version = VK_MAKE_API_VERSION(0, 1, 99, 0);
    Result<HeadlessContext> context = HeadlessContext::create(options);
    ASSERT_FALSE(context.ok());
    EXPECT_EQ(context.error().code, ErrorCode::vulkan);
    EXPECT_NE(context.error().message.find("1.99"), std::string::npos) << context.error().message;
}

TEST_F(VulkanTest, ValidationErrorsAreCounted) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    // Anisotropic filtering without the samplerAnisotropy feature, which the context did not
    // enable (it enables exactly what was required): the layer must report it.
    VkSamplerCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    info.anisotropyEnable = VK_TRUE;
    info.maxAnisotropy = 2.0f;
    VkSampler sampler = VK_NULL_HANDLE;
    if (vkCreateSampler(context.device(), &info, nullptr, &sampler) == VK_SUCCESS) {
        vkDestroySampler(context.device(), sampler, nullptr);
    }
    const ValidationMessages messages = context.validation_messages();
    EXPECT_GE(messages.errors, 1u) << describe(messages);
    EXPECT_TRUE(std::any_of(messages.recent.begin(), messages.recent.end(), [](const std::string& message) {
        return message.rfind("error: ", 0) == 0 && message.find("anisotropyEnable") != std::string::npos;
    })) << describe(messages);

    // Without validation nothing is counted.
    CRISP_CREATE_CONTEXT(quiet, HeadlessContextOptions{});
    EXPECT_EQ(quiet.validation_messages().errors, 0u);
    EXPECT_TRUE(quiet.validation_messages().recent.empty());
}

TEST_F(VulkanTest, AbsentValidationLayerIsReported) {
    // The loader (1.3.234 and newer) hides layers named in this variable, as if not installed.
    const char* kDisable = "VK_LOADER_LAYERS_DISABLE";
    const char* previous = std::getenv(kDisable);
    const std::string saved = previous != nullptr ? previous : "";
    ASSERT_EQ(setenv(kDisable, "VK_LAYER_KHRONOS_validation", 1), 0);
    Result<HeadlessContext> context = HeadlessContext::create(validated_options());
    if (previous != nullptr) {
        setenv(kDisable, saved.c_str(), 1);
    } else {
        unsetenv(kDisable);
    }
    ASSERT_FALSE(context.ok());
    EXPECT_EQ(context.error().code, ErrorCode::vulkan);
    EXPECT_NE(context.error().message.find("VK_LAYER_KHRONOS_validation is not available"), std::string::npos)
        << context.error().message;
}

TEST_F(VulkanTest, SynchronizationHazardsAreReported) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    Result<Buffer> source = context.create_buffer(
        256, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::device_local);
    Result<Buffer> destination =
        context.create_buffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::device_local);
    ASSERT_TRUE(source.ok() && destination.ok());
    // A copy reads what a fill just wrote, with no barrier between: a read-after-write hazard.
    ASSERT_TRUE(context
                    .submit_and_wait([&](VkCommandBuffer commands) {
                        vkCmdFillBuffer(commands, source->handle(), 0, VK_WHOLE_SIZE, 7u);
                        VkBufferCopy region{};
                        region.size = 256;
                        vkCmdCopyBuffer(commands, source->handle(), destination->handle(), 1, &region);
                    })
                    .ok());
    const ValidationMessages messages = context.validation_messages();
    EXPECT_TRUE(std::any_of(messages.recent.begin(), messages.recent.end(), [](const std::string& message) {
        return message.find("SYNC-HAZARD-READ") != std::string::npos;
    })) << describe(messages);
}

TEST_F(VulkanTest, TwoContextsSideBySide) {
    CRISP_CREATE_CONTEXT(first, validated_options());
    CRISP_CREATE_CONTEXT(second, validated_options());
    EXPECT_NE(first.device(), second.device());

    // Interleaved work on both, with different seeds, so results cannot leak across.
    const std::vector<SelftestResult> first_results = run_selftest(first, kSelftestCount, 1);
    const std::vector<SelftestResult> second_results = run_selftest(second, kSelftestCount, 2);
    check_selftest(first_results, kSelftestCount, 1, first.subgroup_properties().subgroupSize);
    check_selftest(second_results, kSelftestCount, 2, second.subgroup_properties().subgroupSize);

    // Each context has its own validation log: an error on one leaves the other clean.
    VkSamplerCreateInfo bad_sampler{};
    bad_sampler.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    bad_sampler.anisotropyEnable = VK_TRUE;
    bad_sampler.maxAnisotropy = 2.0f;
    VkSampler sampler = VK_NULL_HANDLE;
    if (vkCreateSampler(first.device(), &bad_sampler, nullptr, &sampler) == VK_SUCCESS) {
        vkDestroySampler(first.device(), sampler, nullptr);
    }
    EXPECT_GE(first.validation_messages().errors, 1u);
    expect_no_validation_messages(second);

    // Destroy the first (not in reverse order of creation); the second keeps working.
    first = std::move(second);
    const std::vector<std::byte> bytes(256, std::byte{0x5a});
    Result<Buffer> buffer = first.create_buffer_with_data(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    ASSERT_TRUE(buffer.ok()) << buffer.error().message;
    Result<std::vector<std::byte>> back = first.read_buffer(*buffer, 0, bytes.size());
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_TRUE(*back == bytes);
    expect_no_validation_messages(first);
}

TEST_F(VulkanTest, ResourcesMove) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    Result<Buffer> created = context.create_buffer(128, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::upload);
    ASSERT_TRUE(created.ok()) << created.error().message;
    Buffer buffer = std::move(created).value();
    const VkBuffer handle = buffer.handle();
    Buffer moved = std::move(buffer);
    EXPECT_EQ(moved.handle(), handle);
    EXPECT_EQ(buffer.handle(), VK_NULL_HANDLE);  // NOLINT(bugprone-use-after-move): checking the moved-from state
    EXPECT_TRUE(buffer.mapped().empty());
    moved = Buffer();  // destroys it now
    EXPECT_EQ(moved.handle(), VK_NULL_HANDLE);

    Result<Image> image = context.create_image({VK_FORMAT_R8_UNORM, 8, 8, VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image->view(), VK_NULL_HANDLE) << "transfer-only images get no view";
    Image other = std::move(*image);
    EXPECT_EQ(image->handle(), VK_NULL_HANDLE);
    EXPECT_NE(other.handle(), VK_NULL_HANDLE);
    expect_no_validation_messages(context);
}

// crisp's objects carry debug names ("crisp <what>") where the instance has VK_EXT_debug_utils,
// so that the validation layer and debuggers say whose object a message is about.
// Buffers suballocated from an arena: each lies inside its block (a request larger than the
// block the arena would add next gets a block that holds it), no two live buffers share a byte,
// and ranges given back are taken again without overlap; the validation layer checks every bind.
TEST_F(VulkanTest, ArenaBuffersFitTheirBlocksAndNeverOverlap) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    vk::DeviceRef ref =
        vk::make_device_ref(context.functions(), context.physical_device(), context.device(), nullptr, VK_NULL_HANDLE);
    vk::MemoryArena arena(context.functions(), context.device(), nullptr, ref.memory_properties);
    ref.arena = &arena;
    constexpr VkDeviceSize kKiB = 1024, kMiB = 1024 * kKiB;
    const VkDeviceSize sizes[] = {kKiB, 10 * kMiB, 3 * kMiB, 100 * kKiB, 40 * kMiB, 7 * kKiB, 5 * kMiB, 16};
    std::vector<vk::DeviceBuffer> buffers;
    const auto expect_disjoint = [&] {
        for (size_t i = 0; i < buffers.size(); ++i) {
            for (size_t j = i + 1; j < buffers.size(); ++j) {
                const vk::DeviceBuffer& a = buffers[i];
                const vk::DeviceBuffer& b = buffers[j];
                if (a.memory != b.memory) continue;
                const bool apart = a.memory_offset + a.memory_size <= b.memory_offset ||
                                   b.memory_offset + b.memory_size <= a.memory_offset;
                EXPECT_TRUE(apart) << "buffers " << i << " and " << j << " overlap";
            }
        }
    };
    for (bool host_visible : {false, true}) {
        for (VkDeviceSize size : sizes) {
            buffers.emplace_back();
            ASSERT_TRUE(vk::create_buffer(ref, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, host_visible, "probe",
                                          buffers.back()));
            EXPECT_TRUE(buffers.back().suballocated);
            EXPECT_GE(buffers.back().memory_size, size);
            if (host_visible) {
                ASSERT_NE(buffers.back().mapped, nullptr);
                std::memset(buffers.back().mapped, 0xAB, static_cast<size_t>(size));  // the whole range is mapped
            }
        }
    }
    expect_disjoint();
    // Every other buffer back, then as many again: the freed ranges are reused, still disjoint.
    for (size_t i = 0; i < buffers.size(); i += 2) buffers[i].reset();
    std::erase_if(buffers, [](const vk::DeviceBuffer& b) { return b.buffer == VK_NULL_HANDLE; });
    for (VkDeviceSize size : sizes) {
        buffers.emplace_back();
        ASSERT_TRUE(vk::create_buffer(ref, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "again", buffers.back()));
    }
    expect_disjoint();
    EXPECT_LE(arena.block_count(), 12u);
    buffers.clear();
    expect_no_validation_messages(context);
}

TEST_F(VulkanTest, ObjectsAreNamedForTheValidationLayer) {
    CRISP_CREATE_CONTEXT(context, validated_options());
    const vk::DeviceRef ref =
        vk::make_device_ref(context.functions(), context.physical_device(), context.device(), nullptr, VK_NULL_HANDLE);
    ASSERT_NE(ref.fn->vkSetDebugUtilsObjectNameEXT, nullptr);
    vk::DeviceBuffer buffer;
    ASSERT_TRUE(vk::create_buffer(ref, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "probe", buffer));
    // A fill into a buffer made without TRANSFER_DST: the layer reports it, naming the buffer.
    // (The submission may succeed or fail on the invalid command; only the message counts.)
    static_cast<void>(
        context.submit_and_wait([&](VkCommandBuffer cb) { vkCmdFillBuffer(cb, buffer.buffer, 0, 16, 0); }));
    buffer.reset();
    const ValidationMessages messages = context.validation_messages();
    EXPECT_GE(messages.errors, 1u);
    EXPECT_TRUE(std::any_of(messages.recent.begin(), messages.recent.end(), [](const std::string& message) {
        return message.find("crisp probe") != std::string::npos;
    })) << describe(messages);
}

// Pipelines go through the caller's cache. lavapipe's caches hold no data to count, so the test
// hands the renderer and the compositor a cache of another device: the validation layer then
// reports each pipeline made through it, which it could not if crisp ignored the cache.
TEST_F(VulkanTest, PipelinesGoThroughTheCallersCache) {
    auto made = test::create_renderer_context();
    ASSERT_TRUE(made) << made.error().message;
    HeadlessContext& context = *made;
    CRISP_CREATE_CONTEXT(other, validated_options());
    VkPipelineCacheCreateInfo cache_info{};
    cache_info.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    VkPipelineCache foreign = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreatePipelineCache(other.device(), &cache_info, nullptr, &foreign), VK_SUCCESS);
    const auto cache_reports = [&] {
        const ValidationMessages messages = context.validation_messages();
        return std::count_if(messages.recent.begin(), messages.recent.end(), [](const std::string& message) {
            return message.find("pipelineCache") != std::string::npos;
        });
    };
    {
        RendererCreateInfo renderer_info = renderer_create_info(context);
        renderer_info.pipeline_cache = foreign;
        auto renderer = Renderer::create(renderer_info);
        EXPECT_GE(cache_reports(), 1) << describe(context.validation_messages());
        const auto after_renderer = cache_reports();
        CompositorCreateInfo compositor_info = compositor_create_info(context);
        compositor_info.pipeline_cache = foreign;
        auto compositor = Compositor::create(compositor_info);
        EXPECT_GT(cache_reports(), after_renderer) << describe(context.validation_messages());
    }
    vkDestroyPipelineCache(other.device(), foreign, nullptr);
}

// Shader statistics come exactly where the device was created with pipelineExecutableInfo: the
// enabled chain is read for it, and a context asked for statistics enables it where offered
// (NVIDIA's driver does; lavapipe does not, and then nothing changes).
TEST_F(VulkanTest, ShaderStatisticsFollowTheEnabledFeature) {
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable{};
    executable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
    VkPhysicalDeviceFeatures2 chain{};
    chain.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    chain.pNext = &executable;
    for (const VkBool32 on : {VK_FALSE, VK_TRUE}) {
        executable.pipelineExecutableInfo = on;
        Result<vk::DeviceFeatures> read = vk::read_enabled_features(&chain, "test");
        ASSERT_TRUE(read) << read.error().message;
        EXPECT_EQ(read->pipeline_executable_info, on == VK_TRUE);
    }

    HeadlessContextOptions options = validated_options();
    options.crisp_needs = CrispFeatureNeeds{};
    options.shader_statistics = true;
    CRISP_CREATE_CONTEXT(context, options);
    Result<vk::DeviceFeatures> enabled = vk::read_enabled_features(context.enabled_features(), "test");
    ASSERT_TRUE(enabled) << enabled.error().message;
    auto renderer = Renderer::create(renderer_create_info(context));
    ASSERT_TRUE(renderer) << renderer.error().message;
    auto compositor = Compositor::create(compositor_create_info(context));
    ASSERT_TRUE(compositor) << compositor.error().message;
    if (enabled->pipeline_executable_info) {
        const auto& stats = renderer->shader_statistics();
        ASSERT_FALSE(stats.empty());
        EXPECT_TRUE(std::all_of(stats.begin(), stats.end(),
                                [](const ShaderStatistic& s) { return s.shader == "raster.comp" && !s.name.empty(); }));
        EXPECT_FALSE(compositor->shader_statistics().empty());
    } else {
        EXPECT_TRUE(renderer->shader_statistics().empty());
        EXPECT_TRUE(compositor->shader_statistics().empty());
    }
    const ValidationMessages messages = context.validation_messages();
    EXPECT_EQ(messages.errors + messages.warnings, 0u) << describe(messages);
}

TEST(VulkanErrors, CarryTheResultOfTheFailedCall) {
    EXPECT_EQ(vk::vulkan_error("vkQueueSubmit", VK_ERROR_DEVICE_LOST).vk_result, VK_ERROR_DEVICE_LOST);
    const Error oom = vk::vulkan_error("vkAllocateMemory", VK_ERROR_OUT_OF_DEVICE_MEMORY);
    EXPECT_EQ(oom.vk_result, VK_ERROR_OUT_OF_DEVICE_MEMORY);
    EXPECT_EQ(oom.message, "vkAllocateMemory failed: VK_ERROR_OUT_OF_DEVICE_MEMORY");
    EXPECT_EQ(Error{}.vk_result, VK_SUCCESS);
}

// An allocator that refuses every allocation: a driver that allocates host memory for an object
// made with it fails that call with VK_ERROR_OUT_OF_HOST_MEMORY.
void* VKAPI_CALL refuse_allocation(void*, size_t, size_t, VkSystemAllocationScope) {
    return nullptr;
}
void* VKAPI_CALL refuse_reallocation(void*, void*, size_t, size_t, VkSystemAllocationScope) {
    return nullptr;
}
void VKAPI_CALL free_nothing(void*, void*) {}  // it never gave out memory

// The Error of a failed Vulkan call carries what the call returned, from the renderer's and the
// compositor's creation down to the support library's; an error no Vulkan call caused carries
// VK_SUCCESS, whatever its code.
TEST_F(VulkanTest, FailedCallsCarryTheirVkResult) {
    HeadlessContextOptions options = validated_options();
    options.crisp_needs = CrispFeatureNeeds{};
    CRISP_CREATE_CONTEXT(context, options);
    VkAllocationCallbacks refusing{};
    refusing.pfnAllocation = refuse_allocation;
    refusing.pfnReallocation = refuse_reallocation;
    refusing.pfnFree = free_nothing;
    const auto expect_out_of_host_memory = [](const Error& error) {
        EXPECT_EQ(error.code, ErrorCode::vulkan) << error.message;
        EXPECT_EQ(error.vk_result, VK_ERROR_OUT_OF_HOST_MEMORY) << error.message;
        EXPECT_NE(error.message.find("VK_ERROR_OUT_OF_HOST_MEMORY"), std::string::npos) << error.message;
    };
    RendererCreateInfo renderer_info = renderer_create_info(context);
    renderer_info.allocator = &refusing;
    Result<Renderer> renderer = Renderer::create(renderer_info);
    ASSERT_FALSE(renderer.ok());
    expect_out_of_host_memory(renderer.error());
    CompositorCreateInfo compositor_info = compositor_create_info(context);
    compositor_info.allocator = &refusing;
    Result<Compositor> compositor = Compositor::create(compositor_info);
    ASSERT_FALSE(compositor.ok());
    expect_out_of_host_memory(compositor.error());
    // Mesa reports each refusal through the messenger itself; nothing else may be reported (the
    // validation layer finds nothing wrong with the calls).
    const ValidationMessages refusals = context.validation_messages();
    EXPECT_EQ(refusals.warnings, 0u) << describe(refusals);
    ASSERT_EQ(refusals.recent.size(), refusals.errors) << describe(refusals);
    for (const std::string& message : refusals.recent) {
        EXPECT_NE(message.find("VK_ERROR_OUT_OF_HOST_MEMORY"), std::string::npos) << describe(refusals);
    }

    // A compressed format as a storage image: vkGetPhysicalDeviceImageFormatProperties refuses it.
    ImageDesc compressed;
    compressed.format = VK_FORMAT_BC1_RGBA_UNORM_BLOCK;
    compressed.width = compressed.height = 64;
    compressed.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    Result<Image> unsupported = context.create_image(compressed);
    ASSERT_FALSE(unsupported.ok());
    EXPECT_EQ(unsupported.error().code, ErrorCode::vulkan);
    EXPECT_EQ(unsupported.error().vk_result, VK_ERROR_FORMAT_NOT_SUPPORTED) << unsupported.error().message;

    // Refused with no Vulkan call failing: a size past the device's limit (the query succeeded),
    // and a bad argument.
    ImageDesc huge;
    huge.width = context.properties().limits.maxImageDimension2D + 1;
    huge.height = 1;
    huge.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    Result<Image> too_large = context.create_image(huge);
    ASSERT_FALSE(too_large.ok());
    EXPECT_EQ(too_large.error().code, ErrorCode::vulkan);
    EXPECT_EQ(too_large.error().vk_result, VK_SUCCESS) << too_large.error().message;
    renderer_info.allocator = nullptr;
    renderer_info.frames_in_flight = 0;
    Result<Renderer> invalid = Renderer::create(renderer_info);
    ASSERT_FALSE(invalid.ok());
    EXPECT_EQ(invalid.error().code, ErrorCode::invalid_argument);
    EXPECT_EQ(invalid.error().vk_result, VK_SUCCESS);
    const ValidationMessages messages = context.validation_messages();
    EXPECT_EQ(messages.errors, refusals.errors) << describe(messages);
    EXPECT_EQ(messages.warnings, 0u) << describe(messages);
}

TEST(VulkanErrors, DeviceLossIsItsOwnErrorCode) {
    const Error lost = vk::vulkan_error("vkQueueSubmit", VK_ERROR_DEVICE_LOST);
    EXPECT_EQ(lost.code, ErrorCode::device_lost);
    EXPECT_STREQ(error_code_name(lost.code), "device_lost");
    EXPECT_NE(lost.message.find("VK_ERROR_DEVICE_LOST"), std::string::npos);
    EXPECT_EQ(vk::vulkan_error("vkQueueSubmit", VK_ERROR_OUT_OF_DEVICE_MEMORY).code, ErrorCode::vulkan);
}

}  // namespace
}  // namespace crisp
