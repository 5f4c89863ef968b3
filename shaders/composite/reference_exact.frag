// exact, the quad pass rasterized (reference_exact.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "reference_exact.glsl"
