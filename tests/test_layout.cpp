#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace crisp {
namespace {

const std::string kDejaVuPath = std::string(CRISP_SOURCE_DIR) + "/fonts/DejaVuSans.ttf";
const std::string kInterPath = std::string(CRISP_SOURCE_DIR) + "/fonts/Inter-Regular.otf";
const std::string kNotoCjkPath = "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc";

constexpr FontId kDejaVuId = 7;
constexpr FontId kInterId = 11;
constexpr FontId kCjkId = 13;

std::unique_ptr<Font> bake(const std::string& path, FontId id, std::vector<uint32_t> codepoints) {
    return test::bake_font_or_fail(path, id, std::move(codepoints));
}

std::vector<uint32_t> range(uint32_t first, uint32_t last) {
    std::vector<uint32_t> out;
    for (uint32_t cp = first; cp <= last; ++cp) out.push_back(cp);
    return out;
}

class Layout : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dejavu_ = bake(kDejaVuPath, kDejaVuId, {}).release();
        inter_ = bake(kInterPath, kInterId, range(0x20, 0x7E)).release();       // Latin only: no Hebrew, no CJK
        cjk_ = bake(kNotoCjkPath, kCjkId, {0x6F22, 0x5B57, 0x3002}).release();  // 漢字。
    }
    static void TearDownTestSuite() {
        delete dejavu_;
        delete inter_;
        delete cjk_;
    }
    void SetUp() override {
        ASSERT_NE(dejavu_, nullptr);
        ASSERT_NE(inter_, nullptr);
        ASSERT_NE(cjk_, nullptr);
    }

    static TextLayout lay(std::vector<const Font*> fonts, std::string_view text, const TextStyle& style = {},
                          const LayoutOptions& options = {}) {
        return test::layout_or_fail(fonts, text, style, options);
    }
    static TextLayout lay(std::string_view text, const TextStyle& style = {}, const LayoutOptions& options = {}) {
        return lay({dejavu_}, text, style, options);
    }

    // Pen advance of a glyph without kerning, in pixels.
    static float advance(const Font& font, uint32_t glyph, float size) {
        return font.glyph_record(glyph)->advance * size;
    }

    static inline Font* dejavu_ = nullptr;
    static inline Font* inter_ = nullptr;
    static inline Font* cjk_ = nullptr;
};

std::vector<uint32_t> glyph_ids(const TextLayout& layout) {
    std::vector<uint32_t> ids;
    for (const GlyphInstance& glyph : layout.glyphs) ids.push_back(glyph.key.glyph);
    return ids;
}

const GlyphInstance* at_cluster(const TextLayout& layout, uint32_t cluster) {
    for (const GlyphInstance& glyph : layout.glyphs)
        if (glyph.cluster == cluster) return &glyph;
    return nullptr;
}

TEST_F(Layout, FontReportsMetricsAndCoverage) {
    EXPECT_EQ(dejavu_->id(), kDejaVuId);
    EXPECT_EQ(dejavu_->units_per_em(), 2048u);
    EXPECT_GT(dejavu_->ascender(), 0.5f);
    EXPECT_LT(dejavu_->descender(), 0.0f);
    EXPECT_FLOAT_EQ(dejavu_->line_height(), dejavu_->ascender() - dejavu_->descender() + dejavu_->line_gap());
    EXPECT_TRUE(dejavu_->has_glyph_for('A'));
    EXPECT_TRUE(dejavu_->has_glyph_for(0x05D0));  // Hebrew alef
    EXPECT_FALSE(inter_->has_glyph_for(0x05D0));
    EXPECT_FALSE(dejavu_->has_glyph_for(0x6F22));  // no CJK
    EXPECT_TRUE(cjk_->has_glyph_for(0x6F22));
    EXPECT_FALSE(cjk_->has_glyph_for('A'));  // in the font's cmap, but not in this subset
    EXPECT_NE(cjk_->nominal_glyph(0x5B57), 0u);
    EXPECT_EQ(cjk_->nominal_glyph('A'), 0u);
    EXPECT_FALSE(dejavu_->has_glyph_for(0xD800));
    EXPECT_FALSE(dejavu_->has_glyph_for(0x110000));
    EXPECT_EQ(dejavu_->glyph_record(1u << 30), nullptr);
}

TEST_F(Layout, FontRejectsBadAssets) {
    Result<BakeResult> baked = bake_font_file(kDejaVuPath, BakeOptions{});
    ASSERT_TRUE(baked);
    FontAsset truncated = baked->asset;
    truncated.font_bytes.resize(100);
    Result<Font> font = Font::create(std::move(truncated), 1);
    ASSERT_FALSE(font);
    EXPECT_EQ(font.error().code, ErrorCode::asset_invalid);

    FontAsset wrong_glyphs = baked->asset;
    wrong_glyphs.glyphs.pop_back();
    font = Font::create(std::move(wrong_glyphs), 1);
    ASSERT_FALSE(font);
    EXPECT_EQ(font.error().code, ErrorCode::asset_invalid);
}

TEST_F(Layout, Ligatures) {
    const TextLayout fi = lay("fi");
    EXPECT_EQ(fi.shaped_glyphs, 1u);
    ASSERT_EQ(fi.glyphs.size(), 1u);
    EXPECT_NE(fi.glyphs[0].key.glyph, dejavu_->nominal_glyph('f'));
    const TextLayout ffi = lay("ffi");
    EXPECT_LT(ffi.shaped_glyphs, 3u);
    // Separated by a zero width non-joiner, no ligature.
    EXPECT_EQ(lay("f\u200Ci").glyphs.size(), 2u);
}

