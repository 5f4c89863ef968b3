// What every compositing quad pass starts from: its quad, its pixel and the glyph's coverage
// there. Included after #version and the include extension by the *.frag shaders (a quad
// rasterized: one fragment per pixel) and, with CRISP_COMPUTE defined, by the *_quads.comp shaders
// (one invocation per pixel of an 8 x 8 tile of a quad's rect, from the frame's tile list).
#include "shared.h"

#ifdef CRISP_COMPUTE
layout(local_size_x = kCompositeTile * kCompositeTile) in;
#else
layout(early_fragment_tests) in;
#endif

layout(push_constant) uniform PushConstants {
    CompositePushConstants pc;
};

layout(set = 0, binding = kCompositeBindAtlas, rgba16ui) uniform readonly uimage2D atlas;

layout(std430, set = 0, binding = kCompositeBindQuads) readonly buffer Quads {
    CompositeQuad quads[];
};

#include "atlas/atlas_texel.glsl"
#include "contrast.glsl"
#define CRISP_BIND_PAINTS kCompositeBindPaints
#define CRISP_BIND_STOPS kCompositeBindStops
#define CRISP_BIND_IMAGES kCompositeBindImages
#include "paint.glsl"

#ifdef CRISP_COMPUTE
// Per tile: the quad's index, and the tile's top-left texel in the quad's rect (x | y << 16).
layout(std430, set = 0, binding = kCompositeBindTiles) readonly buffer Tiles {
    uvec2 tiles[];
};
#else
layout(location = 0) flat in uint v_quad;
#endif

// One glyph at one pixel, per channel: opacity o = a * coverage, T = 1 - o, L = c * o (linear).
struct GlyphFragment {
    CompositeQuad quad;
    uint pixel;  // y * width + x
    vec3 opacity;
    vec3 transmittance;
    vec3 light;
};

// False where the texel holds no samples: the glyph does not draw there yet.
bool load_fragment(out GlyphFragment f) {
#ifdef CRISP_COMPUTE
    const uint tile_index = gl_WorkGroupID.y * kRasterDispatchWidth + gl_WorkGroupID.x;
    if (tile_index >= pc.tile_count) return false;
    const uvec2 tile = tiles[tile_index];
    f.quad = quads[tile.x];
    const uvec2 texel_in_rect = uvec2(tile.y & 0xFFFFu, tile.y >> 16) +
                                uvec2(gl_LocalInvocationIndex % kCompositeTile, gl_LocalInvocationIndex / kCompositeTile);
    if (texel_in_rect.x >= f.quad.width || texel_in_rect.y >= f.quad.height) return false;
    const ivec2 pixel = ivec2(f.quad.x, f.quad.y) + ivec2(texel_in_rect);
    if (pixel.x < 0 || pixel.y < 0 || pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return false;
#else
    f.quad = quads[v_quad];
    // The draw path's viewport is the caller's rect; glyph positions are relative to its corner.
    const ivec2 pixel = ivec2(gl_FragCoord.xy) - ivec2(pc.origin_x, pc.origin_y);
#endif
    f.pixel = uint(pixel.y) * pc.width + uint(pixel.x);
    // A rect that does not lie in the atlas (not from Renderer::drawn()) draws nothing there.
    vec3 coverage;
    if (!glyph_texel_coverage(f.quad, pixel, coverage)) return false;
    // A colour layer's fill at the pixel (paint.glsl), or the glyph's colour.
    const vec4 fill = quad_fill(f.quad, pixel);
    // The contrast model against the background these passes cannot read (contrast.glsl).
    const float lt = contrast_luminance(fill.rgb);
    coverage = corrected_coverage(coverage, f.quad.contrast_gamma, f.quad.contrast_k, f.quad.contrast_darkening, lt,
                                  assumed_background_luminance(lt));
    f.opacity = fill.a * coverage;
    f.transmittance = 1.0 - f.opacity;
    f.light = fill.rgb * f.opacity;
    return true;
}

// round(clamp(T) * 255) per channel, as the CPU reference (oit::quantize_transmittance).
uvec3 transmittance_codes(vec3 transmittance) {
    return uvec3(clamp(transmittance, 0.0, 1.0) * 255.0 + 0.5);
}

// -ln(code / 255), code 0 taken as the middle of its rounding bin (oit::absorbance_from_code).
float absorbance_from_code(uint code) {
    return -log(code == 0u ? 0.5 / 255.0 : float(code) / 255.0);
}

uint light_fixed(float light) {
    return uint(clamp(light, 0.0, 1.0) * kCompositeLightScale + 0.5);
}
