// wboit, the quad pass rasterized (reference_wboit.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "reference_wboit.glsl"
