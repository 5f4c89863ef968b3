// crisp: structs and constants shared by the C++ sources and the GLSL shaders, declared once.
//
// GLSL sees plain GLSL; C++ sees the same declarations inside namespace crisp::gpu, with GLSL's
// scalar type names, plus static_asserts that its layout matches the shaders' (std430 for storage
// buffers, and push constants).
#ifndef CRISP_SHADERS_SHARED_H
#define CRISP_SHADERS_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>

namespace crisp::gpu {

using uint = std::uint32_t;

#define CRISP_CONSTANT(type, name, value) inline constexpr type name = value
#else
#define CRISP_CONSTANT(type, name, value) const type name = value
#endif

// ---- selftest.comp: checks the context, push constants, storage buffers and subgroup arithmetic.

// Invocations per workgroup: whole subgroups on common GPUs (8 to 64 wide), eight of them on
// lavapipe's 8-wide subgroups.
CRISP_CONSTANT(uint, kSelftestWorkgroupSize, 64u);

struct SelftestPushConstants {
    uint element_count;  // invocations at or past this index write nothing
    uint seed;           // mixed into every value, so results left from an earlier run cannot pass
};

// One per invocation, in a std430 storage buffer.
struct SelftestResult {
    uint value;          // lowbias32(index ^ seed)
    uint subgroup_min;   // subgroupMin(value) over the active invocations of its subgroup
    uint subgroup_max;   // subgroupMax(value), likewise
    uint subgroup_key;   // gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID: which subgroup ran it
    uint active_count;   // subgroupAdd(1u): how many invocations of that subgroup were active
    uint subgroup_size;  // gl_SubgroupSize
};

#ifdef __cplusplus
static_assert(sizeof(SelftestPushConstants) == 8);
static_assert(offsetof(SelftestPushConstants, seed) == 4);
static_assert(sizeof(SelftestResult) == 24);  // std430 array stride: 6 uints, 4-byte aligned
static_assert(offsetof(SelftestResult, subgroup_key) == 12);
static_assert(offsetof(SelftestResult, subgroup_size) == 20);

}  // namespace crisp::gpu
#endif

#undef CRISP_CONSTANT

#endif  // CRISP_SHADERS_SHARED_H
