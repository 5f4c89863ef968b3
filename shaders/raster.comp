// Adds point samples of glyph outlines into the atlas accumulators.
//
// Each workgroup takes 64 texels of one glyph (the work items tile the dispatch; an item covers a
// part of a glyph's rect, or a range of that part's texels), each invocation one texel. For every sample it places one point per colour channel inside that channel's
// subpixel rectangle (the R2 sequence, continued across frames), casts a ray towards +x from each
// and counts the nonzero winding number over the curves of the bands the subgroup touches, using
// Lengyel's root classification. A covered sample adds kRasterCoverageOne to its channel.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "shared.h"

layout(local_size_x = kRasterWorkgroupSize) in;

layout(push_constant) uniform PushConstants {
    RasterPushConstants pc;
};

layout(set = 0, binding = kRasterBindAtlas, rgba16ui) uniform uimage2D atlas;

layout(std430, set = 0, binding = kRasterBindItems) readonly buffer Items {
    RasterItem items[];
};

layout(std430, set = 0, binding = kRasterBindPoints) readonly buffer Points {
    vec2 points[];
} fonts_points[kRasterFontPages];

layout(std430, set = 0, binding = kRasterBindBands) readonly buffer Bands {
    uint words[];
} fonts_bands[kRasterFontPages];

// Below this |a| (em) the curve is treated as a line: t = c / 2b.
const float kLinearEpsilon = 1.0 / 65536.0;

// The winding contribution of one curve, relative to the sample (the sample is the origin, the
// ray runs along +x). The signs of the three y values pick which roots count (the 3-bit class
// looked up in 0x2E74): a crossing at a shared end point is counted once, tangents and curves
// that touch the ray without crossing it count zero.
int winding(vec2 p0, vec2 p1, vec2 p2) {
    uint shift = (floatBitsToUint(p0.y) >> 31) | ((floatBitsToUint(p1.y) >> 30) & 2u) |
                 ((floatBitsToUint(p2.y) >> 29) & 4u);
    uint code = (0x2E74u >> shift) & 0x0101u;
    if (code == 0u) return 0;
    float ay = p0.y - 2.0 * p1.y + p2.y;
    float by = p0.y - p1.y;
    float d = sqrt(max(by * by - ay * p0.y, 0.0));
    float t1, t2;
    if (abs(ay) < kLinearEpsilon) {
        t1 = t2 = p0.y / (2.0 * by);
    } else {
        t1 = (by - d) / ay;
        t2 = (by + d) / ay;
    }
    float ax = p0.x - 2.0 * p1.x + p2.x;
    float bx = p0.x - p1.x;
    int w = 0;
    if ((code & 1u) != 0u && (ax * t1 - 2.0 * bx) * t1 + p0.x > 0.0) w += 1;
    if (code > 1u && (ax * t2 - 2.0 * bx) * t2 + p0.x > 0.0) w -= 1;
    return w;
}

// The same for three samples on one row (stripe layouts): the roots depend only on y, so they are
// solved once and compared against each sample's x.
ivec3 winding_row(vec2 p0, vec2 p1, vec2 p2, float y, vec3 xs) {
    p0.y -= y;
    p1.y -= y;
    p2.y -= y;
    uint shift = (floatBitsToUint(p0.y) >> 31) | ((floatBitsToUint(p1.y) >> 30) & 2u) |
                 ((floatBitsToUint(p2.y) >> 29) & 4u);
    uint code = (0x2E74u >> shift) & 0x0101u;
    if (code == 0u) return ivec3(0);
    float ay = p0.y - 2.0 * p1.y + p2.y;
    float by = p0.y - p1.y;
    float d = sqrt(max(by * by - ay * p0.y, 0.0));
    float t1, t2;
    if (abs(ay) < kLinearEpsilon) {
        t1 = t2 = p0.y / (2.0 * by);
    } else {
        t1 = (by - d) / ay;
        t2 = (by + d) / ay;
    }
    float ax = p0.x - 2.0 * p1.x + p2.x;
    float bx = p0.x - p1.x;
    ivec3 w = ivec3(0);
    // x - xs > 0 written as in winding(), so both paths decide alike.
    if ((code & 1u) != 0u) w += ivec3(greaterThan((ax * t1 - 2.0 * bx) * t1 + (p0.x - xs), vec3(0.0)));
    if (code > 1u) w -= ivec3(greaterThan((ax * t2 - 2.0 * bx) * t2 + (p0.x - xs), vec3(0.0)));
    return w;
}

