#version 450
// One directional light and a sky/ground ambient, in linear colour (the target is RGBA16F).

layout(location = 0) in vec3 world_normal;
layout(location = 1) in vec3 albedo;

layout(location = 0) out vec4 color;

const vec3 kLightDirection = vec3(-0.42, 0.78, 0.46);  // towards the light, normalized below
const vec3 kLight = vec3(1.0, 0.95, 0.85);
const vec3 kSky = vec3(0.22, 0.26, 0.34);
const vec3 kGround = vec3(0.08, 0.07, 0.06);

void main() {
    const vec3 n = normalize(world_normal);
    const float direct = max(dot(n, normalize(kLightDirection)), 0.0);
    const vec3 ambient = mix(kGround, kSky, n.y * 0.5 + 0.5);
    color = vec4(albedo * (ambient + kLight * direct), 1.0);
}
