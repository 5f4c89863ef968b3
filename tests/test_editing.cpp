// Editing over layouts (crisp/editing.hpp): carets and hit tests that find each other through
// bidi text, ligatures and wrapped lines; selections that cover exactly what they select; cursor
// motion by grapheme, word and line; bad input.
#include <crisp/editing.hpp>
#include <crisp/layout.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace crisp {
namespace {

// Mixed-direction paragraphs: Latin with Hebrew and Arabic, digits inside right-to-left text,
// "ffi" and "fi" ligatures, combining marks, hard breaks and an empty line.
const char* const kParagraphs[] = {
    "office fine \u05E9\u05DC\u05D5\u05DD 123 \u0633\u0644\u0627\u0645 cafe\u0301 ok",
    "\u05E9\u05DC\u05D5\u05DD abc 42 \u0645\u0631\u062D\u0628\u0627 \u05D0\u05D1 9\u05D2",
    "\u0627\u0644\u0633\u0644\u0627\u0645 \u0639\u0644\u064A\u0643\u0645 2026 finish \u05E2\u05D1\u05E8\u05D9\u05EA",
    "first line\n\nthird \u05D0\u05D1\u05D2 line with x\u0301 marks",
};

struct Case {
    LayoutOptions options;
    const char* name;
};

std::vector<Case> cases() {
    std::vector<Case> out;
    out.push_back({{}, "one line"});
    out.push_back({{.origin_x = 10, .origin_y = 40, .wrap_width = 130, .align = Align::center}, "wrapped, centred"});
    out.push_back({{.origin_x = 3, .origin_y = 20, .wrap_width = 110, .align = Align::right}, "wrapped, right"});
    out.push_back({{.wrap_width = 90, .align = Align::start, .direction = Direction::rtl}, "wrapped, rtl"});
    return out;
}

class Editing : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        std::string text;
        for (const char* paragraph : kParagraphs) text += paragraph;
        font_ = test::bake_test_font(text).release();
    }
    static void TearDownTestSuite() { delete font_; }
    void SetUp() override { ASSERT_NE(font_, nullptr); }

    static TextLayout lay(std::string_view text, const LayoutOptions& options = {}) {
        return test::layout_or_fail({font_}, text, {.size = 20}, options);
    }
    static TextBoundaries boundaries(std::string_view text) {
        Result<TextBoundaries> found = TextBoundaries::analyze(text);
        EXPECT_TRUE(found) << found.error().message;
        return found ? std::move(found).value() : TextBoundaries{};
    }

    static Font* font_;
};

Font* Editing::font_ = nullptr;

// A grapheme's part of a cluster, worked out here from the cluster and the boundaries.
struct Part {
    uint32_t begin, end, line;
    float left, right;
};

std::vector<Part> parts_of(const TextLayout& layout, const TextBoundaries& bounds) {
    std::vector<Part> parts;
    for (const TextCluster& cluster : layout.clusters) {
        std::vector<uint32_t> edges{cluster.text_begin};
        for (uint32_t g : bounds.graphemes())
            if (g > cluster.text_begin && g < cluster.text_end) edges.push_back(g);
        edges.push_back(cluster.text_end);
        const size_t count = edges.size() - 1;
        const float width = cluster.advance / static_cast<float>(count);
        for (size_t i = 0; i < count; ++i) {
            const size_t visual = (cluster.level & 1) != 0 ? count - 1 - i : i;
            const float left = cluster.x + width * static_cast<float>(visual);
            parts.push_back({edges[i], edges[i + 1], cluster.line, left, left + width});
        }
    }
    return parts;
}

float centre_x(const TextRect& rect) {
    return rect.x + rect.width * 0.5f;
}
float centre_y(const TextRect& rect) {
    return rect.y + rect.height * 0.5f;
}

// Offset `offset` starts a paragraph (nothing before it on its line) or ends one (nothing after).
bool starts_paragraph(const TextLayout& layout, uint32_t offset) {
    for (size_t i = 0; i < layout.lines.size(); ++i)
        if (layout.lines[i].text_begin == offset && (i == 0 || layout.lines[i - 1].text_end != offset)) return true;
    return false;
}
bool ends_paragraph(const TextLayout& layout, uint32_t offset) {
    for (size_t i = 0; i < layout.lines.size(); ++i)
        if (layout.lines[i].text_end == offset &&
            (i + 1 == layout.lines.size() || layout.lines[i + 1].text_begin != offset))
            return true;
    return false;
}

