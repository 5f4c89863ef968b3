// Colour glyphs and emoji in layout: the emoji data and sequences, the expansion of a colour glyph
// into its layers, and font choice by emoji presentation. The colour fonts are baked assets with
// colour glyphs added by hand (DejaVu Sans, and a test font of emoji ligatures that
// tests/make_emoji_font.py makes); Noto Color Emoji where the baker reads it.
#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include "test_support.hpp"
#include "text/emoji.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace crisp {
namespace {

using detail::emoji_presentation;
using detail::emoji_properties;
using detail::emoji_sequence_end;
using detail::Presentation;

const std::string kNotoEmojiPath = "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf";

constexpr FontId kPlainId = 21;
constexpr FontId kColourId = 22;
constexpr FontId kEmojiId = 23;
constexpr FontId kNotoId = 24;
constexpr FontId kEmojiPlainId = 25;
constexpr FontId kColrId = 26;

size_t sequence_length(std::string_view utf8) {
    return emoji_sequence_end(decode_utf8(utf8), 0);
}

Presentation presentation(std::string_view utf8) {
    const std::vector<uint32_t> text = decode_utf8(utf8);
    return emoji_presentation(std::span(text).first(emoji_sequence_end(text, 0)));
}

TEST(EmojiData, PropertiesFromEmojiData) {
    EXPECT_EQ(emoji_properties('a'), 0u);
    EXPECT_EQ(emoji_properties('1'), detail::kEmoji);  // a keycap base, text by default
    EXPECT_EQ(emoji_properties('#'), detail::kEmoji);
    EXPECT_EQ(emoji_properties(0xA9), detail::kEmoji | detail::kExtendedPictographic);  // ©
    EXPECT_EQ(emoji_properties(0x2764), detail::kEmoji | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x1F600), detail::kEmoji | detail::kEmojiPresentation | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x26A1), detail::kEmoji | detail::kEmojiPresentation | detail::kExtendedPictographic);
    EXPECT_EQ(emoji_properties(0x1F1FA), detail::kEmoji | detail::kEmojiPresentation);  // regional indicator
    EXPECT_EQ(emoji_properties(0x1F3FD), detail::kEmoji | detail::kEmojiPresentation);  // skin tone
    EXPECT_EQ(emoji_properties(0x1FC00), detail::kExtendedPictographic);                // reserved
    EXPECT_EQ(emoji_properties(0x1FFFE), 0u);
    EXPECT_EQ(emoji_properties(0x200D), 0u);
    EXPECT_EQ(emoji_properties(0x10FFFF), 0u);
    EXPECT_EQ(emoji_properties(0x110000), 0u);
    EXPECT_EQ(emoji_properties(0xFFFFFFFF), 0u);
}

TEST(EmojiData, Sequences) {
    EXPECT_EQ(sequence_length("a"), 1u);
    EXPECT_EQ(sequence_length("12"), 1u);
    EXPECT_EQ(sequence_length("\U0001F600\U0001F600"), 1u);
    EXPECT_EQ(sequence_length("\u2764\uFE0F!"), 2u);
    EXPECT_EQ(sequence_length("\u2764\uFE0E!"), 2u);
    EXPECT_EQ(sequence_length("\U0001F44D\U0001F3FDx"), 2u);                       // skin tone
    EXPECT_EQ(sequence_length("\U0001F468\u200D\U0001F469\u200D\U0001F467"), 5u);  // ZWJ family
    EXPECT_EQ(sequence_length("\u2764\uFE0F\u200D\U0001F525"), 4u);                // ZWJ after a selector
    EXPECT_EQ(sequence_length("\U0001F44D\U0001F3FB\u200D\u2764"), 4u);            // ZWJ after a modifier
    EXPECT_EQ(sequence_length("\U0001F600\u200D"), 1u);   // a trailing joiner continues nothing
    EXPECT_EQ(sequence_length("\U0001F600\u200Da"), 1u);  // nor one before a letter
    EXPECT_EQ(sequence_length("a\u200D\U0001F600"), 1u);
    EXPECT_EQ(sequence_length("\U0001F1FA\U0001F1F8\U0001F1EB"), 2u);  // a flag, then a lone indicator
    EXPECT_EQ(sequence_length("\U0001F1EB"), 1u);
    EXPECT_EQ(sequence_length("1\uFE0F\u20E3"), 3u);  // keycap
    EXPECT_EQ(sequence_length("#\uFE0F\u20E3"), 3u);
    EXPECT_EQ(sequence_length("1\u20E3"), 1u);  // no U+FE0F: a digit and an enclosing mark
    EXPECT_EQ(sequence_length("\U0001F3F4\U000E0067\U000E0062\U000E0065\U000E006E\U000E0067\U000E007Fx"), 7u);

    EXPECT_EQ(presentation("a"), Presentation::none);
    EXPECT_EQ(presentation("\u2764"), Presentation::text);
    EXPECT_EQ(presentation("\u2764\uFE0F"), Presentation::emoji);
    EXPECT_EQ(presentation("\u2764\uFE0E"), Presentation::text);
    EXPECT_EQ(presentation("\U0001F600"), Presentation::emoji);
    EXPECT_EQ(presentation("\U0001F600\uFE0E"), Presentation::text);
    EXPECT_EQ(presentation("1"), Presentation::text);
    EXPECT_EQ(presentation("1\uFE0F\u20E3"), Presentation::emoji);
    EXPECT_EQ(presentation("\u2764\u200D\U0001F525"), Presentation::emoji);  // a ZWJ sequence is an emoji
    EXPECT_EQ(presentation("\U0001F1FA\U0001F1F8"), Presentation::emoji);
}

