// wboit, the quad pass as a compute dispatch over the frame's tiles (reference_wboit.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#define CRISP_COMPUTE 1
#include "reference_wboit.glsl"