TEST_F(Editing, CaretAndHitTestFindEachOther) {
    for (const Case& test_case : cases()) {
        for (const char* text : kParagraphs) {
            const TextLayout layout = lay(text, test_case.options);
            const TextBoundaries bounds = boundaries(text);
            ASSERT_FALSE(layout.lines.empty());
            if (test_case.options.wrap_width > 0.0f) {
                EXPECT_GT(layout.lines.size(), 1u) << test_case.name;
            }
            for (uint32_t offset : bounds.graphemes()) {
                for (bool upstream : {false, true}) {
                    const TextPosition position{offset, upstream};
                    const TextRect caret = caret_rect(layout, bounds, position);
                    const HitTest hit = hit_test(layout, bounds, centre_x(caret), centre_y(caret));
                    SCOPED_TRACE(std::string(test_case.name) + ", \"" + text + "\", offset " + std::to_string(offset) +
                                 (upstream ? " upstream" : " downstream"));
                    // The offset comes back; its side too, but where the line has no character on
                    // that side (paragraph starts and ends), as the side the caret took.
                    EXPECT_EQ(hit.position.offset, offset);
                    bool side = upstream;
                    if (upstream && starts_paragraph(layout, offset)) side = false;
                    if (!upstream && ends_paragraph(layout, offset) && !starts_paragraph(layout, offset)) side = true;
                    EXPECT_EQ(hit.position.upstream, side);
                    const TextRect again = caret_rect(layout, bounds, hit.position);
                    EXPECT_FLOAT_EQ(again.x, caret.x);
                    EXPECT_FLOAT_EQ(again.y, caret.y);
                    const TextLine& line = layout.lines[hit.line];
                    EXPECT_FLOAT_EQ(caret.y, line.baseline_y - line.ascent);
                    EXPECT_FLOAT_EQ(caret.height, line.ascent + line.descent);
                    EXPECT_FLOAT_EQ(caret.width, 1.0f);
                    EXPECT_EQ(hit.inside, line.text_begin != line.text_end);
                }
            }
        }
    }
}

TEST_F(Editing, CaretAtADirectionBoundaryFollowsItsCharacter) {
    // Bytes: a0 b1 c2 ' '3 alef4 bet6 gimel8, end 10; drawn "abc gimel bet alef".
    const std::string text = "abc \u05D0\u05D1\u05D2";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    ASSERT_EQ(layout.clusters.size(), 7u);
    const TextCluster& space = layout.clusters[3];
    const TextCluster& alef = layout.clusters[4];
    const TextCluster& gimel = layout.clusters[6];
    // Downstream, offset 4 belongs to alef: its leading (right) edge, the right end of the line.
    const TextRect downstream = caret_rect(layout, bounds, {4, false}, 2);
    EXPECT_FLOAT_EQ(downstream.x + downstream.width, alef.x + alef.advance);
    EXPECT_NEAR(downstream.x + downstream.width, layout.lines[0].x + layout.lines[0].width, 1e-3f);
    // Upstream it belongs to the space: its trailing (right) edge, where gimel starts.
    const TextRect upstream = caret_rect(layout, bounds, {4, true}, 2);
    EXPECT_FLOAT_EQ(upstream.x + upstream.width, space.x + space.advance);
    EXPECT_NEAR(space.x + space.advance, gimel.x, 1e-3f);
    // The end of the text: gimel's trailing (left) edge, the rect inside gimel.
    const TextRect end = caret_rect(layout, bounds, {10, false}, 2);
    EXPECT_FLOAT_EQ(end.x, gimel.x);
    EXPECT_EQ(caret_rect(layout, bounds, {10, true}, 2).x, end.x);
    // Digits inside right-to-left text (level 2): offset 4 ("1") downstream is at its left edge.
    const std::string numbers = "\u05D0\u05D1 123";
    const TextLayout rtl = lay(numbers);
    const TextBoundaries rtl_bounds = boundaries(numbers);
    ASSERT_EQ(rtl.clusters.size(), 6u);
    EXPECT_EQ(rtl.clusters[3].level, 2);
    EXPECT_FLOAT_EQ(caret_rect(rtl, rtl_bounds, {5, false}).x, rtl.clusters[3].x);
    // Upstream at 5 belongs to the space (level 1): its trailing (left) edge, right of "123".
    EXPECT_FLOAT_EQ(caret_rect(rtl, rtl_bounds, {5, true}).x, rtl.clusters[2].x);
}