// Colour glyphs for `glyphs` (face glyphs of `asset`): each has three layers, back to front: its
// own outline in palette entry 0, the blank outline `blank` (dropped by layout) in the text's
// colour, and the outline `top` in palette entry 1. Two palettes of two entries.
void add_colour_glyphs(FontAsset& asset, const std::set<uint32_t>& glyphs, uint32_t blank, uint32_t top) {
    asset.palette_size = 2;
    asset.palette_colours = {0xFF0000FFu, 0xFF00FF00u, 0xFFFF0000u, 0x80FFFFFFu};
    asset.stops = {{0.0f, 0, 1.0f}, {0.0f, 1, 1.0f}, {0.0f, kForegroundPaletteIndex, 0.5f}};
    for (uint32_t i = 0; i < 3; ++i) {
        Paint solid;
        solid.first_stop = i;
        solid.stop_count = 1;
        asset.paints.push_back(solid);
    }
    for (uint32_t glyph : glyphs) {
        ColourGlyph colour;
        colour.glyph = glyph;
        colour.first_layer = static_cast<uint32_t>(asset.layers.size());
        colour.layer_count = 3;
        asset.colour_glyphs.push_back(colour);
        asset.layers.push_back({glyph, 0});
        asset.layers.push_back({blank, 2});
        asset.layers.push_back({top, 1});
    }
}

std::unique_ptr<Font> make_font(FontAsset asset, FontId id) {
    Result<Font> font = Font::create(std::move(asset), id);
    if (!font) {
        ADD_FAILURE() << font.error().message;
        return nullptr;
    }
    return std::make_unique<Font>(std::move(font).value());
}

Result<FontAsset> bake(const std::string& path, std::vector<uint32_t> codepoints) {
    BakeOptions options;
    options.all_glyphs = codepoints.empty();
    options.codepoints = std::move(codepoints);
    Result<BakeResult> baked = bake_font_file(path, options);
    if (!baked) return baked.error();
    return std::move(baked.value().asset);
}

// The face glyphs layout gives for each of `texts` in `font`.
std::set<uint32_t> shaped_glyphs(const Font& font, std::initializer_list<std::string_view> texts) {
    std::set<uint32_t> glyphs;
    const Font* fonts[] = {&font};
    for (std::string_view text : texts) {
        Result<TextLayout> layout = layout_text(fonts, text, {}, {});
        EXPECT_TRUE(layout);
        if (layout)
            for (const GlyphInstance& glyph : layout->glyphs) glyphs.insert(glyph.key.glyph);
    }
    return glyphs;
}

// A plain font and a colour one from the same asset: the colour one draws every glyph shaping
// gives for `coloured` as layers (see add_colour_glyphs).
void make_fonts(Result<FontAsset> asset, FontId plain_id, FontId colour_id,
                std::initializer_list<std::string_view> coloured, std::unique_ptr<Font>& plain,
                std::unique_ptr<Font>& colour) {
    ASSERT_TRUE(asset) << asset.error().message;
    plain = make_font(asset.value(), plain_id);
    ASSERT_NE(plain, nullptr);
    FontAsset colour_asset = std::move(asset).value();
    add_colour_glyphs(colour_asset, shaped_glyphs(*plain, coloured), plain->nominal_glyph(' '),
                      plain->nominal_glyph('o'));
    colour = make_font(std::move(colour_asset), colour_id);
}