TEST_F(Layout, Kerning) {
    const float size = 100.0f;
    const TextLayout av = lay("AV", {.size = size});
    ASSERT_EQ(av.glyphs.size(), 2u);
    const float unkerned = advance(*dejavu_, av.glyphs[0].key.glyph, size);
    const float kerned = av.glyphs[1].pen_x - av.glyphs[0].pen_x;
    EXPECT_LT(kerned, unkerned - 1.0f);
    // "AH" has no kerning pair.
    const TextLayout ah = lay("AH", {.size = size});
    EXPECT_NEAR(ah.glyphs[1].pen_x - ah.glyphs[0].pen_x, unkerned, 1e-3f);
}

TEST_F(Layout, ArabicJoinsAndRunsRightToLeft) {
    const std::string text = "\u0643\u062A\u0628";  // كتب: kaf, teh, beh
    const TextLayout layout = lay(text);
    ASSERT_EQ(layout.glyphs.size(), 3u);
    ASSERT_EQ(layout.lines.size(), 1u);
    EXPECT_TRUE(layout.lines[0].rtl);
    // Initial, medial and final forms, none of them the isolated form the cmap maps to.
    const uint32_t isolated[] = {dejavu_->nominal_glyph(0x0643), dejavu_->nominal_glyph(0x062A),
                                 dejavu_->nominal_glyph(0x0628)};
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_NE(isolated[i], 0u);
        EXPECT_NE(layout.glyphs[i].key.glyph, isolated[i]) << i;
        EXPECT_EQ(layout.glyphs[i].cluster, 2 * i);
        EXPECT_EQ(layout.glyphs[i].paint_order, i);
    }
    for (size_t i = 1; i < 3; ++i) EXPECT_LT(layout.glyphs[i].pen_x, layout.glyphs[i - 1].pen_x) << i;
    // Lam + alef is one ligature glyph.
    EXPECT_EQ(lay("\u0644\u0627").shaped_glyphs, 1u);
    // The same letters separated by spaces stay isolated.
    const TextLayout apart = lay("\u0643 \u062A \u0628");
    ASSERT_EQ(apart.glyphs.size(), 3u);
    for (size_t i = 0; i < 3; ++i) EXPECT_EQ(apart.glyphs[i].key.glyph, isolated[i]);
}

TEST_F(Layout, HebrewRunsRightToLeft) {
    const TextLayout layout = lay("\u05E9\u05DC\u05D5\u05DD", {.size = 20});  // שלום
    ASSERT_EQ(layout.glyphs.size(), 4u);
    EXPECT_TRUE(layout.lines[0].rtl);
    EXPECT_EQ(layout.glyphs[0].key.glyph, dejavu_->nominal_glyph(0x05E9));
    for (size_t i = 1; i < 4; ++i) EXPECT_LT(layout.glyphs[i].pen_x, layout.glyphs[i - 1].pen_x);
    // The visually last glyph (logical first) ends at the line's right edge.
    EXPECT_NEAR(layout.glyphs[0].pen_x + advance(*dejavu_, layout.glyphs[0].key.glyph, 20),
                layout.lines[0].x + layout.lines[0].width, 1e-3);
    // Forcing the direction changes nothing for a single strong run.
    const TextLayout forced = lay("\u05E9\u05DC\u05D5\u05DD", {.size = 20}, {.direction = Direction::ltr});
    EXPECT_FALSE(forced.lines[0].rtl);
    EXPECT_EQ(glyph_ids(forced), glyph_ids(layout));
}

TEST_F(Layout, MixedDirectionsReorderPerLine) {
    // Bytes: a0 b1 c2 ' '3 alef4 bet6 gimel8 ' '10 d11 e12 f13
    const TextLayout ltr = lay("abc \u05D0\u05D1\u05D2 def");
    ASSERT_FALSE(ltr.lines[0].rtl);
    auto x = [&](const TextLayout& layout, uint32_t cluster) {
        const GlyphInstance* glyph = at_cluster(layout, cluster);
        EXPECT_NE(glyph, nullptr) << cluster;
        return glyph ? glyph->pen_x : std::numeric_limits<float>::quiet_NaN();
    };
    const uint32_t visual_ltr[] = {0, 1, 2, 8, 6, 4, 11, 12, 13};
    for (size_t i = 1; i < std::size(visual_ltr); ++i)
        EXPECT_LT(x(ltr, visual_ltr[i - 1]), x(ltr, visual_ltr[i])) << visual_ltr[i];
    for (size_t i = 0; i < ltr.glyphs.size(); ++i) EXPECT_EQ(ltr.glyphs[i].paint_order, i);  // logical order

    // Bytes: alef0 bet2 gimel4 ' '6 a7 b8 c9: a right-to-left paragraph with a left-to-right word.
    const TextLayout rtl = lay("\u05D0\u05D1\u05D2 abc");
    ASSERT_TRUE(rtl.lines[0].rtl);
    const uint32_t visual_rtl[] = {7, 8, 9, 4, 2, 0};
    for (size_t i = 1; i < std::size(visual_rtl); ++i)
        EXPECT_LT(x(rtl, visual_rtl[i - 1]), x(rtl, visual_rtl[i])) << visual_rtl[i];

    // Numbers inside right-to-left text (level 2 inside level 1): "123" reads left to right,
    // left of the Hebrew. Bytes: alef0 bet2 ' '4 '1'5 '2'6 '3'7
    const TextLayout numbers = lay("\u05D0\u05D1 123");
    const uint32_t visual_numbers[] = {5, 6, 7, 2, 0};
    for (size_t i = 1; i < std::size(visual_numbers); ++i)
        EXPECT_LT(x(numbers, visual_numbers[i - 1]), x(numbers, visual_numbers[i])) << visual_numbers[i];
}