uint band_of(RasterItem item, float y) {
    float height = (item.bbox_max_y - item.bbox_min_y) / float(item.band_count);
    if (!(height > 0.0)) return 0u;
    float band = floor((y - item.bbox_min_y) / height);
    if (!(band > 0.0)) return 0u;
    return min(uint(band), item.band_count - 1u);
}

uint find_item(uint workgroup) {
    // The last item whose first workgroup is at or before this one.
    uint lo = 0u, hi = pc.item_count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1;
        if (items[mid].first_workgroup <= workgroup) lo = mid;
        else hi = mid - 1u;
    }
    return lo;
}

void main() {
    uint workgroup = gl_WorkGroupID.y * kRasterDispatchWidth + gl_WorkGroupID.x;
    if (workgroup >= pc.workgroup_count) return;
    RasterItem item = items[find_item(workgroup)];
    uint local = (workgroup - item.first_workgroup) * kRasterWorkgroupSize + gl_LocalInvocationIndex;
    if (local >= item.texel_count) return;
    local += item.first_texel;
    uint tx = local % item.width;
    uint ty = local / item.width;
    ivec2 texel = ivec2(item.atlas_x + tx, item.atlas_y + ty);
    tx += item.part_x;  // from here on, texels of the glyph rect
    ty += item.part_y;
    uvec4 sums = item.first_sample == 0u ? uvec4(0u) : imageLoad(atlas, texel);
    uint font = item.font;

    for (uint k = 0u; k < item.sample_count; ++k) {
        // R2: frac(0.5 + n * (1/g, 1/g^2)), g the plastic number. n stays far below 2^24.
        float n = float(item.first_sample + k);
        vec2 r2 = fract(0.5 + n * vec2(0.7548776662466927, 0.5698402909980532));
        vec2 em[3];
        uint lo_band = 0xFFFFFFFFu, hi_band = 0u;
        for (int c = 0; c < 3; ++c) {
            vec4 rect = pc.channel_rects[c];
            vec2 p = vec2(float(tx), float(ty)) + mix(rect.xy, rect.zw, r2);
            em[c] = vec2(item.offset_x + item.scale_x * p.x, item.offset_y + item.scale_y * p.y);
            uint band = band_of(item, em[c].y);
            lo_band = min(lo_band, band);
            hi_band = max(hi_band, band);
        }
        // Uniform band range across the subgroup, so the curve loop and its loads are uniform.
        lo_band = subgroupMin(lo_band);
        hi_band = subgroupMax(hi_band);

        ivec3 w = ivec3(0);
        for (uint word = 0u; word < item.band_words; ++word) {
            uint bits = 0u;
            for (uint band = lo_band; band <= hi_band; ++band) {
                bits |= fonts_bands[font].words[item.band_offset + band * item.band_words + word];
            }
            while (bits != 0u) {
                uint bit = findLSB(bits);
                bits &= bits - 1u;
                uint first = item.point_offset + 2u * (word * 32u + bit);
                vec2 p0 = fonts_points[font].points[first];
                vec2 p1 = fonts_points[font].points[first + 1u];
                vec2 p2 = fonts_points[font].points[first + 2u];
                if (pc.shared_rows != 0u) {
                    w += winding_row(p0, p1, p2, em[0].y, vec3(em[0].x, em[1].x, em[2].x));
                } else {
                    w.r += winding(p0 - em[0], p1 - em[0], p2 - em[0]);
                    w.g += winding(p0 - em[1], p1 - em[1], p2 - em[1]);
                    w.b += winding(p0 - em[2], p1 - em[2], p2 - em[2]);
                }
            }
        }
        sums.rgb += uvec3(notEqual(w, ivec3(0))) * kRasterCoverageOne;
    }
    sums.a += item.sample_count;
    imageStore(atlas, texel, sums);
}
