#include "freetype_reference.hpp"

#include "core/file_io.hpp"
#include "core/limits.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_COLOR_H
#include FT_LCD_FILTER_H
#include FT_MULTIPLE_MASTERS_H
#include FT_OUTLINE_H

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>

namespace crisp::freetype {

namespace {

struct LibraryDeleter {
    void operator()(FT_Library library) const { FT_Done_FreeType(library); }
};
struct FaceDeleter {
    void operator()(FT_Face face) const { FT_Done_Face(face); }
};

std::string tag_name(uint32_t tag) {
    std::string name;
    for (int shift = 24; shift >= 0; shift -= 8) {
        const auto c = static_cast<char>((tag >> shift) & 0xFF);
        name += (c >= 0x20 && c < 0x7F) ? c : '?';
    }
    return name;
}

std::string freetype_error(FT_Error error) {
    const char* text = FT_Error_String(error);
    return text ? std::string(text) : "FreeType error " + std::to_string(error);
}

}  // namespace

struct Face::State {
    std::vector<std::byte> font_bytes;  // FreeType reads a memory face in place: kept alive here
    std::unique_ptr<FT_LibraryRec_, LibraryDeleter> library;
    std::unique_ptr<FT_FaceRec_, FaceDeleter> face;  // declared last: closed before the library
};

Face::Face(std::unique_ptr<State> state) : state_(std::move(state)) {}
Face::Face(Face&&) noexcept = default;
Face& Face::operator=(Face&&) noexcept = default;
Face::~Face() = default;

Face::State* face_state(Face& face) {
    return face.state_.get();
}

uint32_t Face::units_per_em() const {
    return state_->face->units_per_EM;
}

uint32_t Face::glyph_count() const {
    return static_cast<uint32_t>(state_->face->num_glyphs);
}

uint32_t Face::glyph_for(uint32_t codepoint) const {
    return FT_Get_Char_Index(state_->face.get(), codepoint);
}

namespace {

Status apply_variations(FT_Library library, FT_Face face, std::span<const Variation> variations) {
    if (variations.empty()) return {};
    if (!FT_HAS_MULTIPLE_MASTERS(face)) {
        return Error{ErrorCode::font_unsupported, "variations given but the face has no variation axes"};
    }
    FT_MM_Var* mm = nullptr;
    if (const FT_Error error = FT_Get_MM_Var(face, &mm); error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot read the variation axes: " + freetype_error(error)};
    }
    std::vector<FT_Fixed> coords(mm->num_axis);
    for (FT_UInt i = 0; i < mm->num_axis; ++i) coords[i] = mm->axis[i].def;
    Status status;
    for (const Variation& variation : variations) {
        FT_UInt i = 0;
        while (i < mm->num_axis && static_cast<uint32_t>(mm->axis[i].tag) != variation.tag) ++i;
        const double value = static_cast<double>(variation.value);
        if (i == mm->num_axis) {
            status = Error{ErrorCode::font_unsupported, "the face has no axis '" + tag_name(variation.tag) + "'"};
            break;
        }
        if (!std::isfinite(value) || value * 65536.0 < static_cast<double>(mm->axis[i].minimum) ||
            value * 65536.0 > static_cast<double>(mm->axis[i].maximum)) {
            status = Error{ErrorCode::font_unsupported,
                           "axis '" + tag_name(variation.tag) + "' value outside the axis's range"};
            break;
        }
        coords[i] = static_cast<FT_Fixed>(std::lround(value * 65536.0));
    }
    if (status) {
        if (const FT_Error error = FT_Set_Var_Design_Coordinates(face, mm->num_axis, coords.data()); error != 0) {
            status = Error{ErrorCode::font_unsupported, "cannot set the variation: " + freetype_error(error)};
        }
    }
    FT_Done_MM_Var(library, mm);
    return status;
}

}  // namespace

Result<Face> Face::open(std::span<const std::byte> font_bytes, uint32_t face_index,
                        std::span<const Variation> variations) {
    auto state = std::make_unique<State>();
    state->font_bytes.assign(font_bytes.begin(), font_bytes.end());
    FT_Library raw_library = nullptr;
    if (const FT_Error error = FT_Init_FreeType(&raw_library); error != 0) {
        return Error{ErrorCode::font_unreadable, "cannot start FreeType: " + freetype_error(error)};
    }
    state->library.reset(raw_library);
    const auto* data = reinterpret_cast<const FT_Byte*>(state->font_bytes.data());
    const auto size = static_cast<FT_Long>(state->font_bytes.size());
    FT_Face raw_face = nullptr;
    if (const FT_Error error = FT_New_Memory_Face(raw_library, data, size, -1, &raw_face); error != 0) {
        return Error{ErrorCode::font_unreadable, "not a font FreeType can read: " + freetype_error(error)};
    }
    const FT_Long face_count = raw_face->num_faces;
    FT_Done_Face(raw_face);
    if (static_cast<FT_Long>(face_index) >= face_count) {
        return Error{ErrorCode::font_unreadable, "face " + std::to_string(face_index) +
                                                     " requested, but the font holds " + std::to_string(face_count)};
    }
    raw_face = nullptr;
    if (const FT_Error error = FT_New_Memory_Face(raw_library, data, size, static_cast<FT_Long>(face_index), &raw_face);
        error != 0) {
        return Error{ErrorCode::font_unreadable,
                     "cannot open face " + std::to_string(face_index) + ": " + freetype_error(error)};
    }
    state->face.reset(raw_face);
    if (!FT_IS_SCALABLE(raw_face) || raw_face->units_per_EM < 16 || raw_face->units_per_EM > 16384 ||
        raw_face->num_glyphs <= 0) {
        return Error{ErrorCode::font_unsupported, "the face has no scalable outlines"};
    }
    if (Status status = apply_variations(raw_library, raw_face, variations); !status) return status.error();
    return Face(std::move(state));
}

Result<Face> Face::open_file(const std::filesystem::path& path, uint32_t face_index,
                             std::span<const Variation> variations) {
    Result<std::vector<std::byte>> bytes = read_file(path, limits::kFontFileBytes);
    if (!bytes) return bytes.error();
    return open(*bytes, face_index, variations);
}

namespace {

double pixel_size(uint32_t fixed) {
    return static_cast<double>(fixed) / kSizeOne;
}

double subpixel(uint8_t fixed) {
    return static_cast<double>(fixed) / kSubpixelSteps;
}

// The checks every entry shares: a glyph of the face, a sane size.
Status check_key(Face& face, const GlyphKey& key) {
    if (key.glyph >= face.glyph_count()) {
        return Error{ErrorCode::invalid_argument, "glyph " + std::to_string(key.glyph) + " is not in the face (" +
                                                      std::to_string(face.glyph_count()) + " glyphs)"};
    }
    const uint32_t largest = kMaxPixelSize * kSizeOne;
    if (key.size_x == 0 || key.size_y == 0 || key.size_x > largest || key.size_y > largest) {
        return Error{ErrorCode::invalid_argument, "pixel size " + std::to_string(pixel_size(key.size_x)) + " x " +
                                                      std::to_string(pixel_size(key.size_y)) + " is outside (0, " +
                                                      std::to_string(kMaxPixelSize) + "]"};
    }
    return {};
}

// Loads the glyph's unhinted outline with one pixel per font unit: its 26.6 values are font
// units * 64 (fractional where a variation moved a point), as the baker reads it.
Result<const FT_Outline*> load_unscaled_outline(FT_Face face, uint32_t glyph) {
    FT_Set_Transform(face, nullptr, nullptr);
    if (const FT_Error error = FT_Set_Char_Size(face, 0, static_cast<FT_F26Dot6>(face->units_per_EM) * 64, 72, 72);
        error != 0) {
        return Error{ErrorCode::glyph_failed, "cannot scale the face: " + freetype_error(error)};
    }
    if (const FT_Error error = FT_Load_Glyph(face, glyph, FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP); error != 0) {
        return Error{ErrorCode::glyph_failed, "glyph " + std::to_string(glyph) + ": " + freetype_error(error)};
    }
    if (face->glyph->format != FT_GLYPH_FORMAT_OUTLINE) {
        return Error{ErrorCode::glyph_failed, "glyph " + std::to_string(glyph) + " is not an outline"};
    }
    return &face->glyph->outline;
}

}  // namespace

Result<GlyphRect> outline_rect(Face& face, const GlyphKey& key) {
    if (Status status = check_key(face, key); !status) return status.error();
    FT_Face ft_face = face_state(face)->face.get();
    Result<const FT_Outline*> outline = load_unscaled_outline(ft_face, key.glyph);
    if (!outline) return outline.error();
    if ((*outline)->n_points == 0) return GlyphRect{};
    FT_BBox box;
    FT_Outline_Get_CBox(*outline, &box);
    const double to_em = 1.0 / (64.0 * ft_face->units_per_EM);
    GlyphRecord record;
    record.curve_count = 1;  // glyph_rect() only asks whether there is one
    record.bbox_min_x = static_cast<float>(static_cast<double>(box.xMin) * to_em);
    record.bbox_min_y = static_cast<float>(static_cast<double>(box.yMin) * to_em);
    record.bbox_max_x = static_cast<float>(static_cast<double>(box.xMax) * to_em);
    record.bbox_max_y = static_cast<float>(static_cast<double>(box.yMax) * to_em);
    return glyph_rect(record, key);
}

namespace {

int64_t floor_div(int64_t a, int64_t b) {
    return a / b - ((a % b != 0) && ((a < 0) != (b < 0)) ? 1 : 0);
}

// The outline in cell units (x right, y down from the rect's top-left; a texel is S cells), read
// from FreeType's outline and cut into line segments in double. FreeType's rasterizer computes
// exact cell areas for lines but draws curves as chords whose control point may sit 1/4 cell off
// the chord's midpoint; cutting them here, to a deviation of kFlatness cells, shrinks that sliver
// by a factor of 16 or more.
class Polygons {
public:
    // A chord of one of the pieces below deviates from its curve by at most this many cells.
    static constexpr double kFlatness = 1.0 / 256.0;
    // FreeType counts an outline's points in a short.
    static constexpr size_t kMaxPoints = 32000;

