// Adds row samples (or point samples) of glyph outlines into the atlas accumulators.
//
// Each workgroup takes 64 texels of one glyph (the work items tile the dispatch; an item covers a
// part of a glyph's rect, or a range of that part's texels), each invocation one texel.
//
// Row samples (the default): sample n is, per colour channel, a horizontal segment across that
// channel's subpixel rectangle at the height frac(radical_inverse_2(n) + kRasterRowOffset) of it
// (continued across frames). The roots of each curve of the sample's band on that row (Lengyel's
// root classification, as for points) give the winding at the segment's start and
// the crossings inside it, which are sorted and walked: the covered length under the nonzero rule
// is exact, overlapping contours included. Channels on one row (stripes, gray) share one sorted
// list over the union of their segments, each covered stretch clipped to each channel's segment.
// The covered fraction adds up to kRasterCoverageOne, dithered to whole units by the R2 x offset
// of n.
//
// Point samples: one point per channel inside its rectangle (the R2 sequence), a ray towards +x,
// and the nonzero winding number; a covered sample adds kRasterCoverageOne.
//
// A transformed glyph (an item with a RasterTransform; docs/transforms.md) is sampled in its
// rect's texels, where rows stay horizontal: each curve of the bands its row segment crosses in em
// is mapped to texels in homogeneous coordinates (X, Y, W), a rational quadratic whose crossings
// with the row are the roots of Y - y W, classified as above, at x = X / W.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared.h"

layout(local_size_x = kRasterWorkgroupSize) in;

// The items this pipeline rasterizes: 0 axis-aligned ones, 1 transformed ones (those with a
// RasterTransform), kRasterTwoLineItems transformed ones that walk two lines a row sample. Three
// pipelines, so that the axis-aligned one carries none of the transformed path's registers (it
// cost axis-aligned text 46 % of its speed on an H200 in one kernel) and the one-line one none of
// the second line's.
layout(constant_id = 0) const uint kTransformedItems = 0u;
// 1: this pipeline's items are two sets of curves (an effect layer: docs/effects.md), the slots
// from RasterItem::set_b_first on the second, covered where the item's cover_rule holds for the
// two sets' windings; 0: one set, covered where its winding is nonzero.
layout(constant_id = 1) const uint kTwoSetItems = 0u;
// 1: this pipeline's items are blurred (a blurred shadow or glow: docs/effects.md, "Blur"), each
// channel's filter its sample interval convolved with the blur of box width RasterItem::blur_w:
// a row sample's height is the inverse CDF of the y filter at the row's height, and a covered
// stretch adds the x filter's CDF across it instead of its length.
layout(constant_id = 2) const uint kBlurItems = 0u;

layout(push_constant) uniform PushConstants {
    RasterPushConstants pc;
};

layout(set = 0, binding = kRasterBindAtlas, rgba16ui) uniform uimage2D atlas;

layout(std430, set = 0, binding = kRasterBindItems) readonly buffer Items {
    RasterItem items[];
};

// The index into `items` of each workgroup of the dispatch.
layout(std430, set = 0, binding = kRasterBindWorkgroupItems) readonly buffer WorkgroupItems {
    uint workgroup_items[];
};

