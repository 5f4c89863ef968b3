// exact, the quad pass rasterized (exact.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "exact.glsl"
