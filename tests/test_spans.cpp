// Styled spans and paragraph options of Layouter::layout: spans keep shaping across colour-only
// boundaries, change sizes, fonts, features, spacing and shifts where they say; underlines and
// strikethroughs; scale, line height, maximum lines with ellipsis trimming and tab stops; bad
// spans refused by name.
#include <crisp/bake.hpp>
#include <crisp/editing.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace crisp {
namespace {

const std::string kDejaVuPath = std::string(CRISP_SOURCE_DIR) + "/fonts/DejaVuSans.ttf";
const std::string kInterPath = std::string(CRISP_SOURCE_DIR) + "/fonts/Inter-Regular.otf";

std::unique_ptr<Font> bake(const std::string& path, FontId id, std::vector<uint32_t> codepoints) {
    return test::bake_font_or_fail(path, id, std::move(codepoints));
}

std::vector<uint32_t> latin_arabic_hebrew() {
    std::vector<uint32_t> out;
    for (uint32_t cp = 0x20; cp <= 0x7E; ++cp) out.push_back(cp);
    for (uint32_t cp = 0x5D0; cp <= 0x5EA; ++cp) out.push_back(cp);
    for (uint32_t cp = 0x621; cp <= 0x64A; ++cp) out.push_back(cp);
    out.insert(out.end(), {0xE9, 0x2026, 0xFB01, 0xFB02});
    return out;
}

class Spans : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dejavu_ = bake(kDejaVuPath, 7, latin_arabic_hebrew()).release();
        inter_ = bake(kInterPath, 11, latin_arabic_hebrew()).release();
    }
    static void TearDownTestSuite() {
        delete dejavu_;
        delete inter_;
    }
    void SetUp() override {
        ASSERT_NE(dejavu_, nullptr);
        ASSERT_NE(inter_, nullptr);
    }
    static TextLayout lay(std::string_view text, const TextStyle& style, std::vector<TextSpan> spans,
                          const LayoutOptions& options = {}) {
        const Font* fonts[] = {dejavu_};
        Result<TextLayout> layout = layout_text(fonts, text, style, spans, options);
        if (!layout) {
            ADD_FAILURE() << layout.error().message;
            return {};
        }
        return std::move(layout).value();
    }
    static std::string refusal(std::string_view text, std::vector<TextSpan> spans, const LayoutOptions& options = {}) {
        const Font* fonts[] = {dejavu_};
        Result<TextLayout> layout = layout_text(fonts, text, {}, spans, options);
        return layout ? std::string("accepted") : layout.error().message;
    }
    static TextSpan span(uint32_t begin, uint32_t end, TextStyle style) { return {begin, end, style}; }

    static inline Font* dejavu_ = nullptr;
    static inline Font* inter_ = nullptr;
};

TextStyle red() {
    TextStyle style;
    style.color[0] = 1.0f;
    return style;
}

TEST_F(Spans, ColourOnlyBoundariesKeepKerningAndLigatures) {
    // Kerning pairs (AV, To) and ligatures (fi, fl) with a colour change in the middle of each.
    const std::string text = "AVATAR To fine flow";
    const TextLayout plain = lay(text, {}, {});
    std::vector<TextSpan> spans;
    for (const uint32_t at : {1u, 3u, 8u, 11u, 16u}) spans.push_back(span(at, at + 1, red()));
    const TextLayout styled = lay(text, {}, spans);
    ASSERT_EQ(plain.glyphs.size(), styled.glyphs.size());
    for (size_t i = 0; i < plain.glyphs.size(); ++i) {
        EXPECT_EQ(plain.glyphs[i].key, styled.glyphs[i].key) << i;
        EXPECT_EQ(plain.glyphs[i].pen_x, styled.glyphs[i].pen_x) << i;
        EXPECT_EQ(plain.glyphs[i].x, styled.glyphs[i].x) << i;
    }
    // The glyph of a span's character is red; a ligature takes its first character's colour.
    bool saw_red = false;
    for (const GlyphInstance& glyph : styled.glyphs) {
        const bool in_span = std::any_of(spans.begin(), spans.end(), [&](const TextSpan& s) {
            return glyph.cluster >= s.begin && glyph.cluster < s.end;
        });
        EXPECT_EQ(glyph.color[0] == 1.0f, in_span) << glyph.cluster;
        saw_red = saw_red || in_span;
    }
    EXPECT_TRUE(saw_red);
    // The ligatures are there: "fi" and "fl" are one glyph each.
    EXPECT_NE(std::find_if(styled.glyphs.begin(), styled.glyphs.end(),
                           [&](const GlyphInstance& g) { return g.key.glyph == dejavu_->nominal_glyph(0xFB01); }),
              styled.glyphs.end());
}

