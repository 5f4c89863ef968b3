// Writes, for each invocation, a hashed value and what subgroup arithmetic says about its
// subgroup; tests/test_vulkan.cpp recomputes all of it on the CPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared.h"

layout(local_size_x = kSelftestWorkgroupSize) in;

layout(push_constant) uniform PushConstants {
    SelftestPushConstants pc;
};

layout(std430, binding = 0) writeonly buffer Results {
    SelftestResult results[];
};

// lowbias32 (Chris Wellons' hash prospector): neighbouring indices get unrelated values, so the
// minimum and maximum of a subgroup can sit at any invocation.
uint lowbias32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

void main() {
    uint index = gl_GlobalInvocationID.x;
    // Invocations past the end leave before the subgroup operations, which then see only the
    // active ones: the partial last subgroup is part of what is tested.
    if (index >= pc.element_count) return;

    uint value = lowbias32(index ^ pc.seed);
    SelftestResult result;
    result.value = value;
    result.subgroup_min = subgroupMin(value);
    result.subgroup_max = subgroupMax(value);
    result.subgroup_key = gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID;
    result.active_count = subgroupAdd(1u);
    result.subgroup_size = gl_SubgroupSize;
    results[index] = result;
}