    struct Vec {
        double x = 0.0, y = 0.0;
    };

    Polygons(double scale_x, double scale_y, double offset_x, double offset_y)
        : scale_x_(scale_x), scale_y_(scale_y), offset_x_(offset_x), offset_y_(offset_y) {}

    // Reads the outline's contours; false when FreeType cannot decompose it.
    bool read(const FT_Outline& outline) {
        FT_Outline_Funcs funcs{};
        funcs.move_to = [](const FT_Vector* to, void* user) {
            auto* self = static_cast<Polygons*>(user);
            self->contours_.push_back({self->map(*to), {}});
            self->pen_ = self->contours_.back().start;
            return 0;
        };
        funcs.line_to = [](const FT_Vector* to, void* user) {
            static_cast<Polygons*>(user)->add({1, {static_cast<Polygons*>(user)->map(*to)}});
            return 0;
        };
        funcs.conic_to = [](const FT_Vector* control, const FT_Vector* to, void* user) {
            auto* self = static_cast<Polygons*>(user);
            self->add({2, {self->map(*control), self->map(*to)}});
            return 0;
        };
        funcs.cubic_to = [](const FT_Vector* control1, const FT_Vector* control2, const FT_Vector* to, void* user) {
            auto* self = static_cast<Polygons*>(user);
            self->add({3, {self->map(*control1), self->map(*control2), self->map(*to)}});
            return 0;
        };
        return FT_Outline_Decompose(const_cast<FT_Outline*>(&outline), &funcs, this) == 0;
    }