TEST_F(Spans, SizeSpansChangeKeysAndTheLineBox) {
    TextStyle big;
    big.size = 32.0f;
    const TextLayout plain = lay("ab\ncd", {}, {});
    const TextLayout styled = lay("ab\ncd", {}, {span(1, 2, big)});
    ASSERT_EQ(styled.glyphs.size(), 4u);
    EXPECT_EQ(styled.glyphs[0].key.size_x, 16u * kSizeOne);
    EXPECT_EQ(styled.glyphs[1].key.size_x, 32u * kSizeOne);
    EXPECT_EQ(styled.glyphs[1].key.size_y, 32u * kSizeOne);
    ASSERT_EQ(styled.lines.size(), 2u);
    EXPECT_NEAR(styled.lines[0].ascent, 2.0f * plain.lines[0].ascent, 0.01f);
    // The second line is pushed down by the first's taller box.
    EXPECT_GT(styled.lines[1].baseline_y - styled.lines[0].baseline_y,
              plain.lines[1].baseline_y - plain.lines[0].baseline_y + 1.0f);
    EXPECT_GT(styled.height, plain.height);
    // A plain line keeps the style's line height exactly.
    EXPECT_EQ(plain.lines[1].baseline_y - plain.lines[0].baseline_y, plain.line_height);
}

TEST_F(Spans, FontAndFeatureSpans) {
    const Font* inter[] = {inter_, dejavu_};
    TextStyle other;
    other.fonts = inter;
    const TextLayout fonts = lay("ab cd", {}, {span(3, 5, other)});
    ASSERT_EQ(fonts.glyphs.size(), 4u);
    EXPECT_EQ(fonts.glyphs[0].key.font, dejavu_->id());
    EXPECT_EQ(fonts.glyphs[2].key.font, inter_->id());
    EXPECT_EQ(fonts.glyphs[3].key.font, inter_->id());

    const FontFeature no_ligatures[] = {{{'l', 'i', 'g', 'a'}, 0}};
    TextStyle plain_letters;
    plain_letters.features = no_ligatures;
    const TextLayout features = lay("fi fi", {}, {span(3, 5, plain_letters)});
    ASSERT_EQ(features.glyphs.size(), 3u);  // the first "fi" a ligature, the second two letters
    EXPECT_EQ(features.glyphs[0].key.glyph, dejavu_->nominal_glyph(0xFB01));
    EXPECT_EQ(features.glyphs[1].key.glyph, dejavu_->nominal_glyph('f'));
    EXPECT_EQ(features.glyphs[2].key.glyph, dejavu_->nominal_glyph('i'));
}

TEST_F(Spans, LetterSpacingAndBaselineShift) {
    TextStyle spaced;
    spaced.letter_spacing = 3.0f;
    const TextLayout plain = lay("abcd", {}, {});
    const TextLayout styled = lay("abcd", {}, {span(1, 3, spaced)});
    ASSERT_EQ(styled.glyphs.size(), 4u);
    EXPECT_NEAR(styled.glyphs[2].pen_x - plain.glyphs[2].pen_x, 3.0f, 1e-3f);
    EXPECT_NEAR(styled.glyphs[3].pen_x - plain.glyphs[3].pen_x, 6.0f, 1e-3f);
    EXPECT_NEAR(styled.lines[0].width - plain.lines[0].width, 6.0f, 1e-3f);
    // Right to left: spacing widens the line the same, and the marks stay on their base.
    const std::string arabic = "\xD8\xB3\xD9\x84\xD8\xA7\xD9\x85";  // سلام
    TextStyle rtl_spaced;
    rtl_spaced.letter_spacing = 2.0f;
    const TextLayout rtl_plain = lay(arabic, {}, {});
    const TextLayout rtl = lay(arabic, rtl_spaced, {});
    EXPECT_NEAR(rtl.lines[0].width - rtl_plain.lines[0].width, 2.0f * static_cast<float>(rtl_plain.glyphs.size()),
                1e-3f);

    TextStyle raised;
    raised.baseline_shift = 5.0f;
    const TextLayout shifted = lay("abcd", {}, {span(2, 3, raised)});
    EXPECT_NEAR(shifted.glyphs[2].pen_y, plain.glyphs[2].pen_y - 5.0f, 1e-4f);
    EXPECT_EQ(shifted.glyphs[1].pen_y, plain.glyphs[1].pen_y);
    EXPECT_GT(shifted.lines[0].ascent, plain.lines[0].ascent + 4.9f);
}

