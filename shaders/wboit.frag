// wboit, the quad pass rasterized (wboit.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "wboit.glsl"