    // Cuts every curve into chords within kFlatness, coarser only where the outline would pass
    // kMaxPoints; false when even its end points pass it.
    bool flatten() {
        double flatness = kFlatness;
        for (int attempt = 0; attempt < 64; ++attempt) {
            size_t total = 0;
            for (const Contour& contour : contours_) {
                total += 1;
                for (const Piece& piece : contour.pieces) total += pieces_needed(piece, flatness);
            }
            if (total <= kMaxPoints) break;
            if (attempt == 63) return false;
            const double ratio = static_cast<double>(total) / kMaxPoints;
            flatness *= ratio * ratio * 1.01;
        }
        points_.clear();
        contour_ends_.clear();
        for (const Contour& contour : contours_) {
            if (contour.pieces.empty()) continue;
            points_.push_back(contour.start);
            Vec from = contour.start;
            for (const Piece& piece : contour.pieces) {
                const uint32_t count = pieces_needed(piece, flatness);
                for (uint32_t k = 1; k < count; ++k)
                    points_.push_back(evaluate(from, piece, static_cast<double>(k) / count));
                from = piece.points[static_cast<size_t>(piece.degree - 1)];
                points_.push_back(from);
            }
            contour_ends_.push_back(static_cast<decltype(contour_ends_)::value_type>(points_.size() - 1));
        }
        return points_.size() <= kMaxPoints;
    }

    // An outline of the chords, every point on the curve, in FreeType's 26.6 with y up: the cell
    // grid shifted so that cell boundary m lies at cell coordinate m + phase on each axis.
    FT_Outline outline(double phase_x, double phase_y, double cells_high) {
        vectors_.resize(points_.size());
        tags_.assign(points_.size(), FT_CURVE_TAG_ON);
        for (size_t i = 0; i < points_.size(); ++i) {
            vectors_[i].x = static_cast<FT_Pos>(std::llround(64.0 * (points_[i].x - phase_x)));
            vectors_[i].y = static_cast<FT_Pos>(std::llround(64.0 * (cells_high - points_[i].y + phase_y)));
        }
        FT_Outline outline{};
        outline.n_points = static_cast<decltype(outline.n_points)>(points_.size());
        outline.n_contours = static_cast<decltype(outline.n_contours)>(contour_ends_.size());
        outline.points = vectors_.data();
        outline.tags = reinterpret_cast<decltype(outline.tags)>(tags_.data());
        outline.contours = contour_ends_.data();
        outline.flags = FT_OUTLINE_NONE;  // the nonzero rule, as crisp fills
        return outline;
    }

