// The tile pass into a rgba8 storage image (tiles_pass.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#define CRISP_TARGET_FORMAT rgba8
#include "tiles_pass.glsl"