TEST_F(Layout, CombiningMarksSitOnTheirBase) {
    const float size = 64.0f;
    // x has no precomposed form with an acute: the mark is positioned by GPOS.
    const TextLayout layout = lay("x\u0301", {.size = size});
    ASSERT_EQ(layout.glyphs.size(), 2u);
    const GlyphInstance& base = layout.glyphs[0];
    const GlyphInstance& mark = layout.glyphs[1];
    EXPECT_EQ(mark.cluster, 0u);  // one cluster
    EXPECT_EQ(mark.key.glyph, dejavu_->nominal_glyph(0x0301));
    const float base_advance = advance(*dejavu_, base.key.glyph, size);
    // The mark's outline lies over the base's advance, and above it.
    const GlyphRecord& mark_record = *dejavu_->glyph_record(mark.key.glyph);
    const float mark_left = mark.pen_x + mark_record.bbox_min_x * size;
    const float mark_right = mark.pen_x + mark_record.bbox_max_x * size;
    EXPECT_GT(mark_left, base.pen_x);
    EXPECT_LT(mark_right, base.pen_x + base_advance);
    EXPECT_LE(mark.y + static_cast<int32_t>(mark.height), base.y + 2);  // rects overlap only in padding
    EXPECT_EQ(layout.lines[0].width, base_advance);                     // the mark adds no advance

    // e + U+0301 composes into é, which the font has.
    const TextLayout composed = lay("e\u0301");
    ASSERT_EQ(composed.glyphs.size(), 1u);
    EXPECT_EQ(composed.glyphs[0].key.glyph, dejavu_->nominal_glyph(0xE9));
}

TEST_F(Layout, FallsBackAcrossFonts) {
    // Bytes: H0 i1 ' '2 shin3 lamed5 ' '7 han8 zi11
    const TextLayout layout = lay({inter_, dejavu_, cjk_}, "Hi \u05E9\u05DC \u6F22\u5B57");
    EXPECT_EQ(layout.missing_glyphs, 0u);
    const std::map<uint32_t, FontId> expected = {{0, kInterId},  {1, kInterId}, {3, kDejaVuId},
                                                 {5, kDejaVuId}, {8, kCjkId},   {11, kCjkId}};
    for (const auto& [cluster, font] : expected) {
        const GlyphInstance* glyph = at_cluster(layout, cluster);
        ASSERT_NE(glyph, nullptr) << cluster;
        EXPECT_EQ(glyph->key.font, font) << cluster;
        EXPECT_NE(glyph->key.glyph, 0u) << cluster;
    }
    // A Hebrew mark stays with its base's font.
    const TextLayout marked = lay({inter_, dejavu_}, "\u05E9\u05B8");
    for (const GlyphInstance& glyph : marked.glyphs) EXPECT_EQ(glyph.key.font, kDejaVuId);
    // Line metrics come from the first font.
    EXPECT_NEAR(layout.line_height, inter_->line_height() * 16.0f, 1e-3f);
}

TEST_F(Layout, NotdefOnlyWhenNoFontHasTheCharacter) {
    const TextLayout hebrew_inter = lay({inter_}, "\u05D0");
    EXPECT_EQ(hebrew_inter.missing_glyphs, 1u);
    ASSERT_EQ(hebrew_inter.glyphs.size(), 1u);
    EXPECT_EQ(hebrew_inter.glyphs[0].key.glyph, 0u);
    EXPECT_EQ(hebrew_inter.glyphs[0].key.font, kInterId);

    EXPECT_EQ(lay({inter_, dejavu_}, "\u05D0").missing_glyphs, 0u);

    // U+E000 (private use): nobody has it. .notdef of the FIRST font, counted.
    const TextLayout pua = lay({inter_, dejavu_}, "a\uE000b\uE001");
    EXPECT_EQ(pua.missing_glyphs, 2u);
    const GlyphInstance* notdef = at_cluster(pua, 1);
    ASSERT_NE(notdef, nullptr);
    EXPECT_EQ(notdef->key.glyph, 0u);
    EXPECT_EQ(notdef->key.font, kInterId);
    EXPECT_GT(notdef->width, 0u);  // .notdef has an outline: it is drawn

    // A CJK character missing from the subset is missing, not an unbaked glyph.
    EXPECT_EQ(lay({cjk_}, "\u4E00").missing_glyphs, 1u);
}

TEST_F(Layout, InvalidUtf8BecomesReplacementCharacter) {
    const uint32_t replacement = dejavu_->nominal_glyph(0xFFFD);
    ASSERT_NE(replacement, 0u);
    const TextLayout layout =
        lay("a\xFF"
            "b\xE2\x82"
            "c");
    ASSERT_EQ(layout.glyphs.size(), 5u);
    EXPECT_EQ(layout.missing_glyphs, 0u);
    const uint32_t clusters[] = {0, 1, 2, 3, 5};
    for (size_t i = 0; i < 5; ++i) EXPECT_EQ(layout.glyphs[i].cluster, clusters[i]);
    EXPECT_EQ(layout.glyphs[1].key.glyph, replacement);
    EXPECT_EQ(layout.glyphs[3].key.glyph, replacement);  // a truncated sequence: one U+FFFD
    EXPECT_EQ(layout.glyphs[4].key.glyph, dejavu_->nominal_glyph('c'));
}

TEST_F(Layout, EmptyTextIsAnEmptyLayout) {
    const TextLayout layout = lay("", {}, {.first_paint_order = 5});
    EXPECT_TRUE(layout.glyphs.empty());
    EXPECT_TRUE(layout.lines.empty());
    EXPECT_EQ(layout.width, 0.0f);
    EXPECT_EQ(layout.height, 0.0f);
    EXPECT_EQ(layout.next_paint_order, 5u);
}