class Emoji : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        make_fonts(bake(test::kDejaVuSans, {}), kPlainId, kColourId, {"\u2764", "\u26A1", "\u263A"}, plain_, colour_);
        // The emoji font has no 'o': its top layer is U+1F469's box.
        Result<FontAsset> emoji = bake(CRISP_EMOJI_TEST_FONT, {});
        ASSERT_TRUE(emoji) << emoji.error().message;
        std::unique_ptr<Font> plain_emoji = make_font(emoji.value(), kEmojiPlainId);
        ASSERT_NE(plain_emoji, nullptr);
        const std::set<uint32_t> coloured =
            shaped_glyphs(*plain_emoji, {"\U0001F600", "\U0001F468", "1", "\U0001F468\u200D\U0001F469\u200D\U0001F467",
                                         "\U0001F44D\U0001F3FD", "\U0001F1FA\U0001F1F8", "1\uFE0F\u20E3",
                                         "\U0001F3F4\U000E0067\U000E0062\U000E0065\U000E006E\U000E0067\U000E007F"});
        FontAsset asset = std::move(emoji).value();
        add_colour_glyphs(asset, coloured, plain_emoji->nominal_glyph(' '), plain_emoji->nominal_glyph(0x1F469));
        emoji_ = make_font(std::move(asset), kEmojiId);
        emoji_plain_ = std::move(plain_emoji);
    }
    static void TearDownTestSuite() {
        plain_.reset();
        colour_.reset();
        emoji_.reset();
        emoji_plain_.reset();
    }
    void SetUp() override {
        ASSERT_NE(plain_, nullptr);
        ASSERT_NE(colour_, nullptr);
        ASSERT_NE(emoji_, nullptr);
    }

    static TextLayout lay(std::vector<const Font*> fonts, std::string_view text, const TextStyle& style = {},
                          const LayoutOptions& options = {}) {
        return test::layout_or_fail(fonts, text, style, options);
    }

    static inline std::unique_ptr<Font> plain_, colour_, emoji_, emoji_plain_;
};

std::vector<FontId> font_ids(const TextLayout& layout) {
    std::vector<FontId> ids;
    for (const GlyphInstance& glyph : layout.glyphs) ids.push_back(glyph.key.font);
    return ids;
}

TEST_F(Emoji, FontReportsColourGlyphs) {
    EXPECT_TRUE(colour_->has_colour_glyph_for(0x2764));
    EXPECT_TRUE(colour_->has_glyph_for(0x2764));
    EXPECT_FALSE(plain_->has_colour_glyph_for(0x2764));
    EXPECT_FALSE(colour_->has_colour_glyph_for('a'));
    EXPECT_FALSE(colour_->has_colour_glyph_for(0x110000));
    EXPECT_FALSE(colour_->has_colour_glyph_for(0xD800));
}

TEST_F(Emoji, SyntheticLayerGlyphs) {
    // A layer's outline may be a synthetic record past the face's glyphs (a COLRv1 glyph under a
    // transform, a bitmap's rectangle): HarfBuzz counts the face's glyphs alone.
    FontAsset asset = colour_->asset();
    const uint32_t heart = colour_->nominal_glyph(0x2764);
    // A copy of 'o' with points and bands of its own.
    GlyphRecord synthetic = asset.glyphs.at(colour_->nominal_glyph('o'));
    synthetic.flags |= kGlyphSynthetic;
    const auto points =
        std::vector<Point>(asset.points.begin() + synthetic.point_offset,
                           asset.points.begin() + synthetic.point_offset + 2 * synthetic.curve_count + 1);
    const auto bands = std::vector<uint32_t>(
        asset.band_words.begin() + synthetic.band_offset,
        asset.band_words.begin() + synthetic.band_offset + synthetic.band_count * synthetic.band_words);
    synthetic.point_offset = static_cast<uint32_t>(asset.points.size());
    synthetic.band_offset = static_cast<uint32_t>(asset.band_words.size());
    asset.points.insert(asset.points.end(), points.begin(), points.end());
    asset.band_words.insert(asset.band_words.end(), bands.begin(), bands.end());
    const auto synthetic_glyph = static_cast<uint32_t>(asset.glyphs.size());
    asset.glyphs.push_back(synthetic);
    for (ColourGlyph& colour : asset.colour_glyphs)
        if (colour.glyph == heart) asset.layers.at(colour.first_layer + 2).glyph = synthetic_glyph;
    Result<Font> font = Font::create(std::move(asset), kColourId);
    ASSERT_TRUE(font) << font.error().message;
    EXPECT_EQ(font->asset().face_glyph_count(), synthetic_glyph);
    const Font* fonts[] = {&font.value()};
    Result<TextLayout> layout = layout_text(fonts, "\u2764", {.size = 30.0f}, {});
    ASSERT_TRUE(layout) << layout.error().message;
    ASSERT_EQ(layout->glyphs.size(), 2u);
    const GlyphInstance& top = layout->glyphs[1];
    EXPECT_EQ(top.key.glyph, synthetic_glyph);
    EXPECT_EQ(top.paint, 1u);
    const GlyphRect rect = glyph_rect(synthetic, top.key);
    EXPECT_EQ(top.width, rect.width);
    EXPECT_EQ(top.height, rect.height);
    EXPECT_EQ(top.x - layout->glyphs[0].x, rect.x - glyph_rect(*font->glyph_record(heart), top.key).x);
}

