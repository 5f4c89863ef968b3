// Decoding and itemization for layout: bidi levels (FriBidi), scripts and font fallback.
#include "text/itemize.hpp"

#include "text/emoji.hpp"

#include <fribidi.h>

#include <algorithm>

namespace crisp::detail {

namespace {

// Breaking spaces (UAX #14 SP and BA spaces): they hang at a line's end and a line may break
// after them. NO-BREAK SPACE, FIGURE SPACE and NARROW NO-BREAK SPACE are deliberately absent.
bool is_breaking_space(uint32_t cp) {
    return cp == 0x20 || cp == 0x09 || cp == 0x1680 || (cp >= 0x2000 && cp <= 0x2006) ||
           (cp >= 0x2008 && cp <= 0x200A) || cp == 0x205F || cp == 0x3000;
}

// Joiners and variation selectors: HarfBuzz consumes them with the preceding character.
bool is_joiner_or_selector(uint32_t cp) {
    return cp == 0x200C || cp == 0x200D || (cp >= 0xFE00 && cp <= 0xFE0F) || (cp >= 0x180B && cp <= 0x180D) ||
           cp == 0x180F || (cp >= 0xE0100 && cp <= 0xE01EF);
}

bool is_mark(hb_unicode_funcs_t* unicode, uint32_t cp) {
    if (cp < 0x300) return false;  // nothing below U+0300 is a mark
    const hb_unicode_general_category_t category = hb_unicode_general_category(unicode, cp);
    return category == HB_UNICODE_GENERAL_CATEGORY_NON_SPACING_MARK ||
           category == HB_UNICODE_GENERAL_CATEGORY_SPACING_MARK ||
           category == HB_UNICODE_GENERAL_CATEGORY_ENCLOSING_MARK;
}

bool is_letter(hb_unicode_funcs_t* unicode, uint32_t cp) {
    if (cp < 0x80) return (cp | 0x20) >= 'a' && (cp | 0x20) <= 'z';
    const hb_unicode_general_category_t category = hb_unicode_general_category(unicode, cp);
    return category == HB_UNICODE_GENERAL_CATEGORY_LOWERCASE_LETTER ||
           category == HB_UNICODE_GENERAL_CATEGORY_UPPERCASE_LETTER ||
           category == HB_UNICODE_GENERAL_CATEGORY_TITLECASE_LETTER ||
           category == HB_UNICODE_GENERAL_CATEGORY_MODIFIER_LETTER ||
           category == HB_UNICODE_GENERAL_CATEGORY_OTHER_LETTER;
}

// Characters a line may break before and after without a space between (UAX #14 ID, and H2/H3
// for Hangul syllables): CJK ideographs, kana, Hangul, ideographic symbols.
bool breaks_around(uint32_t cp) {
    if (cp < 0x2E80) return false;
    return (cp >= 0x2E80 && cp <= 0x2FFF) || (cp >= 0x3040 && cp <= 0x30FF) || (cp >= 0x3400 && cp <= 0x4DBF) ||
           (cp >= 0x4E00 && cp <= 0x9FFF) || (cp >= 0xAC00 && cp <= 0xD7A3) || (cp >= 0xF900 && cp <= 0xFAFF) ||
           (cp >= 0xFF66 && cp <= 0xFF9D) || (cp >= 0x20000 && cp <= 0x3FFFD);
}

// Closing punctuation, and characters like 、。ー that must not start a line (UAX #14 CL, CP, EX,
// IS, NS: the common ones).
bool no_break_before(uint32_t cp) {
    switch (cp) {
        case ')':
        case ']':
        case '}':
        case '!':
        case ',':
        case '.':
        case ':':
        case ';':
        case '?':
        case '%':
        case 0x3001:
        case 0x3002:
        case 0xFF0C:
        case 0xFF0E:
        case 0xFF1A:
        case 0xFF1B:
        case 0xFF01:
        case 0xFF1F:
        case 0xFF09:
        case 0x300D:
        case 0x300F:
        case 0x3011:
        case 0x3015:
        case 0x3009:
        case 0x300B:
        case 0x3019:
        case 0x3017:
        case 0x301B:
        case 0xFF5D:
        case 0xFF3D:
        case 0x30FB:
        case 0x30FC:
        case 0x3005:
        case 0x309D:
        case 0x309E:
        case 0x30FD:
        case 0x30FE:
            return true;
        default:
            return false;
    }
}

// Opening punctuation that must not end a line (UAX #14 OP: the common ones).
bool no_break_after(uint32_t cp) {
    switch (cp) {
        case '(':
        case '[':
        case '{':
        case 0xFF08:
        case 0x300C:
        case 0x300E:
        case 0x3010:
        case 0x3014:
        case 0x3008:
        case 0x300A:
        case 0x3018:
        case 0x3016:
        case 0x301A:
        case 0xFF5B:
        case 0xFF3B:
        case 0x201C:
        case 0x2018:
            return true;
        default:
            return false;
    }
}

bool is_hyphen(uint32_t cp) {
    return cp == '-' || cp == 0x2010 || cp == 0x2012 || cp == 0x2013;
}

}  // namespace

bool is_default_ignorable(uint32_t cp) {
    const auto in = [cp](uint32_t first, uint32_t last) { return cp >= first && cp <= last; };
    if (cp < 0x2000) {
        return cp == 0xAD || cp == 0x34F || cp == 0x61C || in(0x115F, 0x1160) || in(0x17B4, 0x17B5) ||
               in(0x180B, 0x180F);
    }
    return in(0x200B, 0x200F) || in(0x202A, 0x202E) || in(0x2060, 0x206F) || cp == 0x3164 || in(0xFE00, 0xFE0F) ||
           cp == 0xFEFF || cp == 0xFFA0 || in(0xFFF0, 0xFFF8) || in(0x1BCA0, 0x1BCA3) || in(0x1D173, 0x1D17A) ||
           in(0xE0000, 0xE0FFF);
}

void classify(std::span<const uint32_t> text, std::span<uint8_t> flags) {
    hb_unicode_funcs_t* unicode = hb_unicode_funcs_get_default();
    const size_t n = text.size();
    for (size_t i = 0; i < n; ++i) {
        const uint32_t cp = text[i];
        uint8_t f = 0;
        if (is_breaking_space(cp)) f |= kCharSpace;
        if (cp == 0x09) f |= kCharTab;
        if (is_joiner_or_selector(cp) || is_mark(unicode, cp)) f |= kCharAttached;
        if (cp < 0x80) {
            if (!is_letter(unicode, cp)) f |= kCharCommon;
        } else {
            const hb_script_t script = hb_unicode_script(unicode, cp);
            if (script == HB_SCRIPT_COMMON || script == HB_SCRIPT_INHERITED || script == HB_SCRIPT_UNKNOWN)
                f |= kCharCommon;
        }
        flags[i] = f;
    }
    for (size_t i = 0; i < n;) {
        const size_t end = emoji_sequence_end(text, i);
        for (size_t k = i + 1; k < end; ++k) flags[k] |= kCharEmojiNext;
        i = end;
    }
    // Break opportunities (a subset of UAX #14). Never inside a cluster or an emoji sequence, never
    // before a space (spaces hang), after every run of spaces, after a zero width space, after a
    // hyphen between letters, and around ideographs unless punctuation forbids it.
    for (size_t i = 1; i < n; ++i) {
        const uint32_t prev = text[i - 1], cp = text[i];
        if ((flags[i] & (kCharAttached | kCharEmojiNext | kCharSpace)) != 0) continue;
        bool opportunity = false;
        if ((flags[i - 1] & kCharSpace) != 0 || prev == 0x200B) {
            opportunity = true;
        } else if (is_hyphen(prev)) {
            opportunity = i >= 2 && is_letter(unicode, text[i - 2]) && is_letter(unicode, cp);
        } else if (breaks_around(prev) || breaks_around(cp)) {
            opportunity = !no_break_before(cp) && !no_break_after(prev);
        }
        if (opportunity) flags[i] |= kCharBreakBefore;
    }
}

uint8_t resolve_levels(std::span<const uint32_t> text, Direction direction, BidiScratch& scratch,
                       std::span<uint8_t> levels) {
    const uint8_t forced = direction == Direction::rtl ? 1 : 0;
    // Nothing below U+0590 is right-to-left (no R, AL, AN, nor an explicit embedding): most UI
    // text skips FriBidi.
    if (direction != Direction::rtl && std::all_of(text.begin(), text.end(), [](uint32_t cp) { return cp < 0x590; })) {
        std::fill(levels.begin(), levels.end(), uint8_t{0});
        return 0;
    }
    const size_t n = text.size();
    scratch.types.resize(n);
    scratch.brackets.resize(n);
    scratch.levels.resize(n);
    // The caller bounds the text to INT32_MAX bytes, so the length fits FriBidiStrIndex.
    const auto length = static_cast<FriBidiStrIndex>(n);
    fribidi_get_bidi_types(text.data(), length, scratch.types.data());
    fribidi_get_bracket_types(text.data(), length, scratch.types.data(), scratch.brackets.data());
    FriBidiParType base = direction == Direction::ltr   ? static_cast<FriBidiParType>(FRIBIDI_PAR_LTR)
                          : direction == Direction::rtl ? static_cast<FriBidiParType>(FRIBIDI_PAR_RTL)
                                                        : static_cast<FriBidiParType>(FRIBIDI_PAR_ON);
    const FriBidiLevel max_level = fribidi_get_par_embedding_levels_ex(scratch.types.data(), scratch.brackets.data(),
                                                                       length, &base, scratch.levels.data());
    if (max_level == 0) {
        // FriBidi failed (out of memory): lay out in the requested direction, unreordered.
        std::fill(levels.begin(), levels.end(), forced);
        return forced;
    }
    for (size_t i = 0; i < n; ++i) levels[i] = static_cast<uint8_t>(std::max<FriBidiLevel>(scratch.levels[i], 0));
    return base == static_cast<FriBidiParType>(FRIBIDI_PAR_RTL) ? 1 : 0;
}

void resolve_scripts(std::span<const uint32_t> text, std::span<const uint8_t> flags, std::span<hb_script_t> scripts) {
    hb_unicode_funcs_t* unicode = hb_unicode_funcs_get_default();
    hb_script_t current = HB_SCRIPT_INVALID;
    for (size_t i = 0; i < text.size(); ++i) {
        if ((flags[i] & kCharCommon) != 0) {
            scripts[i] = current;  // INVALID until the first real script, filled in below
            continue;
        }
        const uint32_t cp = text[i];
        const hb_script_t script = cp < 0x80 ? HB_SCRIPT_LATIN : hb_unicode_script(unicode, cp);
        if (current == HB_SCRIPT_INVALID)
            std::fill(scripts.begin(), scripts.begin() + static_cast<ptrdiff_t>(i), script);
        current = script;
        scripts[i] = script;
    }
    if (current == HB_SCRIPT_INVALID) std::fill(scripts.begin(), scripts.end(), HB_SCRIPT_COMMON);
}

namespace {

// Whether font `font` can show `mark` on `base`: it has the mark, or the precomposed character
// HarfBuzz's normalizer would compose them into, or the mark is a joiner or selector, which
// HarfBuzz consumes without a glyph of its own.
bool covers_mark(const Font& font, hb_unicode_funcs_t* unicode, uint32_t base, uint32_t mark) {
    if (is_joiner_or_selector(mark) || font.has_glyph_for(mark)) return true;
    hb_codepoint_t composed = 0;
    return hb_unicode_compose(unicode, base, mark, &composed) && font.has_glyph_for(composed);
}

}  // namespace

void choose_fonts(std::span<const Font* const> fonts, std::span<const uint32_t> text, std::span<const uint8_t> flags,
                  std::span<uint16_t> font_of) {
    const size_t n = text.size();
    if (fonts.size() == 1) {
        std::fill(font_of.begin(), font_of.end(), uint16_t{0});
        return;
    }
    hb_unicode_funcs_t* unicode = hb_unicode_funcs_get_default();
    const auto font_count = static_cast<uint16_t>(fonts.size());
    size_t i = 0;
    while (i < n) {
        // A cluster for font choice: a base and the marks, joiners and selectors after it, or a
        // whole emoji sequence.
        size_t sequence_end = i + 1;
        while (sequence_end < n && (flags[sequence_end] & kCharEmojiNext) != 0) ++sequence_end;
        size_t end = sequence_end;
        while (end < n && (flags[end] & (kCharAttached | kCharEmojiNext)) != 0) ++end;
        const uint32_t base = text[i];
        const Presentation presentation = emoji_presentation(text.subspan(i, sequence_end - i));
        auto covers_cluster = [&](uint16_t f) {
            for (size_t k = i + 1; k < end; ++k)
                if (!covers_mark(*fonts[f], unicode, base, text[k])) return false;
            return true;
        };
        // Text presentation wants the base as a plain outline.
        auto shows_base = [&](uint16_t f, bool plain) {
            return fonts[f]->has_glyph_for(base) && !(plain && fonts[f]->has_colour_glyph_for(base));
        };

        uint16_t chosen = font_count;
        if (presentation == Presentation::emoji) {
            for (uint16_t f = 0; f < font_count && chosen == font_count; ++f)
                if (fonts[f]->has_colour_glyph_for(base)) chosen = f;
        }
        if (chosen == font_count && (flags[i] & kCharCommon) != 0 && i > 0 &&
            shows_base(font_of[i - 1], presentation == Presentation::text) && covers_cluster(font_of[i - 1])) {
            // Spaces, digits and punctuation stay in the font of the text around them, so a run is
            // not cut at every space between two words of a fallback font.
            chosen = font_of[i - 1];
        }
        uint16_t first_with_base = font_count;
        for (int pass = presentation == Presentation::text ? 0 : 1; pass < 2 && chosen == font_count; ++pass) {
            for (uint16_t f = 0; f < font_count; ++f) {
                if (!shows_base(f, pass == 0)) continue;
                if (first_with_base == font_count) first_with_base = f;
                if (end == i + 1 || covers_cluster(f)) {
                    chosen = f;
                    break;
                }
            }
        }
        // No font shows the whole cluster: the base's font; no font has the base: the first,
        // whose .notdef it becomes.
        if (chosen == font_count) chosen = first_with_base == font_count ? uint16_t{0} : first_with_base;
        font_of[i] = chosen;
        for (size_t k = i + 1; k < end; ++k) {
            // An emoji sequence stays whole in its font (HarfBuzz shapes what it can of it). A mark
            // the chosen font cannot show comes from the first font that has it (it then sits in a
            // run of its own, unattached); a mark no font has stays with its base.
            uint16_t mark_font = chosen;
            if (k >= sequence_end && !covers_mark(*fonts[chosen], unicode, base, text[k])) {
                for (uint16_t f = 0; f < font_count; ++f) {
                    if (fonts[f]->has_glyph_for(text[k])) {
                        mark_font = f;
                        break;
                    }
                }
            }
            font_of[k] = mark_font;
        }
        i = end;
    }
}

}  // namespace crisp::detail
