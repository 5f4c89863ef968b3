// A colour layer's fill at a pixel (docs/colour.md): solid, linear, radial and sweep gradients with
// their extend modes, bitmap images, and the clip box. The CPU reference (support/colour_reference)
// evaluates the same definitions in double. The includer defines CRISP_BIND_PAINTS,
// CRISP_BIND_STOPS and CRISP_BIND_IMAGES to its set's bindings.

layout(std430, set = 0, binding = CRISP_BIND_PAINTS) readonly buffer Paints {
    QuadPaint paints[];
};
layout(std430, set = 0, binding = CRISP_BIND_STOPS) readonly buffer Stops {
    PaintStop stops[];
};
layout(set = 0, binding = CRISP_BIND_IMAGES) uniform sampler2DArray paint_images;

const float kPaintTurn = 6.28318530717958647692;

vec3 paint_decode_srgb(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// t on the colour line after the extend mode, within [first, last].
float paint_extend(float t, uint extend, float first, float last) {
    if (extend == kExtendPad || !(last > first)) return clamp(t, first, last);
    float u = (t - first) / (last - first);
    if (extend == kExtendRepeat) {
        u = fract(u);
    } else {
        u = mod(u, 2.0);
        u = u > 1.0 ? 2.0 - u : u;
    }
    return first + u * (last - first);
}

// The colour line at t: premultiplied sRGB-encoded RGBA, interpolated between the stops around t
// (at a stop's offset, the last stop of that offset).
vec4 paint_colour_line(QuadPaint p, float t) {
    const uint first = p.first_stop;
    const uint last = first + p.stop_count - 1u;
    t = paint_extend(t, p.extend, stops[first].offset, stops[last].offset);
    PaintStop previous = stops[first];
    for (uint i = first + 1u; i <= last; ++i) {
        const PaintStop next = stops[i];
        if (t < next.offset) {
            const float f = (t - previous.offset) / (next.offset - previous.offset);
            return mix(previous.colour, next.colour, f);
        }
        previous = next;
    }
    return previous.colour;
}

// The two-point conical gradient's t at q: the largest t whose circle, of radius r(t) >= 0, passes
// through q; false where none does.
bool paint_radial_t(vec4 g0, vec4 g1, vec2 q, out float t) {
    const vec2 c0 = g0.xy, c1 = vec2(g0.w, g1.x);
    const float r0 = g0.z, r1 = g1.y;
    const vec2 cd = c1 - c0, pd = q - c0;
    const float dr = r1 - r0;
    const float a = dot(cd, cd) - dr * dr;
    const float b = dot(pd, cd) + r0 * dr;
    const float c = dot(pd, pd) - r0 * r0;
    if (abs(a) < 1.0e-9 * max(dot(cd, cd) + dr * dr, 1.0e-30)) {
        if (b == 0.0) return false;
        t = c / (2.0 * b);
        return r0 + t * dr >= 0.0;
    }
    const float discriminant = b * b - a * c;
    if (discriminant < 0.0) return false;
    const float root = sqrt(discriminant);
    const float high = max((b + root) / a, (b - root) / a), low = min((b + root) / a, (b - root) / a);
    if (r0 + high * dr >= 0.0) {
        t = high;
        return true;
    }
    t = low;
    return r0 + low * dr >= 0.0;
}

// The fraction of the pixel [pixel, pixel + 1] inside the clip box.
float paint_clip(vec4 clip, vec2 pixel) {
    const vec2 inside = clamp(min(pixel + 1.0, clip.zw) - max(pixel, clip.xy), vec2(0.0), vec2(1.0));
    return inside.x * inside.y;
}

// The fill `paint` (an index in the paints; kNoQuadPaint: `colour`) of a quad of linear colour
// `colour` (straight alpha) at the pixel: its linear colour, straight alpha (times the clip box's
// fraction of the pixel, which multiplies coverage as the alpha does).
vec4 paint_fill(uint paint, vec4 colour, ivec2 pixel) {
    if (paint == kNoQuadPaint) return colour;
    const QuadPaint p = paints[paint];
    const vec2 corner = vec2(pixel);
    const vec3 centre = vec3(corner + 0.5, 1.0);
    vec2 at = vec2(dot(p.to_paint_x.xyz, centre), dot(p.to_paint_y.xyz, centre));
    vec4 premultiplied;  // linear
    if (p.kind == kPaintSolid) {
        premultiplied = vec4(colour.rgb * colour.a, colour.a);
    } else if (p.kind == kPaintImage) {
        // The layer's outline is the image's rectangle, so a pixel its edge crosses reads the image's
        // edge, not the outside (a pixel centre can lie just past the edge), as the CPU reference does.
        at = clamp(at, vec2(0.0), vec2(1.0));
        // The level whose texels are a pixel apart: the mapping's larger scale in layer texels.
        const vec2 side = vec2(textureSize(paint_images, 0).xy) * vec2(p.image_u, p.image_v);
        const float scale = max(length(p.to_paint_x.xy * side.x), length(p.to_paint_y.xy * side.y));
        const float level = log2(max(scale, 1.0e-6));
        premultiplied = textureLod(paint_images, vec3(at * vec2(p.image_u, p.image_v), float(p.image_layer)), level);
        premultiplied *= p.opacity;
    } else {
        float t = 0.0;
        if (p.kind == kPaintLinear) {
            const vec2 d = p.geometry0.zw - p.geometry0.xy;
            t = dot(at - p.geometry0.xy, d) / dot(d, d);
        } else if (p.kind == kPaintRadial) {
            if (!paint_radial_t(p.geometry0, p.geometry1, at, t)) return vec4(0.0);
        } else {
            const vec2 d = at - p.geometry0.xy;
            float angle = atan(d.y, d.x) / kPaintTurn;
            angle = angle < 0.0 ? angle + 1.0 : angle;
            t = (angle - p.geometry0.z) / (p.geometry0.w - p.geometry0.z);
        }
        const vec4 encoded = paint_colour_line(p, t);
        const vec3 straight = encoded.a > 0.0 ? encoded.rgb / encoded.a : vec3(0.0);
        premultiplied = vec4(paint_decode_srgb(straight) * encoded.a, encoded.a) * p.opacity;
    }
    const float alpha = premultiplied.a * paint_clip(p.clip, corner);
    return premultiplied.a > 0.0 ? vec4(premultiplied.rgb / premultiplied.a, alpha) : vec4(0.0);
}

vec4 quad_fill(CompositeQuad q, ivec2 pixel) {
    return paint_fill(q.paint, q.color, pixel);
}