TEST_F(Emoji, ColourGlyphBecomesItsLayers) {
    const TextStyle style{.size = 40.0f, .color = {0.2f, 0.4f, 0.6f, 0.8f}, .depth = 0.25f};
    const LayoutOptions options{.origin_x = 10.3f, .origin_y = 50.7f, .first_paint_order = 100};
    const TextLayout layout = lay({colour_.get()}, "a\u2764b", style, options);
    const TextLayout flat =
        lay({colour_.get()}, "a\u2764b", style,
            {.origin_x = 10.3f, .origin_y = 50.7f, .first_paint_order = 100, .colour_glyphs = false});
    EXPECT_EQ(layout.shaped_glyphs, 3u);
    EXPECT_EQ(layout.colour_glyphs, 1u);
    EXPECT_EQ(layout.colour_layers, 2u);  // the blank layer is dropped
    EXPECT_EQ(layout.blank_glyphs, 0u);
    ASSERT_EQ(layout.glyphs.size(), 4u);
    ASSERT_EQ(layout.lines.size(), 1u);
    EXPECT_EQ(layout.lines[0].glyph_count, 4u);
    EXPECT_EQ(layout.next_paint_order, 104u);

    // Without colour: the plain outline, one instance, as a monochrome font draws it.
    EXPECT_EQ(flat.colour_glyphs, 0u);
    EXPECT_EQ(flat.colour_layers, 0u);
    ASSERT_EQ(flat.glyphs.size(), 3u);
    const GlyphInstance& heart = flat.glyphs[1];
    EXPECT_EQ(heart.key.glyph, colour_->nominal_glyph(0x2764));
    EXPECT_EQ(heart.paint, kNoPaint);
    EXPECT_EQ(heart.colour_glyph, kNoColourGlyph);
    EXPECT_EQ(flat.next_paint_order, 103u);

    const ColourGlyph* colour = colour_->asset().colour_glyph(heart.key.glyph);
    ASSERT_NE(colour, nullptr);
    const auto colour_index = static_cast<uint32_t>(colour - colour_->asset().colour_glyphs.data());
    const GlyphRect heart_rect = glyph_rect(*colour_->glyph_record(heart.key.glyph), heart.key);
    const uint32_t expected_glyphs[] = {heart.key.glyph, colour_->nominal_glyph('o')};
    const uint32_t expected_paints[] = {0, 1};
    for (size_t k = 0; k < 2; ++k) {
        const GlyphInstance& layer = layout.glyphs[1 + k];
        GlyphKey key = heart.key;
        key.glyph = expected_glyphs[k];
        EXPECT_EQ(layer.key, key) << k;
        const GlyphRect rect = glyph_rect(*colour_->glyph_record(key.glyph), key);
        EXPECT_EQ(layer.x, heart.x - heart_rect.x + rect.x) << k;
        EXPECT_EQ(layer.y, heart.y - heart_rect.y + rect.y) << k;
        EXPECT_EQ(layer.width, rect.width) << k;
        EXPECT_EQ(layer.height, rect.height) << k;
        EXPECT_EQ(layer.pen_x, heart.pen_x) << k;
        EXPECT_EQ(layer.pen_y, heart.pen_y) << k;
        EXPECT_EQ(layer.paint, expected_paints[k]) << k;
        EXPECT_EQ(layer.colour_glyph, colour_index) << k;
        EXPECT_EQ(layer.palette, 0u) << k;
        EXPECT_EQ(layer.paint_order, 101 + k) << k;
        EXPECT_EQ(layer.cluster, 1u) << k;
        EXPECT_EQ(layer.line, 0u) << k;
        EXPECT_EQ(layer.depth, 0.25f) << k;
        EXPECT_TRUE(std::equal(std::begin(layer.color), std::end(layer.color), std::begin(heart.color))) << k;
    }
    // The top layer is an 'o': its rect differs from the heart's.
    const GlyphInstance &bottom = layout.glyphs[1], &top = layout.glyphs[2];
    EXPECT_NE(std::tie(top.y, top.width, top.height), std::tie(bottom.y, bottom.width, bottom.height));
    // The text around it is monochrome, and the advance is the shaped one either way.
    for (const size_t g : {size_t{0}, size_t{3}}) {
        EXPECT_EQ(layout.glyphs[g].paint, kNoPaint);
        EXPECT_EQ(layout.glyphs[g].colour_glyph, kNoColourGlyph);
        EXPECT_EQ(layout.glyphs[g].palette, 0u);
    }
    EXPECT_EQ(layout.glyphs[3].pen_x, flat.glyphs[2].pen_x);
    EXPECT_EQ(layout.glyphs[3].paint_order, 103u);
    EXPECT_EQ(layout.width, flat.width);
}

