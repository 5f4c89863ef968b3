#include "colour_reference.hpp"

#include "coverage.hpp"
#include "raster/bitmap_pixels.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

namespace crisp::colour {

double srgb_to_linear(double encoded) {
    if (!(encoded > 0.0)) return 0.0;
    if (encoded >= 1.0) return 1.0;
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

LinearRgba linearize(const Srgba& premultiplied) {
    const double a = premultiplied[3];
    if (!(a > 0.0)) return {};
    const auto channel = [&](double value) { return srgb_to_linear(std::clamp(value / a, 0.0, 1.0)) * a; };
    return {channel(premultiplied[0]), channel(premultiplied[1]), channel(premultiplied[2]), a};
}

double extend_t(PaintExtend extend, double first, double last, double t) {
    if (std::isnan(t)) return first;
    if (extend == PaintExtend::pad || !(last > first)) return std::clamp(t, first, last);
    const double span = last - first;
    if (extend == PaintExtend::repeat) {
        double u = (t - first) / span;
        u -= std::floor(u);
        return first + (u < 1.0 ? u : 0.0) * span;
    }
    double u = (t - first) / (2.0 * span);
    u = 2.0 * (u - std::floor(u));
    return first + (u > 1.0 ? 2.0 - u : u) * span;
}

Vec2 to_paint_space(const Affine& m, Vec2 em) {
    const auto d = [](float value) { return static_cast<double>(value); };
    return {d(m.xx) * em.x + d(m.xy) * em.y + d(m.dx), d(m.yx) * em.x + d(m.yy) * em.y + d(m.dy)};
}

namespace {

// The two-point conical gradient: |q - c(t)| = r(t) with c(t) = c0 + t (c1 - c0), r(t) = r0 + t
// (r1 - r0), i.e. a t^2 - 2 b t + c = 0, solved without cancellation (q = b + sign(b) sqrt(b^2 - a c)
// gives the roots q / a and c / q), so that nearly touching circles (a near 0) keep their finite root.
std::optional<double> radial_t(Vec2 c0, double r0, Vec2 c1, double r1, Vec2 q) {
    const Vec2 cd = c1 - c0, pd = q - c0;
    const double dr = r1 - r0;
    const double a = dot(cd, cd) - dr * dr;
    const double b = dot(pd, cd) + r0 * dr;
    const double c = dot(pd, pd) - r0 * r0;
    const auto radius = [&](double t) { return r0 + t * dr; };
    double roots[2];
    int count = 0;
    if (a == 0.0) {
        if (b == 0.0) return std::nullopt;  // one circle for every t, or no circle through q
        roots[count++] = c / (2.0 * b);
    } else {
        const double discriminant = b * b - a * c;
        if (discriminant < 0.0) return std::nullopt;
        const double s = b + std::copysign(std::sqrt(discriminant), b);
        roots[count++] = s / a;
        if (s != 0.0) roots[count++] = c / s;
    }
    std::optional<double> best;
    for (int i = 0; i < count; ++i) {
        if (std::isfinite(roots[i]) && radius(roots[i]) >= 0.0 && (!best || roots[i] > *best)) best = roots[i];
    }
    return best;
}

}  // namespace

std::optional<double> gradient_t(const Paint& paint, Vec2 em) {
    const Vec2 q = to_paint_space(paint.to_paint, em);
    double g[6];
    for (size_t i = 0; i < 6; ++i) g[i] = static_cast<double>(paint.geometry[i]);
    switch (paint.kind) {
        case PaintKind::linear: {
            const Vec2 p0{g[0], g[1]}, d = Vec2{g[2], g[3]} - p0;
            const double length2 = dot(d, d);
            if (!(length2 > 0.0)) return std::nullopt;
            return dot(q - p0, d) / length2;
        }
        case PaintKind::radial:
            return radial_t({g[0], g[1]}, g[2], {g[3], g[4]}, g[5], q);
        case PaintKind::sweep: {
            if (g[2] == g[3]) return std::nullopt;
            double angle = std::atan2(q.y - g[1], q.x - g[0]) / (2.0 * std::numbers::pi);
            if (angle < 0.0) angle += 1.0;
            if (angle >= 1.0) angle -= 1.0;
            return (angle - g[2]) / (g[3] - g[2]);
        }
        case PaintKind::solid:
        case PaintKind::image:
            break;
    }
    return std::nullopt;
}

Result<Painter> Painter::create(const FontAsset& asset, uint32_t palette, const Srgba& foreground) {
    if (palette >= std::max(asset.palette_count(), 1u)) {
        return Error{ErrorCode::invalid_argument, "palette " + std::to_string(palette) + " is past the asset's " +
                                                      std::to_string(asset.palette_count()) + " palettes"};
    }
    for (double component : foreground) {
        if (!(component >= 0.0 && component <= 1.0)) {
            return Error{ErrorCode::invalid_argument, "the text colour's components must lie in [0, 1]"};
        }
    }
    return Painter(asset, palette, foreground);
}

Result<Srgba> Painter::stop_colour(const ColourStop& stop) const {
    const double alpha = static_cast<double>(stop.alpha);
    if (stop.palette_index == kForegroundPaletteIndex) {
        return Srgba{foreground_[0] * alpha, foreground_[1] * alpha, foreground_[2] * alpha, alpha};
    }
    const size_t entry = size_t{palette_} * asset_->palette_size + stop.palette_index;
    if (stop.palette_index >= asset_->palette_size || entry >= asset_->palette_colours.size()) {
        return Error{ErrorCode::invalid_argument, "palette index " + std::to_string(stop.palette_index) +
                                                      " is past the palette's " + std::to_string(asset_->palette_size) +
                                                      " entries"};
    }
    const uint32_t rgba = asset_->palette_colours[entry];
    const auto byte = [&](int shift) { return static_cast<double>((rgba >> shift) & 0xFFu) / 255.0; };
    const double a = byte(24) * alpha;
    return Srgba{byte(0) * a, byte(8) * a, byte(16) * a, a};
}

Result<Srgba> Painter::colour_line(const Paint& paint, double t) const {
    if (paint.stop_count == 0 || paint.first_stop > asset_->stops.size() ||
        paint.stop_count > asset_->stops.size() - paint.first_stop) {
        return Error{ErrorCode::invalid_argument, "the paint's " + std::to_string(paint.stop_count) + " stops from " +
                                                      std::to_string(paint.first_stop) + " are not in the asset's " +
                                                      std::to_string(asset_->stops.size())};
    }
    const std::span<const ColourStop> stops(asset_->stops.data() + paint.first_stop, paint.stop_count);
    const auto offset = [&](size_t i) { return static_cast<double>(stops[i].offset); };
    t = extend_t(paint.extend, offset(0), offset(stops.size() - 1), t);
    // The last stop at or before t: of equal offsets, the later one.
    size_t i = 0;
    while (i + 1 < stops.size() && offset(i + 1) <= t) ++i;
    Result<Srgba> low = stop_colour(stops[i]);
    if (!low || i + 1 == stops.size() || offset(i) == t) return low;
    Result<Srgba> high = stop_colour(stops[i + 1]);
    if (!high) return high;
    const double u = (t - offset(i)) / (offset(i + 1) - offset(i));
    Srgba mixed;
    for (size_t c = 0; c < 4; ++c) mixed[c] = (*low)[c] + u * ((*high)[c] - (*low)[c]);
    return mixed;
}

LinearRgba Painter::finish(const LinearRgba& colour) const {
    const double alpha = foreground_[3];
    return {colour.r * alpha, colour.g * alpha, colour.b * alpha, colour.a * alpha};
}

Result<const std::vector<uint8_t>*> Painter::image_pixels(const Paint& paint) const {
    if (paint.image >= asset_->images.size()) {
        return Error{ErrorCode::invalid_argument, "image " + std::to_string(paint.image) + " is past the asset's " +
                                                      std::to_string(asset_->images.size())};
    }
    if (auto found = images_.find(paint.image); found != images_.end()) return &found->second;
    Result<std::vector<uint8_t>> pixels = raster::decode_bitmap(*asset_, paint.image);
    if (!pixels) return pixels.error();
    return &images_.emplace(paint.image, std::move(*pixels)).first->second;
}

namespace {

LinearRgba texel_colour(const std::vector<uint8_t>& pixels, size_t texel) {
    const auto code = [&](size_t c) { return static_cast<double>(pixels[texel * 4 + c]) / 255.0; };
    return linearize({code(0), code(1), code(2), code(3)});
}

// The polygon's part on the side of one axis-aligned line: axis 0 clips x, 1 y; keeps coordinates
// >= bound when `above`, else <= bound (Sutherland-Hodgman).
std::vector<Vec2> clip_polygon(const std::vector<Vec2>& polygon, int axis, double bound, bool above) {
    std::vector<Vec2> out;
    const auto coordinate = [&](Vec2 p) { return axis == 0 ? p.x : p.y; };
    const auto inside = [&](Vec2 p) { return above ? coordinate(p) >= bound : coordinate(p) <= bound; };
    for (size_t i = 0; i < polygon.size(); ++i) {
        const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
        if (inside(a)) out.push_back(a);
        if (inside(a) != inside(b)) {
            out.push_back(lerp(a, b, (bound - coordinate(a)) / (coordinate(b) - coordinate(a))));
        }
    }
    return out;
}

double polygon_area(const std::vector<Vec2>& polygon) {
    double twice = 0.0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        const Vec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
        twice += a.x * b.y - b.x * a.y;
    }
    return std::fabs(twice) / 2.0;
}

}  // namespace

Result<LinearRgba> Painter::image_nearest(const Paint& paint, Vec2 em) const {
    if (paint.kind != PaintKind::image) return Error{ErrorCode::invalid_argument, "the paint is not an image"};
    Result<const std::vector<uint8_t>*> pixels = image_pixels(paint);
    if (!pixels) return pixels.error();
    const BitmapImage& image = asset_->images[paint.image];
    const Vec2 q = to_paint_space(paint.to_paint, em);
    const auto texel = [](double coordinate, uint32_t side) {
        const double clamped = std::clamp(std::floor(coordinate * side), 0.0, side - 1.0);
        return std::isnan(clamped) ? size_t{0} : static_cast<size_t>(clamped);
    };
    return finish(texel_colour(**pixels, texel(q.y, image.height) * image.width + texel(q.x, image.width)));
}

Result<LinearRgba> Painter::image_mean(const Paint& paint, const std::array<Vec2, 4>& footprint) const {
    if (paint.kind != PaintKind::image) return Error{ErrorCode::invalid_argument, "the paint is not an image"};
    Result<const std::vector<uint8_t>*> pixels = image_pixels(paint);
    if (!pixels) return pixels.error();
    const BitmapImage& image = asset_->images[paint.image];
    const double w = image.width, h = image.height;
    std::vector<Vec2> polygon;  // in texels, then its part inside the image
    for (const Vec2 corner : footprint) {
        const Vec2 q = to_paint_space(paint.to_paint, corner);
        polygon.push_back({q.x * w, q.y * h});
    }
    polygon = clip_polygon(clip_polygon(polygon, 0, 0.0, true), 0, w, false);
    polygon = clip_polygon(clip_polygon(polygon, 1, 0.0, true), 1, h, false);
    const double area = polygon_area(polygon);
    if (!(area > 0.0)) return LinearRgba{};
    double low_x = w, low_y = h, high_x = 0.0, high_y = 0.0;
    for (const Vec2 p : polygon) {
        low_x = std::min(low_x, p.x), high_x = std::max(high_x, p.x);
        low_y = std::min(low_y, p.y), high_y = std::max(high_y, p.y);
    }
    LinearRgba sum;
    const auto first_x = static_cast<uint32_t>(std::clamp(std::floor(low_x), 0.0, w));
    const auto first_y = static_cast<uint32_t>(std::clamp(std::floor(low_y), 0.0, h));
    const auto end_x = static_cast<uint32_t>(std::clamp(std::ceil(high_x), 0.0, w));
    const auto end_y = static_cast<uint32_t>(std::clamp(std::ceil(high_y), 0.0, h));
    for (uint32_t j = first_y; j < end_y; ++j) {
        const std::vector<Vec2> row = clip_polygon(clip_polygon(polygon, 1, j, true), 1, j + 1.0, false);
        if (row.empty()) continue;
        for (uint32_t i = first_x; i < end_x; ++i) {
            const double part = polygon_area(clip_polygon(clip_polygon(row, 0, i, true), 0, i + 1.0, false));
            if (part == 0.0) continue;
            const LinearRgba texel = texel_colour(**pixels, size_t{j} * image.width + i);
            sum = {sum.r + part * texel.r, sum.g + part * texel.g, sum.b + part * texel.b, sum.a + part * texel.a};
        }
    }
    return finish({sum.r / area, sum.g / area, sum.b / area, sum.a / area});
}

Result<LinearRgba> Painter::evaluate(const Paint& paint, Vec2 em) const {
    if (paint.kind == PaintKind::image) {
        Result<const std::vector<uint8_t>*> pixels = image_pixels(paint);
        if (!pixels) return pixels.error();
        const BitmapImage& image = asset_->images[paint.image];
        const Vec2 q = to_paint_space(paint.to_paint, em);
        const double u = std::floor(q.x * image.width), v = std::floor(q.y * image.height);
        if (!(u >= 0.0 && u < image.width && v >= 0.0 && v < image.height)) return LinearRgba{};
        return finish(texel_colour(**pixels, static_cast<size_t>(v) * image.width + static_cast<size_t>(u)));
    }
    if (paint.kind == PaintKind::solid) {
        Result<Srgba> colour = colour_line(paint, 0.0);
        if (!colour) return colour.error();
        return finish(linearize(*colour));
    }
    const std::optional<double> t = gradient_t(paint, em);
    if (!t) return LinearRgba{};
    Result<Srgba> colour = colour_line(paint, *t);
    if (!colour) return colour.error();
    return finish(linearize(*colour));
}

Result<LinearRgba> evaluate_paint(const FontAsset& asset, const Paint& paint, uint32_t palette, const Srgba& foreground,
                                  Vec2 em) {
    Result<Painter> painter = Painter::create(asset, palette, foreground);
    if (!painter) return painter.error();
    return painter->evaluate(paint, em);
}

namespace {

// The fraction of pixel [x, x + 1] x [y, y + 1] inside the clip box (pixel units, y down).
double clip_fraction(double x, double y, double x0, double y0, double x1, double y1) {
    const double w = std::max(0.0, std::min(x + 1.0, x1) - std::max(x, x0));
    const double h = std::max(0.0, std::min(y + 1.0, y1) - std::max(y, y0));
    return w * h;
}

}  // namespace

Result<ColourImage> render_colour_reference(const FontAsset& asset, uint32_t colour_glyph, const GlyphKey& key,
                                            const SubpixelLayout& layout, uint32_t palette, const Srgba& foreground,
                                            const std::array<double, 3>& background, ImageSampling sampling) {
    if (colour_glyph >= asset.colour_glyphs.size()) {
        return Error{ErrorCode::invalid_argument, "colour glyph " + std::to_string(colour_glyph) +
                                                      " is past the asset's " +
                                                      std::to_string(asset.colour_glyphs.size())};
    }
    const ColourGlyph& glyph = asset.colour_glyphs[colour_glyph];
    if (glyph.first_layer > asset.layers.size() || glyph.layer_count > asset.layers.size() - glyph.first_layer) {
        return Error{ErrorCode::invalid_argument,
                     "colour glyph " + std::to_string(colour_glyph) + "'s layers are not in the asset"};
    }
    if (key.size_x == 0 || key.size_y == 0) return Error{ErrorCode::invalid_argument, "a pixel size of 0"};
    if (Status status = validate_subpixel_layout(layout); !status) return status.error();
    Result<Painter> painter = Painter::create(asset, palette, foreground);
    if (!painter) return painter.error();

    const std::span<const ColourLayer> layers(asset.layers.data() + glyph.first_layer, glyph.layer_count);
    std::vector<GlyphRect> rects;
    int32_t left = INT32_MAX, top = INT32_MAX, right = INT32_MIN, bottom = INT32_MIN;
    for (const ColourLayer& layer : layers) {
        if (layer.glyph >= asset.glyphs.size() || layer.paint >= asset.paints.size()) {
            return Error{ErrorCode::invalid_argument, "a layer of colour glyph " + std::to_string(colour_glyph) +
                                                          " names a glyph or paint the asset does not hold"};
        }
        const GlyphRect& r = rects.emplace_back(glyph_rect(asset.glyphs[layer.glyph], key));
        if (r.width == 0 || r.height == 0) continue;
        left = std::min(left, r.x);
        top = std::min(top, r.y);
        right = std::max(right, r.x + static_cast<int32_t>(r.width));
        bottom = std::max(bottom, r.y + static_cast<int32_t>(r.height));
    }
    ColourImage image;
    if (left == INT32_MAX) return image;
    image.rect = {left, top, static_cast<uint32_t>(right - left), static_cast<uint32_t>(bottom - top)};
    if (uint64_t{image.rect.width} * image.rect.height > kMaxReferencePixels) {
        return Error{ErrorCode::invalid_argument, "colour glyph " + std::to_string(colour_glyph) + " covers " +
                                                      std::to_string(image.rect.width) + " x " +
                                                      std::to_string(image.rect.height) + " pixels, past the " +
                                                      std::to_string(kMaxReferencePixels) + " the reference draws"};
    }
    const size_t values = size_t{image.rect.width} * image.rect.height * 3;
    image.rgb.resize(values);
    image.alpha.assign(values, 1.0);  // the transmittance until every layer is in
    for (size_t i = 0; i < values; ++i) image.rgb[i] = background[i % 3];

    // Em x = (pixel x - sub_x) / size_x and em y = (sub_y - pixel y) / size_y: texel_to_em()'s
    // mapping, in double.
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    const auto em = [&](double x, double y) { return Vec2{(x - sub_x) / size_x, (sub_y - y) / size_y}; };
    // The paint at pixel (x, y): at its centre, or over its square for a box-filtered image.
    const auto paint_at = [&](const Paint& paint, double x, double y) {
        if (paint.kind != PaintKind::image) return painter->evaluate(paint, em(x + 0.5, y + 0.5));
        if (sampling == ImageSampling::nearest) return painter->image_nearest(paint, em(x + 0.5, y + 0.5));
        return painter->image_mean(paint, {em(x, y), em(x + 1.0, y), em(x + 1.0, y + 1.0), em(x, y + 1.0)});
    };
    const bool clipped = (glyph.flags & kColourClipped) != 0;
    const auto f = [](float value) { return static_cast<double>(value); };
    const double clip_x0 = sub_x + f(glyph.clip_min_x) * size_x, clip_x1 = sub_x + f(glyph.clip_max_x) * size_x;
    const double clip_y0 = sub_y - f(glyph.clip_max_y) * size_y, clip_y1 = sub_y - f(glyph.clip_min_y) * size_y;

    for (size_t l = 0; l < layers.size(); ++l) {
        const GlyphRect& r = rects[l];
        if (r.width == 0 || r.height == 0) continue;
        const Paint& paint = asset.paints[layers[l].paint];
        const ExactCoverage exact(asset, asset.glyphs[layers[l].glyph]);
        for (uint32_t j = 0; j < r.height; ++j) {
            for (uint32_t i = 0; i < r.width; ++i) {
                const double x = r.x + static_cast<double>(i), y = r.y + static_cast<double>(j);
                const double fraction = clipped ? clip_fraction(x, y, clip_x0, clip_y0, clip_x1, clip_y1) : 1.0;
                std::array<double, 3> k{};
                for (size_t c = 0; c < 3; ++c) {
                    const SampleRect& s = layout.channels[c];
                    const Vec2 low = em(x + f(s.x0), y + f(s.y1)), high = em(x + f(s.x1), y + f(s.y0));
                    k[c] = fraction * exact.coverage(low.x, low.y, high.x, high.y);
                }
                if (k[0] == 0.0 && k[1] == 0.0 && k[2] == 0.0) continue;
                Result<LinearRgba> colour = paint_at(paint, x, y);
                if (!colour) return colour.error();
                const double light[3] = {colour->r, colour->g, colour->b};
                const size_t column = static_cast<size_t>(r.x - image.rect.x) + i;
                const size_t row = static_cast<size_t>(r.y - image.rect.y) + j;
                const size_t at = (row * image.rect.width + column) * 3;
                for (size_t c = 0; c < 3; ++c) {
                    const double transmittance = 1.0 - colour->a * k[c];
                    image.rgb[at + c] = light[c] * k[c] + transmittance * image.rgb[at + c];
                    image.alpha[at + c] *= transmittance;
                }
            }
        }
    }
    for (double& value : image.alpha) value = 1.0 - value;
    return image;
}

}  // namespace crisp::colour