TEST_F(Editing, LigaturesAreDividedAmongTheirGraphemes) {
    const std::string text = "office";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    const auto ligature = std::find_if(layout.clusters.begin(), layout.clusters.end(),
                                       [](const TextCluster& c) { return c.text_end - c.text_begin > 1; });
    ASSERT_NE(ligature, layout.clusters.end()) << "DejaVu Sans has an ffi or fi ligature";
    const uint32_t count = ligature->text_end - ligature->text_begin;
    const float part = ligature->advance / static_cast<float>(count);
    for (uint32_t i = 0; i <= count; ++i) {
        const uint32_t offset = ligature->text_begin + i;
        const TextRect caret = caret_rect(layout, bounds, {offset, i == count}, 0);
        EXPECT_NEAR(caret.x, ligature->x + part * static_cast<float>(i), 1e-4f) << offset;
        // A click a quarter into each part hits its start.
        if (i < count) {
            const HitTest hit = hit_test(layout, bounds, ligature->x + part * (static_cast<float>(i) + 0.25f), 0);
            EXPECT_EQ(hit.position, (TextPosition{offset, false}));
        }
    }
    std::vector<TextRect> rects;
    selection_rects(layout, bounds, ligature->text_begin + 1, ligature->text_end, rects);
    ASSERT_EQ(rects.size(), 1u);
    EXPECT_NEAR(rects[0].x, ligature->x + part, 1e-4f);
    EXPECT_NEAR(rects[0].width, part * static_cast<float>(count - 1), 1e-4f);
}

// Whether [left, right] lies within the union of `rects` (intervals on x of one line).
bool covered(std::vector<std::pair<float, float>> rects, float left, float right) {
    std::sort(rects.begin(), rects.end());
    float reach = left;
    for (const auto& [a, b] : rects) {
        if (a > reach + 1e-3f) break;
        reach = std::max(reach, b);
    }
    return reach >= right - 1e-3f;
}

TEST_F(Editing, SelectionsCoverExactlyTheSelectedGraphemes) {
    std::mt19937 random(27);
    for (const Case& test_case : cases()) {
        for (const char* text : kParagraphs) {
            const TextLayout layout = lay(text, test_case.options);
            const TextBoundaries bounds = boundaries(text);
            const std::vector<Part> parts = parts_of(layout, bounds);
            const auto graphemes = bounds.graphemes();
            std::uniform_int_distribution<size_t> pick(0, graphemes.size() - 1);
            std::vector<TextRect> rects;
            for (int trial = 0; trial < 40; ++trial) {
                uint32_t begin = graphemes[pick(random)], end = graphemes[pick(random)];
                selection_rects(layout, bounds, begin, end, rects);
                if (begin > end) std::swap(begin, end);
                SCOPED_TRACE(std::string(test_case.name) + ", \"" + text + "\", [" + std::to_string(begin) + ", " +
                             std::to_string(end) + ")");
                if (begin == end) {
                    EXPECT_TRUE(rects.empty());
                }
                for (const Part& part : parts) {
                    const TextLine& line = layout.lines[part.line];
                    std::vector<std::pair<float, float>> on_line;
                    for (const TextRect& rect : rects) {
                        if (rect.y == line.baseline_y - line.ascent) on_line.emplace_back(rect.x, rect.x + rect.width);
                        EXPECT_FLOAT_EQ(rect.height, line.ascent + line.descent);
                    }
                    const bool selected = part.begin >= begin && part.end <= end;
                    if (selected) {
                        EXPECT_TRUE(covered(on_line, part.left, part.right)) << "part at " << part.begin;
                    } else {
                        const float middle = 0.5f * (part.left + part.right);
                        for (const auto& [a, b] : on_line)
                            EXPECT_FALSE(middle > a + 1e-3f && middle < b - 1e-3f) << "part at " << part.begin;
                    }
                }
                // Every rect covers something selected: none is empty.
                for (const TextRect& rect : rects) EXPECT_GT(rect.width, 0.0f);
            }
        }
    }
}

