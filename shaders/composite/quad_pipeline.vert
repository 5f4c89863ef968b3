// The compositor's glyph quads: one instance per quad, four vertices as a triangle strip. A quad
// covers exactly the pixels of its glyph's atlas rect placed at its target position (pixel centres
// inside [x, x + width) x [y, y + height)), so each fragment reads one atlas texel.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared.h"

layout(push_constant) uniform PushConstants {
    CompositePushConstants pc;
};

layout(std430, set = 0, binding = kCompositeBindQuads) readonly buffer Quads {
    CompositeQuad quads[];
};

layout(location = 0) flat out uint v_quad;

void main() {
    // The draw path's quads are sorted front to back: drawn in reverse, "over" is exact.
    const uint index = pc.back_to_front != 0u ? pc.quad_count - 1u - uint(gl_InstanceIndex) : uint(gl_InstanceIndex);
    const CompositeQuad q = quads[index];
    const vec2 corner = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1));
    const vec2 p = vec2(q.x, q.y) + corner * vec2(q.width, q.height);
    // z: the glyph's depth (key_depth is depth * 2^32), which the draw path may test against the
    // caller's depth attachment; passes without one ignore it.
    gl_Position = vec4(p / vec2(pc.width, pc.height) * 2.0 - 1.0, float(q.key_depth) * exp2(-32.0), 1.0);
    v_quad = index;
}
