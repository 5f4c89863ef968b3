// The tile pass into a rgba8 storage image (tile_composite.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#define CRISP_TARGET_FORMAT rgba8
#include "tile_composite.glsl"
