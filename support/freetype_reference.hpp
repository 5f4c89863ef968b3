// FreeType beside crisp, for the coverage benchmark (docs/coverage.md, "An outside reference:
// FreeType"):
//
// 1. A reference coverage that is not crisp's own: the glyph's original outline (not crisp's
//    baked curves, so CFF cubics are not lowered) cut here into chords within 1/256 of a cell of
//    each curve, rendered by FreeType's smooth rasterizer with each of crisp's texels cut into
//    S x S cells, and summed over each channel's subpixel rectangle. The rasterizer computes each
//    cell's area under straight edges exactly; rectangle edges that fall inside cells (thirds of
//    a pixel) are met by rendering once more with the cell grid shifted onto them and combining
//    corner sums, so no cell is split by a guess. What remains, the reference's resolution:
//    - input points rounded to 1/64 cell, 1/(64 S) texel: an edge moves by up to 1/(128 S)
//      texel, which in a channel a third of a pixel wide weighs three times;
//    - 8-bit cells: FreeType stores a cell of area coverage c as floor(256 c) (255 at most); this
//      module reads v back as 0 for 0, 1 for 255 and (v + 0.5) / 256 otherwise, so only cells an
//      edge crosses err, by at most 1/256 each;
//    - the chords' sliver, at most 1/(256 S) texel thick (FreeType's own chords, up to 1/16 cell
//      off, would cost 16 times more: they are why the peer below errs);
//    - the nonzero rule applied to each cell's summed signed area rather than point by point,
//      which differs only in cells where two contours' edges cross (overlapping contours).
//    Measured against crisp's exact area coverage on DejaVu Sans at 13 and 48 px, S = 16: mean
//    1.6e-4 and worst 7e-4 per channel for gray, 4.9e-4 and 5.4e-3 for rgb thirds; S = 64: 1e-4
//    and 1.1e-3 for rgb (docs/coverage.md). FreeType fills TrueType and CFF outlines by the
//    nonzero rule, as crisp does; the outline handed to the rasterizer has no
//    FT_OUTLINE_EVEN_ODD_FILL whatever the font's driver set.
// 2. FreeType as a peer: the glyph rendered at the pixel size as an application renders it
//    (unhinted; gray, or LCD with or without FreeType's default filter), placed on crisp's texel
//    grid, with its CPU time per glyph.
// 3. The error between two coverage images on the same grid.
// 4. FreeType's blending of a COLRv0 glyph's layers (FT_LOAD_COLOR), beside the colour reference.
//
// Every function here takes a GlyphRect: the texels the image covers. Pass glyph_rect() of the
// baked asset's GlyphRecord to compare with crisp's atlas texel for texel; outline_rect() computes
// the same rect from FreeType's outline (equal for TrueType glyphs, whose baked curves keep their
// points; CFF glyphs' lowered curves may have a slightly different control box).
#pragma once

#include <crisp/bake.hpp>
#include <crisp/glyph.hpp>
#include <crisp/result.hpp>
#include <crisp/subpixel.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

namespace crisp::freetype {

// Rasterizer cells per texel along each axis for reference_coverage (S): 256 cells a texel.
inline constexpr uint32_t kDefaultCellsPerTexel = 16;
// The largest pixel size (px per em, either axis) the functions here accept.
inline constexpr uint32_t kMaxPixelSize = 4096;
// FreeType reports span positions as 16-bit values: a reference image is at most this many cells
// wide and high (for a 240 px glyph, S up to about 128).
inline constexpr uint32_t kMaxCells = 32767;

// Per-texel, per-channel coverage over a glyph's rect: texel (column, row) of the rect (row 0 at
// the top), channels red, green, blue; each value in [0, 1].
struct CoverageImage {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> values;  // ((row * width) + column) * 3 + channel

    float at(uint32_t column, uint32_t row, uint32_t channel) const {
        return values[(size_t{row} * width + column) * 3 + channel];
    }
};

// A face opened with FreeType (its own FT_Library, and its own copy of the font bytes). Move-only.
// The functions below set the face's size and transform as each needs; one Face is not to be used
// from two threads at once.
class Face {
public:
    // Opens face `face_index` of the font bytes at the given axis values (unnamed axes at their
    // defaults). Errors: font_unreadable (FreeType cannot open the bytes, or the face index is past
    // the collection), font_unsupported (no scalable outlines; a variation on a face without axes,
    // an unknown axis tag or a value outside its axis), never a crash on hostile bytes.
    static Result<Face> open(std::span<const std::byte> font_bytes, uint32_t face_index = 0,
                             std::span<const Variation> variations = {});
    // Reads the file (ErrorCode::io if it cannot), then open().
    static Result<Face> open_file(const std::filesystem::path& path, uint32_t face_index = 0,
                                  std::span<const Variation> variations = {});

    Face(Face&&) noexcept;
    Face& operator=(Face&&) noexcept;
    ~Face();

    uint32_t units_per_em() const;
    uint32_t glyph_count() const;
    // The glyph the face's Unicode cmap maps `codepoint` to; 0 (.notdef) when it maps none.
    uint32_t glyph_for(uint32_t codepoint) const;

