// Colour bitmap glyphs (CBDT/CBLC, sbix), read with FreeType's FT_LOAD_COLOR from the face's largest
// strike. Each becomes a colour glyph of one layer (docs/colour.md): the image's rectangle, an
// outline of its own (a synthetic glyph, shared by every image of the same placement), filled with an
// image paint whose pixels the asset holds zlib-compressed.
#pragma once

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>
#include <crisp/result.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct FT_FaceRec_;
struct FT_SizeRec_;

namespace crisp {

// Decoded bitmap bytes (4 per pixel) one bake converts in all (docs/limits.md): four times Noto
// Color Emoji's 261 MiB. FreeType decodes a glyph's image before its size can be refused, and every
// glyph of a hostile font may point at one large image: this bounds the bake's time.
inline constexpr uint64_t kMaxBitmapBytesPerBake = uint64_t{1} << 30;

// True for a face without outlines whose strikes hold colour bitmaps: its glyphs are baked from the
// bitmaps alone.
bool is_colour_bitmap_face(FT_FaceRec_* face);

struct FaceMetrics {
    uint32_t units_per_em = 0;
    int32_t ascender = 0;  // font units
    int32_t descender = 0;
    int32_t height = 0;  // ascender - descender + line gap
};

// The face's units per em and vertical metrics: FreeType's, where it has them. For a face of CBDT
// bitmaps without outlines FreeType leaves them 0, though head, hhea and OS/2 hold them (HarfBuzz
// reads them, and lays the face out in them): there they are read as FreeType reads them for a
// scalable face.
FaceMetrics face_metrics(FT_FaceRec_* face);

// The bitmaps of one bake. Glyphs are baked one by one (bake), in glyph order; finish() then adds
// their colour glyphs to the asset, after every other source of colour glyphs has added its own.
class BitmapGlyphs {
public:
    // The face's largest colour strike, selected in an FT_Size of its own, so that the face's size
    // (one pixel per font unit, for outlines) stays active. Inert (bake does nothing) for a face
    // without colour strikes. font_unsupported when FreeType cannot select the strike.
    static Result<BitmapGlyphs> open(FT_FaceRec_* face, uint32_t units_per_em);

    // A face whose records come from its bitmaps alone (is_colour_bitmap_face).
    bool bitmap_only() const { return bitmap_only_; }

    // Reads the glyph's bitmap, converts it to premultiplied RGBA and compresses it. On a bitmap-only
    // face it also fills the glyph's record: baked, no curves, the advance of hmtx (HarfBuzz's). A
    // glyph without a bitmap (whitespace) is no failure; a bitmap FreeType cannot read, one larger
    // than kMaxBitmapSide a side, a placement past +-64 em, pixels other than BGRA, or a bake past
    // kMaxBitmapBytesPerBake fail the glyph: the reason is returned. On a face with outlines a bitmap
    // FreeType cannot read, or one other than BGRA, counts as none: the glyph keeps its outline, as
    // it does in FreeType.
    std::optional<std::string> bake(uint32_t glyph, FontAsset& asset, BakeReport& report);

    // Adds a colour glyph for each baked bitmap whose glyph did not fail and has no colour glyph yet
    // (a COLR entry wins over a bitmap): its image, its image paint, one layer, and the rectangles
    // after the face's glyphs as synthetic glyphs; colour_glyphs stays sorted, and the layers in their
    // order. font_unsupported past
    // kMaxSyntheticGlyphs synthetic glyphs or 4 GiB of compressed images.
    Status finish(FontAsset& asset);

private:
    struct SizeDeleter {
        void operator()(FT_SizeRec_* size) const;
    };
    struct Rect {
        float x0 = 0.0f, y0 = 0.0f, x1 = 0.0f, y1 = 0.0f;  // em, y up
        auto operator<=>(const Rect&) const = default;
    };
    struct Baked {
        uint32_t glyph = 0;
        uint32_t width = 0, height = 0;
        Rect rect;
        size_t byte_offset = 0;  // its zlib stream in compressed_
        size_t byte_count = 0;
    };

    FT_FaceRec_* face_ = nullptr;
    std::unique_ptr<FT_SizeRec_, SizeDeleter> strike_;
    double ppem_x_ = 0.0, ppem_y_ = 0.0;
    double units_per_em_ = 0.0;
    bool bitmap_only_ = false;
    uint64_t decoded_bytes_ = 0;
    std::vector<Baked> baked_;
    std::vector<std::byte> compressed_;  // the baked images' streams, one after the other
};

}  // namespace crisp
