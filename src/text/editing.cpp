// Editing over a laid-out text (crisp/editing.hpp): grapheme and word boundaries from ICU, and
// carets, hit tests, selections and cursor motion from the layout's clusters.
#include <crisp/editing.hpp>

#include <unicode/ubrk.h>
#include <unicode/utext.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>

namespace crisp {

namespace {

Error icu_failed(const char* call, UErrorCode code) {
    return Error{ErrorCode::invalid_argument,
                 std::string("text boundaries: ICU's ") + call + " failed: " + u_errorName(code)};
}

// ICU's C objects, closed when they go out of scope.
struct IcuText {
    UText* text = nullptr;
    ~IcuText() { utext_close(text); }
};
struct IcuBreaks {
    UBreakIterator* breaks = nullptr;
    ~IcuBreaks() { ubrk_close(breaks); }
};

// A break iterator of `type` over `text`, or an error naming the ICU call that failed.
Status open_breaks(UBreakIteratorType type, UText* text, IcuBreaks& out) {
    UErrorCode code = U_ZERO_ERROR;
    out.breaks = ubrk_open(type, "", nullptr, 0, &code);
    if (U_FAILURE(code)) return icu_failed("ubrk_open", code);
    ubrk_setUText(out.breaks, text, &code);
    if (U_FAILURE(code)) return icu_failed("ubrk_setUText", code);
    return {};
}

// Where carets and selections that ask for the same pixel meet: edges closer than this are one.
constexpr float kSameEdge = 1.0f / 64.0f;

bool is_rtl(const TextCluster& cluster) {
    return (cluster.level & 1) != 0;
}

// A grapheme's share of a cluster: its byte range and its left and right edges on the canvas.
struct Part {
    uint32_t begin = 0, end = 0;
    float left = 0.0f, right = 0.0f;
};

// The graphemes of a cluster: the boundaries inside it divide its advance evenly, in its direction.
class ClusterParts {
public:
    ClusterParts(const TextCluster& cluster, std::span<const uint32_t> graphemes) : cluster_(cluster) {
        const auto* first = std::upper_bound(graphemes.data(), graphemes.data() + graphemes.size(), cluster.text_begin);
        const auto* last = std::lower_bound(first, graphemes.data() + graphemes.size(), cluster.text_end);
        inner_ = std::span(first, last);
        width_ = cluster.advance / static_cast<float>(count());
    }
    uint32_t count() const { return static_cast<uint32_t>(inner_.size()) + 1; }
    // The part in logical place `index` (< count()).
    Part part(uint32_t index) const {
        Part part;
        part.begin = index == 0 ? cluster_.text_begin : inner_[index - 1];
        part.end = index + 1 == count() ? cluster_.text_end : inner_[index];
        const uint32_t visual = is_rtl(cluster_) ? count() - 1 - index : index;
        part.left = cluster_.x + static_cast<float>(visual) * width_;
        part.right = visual + 1 == count() ? cluster_.x + cluster_.advance : part.left + width_;
        return part;
    }
    // The logical place of the part holding byte `offset` of the cluster.
    uint32_t index_of(uint32_t offset) const {
        return static_cast<uint32_t>(std::upper_bound(inner_.begin(), inner_.end(), offset) - inner_.begin());
    }
    // The logical place of the part under canvas x (the nearest end one outside the cluster).
    uint32_t index_at(float x) const {
        uint32_t visual = 0;
        if (width_ > 0.0f) {
            const float place = std::floor((x - cluster_.x) / width_);
            visual = place <= 0.0f ? 0 : static_cast<uint32_t>(std::min(place, static_cast<float>(count() - 1)));
        }
        return is_rtl(cluster_) ? count() - 1 - visual : visual;
    }

private:
    const TextCluster& cluster_;
    std::span<const uint32_t> inner_;
    float width_ = 0.0f;
};

// The clusters of line `line`.
std::span<const TextCluster> line_clusters(const TextLayout& layout, uint32_t line) {
    const auto begin = std::partition_point(layout.clusters.begin(), layout.clusters.end(),
                                            [line](const TextCluster& cluster) { return cluster.line < line; });
    const auto end = std::partition_point(begin, layout.clusters.end(),
                                          [line](const TextCluster& cluster) { return cluster.line <= line; });
    return {begin, end};
}

// The line a position is on (the layout has lines): the first whose range reaches its offset, or
// for downstream at the end of a wrapped line, the next.
uint32_t line_of(const TextLayout& layout, TextPosition position) {
    const auto& lines = layout.lines;
    auto line = static_cast<uint32_t>(
        std::partition_point(lines.begin(), lines.end(),
                             [&](const TextLine& record) { return record.text_end < position.offset; }) -
        lines.begin());
    if (line == lines.size()) return line - 1;
    if (!position.upstream && lines[line].text_end == position.offset && line + 1 < lines.size() &&
        lines[line + 1].text_begin == position.offset)
        ++line;
    return line;
}

// Where a position's caret is: the edge it is at, and on which side of the character it belongs
// to (its leading or trailing one, in that character's direction).
struct Edge {
    float x = 0.0f;
    bool found = false;  // false: the line has no character for it; x is the line's
    bool leading = false;
    bool rtl = false;
};

Edge leading_edge(const TextCluster& cluster, const Part& part) {
    return {is_rtl(cluster) ? part.right : part.left, true, true, is_rtl(cluster)};
}

Edge trailing_edge(const TextCluster& cluster, const Part& part) {
    return {is_rtl(cluster) ? part.left : part.right, true, false, is_rtl(cluster)};
}

// The caret rule (crisp/editing.hpp) for a position already snapped, on line `line`.
Edge caret_edge(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t line, TextPosition position) {
    const std::span<const TextCluster> clusters = line_clusters(layout, line);
    const uint32_t offset = position.offset;
    // The cluster holding the character at the offset, and the one holding the character before.
    const auto* after =
        std::partition_point(clusters.data(), clusters.data() + clusters.size(),
                             [offset](const TextCluster& cluster) { return cluster.text_end <= offset; });
    const bool has_after = after != clusters.data() + clusters.size() && after->text_begin <= offset;
    const auto* before =
        std::partition_point(clusters.data(), clusters.data() + clusters.size(),
                             [offset](const TextCluster& cluster) { return cluster.text_end < offset; });
    const bool has_before = before != clusters.data() + clusters.size() && before->text_begin < offset;
    auto lead = [&] {
        const ClusterParts parts(*after, boundaries.graphemes());
        return leading_edge(*after, parts.part(parts.index_of(offset)));
    };
    auto trail = [&] {
        const ClusterParts parts(*before, boundaries.graphemes());
        return trailing_edge(*before, parts.part(parts.index_of(offset - 1)));
    };
    if (has_after && (!position.upstream || !has_before)) return lead();
    if (has_before) return trail();
    const TextLine& record = layout.lines[line];
    Edge edge;
    edge.x = record.x;
    edge.rtl = record.rtl;
    return edge;
}

// The first of the sorted `offsets` after `offset`, or `end`.
uint32_t next_after(std::span<const uint32_t> offsets, uint32_t offset, uint32_t end) {
    const auto* next = std::upper_bound(offsets.data(), offsets.data() + offsets.size(), offset);
    return next == offsets.data() + offsets.size() ? end : *next;
}

// The last of the sorted `offsets` before `offset`, or 0.
uint32_t previous_before(std::span<const uint32_t> offsets, uint32_t offset) {
    const auto* at = std::lower_bound(offsets.data(), offsets.data() + offsets.size(), offset);
    return at == offsets.data() ? 0 : *(at - 1);
}

TextPosition snapped(const TextBoundaries& boundaries, TextPosition position) {
    return {boundaries.snap(position.offset), position.upstream};
}

// The positions of a grapheme part's leading and trailing edges. A part's ends are grapheme
// boundaries unless HarfBuzz's clusters and ICU's graphemes disagree (a cluster cut after
// kMaxMarksPerCluster marks, a line broken inside a grapheme): then the grapheme holding them.
TextPosition leading_position(const TextBoundaries& boundaries, const Part& part) {
    return {boundaries.snap(part.begin), false};
}
TextPosition trailing_position(const TextBoundaries& boundaries, const Part& part) {
    const uint32_t end = boundaries.is_grapheme_boundary(part.end) ? part.end : boundaries.next_grapheme(part.end);
    return {end, true};
}

// The line nearest y in its box.
uint32_t line_at(const TextLayout& layout, float y) {
    const auto& lines = layout.lines;
    const auto below = std::partition_point(lines.begin(), lines.end(),
                                            [y](const TextLine& line) { return line.baseline_y + line.descent < y; });
    if (below == lines.end()) return static_cast<uint32_t>(lines.size() - 1);
    const auto index = static_cast<uint32_t>(below - lines.begin());
    const float top = below->baseline_y - below->ascent;
    if (index == 0 || y >= top) return index;
    const TextLine& above = lines[index - 1];
    return y - (above.baseline_y + above.descent) <= top - y ? index - 1 : index;
}

// hit_test() on a given line.
HitTest hit_line(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t line, float x) {
    HitTest hit;
    hit.line = line;
    const std::span<const TextCluster> clusters = line_clusters(layout, line);
    if (clusters.empty()) {
        hit.position = {boundaries.snap(layout.lines[line].text_begin), false};
        return hit;
    }
    // In doubles, with x clamped, so that far points (infinite ones too) still tell clusters apart.
    const double at = std::clamp(static_cast<double>(x), -kMaxCoordinate, kMaxCoordinate);
    const TextCluster* nearest = nullptr;
    double nearest_distance = 0.0;
    for (const TextCluster& cluster : clusters) {
        const double left = static_cast<double>(cluster.x), right = left + static_cast<double>(cluster.advance);
        const double distance = std::max({left - at, at - right, 0.0});
        if (nearest == nullptr || distance < nearest_distance) {
            nearest = &cluster;
            nearest_distance = distance;
        }
    }
    const ClusterParts parts(*nearest, boundaries.graphemes());
    const Part part = parts.part(parts.index_at(x));
    const float middle = 0.5f * (part.left + part.right);
    const bool leading = is_rtl(*nearest) ? x >= middle : x < middle;
    hit.position = leading ? leading_position(boundaries, part) : trailing_position(boundaries, part);
    hit.inside = nearest_distance == 0.0;
    return hit;
}

TextRect line_box(const TextLine& line, float x, float width) {
    return {x, line.baseline_y - line.ascent, width, line.ascent + line.descent};
}

// A caret stop of a line: where a grapheme's leading or trailing edge is, the position it is, and
// whether the grapheme lies left of it.
struct Stop {
    float x = 0.0f;
    TextPosition position;
    bool owner_left = false;
};

// Calls visit(stop) for both edges of every grapheme on `line`.
template <class Visit>
void for_each_stop(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t line, Visit visit) {
    for (const TextCluster& cluster : line_clusters(layout, line)) {
        const ClusterParts parts(cluster, boundaries.graphemes());
        const bool rtl = is_rtl(cluster);
        for (uint32_t i = 0; i < parts.count(); ++i) {
            const Part part = parts.part(i);
            visit(Stop{rtl ? part.right : part.left, leading_position(boundaries, part), rtl});
            visit(Stop{rtl ? part.left : part.right, trailing_position(boundaries, part), !rtl});
        }
    }
}

// The next stop from x in `direction` (+1 right, -1 left) on `line`: the nearest edge past x, and of
// two at one edge the one whose grapheme was passed over. `found` false when there is none.
Stop next_stop(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t line, float x, int direction,
               bool& found) {
    found = false;
    Stop best;
    for_each_stop(layout, boundaries, line, [&](const Stop& stop) {
        const float ahead = (stop.x - x) * static_cast<float>(direction);
        if (ahead <= kSameEdge) return;
        const bool passed_over = stop.owner_left == (direction > 0);
        if (found) {
            const float gain = (best.x - stop.x) * static_cast<float>(direction);
            const bool tie = std::abs(gain) <= kSameEdge;
            const bool best_passed_over = best.owner_left == (direction > 0);
            if (!(gain > kSameEdge || (tie && passed_over && !best_passed_over))) return;
        }
        best = stop;
        found = true;
    });
    return best;
}

// The stop at the left (direction -1) or right (+1) end of `line`; its start where it has none.
TextPosition end_stop(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t line, int direction) {
    bool found = false;
    const float far = direction > 0 ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity();
    const Stop stop = next_stop(layout, boundaries, line, far, -direction, found);
    return found ? stop.position : TextPosition{layout.lines[line].text_begin, false};
}

// One grapheme edge left or right on screen, or on to the next line in that direction.
TextPosition move_visually(const TextLayout& layout, const TextBoundaries& boundaries, TextPosition position,
                           int direction) {
    const uint32_t line = line_of(layout, position);
    const Edge edge = caret_edge(layout, boundaries, line, position);
    bool found = false;
    const Stop stop = next_stop(layout, boundaries, line, edge.x, direction, found);
    if (found) return stop.position;
    // Past the line's end in its reading direction: the next line; against it: the previous.
    const bool forward = (direction > 0) != layout.lines[line].rtl;
    if (forward ? line + 1 >= layout.lines.size() : line == 0) return position;
    const uint32_t next = forward ? line + 1 : line - 1;
    return end_stop(layout, boundaries, next, -direction);
}

}  // namespace

TextBoundaries::TextBoundaries() : graphemes_{0} {}

Result<TextBoundaries> TextBoundaries::analyze(std::string_view utf8) {
    if (utf8.size() > kMaxTextBytes)
        return Error{ErrorCode::invalid_argument, "text boundaries: the text is " + std::to_string(utf8.size()) +
                                                      " bytes, more than the " + std::to_string(kMaxTextBytes) +
                                                      " supported (kMaxTextBytes)"};
    TextBoundaries out;
    out.size_ = static_cast<uint32_t>(utf8.size());
    if (utf8.empty()) return out;
    UErrorCode code = U_ZERO_ERROR;
    IcuText text;
    text.text = utext_openUTF8(nullptr, utf8.data(), static_cast<int64_t>(utf8.size()), &code);
    if (U_FAILURE(code)) return icu_failed("utext_openUTF8", code);

    IcuBreaks characters;
    if (Status status = open_breaks(UBRK_CHARACTER, text.text, characters); !status) return status.error();
    out.graphemes_.clear();
    // UTF-8 native indexes are byte offsets.
    for (int32_t at = ubrk_first(characters.breaks); at != UBRK_DONE; at = ubrk_next(characters.breaks))
        out.graphemes_.push_back(static_cast<uint32_t>(at));

    IcuBreaks words;
    if (Status status = open_breaks(UBRK_WORD, text.text, words); !status) return status.error();
    int32_t start = ubrk_first(words.breaks);
    for (int32_t at = ubrk_next(words.breaks); at != UBRK_DONE; at = ubrk_next(words.breaks)) {
        // The rule status tells what the segment that ends here is: spaces and punctuation are
        // "none", letters, numbers, kana and ideographs are words.
        if (ubrk_getRuleStatus(words.breaks) >= UBRK_WORD_NONE_LIMIT)
            out.word_starts_.push_back(static_cast<uint32_t>(start));
        start = at;
    }
    return out;
}

bool TextBoundaries::is_grapheme_boundary(uint32_t offset) const {
    return std::binary_search(graphemes_.begin(), graphemes_.end(), offset);
}

uint32_t TextBoundaries::snap(uint32_t offset) const {
    if (offset >= size_) return size_;
    return *(std::upper_bound(graphemes_.begin(), graphemes_.end(), offset) - 1);
}

uint32_t TextBoundaries::next_grapheme(uint32_t offset) const {
    return next_after(graphemes_, offset, size_);
}

uint32_t TextBoundaries::previous_grapheme(uint32_t offset) const {
    return previous_before(graphemes_, offset);
}

uint32_t TextBoundaries::next_word_start(uint32_t offset) const {
    return next_after(word_starts_, offset, size_);
}

uint32_t TextBoundaries::previous_word_start(uint32_t offset) const {
    return previous_before(word_starts_, offset);
}

HitTest hit_test(const TextLayout& layout, const TextBoundaries& boundaries, float x, float y) {
    if (layout.lines.empty()) return {};
    if (std::isnan(x)) x = 0.0f;
    if (std::isnan(y)) y = 0.0f;
    const uint32_t line = line_at(layout, y);
    HitTest hit = hit_line(layout, boundaries, line, x);
    const TextLine& record = layout.lines[line];
    hit.inside = hit.inside && y >= record.baseline_y - record.ascent && y <= record.baseline_y + record.descent;
    return hit;
}

TextRect caret_rect(const TextLayout& layout, const TextBoundaries& boundaries, TextPosition position, float width) {
    if (!std::isfinite(width) || width < 0.0f) width = 1.0f;
    if (layout.lines.empty()) return {layout.x, layout.y, width, layout.line_height};
    position = snapped(boundaries, position);
    const uint32_t line = line_of(layout, position);
    const Edge edge = caret_edge(layout, boundaries, line, position);
    // Inside the character the caret belongs to: on the right of a left edge, the left of a right one.
    const bool left_edge = edge.found ? edge.leading != edge.rtl : !edge.rtl;
    return line_box(layout.lines[line], left_edge ? edge.x : edge.x - width, width);
}

void selection_rects(const TextLayout& layout, const TextBoundaries& boundaries, uint32_t begin, uint32_t end,
                     std::vector<TextRect>& out) {
    out.clear();
    if (begin > end) std::swap(begin, end);
    begin = boundaries.snap(begin);
    end = boundaries.snap(end);
    if (begin >= end) return;
    // The selected parts of one line, merged into rectangles when it ends.
    struct Span {
        float left, right;
        uint8_t level;
    };
    std::vector<Span> spans;
    auto flush = [&](uint32_t line) {
        std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) { return a.left < b.left; });
        for (size_t i = 0; i < spans.size(); ++i) {
            const Span& span = spans[i];
            // A span that touches the one before it, at the same level, extends its rectangle.
            if (i > 0 && span.level == spans[i - 1].level && span.left - spans[i - 1].right <= kSameEdge) {
                TextRect& last = out.back();
                last.width = std::max(last.width, span.right - last.x);
                continue;
            }
            out.push_back(line_box(layout.lines[line], span.left, span.right - span.left));
        }
        spans.clear();
    };
    auto cluster = std::partition_point(layout.clusters.begin(), layout.clusters.end(),
                                        [begin](const TextCluster& c) { return c.text_end <= begin; });
    uint32_t line = cluster == layout.clusters.end() ? 0 : cluster->line;
    for (; cluster != layout.clusters.end() && cluster->text_begin < end; ++cluster) {
        if (cluster->line != line) {
            flush(line);
            line = cluster->line;
        }
        const ClusterParts parts(*cluster, boundaries.graphemes());
        const Part first = parts.part(parts.index_of(std::max(begin, cluster->text_begin)));
        const Part last = parts.part(parts.index_of(std::min(end, cluster->text_end) - 1));
        spans.push_back({std::min(first.left, last.left), std::max(first.right, last.right), cluster->level});
    }
    flush(line);
}