    bool empty() const { return points_.empty(); }

private:
    struct Piece {
        int degree = 1;  // 1 line, 2 quadratic, 3 cubic: points holds the controls and the end
        std::array<Vec, 3> points;
        double bend = 0.0;  // largest |second difference| of its control points
    };
    struct Contour {
        Vec start;
        std::vector<Piece> pieces;
    };

    Vec map(const FT_Vector& v) const {
        return {offset_x_ + scale_x_ * static_cast<double>(v.x), offset_y_ - scale_y_ * static_cast<double>(v.y)};
    }
    // Appends a piece starting at the pen, with the size of its second difference.
    void add(Piece piece) {
        if (contours_.empty()) return;
        const auto second = [](Vec a, Vec b, Vec c) { return std::hypot(a.x - 2 * b.x + c.x, a.y - 2 * b.y + c.y); };
        if (piece.degree == 2) piece.bend = second(pen_, piece.points[0], piece.points[1]);
        if (piece.degree == 3) {
            piece.bend = std::max(second(pen_, piece.points[0], piece.points[1]),
                                  second(piece.points[0], piece.points[1], piece.points[2]));
        }
        pen_ = piece.points[static_cast<size_t>(piece.degree - 1)];
        contours_.back().pieces.push_back(piece);
    }
    // The pieces that keep each chord within `flatness`: a quadratic's chords over n equal steps of
    // t stray at most |p0 - 2 p1 + p2| / (4 n^2), a cubic's 3 max(|p0 - 2 p1 + p2|, |p1 - 2 p2 + p3|)
    // / (4 n^2).
    uint32_t pieces_needed(const Piece& piece, double flatness) const {
        if (piece.degree == 1) return 1;
        const double deviation = piece.degree == 2 ? piece.bend / 4.0 : 3.0 * piece.bend / 4.0;
        return static_cast<uint32_t>(std::clamp(std::ceil(std::sqrt(deviation / flatness)), 1.0, 65536.0));
    }
    static Vec evaluate(Vec p0, const Piece& piece, double t) {
        const double s = 1.0 - t;
        if (piece.degree == 2) {
            const Vec& p1 = piece.points[0];
            const Vec& p2 = piece.points[1];
            return {s * s * p0.x + 2 * s * t * p1.x + t * t * p2.x, s * s * p0.y + 2 * s * t * p1.y + t * t * p2.y};
        }
        const Vec& p1 = piece.points[0];
        const Vec& p2 = piece.points[1];
        const Vec& p3 = piece.points[2];
        return {s * s * s * p0.x + 3 * s * s * t * p1.x + 3 * s * t * t * p2.x + t * t * t * p3.x,
                s * s * s * p0.y + 3 * s * s * t * p1.y + 3 * s * t * t * p2.y + t * t * t * p3.y};
    }

    double scale_x_, scale_y_, offset_x_, offset_y_;
    std::vector<Contour> contours_;
    Vec pen_;
    std::vector<Vec> points_;
    std::vector<std::remove_pointer_t<decltype(FT_Outline::contours)>> contour_ends_;
    std::vector<FT_Vector> vectors_;
    std::vector<unsigned char> tags_;
};

// The cells' coverage summed into corner tables, for one rendering of the outline at one phase:
// A(oy, ox, j, i) = covered cell area above row boundary j S + oy and left of column boundary
// i S + ox (cell units of this rendering's grid). A span of cells adds to every corner below and
// right of it; `full` takes what a span adds whole (summed over i and j at the end), `partial` what
// it adds to the columns that cut it (summed over j).
struct CornerTables {
    double phase_x = 0.0, phase_y = 0.0;  // cell boundary m sits at cell coordinate m + phase
    std::vector<int64_t> offsets_x, offsets_y;
    uint32_t width = 0, height = 0, cells_high = 0, cells_per_texel = 0;
    std::vector<double> full, partial;

    size_t index(size_t oy, size_t ox, uint32_t j, uint32_t i) const {
        return ((oy * offsets_x.size() + ox) * (height + 1) + j) * (width + 1) + i;
    }
    size_t offset_index(const std::vector<int64_t>& offsets, int64_t offset) const {
        return static_cast<size_t>(std::find(offsets.begin(), offsets.end(), offset) - offsets.begin());
    }