TEST_F(Layout, RefusesBadArguments) {
    const Font* fonts[] = {dejavu_};
    auto refused = [&](const TextStyle& style, const LayoutOptions& options, std::span<const Font* const> list,
                       const char* what) {
        Result<TextLayout> layout = layout_text(list, "abc", style, options);
        if (layout) {
            ADD_FAILURE() << what << " was accepted";
            return;
        }
        EXPECT_EQ(layout.error().code, ErrorCode::invalid_argument) << what;
        EXPECT_FALSE(layout.error().message.empty());
    };
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (float size : {0.0f, -1.0f, nan, inf, -inf, 4097.0f, -1e-45f}) {
        refused({.size = size}, {}, fonts, "size");
        refused({.size = 16, .size_y = size == 0.0f ? -1.0f : size}, {}, fonts, "size_y");
    }
    Result<TextLayout> nan_size = layout_text(fonts, "abc", {.size = nan}, {});
    ASSERT_FALSE(nan_size);
    EXPECT_NE(nan_size.error().message.find("size"), std::string::npos) << nan_size.error().message;
    EXPECT_TRUE(layout_text(fonts, "abc", {.size = 4096}, {}));
    EXPECT_TRUE(layout_text(fonts, "", {.size = 4096}, {}));
    // The value as it is (the smallest subnormal float), not rounded to 0 by a fixed six decimals.
    Result<TextLayout> negative = layout_text(fonts, "abc", {.size = -1e-45f}, {});
    ASSERT_FALSE(negative);
    EXPECT_NE(negative.error().message.find("style.size is -1e-45;"), std::string::npos) << negative.error().message;
    // (0, 4096] as documented: below the 1/256 px of glyph keys a size is laid out at 1/256 px.
    for (float tiny : {0.001f, 1e-45f}) {
        Result<TextLayout> small = layout_text(fonts, "abc", {.size = tiny}, {});
        ASSERT_TRUE(small) << tiny << ": " << small.error().message;
        ASSERT_EQ(small->glyphs.size(), 3u);
        for (const GlyphInstance& glyph : small->glyphs) EXPECT_EQ(glyph.key.size_x, 1u) << tiny;
    }

    refused({}, {.origin_x = nan}, fonts, "origin_x");
    refused({}, {.origin_y = inf}, fonts, "origin_y");
    refused({}, {.wrap_width = inf}, fonts, "wrap_width inf");
    refused({}, {.wrap_width = -5}, fonts, "wrap_width negative");
    refused({}, {.subpixel_steps = 0}, fonts, "steps 0");
    refused({}, {.subpixel_steps = 3}, fonts, "steps 3");
    refused({}, {.subpixel_steps = 512}, fonts, "steps 512");
    refused({.color = {nan, 0, 0, 1}}, {}, fonts, "color");
    refused({.depth = inf}, {}, fonts, "depth");
    refused({}, {}, {}, "no fonts");
    const Font* null_font[] = {dejavu_, nullptr};
    refused({}, {}, null_font, "null font");
    // Bad arguments are refused even for empty text.
    EXPECT_FALSE(layout_text(fonts, "", {.size = 0}, {}));
}

TEST_F(Layout, NewlinesStartLinesOneLineHeightApart) {
    const float size = 20.0f;
    const LayoutOptions options{.origin_x = 5.0f, .origin_y = 100.0f};
    // a0 \n1 b2 \r3 \n4 c5 \r6 d7 \n8 : "\r\n" is one break; a lone "\r" is a break; the final
    // "\n" ends with an empty line.
    const TextLayout layout = lay("a\nb\r\nc\rd\n", {.size = size}, options);
    ASSERT_EQ(layout.lines.size(), 5u);
    const float line_height = (dejavu_->ascender() - dejavu_->descender() + dejavu_->line_gap()) * size;
    EXPECT_NEAR(layout.line_height, line_height, 1e-3f);
    EXPECT_NEAR(layout.height, 5 * line_height, 1e-2f);
    ASSERT_EQ(layout.glyphs.size(), 4u);
    for (uint32_t i = 0; i < 4; ++i) {
        EXPECT_EQ(layout.glyphs[i].line, i);
        EXPECT_FLOAT_EQ(layout.glyphs[i].pen_x, 5.0f);
        EXPECT_NEAR(layout.glyphs[i].pen_y, 100.0f + static_cast<float>(i) * line_height, 1e-3f);
        EXPECT_NEAR(layout.lines[i].baseline_y, 100.0f + static_cast<float>(i) * line_height, 1e-3f);
    }
    EXPECT_EQ(layout.lines[1].text_begin, 2u);
    EXPECT_EQ(layout.lines[1].text_end, 3u);
    EXPECT_EQ(layout.lines[4].glyph_count, 0u);
    EXPECT_EQ(layout.glyphs[2].cluster, 5u);
}

const char* const kParagraph =
    "The quick brown fox jumps over the lazy dog. Pack my box with five dozen liquor jugs. "
    "How vexingly quick daft zebras jump! Sphinx of black quartz, judge my vow.";

TEST_F(Layout, WrapsAtWordsWithinTheWidth) {
    const float wrap = 200.0f;
    const TextLayout layout = lay(kParagraph, {.size = 16}, {.origin_x = 10.0f, .wrap_width = wrap});
    ASSERT_GT(layout.lines.size(), 4u);
    const std::string text = kParagraph;
    for (const TextLine& line : layout.lines) {
        EXPECT_LE(line.width, wrap) << text.substr(line.text_begin, line.text_end - line.text_begin);
        // Lines start at words and end after spaces.
        EXPECT_NE(text[line.text_begin], ' ');
        if (line.text_end < text.size()) {
            EXPECT_EQ(text[line.text_end - 1], ' ');
        }
        EXPECT_FLOAT_EQ(line.x, 10.0f);
    }
    // Greedy: the next line's first word would not have fitted.
    const TextLayout unwrapped = lay(kParagraph, {.size = 16});
    for (size_t i = 0; i + 1 < layout.lines.size(); ++i) {
        const TextLine& next = layout.lines[i + 1];
        const size_t word_end = text.find(' ', next.text_begin);
        const std::string with_word = text.substr(layout.lines[i].text_begin, word_end - layout.lines[i].text_begin);
        EXPECT_GT(lay(with_word, {.size = 16}).lines[0].width, wrap) << with_word;
    }
    EXPECT_EQ(layout.glyphs.size(), unwrapped.glyphs.size());
    for (const GlyphInstance& glyph : layout.glyphs) {
        const TextLine& line = layout.lines[glyph.line];
        EXPECT_GE(glyph.pen_x, line.x - 1e-3f);
        EXPECT_LE(glyph.pen_x, line.x + line.width + 1e-3f);
    }
}