layout(std430, set = 0, binding = kRasterBindTransforms) readonly buffer Transforms {
    RasterTransform transforms[];
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

// The row segment being walked: [start, end] in em (the union of the segments of the channels that
// share the row), the winding just right of start (the crossings right of it), and the crossings
// inside (start, end), kept in arrival order and sorted by x before the walk, with their
// directions as bits (set: -1, running up); unused entries hold +infinity. At most
// kRasterRowCrossings are kept, the leftmost; when one more comes, the largest kept gives way
// to a smaller one, and `more` says that the segment goes on from the last crossing kept, in
// another pass. Every index into `x` is a compile-time constant (the steps are written out), so
// that the list can live in registers. One list serves every channel on the row: the walk clips
// each covered stretch to each channel's own segment.
struct RowList {
    float start;
    float end;
    int winding;
    int winding_b;  // the same for the second set of a two-set item
    uint count;
    bool more;
    // A transformed row's later pass, which starts at a crossing kept by none before it: crossings
    // at the start count (the previous pass stopped short of every crossing there).
    bool from_crossing;
    uint up;
    uint in_b;  // per entry, set: a crossing of the second set
    float x[kRasterRowCrossings];
};

// Whether a point of windings wa (the first set) and wb (the second) is covered: nonzero wa, or
// for a two-set item the item's cover_rule, a truth table indexed by (wa != 0) + 2 (wb != 0).
bool row_covers(uint rule, int wa, int wb) {
    if (kTwoSetItems == 0u) return wa != 0;
    return ((rule >> (uint(wa != 0) | (uint(wb != 0) << 1u))) & 1u) != 0u;
}

// row_crossing(), row_sort() and row_walk() write out their steps for 8 entries: a shader of this
// size fails to compile if kRasterRowCrossings changes without them.
const uint kRowStepsWritten[kRasterRowCrossings == 8u ? 1 : 0] = uint[1](8u);

void row_begin_pass(inout RowList r) {
    r.winding = 0;
    r.winding_b = 0;
    r.count = 0u;
    r.more = false;
    r.up = 0u;
    r.in_b = 0u;
    const float inf = uintBitsToFloat(0x7F800000u);
    r.x[0] = inf;
    r.x[1] = inf;
    r.x[2] = inf;
    r.x[3] = inf;
    r.x[4] = inf;
    r.x[5] = inf;
    r.x[6] = inf;
    r.x[7] = inf;
}

// Crossing x of the row, running down (+1) or up (-1). Appending costs a dozen instructions where
// a sorted insertion cost some fifty, and a subgroup pays for whichever lane adds one: most
// crossings land in some lane's segment. Written out, not a loop: lavapipe ends every loop of an
// invocation once their iterations together reach 65535, and this runs per crossing (see "Loops"
// in docs/rasterizer.md).
void row_crossing(inout RowList r, float x, int direction, bool in_b) {
    if (!(x > r.start) && !(kTransformedItems != 0u && r.from_crossing && x == r.start)) return;
    if (kTwoSetItems != 0u && in_b) {
        r.winding_b += direction;
    } else {
        r.winding += direction;
    }
    if (!(x < r.end)) return;
    uint at = r.count;
    if (at == kRasterRowCrossings) {
        // Full: keep the 8 leftmost. Which of equal largest gives way changes no covered length
        // (crossings at one x bound stretches of no length).
        r.more = true;
        float largest = max(max(max(r.x[0], r.x[1]), max(r.x[2], r.x[3])), max(max(r.x[4], r.x[5]), max(r.x[6], r.x[7])));
        if (!(x < largest)) return;
        at = r.x[0] == largest   ? 0u
             : r.x[1] == largest ? 1u
             : r.x[2] == largest ? 2u
             : r.x[3] == largest ? 3u
             : r.x[4] == largest ? 4u
             : r.x[5] == largest ? 5u
             : r.x[6] == largest ? 6u
                                 : 7u;
    } else {
        r.count = at + 1u;
    }
    r.x[0] = at == 0u ? x : r.x[0];
    r.x[1] = at == 1u ? x : r.x[1];
    r.x[2] = at == 2u ? x : r.x[2];
    r.x[3] = at == 3u ? x : r.x[3];
    r.x[4] = at == 4u ? x : r.x[4];
    r.x[5] = at == 5u ? x : r.x[5];
    r.x[6] = at == 6u ? x : r.x[6];
    r.x[7] = at == 7u ? x : r.x[7];
    r.up = (r.up & ~(1u << at)) | (direction < 0 ? 1u << at : 0u);
    if (kTwoSetItems != 0u) r.in_b = (r.in_b & ~(1u << at)) | (in_b ? 1u << at : 0u);
}

// Entries i < j in order, with their direction bits.
void row_order(inout RowList r, uint i, uint j) {
    float a = r.x[i];
    float b = r.x[j];
    if (b < a) {
        r.x[i] = b;
        r.x[j] = a;
        uint differ = ((r.up >> i) ^ (r.up >> j)) & 1u;
        r.up ^= differ * ((1u << i) | (1u << j));
        if (kTwoSetItems != 0u) {
            uint differ_b = ((r.in_b >> i) ^ (r.in_b >> j)) & 1u;
            r.in_b ^= differ_b * ((1u << i) | (1u << j));
        }
    }
}

// Sorts the entries by x: sorting networks of 1, 5 and 19 comparators for up to 2, 4 and 8
// entries (the unused ones, +infinity, stay last). Entries of equal x may come in either order:
// they bound stretches of no length, so the covered lengths are the same bits as a stable sort's.
void row_sort(inout RowList r) {
    if (r.count == 2u) {
        row_order(r, 0u, 1u);
    } else if (r.count > 2u && r.count <= 4u) {
        row_order(r, 0u, 1u);
        row_order(r, 2u, 3u);
        row_order(r, 0u, 2u);
        row_order(r, 1u, 3u);
        row_order(r, 1u, 2u);
    } else if (r.count > 4u) {
        row_order(r, 0u, 2u);
        row_order(r, 1u, 3u);
        row_order(r, 4u, 6u);
        row_order(r, 5u, 7u);
        row_order(r, 0u, 4u);
        row_order(r, 1u, 5u);
        row_order(r, 2u, 6u);
        row_order(r, 3u, 7u);
        row_order(r, 0u, 1u);
        row_order(r, 2u, 3u);
        row_order(r, 4u, 5u);
        row_order(r, 6u, 7u);
        row_order(r, 2u, 4u);
        row_order(r, 3u, 5u);
        row_order(r, 1u, 4u);
        row_order(r, 3u, 6u);
        row_order(r, 1u, 2u);
        row_order(r, 3u, 4u);
        row_order(r, 5u, 6u);
    }
}

// The roots of a quadratic whose Bernstein coefficients are y0, y1, y2 (a curve's y relative to
// the row): Lengyel's classification of their signs, which roots count (code: bit 0 the first,
// bit 8 the second; 0 none), and the roots as in winding().
uint row_roots(float y0, float y1, float y2, out float t1, out float t2) {
    uint shift = (floatBitsToUint(y0) >> 31) | ((floatBitsToUint(y1) >> 30) & 2u) | ((floatBitsToUint(y2) >> 29) & 4u);
    uint code = (0x2E74u >> shift) & 0x0101u;
    float ay = y0 - 2.0 * y1 + y2;
    float by = y0 - y1;
    float d = sqrt(max(by * by - ay * y0, 0.0));
    if (abs(ay) < kLinearEpsilon) {
        t1 = t2 = y0 / (2.0 * by);
    } else {
        t1 = (by - d) / ay;
        t2 = (by + d) / ay;
    }
    return code;
}

// The quadratic of Bernstein coefficients x0, x1, x2 at t.
float bernstein(float x0, float x1, float x2, float t) {
    return ((x0 - 2.0 * x1 + x2) * t - 2.0 * (x0 - x1)) * t + x0;
}

// ---- Blur (src/text/blur_kernel.hpp, operation for operation).

// The CDF of the unit B3 kernel (three unit boxes, support [-3/2, 3/2]) at z.
float blur_b3_cdf(float z) {
    float a = abs(z);
    float upper;  // the CDF at -a
    if (a >= 1.5) {
        upper = 0.0;
    } else if (a >= 0.5) {
        float s = 1.5 - a;
        upper = s * s * s / 6.0;
    } else {
        upper = 0.5 - a * (0.75 - a * a / 3.0);
    }
    return z < 0.0 ? upper : 1.0 - upper;
}

// The integral of blur_b3_cdf from -infinity to z.
float blur_h(float z) {
    float n = -abs(z);
    float h;
    if (n <= -1.5) {
        h = 0.0;
    } else if (n <= -0.5) {
        float s = n + 1.5;
        float s2 = s * s;
        h = s2 * s2 / 24.0;
    } else {
        float s = n + 0.5;
        float n2 = n * n;
        h = 1.0 / 24.0 + s / 6.0 + 0.375 * s * s - (n2 * n2 / 4.0 + n / 8.0 + 3.0 / 64.0) / 3.0;
    }
    return z > 0.0 ? z + h : h;
}

// The CDF at t of the box [x0, x1] convolved with the blur of box width w > 0.
float blur_cdf(float t, float x0, float x1, float w) {
    float b = x1 - x0;
    if (!(b > 0.0)) return blur_b3_cdf((t - x0) / w);
    return (w / b) * (blur_h((t - x0) / w) - blur_h((t - x1) / w));
}

float blur_density(float t, float x0, float x1, float w) {
    float b = x1 - x0;
    if (!(b > 0.0)) return 0.0;
    return (blur_b3_cdf((t - x0) / w) - blur_b3_cdf((t - x1) / w)) / b;
}

// One safeguarded Newton step of blur_inverse_cdf().
void blur_inverse_step(float v, float x0, float x1, float w, inout float lo, inout float hi, inout float t) {
    float f = blur_cdf(t, x0, x1, w) - v;
    if (f < 0.0) lo = t;
    if (f > 0.0) hi = t;
    float d = blur_density(t, x0, x1, w);
    float next = d > 0.0 ? t - f / d : lo - 1.0;
    t = next >= lo && next <= hi ? next : 0.5 * (lo + hi);
}

// The t where blur_cdf(t, x0, x1, w) = v: kBlurInverseSteps (12) steps, written out (see "Loops"
// in docs/rasterizer.md).
float blur_inverse_cdf(float v, float x0, float x1, float w) {
    float lo = x0 - 1.5 * w, hi = x1 + 1.5 * w;
    float t = x0 + v * (x1 - x0);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    blur_inverse_step(v, x0, x1, w, lo, hi, t);
    return t;
}

// Adds the crossings x1 and x2 that `code` counts. Two roots that meet (a tangent, or a curve
// that misses the row) cancel exactly: skipping them keeps the walk the same whichever band range
// the curves come from (the CPU reference reads only the sample's band).
void row_add_roots(inout RowList r, uint code, float x1, float x2, bool in_b) {
    if (code == 0x0101u && x1 == x2) return;
    if ((code & 1u) != 0u) row_crossing(r, x1, 1, in_b);
    if (code > 1u) row_crossing(r, x2, -1, in_b);
}

// The crossings of one curve with the row at height y (absolute em): Lengyel's roots as in
// winding(), as absolute x's, added to the list.
void row_curve(inout RowList r, vec2 p0, vec2 p1, vec2 p2, float y, bool in_b) {
    float t1, t2;
    uint code = row_roots(p0.y - y, p1.y - y, p2.y - y, t1, t2);
    if (code == 0u) return;
    row_add_roots(r, code, bernstein(p0.x, p1.x, p2.x, t1), bernstein(p0.x, p1.x, p2.x, t2), in_b);
}

// The same for a curve of a transformed glyph (em), for the row whose Y - y W is dot(row, (p, 1))
// (to_texel's second row less y times its third): its roots classified from those three values,
// and only a curve that crosses is mapped on, to X / W (W is 1 without perspective).
void row_curve_transformed(inout RowList r, RasterTransform m, vec3 row, bool perspective, vec2 p0, vec2 p1, vec2 p2,
                           bool in_b) {
    float t1, t2;
    uint code = row_roots(dot(row, vec3(p0, 1.0)), dot(row, vec3(p1, 1.0)), dot(row, vec3(p2, 1.0)), t1, t2);
    if (code == 0u) return;
    vec3 to_x = m.to_texel[0].xyz;
    float x0 = dot(to_x, vec3(p0, 1.0)), x1 = dot(to_x, vec3(p1, 1.0)), x2 = dot(to_x, vec3(p2, 1.0));
    float a = bernstein(x0, x1, x2, t1), b = bernstein(x0, x1, x2, t2);
    if (perspective) {
        vec3 to_w = m.to_texel[2].xyz;
        float w0 = dot(to_w, vec3(p0, 1.0)), w1 = dot(to_w, vec3(p1, 1.0)), w2 = dot(to_w, vec3(p2, 1.0));
        a /= bernstein(w0, w1, w2, t1);
        b /= bernstein(w0, w1, w2, t2);
    }
    row_add_roots(r, code, a, b, in_b);
}

// Adds the covered stretch [from, to] of the row, clipped to each channel's segment [lo, hi].
// Inside a channel's segment the clip is exact (min and max pick an operand), so a channel sums
// the same differences as a walk of its own segment would. A blurred item (blur, the box width in
// the row's units, > 0) adds each channel's filter CDF across the stretch instead: its fraction
// of the channel's blurred coverage.
void row_cover(inout vec3 covered, float from, float to, vec3 lo, vec3 hi, float blur) {
    if (kBlurItems != 0u && blur > 0.0) {
        covered += vec3(blur_cdf(to, lo.x, hi.x, blur) - blur_cdf(from, lo.x, hi.x, blur),
                        blur_cdf(to, lo.y, hi.y, blur) - blur_cdf(from, lo.y, hi.y, blur),
                        blur_cdf(to, lo.z, hi.z, blur) - blur_cdf(from, lo.z, hi.z, blur));
        return;
    }
    covered += max(min(vec3(to), hi) - max(vec3(from), lo), vec3(0.0));
}

// Step i of the walk.
void row_walk_step(RowList r, uint rule, uint i, vec3 lo, vec3 hi, float blur, float limit, inout ivec2 w,
                   inout float at, inout vec3 covered) {
    if (i >= r.count || !(r.x[i] < limit)) return;
    float x = r.x[i];
    if (row_covers(rule, w.x, w.y)) row_cover(covered, at, x, lo, hi, blur);
    int step = (r.up & (1u << i)) != 0u ? -1 : 1;
    if (kTwoSetItems != 0u && (r.in_b & (1u << i)) != 0u) {
        w.y -= step;
    } else {
        w.x -= step;
    }
    at = x;
}

// The covered length of each channel's segment [lo, hi] within the part of the row this pass saw:
// up to its end, or up to its last crossing kept when more follow (start then moves there for the
// next pass). Sorts the list first. Written out, as the crossings, so that the list's indices are
// constants. `blur`: row_cover()'s.
vec3 row_walk(inout RowList r, uint rule, vec3 lo, vec3 hi, float blur) {
    row_sort(r);
    ivec2 w = ivec2(r.winding, r.winding_b);
    float at = r.start;
    vec3 covered = vec3(0.0);
    // A transformed row carries its winding to the next pass, so a pass that overflowed stops short
    // of the largest crossing kept: a crossing of the same x may have been dropped, and the next
    // pass takes them all, from there (unless all eight kept share that x: then as before).
    const float inf = uintBitsToFloat(0x7F800000u);
    float limit = kTransformedItems != 0u && r.more && r.x[0] < r.x[7] ? r.x[7] : inf;
    row_walk_step(r, rule, 0u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 1u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 2u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 3u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 4u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 5u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 6u, lo, hi, blur, limit, w, at, covered);
    row_walk_step(r, rule, 7u, lo, hi, blur, limit, w, at, covered);
    if (r.more) {
        if (limit < inf) {
            if (row_covers(rule, w.x, w.y)) row_cover(covered, at, limit, lo, hi, blur);
            at = limit;
        }
        r.from_crossing = limit < inf;
        r.start = at;
        r.winding = w.x;  // just right of the new start: what a transformed row carries to its next pass
        r.winding_b = w.y;
    } else if (row_covers(rule, w.x, w.y)) {
        row_cover(covered, at, r.end, lo, hi, blur);
    }
    return covered;
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

// A sample's two lines of a glyph whose stems run along the rows sit this far either side of its
// height: 1/32, so that eight samples' lines are the centres of sixteen strata.
const float kRasterHalfRowShift = 1.0 / 32.0;

// How far left of its segment a transformed row starts (texels): an odd fraction, unlike curve
// positions on a fixed-point grid.
const float kTransformedStartBack = 0.000707107;

// Texel point (x, y) of a transformed glyph's rect in em.
vec2 texel_em(RasterTransform m, float x, float y) {
    vec3 h = vec3(dot(m.to_em[0].xyz, vec3(x, y, 1.0)), dot(m.to_em[1].xyz, vec3(x, y, 1.0)),
                  dot(m.to_em[2].xyz, vec3(x, y, 1.0)));
    return h.xy / h.z;
}

uint band_of(RasterItem item, float y) {
    float height = (item.bbox_max_y - item.bbox_min_y) / float(item.band_count);
    if (!(height > 0.0)) return 0u;
    float band = floor((y - item.bbox_min_y) / height);
    if (!(band > 0.0)) return 0u;
    return min(uint(band), item.band_count - 1u);
}

// The item's point samples of texel (tx, ty) of the glyph rect: kRasterCoverageOne per covered
// sample and channel.
uvec3 point_samples(RasterItem item, uint tx, uint ty) {
    uint font = item.font;
    const bool transformed = kTransformedItems != 0u;
    RasterTransform m;
    if (transformed) m = transforms[item.transform];
    uvec3 sums = uvec3(0u);
    for (uint k = 0u; k < item.sample_count; ++k) {
        // R2: frac(0.5 + n * (1/g, 1/g^2)), g the plastic number. n stays far below 2^24.
        float n = float(item.first_sample + k);
        vec2 r2 = fract(0.5 + n * vec2(kRasterR2StepX, kRasterR2StepY));
        vec2 em[3];
        uint lo_band = 0xFFFFFFFFu, hi_band = 0u;
        for (int c = 0; c < 3; ++c) {
            vec4 rect = pc.channel_rects[c];
            vec2 p = vec2(float(tx), float(ty)) + mix(rect.xy, rect.zw, r2);
            // A blurred point: each coordinate the inverse CDF of its axis's filter at r2.
            if (kBlurItems != 0u) {
                p = vec2(blur_inverse_cdf(r2.x, float(tx) + rect.x, float(tx) + rect.z, item.blur_w),
                         blur_inverse_cdf(r2.y, float(ty) + rect.y, float(ty) + rect.w, item.blur_w));
            }
            em[c] = transformed ? texel_em(m, p.x, p.y)
                                : vec2(item.offset_x + item.scale_x * p.x, item.offset_y + item.scale_y * p.y);
            uint band = band_of(item, em[c].y);
            lo_band = min(lo_band, band);
            hi_band = max(hi_band, band);
        }
        // The bands of this invocation's channels (one where they share a row): a subgroup takes as
        // many steps as its fullest range has curves, not the curves of every range it holds.

        ivec3 w = ivec3(0), w_b = ivec3(0);
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
                ivec3 here;
                if (pc.shared_rows != 0u && !transformed) {
                    here = winding_row(p0, p1, p2, em[0].y, vec3(em[0].x, em[1].x, em[2].x));
                } else {
                    here = ivec3(winding(p0 - em[0], p1 - em[0], p2 - em[0]), winding(p0 - em[1], p1 - em[1], p2 - em[1]),
                                 winding(p0 - em[2], p1 - em[2], p2 - em[2]));
                }
                if (kTwoSetItems != 0u && word * 32u + bit >= item.set_b_first) {
                    w_b += here;
                } else {
                    w += here;
                }
            }
        }
        for (int c = 0; c < 3; ++c) {
            if (row_covers(item.cover_rule, w[c], w_b[c])) sums[c] += kRasterCoverageOne;
        }
    }
    return sums;
}