TEST_F(Editing, SelectionsSplitAtDirectionRuns) {
    // Bytes: a0 b1 c2 ' '3 alef4 bet6 gimel8 ' '10 d11 e12 f13
    const std::string text = "abc \u05D0\u05D1\u05D2 def";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    std::vector<TextRect> rects;
    selection_rects(layout, bounds, 0, static_cast<uint32_t>(text.size()), rects);
    ASSERT_EQ(rects.size(), 3u);  // "abc ", the Hebrew, " def": contiguous, three runs
    for (size_t i = 1; i < rects.size(); ++i) EXPECT_NEAR(rects[i].x, rects[i - 1].x + rects[i - 1].width, 1e-3f);
    EXPECT_NEAR(rects[0].x, layout.lines[0].x, 1e-4f);
    // "c" and alef: logically adjacent, apart on screen.
    selection_rects(layout, bounds, 2, 6, rects);
    ASSERT_EQ(rects.size(), 2u);
    EXPECT_GT(rects[1].x - (rects[0].x + rects[0].width), 10.0f);
    // Reversed ends are swapped.
    std::vector<TextRect> reversed;
    selection_rects(layout, bounds, 6, 2, reversed);
    ASSERT_EQ(reversed.size(), rects.size());
    for (size_t i = 0; i < rects.size(); ++i) EXPECT_EQ(reversed[i].x, rects[i].x);
}

TEST_F(Editing, GraphemeMotionNeverSplitsACluster) {
    // e + combining acute, a family of three joined by ZWJ, Hangul from jamo and precomposed, a flag.
    const std::string text =
        "e\u0301\U0001F468\u200D\U0001F469\u200D\U0001F467\u1100\u1161\u11A8\uD55C\uAD6D"
        "\U0001F1EB\U0001F1F7!";
    const TextBoundaries bounds = boundaries(text);
    const std::vector<uint32_t> expected = {0, 3, 21, 30, 33, 36, 44, 45};
    EXPECT_EQ(std::vector<uint32_t>(bounds.graphemes().begin(), bounds.graphemes().end()), expected);
    uint32_t at = 0;
    for (size_t i = 1; i < expected.size(); ++i) {
        at = bounds.next_grapheme(at);
        EXPECT_EQ(at, expected[i]);
    }
    EXPECT_EQ(bounds.next_grapheme(at), at);  // stays at the end
    for (size_t i = expected.size() - 1; i-- > 0;) {
        at = bounds.previous_grapheme(at);
        EXPECT_EQ(at, expected[i]);
    }
    EXPECT_EQ(bounds.previous_grapheme(0), 0u);
    // Offsets inside a grapheme snap to its start; the motions step from them to whole ones.
    EXPECT_EQ(bounds.snap(2), 0u);
    EXPECT_EQ(bounds.snap(10), 3u);
    EXPECT_EQ(bounds.next_grapheme(10), 21u);
    EXPECT_EQ(bounds.previous_grapheme(10), 3u);
    EXPECT_FALSE(bounds.is_grapheme_boundary(1));
    EXPECT_TRUE(bounds.is_grapheme_boundary(21));
}

TEST_F(Editing, WordMotionStopsAtWordStarts) {
    // Bytes: Hello0 ','5 ' '6 world7 ' '12 ' '13 foo14 '-'17 bar18 ' '21 42 22 ' '24 shalom25
    const std::string text = "Hello, world  foo-bar 42 \u05E9\u05DC\u05D5\u05DD.";
    const TextBoundaries bounds = boundaries(text);
    const std::vector<uint32_t> starts = {0, 7, 14, 18, 22, 25};
    EXPECT_EQ(std::vector<uint32_t>(bounds.word_starts().begin(), bounds.word_starts().end()), starts);
    const TextLayout layout = lay(text);
    Caret caret;
    for (size_t i = 1; i < starts.size(); ++i) {
        caret = move_caret(layout, bounds, caret, CaretMotion::next_word);
        EXPECT_EQ(caret.position.offset, starts[i]);
    }
    caret = move_caret(layout, bounds, caret, CaretMotion::next_word);
    EXPECT_EQ(caret.position.offset, text.size());
    for (size_t i = starts.size(); i-- > 0;) {
        caret = move_caret(layout, bounds, caret, CaretMotion::previous_word);
        EXPECT_EQ(caret.position.offset, starts[i]);
    }
    // From inside a word, back to its start.
    EXPECT_EQ(move_caret(layout, bounds, {{9, false}}, CaretMotion::previous_word).position.offset, 7u);
}