    static double decode(unsigned char value) {
        if (value == 0) return 0.0;
        if (value == 255) return 1.0;
        return (value + 0.5) / 256.0;
    }

    void add(int y, int count, const FT_Span* spans) {
        const int64_t row = int64_t{cells_high} - 1 - y;  // FreeType's rows run up, texel rows down
        const int64_t s = cells_per_texel;
        for (size_t oy = 0; oy < offsets_y.size(); ++oy) {
            const int64_t first_j = std::max<int64_t>(floor_div(row - offsets_y[oy], s) + 1, 0);
            if (first_j > height) continue;
            const auto j = static_cast<uint32_t>(first_j);
            for (size_t ox = 0; ox < offsets_x.size(); ++ox) {
                for (int k = 0; k < count; ++k) {
                    const double value = decode(spans[k].coverage);
                    const int64_t x0 = spans[k].x, x1 = x0 + spans[k].len;
                    // Columns i S + ox >= x1 take the whole span; those inside it, the part left of them.
                    const int64_t whole = std::clamp<int64_t>(-floor_div(-(x1 - offsets_x[ox]), s), 0, width);
                    const int64_t cut = std::clamp<int64_t>(floor_div(x0 - offsets_x[ox], s) + 1, 0, width);
                    full[index(oy, ox, j, static_cast<uint32_t>(whole))] += value * static_cast<double>(x1 - x0);
                    for (int64_t i = cut; i < whole; ++i) {
                        partial[index(oy, ox, j, static_cast<uint32_t>(i))] +=
                            value * static_cast<double>(i * s + offsets_x[ox] - x0);
                    }
                }
            }
        }
    }

    static void callback(int y, int count, const FT_Span* spans, void* user) {
        static_cast<CornerTables*>(user)->add(y, count, spans);
    }

    // Turns the span sums into the corner areas A.
    void finish() {
        for (size_t oy = 0; oy < offsets_y.size(); ++oy) {
            for (size_t ox = 0; ox < offsets_x.size(); ++ox) {
                for (uint32_t j = 0; j <= height; ++j) {
                    double running = 0.0;
                    for (uint32_t i = 0; i <= width; ++i) {
                        running += full[index(oy, ox, j, i)];
                        full[index(oy, ox, j, i)] = running + partial[index(oy, ox, j, i)];
                        if (j > 0) full[index(oy, ox, j, i)] += full[index(oy, ox, j - 1, i)];
                    }
                }
            }
        }
    }