// One line of a transformed glyph's row sample being walked: its list, its height, the row's
// Y - y W, its start in em and that start's windings (both sets), found from an em ray in the
// start's band on the first pass and carried from pass to pass.
struct RowLine {
    RowList r;
    float y;
    vec3 y_row;
    vec2 start_em;
    uint start_band;
    bool start_inside;
    ivec2 start_winding;
    bool pending;  // passes remain
};

// Sets up line `line` at height h (texels) of the row rect `rect` over the segment [start, end],
// and widens [lo_band, hi_band] to the bands the segment crosses.
// The row segment is oblique in em: it walks the bands it crosses. Its crossings past the
// segment's end lie in other bands, so the winding at its start is not theirs to count: it is the
// start's own, from a ray along em x in the start's band (winding()), negated where the map to
// texels reverses orientation, and carried from pass to pass.
void row_line_begin(inout RowLine line, RasterItem item, RasterTransform m, vec4 rect, uint ty, float h, float start,
                    float end, inout uint lo_band, inout uint hi_band) {
    // A blurred row sits where the y filter's CDF is h (texels: row_samples() widened the segment).
    line.y = kBlurItems != 0u ? blur_inverse_cdf(h, float(ty) + rect.y, float(ty) + rect.w, item.blur_w)
                              : float(ty) + (rect.y + (rect.w - rect.y) * h);
    line.y_row = m.to_texel[1].xyz - line.y * m.to_texel[2].xyz;
    // The start a hair left of the segment, so that it is not on a curve where the segment begins
    // at one (a stem on the texel's edge): the walk clips to the channels' segments, so the stretch
    // before them adds nothing.
    line.r.start = start - kTransformedStartBack;
    line.r.from_crossing = false;
    line.r.end = end;
    line.start_em = texel_em(m, line.r.start, line.y);
    float yb = texel_em(m, line.r.end, line.y).y;
    line.start_band = band_of(item, line.start_em.y);
    // Outside the glyph's bbox the start's winding is 0: no ray to cast.
    line.start_inside = line.start_em.x >= m.to_texel[1].w && line.start_em.x <= m.to_texel[2].w &&
                        line.start_em.y >= item.bbox_min_y && line.start_em.y <= item.bbox_max_y;
    line.start_winding = ivec2(0);
    line.pending = true;
    lo_band = min(lo_band, band_of(item, min(line.start_em.y, yb)));
    hi_band = max(hi_band, band_of(item, max(line.start_em.y, yb)));
}

