// HeadlessContext: an instance, device and queue made through support/vulkan_device.hpp, one-off
// submissions, and the renderer's and compositor's create infos for it. Its buffers and images
// live in headless_resources.cpp.
#include "headless_context.hpp"

#include "vk/functions.hpp"
#include "vk/resources.hpp"

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <utility>

namespace crisp {

struct HeadlessContext::State {
    ValidationLog validation_log;  // before the instance, which logs into it
    VulkanInstance instance;
    PhysicalDevice physical;
    VulkanDevice device;
    VkCommandPool command_pool = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    bool recording = false;  // catches submit_and_wait called from inside its own record callback
    bool lost = false;       // a submission or wait returned VK_ERROR_DEVICE_LOST

    std::string device_name;
    std::string driver_name;
    std::string driver_info;
    VkPhysicalDeviceSubgroupProperties subgroup{};

    State() = default;
    State(const State&) = delete;
    State& operator=(const State&) = delete;

    // create()'s steps after the instance, in order; each leaves what it made for the destructor
    // on failure.
    Status create_device(PhysicalDevice chosen);
    Status create_submission_objects();

    // Destroys in reverse order of creation; create() relies on this to clean up after a failure
    // part-way through.
    ~State() {
        const ValidationMessages before = validation_log.snapshot();
        if (device.handle() != VK_NULL_HANDLE) {
            const vk::Functions& fn = device.functions();
            // Nothing may be destroyed while the GPU still uses it.
            fn.vkDeviceWaitIdle(device.handle());
            if (fence != VK_NULL_HANDLE) fn.vkDestroyFence(device.handle(), fence, nullptr);
            if (command_pool != VK_NULL_HANDLE) fn.vkDestroyCommandPool(device.handle(), command_pool, nullptr);
        }
        device = {};
        instance = {};
        // What the layer says during teardown (typically: a Buffer or Image outlived its context)
        // has no one left to read it, so it goes to stderr.
        const ValidationMessages after = validation_log.snapshot();
        const size_t added = (after.errors + after.warnings) - (before.errors + before.warnings);
        const size_t shown = std::min(added, after.recent.size());
        for (size_t i = after.recent.size() - shown; i < after.recent.size(); ++i) {
            std::fprintf(stderr, "crisp: validation during HeadlessContext teardown: %s\n", after.recent[i].c_str());
        }
    }
};

// The device from `chosen`, its queue, and what the accessors report of it.
Status HeadlessContext::State::create_device(PhysicalDevice chosen) {
    physical = std::move(chosen);
    device_name = physical.properties.deviceName;
    driver_name = physical.vulkan12.driverName;
    driver_info = physical.vulkan12.driverInfo;
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    subgroup.subgroupSize = physical.vulkan11.subgroupSize;
    subgroup.supportedStages = physical.vulkan11.subgroupSupportedStages;
    subgroup.supportedOperations = physical.vulkan11.subgroupSupportedOperations;
    subgroup.quadOperationsInAllStages = physical.vulkan11.subgroupQuadOperationsInAllStages;
    Result<VulkanDevice> created = VulkanDevice::create(instance, physical);
    if (!created) return created.error();
    device = std::move(*created);
    return {};
}

// The command pool, command buffer and fence submit_and_wait() uses.
Status HeadlessContext::State::create_submission_objects() {
    const vk::Functions& fn = device.functions();
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    // One command buffer, re-recorded for every submission.
    pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = physical.queue_family;
    if (VkResult result = fn.vkCreateCommandPool(device.handle(), &pool_info, nullptr, &command_pool);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateCommandPool", result);
    }
    VkCommandBufferAllocateInfo buffer_info{};
    buffer_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    buffer_info.commandPool = command_pool;
    buffer_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    buffer_info.commandBufferCount = 1;
    if (VkResult result = fn.vkAllocateCommandBuffers(device.handle(), &buffer_info, &command_buffer);
        result != VK_SUCCESS) {
        return vk::vulkan_error("vkAllocateCommandBuffers", result);
    }
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if (VkResult result = fn.vkCreateFence(device.handle(), &fence_info, nullptr, &fence); result != VK_SUCCESS) {
        return vk::vulkan_error("vkCreateFence", result);
    }
    return {};
}

Result<HeadlessContext> HeadlessContext::create(const HeadlessContextOptions& given) {
    // The instance asks for the version crisp's needs imply (1.3 for the draw path) too.
    HeadlessContextOptions options = given;
    add_crisp_needs(options);
    if (Status s = check_requirements(options); !s) return s.error();
    auto state = std::make_unique<State>();
    InstanceOptions instance_options;
    instance_options.api_version = options.api_version;
    instance_options.minimum_version = options.api_version;
    instance_options.validation = options.validation;
    instance_options.synchronization_validation = options.synchronization_validation;
    instance_options.validation_log = &state->validation_log;
    Result<VulkanInstance> instance = VulkanInstance::create(instance_options);
    if (!instance) return instance.error();
    state->instance = std::move(*instance);
    Result<PhysicalDevice> chosen = choose_physical_device(state->instance, options);
    if (!chosen) return chosen.error();
    if (Status s = state->create_device(std::move(*chosen)); !s) return s.error();
    if (Status s = state->create_submission_objects(); !s) return s.error();
    return HeadlessContext(std::move(state));
}

HeadlessContext::HeadlessContext(std::unique_ptr<State> state) : state_(std::move(state)) {}
HeadlessContext::HeadlessContext(HeadlessContext&& other) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&& other) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

