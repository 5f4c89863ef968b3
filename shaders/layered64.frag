// layered, 64-bit keys: depth, paint order and RGB transmittance (needs shaderInt64 and
// shaderBufferInt64Atomics).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define CRISP_KEY64 1
#include "layered.glsl"