namespace {

// move_caret() before its result is snapped.
Caret move_unsnapped(const TextLayout& layout, const TextBoundaries& boundaries, Caret caret, CaretMotion motion) {
    constexpr float kNoGoal = std::numeric_limits<float>::quiet_NaN();
    const TextPosition position = snapped(boundaries, caret.position);
    const uint32_t offset = position.offset;
    switch (motion) {
        case CaretMotion::next_grapheme:
            return {{boundaries.next_grapheme(offset), false}, kNoGoal};
        case CaretMotion::previous_grapheme:
            return {{boundaries.previous_grapheme(offset), false}, kNoGoal};
        case CaretMotion::next_word:
            return {{boundaries.next_word_start(offset), false}, kNoGoal};
        case CaretMotion::previous_word:
            return {{boundaries.previous_word_start(offset), false}, kNoGoal};
        case CaretMotion::line_start:
            return {{layout.lines[line_of(layout, position)].text_begin, false}, kNoGoal};
        case CaretMotion::line_end:
            return {{layout.lines[line_of(layout, position)].text_end, true}, kNoGoal};
        case CaretMotion::text_start:
            return {{0, false}, kNoGoal};
        case CaretMotion::text_end:
            return {{boundaries.size(), true}, kNoGoal};
        case CaretMotion::left:
            return {move_visually(layout, boundaries, position, -1), kNoGoal};
        case CaretMotion::right:
            return {move_visually(layout, boundaries, position, +1), kNoGoal};
        case CaretMotion::word_left:
        case CaretMotion::word_right: {
            // On screen, one grapheme edge at a time, until the caret stands at a word's start
            // (or at the text's ends, or where it can go no further).
            const int step = motion == CaretMotion::word_left ? -1 : +1;
            TextPosition at = position;
            // Visual steps through text of many direction runs and lines may come back to where
            // they were: at most as many steps as there are caret positions.
            const size_t limit = 2 * size_t{boundaries.size()} + 2;
            for (size_t steps = 0;; ++steps) {
                const TextPosition next = move_visually(layout, boundaries, at, step);
                if (next == at || steps == limit) return {at, kNoGoal};
                at = next;
                const bool word_start =
                    at.offset == 0 || at.offset >= boundaries.size() ||
                    boundaries.previous_word_start(boundaries.next_grapheme(at.offset)) == at.offset;
                if (word_start) return {at, kNoGoal};
            }
        }
        case CaretMotion::up:
        case CaretMotion::down: {
            const uint32_t line = line_of(layout, position);
            const float goal =
                std::isfinite(caret.goal_x) ? caret.goal_x : caret_edge(layout, boundaries, line, position).x;
            if (motion == CaretMotion::up && line == 0) return {{0, false}, goal};
            if (motion == CaretMotion::down && line + 1 == layout.lines.size())
                return {{boundaries.size(), true}, goal};
            const uint32_t next = motion == CaretMotion::up ? line - 1 : line + 1;
            return {hit_line(layout, boundaries, next, goal).position, goal};
        }
    }
    return {position, kNoGoal};
}

}  // namespace

Caret move_caret(const TextLayout& layout, const TextBoundaries& boundaries, Caret caret, CaretMotion motion) {
    if (layout.lines.empty()) return {};
    Caret moved = move_unsnapped(layout, boundaries, caret, motion);
    // Line ends are where HarfBuzz's clusters allowed a break; ICU's graphemes have the last word.
    moved.position = snapped(boundaries, moved.position);
    return moved;
}

}  // namespace crisp
