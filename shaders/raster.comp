// Adds row samples (or point samples) of glyph outlines into the atlas accumulators.
//
// Each workgroup takes 64 texels of one glyph (the work items tile the dispatch; an item covers a
// part of a glyph's rect, or a range of that part's texels), each invocation one texel.
//
// Row samples (the default): sample n is, per colour channel, a horizontal segment across that
// channel's subpixel rectangle at the height frac(radical_inverse_2(n) + kRasterRowOffset) of it
// (continued across frames). The roots of each curve of the bands the subgroup touches on that
// row (Lengyel's root classification, as for points) give the winding at the segment's start and
// the crossings inside it, which are sorted and walked: the covered length under the nonzero rule
// is exact, overlapping contours included. The covered fraction adds up to kRasterCoverageOne,
// dithered to whole units by the R2 x offset of n.
//
// Point samples: one point per channel inside its rectangle (the R2 sequence), a ray towards +x,
// and the nonzero winding number; a covered sample adds kRasterCoverageOne.
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

// ---- Row samples.

// Per channel, the row segment of the sample being walked: [row_start, row_end] in em, the
// winding just right of row_start (the crossings right of it), and the crossings inside
// (row_start, row_end) sorted by x. At most kRasterRowCrossings are kept, the leftmost; when one
// more comes, the rightmost is dropped and row_more says that the segment goes on from the last
// crossing kept, in another pass.
float row_start[3];
float row_end[3];
int row_winding[3];
uint row_count[3];
bool row_more[3];
float row_x[3][kRasterRowCrossings];
int row_direction[3][kRasterRowCrossings];

// Step j of an insertion of x among the first n (< kRasterRowCrossings) sorted entries: entry j - 1
// moves up to j when greater than x, otherwise x goes to j and the insertion is done.
void row_insert_step(uint c, uint j, uint n, float x, int direction, inout bool placed) {
    if (placed || j > n) return;
    if (row_x[c][j - 1u] > x) {
        row_x[c][j] = row_x[c][j - 1u];
        row_direction[c][j] = row_direction[c][j - 1u];
    } else {
        row_x[c][j] = x;
        row_direction[c][j] = direction;
        placed = true;
    }
}

// row_crossing() writes out its insertion's steps for 8 registers: a shader of this size fails to
// compile if kRasterRowCrossings changes without them.
const uint kRowInsertStepsWritten[kRasterRowCrossings == 8u ? 1 : 0] = uint[1](8u);

void row_crossing(uint c, float x, int direction) {
    if (!(x > row_start[c])) return;
    row_winding[c] += direction;
    if (!(x < row_end[c])) return;
    uint n = row_count[c];
    bool full = n == kRasterRowCrossings;
    if (full) row_more[c] = true;
    // When full, the rightmost is dropped: every crossing dropped lies at or right of every one kept.
    if (full && !(x < row_x[c][kRasterRowCrossings - 1u])) return;
    if (full) n = kRasterRowCrossings - 1u;
    row_count[c] = n + 1u;
    // Written out, not a loop: lavapipe ends every loop of an invocation once their iterations
    // together reach 65535, and this runs per crossing (see "Loops" in docs/rasterizer.md).
    bool placed = false;
    row_insert_step(c, 7u, n, x, direction, placed);
    row_insert_step(c, 6u, n, x, direction, placed);
    row_insert_step(c, 5u, n, x, direction, placed);
    row_insert_step(c, 4u, n, x, direction, placed);
    row_insert_step(c, 3u, n, x, direction, placed);
    row_insert_step(c, 2u, n, x, direction, placed);
    row_insert_step(c, 1u, n, x, direction, placed);
    if (!placed) {
        row_x[c][0] = x;
        row_direction[c][0] = direction;
    }
}

// The roots of one curve as crossings of channel c's segment.
void row_roots(uint c, uint code, float x1, float x2) {
    if ((code & 1u) != 0u) row_crossing(c, x1, 1);
    if (code > 1u) row_crossing(c, x2, -1);
}

// The crossings of one curve with the row at height y (absolute em), added to the channels of
// `mask`. The roots are Lengyel's, as in winding(); x(t) is absolute, so one solve serves every
// channel on the row.
void row_curve(vec2 p0, vec2 p1, vec2 p2, float y, uint mask) {
    p0.y -= y;
    p1.y -= y;
    p2.y -= y;
    uint shift = (floatBitsToUint(p0.y) >> 31) | ((floatBitsToUint(p1.y) >> 30) & 2u) |
                 ((floatBitsToUint(p2.y) >> 29) & 4u);
    uint code = (0x2E74u >> shift) & 0x0101u;
    if (code == 0u) return;
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
    float x1 = (ax * t1 - 2.0 * bx) * t1 + p0.x;
    float x2 = (ax * t2 - 2.0 * bx) * t2 + p0.x;
    // Two roots that meet (a tangent, or a curve that misses the row) cancel exactly: skipping them
    // keeps the walk the same whichever band range the curves come from (the CPU reference reads
    // only the sample's band).
    if (code == 0x0101u && x1 == x2) return;
    // The channels written out, not a loop (as in row_crossing()).
    if ((mask & 1u) != 0u) row_roots(0u, code, x1, x2);
    if ((mask & 2u) != 0u) row_roots(1u, code, x1, x2);
    if ((mask & 4u) != 0u) row_roots(2u, code, x1, x2);
}