TEST_F(Editing, VisualMotionMovesThePressedWay) {
    for (const Case& test_case : cases()) {
        for (const char* text : kParagraphs) {
            const TextLayout layout = lay(text, test_case.options);
            const TextBoundaries bounds = boundaries(text);
            SCOPED_TRACE(std::string(test_case.name) + ", \"" + text + "\"");
            for (uint32_t line = 0; line < layout.lines.size(); ++line) {
                // From the line's left end rightwards: each press moves the caret right, until the
                // line's right end, where it goes on to another line.
                const TextLine& record = layout.lines[line];
                float left_end = record.x;  // hanging spaces of a right-to-left line lie left of x
                for (const TextCluster& cluster : layout.clusters)
                    if (cluster.line == line) left_end = std::min(left_end, cluster.x);
                const float right_end = record.x + record.width;
                Caret caret{hit_test(layout, bounds, left_end - 5, record.baseline_y).position};
                for (TextRect rect = caret_rect(layout, bounds, caret.position, 0); rect.x < right_end - 1e-3f;) {
                    caret = move_caret(layout, bounds, caret, CaretMotion::right);
                    const TextRect next = caret_rect(layout, bounds, caret.position, 0);
                    if (next.y != rect.y) break;  // hanging spaces: past the content's end
                    ASSERT_GT(next.x, rect.x) << "line " << line << " offset " << caret.position.offset;
                    rect = next;
                }
                // And back from the right end.
                caret = {hit_test(layout, bounds, right_end + 50, record.baseline_y).position};
                for (TextRect rect = caret_rect(layout, bounds, caret.position, 0); rect.x > left_end + 1e-3f;) {
                    caret = move_caret(layout, bounds, caret, CaretMotion::left);
                    const TextRect next = caret_rect(layout, bounds, caret.position, 0);
                    if (next.y != rect.y) break;
                    ASSERT_LT(next.x, rect.x) << "line " << line << " offset " << caret.position.offset;
                    rect = next;
                }
            }
        }
    }
}

TEST_F(Editing, VisualMotionThroughAnRtlRun) {
    // Bytes: shin0 lamed2 vav4 final mem6, end 8: a right-to-left paragraph, offset 0 at the right.
    const std::string text = "\u05E9\u05DC\u05D5\u05DD";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    Caret caret;
    float x = caret_rect(layout, bounds, caret.position, 0).x;
    EXPECT_NEAR(x, layout.lines[0].x + layout.lines[0].width, 1e-3f);
    const uint32_t offsets[] = {2, 4, 6, 8};
    for (uint32_t offset : offsets) {
        caret = move_caret(layout, bounds, caret, CaretMotion::left);
        EXPECT_EQ(caret.position.offset, offset);
        const float next = caret_rect(layout, bounds, caret.position, 0).x;
        EXPECT_LT(next, x);
        x = next;
    }
    EXPECT_EQ(move_caret(layout, bounds, caret, CaretMotion::left).position.offset, 8u);  // the end: stays
    for (uint32_t offset : {6u, 4u, 2u, 0u}) {
        caret = move_caret(layout, bounds, caret, CaretMotion::right);
        EXPECT_EQ(caret.position.offset, offset);
        const float next = caret_rect(layout, bounds, caret.position, 0).x;
        EXPECT_GT(next, x);
        x = next;
    }
    // Logical motion goes the other way on screen: forward is left.
    const Caret forward = move_caret(layout, bounds, {}, CaretMotion::next_grapheme);
    EXPECT_EQ(forward.position.offset, 2u);
    EXPECT_LT(caret_rect(layout, bounds, forward.position).x, caret_rect(layout, bounds, {}).x);

    // Through a direction boundary in a left-to-right paragraph: after the space, the Hebrew from
    // its left end. Bytes: a0 ' '1 alef2 bet4 gimel6, end 8.
    const std::string mixed = "a \u05D0\u05D1\u05D2";
    const TextLayout mixed_layout = lay(mixed);
    const TextBoundaries mixed_bounds = boundaries(mixed);
    Caret step;
    std::vector<TextPosition> visited;
    for (int i = 0; i < 6; ++i) {
        step = move_caret(mixed_layout, mixed_bounds, step, CaretMotion::right);
        visited.push_back(step.position);
    }
    const std::vector<TextPosition> expected = {{1, true}, {2, true}, {6, false}, {4, false}, {2, false}, {2, false}};
    EXPECT_EQ(visited, expected);
}