TEST_F(Spans, UnderlinesSkipInkAndMergeAcrossSpans) {
    TextStyle underlined;
    underlined.underline = true;
    TextStyle underlined_red = underlined;
    underlined_red.color[0] = 1.0f;
    // "ab" and "cd" one colour (one rectangle), "ef" another.
    const TextLayout merged =
        lay("ab cd ef", {}, {span(0, 2, underlined), span(2, 5, underlined), span(6, 8, underlined_red)});
    ASSERT_EQ(merged.decorations.size(), 2u);
    const TextDecoration& first = merged.decorations[0];
    EXPECT_EQ(first.kind, DecorationKind::underline);
    EXPECT_EQ(first.text_begin, 0u);
    EXPECT_EQ(first.text_end, 5u);
    EXPECT_GT(first.y, merged.lines[0].baseline_y);  // below the baseline
    EXPECT_GT(first.height, 0.5f);
    EXPECT_LT(first.height, 3.0f);
    EXPECT_NEAR(first.x, merged.glyphs[0].pen_x, 1e-3f);
    EXPECT_EQ(merged.decorations[1].color[0], 1.0f);

    // A descender breaks the underline unless ink skipping is off.
    const TextLayout skipping = lay("gap", underlined, {});
    EXPECT_GE(skipping.decorations.size(), 2u);
    TextStyle through = underlined;
    through.skip_ink = false;
    const TextLayout solid = lay("gap", through, {});
    ASSERT_EQ(solid.decorations.size(), 1u);
    float covered = 0.0f;
    for (const TextDecoration& d : skipping.decorations) covered += d.width;
    EXPECT_LT(covered, solid.decorations[0].width);

    // Tracking tighter than the glyphs' advances: one rectangle, running left to right.
    TextStyle tight = underlined;
    tight.letter_spacing = -12.0f;
    const TextLayout overlapping = lay("iiii", tight, {});
    ASSERT_EQ(overlapping.decorations.size(), 1u);
    EXPECT_GT(overlapping.decorations[0].width, 0.0f);

    TextStyle struck;
    struck.strikethrough = true;
    const TextLayout strike = lay("xx", struck, {});
    ASSERT_EQ(strike.decorations.size(), 1u);
    EXPECT_EQ(strike.decorations[0].kind, DecorationKind::strikethrough);
    EXPECT_LT(strike.decorations[0].y, strike.lines[0].baseline_y);  // above the baseline
    EXPECT_TRUE(lay("xx", {}, {}).decorations.empty());
}

TEST_F(Spans, ScaleMultipliesLogicalSizes) {
    LayoutOptions one;
    one.wrap_width = 60.0f;
    LayoutOptions two = one;
    two.scale = 2.0f;
    const std::string text = "one two three four";
    const TextLayout a = lay(text, {}, {}, one);
    const TextLayout b = lay(text, {}, {}, two);
    ASSERT_EQ(a.glyphs.size(), b.glyphs.size());
    ASSERT_EQ(a.lines.size(), b.lines.size());
    for (size_t i = 0; i < a.glyphs.size(); ++i) {
        EXPECT_EQ(b.glyphs[i].key.size_x, 2 * a.glyphs[i].key.size_x);
        EXPECT_NEAR(b.glyphs[i].pen_x, 2.0f * a.glyphs[i].pen_x, 1e-3f);
        EXPECT_EQ(b.glyphs[i].line, a.glyphs[i].line);
    }
    EXPECT_NEAR(b.line_height, 2.0f * a.line_height, 1e-3f);
}

TEST_F(Spans, LineHeightAndSpacing) {
    LayoutOptions fixed;
    fixed.line_height = 30.0f;
    const TextLayout a = lay("a\nb\nc", {}, {}, fixed);
    ASSERT_EQ(a.lines.size(), 3u);
    EXPECT_FLOAT_EQ(a.lines[1].baseline_y - a.lines[0].baseline_y, 30.0f);
    EXPECT_FLOAT_EQ(a.lines[2].baseline_y - a.lines[1].baseline_y, 30.0f);
    LayoutOptions spaced;
    spaced.line_spacing = 1.5f;
    const TextLayout plain = lay("a\nb", {}, {});
    const TextLayout b = lay("a\nb", {}, {}, spaced);
    EXPECT_NEAR(b.lines[1].baseline_y - b.lines[0].baseline_y, 1.5f * plain.line_height, 1e-3f);
}

