// The COLRv1 paint graph of one glyph, walked from its root and flattened into layers
// (docs/colour.md): transforms are multiplied down the walk, a PaintGlyph becomes the outline of
// the fills beneath it, groups and the composite modes a layer list expresses exactly become
// consecutive layers.
#include "bake/colr.hpp"

#include <crisp/bake.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>

namespace crisp {

using sfnt::fits;
using sfnt::s16;
using sfnt::s32;
using sfnt::u16;
using sfnt::u24;
using sfnt::u32;
using sfnt::u8;

namespace {

// x' = xx x + xy y + dx, y' = yx x + yy y + dy, in double: a walk multiplies up to 64 of them.
struct Matrix {
    double xx = 1.0, yx = 0.0, xy = 0.0, yy = 1.0, dx = 0.0, dy = 0.0;
};

// a after b.
Matrix operator*(const Matrix& a, const Matrix& b) {
    return {a.xx * b.xx + a.xy * b.yx, a.yx * b.xx + a.yy * b.yx,        a.xx * b.xy + a.xy * b.yy,
            a.yx * b.xy + a.yy * b.yy, a.xx * b.dx + a.xy * b.dy + a.dx, a.yx * b.dx + a.yy * b.dy + a.dy};
}

Matrix translation(double x, double y) {
    return {1.0, 0.0, 0.0, 1.0, x, y};
}

Matrix around_center(const Matrix& m, double x, double y) {
    return translation(x, y) * m * translation(-x, -y);
}

// Singular (or not finite): false, and the layer under it is dropped.
bool invert(const Matrix& m, Matrix& inverse) {
    const double det = m.xx * m.yy - m.xy * m.yx;
    if (!(std::isfinite(det) && det != 0.0)) return false;
    inverse.xx = m.yy / det;
    inverse.xy = -m.xy / det;
    inverse.yx = -m.yx / det;
    inverse.yy = m.xx / det;
    inverse.dx = -(inverse.xx * m.dx + inverse.xy * m.dy);
    inverse.dy = -(inverse.yx * m.dx + inverse.yy * m.dy);
    return true;
}

Affine to_affine(const Matrix& m) {
    return {static_cast<float>(m.xx), static_cast<float>(m.yx), static_cast<float>(m.xy),
            static_cast<float>(m.yy), static_cast<float>(m.dx), static_cast<float>(m.dy)};
}

// The loader's bound on paint mappings and geometry (asset/validate_colour.cpp): past it the
// shaders' float arithmetic means nothing.
constexpr float kMaxPaintValue = 1.0e6f;

bool sane(std::initializer_list<float> values) {
    return std::all_of(values.begin(), values.end(),
                       [](float v) { return std::isfinite(v) && std::fabs(v) <= kMaxPaintValue; });
}

bool sane(const Affine& a) {
    return sane({a.xx, a.yx, a.xy, a.yy, a.dx, a.dy});
}

double f2dot14(std::span<const std::byte> table, size_t at) {
    return s16(table, at) / 16384.0;
}

double fixed(std::span<const std::byte> table, size_t at) {
    return s32(table, at) / 65536.0;
}

enum Format : uint32_t {
    kColrLayers = 1,
    kSolid = 2,
    kLinear = 4,
    kRadial = 6,
    kSweep = 8,
    kGlyph = 10,
    kColrGlyph = 11,
    kTransform = 12,
    kTranslate = 14,
    kScale = 16,
    kScaleAroundCenter = 18,
    kScaleUniform = 20,
    kScaleUniformAroundCenter = 22,
    kRotate = 24,
    kRotateAroundCenter = 26,
    kSkew = 28,
    kSkewAroundCenter = 30,
    kComposite = 32,
};

// Each Var* format is its plain format plus one (PaintColrGlyph, 11, has none), laid out as the
// plain one with a 32-bit VarIndexBase after it; crisp reads the default values.
bool is_variable(uint32_t format) {
    return format % 2 == 1 && ((format >= 3 && format <= 9) || (format >= 13 && format <= 31));
}

// The fixed size of each paint format's table, 0 for an unknown format.
size_t paint_size(uint32_t format) {
    static constexpr size_t kSizes[33] = {0,  6,  5,  9, 16, 20, 16, 20, 12, 16, 6,  3, 7,  7,  8,  12, 8,
                                          12, 12, 16, 6, 10, 10, 14, 6,  10, 10, 14, 8, 12, 12, 16, 8};
    return format < 33 ? kSizes[format] : 0;
}

const char* paint_name(uint32_t format) {
    static constexpr const char* kNames[33] = {"",
                                               "PaintColrLayers",
                                               "PaintSolid",
                                               "PaintVarSolid",
                                               "PaintLinearGradient",
                                               "PaintVarLinearGradient",
                                               "PaintRadialGradient",
                                               "PaintVarRadialGradient",
                                               "PaintSweepGradient",
                                               "PaintVarSweepGradient",
                                               "PaintGlyph",
                                               "PaintColrGlyph",
                                               "PaintTransform",
                                               "PaintVarTransform",
                                               "PaintTranslate",
                                               "PaintVarTranslate",
                                               "PaintScale",
                                               "PaintVarScale",
                                               "PaintScaleAroundCenter",
                                               "PaintVarScaleAroundCenter",
                                               "PaintScaleUniform",
                                               "PaintVarScaleUniform",
                                               "PaintScaleUniformAroundCenter",
                                               "PaintVarScaleUniformAroundCenter",
                                               "PaintRotate",
                                               "PaintVarRotate",
                                               "PaintRotateAroundCenter",
                                               "PaintVarRotateAroundCenter",
                                               "PaintSkew",
                                               "PaintVarSkew",
                                               "PaintSkewAroundCenter",
                                               "PaintVarSkewAroundCenter",
                                               "PaintComposite"};
    return format < 33 ? kNames[format] : "an unknown paint";
}

// COLRv1's CompositeMode values, in order.
const char* composite_mode_name(uint32_t mode) {
    static constexpr const char* kModes[28] = {
        "clear",      "src",       "dest",     "src_over",    "dest_over",  "src_in",     "dest_in",
        "src_out",    "dest_out",  "src_atop", "dest_atop",   "xor",        "plus",       "screen",
        "overlay",    "darken",    "lighten",  "color_dodge", "color_burn", "hard_light", "soft_light",
        "difference", "exclusion", "multiply", "hue",         "saturation", "color",      "luminosity"};
    return mode < 28 ? kModes[mode] : "unknown";
}

}  // namespace

// One walk of one glyph's graph. `path_` holds the paints from the root to the one being visited:
// a paint met again on it is a cycle (a paint met again elsewhere is a shared subgraph, which is fine).
class PaintWalk {
public:
    PaintWalk(ColrReader& reader, ColrGlyph& out) : reader_(reader), colr_(reader.colr_), out_(out) {}