TEST_F(Layout, LongWordsOverflowOrBreak) {
    const std::string text = "a supercalifragilisticexpialidocious word";
    const TextLayout overflow = lay(text, {.size = 16}, {.wrap_width = 60});
    ASSERT_EQ(overflow.lines.size(), 3u);
    EXPECT_GT(overflow.lines[1].width, 60.0f);  // alone on its line, overflowing
    EXPECT_EQ(overflow.lines[1].text_begin, 2u);

    const TextLayout broken = lay(text, {.size = 16}, {.wrap_width = 60, .break_long_words = true});
    EXPECT_GT(broken.lines.size(), 4u);
    for (const TextLine& line : broken.lines) EXPECT_LE(line.width, 60.0f);
    EXPECT_EQ(broken.glyphs.size(), overflow.glyphs.size());
}

TEST_F(Layout, LinesCutAtUnsafeBreaksAreReshaped) {
    // A kerned pair split over two lines: A's line must not keep the kerning it had against V.
    const float size = 100.0f;
    const TextLayout whole = lay("AV", {.size = size});
    const float unkerned = advance(*dejavu_, whole.glyphs[0].key.glyph, size);
    const float kerned = whole.glyphs[1].pen_x - whole.glyphs[0].pen_x;
    ASSERT_LT(kerned, unkerned - 1.0f);
    const TextLayout split = lay("AV", {.size = size}, {.wrap_width = unkerned + 1.0f, .break_long_words = true});
    ASSERT_EQ(split.lines.size(), 2u);
    EXPECT_FLOAT_EQ(split.lines[0].width, unkerned);
    EXPECT_EQ(split.glyphs[0].key.glyph, whole.glyphs[0].key.glyph);
    EXPECT_EQ(split.glyphs[1].key.glyph, whole.glyphs[1].key.glyph);
}

TEST_F(Layout, WrapsCjkBetweenIdeographs) {
    const std::string text = "\u6F22\u5B57\u6F22\u5B57\u6F22\u5B57\u3002\u6F22\u5B57";
    const TextLayout layout = lay({cjk_}, text, {.size = 20}, {.wrap_width = 45});
    ASSERT_GT(layout.lines.size(), 3u);
    for (const TextLine& line : layout.lines) {
        EXPECT_LE(line.width, 45.0f);
        EXPECT_NE(text.substr(line.text_begin, 3), "\u3002");  // 。 never starts a line
    }
}

TEST_F(Layout, AlignsLines) {
    const float wrap = 250.0f, origin = 30.0f;
    for (Align align : {Align::left, Align::center, Align::right}) {
        const TextLayout layout =
            lay(kParagraph, {.size = 16}, {.origin_x = origin, .wrap_width = wrap, .align = align});
        ASSERT_GT(layout.lines.size(), 2u);
        for (const TextLine& line : layout.lines) {
            const float end = line.x + line.width;
            if (align == Align::left) {
                EXPECT_FLOAT_EQ(line.x, origin);
            } else if (align == Align::right) {
                EXPECT_NEAR(end, origin + wrap, 1e-3f);
            } else {
                EXPECT_NEAR(line.x - origin, origin + wrap - end, 1e-3f);
            }
        }
        // The last glyph of every line ends where the line ends.
        for (const TextLine& line : layout.lines) {
            const GlyphInstance& last = layout.glyphs[line.glyph_begin + line.glyph_count - 1];
            EXPECT_NEAR(last.pen_x + advance(*dejavu_, last.key.glyph, 16), line.x + line.width, 1e-2f);
        }
    }
    // Without a wrap width, lines align within the widest.
    const TextLayout right = lay("wide line here\nnarrow", {.size = 16}, {.align = Align::right});
    ASSERT_EQ(right.lines.size(), 2u);
    EXPECT_NEAR(right.lines[0].x + right.lines[0].width, right.lines[1].x + right.lines[1].width, 1e-3f);
    EXPECT_FLOAT_EQ(right.lines[0].x, 0.0f);
    EXPECT_GT(right.lines[1].x, 10.0f);
    // start and end follow the paragraph's direction.
    const TextLayout start =
        lay("abc\n\u05D0\u05D1\u05D2 \u05D3", {.size = 16}, {.wrap_width = 300, .align = Align::start});
    EXPECT_FLOAT_EQ(start.lines[0].x, 0.0f);
    EXPECT_NEAR(start.lines[1].x + start.lines[1].width, 300.0f, 1e-3f);
}

TEST_F(Layout, RightToLeftParagraphsWrapFromTheRight) {
    std::string text;
    for (int i = 0; i < 12; ++i) text += "\u05E9\u05DC\u05D5\u05DD ";
    const TextLayout layout = lay(text, {.size = 16}, {.wrap_width = 120, .align = Align::start});
    ASSERT_GT(layout.lines.size(), 2u);
    for (const TextLine& line : layout.lines) {
        EXPECT_TRUE(line.rtl);
        EXPECT_LE(line.width, 120.0f);
        EXPECT_NEAR(line.x + line.width, 120.0f, 1e-3f);
        // The logically first glyph is the rightmost.
        const GlyphInstance& first = layout.glyphs[line.glyph_begin];
        for (uint32_t i = 1; i < line.glyph_count; ++i)
            EXPECT_LT(layout.glyphs[line.glyph_begin + i].pen_x, first.pen_x);
    }
}

