// A glyph quad's fragment at one pixel, from its atlas texel: per channel, coverage k = sum /
// (kRasterCoverageOne * count), opacity o = a * k, transmittance T = 1 - o and premultiplied light
// L = c * o, with c the quad's linear colour and a its alpha. Shared by every compositing shader so
// that all of them see the same fragment bit for bit. Needs shared.h and the atlas image declared.

// False where the texel lies outside the atlas or holds no samples yet: nothing is drawn there.
bool glyph_texel_coverage(CompositeQuad quad, ivec2 pixel_in_rect, out vec3 coverage) {
    const ivec2 texel = ivec2(quad.atlas_x, quad.atlas_y) + pixel_in_rect - ivec2(quad.x, quad.y);
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, imageSize(atlas)))) return false;
    const uvec4 sums = imageLoad(atlas, texel);
    if (sums.a == 0u) return false;
    coverage = min(vec3(sums.rgb) / (float(kRasterCoverageOne) * float(sums.a)), vec3(1.0));
    return true;
}

bool glyph_texel_opacity(CompositeQuad quad, ivec2 pixel_in_rect, out vec3 opacity) {
    vec3 coverage;
    if (!glyph_texel_coverage(quad, pixel_in_rect, coverage)) return false;
    opacity = quad.color.a * coverage;
    return true;
}