TEST_F(Emoji, PaletteChoice) {
    const std::string heart = "\u2764";
    EXPECT_EQ(lay({colour_.get()}, heart, {.palette = 1}).glyphs.at(0).palette, 1u);
    // Past the font's two palettes: palette 0.
    EXPECT_EQ(lay({colour_.get()}, heart, {.palette = 2}).glyphs.at(0).palette, 0u);
    EXPECT_EQ(lay({colour_.get()}, heart, {.palette = 0xFFFFFFFF}).glyphs.at(0).palette, 0u);
    // Monochrome instances carry no palette.
    EXPECT_EQ(lay({colour_.get()}, "a", {.palette = 1}).glyphs.at(0).palette, 0u);
}

TEST_F(Emoji, LayersAreGlyphsOfTheirClusterAndLine) {
    // Two hearts on two lines: each line's glyph range holds its heart's layers.
    const TextLayout layout = lay({colour_.get()}, "\u2764 \u2764", {.size = 20.0f}, {.wrap_width = 25.0f});
    ASSERT_EQ(layout.lines.size(), 2u);
    EXPECT_EQ(layout.colour_glyphs, 2u);
    ASSERT_EQ(layout.glyphs.size(), 4u);
    for (uint32_t line = 0; line < 2; ++line) {
        EXPECT_EQ(layout.lines[line].glyph_begin, 2 * line);
        EXPECT_EQ(layout.lines[line].glyph_count, 2u);
        for (uint32_t k = 0; k < 2; ++k) {
            EXPECT_EQ(layout.glyphs[2 * line + k].line, line);
            EXPECT_EQ(layout.glyphs[2 * line + k].cluster, 4 * line);
        }
    }
    // A kept blank glyph stays one instance; layers are never kept blank.
    const TextLayout kept = lay({colour_.get()}, "\u2764 ", {}, {.keep_blank_glyphs = true});
    EXPECT_EQ(kept.glyphs.size(), 3u);
    EXPECT_EQ(kept.blank_glyphs, 1u);
}

TEST_F(Emoji, ColourGlyphWithoutOutlinesIsBlank) {
    // U+263A's layers all made blank: nothing is drawn, neither layers nor the plain outline.
    FontAsset asset = colour_->asset();
    const uint32_t smile = colour_->nominal_glyph(0x263A);
    for (ColourGlyph& colour : asset.colour_glyphs)
        if (colour.glyph == smile)
            for (uint32_t k = 0; k < colour.layer_count; ++k)
                asset.layers.at(colour.first_layer + k).glyph = colour_->nominal_glyph(' ');
    std::unique_ptr<Font> font = make_font(std::move(asset), kColourId);
    ASSERT_NE(font, nullptr);
    TextLayout layout = lay({font.get()}, "\u263A");
    EXPECT_TRUE(layout.glyphs.empty());
    EXPECT_EQ(layout.blank_glyphs, 1u);
    EXPECT_EQ(layout.colour_glyphs, 0u);
    layout = lay({font.get()}, "\u263A", {}, {.keep_blank_glyphs = true});
    ASSERT_EQ(layout.glyphs.size(), 1u);
    EXPECT_EQ(layout.glyphs[0].key.glyph, smile);
    EXPECT_EQ(layout.glyphs[0].width, 0u);
    EXPECT_EQ(layout.glyphs[0].height, 0u);
    EXPECT_EQ(layout.glyphs[0].paint, kNoPaint);
    // Without colour it is its outline again.
    layout = lay({font.get()}, "\u263A", {}, {.colour_glyphs = false});
    ASSERT_EQ(layout.glyphs.size(), 1u);
    EXPECT_GT(layout.glyphs[0].width, 0u);
}