TEST_F(Editing, VisualWordMotionStopsAtWordStartsOnScreen) {
    // "one two " then Hebrew "שלום אב" (a right-to-left run) then " end": Ctrl+Right from
    // the start stops at each word start in turn; inside the Hebrew run, going right on screen
    // walks it backwards, so its stops are its words' starts met from their left side.
    const std::string text = "one two \u05E9\u05DC\u05D5\u05DD \u05D0\u05D1 end";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    Caret caret;
    float x = caret_rect(layout, bounds, caret.position, 0).x;
    std::vector<uint32_t> stops;
    for (int i = 0; i < 12; ++i) {
        const Caret next = move_caret(layout, bounds, caret, CaretMotion::word_right);
        if (next.position == caret.position) break;
        const float next_x = caret_rect(layout, bounds, next.position, 0).x;
        EXPECT_GT(next_x, x) << "word_right moved the caret left, to " << next.position.offset;
        x = next_x;
        caret = next;
        stops.push_back(caret.position.offset);
    }
    // Every stop is a word start or the text's end, and the LTR words' starts are among them.
    for (const uint32_t stop : stops) {
        const bool word_start = stop == text.size() || bounds.previous_word_start(bounds.next_grapheme(stop)) == stop;
        EXPECT_TRUE(word_start) << stop;
    }
    EXPECT_NE(std::find(stops.begin(), stops.end(), 4u), stops.end());  // "two"
    EXPECT_EQ(stops.back(), text.size());
    // And back: word_left retraces to the start, moving left every time.
    for (int i = 0; i < 12 && caret.position.offset != 0; ++i) {
        const Caret next = move_caret(layout, bounds, caret, CaretMotion::word_left);
        ASSERT_NE(next.position, caret.position);
        const float next_x = caret_rect(layout, bounds, next.position, 0).x;
        EXPECT_LT(next_x, x);
        x = next_x;
        caret = next;
    }
    EXPECT_EQ(caret.position.offset, 0u);
}

TEST_F(Editing, UpAndDownKeepTheGoalX) {
    // Three lines: long, short, long. Bytes: line 0 [0, 15), line 1 [16, 18), line 2 [19, 34).
    const std::string text = "a long line one\nab\na long line two";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    ASSERT_EQ(layout.lines.size(), 3u);
    Caret caret{{10, false}};
    const float goal = caret_rect(layout, bounds, caret.position, 0).x;
    caret = move_caret(layout, bounds, caret, CaretMotion::down);
    EXPECT_EQ(caret.position.offset, 18u);  // the short line's end, nearest the goal
    EXPECT_FLOAT_EQ(caret.goal_x, goal);
    caret = move_caret(layout, bounds, caret, CaretMotion::down);
    EXPECT_EQ(caret.position.offset, 29u);  // the same column again
    EXPECT_NEAR(caret_rect(layout, bounds, caret.position, 0).x, goal, 1.0f);
    caret = move_caret(layout, bounds, caret, CaretMotion::up);
    caret = move_caret(layout, bounds, caret, CaretMotion::up);
    EXPECT_EQ(caret.position.offset, 10u);
    // Up on the first line goes to the start, down on the last to the end.
    EXPECT_EQ(move_caret(layout, bounds, caret, CaretMotion::up).position, (TextPosition{0, false}));
    EXPECT_EQ(move_caret(layout, bounds, {{30, false}}, CaretMotion::down).position, (TextPosition{34, true}));
    // Any other motion forgets the goal.
    EXPECT_TRUE(std::isnan(move_caret(layout, bounds, caret, CaretMotion::right).goal_x));
}

TEST_F(Editing, HomeAndEndGoToTheLineEnds) {
    // Wrapped: "one two three" in 60 px: "one two " / "three", or shorter lines; Home and End keep
    // the caret on its line, End after the hanging space, upstream.
    const std::string text = "one two three\nfour";
    const TextLayout layout = lay(text, {.wrap_width = 60});
    const TextBoundaries bounds = boundaries(text);
    ASSERT_GE(layout.lines.size(), 3u);
    for (uint32_t i = 0; i < layout.lines.size(); ++i) {
        const TextLine& line = layout.lines[i];
        const TextPosition inside{bounds.next_grapheme(line.text_begin), false};
        const Caret home = move_caret(layout, bounds, {inside}, CaretMotion::line_start);
        const Caret end = move_caret(layout, bounds, {inside}, CaretMotion::line_end);
        EXPECT_EQ(home.position, (TextPosition{line.text_begin, false})) << i;
        EXPECT_EQ(end.position, (TextPosition{line.text_end, true})) << i;
        // Both carets are drawn on this line.
        EXPECT_FLOAT_EQ(caret_rect(layout, bounds, home.position).y, line.baseline_y - line.ascent);
        EXPECT_FLOAT_EQ(caret_rect(layout, bounds, end.position).y, line.baseline_y - line.ascent);
    }
    EXPECT_EQ(move_caret(layout, bounds, {{5, false}}, CaretMotion::text_end).position,
              (TextPosition{static_cast<uint32_t>(text.size()), true}));
    EXPECT_EQ(move_caret(layout, bounds, {{5, false}}, CaretMotion::text_start).position, (TextPosition{0, false}));
}