// The bits of word `word` of the start's band, for the start's winding (first pass only).
uint row_line_start_bits(RowLine line, RasterItem item, uint word, bool first_pass) {
    if (!first_pass || !line.start_inside) return 0u;
    return fonts_bands[item.font].words[item.band_offset + line.start_band * item.band_words + word];
}

// One curve (slot `bit` of the word whose start bits are `start_bits`) for the line.
void row_line_curve(inout RowLine line, RasterTransform m, bool perspective, vec2 p0, vec2 p1, vec2 p2, bool in_b,
                    uint start_bits, uint bit) {
    row_curve_transformed(line.r, m, line.y_row, perspective, p0, p1, p2, in_b);
    if (((start_bits >> bit) & 1u) != 0u) {
        int wound = winding(p0 - line.start_em, p1 - line.start_em, p2 - line.start_em);
        line.start_winding += in_b ? ivec2(0, wound) : ivec2(wound, 0);
    }
}

// The end of a pass: the line's covered lengths, and whether it needs another pass.
vec3 row_line_end(inout RowLine line, RasterItem item, RasterTransform m, vec3 lo, vec3 hi, bool first_pass) {
    ivec2 start = first_pass ? line.start_winding * int(m.to_texel[0].w) : line.start_winding;
    line.r.winding = start.x;
    line.r.winding_b = start.y;
    vec3 covered = row_walk(line.r, item.cover_rule, lo, hi, kBlurItems != 0u ? item.blur_w : 0.0);
    line.pending = line.r.more;
    line.start_winding = ivec2(line.r.winding, line.r.winding_b);
    return covered;
}

