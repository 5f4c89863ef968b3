// layered, 64-bit keys, the quad passes as compute dispatches over the frame's tiles.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define CRISP_KEY64 1
#define CRISP_COMPUTE 1
#include "layered.glsl"
