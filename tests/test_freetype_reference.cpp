// FreeType as an outside coverage reference and as a peer (support/freetype_reference.hpp): the
// reference held to crisp's exact area coverage where the two must agree (TrueType, whose baked
// curves are the original ones), the peer held to the reference, and bad input refused.
// docs/coverage.md ("An outside reference: FreeType") records the table this prints.
#include "coverage.hpp"
#include "freetype_reference.hpp"
#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace crisp {
namespace {

using freetype::CoverageError;
using freetype::CoverageImage;
using freetype::Face;
using freetype::PeerMode;
using test::kDejaVuSans;
using test::key_at;

// crisp's exact area coverage of each channel rectangle of each texel of the rect, on the mapping
// reference_coverage documents (texel_to_em's, in double).
CoverageImage exact_image(const ExactCoverage& exact, const GlyphKey& key, const GlyphRect& rect,
                          const SubpixelLayout& layout) {
    const double size_x = static_cast<double>(key.size_x) / kSizeOne;
    const double size_y = static_cast<double>(key.size_y) / kSizeOne;
    const double sub_x = static_cast<double>(key.subpixel_x) / kSubpixelSteps;
    const double sub_y = static_cast<double>(key.subpixel_y) / kSubpixelSteps;
    CoverageImage image;
    image.width = rect.width;
    image.height = rect.height;
    image.values.assign(size_t{rect.width} * rect.height * 3, 0.0f);
    for (uint32_t row = 0; row < rect.height; ++row) {
        for (uint32_t column = 0; column < rect.width; ++column) {
            for (uint32_t channel = 0; channel < 3; ++channel) {
                const SampleRect& r = layout.channels[channel];
                const double u0 = column + static_cast<double>(r.x0), u1 = column + static_cast<double>(r.x1);
                const double v0 = row + static_cast<double>(r.y0), v1 = row + static_cast<double>(r.y1);
                const double x0 = (rect.x + u0 - sub_x) / size_x, x1 = (rect.x + u1 - sub_x) / size_x;
                const double y0 = (sub_y - rect.y - v1) / size_y, y1 = (sub_y - rect.y - v0) / size_y;
                image.values[(size_t{row} * rect.width + column) * 3 + channel] =
                    static_cast<float>(exact.coverage(x0, y0, x1, y1));
            }
        }
    }
    return image;
}

CoverageError compare(const CoverageImage& a, const CoverageImage& b) {
    Result<CoverageError> error = freetype::compare_coverage(a, b);
    EXPECT_TRUE(error.ok());
    return error.ok() ? *error : CoverageError{};
}

SubpixelLayout layout_named(const char* name) {
    Result<SubpixelLayout> layout = subpixel_preset(name);
    EXPECT_TRUE(layout.ok());
    return layout.ok() ? *layout : SubpixelLayout{};
}

TEST(FreeTypeReference, AgreesWithExactCoverageAndHoldsThePeer) {
    const std::string text = "g@&e";
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = decode_utf8(text);
    Result<BakeResult> baked = bake_font_file(kDejaVuSans, options);
    ASSERT_TRUE(baked.ok()) << baked.error().message;
    const FontAsset& asset = baked->asset;
    Result<Face> opened = Face::open_file(kDejaVuSans);
    ASSERT_TRUE(opened.ok()) << opened.error().message;
    Face& face = *opened;
    const SubpixelLayout gray = layout_named("gray");
    const SubpixelLayout rgb = layout_named("rgb");

    std::printf("%-6s %4s %-6s %-9s %17s %17s %17s %17s %17s %6s %9s\n", "glyph", "px", "layout", "offset",
                "ref-exact mean/max", "ref64-exact", "gray-ref", "lcd-ref", "lcd_none-ref", "us", "gray bias");
    for (uint32_t codepoint : decode_utf8(text)) {
        const uint32_t glyph = face.glyph_for(codepoint);
        ASSERT_NE(glyph, 0u);
        const ExactCoverage exact(asset, asset.glyphs[glyph]);
        for (uint32_t pixels : {13u, 48u}) {
            for (const auto& [sub_x, sub_y] : {std::pair<uint8_t, uint8_t>{0, 0}, {96, 160}}) {
                const GlyphKey key = key_at(glyph, pixels, sub_x, sub_y);
                const GlyphRect rect = glyph_rect(asset.glyphs[glyph], key);
                // The rect from FreeType's own outline is the baked glyph's: the grids agree.
                Result<GlyphRect> from_outline = freetype::outline_rect(face, key);
                ASSERT_TRUE(from_outline.ok()) << from_outline.error().message;
                EXPECT_EQ(from_outline->x, rect.x);
                EXPECT_EQ(from_outline->y, rect.y);
                EXPECT_EQ(from_outline->width, rect.width);
                EXPECT_EQ(from_outline->height, rect.height);

                for (const SubpixelLayout* layout : {&gray, &rgb}) {
                    Result<CoverageImage> reference = freetype::reference_coverage(face, key, rect, *layout);
                    ASSERT_TRUE(reference.ok()) << reference.error().message;
                    const CoverageImage truth = exact_image(exact, key, rect, *layout);
                    const CoverageError against_exact = compare(*reference, truth);
                    // The reference's resolution (freetype_reference.hpp): points rounded to 1/1024
                    // texel, 8-bit cells. An edge's rounding weighs three times as much in a third of
                    // a pixel. Measured at most 1.6e-4 / 7e-4 (gray), 4.9e-4 / 5.4e-3 (rgb).
                    const bool thirds = layout == &rgb;
                    EXPECT_LT(against_exact.mean, thirds ? 0.001 : 0.0003) << key.glyph << " at " << pixels << " px";
                    EXPECT_LT(against_exact.worst, thirds ? 0.008 : 0.0015) << key.glyph << " at " << pixels << " px";
                    CoverageError fine{};
                    {  // 64 cells a texel: a quarter of the rounding
                        Result<CoverageImage> fine_reference =
                            freetype::reference_coverage(face, key, rect, *layout, 64);
                        ASSERT_TRUE(fine_reference.ok());
                        fine = compare(*fine_reference, truth);
                        EXPECT_LT(fine.mean, against_exact.mean);
                    }

                    // The peer: gray against the gray reference, LCD against the rgb one.
                    const bool is_gray = layout == &gray;
                    CoverageError peer_gray{}, peer_lcd{}, peer_lcd_none{};
                    double microseconds = 0.0, gray_bias = 0.0;
                    if (is_gray) {
                        Result<freetype::PeerRender> peer = freetype::render_peer(face, key, rect, PeerMode::gray);
                        ASSERT_TRUE(peer.ok()) << peer.error().message;
                        EXPECT_EQ(peer->lost_coverage, 0.0);
                        EXPECT_GT(peer->seconds_per_glyph, 0.0);
                        peer_gray = compare(peer->image, *reference);
                        microseconds = peer->seconds_per_glyph * 1e6;
                        // Also area coverage, at 8 bits, but FreeType draws curves as chords up to 1/16
                        // px off them: a few 1/255 on average, lost on outer contours and gained on
                        // inner ones, so the bias is under 0.4 of it. Measured at most 6.0/255 at 13 px and
                        // 2.6/255 at 48 px.
                        EXPECT_LT(peer_gray.mean, (pixels < 20 ? 7.0 : 3.5) / 255.0) << key.glyph << " at " << pixels;
                        EXPECT_LT(std::fabs(peer_gray.bias), 0.4 * peer_gray.mean) << key.glyph << " at " << pixels;
                        gray_bias = peer_gray.bias;
                    } else {
                        Result<freetype::PeerRender> filtered = freetype::render_peer(face, key, rect, PeerMode::lcd);
                        Result<freetype::PeerRender> unfiltered =
                            freetype::render_peer(face, key, rect, PeerMode::lcd_unfiltered);
                        ASSERT_TRUE(filtered.ok()) << filtered.error().message;
                        ASSERT_TRUE(unfiltered.ok()) << unfiltered.error().message;
                        EXPECT_EQ(filtered->lost_coverage, 0.0);
                        peer_lcd = compare(filtered->image, *reference);
                        peer_lcd_none = compare(unfiltered->image, *reference);
                        microseconds = filtered->seconds_per_glyph * 1e6;
                        // Unfiltered, each subpixel is its third's area coverage; the filter blurs it
                        // over five thirds, which costs more than the 8 bits.
                        EXPECT_LT(peer_lcd_none.mean, 3.0 / 255.0) << key.glyph << " at " << pixels << " px";
                        EXPECT_GT(peer_lcd.mean, peer_lcd_none.mean);
                    }
                    char offset[16];
                    std::snprintf(offset, sizeof offset, "%.3f,%.3f", sub_x / 256.0, sub_y / 256.0);
                    const auto pair = [](const CoverageError& e) {
                        char cell[32];
                        if (e.touched_texels == 0) return std::string("-");
                        std::snprintf(cell, sizeof cell, "%.5f/%.4f", e.mean, e.worst);
                        return std::string(cell);
                    };
                    std::printf("U+%04X %4u %-6s %-9s %17s %17s %17s %17s %17s %6.1f %9.5f\n", codepoint, pixels,
                                layout->name.c_str(), offset, pair(against_exact).c_str(), pair(fine).c_str(),
                                pair(peer_gray).c_str(), pair(peer_lcd).c_str(), pair(peer_lcd_none).c_str(),
                                microseconds, gray_bias);
                }
            }
        }
    }
}

TEST(FreeTypeReference, CompareCoverage) {
    CoverageImage a;
    a.width = 2;
    a.height = 1;
    a.values = {0, 0, 0, 0.5f, 0.25f, 1};
    CoverageImage b = a;
    b.values[5] = 0.75f;
    Result<CoverageError> error = freetype::compare_coverage(a, b);
    ASSERT_TRUE(error.ok());
    EXPECT_EQ(error->touched_texels, 1u);  // the empty texel is not counted
    EXPECT_DOUBLE_EQ(error->mean, 0.25 / 3);
    EXPECT_DOUBLE_EQ(error->bias, 0.25 / 3);
    EXPECT_DOUBLE_EQ(error->worst, 0.25);
    EXPECT_EQ(error->worst_column, 1u);
    EXPECT_EQ(error->worst_channel, 2u);
    b.width = 1;
    EXPECT_FALSE(freetype::compare_coverage(a, b).ok());
}

TEST(FreeTypeReference, BadInputIsAnErrorNotACrash) {
    const std::vector<std::byte> garbage(4096, std::byte{0x5A});
    Result<Face> unreadable = Face::open(garbage);
    ASSERT_FALSE(unreadable.ok());
    EXPECT_EQ(unreadable.error().code, ErrorCode::font_unreadable);
    EXPECT_EQ(Face::open_file("/nonexistent/font.ttf").error().code, ErrorCode::io);
    EXPECT_EQ(Face::open_file(kDejaVuSans, 1).error().code, ErrorCode::font_unreadable);
    const Variation weight{make_tag("wght"), 700.0f};
    EXPECT_EQ(Face::open_file(kDejaVuSans, 0, {&weight, 1}).error().code, ErrorCode::font_unsupported);

    Result<Face> opened = Face::open_file(kDejaVuSans);
    ASSERT_TRUE(opened.ok());
    Face& face = *opened;
    const SubpixelLayout gray = layout_named("gray");
    const GlyphKey good = key_at(face.glyph_for('g'), 13, 0, 0);
    Result<GlyphRect> rect = freetype::outline_rect(face, good);
    ASSERT_TRUE(rect.ok());

    const auto refused = [&](const GlyphKey& key, const GlyphRect& r, uint32_t cells_per_texel) {
        const Result<GlyphRect> outline = freetype::outline_rect(face, key);
        const Result<CoverageImage> reference = freetype::reference_coverage(face, key, r, gray, cells_per_texel);
        const Result<freetype::PeerRender> peer = freetype::render_peer(face, key, r, PeerMode::gray);
        EXPECT_FALSE(reference.ok());
        if (!reference.ok()) {
            EXPECT_EQ(reference.error().code, ErrorCode::invalid_argument) << reference.error().message;
        }
        return !outline.ok() && !peer.ok();
    };
    GlyphKey out_of_range = good;
    out_of_range.glyph = face.glyph_count();
    EXPECT_TRUE(refused(out_of_range, *rect, 16));
    GlyphKey size_zero = good;
    size_zero.size_x = 0;
    EXPECT_TRUE(refused(size_zero, *rect, 16));
    GlyphKey absurd = good;
    absurd.size_y = (freetype::kMaxPixelSize + 1) * kSizeOne;
    EXPECT_TRUE(refused(absurd, *rect, 16));
    refused(good, *rect, 0);                                                        // no cells
    refused(good, *rect, freetype::kMaxCells);                                      // too many
    refused(good, GlyphRect{rect->x + 3, rect->y, rect->width, rect->height}, 16);  // misses the outline
    SubpixelLayout inverted = gray;
    inverted.channels[1] = {1, 0, 0, 1};
    EXPECT_FALSE(freetype::reference_coverage(face, good, *rect, inverted).ok());

    // A glyph without an outline has an empty rect and an empty image.
    const GlyphKey space = key_at(face.glyph_for(' '), 13, 0, 0);
    Result<GlyphRect> space_rect = freetype::outline_rect(face, space);
    ASSERT_TRUE(space_rect.ok());
    EXPECT_EQ(space_rect->width, 0u);
    Result<CoverageImage> space_image = freetype::reference_coverage(face, space, *space_rect, gray);
    ASSERT_TRUE(space_image.ok());
    EXPECT_TRUE(space_image->values.empty());

    // A truncated font opens or fails, and never crashes when rendered.
    const std::vector<std::byte> whole = test::read_file(kDejaVuSans);
    const std::vector<std::byte> truncated(whole.begin(), whole.begin() + static_cast<ptrdiff_t>(whole.size() / 3));
    if (Result<Face> cut = Face::open(truncated); cut.ok()) {
        const GlyphKey last = key_at(cut->glyph_count() - 1, 13, 0, 0);
        if (Result<GlyphRect> r = freetype::outline_rect(*cut, last); r.ok()) {
            (void)freetype::reference_coverage(*cut, last, *r, gray);
            (void)freetype::render_peer(*cut, last, *r, PeerMode::gray);
        }
    }
}

}  // namespace
}  // namespace crisp