TEST_F(Editing, BadInputIsClampedOrSnapped) {
    // Bytes: a0 alef1 e3 acute4, end 6.
    const std::string text = "a\u05D0e\u0301";
    const TextLayout layout = lay(text);
    const TextBoundaries bounds = boundaries(text);
    auto same = [](const TextRect& a, const TextRect& b) {
        return a.x == b.x && a.y == b.y && a.width == b.width && a.height == b.height;
    };
    // Past the end, inside a UTF-8 sequence, inside a grapheme: the boundary before.
    EXPECT_TRUE(same(caret_rect(layout, bounds, {1000, false}), caret_rect(layout, bounds, {6, false})));
    EXPECT_TRUE(same(caret_rect(layout, bounds, {2, false}), caret_rect(layout, bounds, {1, false})));
    EXPECT_TRUE(same(caret_rect(layout, bounds, {5, true}), caret_rect(layout, bounds, {3, true})));
    EXPECT_EQ(move_caret(layout, bounds, {{2, false}}, CaretMotion::next_grapheme).position.offset, 3u);
    std::vector<TextRect> rects, snapped;
    selection_rects(layout, bounds, 2, 1000, rects);
    selection_rects(layout, bounds, 1, 6, snapped);
    ASSERT_EQ(rects.size(), snapped.size());
    for (size_t i = 0; i < rects.size(); ++i) EXPECT_TRUE(same(rects[i], snapped[i]));
    // A width that is NaN, infinite or negative is 1.
    for (float width : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -2.0f})
        EXPECT_EQ(caret_rect(layout, bounds, {0, false}, width).width, 1.0f);
    // A NaN coordinate is 0; infinite ones are the far side.
    const float nan = std::numeric_limits<float>::quiet_NaN(), infinity = std::numeric_limits<float>::infinity();
    EXPECT_EQ(hit_test(layout, bounds, nan, nan).position, hit_test(layout, bounds, 0, 0).position);
    EXPECT_EQ(hit_test(layout, bounds, -infinity, 0).position, (TextPosition{0, false}));
    EXPECT_EQ(hit_test(layout, bounds, infinity, infinity).position, (TextPosition{6, true}));
    EXPECT_FALSE(hit_test(layout, bounds, infinity, 0).inside);
    // A NaN goal is none.
    EXPECT_EQ(move_caret(layout, bounds, {{0, false}, nan}, CaretMotion::down).position, (TextPosition{6, true}));

    // Boundaries of another text never take the functions outside the layout.
    const TextBoundaries other = boundaries("a much longer text than the one laid out, e\u0301");
    for (uint32_t offset = 0; offset < 60; ++offset) {
        const TextRect caret = caret_rect(layout, other, {offset, offset % 2 == 0});
        EXPECT_TRUE(std::isfinite(caret.x)) << offset;
        EXPECT_LE(hit_test(layout, other, caret.x, caret.y).position.offset, 6u);
        selection_rects(layout, other, 0, offset, rects);
        for (CaretMotion motion : {CaretMotion::left, CaretMotion::right, CaretMotion::up, CaretMotion::line_end})
            EXPECT_TRUE(
                std::isfinite(caret_rect(layout, other, move_caret(layout, other, {{offset}}, motion).position).x));
    }

    // Invalid UTF-8 has boundaries; too long a text is refused.
    EXPECT_TRUE(TextBoundaries::analyze("a\xFF\xC3(b"));
    const Result<TextBoundaries> too_long = TextBoundaries::analyze(std::string(kMaxTextBytes + 1, 'a'));
    ASSERT_FALSE(too_long);
    EXPECT_NE(too_long.error().message.find("kMaxTextBytes"), std::string::npos);
}

