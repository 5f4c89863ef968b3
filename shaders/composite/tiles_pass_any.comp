// The tile pass into a storage image read and written without a format qualifier (B8G8R8A8, which
// has none); the device needs shaderStorageImageReadWithoutFormat and WriteWithoutFormat.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_image_load_formatted : require
#include "tiles_pass.glsl"