// row_samples() of an axis-aligned item, rows walked in em: each channel's segment [lo, hi] in x,
// `rows` rows a sample. Each invocation walks the curves of its own band: a subgroup then takes as
// many steps as its fullest band has curves, where a band range shared by the subgroup took the
// curves of all its rows' bands (the loads differ between invocations on different rows, a few
// addresses a step). Its own loop, without the transformed path's lines, so that its registers
// stay as few as they were before there was one (59 on an H200, against 67 in a loop shared with
// it: 6 % of its time).
uvec3 row_samples_axis_aligned(RasterItem item, vec3 lo, vec3 hi, uint rows, uint ty) {
    uint font = item.font;
    // The blur's box width in em along x (the filter's CDF is the same in any unit).
    float blur = kBlurItems != 0u ? item.blur_w * item.scale_x : 0.0;
    uvec3 sums = uvec3(0u);
    for (uint k = 0u; k < item.sample_count; ++k) {
        uint n = item.first_sample + k;
        float v = row_height(n);
        // The R2 x offset of n, free now that rows need no x: the dither of the quantization.
        float dither = fract(0.5 + float(n) * kRasterR2StepX);
        vec3 covered = vec3(0.0);
        for (uint row = 0u; row < rows; ++row) {
            vec4 rect = pc.channel_rects[row];
            // A blurred row sits where the y filter's CDF is v, its segment reaches the x filters'
            // supports, 3w/2 past the channels' intervals.
            float row_y = kBlurItems != 0u ? blur_inverse_cdf(v, float(ty) + rect.y, float(ty) + rect.w, item.blur_w)
                                           : float(ty) + (rect.y + (rect.w - rect.y) * v);
            float y = item.offset_y + item.scale_y * row_y;
            // The channels this row adds to, as factors: 1 keeps a length exactly, 0 adds nothing.
            vec3 mine = rows == 1u ? vec3(1.0) : vec3(equal(uvec3(0u, 1u, 2u), uvec3(row)));
            RowList r;
            r.from_crossing = false;
            r.start = (rows == 1u ? min(lo.x, min(lo.y, lo.z)) : lo[row]) - 1.5 * blur;
            r.end = (rows == 1u ? max(hi.x, max(hi.y, hi.z)) : hi[row]) + 1.5 * blur;
            uint band = band_of(item, y);
            // A pass per kRasterRowCrossings crossings.
            bool pending = true;
            while (pending) {
                row_begin_pass(r);
                for (uint word = 0u; word < item.band_words; ++word) {
                    uint bits = fonts_bands[font].words[item.band_offset + band * item.band_words + word];
                    while (bits != 0u) {
                        uint bit = findLSB(bits);
                        bits &= bits - 1u;
                        uint first = item.point_offset + 2u * (word * 32u + bit);
                        vec2 p0 = fonts_points[font].points[first];
                        vec2 p1 = fonts_points[font].points[first + 1u];
                        vec2 p2 = fonts_points[font].points[first + 2u];
                        row_curve(r, p0, p1, p2, y, kTwoSetItems != 0u && word * 32u + bit >= item.set_b_first);
                    }
                }
                covered += row_walk(r, item.cover_rule, lo, hi, blur) * mine;
                pending = r.more;
            }
        }
        // A blurred walk's sums are fractions already.
        vec3 lengths = kBlurItems != 0u ? vec3(1.0) : hi - lo;
        sums += uvec3(row_units(covered.x, lengths.x, dither), row_units(covered.y, lengths.y, dither),
                      row_units(covered.z, lengths.z, dither));
    }
    return sums;
}