TEST_F(Layout, SnapsPensToWholePixels) {
    const TextLayout layout = lay(kParagraph, {.size = 13.3f},
                                  {.origin_x = 10.3f, .origin_y = 20.7f, .wrap_width = 300, .snap_to_pixels = true});
    ASSERT_FALSE(layout.glyphs.empty());
    for (const GlyphInstance& glyph : layout.glyphs) {
        EXPECT_EQ(glyph.key.subpixel_x, 0);
        EXPECT_EQ(glyph.key.subpixel_y, 0);
        EXPECT_EQ(glyph.pen_x, std::round(glyph.pen_x));
        EXPECT_EQ(glyph.pen_y, std::round(glyph.pen_y));
    }
    EXPECT_EQ(layout.line_height, std::round(layout.line_height));
    EXPECT_EQ(layout.lines[0].baseline_y, 21.0f);
    // Equal glyphs share one key wherever they are.
    std::map<uint32_t, GlyphKey> keys;
    for (const GlyphInstance& glyph : layout.glyphs) {
        auto [it, inserted] = keys.emplace(glyph.key.glyph, glyph.key);
        EXPECT_EQ(it->second, glyph.key);
    }
    // Monospaced pitch: every advance is a whole number of pixels, so equal glyphs are equally spaced.
    const TextLayout dots = lay("........", {.size = 13.3f}, {.origin_x = 0.4f, .snap_to_pixels = true});
    for (size_t i = 2; i < dots.glyphs.size(); ++i)
        EXPECT_EQ(dots.glyphs[i].pen_x - dots.glyphs[i - 1].pen_x, dots.glyphs[1].pen_x - dots.glyphs[0].pen_x);
}

TEST_F(Layout, QuantizesSubpixelOffsets) {
    const TextLayout layout =
        lay(kParagraph, {.size = 13.3f}, {.origin_x = 0.37f, .origin_y = 10.2f, .subpixel_steps = 4});
    std::set<int> seen;
    for (const GlyphInstance& glyph : layout.glyphs) {
        EXPECT_EQ(glyph.key.subpixel_x % 64, 0);
        EXPECT_EQ(glyph.key.subpixel_y % 64, 0);
        seen.insert(glyph.key.subpixel_x);
        // The offset is round(frac * 4) / 4 of the exact pen position, carried into the pixel.
        const double pen = static_cast<double>(glyph.pen_x);
        const double quantized = std::floor(pen) + std::round((pen - std::floor(pen)) * 4) / 4;
        const GlyphRect rect = glyph_rect(*dejavu_->glyph_record(glyph.key.glyph), glyph.key);
        EXPECT_DOUBLE_EQ(
            static_cast<double>(glyph.x - rect.x) + static_cast<double>(subpixel_to_float(glyph.key.subpixel_x)),
            quantized);
    }
    EXPECT_EQ(seen.size(), 4u);  // a paragraph visits every offset

    // Carry: 10.9 with 4 steps rounds to 11 + 0/4.
    const TextLayout carry = lay("l", {.size = 16}, {.origin_x = 10.9f, .origin_y = 5.0f, .subpixel_steps = 4});
    ASSERT_EQ(carry.glyphs.size(), 1u);
    EXPECT_EQ(carry.glyphs[0].key.subpixel_x, 0);
    const GlyphRect rect = glyph_rect(*dejavu_->glyph_record(carry.glyphs[0].key.glyph), carry.glyphs[0].key);
    EXPECT_EQ(carry.glyphs[0].x - rect.x, 11);
    // 10.6 rounds to 10 + 2/4 = 128; 256 steps keep 1/256 px.
    EXPECT_EQ(lay("l", {.size = 16}, {.origin_x = 10.6f, .subpixel_steps = 4}).glyphs[0].key.subpixel_x, 128);
    EXPECT_EQ(lay("l", {.size = 16}, {.origin_x = 10.25f}).glyphs[0].key.subpixel_x, 64);
    EXPECT_EQ(lay("l", {.size = 16}, {.origin_x = 10.999f}).glyphs[0].key.subpixel_x, 0);  // carried
    EXPECT_EQ(lay("l", {.size = 16}, {.origin_x = 10.5f, .subpixel_steps = 1}).glyphs[0].key.subpixel_x, 0);
}

TEST_F(Layout, EqualGlyphsAtEqualOffsetsShareKeys) {
    const TextLayout layout =
        lay(kParagraph, {.size = 15.5f, .size_y = 17.25f}, {.origin_x = 0.3f, .subpixel_steps = 2});
    std::map<std::pair<uint32_t, uint8_t>, const GlyphInstance*> first;
    GlyphKeyHash hash;
    size_t repeats = 0;
    for (const GlyphInstance& glyph : layout.glyphs) {
        EXPECT_EQ(glyph.key.font, kDejaVuId);
        EXPECT_EQ(glyph.key.size_x, 15u * 256 + 128);
        EXPECT_EQ(glyph.key.size_y, 17u * 256 + 64);
        auto [it, inserted] = first.emplace(std::pair(glyph.key.glyph, glyph.key.subpixel_x), &glyph);
        if (inserted) continue;
        ++repeats;
        EXPECT_EQ(it->second->key, glyph.key);
        EXPECT_EQ(hash(it->second->key), hash(glyph.key));
        EXPECT_EQ(it->second->width, glyph.width);
        EXPECT_EQ(it->second->height, glyph.height);
    }
    EXPECT_GT(repeats, 50u);
}