// The covered length of the part of channel c's segment this pass saw: up to its end, or up to
// its last crossing kept when more follow (row_start then moves there for the next pass).
float row_walk(uint c) {
    int w = row_winding[c];
    float at = row_start[c];
    float length = 0.0;
    for (uint i = 0u; i < row_count[c]; ++i) {
        float x = row_x[c][i];
        if (w != 0) length += x - at;
        w -= row_direction[c][i];
        at = x;
    }
    if (row_more[c]) {
        row_start[c] = at;
    } else if (w != 0) {
        length += row_end[c] - at;
    }
    return length;
}

// The covered fraction of a segment of `length` em in kRasterCoverageOne units, dithered: the
// fraction's remainder becomes one more unit when it is at least 1 - dither, so that over samples
// with equidistributed dithers the sum's quantization error stays below a unit or two instead of
// growing with the sample count. Empty and full segments stay exactly 0 and kRasterCoverageOne.
uint row_units(float covered, float length, float dither) {
    if (!(length > 0.0)) return 0u;
    float units = floor((covered / length) * float(kRasterCoverageOne) + dither);
    return uint(clamp(units, 0.0, float(kRasterCoverageOne)));
}

// The height of row sample n within the rect, in [0, 1): the base-2 radical inverse of n (exact
// in float) plus kRasterRowOffset, wrapped.
float row_height(uint n) {
    return fract(float(bitfieldReverse(n)) * (1.0 / 4294967296.0) + kRasterRowOffset);
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

// The item's point samples of texel (tx, ty) of the glyph rect: kRasterCoverageOne per covered
// sample and channel.
uvec3 point_samples(RasterItem item, uint tx, uint ty) {
    uint font = item.font;
    uvec3 sums = uvec3(0u);
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
        sums += uvec3(notEqual(w, ivec3(0))) * kRasterCoverageOne;
    }
    return sums;
}

// The item's row samples of texel (tx, ty) of the glyph rect: per sample and channel, the covered
// fraction of the channel's segment in kRasterCoverageOne units.
uvec3 row_samples(RasterItem item, uint tx, uint ty) {
    uint font = item.font;
    uvec3 sums = uvec3(0u);
    for (uint k = 0u; k < item.sample_count; ++k) {
        uint n = item.first_sample + k;
        float v = row_height(n);
        // The R2 x offset of n, free now that rows need no x: the dither of the quantization.
        float dither = fract(0.5 + float(n) * 0.7548776662466927);
        float ys[3];
        float lengths[3];
        uint lo_band = 0xFFFFFFFFu, hi_band = 0u;
        for (uint c = 0u; c < 3u; ++c) {
            vec4 rect = pc.channel_rects[c];
            float py = float(ty) + (rect.y + (rect.w - rect.y) * v);
            ys[c] = item.offset_y + item.scale_y * py;
            row_start[c] = item.offset_x + item.scale_x * (float(tx) + rect.x);
            row_end[c] = item.offset_x + item.scale_x * (float(tx) + rect.z);
            lengths[c] = row_end[c] - row_start[c];
            uint band = band_of(item, ys[c]);
            lo_band = min(lo_band, band);
            hi_band = max(hi_band, band);
        }
        // Uniform band range across the subgroup, so the curve loop and its loads are uniform.
        lo_band = subgroupMin(lo_band);
        hi_band = subgroupMax(hi_band);

        // Channels whose segment is still being walked; a pass per kRasterRowCrossings crossings.
        // The subgroup passes together (an invocation done adds nothing), so that the curve loop
        // and its loads stay uniform.
        float covered[3] = float[3](0.0, 0.0, 0.0);
        // Equal rects (gray) give three equal walks: the red one stands for all.
        uint pending = pc.equal_channels != 0u ? 1u : 7u;
        while (subgroupMax(pending) != 0u) {
            for (uint c = 0u; c < 3u; ++c) {
                row_winding[c] = 0;
                row_count[c] = 0u;
                row_more[c] = false;
            }
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
                        row_curve(p0, p1, p2, ys[0], pending);
                    } else {
                        // The channels written out, not a loop (as in row_crossing()).
                        if ((pending & 1u) != 0u) row_curve(p0, p1, p2, ys[0], 1u);
                        if ((pending & 2u) != 0u) row_curve(p0, p1, p2, ys[1], 2u);
                        if ((pending & 4u) != 0u) row_curve(p0, p1, p2, ys[2], 4u);
                    }
                }
            }
            uint next = 0u;
            for (uint c = 0u; c < 3u; ++c) {
                if ((pending & (1u << c)) == 0u) continue;
                covered[c] += row_walk(c);
                if (row_more[c]) next |= 1u << c;
            }
            pending = next;
        }
        if (pc.equal_channels != 0u) {
            sums += uvec3(row_units(covered[0], lengths[0], dither));
        } else {
            for (uint c = 0u; c < 3u; ++c) sums[c] += row_units(covered[c], lengths[c], dither);
        }
    }
    return sums;
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

    if (pc.sample_kind == kRasterSampleRows) {
        sums.rgb += row_samples(item, tx, ty);
    } else {
        sums.rgb += point_samples(item, tx, ty);
    }
    sums.a += item.sample_count;
    imageStore(atlas, texel, sums);
}
