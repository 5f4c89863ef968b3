// The tile pass into a rgba16f storage image (tiles_pass.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#define CRISP_TARGET_FORMAT rgba16f
#include "tiles_pass.glsl"