    ColrRefusal run(size_t root, std::string& reason) {
        const ColrRefusal refusal = visit(root, Matrix{}, Clip{});
        if (refusal != ColrRefusal::none) reason = std::move(reason_);
        return refusal;
    }

private:
    // The PaintGlyph above a fill: its outline, under the transform above it.
    struct Clip {
        bool active = false;
        uint32_t glyph = 0;
        Matrix outline;
    };

    ColrRefusal refuse(ColrRefusal kind, std::string why) {
        reason_ = std::move(why);
        return kind;
    }

    std::string where(size_t paint) const {
        return std::string("the ") + paint_name(u8(colr_, paint)) + " at offset " + std::to_string(paint);
    }

    std::string past_end(const std::string& what) const {
        return what + " lies past the end of COLR (" + std::to_string(colr_.size()) + " bytes)";
    }

    ColrRefusal visit(size_t paint, const Matrix& m, const Clip& clip) {
        if (path_.size() >= kMaxPaintDepth) {
            return refuse(ColrRefusal::malformed, "the paint graph nests deeper than " +
                                                      std::to_string(kMaxPaintDepth) +
                                                      " paints (kMaxPaintDepth) at offset " + std::to_string(paint));
        }
        if (!fits(colr_, paint, 1))
            return refuse(ColrRefusal::malformed, past_end("a paint at offset " + std::to_string(paint)));
        if (std::find(path_.begin(), path_.end(), paint) != path_.end()) {
            return refuse(ColrRefusal::malformed,
                          "a cycle in the paint graph: " + where(paint) + " is reached again from inside itself");
        }
        if (++nodes_ > kMaxPaintNodes) {
            return refuse(ColrRefusal::malformed, "the paint graph visits more than " + std::to_string(kMaxPaintNodes) +
                                                      " paints (kMaxPaintNodes)");
        }
        if (++reader_.font_nodes_ > kMaxFontPaintNodes) {
            return refuse(ColrRefusal::malformed, "the font's colour glyphs visit more than " +
                                                      std::to_string(kMaxFontPaintNodes) +
                                                      " paints in all (kMaxFontPaintNodes)");
        }
        const uint32_t format = u8(colr_, paint);
        if (paint_size(format) == 0) {
            return refuse(ColrRefusal::unsupported, "paint format " + std::to_string(format) + " at offset " +
                                                        std::to_string(paint) + " is unknown");
        }
        if (!fits(colr_, paint, paint_size(format))) return refuse(ColrRefusal::malformed, past_end(where(paint)));
        path_.push_back(paint);
        const ColrRefusal refusal = visit_format(paint, format, m, clip);
        path_.pop_back();
        return refusal;
    }