TEST_F(Emoji, SelectorsChooseColourOrPlain) {
    const std::vector<const Font*> plain_first = {plain_.get(), colour_.get()};
    const std::vector<const Font*> colour_first = {colour_.get(), plain_.get()};
    // U+2764 is text by default: the plain font, wherever the colour one is.
    EXPECT_EQ(font_ids(lay(plain_first, "\u2764")), std::vector<FontId>{kPlainId});
    EXPECT_EQ(font_ids(lay(colour_first, "\u2764")), std::vector<FontId>{kPlainId});
    // U+FE0F: the colour font; U+FE0E: the plain one.
    TextLayout layout = lay(plain_first, "\u2764\uFE0F");
    EXPECT_EQ(font_ids(layout), (std::vector<FontId>{kColourId, kColourId}));
    EXPECT_EQ(layout.colour_glyphs, 1u);
    EXPECT_EQ(layout.shaped_glyphs, 1u);  // the selector is consumed
    EXPECT_EQ(font_ids(lay(colour_first, "\u2764\uFE0E")), std::vector<FontId>{kPlainId});
    // U+26A1 is an emoji by default; U+FE0E makes it text.
    EXPECT_EQ(font_ids(lay(plain_first, "\u26A1")), (std::vector<FontId>{kColourId, kColourId}));
    EXPECT_EQ(font_ids(lay(plain_first, "\u26A1\uFE0E")), std::vector<FontId>{kPlainId});
    EXPECT_EQ(font_ids(lay(colour_first, "\u26A1\uFE0E")), std::vector<FontId>{kPlainId});
    // Between words of the colour font a heart of text presentation still goes to the plain one.
    layout = lay(colour_first, "a\u2764b");
    EXPECT_EQ(font_ids(layout), (std::vector<FontId>{kColourId, kPlainId, kColourId}));
    // Without a font with the plain outline, text presentation takes the colour glyph.
    EXPECT_EQ(lay({colour_.get()}, "\u2764\uFE0E").colour_glyphs, 1u);
    // And an emoji no font has in colour is the first font's that has it.
    EXPECT_EQ(font_ids(lay({plain_.get(), emoji_plain_.get()}, "\U0001F600")), std::vector<FontId>{kPlainId});
}

TEST_F(Emoji, DigitsAfterAnEmojiStayText) {
    // The emoji font draws '1' in colour (as Noto Color Emoji does); after an emoji, digits of
    // text presentation go back to the plain font rather than staying in the emoji font.
    const TextLayout layout = lay({plain_.get(), emoji_.get()}, "\U0001F600 12");
    ASSERT_EQ(layout.glyphs.size(), 4u);  // two layers of the emoji, two digits (the space is dropped)
    EXPECT_EQ(font_ids(layout), (std::vector<FontId>{kEmojiId, kEmojiId, kPlainId, kPlainId}));
    EXPECT_EQ(lay({plain_.get(), emoji_.get()}, "1\uFE0F").colour_glyphs, 1u);
}

// Every glyph of `layout` is in font `id`, in cluster 0, and they are the layers of one colour glyph.
void expect_one_colour_glyph(const TextLayout& layout, FontId id) {
    EXPECT_EQ(layout.shaped_glyphs, 1u);
    EXPECT_EQ(layout.colour_glyphs, 1u);
    EXPECT_EQ(layout.colour_layers, 2u);
    EXPECT_EQ(layout.missing_glyphs, 0u);
    ASSERT_EQ(layout.glyphs.size(), 2u);
    for (const GlyphInstance& glyph : layout.glyphs) {
        EXPECT_EQ(glyph.key.font, id);
        EXPECT_EQ(glyph.cluster, 0u);
        EXPECT_EQ(glyph.colour_glyph, layout.glyphs[0].colour_glyph);
    }
}

