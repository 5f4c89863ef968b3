#include "bake/bitmap.hpp"
#include "asset/bands.hpp"
#include "bake/outline.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_ADVANCES_H
#include FT_SIZES_H
#include FT_TRUETYPE_TABLES_H
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <map>

namespace crisp {

namespace {

// The loader's bound on every coordinate (asset/asset_format.hpp), as bake.cpp applies it.
constexpr double kMaxEmCoordinate = 64.0;

const char* pixel_mode_name(unsigned char mode) {
    switch (mode) {
        case FT_PIXEL_MODE_MONO:
            return "1-bit";
        case FT_PIXEL_MODE_GRAY:
            return "8-bit gray";
        case FT_PIXEL_MODE_GRAY2:
            return "2-bit gray";
        case FT_PIXEL_MODE_GRAY4:
            return "4-bit gray";
        case FT_PIXEL_MODE_LCD:
            return "LCD";
        case FT_PIXEL_MODE_LCD_V:
            return "vertical LCD";
        default:
            return "unknown";
    }
}

// FreeType's BGRA, premultiplied in sRGB, as the asset's premultiplied RGBA rows, top to bottom.
std::vector<uint8_t> rgba_rows(const FT_Bitmap& bitmap) {
    const size_t row_bytes = size_t{bitmap.width} * 4;
    std::vector<uint8_t> pixels(row_bytes * bitmap.rows);
    const auto pitch = static_cast<ptrdiff_t>(bitmap.pitch);
    for (uint32_t y = 0; y < bitmap.rows; ++y) {
        // A negative pitch stores the rows bottom up, from `buffer` on.
        const unsigned char* row = bitmap.buffer + (pitch >= 0 ? static_cast<ptrdiff_t>(y) * pitch
                                                               : static_cast<ptrdiff_t>(bitmap.rows - 1 - y) * -pitch);
        uint8_t* out = pixels.data() + y * row_bytes;
        for (size_t x = 0; x < row_bytes; x += 4) {
            out[x + 0] = row[x + 2];
            out[x + 1] = row[x + 1];
            out[x + 2] = row[x + 0];
            out[x + 3] = row[x + 3];
        }
    }
    return pixels;
}

}  // namespace

bool is_colour_bitmap_face(FT_Face face) {
    return !FT_IS_SCALABLE(face) && FT_HAS_COLOR(face) && face->num_fixed_sizes > 0;
}

FaceMetrics face_metrics(FT_Face face) {
    FaceMetrics metrics{face->units_per_EM, face->ascender, face->descender, face->height};
    if (metrics.units_per_em != 0) return metrics;
    const auto* head = static_cast<const TT_Header*>(FT_Get_Sfnt_Table(face, FT_SFNT_HEAD));
    const auto* hhea = static_cast<const TT_HoriHeader*>(FT_Get_Sfnt_Table(face, FT_SFNT_HHEA));
    const auto* os2 = static_cast<const TT_OS2*>(FT_Get_Sfnt_Table(face, FT_SFNT_OS2));
    if (head) metrics.units_per_em = head->Units_Per_EM;
    if (hhea) {
        metrics.ascender = hhea->Ascender;
        metrics.descender = hhea->Descender;
        metrics.height = metrics.ascender - metrics.descender + hhea->Line_Gap;
    }
    // FreeType's fallback where hhea has neither (sfobjs.c): OS/2's typographic metrics, else its
    // Windows ones.
    if (metrics.ascender == 0 && metrics.descender == 0 && os2 && os2->version != 0xFFFF) {
        if (os2->sTypoAscender != 0 || os2->sTypoDescender != 0) {
            metrics.ascender = os2->sTypoAscender;
            metrics.descender = os2->sTypoDescender;
            metrics.height = metrics.ascender - metrics.descender + os2->sTypoLineGap;
        } else {
            metrics.ascender = os2->usWinAscent;
            metrics.descender = -static_cast<int32_t>(os2->usWinDescent);
            metrics.height = metrics.ascender - metrics.descender;
        }
    }
    return metrics;
}

void BitmapGlyphs::SizeDeleter::operator()(FT_Size size) const {
    FT_Done_Size(size);
}

Result<BitmapGlyphs> BitmapGlyphs::open(FT_Face face, uint32_t units_per_em) {
    BitmapGlyphs glyphs;
    glyphs.face_ = face;
    glyphs.units_per_em_ = units_per_em;
    glyphs.bitmap_only_ = is_colour_bitmap_face(face);
    if (!FT_HAS_COLOR(face) || face->num_fixed_sizes <= 0) return glyphs;

    // The most pixels per em: the most detail for the layers to filter down from.
    int largest = -1;
    for (int i = 0; i < face->num_fixed_sizes; ++i) {
        const FT_Bitmap_Size& size = face->available_sizes[i];
        if (size.x_ppem > 0 && size.y_ppem > 0 && (largest < 0 || size.y_ppem > face->available_sizes[largest].y_ppem))
            largest = i;
    }
    if (largest < 0) {
        if (!glyphs.bitmap_only_) return glyphs;
        return Error{ErrorCode::font_unsupported, "none of the face's " + std::to_string(face->num_fixed_sizes) +
                                                      " bitmap strikes has a size in pixels per em"};
    }
    const FT_Size outlines = face->size;
    FT_Size strike = nullptr;
    if (const FT_Error error = FT_New_Size(face, &strike); error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot make a size for the bitmap strike: " + freetype_error(error)};
    }
    glyphs.strike_.reset(strike);
    FT_Activate_Size(strike);
    const FT_Error error = FT_Select_Size(face, largest);
    FT_Activate_Size(outlines);
    // 26.6 pixels per em, whole for CBDT and sbix.
    const FT_Bitmap_Size& size = face->available_sizes[largest];
    glyphs.ppem_x_ = static_cast<double>(size.x_ppem) / 64.0;
    glyphs.ppem_y_ = static_cast<double>(size.y_ppem) / 64.0;
    if (error != 0) {
        return Error{ErrorCode::font_unsupported, "cannot select the bitmap strike of " +
                                                      std::to_string(size.y_ppem / 64) +
                                                      " pixels per em: " + freetype_error(error)};
    }
    return glyphs;
}

std::optional<std::string> BitmapGlyphs::bake(uint32_t glyph, FontAsset& asset, BakeReport& report) {
    if (bitmap_only_) {
        GlyphRecord& record = asset.glyphs[glyph];
        FT_Fixed advance = 0;
        if (const FT_Error error = FT_Get_Advance(face_, glyph, FT_LOAD_NO_SCALE, &advance); error != 0)
            return "no advance in hmtx: " + freetype_error(error);
        // hmtx, in font units: what HarfBuzz advances by. The strike's own advance (136 pixels at 109
        // ppem in Noto Color Emoji, 1.2477 em) is rounded to its pixels (hmtx: 2550 / 2048 = 1.2451 em).
        const double advance_em = static_cast<double>(advance) / units_per_em_;
        if (std::fabs(advance_em) > kMaxEmCoordinate) return "advance beyond +-64 em";
        record.advance = static_cast<float>(advance_em);
        record.flags = kGlyphBaked;
        ++report.empty_glyphs;
    }
    if (!strike_) return {};

    const FT_Size outlines = face_->size;
    FT_Activate_Size(strike_.get());
    const FT_Error error =
        FT_Load_Glyph(face_, glyph, static_cast<FT_Int32>(FT_LOAD_COLOR | (bitmap_only_ ? 0 : FT_LOAD_SBITS_ONLY)));
    FT_Activate_Size(outlines);
    // With outlines to fall back to, FreeType reports a bitmap it cannot read as no bitmap at all
    // (FT_LOAD_SBITS_ONLY): the glyph keeps its outline, as it would in FreeType.
    if (error != 0)
        return bitmap_only_ ? std::optional<std::string>("its bitmap: " + freetype_error(error)) : std::nullopt;
    const FT_GlyphSlot slot = face_->glyph;
    const FT_Bitmap& bitmap = slot->bitmap;
    // An empty bitmap: whitespace, or a glyph the strike lacks.
    if (slot->format != FT_GLYPH_FORMAT_BITMAP || bitmap.width == 0 || bitmap.rows == 0) return {};
    if (bitmap.pixel_mode != FT_PIXEL_MODE_BGRA) {
        if (!bitmap_only_) return {};
        return std::string("a ") + pixel_mode_name(bitmap.pixel_mode) +
               " bitmap: crisp bakes colour (BGRA) bitmaps only";
    }
    const std::string size_text = std::to_string(bitmap.width) + " x " + std::to_string(bitmap.rows) + " pixels";
    if (bitmap.width > kMaxBitmapSide || bitmap.rows > kMaxBitmapSide)
        return "a bitmap of " + size_text + ", more than " + std::to_string(kMaxBitmapSide) + " a side";
    if (static_cast<size_t>(std::abs(bitmap.pitch)) < size_t{bitmap.width} * 4)
        return "a bitmap of " + size_text + " with rows of " + std::to_string(std::abs(bitmap.pitch)) + " bytes";

    // The pixels' place at the strike's size, in em; for sbix, FreeType has applied the strike's origin.
    const double left = slot->bitmap_left, top = slot->bitmap_top;
    const double x0 = left / ppem_x_, x1 = (left + bitmap.width) / ppem_x_;
    const double y0 = (top - bitmap.rows) / ppem_y_, y1 = top / ppem_y_;
    if (std::max({std::fabs(x0), std::fabs(x1), std::fabs(y0), std::fabs(y1)}) > kMaxEmCoordinate)
        return "a bitmap placed beyond +-64 em";

    const uint64_t bytes = uint64_t{bitmap.width} * bitmap.rows * 4;
    if (decoded_bytes_ + bytes > kMaxBitmapBytesPerBake)
        return "its bitmap takes the bake's decoded bitmaps past " + std::to_string(kMaxBitmapBytesPerBake >> 20) +
               " MiB (kMaxBitmapBytesPerBake)";
    decoded_bytes_ += bytes;

    const std::vector<uint8_t> pixels = rgba_rows(bitmap);
    const size_t offset = compressed_.size();
    uLongf compressed_size = compressBound(static_cast<uLong>(pixels.size()));
    compressed_.resize(offset + compressed_size);
    // Level 9 and no row filter: on Noto Color Emoji's flat art 13.7 MiB, where PNG's "sub" and
    // "up" filters take 20.9 and 21.8 and level 6 14.2 (in a third of the time).
    if (compress2(reinterpret_cast<Bytef*>(compressed_.data() + offset), &compressed_size, pixels.data(),
                  static_cast<uLong>(pixels.size()), Z_BEST_COMPRESSION) != Z_OK) {
        compressed_.resize(offset);
        return "zlib cannot compress its " + size_text;
    }
    compressed_.resize(offset + compressed_size);
    const Rect rect{static_cast<float>(x0), static_cast<float>(y0), static_cast<float>(x1), static_cast<float>(y1)};
    baked_.push_back({glyph, bitmap.width, bitmap.rows, rect, offset, compressed_size});
    return {};
}

namespace {

// The image's rectangle as an outline: four lines, clockwise in y-up as TrueType's outer contours run.
GlyphRecord rectangle_glyph(double x0, double y0, double x1, double y1, FontAsset& asset) {
    OutlineCounters counters;
    OutlineBuilder builder(OutlineOptions{}, counters);
    builder.move_to({x0, y1});
    builder.line_to({x1, y1});
    builder.line_to({x1, y0});
    builder.line_to({x0, y0});
    const PackedGlyph packed = pack_contours(builder.finish());
    GlyphRecord record;
    record.bearing_x = static_cast<float>(x0);
    record.bearing_y = static_cast<float>(y1);
    record.flags = kGlyphBaked | kGlyphSynthetic;
    append_glyph(packed, build_bands(packed, kTargetCurvesPerBand, kMaxBands, kBandOverlap), record, asset);
    return record;
}

// Em space to the image's unit square: (x0, y1), its top-left corner, to (0, 0); (x1, y0) to (1, 1).
Affine to_unit_square(double x0, double y0, double x1, double y1) {
    Affine map;
    map.xx = static_cast<float>(1.0 / (x1 - x0));
    map.dx = static_cast<float>(-x0 / (x1 - x0));
    map.yy = static_cast<float>(-1.0 / (y1 - y0));
    map.dy = static_cast<float>(y1 / (y1 - y0));
    return map;
}

}  // namespace

Status BitmapGlyphs::finish(FontAsset& asset) {
    // The colour glyphs already made (COLR's), sorted; those of the bitmaps follow them until the sort.
    const auto colr_count = static_cast<ptrdiff_t>(asset.colour_glyphs.size());
    const auto has_colour_glyph = [&](uint32_t glyph) {
        const auto end = asset.colour_glyphs.begin() + colr_count;
        const auto at = std::lower_bound(asset.colour_glyphs.begin(), end, glyph,
                                         [](const ColourGlyph& entry, uint32_t value) { return entry.glyph < value; });
        return at != end && at->glyph == glyph;
    };
    const auto first_new = static_cast<uint32_t>(asset.glyphs.size());
    std::map<Rect, uint32_t> rect_glyphs;
    std::vector<Rect> rects;
    for (const Baked& baked : baked_) {
        if ((asset.glyphs[baked.glyph].flags & kGlyphFailed) != 0 || has_colour_glyph(baked.glyph)) continue;
        if (asset.image_bytes.size() + baked.byte_count > UINT32_MAX)
            return Error{ErrorCode::font_unsupported, "the bitmaps compress to more than 4 GiB"};
        const auto [at, added] = rect_glyphs.try_emplace(baked.rect, first_new + static_cast<uint32_t>(rects.size()));
        if (added) rects.push_back(baked.rect);

        asset.images.push_back({baked.width, baked.height, static_cast<uint32_t>(asset.image_bytes.size()),
                                static_cast<uint32_t>(baked.byte_count)});
        const auto stream = compressed_.begin() + static_cast<ptrdiff_t>(baked.byte_offset);
        asset.image_bytes.insert(asset.image_bytes.end(), stream, stream + static_cast<ptrdiff_t>(baked.byte_count));
        Paint paint;
        paint.kind = PaintKind::image;
        paint.image = static_cast<uint32_t>(asset.images.size() - 1);
        const Rect& rect = baked.rect;
        paint.to_paint = to_unit_square(static_cast<double>(rect.x0), static_cast<double>(rect.y0),
                                        static_cast<double>(rect.x1), static_cast<double>(rect.y1));
        asset.paints.push_back(paint);
        ColourGlyph colour;
        colour.glyph = baked.glyph;
        colour.first_layer = static_cast<uint32_t>(asset.layers.size());
        colour.layer_count = 1;
        asset.layers.push_back({at->second, static_cast<uint32_t>(asset.paints.size() - 1)});
        asset.colour_glyphs.push_back(colour);
    }
    baked_.clear();
    compressed_ = {};

    const uint64_t synthetic = uint64_t{first_new} - asset.face_glyph_count() + rects.size();
    if (synthetic > kMaxSyntheticGlyphs)
        return Error{ErrorCode::font_unsupported, std::to_string(synthetic) + " synthetic glyphs, more than " +
                                                      std::to_string(kMaxSyntheticGlyphs) + " (kMaxSyntheticGlyphs)"};
    for (const Rect& rect : rects) {
        asset.glyphs.push_back(rectangle_glyph(static_cast<double>(rect.x0), static_cast<double>(rect.y0),
                                               static_cast<double>(rect.x1), static_cast<double>(rect.y1), asset));
    }
    const auto by_glyph = [](const ColourGlyph& a, const ColourGlyph& b) { return a.glyph < b.glyph; };
    if (std::is_sorted(asset.colour_glyphs.begin(), asset.colour_glyphs.end(), by_glyph)) return {};
    // Bitmaps among COLR glyphs: sorted by glyph, with their layer ranges moved into that order too,
    // which the asset keeps.
    std::sort(asset.colour_glyphs.begin(), asset.colour_glyphs.end(), by_glyph);
    std::vector<ColourLayer> layers;
    layers.reserve(asset.layers.size());
    for (ColourGlyph& colour : asset.colour_glyphs) {
        const auto first = asset.layers.begin() + static_cast<ptrdiff_t>(colour.first_layer);
        colour.first_layer = static_cast<uint32_t>(layers.size());
        layers.insert(layers.end(), first, first + static_cast<ptrdiff_t>(colour.layer_count));
    }
    asset.layers = std::move(layers);
    return {};
}

}  // namespace crisp
