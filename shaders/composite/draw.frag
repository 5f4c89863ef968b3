// unsorted: premultiplied "over" in submission order, with per-channel transmittance through
// dual-source blending: dst = L + T * dst (colour), dst.a = o + (1 - o) * dst.a with o the
// largest channel opacity.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "quad_pipeline.glsl"

layout(location = 0, index = 0) out vec4 out_light;
layout(location = 0, index = 1) out vec4 out_transmittance;

void main() {
    GlyphFragment f;
    if (!load_fragment(f)) discard;
    const float opacity = max(f.opacity.r, max(f.opacity.g, f.opacity.b));
    out_light = vec4(f.light, opacity);
    out_transmittance = vec4(f.transmittance, 1.0 - opacity);
}