TEST_F(Spans, MaxLinesTrimWithAnEllipsis) {
    const uint32_t ellipsis = dejavu_->nominal_glyph(0x2026);
    const std::string text = "The quick brown fox jumps over the lazy dog";
    LayoutOptions options;
    options.wrap_width = 100.0f;
    options.max_lines = 2;
    const TextLayout dropped = lay(text, {}, {}, options);
    EXPECT_EQ(dropped.lines.size(), 2u);
    EXPECT_TRUE(dropped.trimmed);
    for (const GlyphInstance& glyph : dropped.glyphs) EXPECT_NE(glyph.key.glyph, ellipsis);

    for (const Trimming trimming : {Trimming::end, Trimming::start, Trimming::middle}) {
        options.trimming = trimming;
        options.max_lines = 1;
        const TextLayout trimmed = lay(text, {}, {}, options);
        ASSERT_EQ(trimmed.lines.size(), 1u);
        EXPECT_TRUE(trimmed.trimmed);
        EXPECT_LE(trimmed.lines[0].width, 100.0f + 1e-3f);
        EXPECT_GT(trimmed.lines[0].width, 60.0f);  // as much text as fits
        const auto found = std::find_if(trimmed.glyphs.begin(), trimmed.glyphs.end(),
                                        [&](const GlyphInstance& g) { return g.key.glyph == ellipsis; });
        ASSERT_NE(found, trimmed.glyphs.end());
        // In visual order: last at the end, first at the start, inside in the middle.
        float leftmost = 1e9f, rightmost = -1e9f;
        for (const GlyphInstance& glyph : trimmed.glyphs) {
            leftmost = std::min(leftmost, glyph.pen_x);
            rightmost = std::max(rightmost, glyph.pen_x);
        }
        if (trimming == Trimming::end) {
            EXPECT_EQ(found->pen_x, rightmost);
        }
        if (trimming == Trimming::start) {
            EXPECT_EQ(found->pen_x, leftmost);
        }
        if (trimming == Trimming::middle) {
            EXPECT_GT(found->pen_x, leftmost);
            EXPECT_LT(found->pen_x, rightmost);
            // The text's end shows: "dog".
            EXPECT_EQ(trimmed.glyphs.back().key.glyph, dejavu_->nominal_glyph('g'));
        }
    }
    // Nothing dropped: no ellipsis, not trimmed.
    options.max_lines = 5;
    options.trimming = Trimming::end;
    const TextLayout whole = lay(text, {}, {}, options);
    EXPECT_FALSE(whole.trimmed);
    for (const GlyphInstance& glyph : whole.glyphs) EXPECT_NE(glyph.key.glyph, ellipsis);
    options.max_lines = 1;
    EXPECT_FALSE(lay("Title\n", {}, {}, options).trimmed);
}

TEST_F(Spans, TabStops) {
    const float stops[] = {50.0f, 120.0f};
    LayoutOptions options;
    options.tab_stops = stops;
    const TextLayout layout = lay("a\tb\tc\td", {}, {}, options);
    ASSERT_EQ(layout.glyphs.size(), 4u);
    EXPECT_NEAR(layout.glyphs[1].pen_x, 50.0f, 1e-3f);
    EXPECT_NEAR(layout.glyphs[2].pen_x, 120.0f, 1e-3f);
    const float space = dejavu_->glyph_record(dejavu_->nominal_glyph(' '))->advance * 16.0f;
    const float grid = 4.0f * space;  // past the last stop, tab_spaces' stops
    const float c_end = layout.glyphs[2].pen_x + dejavu_->glyph_record(layout.glyphs[2].key.glyph)->advance * 16.0f;
    EXPECT_NEAR(layout.glyphs[3].pen_x, std::ceil(c_end / grid) * grid, 1e-3f);
}

