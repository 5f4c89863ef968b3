// layered, 32-bit mono keys: depth (16 bits), paint order and one transmittance for the three
// channels. Gray layouts, and devices without 64-bit buffer atomics.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "layered.glsl"