    struct State;

private:
    explicit Face(std::unique_ptr<State> state);
    friend State* face_state(Face& face);
    std::unique_ptr<State> state_;
};

// The rect glyph_rect() gives a glyph whose bbox is the control box of FreeType's unhinted outline
// of key.glyph (font units / units per em, rounded to float as the baker rounds), at the key's size
// and subpixel offset. Empty (0 x 0) for a glyph without an outline. Errors as reference_coverage.
Result<GlyphRect> outline_rect(Face& face, const GlyphKey& key);

// Reference coverage of glyph key.glyph at the key's size and subpixel offset over `rect` (see the
// file comment for the method and its resolution; an outline that would pass FreeType's 32767
// points is cut into coarser chords): per texel and channel, the area fraction of
// the channel's rectangle of `layout` (pixel units from the texel's top-left corner, y down) that
// the original outline covers under the nonzero rule. Texel (i, j) of the rect is pen-relative
// pixel (rect.x + i, rect.y + j), so em point (x, y) lies at texel (sub_x + x size_x - rect.x,
// sub_y - y size_y - rect.y): the mapping of texel_to_em(), in double. Cost: one rendering of
// rect.width * rect.height * cells_per_texel^2 cells per distinct cell phase of the layout's
// rectangle edges (1 for gray, 3 for rgb).
// Errors, with nothing rendered: invalid_argument for key.glyph not below glyph_count(), a size of
// 0 or above kMaxPixelSize, cells_per_texel 0 or a rect more than kMaxCells cells wide or high, an
// invalid layout (validate_subpixel_layout), or a rect that does not hold the outline;
// glyph_failed when FreeType cannot load the glyph or it is not an outline.
Result<CoverageImage> reference_coverage(Face& face, const GlyphKey& key, const GlyphRect& rect,
                                         const SubpixelLayout& layout,
                                         uint32_t cells_per_texel = kDefaultCellsPerTexel);

// How the peer renders, as an application using FreeType does.
enum class PeerMode {
    gray,            // FT_RENDER_MODE_NORMAL: all three channels carry the gray value
    lcd,             // FT_RENDER_MODE_LCD with FT_LCD_FILTER_DEFAULT; horizontal RGB stripes
    lcd_unfiltered,  // FT_RENDER_MODE_LCD with FT_LCD_FILTER_NONE: each subpixel's own coverage
};

struct PeerRender {
    CoverageImage image;             // FreeType's 8-bit values v as v / 255, on the rect's texels
    double seconds_per_glyph = 0.0;  // median over the repetitions of FT_Load_Glyph + FT_Render_Glyph
    double lost_coverage = 0.0;      // sum of the values FreeType drew outside the rect (dropped)
};

// FreeType as a peer: glyph key.glyph rendered unhinted (FT_LOAD_NO_HINTING) at the key's pixel
// size, the pen offset by the key's subpixel offset through FT_Set_Transform, and FT_Render_Glyph
// in `mode`; bitmap_left and bitmap_top place the bitmap on the rect's texels. FreeType's 26.6
// units round the size and the offset to 1/64 px (crisp's offsets are 1/256 px). LCD modes match
// crisp's "rgb" layout (red left). The time is the median of `repetitions` loads and renders
// (at least 1), the face already open and sized; nothing else is timed.
// Errors: as reference_coverage, and font_unsupported for an LCD mode where FreeType was built
// without LCD filtering.
Result<PeerRender> render_peer(Face& face, const GlyphKey& key, const GlyphRect& rect, PeerMode mode,
                               uint32_t repetitions = 9);

// FreeType's own blending of a COLRv0 glyph's layers, as an outside check of the colour glyph
// reference (colour_reference.hpp): one BGRA bitmap, premultiplied, sRGB-encoded.
struct ColourBitmap {
    // Column c of the bitmap is pixel left + c right of the pen's whole pixel; row r is pixel
    // r - top below it (FreeType's bitmap_left and bitmap_top).
    int32_t left = 0;
    int32_t top = 0;
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint8_t> bgra;  // rows top to bottom, width * 4 bytes each: blue, green, red, alpha
};

// Glyph key.glyph loaded with FT_LOAD_COLOR | FT_LOAD_RENDER | FT_LOAD_NO_HINTING at the key's
// size and subpixel offset (placed as render_peer places it), with palette `palette` selected
// (FT_Palette_Select) and `foreground` (sRGB-encoded straight RGBA8: red, green, blue, alpha) as
// the text colour (FT_Palette_Set_Foreground_Color). FreeType renders each COLRv0 layer's outline
// gray and blends it src-over into the bitmap in 8-bit premultiplied sRGB-encoded values,
// truncating each product (FreeType 2.12's tt_face_colr_blend_layer); COLRv1 glyphs it does not
// blend. Errors: as render_peer; invalid_argument for a palette past the face's (font_unsupported
// where the face has none); glyph_failed where FreeType gives no BGRA bitmap (a glyph without
// COLRv0 layers).
Result<ColourBitmap> render_colour_layers(Face& face, const GlyphKey& key, uint32_t palette,
                                          const std::array<uint8_t, 4>& foreground);

// The difference between two coverage images on the same grid, over the texels either touches
// (some channel above 0 in either).
struct CoverageError {
    double mean = 0.0;   // mean |a - b| over the touched texels' channels
    double bias = 0.0;   // mean (a - b) over the same
    double worst = 0.0;  // largest |a - b| of one channel
    uint32_t worst_column = 0, worst_row = 0, worst_channel = 0;
    uint64_t touched_texels = 0;
};

// invalid_argument when the images' sizes differ or a value count is not width * height * 3.
Result<CoverageError> compare_coverage(const CoverageImage& a, const CoverageImage& b);

}  // namespace crisp::freetype
