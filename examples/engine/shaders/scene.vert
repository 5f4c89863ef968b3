#version 450
// The scene's lit shapes: world-space normals for the fragment shader's light.

layout(push_constant) uniform Push {
    mat4 model_view_projection;
    mat4 model;  // rotation and translation only, so it also turns normals
} push;

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 color;

layout(location = 0) out vec3 world_normal;
layout(location = 1) out vec3 albedo;

void main() {
    gl_Position = push.model_view_projection * vec4(position, 1.0);
    world_normal = mat3(push.model) * normal;
    albedo = color;
}