TEST_F(Editing, HostileTextNeverCrashes) {
    // Marks past kMaxMarksPerCluster, bidi controls, joiners, invalid bytes, breaks: whatever the
    // clusters, every position that comes back is on a grapheme boundary and every rect is finite.
    std::mt19937 random(2027);
    const std::string pieces[] = {"a",        " ",
                                  "\n",       "\r\n",
                                  "\t",       "\u05D0",
                                  "\u0627",   "\u0301",
                                  "\u200D",   "\u202E",
                                  "\u2067",   "\u2069",
                                  "1",        "\xFF",
                                  "\xE2\x82", "\u200B",
                                  "f",        "i",
                                  "-",        "\u1100",
                                  "\u1161",   std::string(70, '\xCC') + "\x81"};
    const std::string combining = [] {
        std::string marks = "e";
        for (int i = 0; i < 70; ++i) marks += "\u0301";
        return marks;
    }();
    std::vector<TextRect> rects;
    for (int round = 0; round < 100; ++round) {
        std::string text = round % 10 == 0 ? combining : std::string();
        const int length = static_cast<int>(random() % 48);
        for (int i = 0; i < length; ++i) text += pieces[random() % std::size(pieces)];
        LayoutOptions options;
        options.wrap_width = static_cast<float>(random() % 4) * 25.0f;
        options.align = static_cast<Align>(random() % 5);
        options.direction = static_cast<Direction>(random() % 3);
        options.break_long_words = random() % 2 == 0;
        const TextLayout layout = lay(text, options);
        const TextBoundaries bounds = boundaries(text);
        auto on_boundary = [&](TextPosition position) {
            return position.offset <= text.size() && bounds.is_grapheme_boundary(position.offset);
        };
        for (uint32_t offset = 0; offset <= text.size(); ++offset) {
            const TextPosition position{offset, offset % 2 == 1};
            const TextRect caret = caret_rect(layout, bounds, position);
            ASSERT_TRUE(std::isfinite(caret.x) && std::isfinite(caret.y)) << round << " " << offset;
            const HitTest hit = hit_test(layout, bounds, centre_x(caret), centre_y(caret));
            ASSERT_TRUE(on_boundary(hit.position)) << round << " " << offset;
            for (uint8_t motion = 0; motion <= static_cast<uint8_t>(CaretMotion::down); ++motion)
                ASSERT_TRUE(on_boundary(move_caret(layout, bounds, {position}, CaretMotion{motion}).position))
                    << round << " " << offset << " motion " << int{motion};
        }
        selection_rects(layout, bounds, 0, static_cast<uint32_t>(text.size()), rects);
        for (const TextRect& rect : rects) ASSERT_TRUE(rect.width >= 0.0f && std::isfinite(rect.x)) << round;
    }
}

TEST_F(Editing, EmptyTextHasACaret) {
    const TextLayout layout = lay("", {.origin_x = 12, .origin_y = 50});
    const TextBoundaries bounds = boundaries("");
    ASSERT_TRUE(layout.lines.empty());
    const TextRect caret = caret_rect(layout, bounds, {7, true}, 2);
    EXPECT_FLOAT_EQ(caret.x, 12.0f);
    EXPECT_NEAR(caret.y, 50.0f - font_->ascender() * 20, 1e-4f);
    EXPECT_FLOAT_EQ(caret.width, 2.0f);
    EXPECT_FLOAT_EQ(caret.height, layout.line_height);
    EXPECT_GT(caret.height, 0.0f);
    const HitTest hit = hit_test(layout, bounds, 100, 100);
    EXPECT_EQ(hit.position, TextPosition{});
    EXPECT_FALSE(hit.inside);
    std::vector<TextRect> rects{{}};
    selection_rects(layout, bounds, 0, 5, rects);
    EXPECT_TRUE(rects.empty());
    for (CaretMotion motion : {CaretMotion::right, CaretMotion::down, CaretMotion::text_end})
        EXPECT_EQ(move_caret(layout, bounds, {{3, true}}, motion).position, TextPosition{});
    // Empty lines between paragraphs have carets at their x.
    const std::string text = "a\n\nb";
    const TextLayout lines = lay(text, {.origin_x = 4});
    const TextBoundaries line_bounds = boundaries(text);
    ASSERT_EQ(lines.lines.size(), 3u);
    const TextRect empty_line = caret_rect(lines, line_bounds, {2, false});
    EXPECT_FLOAT_EQ(empty_line.x, 4.0f);
    EXPECT_FLOAT_EQ(empty_line.y, lines.lines[1].baseline_y - lines.lines[1].ascent);
}

}  // namespace
}  // namespace crisp