// The item's row samples of texel (tx, ty) of the glyph rect: per sample and channel, the covered
// fraction of the channel's segment in kRasterCoverageOne units.
uvec3 row_samples(RasterItem item, uint tx, uint ty) {
    uint font = item.font;
    // A transformed glyph walks its rows in texels, others in em.
    const bool transformed = kTransformedItems != 0u;
    // Each channel's segment in x, the same for every sample.
    vec3 lo, hi;
    for (int c = 0; c < 3; ++c) {
        vec4 rect = pc.channel_rects[c];
        lo[c] = transformed ? float(tx) + rect.x : item.offset_x + item.scale_x * (float(tx) + rect.x);
        hi[c] = transformed ? float(tx) + rect.z : item.offset_x + item.scale_x * (float(tx) + rect.z);
    }
    // Channels that share their rows (stripes, gray) walk one list over the union of their
    // segments; otherwise each channel is a row of its own, walked in turn.
    uint rows = pc.shared_rows != 0u ? 1u : 3u;
    if (!transformed) return row_samples_axis_aligned(item, lo, hi, rows, ty);
    RasterTransform m = transforms[item.transform];
    bool perspective = m.to_texel[2].x != 0.0 || m.to_texel[2].y != 0.0;
    // Two lines a sample for the transformed glyphs whose stems run along the rows
    // (kRasterTwoLineItems), at v -+ 1/32, the centres of sixteen strata where v is of eight: walked
    // together, one pass over the curves of both lines' bands serving both lists. A curve of the
    // other line's bands crosses a line's segment nowhere (it would be listed in the band it
    // crosses in), and crossings right of the segment add nothing. Two named lines, not an array,
    // so that they stay in registers.
    const bool two_lines = kTransformedItems == kRasterTwoLineItems;
    uvec3 sums = uvec3(0u);
    for (uint k = 0u; k < item.sample_count; ++k) {
        uint n = item.first_sample + k;
        float v = row_height(n);
        // The R2 x offset of n, free now that rows need no x: the dither of the quantization.
        float dither = fract(0.5 + float(n) * kRasterR2StepX);
        vec3 covered = vec3(0.0);
        for (uint row = 0u; row < rows; ++row) {
            vec4 rect = pc.channel_rects[row];
            // The channels this row adds to, as factors: 1 keeps a length exactly, 0 adds nothing.
            vec3 mine = rows == 1u ? vec3(1.0) : vec3(equal(uvec3(0u, 1u, 2u), uvec3(row)));
            // A blurred segment reaches the x filters' supports, 3w/2 past the channels' intervals.
            float reach = kBlurItems != 0u ? 1.5 * item.blur_w : 0.0;
            float start = (rows == 1u ? min(lo.x, min(lo.y, lo.z)) : lo[row]) - reach;
            float end = (rows == 1u ? max(hi.x, max(hi.y, hi.z)) : hi[row]) + reach;
            uint lo_band = 0xFFFFFFFFu, hi_band = 0u;
            RowLine a, b;
            row_line_begin(a, item, m, rect, ty, two_lines ? fract(v - kRasterHalfRowShift) : v, start, end, lo_band,
                           hi_band);
            b.pending = false;
            if (two_lines) row_line_begin(b, item, m, rect, ty, fract(v + kRasterHalfRowShift), start, end, lo_band, hi_band);
            // A pass per kRasterRowCrossings crossings.
            bool first_pass = true;
            while (a.pending || b.pending) {
                if (a.pending) row_begin_pass(a.r);
                if (b.pending) row_begin_pass(b.r);
                for (uint word = 0u; word < item.band_words; ++word) {
                    uint bits = 0u;
                    for (uint band = lo_band; band <= hi_band; ++band) {
                        bits |= fonts_bands[font].words[item.band_offset + band * item.band_words + word];
                    }
                    // Curves flat in em, which no band lists, cross oblique rows.
                    if (item.flat_row != kRasterNoTransform) bits |= fonts_bands[font].words[item.flat_row + word];
                    uint start_a = row_line_start_bits(a, item, word, first_pass);
                    uint start_b = two_lines ? row_line_start_bits(b, item, word, first_pass) : 0u;
                    while (bits != 0u) {
                        uint bit = findLSB(bits);
                        bits &= bits - 1u;
                        uint first = item.point_offset + 2u * (word * 32u + bit);
                        vec2 p0 = fonts_points[font].points[first];
                        vec2 p1 = fonts_points[font].points[first + 1u];
                        vec2 p2 = fonts_points[font].points[first + 2u];
                        bool in_b = kTwoSetItems != 0u && word * 32u + bit >= item.set_b_first;
                        if (a.pending) row_line_curve(a, m, perspective, p0, p1, p2, in_b, start_a, bit);
                        if (two_lines && b.pending) row_line_curve(b, m, perspective, p0, p1, p2, in_b, start_b, bit);
                    }
                }
                if (a.pending) covered += row_line_end(a, item, m, lo, hi, first_pass) * mine;
                if (two_lines && b.pending) covered += row_line_end(b, item, m, lo, hi, first_pass) * mine;
                first_pass = false;
            }
        }
        if (two_lines) covered *= 0.5;
        // A blurred walk's sums are fractions already.
        vec3 lengths = kBlurItems != 0u ? vec3(1.0) : hi - lo;
        sums += uvec3(row_units(covered.x, lengths.x, dither), row_units(covered.y, lengths.y, dither),
                      row_units(covered.z, lengths.z, dither));
    }
    return sums;
}

void main() {
    uint workgroup = gl_WorkGroupID.y * kRasterDispatchWidth + gl_WorkGroupID.x;
    if (workgroup >= pc.workgroup_count) return;
    workgroup += pc.workgroup_base;
    RasterItem item = items[workgroup_items[workgroup]];
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
