#include "text_field.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace engine {
namespace {

constexpr float kTextSize = 15.0f;
constexpr float kPadding = 8.0f;         // between the field's edge and its text
constexpr float kCaretWidth = 2.0f;      // whole pixels, so that the caret is sharp wherever it stands
constexpr uint32_t kPaintOrder = 60000;  // after the sign's

// Text colours are sRGB (as crisp takes them); panel colours are linear (the scene target's).
constexpr std::array<float, 4> kTextColor = {0.94f, 0.95f, 0.97f, 1.0f};
constexpr std::array<float, 4> kFieldPanel = {0.002f, 0.003f, 0.006f, 0.90f};
constexpr std::array<float, 4> kFocusedPanel = {0.008f, 0.012f, 0.030f, 0.95f};
constexpr std::array<float, 4> kSelectionPanel = {0.05f, 0.20f, 0.60f, 1.0f};
constexpr std::array<float, 4> kCaretPanel = {1.0f, 0.45f, 0.05f, 1.0f};

// The length of a valid UTF-8 sequence starting at text[i], or 0 where none starts there.
size_t utf8_sequence(std::string_view text, size_t i) {
    const auto byte = [&](size_t k) { return k < text.size() ? static_cast<unsigned char>(text[k]) : 0u; };
    const unsigned lead = byte(i);
    const auto continuation = [&](size_t k) { return (byte(k) & 0xC0u) == 0x80u; };
    if (lead < 0x80u) return 1;
    if (lead >= 0xC2u && lead <= 0xDFu) return continuation(i + 1) ? 2 : 0;
    if (lead >= 0xE0u && lead <= 0xEFu) {
        const unsigned second = byte(i + 1);
        // Overlong forms (E0 below A0) and surrogates (ED from A0) are not UTF-8.
        if ((lead == 0xE0u && second < 0xA0u) || (lead == 0xEDu && second >= 0xA0u)) return 0;
        return continuation(i + 1) && continuation(i + 2) ? 3 : 0;
    }
    if (lead >= 0xF0u && lead <= 0xF4u) {
        const unsigned second = byte(i + 1);
        if ((lead == 0xF0u && second < 0x90u) || (lead == 0xF4u && second >= 0x90u)) return 0;
        return continuation(i + 1) && continuation(i + 2) && continuation(i + 3) ? 4 : 0;
    }
    return 0;
}

// `codepoint` as UTF-8, appended to `out`. The caller has checked it is a scalar value.
void append_utf8(uint32_t codepoint, std::string& out) {
    if (codepoint < 0x80) {
        out += static_cast<char>(codepoint);
    } else if (codepoint < 0x800) {
        out += static_cast<char>(0xC0 | (codepoint >> 6));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    } else if (codepoint < 0x10000) {
        out += static_cast<char>(0xE0 | (codepoint >> 12));
        out += static_cast<char>(0x80 | ((codepoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (codepoint >> 18));
        out += static_cast<char>(0x80 | ((codepoint >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((codepoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codepoint & 0x3F));
    }
}

// The part of `rect` inside `clip`; nullopt when nothing is.
std::optional<FieldRect> intersect(const FieldRect& rect, const FieldRect& clip) {
    const float x0 = std::max(rect.x, clip.x), y0 = std::max(rect.y, clip.y);
    const float x1 = std::min(rect.x + rect.width, clip.x + clip.width);
    const float y1 = std::min(rect.y + rect.height, clip.y + clip.height);
    if (!(x1 > x0 && y1 > y0)) return std::nullopt;
    return FieldRect{x0, y0, x1 - x0, y1 - y0};
}

Panel panel_of(const FieldRect& rect, const std::array<float, 4>& color) {
    return {rect.x, rect.y, rect.width, rect.height, color};
}

}  // namespace

TextField::TextField(std::span<const crisp::Font* const> fonts, crisp::Layouter& layouter, uint32_t blink_ms)
    : fonts_(fonts), layouter_(layouter), blink_(blink_ms), touched_at_(std::chrono::steady_clock::now()) {}

crisp::Status TextField::set_text(std::string_view text) {
    size_t valid = 0;
    while (valid < text.size()) {
        const size_t length = utf8_sequence(text, valid);
        if (length == 0) {
            return crisp::Error{crisp::ErrorCode::invalid_argument,
                                "the text field's text is not UTF-8 at byte " + std::to_string(valid)};
        }
        if (valid + length > kFieldMaxBytes) break;
        valid += length;
    }
    text_.assign(text.substr(0, valid));
    if (crisp::Status s = lay_out(); !s) return s;
    caret_ = {static_cast<uint32_t>(text_.size()), false};
    anchor_ = caret_.offset;
    touched();
    return {};
}

crisp::Status TextField::lay_out() {
    crisp::TextStyle style;
    style.size = kTextSize;
    std::copy(kTextColor.begin(), kTextColor.end(), style.color);
    crisp::LayoutOptions options;
    options.first_paint_order = kPaintOrder;
    // A field is one line: no wrap width, and the text reads in the direction of its first strong
    // character, as a browser's dir="auto" input does.
    if (crisp::Status s = layouter_.layout(fonts_, text_, style, options, layout_); !s) return s;
    crisp::Result<crisp::TextBoundaries> boundaries = crisp::TextBoundaries::analyze(text_);
    if (!boundaries) return boundaries.error();
    boundaries_ = std::move(*boundaries);
    return {};
}

void TextField::place(FieldRect box) {
    box_ = box;
    scroll_to_caret();
}

uint32_t TextField::selection_begin() const {
    return std::min(anchor_, caret_.offset);
}

uint32_t TextField::selection_end() const {
    return std::max(anchor_, caret_.offset);
}

void TextField::replace_selection(std::string_view utf8) {
    const uint32_t begin = selection_begin(), end = selection_end();
    if (text_.size() - (end - begin) + utf8.size() > kFieldMaxBytes) return;
    if (begin == end && utf8.empty()) {  // Backspace at the start, Delete at the end: nothing changes
        touched();
        return;
    }
    std::string before = text_;
    text_.replace(begin, end - begin, utf8);
    // Valid UTF-8 within kFieldMaxBytes fails to lay out only where memory runs out: the edit is
    // then undone, so that the text, its layout and its boundaries stay one text.
    if (!lay_out()) {
        text_ = std::move(before);
        (void)lay_out();
        return;
    }
    caret_ = {static_cast<uint32_t>(begin + utf8.size()), false};
    anchor_ = caret_.offset;
    touched();
}

void TextField::move_caret(crisp::TextPosition position, bool extend) {
    caret_ = position;
    if (!extend) anchor_ = position.offset;
    touched();
}

void TextField::move_caret(crisp::CaretMotion motion, bool extend) {
    move_caret(
        crisp::move_caret(layout_, boundaries_, {caret_, std::numeric_limits<float>::quiet_NaN()}, motion).position,
        extend);
}

void TextField::touched() {
    touched_at_ = std::chrono::steady_clock::now();
    scroll_to_caret();
}

float TextField::origin_x() const {
    return box_.x + kPadding - scroll_;
}

// The font's ascender to descender, centred in the field: the baseline stays put whatever the
// text (empty text included), on a whole pixel.
float TextField::origin_y() const {
    const float ascent = fonts_.front()->ascender() * kTextSize, descent = -fonts_.front()->descender() * kTextSize;
    return std::round(box_.y + (box_.height - ascent - descent) / 2.0f + ascent);
}

// Keeps the caret inside the field's inner width, scrolling by whole pixels.
void TextField::scroll_to_caret() {
    const float inner = box_.width - 2.0f * kPadding;
    const crisp::TextRect caret = crisp::caret_rect(layout_, boundaries_, caret_, kCaretWidth);
    if (caret.x + kCaretWidth - scroll_ > inner) scroll_ = std::ceil(caret.x + kCaretWidth - inner);
    if (caret.x - scroll_ < 0.0f) scroll_ = std::floor(caret.x);
    const float widest = std::max(0.0f, std::ceil(layout_.x + layout_.width + kCaretWidth - inner));
    scroll_ = std::clamp(scroll_, 0.0f, widest);
}

crisp::TextPosition TextField::hit(float x, float y) const {
    return crisp::hit_test(layout_, boundaries_, x - origin_x(), y - origin_y()).position;
}

bool TextField::caret_shown() const {
    if (!focused_) return false;
    if (blink_.count() == 0) return true;
    const auto since =
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - touched_at_);
    return (since / blink_) % 2 == 0;
}

void TextField::type(uint32_t codepoint) {
    if (!focused_ || codepoint < 0x20 || (codepoint >= 0x7F && codepoint < 0xA0) ||
        (codepoint >= 0xD800 && codepoint < 0xE000) || codepoint > 0x10FFFF) {
        return;
    }
    std::string utf8;
    append_utf8(codepoint, utf8);
    replace_selection(utf8);
}

bool TextField::key(int key, int mods) {
    if (!focused_) return false;
    const bool shift = (mods & GLFW_MOD_SHIFT) != 0, control = (mods & GLFW_MOD_CONTROL) != 0;
    const bool selection = selection_begin() != selection_end();
    switch (key) {
        case GLFW_KEY_BACKSPACE:
        case GLFW_KEY_DELETE:
            if (!selection) {
                const uint32_t next = key == GLFW_KEY_DELETE ? boundaries_.next_grapheme(caret_.offset)
                                                             : boundaries_.previous_grapheme(caret_.offset);
                anchor_ = next;
            }
            replace_selection({});
            return true;
        case GLFW_KEY_LEFT:
        case GLFW_KEY_RIGHT: {
            const bool right = key == GLFW_KEY_RIGHT;
            // On screen, by grapheme or (Ctrl) by word, through either direction.
            const crisp::CaretMotion motion =
                !control ? (right ? crisp::CaretMotion::right : crisp::CaretMotion::left)
                         : (right ? crisp::CaretMotion::word_right : crisp::CaretMotion::word_left);
            move_caret(motion, shift);
            return true;
        }
        case GLFW_KEY_HOME:
        case GLFW_KEY_END:
            move_caret(key == GLFW_KEY_END ? crisp::CaretMotion::line_end : crisp::CaretMotion::line_start, shift);
            return true;
        case GLFW_KEY_A:
            if (!control) return false;
            anchor_ = 0;
            move_caret({static_cast<uint32_t>(text_.size()), false}, true);
            return true;
        case GLFW_KEY_ESCAPE:
            focused_ = false;
            dragging_ = false;
            return true;
        default:
            return false;
    }
}

bool TextField::press(float x, float y, bool shift) {
    const bool inside = x >= box_.x && x < box_.x + box_.width && y >= box_.y && y < box_.y + box_.height;
    if (!inside) {
        focused_ = false;
        dragging_ = false;
        return false;
    }
    // Shift+click extends from the anchor only in a field that has the focus (and so a caret).
    move_caret(hit(x, y), shift && focused_);
    focused_ = true;
    dragging_ = true;
    return true;
}

void TextField::drag(float x, float y) {
    if (!dragging_) return;
    move_caret(hit(x, y), true);
}

void TextField::draw(crisp::Renderer& renderer, std::vector<Panel>& panels, uint64_t id) {
    // The text and the selection show inside the padding's inner half (a caret at either end fits).
    const FieldRect inner{box_.x + kPadding / 2.0f, box_.y, std::max(box_.width - kPadding, 0.0f), box_.height};
    const float dx = origin_x(), dy = origin_y();
    report_ = {};
    report_.text = text_;
    report_.focused = focused_;
    report_.caret = caret_.offset;
    report_.caret_upstream = caret_.upstream;
    report_.anchor = anchor_;
    report_.box = box_;
    report_.text_x = dx + (layout_.lines.empty() ? 0.0f : layout_.lines.front().x);
    report_.baseline_y = dy;
    panels.push_back(panel_of(box_, focused_ ? kFocusedPanel : kFieldPanel));

    std::vector<crisp::TextRect> rects;
    crisp::selection_rects(layout_, boundaries_, selection_begin(), selection_end(), rects);
    for (const crisp::TextRect& rect : rects) {
        const std::optional<FieldRect> shown = intersect({rect.x + dx, rect.y + dy, rect.width, rect.height}, inner);
        if (!shown) continue;
        panels.push_back(panel_of(*shown, kSelectionPanel));
        report_.selection_rects.push_back(*shown);
    }

    const crisp::TextRect caret = crisp::caret_rect(layout_, boundaries_, caret_, kCaretWidth);
    report_.caret_rect = {std::round(caret.x + dx), std::round(caret.y + dy), kCaretWidth, std::round(caret.height)};
    report_.caret_visible = caret_shown();
    if (report_.caret_visible) panels.push_back(panel_of(report_.caret_rect, kCaretPanel));

    crisp::DrawOptions options;
    options.offset_x = dx;
    options.offset_y = dy;
    options.visible = VkRect2D{{static_cast<int32_t>(inner.x), static_cast<int32_t>(inner.y)},
                               {static_cast<uint32_t>(inner.width), static_cast<uint32_t>(inner.height)}};
    options.id = id;
    renderer.draw(layout_.glyphs, options);
}

}  // namespace engine