TEST_F(Spans, CaretsRoundTripThroughStyledLines) {
    // Sizes, shifts and spacing change the line boxes and advances the caret works from; every
    // grapheme boundary's caret, hit at its centre, gives the position back, and the caret is as
    // tall as its line's box.
    const std::string text =
        "Mixed sizes: big \xD7\xA9\xD7\x9C\xD7\x95\xD7\x9D small x2 and spaced \xD8\xB3\xD9\x84\xD8\xA7\xD9\x85 end";
    TextStyle big;
    big.size = 30.0f;
    TextStyle raised;
    raised.size = 10.0f;
    raised.baseline_shift = 6.0f;
    TextStyle spaced;
    spaced.letter_spacing = 3.0f;
    const uint32_t two = static_cast<uint32_t>(text.find("x2")) + 1;
    const uint32_t spaced_at = static_cast<uint32_t>(text.find("spaced"));
    LayoutOptions options;
    options.wrap_width = 160.0f;
    const TextLayout layout =
        lay(text, {}, {span(13, 16, big), span(two, two + 1, raised), span(spaced_at, spaced_at + 6, spaced)}, options);
    ASSERT_GE(layout.lines.size(), 2u);
    Result<TextBoundaries> boundaries = TextBoundaries::analyze(text);
    ASSERT_TRUE(boundaries) << boundaries.error().message;
    size_t checked = 0;
    for (uint32_t offset = 0; offset <= text.size(); ++offset) {
        if (!boundaries->is_grapheme_boundary(offset)) continue;
        for (const bool upstream : {false, true}) {
            const TextPosition position{offset, upstream};
            const TextRect caret = caret_rect(layout, *boundaries, position);
            const HitTest hit = hit_test(layout, *boundaries, caret.x + caret.width / 2, caret.y + caret.height / 2);
            const TextRect back = caret_rect(layout, *boundaries, hit.position);
            // The same caret (a position at a line's end and the next line's start are two carets).
            EXPECT_NEAR(back.x, caret.x, 1e-3f) << offset << (upstream ? " upstream" : "");
            EXPECT_NEAR(back.y, caret.y, 1e-3f) << offset << (upstream ? " upstream" : "");
            const TextLine& line = layout.lines[hit.line];
            EXPECT_NEAR(caret.height, line.ascent + line.descent, 1e-3f) << offset;
            ++checked;
        }
    }
    EXPECT_GT(checked, 100u);
    // The first line holds the big word: its box is taller than the base style's.
    EXPECT_GT(layout.lines[0].ascent, 1.5f * lay("x", {}, {}).lines[0].ascent);
}

TEST_F(Spans, BadSpansAreRefusedByName) {
    const std::string text = "caf\xC3\xA9 au lait";  // é is bytes 3 and 4
    EXPECT_NE(refusal(text, {span(0, 4, {})}).find("spans[0] ends at byte 4, inside a UTF-8 sequence"),
              std::string::npos)
        << refusal(text, {span(0, 4, {})});
    EXPECT_NE(refusal(text, {span(4, 6, {})}).find("spans[0] begins at byte 4, inside a UTF-8 sequence"),
              std::string::npos);
    EXPECT_NE(refusal(text, {span(0, 3, {}), span(2, 6, {})}).find("spans[1] begins at byte 2, inside the span"),
              std::string::npos);
    EXPECT_NE(refusal(text, {span(0, 40, {})}).find("spans[0] ends at byte 40, past the text's 13 bytes"),
              std::string::npos);
    EXPECT_NE(refusal(text, {span(5, 2, {})}).find("spans[0] ends (byte 2) before it begins"), std::string::npos);
    TextStyle nan_size;
    nan_size.size = NAN;
    EXPECT_NE(refusal(text, {span(0, 1, {}), span(1, 2, nan_size)}).find("spans[1].style.size is NaN"),
              std::string::npos);
    const Font* null_font[] = {nullptr};
    TextStyle null_list;
    null_list.fonts = null_font;
    EXPECT_NE(refusal(text, {span(0, 1, null_list)}).find("spans[0].style.fonts[0] is null"), std::string::npos);
    const FontFeature bad_tag[] = {{{'l', 'i', 'g', '\n'}, 0}};
    TextStyle bad_feature;
    bad_feature.features = bad_tag;
    EXPECT_NE(refusal(text, {span(0, 1, bad_feature)}).find("spans[0].style.features[0]"), std::string::npos);
    TextStyle far;
    far.letter_spacing = 100.0f;
    EXPECT_NE(refusal(text, {span(0, 1, far)}).find("spans[0].style.letter_spacing is 100"), std::string::npos);
    // An empty span is ignored; so is text outside every span.
    EXPECT_EQ(refusal(text, {span(3, 3, red()), span(5, 13, {})}), "accepted");
    LayoutOptions bad_scale;
    bad_scale.scale = 0.0f;
    EXPECT_NE(refusal(text, {}, bad_scale).find("options.scale is 0"), std::string::npos);
    const float bad_stops[] = {10.0f, 5.0f};
    LayoutOptions unordered;
    unordered.tab_stops = bad_stops;
    EXPECT_NE(refusal(text, {}, unordered).find("options.tab_stops[1] is 5"), std::string::npos);
}

}  // namespace
}  // namespace crisp
