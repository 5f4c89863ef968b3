#version 450
// A filled rectangle in window pixels (HUD panels, label backgrounds), as a 4-vertex strip.

layout(push_constant) uniform Push {
    vec4 rect;      // x, y, width, height in pixels, y down
    vec4 color;     // linear, straight alpha
    vec2 viewport;  // the target's size in pixels
} push;

void main() {
    const vec2 corner = vec2(gl_VertexIndex & 1, gl_VertexIndex >> 1);
    const vec2 pixel = push.rect.xy + corner * push.rect.zw;
    gl_Position = vec4(pixel / push.viewport * 2.0 - 1.0, 0.0, 1.0);
}