const vk::Functions& HeadlessContext::functions() const {
    return state_->device.functions();
}
PFN_vkGetInstanceProcAddr HeadlessContext::get_instance_proc_addr() const {
    return state_->device.functions().vkGetInstanceProcAddr;
}
VkInstance HeadlessContext::instance() const {
    return state_->instance.handle();
}
uint32_t HeadlessContext::instance_api_version() const {
    return state_->instance.api_version();
}
VkPhysicalDevice HeadlessContext::physical_device() const {
    return state_->physical.handle;
}
VkDevice HeadlessContext::device() const {
    return state_->device.handle();
}
uint32_t HeadlessContext::queue_family() const {
    return state_->physical.queue_family;
}

const VkPhysicalDeviceFeatures2* HeadlessContext::enabled_features() const {
    return state_->device.enabled_features();
}
VkQueue HeadlessContext::queue() const {
    return state_->device.queue();
}
const std::string& HeadlessContext::device_name() const {
    return state_->device_name;
}
const std::string& HeadlessContext::driver_name() const {
    return state_->driver_name;
}
const std::string& HeadlessContext::driver_info() const {
    return state_->driver_info;
}
VkDriverId HeadlessContext::driver_id() const {
    return state_->physical.vulkan12.driverID;
}
uint32_t HeadlessContext::driver_version() const {
    return state_->physical.properties.driverVersion;
}
uint32_t HeadlessContext::api_version() const {
    return state_->physical.api_version;
}
const VkPhysicalDeviceProperties& HeadlessContext::properties() const {
    return state_->physical.properties;
}
const VkPhysicalDeviceMemoryProperties& HeadlessContext::memory_properties() const {
    return state_->physical.memory_properties;
}
const VkPhysicalDeviceSubgroupProperties& HeadlessContext::subgroup_properties() const {
    return state_->subgroup;
}
const std::vector<std::string>& HeadlessContext::enabled_extensions() const {
    return state_->device.enabled_extensions();
}

bool HeadlessContext::supports_compute_subgroup_arithmetic() const {
    return (state_->subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
           (state_->subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0;
}

ValidationMessages HeadlessContext::validation_messages() const {
    return state_->validation_log.snapshot();
}

Status HeadlessContext::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
    State& s = *state_;
    const vk::Functions& fn = s.device.functions();
    assert(!s.recording && "submit_and_wait called from inside its own record callback");
    if (s.lost) {
        return Error{ErrorCode::device_lost, "the device was lost earlier: make a new context", VK_ERROR_DEVICE_LOST};
    }
    // Leaves the command buffer reusable even if `record` throws.
    struct RecordingGuard {
        State& s;
        bool ended = false;
        explicit RecordingGuard(State& state) : s(state) { s.recording = true; }
        ~RecordingGuard() {
            if (!ended) s.device.functions().vkResetCommandBuffer(s.command_buffer, 0);
            s.recording = false;
        }
    } guard(s);

    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (VkResult result = fn.vkBeginCommandBuffer(s.command_buffer, &begin); result != VK_SUCCESS) {
        return vk::vulkan_error("vkBeginCommandBuffer", result);
    }
    record(s.command_buffer);
    VkResult ended = fn.vkEndCommandBuffer(s.command_buffer);
    guard.ended = ended == VK_SUCCESS;
    if (ended != VK_SUCCESS) return vk::vulkan_error("vkEndCommandBuffer", ended);

    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &s.command_buffer;
    if (VkResult result = fn.vkQueueSubmit(s.device.queue(), 1, &submit, s.fence); result != VK_SUCCESS) {
        s.lost = result == VK_ERROR_DEVICE_LOST;
        return vk::vulkan_error("vkQueueSubmit", result);
    }
    if (VkResult result = fn.vkWaitForFences(s.device.handle(), 1, &s.fence, VK_TRUE, UINT64_MAX);
        result != VK_SUCCESS) {
        s.lost = result == VK_ERROR_DEVICE_LOST;
        return vk::vulkan_error("vkWaitForFences", result);
    }
    if (VkResult result = fn.vkResetFences(s.device.handle(), 1, &s.fence); result != VK_SUCCESS) {
        return vk::vulkan_error("vkResetFences", result);
    }
    return {};
}

RendererCreateInfo renderer_create_info(const HeadlessContext& context) {
    RendererCreateInfo info;
    info.instance = context.instance();
    info.instance_api_version = context.instance_api_version();
    info.get_instance_proc_addr = context.get_instance_proc_addr();
    info.physical_device = context.physical_device();
    info.device = context.device();
    info.queue_family = context.queue_family();
    info.enabled_features = context.enabled_features();
    info.allocator = context.allocation_callbacks();
    return info;
}

CompositorCreateInfo compositor_create_info(const HeadlessContext& context) {
    CompositorCreateInfo info;
    info.instance = context.instance();
    info.instance_api_version = context.instance_api_version();
    info.get_instance_proc_addr = context.get_instance_proc_addr();
    info.physical_device = context.physical_device();
    info.device = context.device();
    info.allocator = context.allocation_callbacks();
    info.enabled_features = context.enabled_features();
    return info;
}

}  // namespace crisp