TEST_F(Layout, InstancesCarryStyleAndPaintOrder) {
    const TextStyle style{.size = 16, .color = {0.5f, 1.0f, 0.0f, 0.25f}, .depth = 0.75f};
    const TextLayout layout = lay("a b c", style, {.first_paint_order = 100});
    ASSERT_EQ(layout.glyphs.size(), 3u);  // the spaces are blank: counted, not emitted
    EXPECT_EQ(layout.blank_glyphs, 2u);
    EXPECT_EQ(layout.shaped_glyphs, 5u);
    for (size_t i = 0; i < 3; ++i) {
        const GlyphInstance& glyph = layout.glyphs[i];
        EXPECT_EQ(glyph.paint_order, 100 + i);
        EXPECT_NEAR(glyph.color[0], 0.21404114f, 1e-6f);  // exact sRGB transfer function
        EXPECT_EQ(glyph.color[1], 1.0f);
        EXPECT_EQ(glyph.color[2], 0.0f);
        EXPECT_EQ(glyph.color[3], 0.25f);  // straight alpha, not premultiplied
        EXPECT_EQ(glyph.depth, 0.75f);
        EXPECT_GT(glyph.width, 0u);
    }
    EXPECT_EQ(layout.next_paint_order, 103u);
    EXPECT_NEAR(srgb_to_linear(0.04f), 0.04f / 12.92f, 1e-7f);
    const TextLayout kept = lay("a b", style, {.keep_blank_glyphs = true});
    ASSERT_EQ(kept.glyphs.size(), 3u);
    EXPECT_EQ(kept.glyphs[1].width, 0u);
    EXPECT_EQ(kept.glyphs[1].cluster, 1u);
}

TEST_F(Layout, TabsAdvanceToStops) {
    const float space = advance(*dejavu_, dejavu_->nominal_glyph(' '), 16);
    const TextLayout layout = lay("a\tb\tc", {.size = 16}, {.tab_spaces = 4});
    ASSERT_EQ(layout.glyphs.size(), 3u);
    EXPECT_NEAR(layout.glyphs[1].pen_x, 4 * space, 1e-3f);
    EXPECT_NEAR(layout.glyphs[2].pen_x, 8 * space, 1e-3f);
    EXPECT_EQ(layout.missing_glyphs, 0u);
    const TextLayout spaces = lay("a\tb", {.size = 16}, {.tab_spaces = 0});
    EXPECT_NEAR(spaces.glyphs[1].pen_x - spaces.glyphs[0].pen_x,
                advance(*dejavu_, spaces.glyphs[0].key.glyph, 16) + space, 1e-3f);
}

// The clusters of a layout tile each line's text and its width: in logical order, without gaps,
// side by side on screen.
void expect_clusters_tile_lines(const TextLayout& layout) {
    size_t c = 0;
    for (uint32_t i = 0; i < layout.lines.size(); ++i) {
        const TextLine& line = layout.lines[i];
        uint32_t next = line.text_begin;
        float left = std::numeric_limits<float>::infinity(), right = -left, content = 0.0f;
        for (; c < layout.clusters.size() && layout.clusters[c].line == i; ++c) {
            const TextCluster& cluster = layout.clusters[c];
            EXPECT_EQ(cluster.text_begin, next) << "line " << i;
            EXPECT_LT(cluster.text_begin, cluster.text_end);
            next = cluster.text_end;
            left = std::min(left, cluster.x);
            right = std::max(right, cluster.x + cluster.advance);
            content += cluster.advance;
        }
        EXPECT_EQ(next, line.text_end) << "line " << i;
        if (line.text_begin != line.text_end) {
            EXPECT_NEAR(right - left, content, 1e-3f) << "line " << i;
        }
    }
    EXPECT_EQ(c, layout.clusters.size());
}

TEST_F(Layout, ClustersCoverTheTextInLogicalOrder) {
    // Bytes: a0 b1 c2 ' '3 alef4 bet6 gimel8 ' '10 d11 e12 f13
    const TextLayout mixed = lay("abc \u05D0\u05D1\u05D2 def", {.size = 20});
    ASSERT_EQ(mixed.clusters.size(), 11u);
    expect_clusters_tile_lines(mixed);
    for (const TextCluster& cluster : mixed.clusters) {
        // Spaces are clusters though their glyphs are dropped; Hebrew is odd, the rest even.
        const bool hebrew = cluster.text_begin >= 4 && cluster.text_begin < 10;
        EXPECT_EQ(cluster.level & 1, hebrew ? 1 : 0) << cluster.text_begin;
        const GlyphInstance* glyph = at_cluster(mixed, cluster.text_begin);
        if (glyph != nullptr) {
            EXPECT_NEAR(glyph->pen_x, cluster.x, 1e-3f) << cluster.text_begin;
        }
    }
    // The Hebrew reads right to left: alef is the rightmost of the three.
    EXPECT_GT(mixed.clusters[4].x, mixed.clusters[5].x);
    EXPECT_GT(mixed.clusters[5].x, mixed.clusters[6].x);
    EXPECT_NEAR(mixed.clusters[6].x, mixed.clusters[3].x + mixed.clusters[3].advance, 1e-3f);

    // A ligature and a mark with its base are one cluster each; a tab reaches to its stop.
    const TextLayout ligature = lay("office e\u0301\tx", {.size = 20}, {.tab_spaces = 4});
    expect_clusters_tile_lines(ligature);
    EXPECT_LT(ligature.clusters.size(), 10u);
    const auto mark = std::find_if(ligature.clusters.begin(), ligature.clusters.end(),
                                   [](const TextCluster& cluster) { return cluster.text_begin == 7; });
    ASSERT_NE(mark, ligature.clusters.end());
    EXPECT_EQ(mark->text_end, 10u);
    const TextCluster& tab = *(mark + 1);
    const float space = advance(*dejavu_, dejavu_->nominal_glyph(' '), 20);
    const float stops = (tab.x + tab.advance - ligature.lines[0].x) / (4 * space);
    EXPECT_NEAR(stops, std::round(stops), 1e-4f);
    EXPECT_GT(tab.advance, 0.0f);

    // Wrapped lines, centred: the hanging space is the first line's last cluster, after alignment.
    const TextLayout wrapped = lay("abc def", {.size = 20}, {.wrap_width = 50, .align = Align::center});
    ASSERT_EQ(wrapped.lines.size(), 2u);
    expect_clusters_tile_lines(wrapped);
    ASSERT_EQ(wrapped.clusters.size(), 7u);
    EXPECT_EQ(wrapped.clusters[3].line, 0u);
    EXPECT_NEAR(wrapped.clusters[3].x, wrapped.lines[0].x + wrapped.lines[0].width, 1e-3f);
    EXPECT_NEAR(wrapped.clusters[4].x, wrapped.lines[1].x, 1e-3f);
    EXPECT_GT(wrapped.lines[0].x, 0.0f);

    // The line box: the font's ascender above the baseline and descender below it.
    EXPECT_NEAR(mixed.lines[0].ascent, dejavu_->ascender() * 20, 1e-4f);
    EXPECT_NEAR(mixed.lines[0].descent, -dejavu_->descender() * 20, 1e-4f);
    EXPECT_NEAR(mixed.y, mixed.lines[0].baseline_y - mixed.lines[0].ascent, 1e-4f);

    // Empty text has no clusters, and its box starts where its first line's would.
    const TextLayout empty = lay("", {.size = 20}, {.origin_x = 5, .origin_y = 30});
    EXPECT_TRUE(empty.clusters.empty());
    EXPECT_FLOAT_EQ(empty.x, 5.0f);
    EXPECT_NEAR(empty.y, 30.0f - dejavu_->ascender() * 20, 1e-4f);
}