TEST_F(Emoji, SequencesStayInOneFontAndCluster) {
    const std::vector<const Font*> fonts = {plain_.get(), emoji_.get()};
    struct Case {
        const char* name;
        std::string text;
    };
    const Case cases[] = {
        {"ZWJ family", "\U0001F468\u200D\U0001F469\u200D\U0001F467"},
        {"skin tone", "\U0001F44D\U0001F3FD"},
        {"flag", "\U0001F1FA\U0001F1F8"},
        {"keycap", "1\uFE0F\u20E3"},
        {"tag sequence", "\U0001F3F4\U000E0067\U000E0062\U000E0065\U000E006E\U000E0067\U000E007F"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        // HarfBuzz forms the font's ligature of the whole sequence.
        const TextLayout plain = lay({emoji_plain_.get()}, c.text);
        EXPECT_EQ(plain.shaped_glyphs, 1u);
        expect_one_colour_glyph(lay(fonts, c.text), kEmojiId);
        // In a right-to-left paragraph, and with a wrap width narrower than the emoji.
        const TextLayout rtl = lay(fonts, "\u05D0 " + c.text + " \u05D1");
        EXPECT_EQ(rtl.colour_glyphs, 1u);
        const TextLayout narrow = lay(fonts, c.text, {.size = 20.0f}, {.wrap_width = 5.0f, .break_long_words = true});
        EXPECT_EQ(narrow.lines.size(), 1u);
        EXPECT_EQ(narrow.colour_glyphs, 1u);
    }
    // Two flags in a row are two clusters; a third indicator stands alone.
    const TextLayout flags = lay(fonts, "\U0001F1FA\U0001F1F8\U0001F1FA\U0001F1F8\U0001F1FA");
    EXPECT_EQ(flags.colour_glyphs, 2u);
    EXPECT_EQ(flags.shaped_glyphs, 3u);
    std::set<uint32_t> clusters;
    for (const GlyphInstance& glyph : flags.glyphs) clusters.insert(glyph.cluster);
    EXPECT_EQ(clusters, (std::set<uint32_t>{0, 8, 16}));
}

TEST_F(Emoji, SequenceFollowsItsFirstCharactersFont) {
    // U+263A after a joiner continues the sequence: it stays in the emoji font, which lacks it
    // (HarfBuzz gives .notdef), rather than going to the plain font that has it.
    const TextLayout layout = lay({plain_.get(), emoji_.get()}, "\U0001F600\u200D\u263A");
    EXPECT_EQ(layout.missing_glyphs, 1u);
    for (const GlyphInstance& glyph : layout.glyphs) EXPECT_EQ(glyph.key.font, kEmojiId);
    // Without the joiner it is a character of its own, text by default: the plain font.
    const TextLayout apart = lay({plain_.get(), emoji_.get()}, "\U0001F600\u263A");
    EXPECT_EQ(apart.missing_glyphs, 0u);
    EXPECT_EQ(apart.glyphs.back().key.font, kPlainId);
}

TEST_F(Emoji, LongJoinerChainsAreCut) {
    // A sequence is one HarfBuzz cluster; like marks, past kMaxMarksPerCluster characters it
    // continues in a new run.
    constexpr uint32_t kEmojiCount = 1000;
    std::string text = "\U0001F600";
    for (uint32_t i = 1; i < kEmojiCount; ++i) text += "\u200D\U0001F600";
    const TextLayout layout = lay({plain_.get(), emoji_.get()}, text);
    const uint32_t continuing = 2 * (kEmojiCount - 1);
    EXPECT_EQ(layout.mark_splits, 1 + (continuing - kMaxMarksPerCluster - 1) / kMaxMarksPerCluster);
    EXPECT_EQ(layout.colour_glyphs, kEmojiCount);
    for (const GlyphInstance& glyph : layout.glyphs) EXPECT_EQ(glyph.key.font, kEmojiId);
}

TEST_F(Emoji, HostileSequencesKeepTheInvariants) {
    std::mt19937 random(51);
    const std::vector<const Font*> fonts = {plain_.get(), emoji_.get(), colour_.get()};
    const std::string pieces[] = {"a",          " ",          "1",          "#",          "\u2764",     "\u26A1",
                                  "\uFE0F",     "\uFE0E",     "\u200D",     "\u20E3",     "\u05D0",     "\u0301",
                                  "\U0001F600", "\U0001F44D", "\U0001F3FD", "\U0001F1FA", "\U0001F1F8", "\U0001F3F4",
                                  "\U000E0067", "\U000E007F", "\U0001F468", "\U0001F469", "\n",         "\xF0\x9F"};
    for (int round = 0; round < 300; ++round) {
        std::string text;
        const auto length = random() % 48;
        for (uint32_t i = 0; i < length; ++i) text += pieces[random() % std::size(pieces)];
        LayoutOptions options;
        options.wrap_width = static_cast<float>(random() % 3) * 30.0f;
        options.direction = static_cast<Direction>(random() % 3);
        options.keep_blank_glyphs = random() % 2 == 0;
        options.colour_glyphs = random() % 4 != 0;
        options.first_paint_order = 7;
        const TextLayout layout = lay(fonts, text, {.size = 17.0f}, options);
        SCOPED_TRACE(text);
        uint32_t layers = 0;
        for (size_t g = 0; g < layout.glyphs.size(); ++g) {
            const GlyphInstance& glyph = layout.glyphs[g];
            EXPECT_EQ(glyph.paint_order, 7 + g);
            ASSERT_LT(glyph.line, layout.lines.size());
            const TextLine& line = layout.lines[glyph.line];
            EXPECT_GE(g, line.glyph_begin);
            EXPECT_LT(g, line.glyph_begin + line.glyph_count);
            EXPECT_LE(glyph.cluster, text.size());
            if (glyph.paint == kNoPaint) {
                EXPECT_EQ(glyph.colour_glyph, kNoColourGlyph);
                continue;
            }
            ++layers;
            EXPECT_TRUE(options.colour_glyphs);
            const Font* font = glyph.key.font == kEmojiId ? emoji_.get() : colour_.get();
            ASSERT_LT(glyph.colour_glyph, font->asset().colour_glyphs.size());
            EXPECT_LT(glyph.paint, font->asset().paints.size());
        }
        EXPECT_EQ(layers, layout.colour_layers);
        EXPECT_LE(layout.colour_glyphs, layout.colour_layers);
        EXPECT_EQ(layout.next_paint_order, 7 + layout.glyphs.size());
    }
}

TEST_F(Emoji, ColrTestFonts) {
    // The emoji of the COLR test fonts (tests/fonts/colour/README.md), baked from their COLR tables,
    // behind DejaVu Sans: presentation picks the font, sequences become its ligatures.
    for (const char* file : {"colrv0.ttf", "colrv1.ttf"}) {
        SCOPED_TRACE(file);
        Result<FontAsset> asset = bake(test::source_path(std::string("tests/fonts/colour/") + file), {});
        ASSERT_TRUE(asset) << asset.error().message;
        std::unique_ptr<Font> colr = make_font(std::move(asset).value(), kColrId);
        ASSERT_NE(colr, nullptr);
        const std::vector<const Font*> fonts = {plain_.get(), colr.get()};
        EXPECT_EQ(font_ids(lay(fonts, "\u2764")), std::vector<FontId>{kPlainId});
        EXPECT_EQ(lay(fonts, "\u2764").colour_glyphs, 0u);
        struct Case {
            const char* name;
            std::string text;
        };
        const Case cases[] = {
            {"heart with VS16", "\u2764\uFE0F"},
            {"smile", "\U0001F600"},
            {"skin tone", "\U0001F44D\U0001F3FD"},
            {"flag", "\U0001F1FA\U0001F1F8"},
            {"ZWJ sequence", "\u2764\uFE0F\u200D\U0001F600"},
            {"ZWJ sequence without VS16", "\u2764\u200D\U0001F600"},  // an emoji though U+2764 is text
        };
        for (const Case& c : cases) {
            SCOPED_TRACE(c.name);
            const TextLayout layout = lay(fonts, c.text);
            EXPECT_EQ(layout.shaped_glyphs, 1u);
            EXPECT_EQ(layout.colour_glyphs, 1u);
            EXPECT_EQ(layout.missing_glyphs, 0u);
            ASSERT_FALSE(layout.glyphs.empty());
            for (const GlyphInstance& glyph : layout.glyphs) {
                EXPECT_EQ(glyph.key.font, kColrId);
                EXPECT_EQ(glyph.cluster, 0u);
                EXPECT_NE(glyph.paint, kNoPaint);
                EXPECT_EQ(glyph.colour_glyph, layout.glyphs[0].colour_glyph);
            }
        }
        // Text after the emoji goes back to DejaVu Sans.
        const TextLayout mixed = lay(fonts, "\U0001F600a1");
        ASSERT_GE(mixed.glyphs.size(), 3u);
        EXPECT_EQ(mixed.glyphs[mixed.glyphs.size() - 2].key.font, kPlainId);
        EXPECT_EQ(mixed.glyphs.back().key.font, kPlainId);
    }
}

TEST_F(Emoji, NotoColorEmoji) {
    Result<FontAsset> asset = bake(kNotoEmojiPath, {0x2764, 0x1F44D, 0x1F3FD, 0x1F1FA, 0x1F1F8});
    if (!asset) GTEST_SKIP() << "the baker does not read Noto Color Emoji yet: " << asset.error().message;
    std::unique_ptr<Font> noto = make_font(std::move(asset).value(), kNotoId);
    ASSERT_NE(noto, nullptr);
    const std::vector<const Font*> fonts = {plain_.get(), noto.get()};
    EXPECT_EQ(font_ids(lay(fonts, "\u2764")), std::vector<FontId>{kPlainId});
    for (const std::string text : {"\u2764\uFE0F", "\U0001F44D\U0001F3FD", "\U0001F1FA\U0001F1F8"}) {
        const TextLayout layout = lay(fonts, text);
        EXPECT_EQ(layout.shaped_glyphs, 1u) << text;
        EXPECT_EQ(layout.colour_glyphs, 1u) << text;
        EXPECT_GE(layout.glyphs.size(), 1u) << text;
        for (const GlyphInstance& glyph : layout.glyphs) {
            EXPECT_EQ(glyph.key.font, kNotoId) << text;
            EXPECT_EQ(glyph.cluster, 0u) << text;
            EXPECT_NE(glyph.paint, kNoPaint) << text;
        }
    }
}

}  // namespace
}  // namespace crisp