    double area(int64_t offset_x, int64_t offset_y, uint32_t i, uint32_t j) const {
        return full[index(offset_index(offsets_y, offset_y), offset_index(offsets_x, offset_x), j, i)];
    }
};

Status check_rect(const GlyphRect& rect, uint32_t cells_per_texel) {
    if (cells_per_texel == 0 || uint64_t{rect.width} * cells_per_texel > kMaxCells ||
        uint64_t{rect.height} * cells_per_texel > kMaxCells) {
        return Error{ErrorCode::invalid_argument, "a rect of " + std::to_string(rect.width) + " x " +
                                                      std::to_string(rect.height) + " texels at " +
                                                      std::to_string(cells_per_texel) +
                                                      " cells per texel is outside "
                                                      "1 to " +
                                                      std::to_string(kMaxCells) + " cells a side"};
    }
    return {};
}

// A channel rectangle's edge at texel coordinate t + edge lies at cell coordinate (t S + offset) + phase.
struct Edge {
    int64_t offset = 0;
    double phase = 0.0;
};
Edge edge_of(float edge, uint32_t cells_per_texel) {
    const double cells = static_cast<double>(edge) * cells_per_texel;
    const double whole = std::floor(cells);
    return {static_cast<int64_t>(whole), cells - whole};
}

}  // namespace

Result<CoverageImage> reference_coverage(Face& face, const GlyphKey& key, const GlyphRect& rect,
                                         const SubpixelLayout& layout, uint32_t cells_per_texel) {
    if (Status status = check_key(face, key); !status) return status.error();
    if (Status status = check_rect(rect, cells_per_texel); !status) return status.error();
    if (Status status = validate_subpixel_layout(layout); !status) return status.error();
    FT_Face ft_face = face_state(face)->face.get();
    Result<const FT_Outline*> loaded = load_unscaled_outline(ft_face, key.glyph);
    if (!loaded) return loaded.error();

    CoverageImage image;
    image.width = rect.width;
    image.height = rect.height;
    image.values.assign(size_t{rect.width} * rect.height * 3, 0.0f);
    if ((*loaded)->n_points == 0 || rect.width == 0 || rect.height == 0) return image;

    // Texel u = sub_x + x_em size_x - rect.x and v = sub_y - y_em size_y - rect.y; a cell is 1/S
    // texel, and the outline's 26.6 values are font units * 64.
    const double s = cells_per_texel;
    const double upem = ft_face->units_per_EM;
    Polygons polygons(s * pixel_size(key.size_x) / (64.0 * upem), s * pixel_size(key.size_y) / (64.0 * upem),
                      s * (subpixel(key.subpixel_x) - rect.x), s * (subpixel(key.subpixel_y) - rect.y));
    if (!polygons.read(**loaded) || !polygons.flatten()) {
        return Error{ErrorCode::glyph_failed, "cannot read glyph " + std::to_string(key.glyph) + "'s outline"};
    }
    if (polygons.empty()) return image;

    // One rendering per phase pair that a channel corner needs; each keeps the corner tables of
    // the offsets at that phase.
    const uint32_t cells_wide = rect.width * cells_per_texel;
    const uint32_t cells_high = rect.height * cells_per_texel;
    std::vector<CornerTables> renderings;
    const auto rendering_for = [&](Edge x, Edge y) -> CornerTables& {
        for (CornerTables& tables : renderings) {
            if (tables.phase_x == x.phase && tables.phase_y == y.phase) return tables;
        }
        CornerTables& tables = renderings.emplace_back();
        tables.phase_x = x.phase;
        tables.phase_y = y.phase;
        return tables;
    };
    for (const SampleRect& channel : layout.channels) {
        for (float cx : {channel.x0, channel.x1}) {
            for (float cy : {channel.y0, channel.y1}) {
                const Edge x = edge_of(cx, cells_per_texel), y = edge_of(cy, cells_per_texel);
                CornerTables& tables = rendering_for(x, y);
                if (std::find(tables.offsets_x.begin(), tables.offsets_x.end(), x.offset) == tables.offsets_x.end())
                    tables.offsets_x.push_back(x.offset);
                if (std::find(tables.offsets_y.begin(), tables.offsets_y.end(), y.offset) == tables.offsets_y.end())
                    tables.offsets_y.push_back(y.offset);
            }
        }
    }
    for (CornerTables& tables : renderings) {
        tables.width = rect.width;
        tables.height = rect.height;
        tables.cells_high = cells_high;
        tables.cells_per_texel = cells_per_texel;
        const size_t size = tables.offsets_x.size() * tables.offsets_y.size() * (rect.width + 1) * (rect.height + 1);
        tables.full.assign(size, 0.0);
        tables.partial.assign(size, 0.0);

        FT_Outline outline = polygons.outline(tables.phase_x, tables.phase_y, cells_high);
        FT_BBox box;
        FT_Outline_Get_CBox(&outline, &box);
        if (box.xMin < 0 || box.yMin < 0 || box.xMax > FT_Pos{cells_wide} * 64 || box.yMax > FT_Pos{cells_high} * 64) {
            return Error{ErrorCode::invalid_argument, "the rect does not hold glyph " + std::to_string(key.glyph) +
                                                          "'s outline at this size and offset"};
        }
        FT_Raster_Params params{};
        params.source = &outline;
        params.flags = FT_RASTER_FLAG_AA | FT_RASTER_FLAG_DIRECT | FT_RASTER_FLAG_CLIP;
        params.gray_spans = &CornerTables::callback;
        params.user = &tables;
        params.clip_box = {0, 0, static_cast<FT_Pos>(cells_wide), static_cast<FT_Pos>(cells_high)};
        if (const FT_Error error = FT_Outline_Render(face_state(face)->library.get(), &outline, &params); error != 0) {
            return Error{ErrorCode::glyph_failed,
                         "FreeType cannot render glyph " + std::to_string(key.glyph) + ": " + freetype_error(error)};
        }
        tables.finish();
    }

    for (uint32_t channel = 0; channel < 3; ++channel) {
        const SampleRect& r = layout.channels[channel];
        const Edge x0 = edge_of(r.x0, cells_per_texel), x1 = edge_of(r.x1, cells_per_texel);
        const Edge y0 = edge_of(r.y0, cells_per_texel), y1 = edge_of(r.y1, cells_per_texel);
        const CornerTables& top_left = rendering_for(x0, y0);
        const CornerTables& top_right = rendering_for(x1, y0);
        const CornerTables& bottom_left = rendering_for(x0, y1);
        const CornerTables& bottom_right = rendering_for(x1, y1);
        const double cells = (static_cast<double>(r.x1) - static_cast<double>(r.x0)) *
                             (static_cast<double>(r.y1) - static_cast<double>(r.y0)) * s * s;
        for (uint32_t j = 0; j < rect.height; ++j) {
            for (uint32_t i = 0; i < rect.width; ++i) {
                const double area =
                    bottom_right.area(x1.offset, y1.offset, i, j) - bottom_left.area(x0.offset, y1.offset, i, j) -
                    top_right.area(x1.offset, y0.offset, i, j) + top_left.area(x0.offset, y0.offset, i, j);
                image.values[(size_t{j} * rect.width + i) * 3 + channel] =
                    static_cast<float>(std::clamp(area / cells, 0.0, 1.0));
            }
        }
    }
    return image;
}

namespace {

// Copies a rendered bitmap onto the rect's texels; returns the coverage that fell outside.
double place_bitmap(const FT_GlyphSlot slot, const GlyphRect& rect, PeerMode mode, CoverageImage& image) {
    const FT_Bitmap& bitmap = slot->bitmap;
    const bool lcd = mode != PeerMode::gray;
    const uint32_t pixels_wide = lcd ? bitmap.width / 3 : bitmap.width;
    double lost = 0.0;
    for (uint32_t r = 0; r < bitmap.rows; ++r) {
        const unsigned char* line = bitmap.buffer + static_cast<ptrdiff_t>(r) * bitmap.pitch;
        const int64_t row = int64_t{-slot->bitmap_top} + r - rect.y;
        for (uint32_t c = 0; c < pixels_wide; ++c) {
            const int64_t column = int64_t{slot->bitmap_left} + c - rect.x;
            const bool inside = row >= 0 && row < rect.height && column >= 0 && column < rect.width;
            for (uint32_t channel = 0; channel < 3; ++channel) {
                const double value = (lcd ? line[c * 3 + channel] : line[c]) / 255.0;
                if (inside) {
                    image.values[(static_cast<size_t>(row) * rect.width + static_cast<size_t>(column)) * 3 + channel] =
                        static_cast<float>(value);
                } else {
                    lost += value;
                }
            }
        }
    }
    return lost;
}

// Sizes the face at the key's pixel size and moves the pen by its subpixel offset, as an
// application placing a glyph at a fractional pen does; FT_Set_Transform(face, nullptr, nullptr)
// undoes the move.
Status place_pen(FT_Face face, const GlyphKey& key) {
    // 26.6 from u24.8 and u0.8, rounded to the nearest 1/64 px.
    const auto to_26_6 = [](uint32_t fixed) { return static_cast<FT_F26Dot6>((fixed + 2) / 4); };
    if (const FT_Error error = FT_Set_Char_Size(face, to_26_6(key.size_x), to_26_6(key.size_y), 72, 72); error != 0) {
        return Error{ErrorCode::glyph_failed, "cannot scale the face: " + freetype_error(error)};
    }
    FT_Vector pen{to_26_6(key.subpixel_x), -to_26_6(key.subpixel_y)};  // FreeType's y runs up
    FT_Set_Transform(face, nullptr, &pen);
    return {};
}

}  // namespace

Result<PeerRender> render_peer(Face& face, const GlyphKey& key, const GlyphRect& rect, PeerMode mode,
                               uint32_t repetitions) {
    if (Status status = check_key(face, key); !status) return status.error();
    FT_Library library = face_state(face)->library.get();
    FT_Face ft_face = face_state(face)->face.get();
    if (mode != PeerMode::gray) {
        const FT_LcdFilter filter = mode == PeerMode::lcd ? FT_LCD_FILTER_DEFAULT : FT_LCD_FILTER_NONE;
        if (const FT_Error error = FT_Library_SetLcdFilter(library, filter); error != 0) {
            return Error{ErrorCode::font_unsupported, "FreeType cannot set the LCD filter: " + freetype_error(error)};
        }
    }
    if (Status status = place_pen(ft_face, key); !status) return status.error();
    const FT_Render_Mode render_mode = mode == PeerMode::gray ? FT_RENDER_MODE_NORMAL : FT_RENDER_MODE_LCD;

    std::vector<double> seconds;
    FT_Error error = 0;
    for (uint32_t repetition = 0; repetition < std::max(repetitions, 1u) && error == 0; ++repetition) {
        const auto started = std::chrono::steady_clock::now();
        error = FT_Load_Glyph(ft_face, key.glyph, FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP);
        if (error == 0) error = FT_Render_Glyph(ft_face->glyph, render_mode);
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    }
    FT_Set_Transform(ft_face, nullptr, nullptr);
    if (error != 0) {
        return Error{ErrorCode::glyph_failed,
                     "FreeType cannot render glyph " + std::to_string(key.glyph) + ": " + freetype_error(error)};
    }
    PeerRender peer;
    std::nth_element(seconds.begin(), seconds.begin() + static_cast<ptrdiff_t>(seconds.size() / 2), seconds.end());
    peer.seconds_per_glyph = seconds[seconds.size() / 2];
    peer.image.width = rect.width;
    peer.image.height = rect.height;
    peer.image.values.assign(size_t{rect.width} * rect.height * 3, 0.0f);
    peer.lost_coverage = place_bitmap(ft_face->glyph, rect, mode, peer.image);
    return peer;
}

Result<ColourBitmap> render_colour_layers(Face& face, const GlyphKey& key, uint32_t palette,
                                          const std::array<uint8_t, 4>& foreground) {
    if (Status status = check_key(face, key); !status) return status.error();
    FT_Face ft_face = face_state(face)->face.get();
    FT_Palette_Data palettes;
    if (const FT_Error error = FT_Palette_Data_Get(ft_face, &palettes); error != 0 || palettes.num_palettes == 0) {
        return Error{ErrorCode::font_unsupported, "the face has no CPAL palettes"};
    }
    if (palette >= palettes.num_palettes) {
        return Error{ErrorCode::invalid_argument, "palette " + std::to_string(palette) + " is past the face's " +
                                                      std::to_string(palettes.num_palettes)};
    }
    if (const FT_Error error = FT_Palette_Select(ft_face, static_cast<FT_UShort>(palette), nullptr); error != 0) {
        return Error{ErrorCode::font_unsupported,
                     "cannot select palette " + std::to_string(palette) + ": " + freetype_error(error)};
    }
    const FT_Color text{foreground[2], foreground[1], foreground[0], foreground[3]};
    if (const FT_Error error = FT_Palette_Set_Foreground_Color(ft_face, text); error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot set the foreground colour: " + freetype_error(error)};
    }
    if (Status status = place_pen(ft_face, key); !status) return status.error();
    const FT_Error error = FT_Load_Glyph(ft_face, key.glyph, FT_LOAD_COLOR | FT_LOAD_RENDER | FT_LOAD_NO_HINTING);
    FT_Set_Transform(ft_face, nullptr, nullptr);
    if (error != 0) {
        return Error{ErrorCode::glyph_failed,
                     "FreeType cannot render glyph " + std::to_string(key.glyph) + ": " + freetype_error(error)};
    }
    const FT_GlyphSlot slot = ft_face->glyph;
    const FT_Bitmap& bitmap = slot->bitmap;
    if (slot->format != FT_GLYPH_FORMAT_BITMAP || bitmap.pixel_mode != FT_PIXEL_MODE_BGRA) {
        return Error{ErrorCode::glyph_failed,
                     "FreeType gave glyph " + std::to_string(key.glyph) + " no BGRA bitmap: it has no COLRv0 layers"};
    }
    ColourBitmap out;
    out.left = slot->bitmap_left;
    out.top = slot->bitmap_top;
    out.width = bitmap.width;
    out.height = bitmap.rows;
    out.bgra.resize(size_t{bitmap.width} * bitmap.rows * 4);
    for (uint32_t row = 0; row < bitmap.rows; ++row) {
        const unsigned char* line = bitmap.buffer + static_cast<ptrdiff_t>(row) * bitmap.pitch;
        std::copy(line, line + size_t{bitmap.width} * 4,
                  out.bgra.begin() + static_cast<ptrdiff_t>(row) * bitmap.width * 4);
    }
    return out;
}

Result<CoverageError> compare_coverage(const CoverageImage& a, const CoverageImage& b) {
    const size_t count = size_t{a.width} * a.height * 3;
    if (a.width != b.width || a.height != b.height || a.values.size() != count || b.values.size() != count) {
        return Error{ErrorCode::invalid_argument, "the coverage images are not on the same grid"};
    }
    CoverageError result;
    double sum = 0.0, signed_sum = 0.0;
    for (size_t texel = 0; texel < count / 3; ++texel) {
        const float* pa = &a.values[texel * 3];
        const float* pb = &b.values[texel * 3];
        if (std::max({pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]}) <= 0.0f) continue;
        ++result.touched_texels;
        for (uint32_t channel = 0; channel < 3; ++channel) {
            const double difference = static_cast<double>(pa[channel]) - static_cast<double>(pb[channel]);
            sum += std::fabs(difference);
            signed_sum += difference;
            if (std::fabs(difference) > result.worst) {
                result.worst = std::fabs(difference);
                result.worst_column = static_cast<uint32_t>(texel % a.width);
                result.worst_row = static_cast<uint32_t>(texel / a.width);
                result.worst_channel = channel;
            }
        }
    }
    if (result.touched_texels > 0) {
        result.mean = sum / static_cast<double>(result.touched_texels * 3);
        result.bias = signed_sum / static_cast<double>(result.touched_texels * 3);
    }
    return result;
}

}  // namespace crisp::freetype