TEST_F(Layout, ReusedLayouterGivesTheSameResult) {
    Layouter layouter;
    const Font* fonts[] = {inter_, dejavu_, cjk_};
    TextLayout a, b;
    ASSERT_TRUE(layouter.layout(fonts, "Hello \u05E9\u05DC\u05D5\u05DD \u6F22\u5B57", {}, {.wrap_width = 80}, a));
    ASSERT_TRUE(layouter.layout(fonts, kParagraph, {}, {}, b));
    ASSERT_TRUE(layouter.layout(fonts, "Hello \u05E9\u05DC\u05D5\u05DD \u6F22\u5B57", {}, {.wrap_width = 80}, b));
    ASSERT_EQ(a.glyphs.size(), b.glyphs.size());
    for (size_t i = 0; i < a.glyphs.size(); ++i) {
        EXPECT_EQ(a.glyphs[i].key, b.glyphs[i].key);
        EXPECT_EQ(a.glyphs[i].pen_x, b.glyphs[i].pen_x);
    }
    // A failed call empties the output.
    EXPECT_FALSE(layouter.layout(fonts, "x", {.size = -1}, {}, b));
    EXPECT_TRUE(b.glyphs.empty());
}

TEST_F(Layout, HostileTextNeverCrashes) {
    std::mt19937 random(1234);
    const Font* fonts[] = {inter_, dejavu_, cjk_};
    const std::string pieces[] = {"a",        " ",
                                  "\n",       "\r",
                                  "\t",       "\u05D0",
                                  "\u0627",   "\u0644",
                                  "\u0301",   "\u200D",
                                  "\u202E",   "\u2067",
                                  "\u2069",   "(",
                                  ")",        "1",
                                  "\u6F22",   "\xFF",
                                  "\xE2\x82", "\xF0\x9F\x98\x80",
                                  "-",        std::string(1, '\0'),
                                  "\uFFFD",   "\u200B",
                                  "\uFE0F",   "\u00AD",
                                  "\u3002",   "\u3000",
                                  "\u0085",   "\u2029",
                                  "\u05B8"};
    Layouter layouter;
    TextLayout layout;
    for (int round = 0; round < 300; ++round) {
        std::string text;
        const int length = static_cast<int>(random() % 64);
        for (int i = 0; i < length; ++i) {
            if (random() % 8 == 0)
                text += static_cast<char>(random() % 256);
            else
                text += pieces[random() % std::size(pieces)];
        }
        LayoutOptions options;
        options.wrap_width = static_cast<float>(random() % 4) * 20.0f;
        options.align = static_cast<Align>(random() % 5);
        options.direction = static_cast<Direction>(random() % 3);
        options.snap_to_pixels = random() % 2 == 0;
        options.break_long_words = random() % 2 == 0;
        options.subpixel_steps = 1u << (random() % 9);
        const TextStyle style{.size = 1.0f + static_cast<float>(random() % 100)};
        ASSERT_TRUE(layouter.layout(fonts, text, style, options, layout)) << round;
        for (const GlyphInstance& glyph : layout.glyphs) {
            ASSERT_LT(glyph.cluster, std::max<size_t>(text.size(), 1));
            ASSERT_LT(glyph.line, layout.lines.size());
        }
    }
    // Far from the origin: glyphs are dropped and counted, nothing overflows.
    const TextLayout far = lay("abc", {}, {.origin_x = 3e9f});
    EXPECT_TRUE(far.glyphs.empty());
    EXPECT_EQ(far.out_of_range_glyphs, 3u);
}

TEST_F(Layout, AMillionCharacters) {
    std::string text;
    text.reserve(1'000'000 + 64);
    const std::string words = "lorem ipsum dolor sit amet, consectetur adipiscing elit ";
    while (text.size() < 1'000'000) text += words;
    text.resize(1'000'000);
    Result<TextLayout> wrapped =
        layout_text(std::vector<const Font*>{dejavu_}, text, {.size = 12}, {.wrap_width = 900});
    ASSERT_TRUE(wrapped) << wrapped.error().message;
    // About 7 in 8 characters are letters (spaces are blank); "fi" ligatures are rare here.
    EXPECT_GT(wrapped->glyphs.size(), 800'000u);
    EXPECT_LT(wrapped->glyphs.size(), 900'000u);
    EXPECT_GT(wrapped->lines.size(), 1000u);
    // One line, unwrapped: positions far right of the origin stay exact enough for subpixel keys.
    Result<TextLayout> single = layout_text(std::vector<const Font*>{dejavu_}, text, {.size = 12}, {});
    ASSERT_TRUE(single);
    EXPECT_EQ(single->glyphs.size(), wrapped->glyphs.size());
    EXPECT_EQ(single->lines.size(), 1u);
}

}  // namespace
}  // namespace crisp