    ColrRefusal visit_format(size_t paint, uint32_t format, const Matrix& m, const Clip& clip) {
        const uint32_t plain = is_variable(format) ? format - 1 : format;
        // The formats with one child paint hold its offset first.
        const auto child = [&] { return paint + u24(colr_, paint + 1); };
        switch (plain) {
            case kColrLayers:
                return visit_layers(paint, m, clip);
            case kSolid:
            case kLinear:
            case kRadial:
            case kSweep:
                return fill(paint, plain, is_variable(format), m, clip);
            case kGlyph: {
                if (clip.active) {
                    return refuse(ColrRefusal::unsupported,
                                  where(paint) +
                                      " is inside another PaintGlyph: a nested clip, which crisp does "
                                      "not support");
                }
                const uint32_t glyph = u16(colr_, paint + 4);
                if (glyph >= reader_.glyph_count_) {
                    return refuse(ColrRefusal::malformed, where(paint) + " names glyph " + std::to_string(glyph) +
                                                              ", past the face's " +
                                                              std::to_string(reader_.glyph_count_) + " glyphs");
                }
                return visit(child(), m, Clip{true, glyph, m});
            }
            case kColrGlyph: {
                const uint32_t glyph = u16(colr_, paint + 1);
                const size_t target = reader_.v1_paint(glyph);
                if (target == 0) {
                    return refuse(ColrRefusal::malformed, where(paint) + " names glyph " + std::to_string(glyph) +
                                                              ", which has no COLRv1 paint");
                }
                return visit(target, m, clip);
            }
            case kTransform: {
                const size_t affine = paint + u24(colr_, paint + 4);
                if (!fits(colr_, affine, format == kTransform ? 24 : 28)) {
                    return refuse(ColrRefusal::malformed, past_end("the matrix of " + where(paint)));
                }
                const Matrix t{fixed(colr_, affine),      fixed(colr_, affine + 4),  fixed(colr_, affine + 8),
                               fixed(colr_, affine + 12), fixed(colr_, affine + 16), fixed(colr_, affine + 20)};
                return visit(child(), m * t, clip);
            }
            case kComposite:
                return visit_composite(paint, m, clip);
            default:
                return visit(child(), m * simple_transform(paint, plain), clip);
        }
    }

    // The transforms whose values sit in the paint itself, after its child offset (at +4).
    Matrix simple_transform(size_t paint, uint32_t plain) const {
        const size_t v = paint + 4;
        switch (plain) {
            case kTranslate:
                return translation(s16(colr_, v), s16(colr_, v + 2));
            case kScale:
                return {f2dot14(colr_, v), 0.0, 0.0, f2dot14(colr_, v + 2), 0.0, 0.0};
            case kScaleAroundCenter:
                return around_center({f2dot14(colr_, v), 0.0, 0.0, f2dot14(colr_, v + 2), 0.0, 0.0}, s16(colr_, v + 4),
                                     s16(colr_, v + 6));
            case kScaleUniform:
                return {f2dot14(colr_, v), 0.0, 0.0, f2dot14(colr_, v), 0.0, 0.0};
            case kScaleUniformAroundCenter:
                return around_center({f2dot14(colr_, v), 0.0, 0.0, f2dot14(colr_, v), 0.0, 0.0}, s16(colr_, v + 2),
                                     s16(colr_, v + 4));
            case kRotate:
            case kRotateAroundCenter: {
                // Counter-clockwise, 180 degrees per 1.0.
                const double angle = f2dot14(colr_, v) * std::numbers::pi;
                const Matrix rotation{std::cos(angle), std::sin(angle), -std::sin(angle), std::cos(angle), 0.0, 0.0};
                return plain == kRotate ? rotation : around_center(rotation, s16(colr_, v + 2), s16(colr_, v + 4));
            }
            default: {  // kSkew, kSkewAroundCenter
                // Counter-clockwise angles: the x skew leans the y axis towards -x, the y skew the
                // x axis towards +y.
                const Matrix skew{1.0,
                                  std::tan(f2dot14(colr_, v + 2) * std::numbers::pi),
                                  -std::tan(f2dot14(colr_, v) * std::numbers::pi),
                                  1.0,
                                  0.0,
                                  0.0};
                return plain == kSkew ? skew : around_center(skew, s16(colr_, v + 4), s16(colr_, v + 6));
            }
        }
    }

