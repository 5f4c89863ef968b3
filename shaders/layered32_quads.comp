// layered, 32-bit mono keys, the quad passes as compute dispatches over the frame's tiles.
#version 460
#extension GL_GOOGLE_include_directive : require
#define CRISP_COMPUTE 1
#include "layered.glsl"