    ColrRefusal visit_layers(size_t paint, const Matrix& m, const Clip& clip) {
        const size_t count = u8(colr_, paint + 1), first = u32(colr_, paint + 2);
        if (first + count > reader_.layer_count_) {
            return refuse(ColrRefusal::malformed, where(paint) + ": layers " + std::to_string(first) + " to " +
                                                      std::to_string(first + count - 1) + " are past the LayerList's " +
                                                      std::to_string(reader_.layer_count_));
        }
        for (size_t i = first; i < first + count; ++i) {
            const size_t layer = reader_.layer_list_ + u32(colr_, reader_.layer_list_ + 4 + 4 * i);
            if (ColrRefusal refusal = visit(layer, m, clip); refusal != ColrRefusal::none) return refusal;
        }
        return ColrRefusal::none;
    }

    // The modes a list of layers composited src-over expresses exactly; every other is refused.
    ColrRefusal visit_composite(size_t paint, const Matrix& m, const Clip& clip) {
        const size_t source = paint + u24(colr_, paint + 1), backdrop = paint + u24(colr_, paint + 5);
        const uint32_t mode = u8(colr_, paint + 4);
        const auto both = [&](size_t below, size_t above) {
            const ColrRefusal refusal = visit(below, m, clip);
            return refusal != ColrRefusal::none ? refusal : visit(above, m, clip);
        };
        switch (mode) {
            case 0:
                return ColrRefusal::none;  // clear: nothing of either shows
            case 1:
                return visit(source, m, clip);
            case 2:
                return visit(backdrop, m, clip);
            case 3:
                return both(backdrop, source);  // src_over
            case 4:
                return both(source, backdrop);  // dest_over
            default:
                return refuse(ColrRefusal::unsupported, where(paint) + ": composite mode " + composite_mode_name(mode) +
                                                            " (" + std::to_string(mode) + ") is not supported");
        }
    }

    // Reads a (Var)ColorLine into the layer's extend and stops; false with the reason when it is malformed.
    ColrRefusal read_colour_line(size_t paint, bool variable, ColrLayer& layer) {
        const size_t line = paint + u24(colr_, paint + 1);
        if (!fits(colr_, line, 3))
            return refuse(ColrRefusal::malformed, past_end("the colour line of " + where(paint)));
        const uint32_t extend = u8(colr_, line);
        // An unknown extend mode is pad, as the specification asks.
        layer.paint.extend = extend == 1 ? PaintExtend::repeat : extend == 2 ? PaintExtend::reflect : PaintExtend::pad;
        const size_t count = u16(colr_, line + 1), stop_size = variable ? 10 : 6;
        if (count > kMaxColourStops) {
            return refuse(ColrRefusal::malformed, "the colour line of " + where(paint) + " has " +
                                                      std::to_string(count) + " stops, more than " +
                                                      std::to_string(kMaxColourStops) + " (kMaxColourStops)");
        }
        if (!fits(colr_, line + 3, count * stop_size)) {
            return refuse(ColrRefusal::malformed, past_end("the stops of " + where(paint)));
        }
        for (size_t i = 0; i < count; ++i) {
            const size_t stop = line + 3 + i * stop_size;
            const uint32_t palette_index = u16(colr_, stop + 2);
            std::string why;
            if (!reader_.check_palette_index(palette_index, why)) {
                return refuse(ColrRefusal::malformed, "stop " + std::to_string(i) + " of " + where(paint) + ": " + why);
            }
            layer.stops.push_back({static_cast<float>(f2dot14(colr_, stop)), palette_index,
                                   static_cast<float>(std::clamp(f2dot14(colr_, stop + 4), 0.0, 1.0))});
        }
        std::stable_sort(layer.stops.begin(), layer.stops.end(),
                         [](const ColourStop& a, const ColourStop& b) { return a.offset < b.offset; });
        return ColrRefusal::none;
    }

    // A solid or gradient under the PaintGlyph `clip`, seen through `m`: one layer, or none where
    // the paint draws nothing (a singular transform, a degenerate gradient, no stops).
    ColrRefusal fill(size_t paint, uint32_t plain, bool variable, const Matrix& m, const Clip& clip) {
        if (!clip.active) {
            return refuse(ColrRefusal::unsupported,
                          where(paint) + " is outside any PaintGlyph: an unbounded fill, which crisp does not support");
        }
        const double em = 1.0 / reader_.units_per_em_;
        const auto to_em = [em](Matrix t) {
            t.dx *= em;
            t.dy *= em;
            return t;
        };
        ColrLayer layer;
        layer.glyph = clip.glyph;
        const Matrix outline = to_em(clip.outline);
        Matrix to_paint, unused;
        if (!invert(outline, unused) || !invert(to_em(m), to_paint)) return ColrRefusal::none;
        layer.outline_transform = to_affine(outline);
        layer.transformed = layer.outline_transform != Affine{};
        const auto coordinate = [&](size_t at) { return static_cast<float>(s16(colr_, paint + at) * em); };
        float* geometry = layer.paint.geometry;
        if (plain == kSolid) {
            const uint32_t palette_index = u16(colr_, paint + 1);
            std::string why;
            if (!reader_.check_palette_index(palette_index, why)) {
                return refuse(ColrRefusal::malformed, where(paint) + ": " + why);
            }
            layer.paint.kind = PaintKind::solid;
            layer.stops.push_back(
                {0.0f, palette_index, static_cast<float>(std::clamp(f2dot14(colr_, paint + 3), 0.0, 1.0))});
        } else {
            if (ColrRefusal refusal = read_colour_line(paint, variable, layer); refusal != ColrRefusal::none) {
                return refusal;
            }
            if (layer.stops.empty()) return ColrRefusal::none;
            layer.paint.to_paint = to_affine(to_paint);
            if (plain == kLinear) {
                // p1 moved along p0->p2's normal so that lines of equal colour run parallel to p0->p2.
                const double x0 = s16(colr_, paint + 4), y0 = s16(colr_, paint + 6);
                const double vx = s16(colr_, paint + 8) - x0, vy = s16(colr_, paint + 10) - y0;
                const double nx = s16(colr_, paint + 12) - x0, ny = s16(colr_, paint + 14) - y0;
                const double n2 = nx * nx + ny * ny;
                if (n2 == 0.0) return ColrRefusal::none;
                const double along = (vx * nx + vy * ny) / n2;
                const double px = vx - along * nx, py = vy - along * ny;
                if (px == 0.0 && py == 0.0) return ColrRefusal::none;
                layer.paint.kind = PaintKind::linear;
                geometry[0] = static_cast<float>(x0 * em);
                geometry[1] = static_cast<float>(y0 * em);
                geometry[2] = static_cast<float>((x0 + px) * em);
                geometry[3] = static_cast<float>((y0 + py) * em);
            } else if (plain == kRadial) {
                layer.paint.kind = PaintKind::radial;
                geometry[0] = coordinate(4);
                geometry[1] = coordinate(6);
                geometry[2] = static_cast<float>(u16(colr_, paint + 8) * em);
                geometry[3] = coordinate(10);
                geometry[4] = coordinate(12);
                geometry[5] = static_cast<float>(u16(colr_, paint + 14) * em);
            } else {
                // OpenType 1.9.1 biases the sweep's angles by 1.0 (180 degrees) so that 0 to 360
                // degrees fit F2DOT14: the angle is (value + 1) * 180 degrees, (value + 1) / 2 turns.
                const double start = (f2dot14(colr_, paint + 8) + 1.0) / 2.0;
                const double end = (f2dot14(colr_, paint + 10) + 1.0) / 2.0;
                if (start == end) return ColrRefusal::none;
                layer.paint.kind = PaintKind::sweep;
                geometry[0] = coordinate(4);
                geometry[1] = coordinate(6);
                geometry[2] = static_cast<float>(start);
                geometry[3] = static_cast<float>(end);
            }
        }
        const float* g = layer.paint.geometry;
        if (!sane(layer.outline_transform) || !sane(layer.paint.to_paint) ||
            !sane({g[0], g[1], g[2], g[3], g[4], g[5]})) {
            return refuse(ColrRefusal::malformed, "the transforms above " + where(paint) + " scale it past " +
                                                      "what crisp can draw (a value beyond 1e6)");
        }
        if (out_.layers.size() >= kMaxColourLayers) {
            return refuse(ColrRefusal::malformed, "more than " + std::to_string(kMaxColourLayers) +
                                                      " layers once flattened (kMaxColourLayers)");
        }
        out_.layers.push_back(std::move(layer));
        return ColrRefusal::none;
    }

    ColrReader& reader_;
    std::span<const std::byte> colr_;
    ColrGlyph& out_;
    std::vector<size_t> path_;
    uint32_t nodes_ = 0;
    std::string reason_;
};

ColrRefusal ColrReader::flatten_v1(uint32_t glyph, size_t paint, ColrGlyph& out, std::string& reason) {
    if (ColrRefusal refusal = read_clip_box(glyph, out, reason); refusal != ColrRefusal::none) return refusal;
    return PaintWalk(*this, out).run(paint, reason);
}

}  // namespace crisp
