// Layout: validating, shaping runs with HarfBuzz and turning pen positions into glyph keys and
// rects; lines are broken, ordered, placed and aligned in text/lines.cpp, itemized in itemize.cpp.
#include "text/layout_state.hpp"

#include <hb.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <utility>

namespace crisp {

using namespace detail;

namespace {

Error invalid(std::string message) {
    return Error{ErrorCode::invalid_argument, std::move(message)};
}

// The shortest text that reads back as `value` (1.4e-45, not the 0 of a fixed six decimals).
std::string show(float value) {
    if (std::isnan(value)) return "NaN";
    if (std::isinf(value)) return value > 0 ? "infinity" : "-infinity";
    char text[32];
    const auto written = std::to_chars(text, text + sizeof text, value);
    return std::string(text, written.ptr);
}

Status check_size(const char* name, float size) {
    if (!std::isfinite(size) || !(size > 0.0f) || size > kMaxTextSize)
        return invalid(std::string("layout: ") + name + " is " + show(size) +
                       "; it must be a finite number of pixels per em in (0, 4096]");
    return {};
}

// A size in glyph keys' 1/256 px, at least one: a size below it is laid out and drawn as 1/256 px
// per em (far below a pixel either way), as transformed keys are.
uint32_t key_size(double size) {
    return std::max(1u, static_cast<uint32_t>(std::lround(size * kSizeOne)));
}

Status check_finite(const char* name, float value) {
    if (!std::isfinite(value))
        return invalid(std::string("layout: ") + name + " is " + show(value) + "; it must be finite");
    return {};
}

// The checks of a style, named `name` ("style", "spans[3].style") in messages.
Status check_style(const std::string& name, const TextStyle& style, float scale) {
    const std::string prefix = name + ".";
    if (Status status = check_size((prefix + "size").c_str(), style.size); !status) return status;
    if (style.size_y != 0.0f) {
        if (Status status = check_size((prefix + "size_y").c_str(), style.size_y); !status) return status;
    }
    const float tallest = std::max(style.size, style.size_y);
    if (static_cast<double>(tallest) * static_cast<double>(scale) > static_cast<double>(kMaxTextSize))
        return invalid("layout: " + prefix + "size times options.scale is " +
                       show(static_cast<float>(static_cast<double>(tallest) * static_cast<double>(scale))) +
                       " pixels per em, more than 4096");
    const std::pair<const char*, float> finite[] = {
        {"color[0]", style.color[0]},
        {"color[1]", style.color[1]},
        {"color[2]", style.color[2]},
        {"color[3]", style.color[3]},
        {"depth", style.depth},
        {"letter_spacing", style.letter_spacing},
        {"baseline_shift", style.baseline_shift},
    };
    for (const auto& [member, value] : finite) {
        if (Status status = check_finite((prefix + member).c_str(), value); !status) return status;
    }
    if (std::abs(style.letter_spacing) > style.size)
        return invalid("layout: " + prefix + "letter_spacing is " + show(style.letter_spacing) +
                       "; it must lie within one size (" + show(style.size) + ") either way");
    if (std::abs(style.baseline_shift) > 4.0f * tallest)
        return invalid("layout: " + prefix + "baseline_shift is " + show(style.baseline_shift) +
                       "; it must lie within four sizes (" + show(4.0f * tallest) + ") either way");
    for (size_t i = 0; i < style.fonts.size(); ++i) {
        if (style.fonts[i] == nullptr) return invalid("layout: " + prefix + "fonts[" + std::to_string(i) + "] is null");
    }
    for (size_t i = 0; i < style.features.size(); ++i) {
        for (const char letter : style.features[i].tag) {
            if (letter < 0x20 || letter > 0x7E)
                return invalid("layout: " + prefix + "features[" + std::to_string(i) +
                               "] has a tag that is not four printable ASCII characters");
        }
    }
    return {};
}

Status validate(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                const LayoutOptions& options) {
    if (fonts.empty()) return invalid("layout: the font list is empty; pass at least one font");
    if (fonts.size() > 65535)
        return invalid("layout: " + std::to_string(fonts.size()) + " fonts, at most 65535 are supported");
    for (size_t i = 0; i < fonts.size(); ++i) {
        if (fonts[i] == nullptr) return invalid("layout: fonts[" + std::to_string(i) + "] is null");
        for (size_t j = 0; j < i; ++j) {
            if (fonts[j] != fonts[i] && fonts[j]->id() == fonts[i]->id())
                return invalid("layout: fonts[" + std::to_string(j) + "] and fonts[" + std::to_string(i) +
                               "] are different fonts with the same FontId " + std::to_string(fonts[i]->id()) +
                               "; their glyph keys would collide");
        }
    }
    const std::pair<const char*, float> finite[] = {
        {"options.origin_x", options.origin_x},       {"options.origin_y", options.origin_y},
        {"options.wrap_width", options.wrap_width},   {"options.scale", options.scale},
        {"options.line_height", options.line_height}, {"options.line_spacing", options.line_spacing},
    };
    for (const auto& [name, value] : finite) {
        if (Status status = check_finite(name, value); !status) return status;
    }
    if (!(options.scale > 0.0f) || options.scale > 64.0f)
        return invalid("layout: options.scale is " + show(options.scale) + "; it must lie in (0, 64]");
    if (Status status = check_style("style", style, options.scale); !status) return status;
    if (options.wrap_width < 0.0f)
        return invalid("layout: options.wrap_width is " + show(options.wrap_width) +
                       "; it must be 0 (no wrapping) or positive");
    if (options.line_height < 0.0f || options.line_height > 16.0f * kMaxTextSize)
        return invalid("layout: options.line_height is " + show(options.line_height) +
                       "; it must be 0 (from the fonts) or a positive number of pixels up to 65536");
    if (!(options.line_spacing > 0.0f) || options.line_spacing > 16.0f)
        return invalid("layout: options.line_spacing is " + show(options.line_spacing) + "; it must lie in (0, 16]");
    float previous_stop = 0.0f;
    for (size_t i = 0; i < options.tab_stops.size(); ++i) {
        const float stop = options.tab_stops[i];
        if (!std::isfinite(stop) || !(stop > previous_stop) || static_cast<double>(stop) > kMaxCoordinate)
            return invalid("layout: options.tab_stops[" + std::to_string(i) + "] is " + show(stop) +
                           "; tab stops must be finite, positive and increasing");
        previous_stop = stop;
    }
    const uint32_t steps = options.subpixel_steps;
    if (steps == 0 || steps > kSubpixelSteps || (steps & (steps - 1)) != 0)
        return invalid("layout: options.subpixel_steps is " + std::to_string(steps) +
                       "; it must be a power of two from 1 to 256");
    if (utf8.size() > kMaxTextBytes)
        return invalid("layout: the text is " + std::to_string(utf8.size()) + " bytes, more than the " +
                       std::to_string(kMaxTextBytes) + " supported");
    return {};
}

// Splits a pen coordinate into its whole pixel and a subpixel offset on a grid of `steps` per
// pixel, in u0.8. An offset that rounds up to a whole pixel carries into it.
void quantize(double pen, uint32_t steps, int32_t& whole, uint8_t& subpixel) {
    double base = std::floor(pen);
    double step = std::round((pen - base) * steps);
    if (step >= steps) {
        base += 1.0;
        step = 0.0;
    }
    whole = static_cast<int32_t>(base);
    subpixel = static_cast<uint8_t>(static_cast<uint32_t>(step) * (kSubpixelSteps / steps));
}

// Empties a layout, keeping its vectors' memory.
void reset(TextLayout& out, uint32_t first_paint_order) {
    out.glyphs.clear();
    out.lines.clear();
    out.decorations.clear();
    out.clusters.clear();
    out.x = out.y = out.width = out.height = out.line_height = 0.0f;
    out.trimmed = false;
    out.shaped_glyphs = out.missing_glyphs = out.blank_glyphs = out.out_of_range_glyphs = out.mark_splits = 0;
    out.ignorable_splits = 0;
    out.colour_glyphs = out.colour_layers = 0;
    out.next_paint_order = first_paint_order;
}

constexpr GlyphRecord kNoOutline{};

// The layers of face glyph `glyph`'s colour glyph, with its index in `colour_index`; empty where it
// has none or (only with an inconsistent asset) its layers run past the asset's.
std::span<const ColourLayer> colour_layers(const FontAsset& asset, uint32_t glyph, uint32_t& colour_index) {
    const ColourGlyph* colour = asset.colour_glyph(glyph);
    if (colour == nullptr || uint64_t{colour->first_layer} + colour->layer_count > asset.layers.size()) return {};
    colour_index = static_cast<uint32_t>(colour - asset.colour_glyphs.data());
    return std::span(asset.layers).subspan(colour->first_layer, colour->layer_count);
}

}  // namespace

float srgb_to_linear(float encoded) {
    const double c = static_cast<double>(encoded);
    return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

bool Layouter::State::resolve_styles(std::span<const Font* const> font_list, const TextStyle& base,
                                     std::span<const TextSpan> spans) {
    const LayoutOptions& o = *options;
    const double scale = static_cast<double>(o.scale);
    all_fonts.assign(font_list.begin(), font_list.end());
    font_map.clear();
    styles.clear();
    features.clear();
    font_index.clear();
    font_by_id.clear();
    for (size_t i = 0; i < font_list.size(); ++i) {
        font_index.emplace(font_list[i], static_cast<uint16_t>(i));
        font_by_id.emplace(font_list[i]->id(), font_list[i]);
    }
    // Byte offsets to code points, walking the spans in order: a span's ends must be code point
    // boundaries (offsets holds every one, and the text's size).
    size_t cursor = 0;
    auto code_point_at = [&](uint32_t byte, size_t& index) {
        while (cursor < offsets.size() && offsets[cursor] < byte) ++cursor;
        index = cursor;
        return cursor < offsets.size() && offsets[cursor] == byte;
    };
    std::fill(style_of.begin(), style_of.end(), 0u);
    auto add_style = [&](const TextStyle& style) -> bool {
        StyleView view;
        view.style = &style;
        const bool own_list =
            !style.fonts.empty() && !(style.fonts.data() == font_list.data() && style.fonts.size() == font_list.size());
        if (!own_list) {
            view.font_map = UINT32_MAX;
            view.font_count = static_cast<uint16_t>(font_list.size());
        } else if (!styles.empty() && styles.back().font_map != UINT32_MAX &&
                   std::equal(style.fonts.begin(), style.fonts.end(), styles.back().style->fonts.begin(),
                              styles.back().style->fonts.end())) {
            view.font_map = styles.back().font_map;  // the span before had this list too
            view.font_count = styles.back().font_count;
        } else {
            if (style.fonts.size() > 65535) {
                failure = "layout: a span's font list has " + std::to_string(style.fonts.size()) +
                          " fonts, at most 65535 are supported";
                return false;
            }
            view.font_map = static_cast<uint32_t>(font_map.size());
            view.font_count = static_cast<uint16_t>(style.fonts.size());
            for (const Font* font : style.fonts) {
                auto [found, added] = font_index.emplace(font, static_cast<uint16_t>(all_fonts.size()));
                if (added) {
                    if (all_fonts.size() >= 65535) {
                        failure = "layout: the spans' font lists hold more than 65535 different fonts";
                        return false;
                    }
                    auto [same_id, fresh] = font_by_id.emplace(font->id(), font);
                    if (!fresh) {
                        failure = "layout: two different fonts of the font lists have the same FontId " +
                                  std::to_string(font->id()) + "; their glyph keys would collide";
                        return false;
                    }
                    all_fonts.push_back(font);
                }
                font_map.push_back(found->second);
            }
        }
        view.feature_begin = static_cast<uint32_t>(features.size());
        view.feature_count = static_cast<uint32_t>(style.features.size());
        for (const FontFeature& feature : style.features) {
            const auto tag = static_cast<hb_tag_t>((uint32_t{static_cast<uint8_t>(feature.tag[0])} << 24) |
                                                   (uint32_t{static_cast<uint8_t>(feature.tag[1])} << 16) |
                                                   (uint32_t{static_cast<uint8_t>(feature.tag[2])} << 8) |
                                                   uint32_t{static_cast<uint8_t>(feature.tag[3])});
            features.push_back({tag, feature.value, HB_FEATURE_GLOBAL_START, HB_FEATURE_GLOBAL_END});
        }
        const auto px = [&](float logical) {
            const double value = static_cast<double>(logical) * scale;
            return static_cast<float>(o.snap_to_pixels ? std::round(value) : value);
        };
        view.size_x_fixed = key_size(static_cast<double>(style.size) * scale);
        view.size_y_fixed = key_size(static_cast<double>(style.size_y == 0.0f ? style.size : style.size_y) * scale);
        view.size_x = static_cast<double>(view.size_x_fixed) / kSizeOne;
        view.size_y = static_cast<double>(view.size_y_fixed) / kSizeOne;
        for (int c = 0; c < 3; ++c) view.color[c] = srgb_to_linear(std::clamp(style.color[c], 0.0f, 1.0f));
        view.color[3] = std::clamp(style.color[3], 0.0f, 1.0f);
        view.letter_spacing = px(style.letter_spacing);
        view.baseline_shift = px(style.baseline_shift);
        const Font& first = own_list ? *style.fonts[0] : *font_list[0];
        const double shift = static_cast<double>(view.baseline_shift);
        view.above = static_cast<double>(first.ascender()) * view.size_y + shift;
        view.descent = -static_cast<double>(first.descender()) * view.size_y - shift;
        view.gap = static_cast<double>(first.line_gap()) * view.size_y;
        if (styles.empty()) {
            strut_above = view.above - shift;
            strut_descent = view.descent + shift;
            strut_below = strut_descent + view.gap;
            strut_height = static_cast<double>(first.line_height()) * view.size_y;
        }
        styles.push_back(view);
        return true;
    };
    if (!add_style(base)) return false;
    uint32_t previous_end = 0;
    for (size_t k = 0; k < spans.size(); ++k) {
        const TextSpan& span = spans[k];
        const std::string name = "spans[" + std::to_string(k) + "]";
        if (span.end < span.begin) {
            failure = "layout: " + name + " ends (byte " + std::to_string(span.end) + ") before it begins (byte " +
                      std::to_string(span.begin) + ")";
            return false;
        }
        if (span.end > offsets.back()) {
            failure = "layout: " + name + " ends at byte " + std::to_string(span.end) + ", past the text's " +
                      std::to_string(offsets.back()) + " bytes";
            return false;
        }
        if (span.begin < previous_end) {
            failure = "layout: " + name + " begins at byte " + std::to_string(span.begin) +
                      ", inside the span before it (which ends at byte " + std::to_string(previous_end) +
                      "): spans must be in order and must not overlap";
            return false;
        }
        if (Status status = check_style(name + ".style", span.style, o.scale); !status) {
            failure = status.error().message;
            return false;
        }
        size_t first = 0, last = 0;
        if (!code_point_at(span.begin, first) || !code_point_at(span.end, last)) {
            failure = "layout: " + name + " " + (offsets[first] == span.begin ? "ends" : "begins") + " at byte " +
                      std::to_string(offsets[first] == span.begin ? span.end : span.begin) +
                      ", inside a UTF-8 sequence: spans begin and end on code point boundaries";
            return false;
        }
        previous_end = span.end;
        if (span.begin == span.end) continue;
        if (!add_style(span.style)) return false;
        std::fill(style_of.begin() + static_cast<ptrdiff_t>(first), style_of.begin() + static_cast<ptrdiff_t>(last),
                  static_cast<uint32_t>(styles.size() - 1));
    }
    fonts = all_fonts;
    return true;
}

bool Layouter::State::same_shaping(uint32_t a, uint32_t b) const {
    if (a == b) return true;
    const StyleView& x = styles[a];
    const StyleView& y = styles[b];
    if (x.size_x_fixed != y.size_x_fixed || x.size_y_fixed != y.size_y_fixed || x.feature_count != y.feature_count)
        return false;
    for (uint32_t i = 0; i < x.feature_count; ++i) {
        const hb_feature_t& f = features[x.feature_begin + i];
        const hb_feature_t& g = features[y.feature_begin + i];
        if (f.tag != g.tag || f.value != g.value) return false;
    }
    return true;
}

// The font of every character of the paragraph, in all_fonts: each stretch of one fallback list
// chooses in that list.
void Layouter::State::choose_paragraph_fonts(uint32_t p0, uint32_t p1) {
    const std::span<const uint32_t> text(codepoints);
    const std::span<const uint8_t> flag_span(flags);
    for (uint32_t begin = p0; begin < p1;) {
        const StyleView& view = styles[style_of[begin]];
        uint32_t end = begin + 1;
        while (end < p1 && styles[style_of[end]].font_map == view.font_map) ++end;
        const std::span<uint16_t> chosen(font_of.data() + begin, end - begin);
        if (view.font_map == UINT32_MAX) {
            choose_fonts(fonts.first(base_font_count), text.subspan(begin, end - begin),
                         flag_span.subspan(begin, end - begin), chosen);
        } else {
            choose_fonts(view.style->fonts, text.subspan(begin, end - begin), flag_span.subspan(begin, end - begin),
                         chosen);
            for (uint16_t& font : chosen) font = font_map[view.font_map + font];
        }
        begin = end;
    }
}

bool Layouter::State::shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
                            uint16_t font, uint32_t style) {
    // HarfBuzz (before 10.2, which lets the caller set it) stops a buffer at max(64 glyphs a
    // character, 16,384): a run it cannot hold is shaped again in halves, cut before a character
    // that starts a cluster, down to pieces of kPieceCharacters.
    constexpr uint32_t kPieceCharacters = 16;
    if (shape_once(p0, p1, begin, end, level, script, font, style)) {
        if (glyphs_shaped <= kMaxLayoutGlyphs) return true;
        failure = "layout: the text shapes into more than " + std::to_string(kMaxLayoutGlyphs) +
                  " glyphs (kMaxLayoutGlyphs) by its character " + std::to_string(end) + " of " +
                  std::to_string(codepoints.size()) +
                  (glyphs_shaped > 4 * size_t{end} ? ": its font's substitutions (GSUB) make many glyphs of a character"
                                                   : "");
        return false;
    }
    uint32_t middle = begin + (end - begin) / 2;
    while (middle > begin && (flags[middle] & (kCharAttached | kCharEmojiNext)) != 0) --middle;
    if (end - begin > kPieceCharacters && middle > begin) {
        return shape(p0, p1, begin, middle, level, script, font, style) &&
               shape(p0, p1, middle, end, level, script, font, style);
    }
    failure = "layout: shaping characters " + std::to_string(begin) + " to " + std::to_string(end) +
              " makes more glyphs than HarfBuzz's buffer holds (16384 for up to 256 characters, 64 a character "
              "past that): the font's substitutions (GSUB) multiply them";
    return false;
}

bool Layouter::State::shape_once(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level,
                                 hb_script_t script, uint16_t font, uint32_t style) {
    const StyleView& view = styles[style];
    const bool rtl = (level & 1) != 0;
    hb_buffer_clear_contents(buffer);
    hb_buffer_set_direction(buffer, rtl ? HB_DIRECTION_RTL : HB_DIRECTION_LTR);
    hb_buffer_set_script(buffer, script);
    if (language != nullptr) hb_buffer_set_language(buffer, language);
    // Beginning and end of text only at the paragraph's ends: elsewhere the neighbours are passed
    // as context, so Arabic joins across a change of font or level.
    unsigned buffer_flags = HB_BUFFER_FLAG_REMOVE_DEFAULT_IGNORABLES;
    if (begin == p0) buffer_flags |= HB_BUFFER_FLAG_BOT;
    if (end == p1) buffer_flags |= HB_BUFFER_FLAG_EOT;
    hb_buffer_set_flags(buffer, static_cast<hb_buffer_flags_t>(buffer_flags));
    hb_buffer_add_codepoints(buffer, codepoints.data() + p0, static_cast<int>(p1 - p0), begin - p0,
                             static_cast<int>(end - begin));
    hb_shape(fonts[font]->harfbuzz_font(), buffer, features.data() + view.feature_begin, view.feature_count);
    if (!hb_buffer_allocation_successful(buffer)) return false;

    unsigned count = 0;
    const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &count);
    glyphs_shaped += count;
    if (glyphs_shaped > kMaxLayoutGlyphs) return true;  // shape() says so
    const hb_glyph_position_t* positions = hb_buffer_get_glyph_positions(buffer, nullptr);
    const double per_unit = 1.0 / fonts[font]->units_per_em();
    const double scale_x = per_unit * view.size_x, scale_y = per_unit * view.size_y;
    const bool snap = options->snap_to_pixels;
    auto pixels = [snap](double value) { return static_cast<float>(snap ? std::round(value) : value); };
    // Grown geometrically: reserving exactly size + count here reallocated on every run (quadratic
    // in a paragraph of many runs).
    if (shaped.capacity() < shaped.size() + count)
        shaped.reserve(std::max(shaped.size() + count, 2 * shaped.capacity()));
    for (unsigned k = 0; k < count; ++k) {
        // HarfBuzz returns right-to-left runs in visual order; keep everything logical.
        const unsigned i = rtl ? count - 1 - k : k;
        ShapedGlyph glyph;
        glyph.glyph = infos[i].codepoint;
        glyph.cluster = p0 + infos[i].cluster;
        glyph.advance = pixels(positions[i].x_advance * scale_x);
        glyph.x_offset = pixels(positions[i].x_offset * scale_x);
        glyph.y_offset = pixels(positions[i].y_offset * scale_y);
        glyph.font = font;
        // What hb.h's hb_glyph_info_get_glyph_flags() macro reads, without its C casts.
        glyph.unsafe_to_break = (infos[i].mask & HB_GLYPH_FLAG_UNSAFE_TO_BREAK) != 0;
        const StyleView& own = styles[style_of[glyph.cluster]];
        glyph.y_offset += own.baseline_shift;
        // Letter spacing after each cluster, on the glyph of it placed last (lines are placed in
        // visual order): the last in logical order left to right, the first right to left.
        const bool placed_last = (rtl ? k == 0 : k + 1 == count) || infos[i + 1].cluster != infos[i].cluster;
        if (placed_last) glyph.advance += own.letter_spacing;
        shaped.push_back(glyph);
    }
    return true;
}

void Layouter::State::paragraph(uint32_t p0, uint32_t p1) {
    const LayoutOptions& o = *options;
    if (p0 == p1) {
        lines.push_back({p0, p1, 0.0, strut_above, strut_descent, strut_below, false, o.direction == Direction::rtl});
        if (o.max_lines != 0 && lines.size() >= o.max_lines) {
            stopped = true;
            for (size_t i = p1; i < codepoints.size() && !dropped; ++i) dropped = !is_hard_break(codepoints[i]);
        }
        return;
    }
    const size_t n = p1 - p0;
    std::span<const uint32_t> text(codepoints.data() + p0, n);
    std::span<uint8_t> paragraph_flags(flags.data() + p0, n);
    classify(text, paragraph_flags);
    const uint8_t base_level = resolve_levels(text, o.direction, bidi, std::span(levels.data() + p0, n));
    // An emoji sequence is one run: its joiners, selectors and tags (BN, NSM) and its flag's second
    // indicator could otherwise resolve apart from its first character.
    for (uint32_t i = p0 + 1; i < p1; ++i)
        if ((flags[i] & kCharEmojiNext) != 0) levels[i] = levels[i - 1];
    // Tabs are shaped as spaces (few fonts map U+0009) after bidi, which treats them as segment
    // separators; their width is set when the line is placed.
    for (size_t i = 0; i < n; ++i)
        if ((paragraph_flags[i] & kCharTab) != 0) codepoints[p0 + i] = ' ';
    resolve_scripts(text, paragraph_flags, std::span(scripts.data() + p0, n));
    choose_paragraph_fonts(p0, p1);

    runs.clear();
    shaped.clear();
    uint32_t run_begin = p0;
    // Combining marks (and joiners, selectors) attached to one base: HarfBuzz reorders a cluster's
    // marks in time quadratic in their number, so past kMaxMarksPerCluster a new run starts. What
    // continues an emoji sequence counts too: HarfBuzz makes the whole sequence one cluster.
    uint32_t attached = (flags[p0] & kCharAttached) != 0 ? 1 : 0;
    // Default ignorables in a row at the end of the run: HarfBuzz removes a row of them at a run's
    // start in time quadratic in its length, so past kMaxIgnorablesPerRun a new run starts.
    uint32_t ignorables = is_default_ignorable(codepoints[p0]) ? 1 : 0;
    for (uint32_t i = p0 + 1; i <= p1; ++i) {
        bool split = false, cut = false;
        if (i < p1) {
            const bool continues = (flags[i] & (kCharAttached | kCharEmojiNext)) != 0;
            attached = continues ? attached + 1 : 0;
            split = attached > kMaxMarksPerCluster;
            ignorables = is_default_ignorable(codepoints[i]) ? ignorables + 1 : 0;
            cut = ignorables > kMaxIgnorablesPerRun;
            // A long run: cut after a space, or anywhere a cluster starts 256 characters later.
            const uint32_t length = i - run_begin;
            cut = cut || (!continues && length >= kMaxShapingRunCharacters &&
                          (codepoints[i - 1] == ' ' || length >= kMaxShapingRunCharacters + 256));
        }
        if (i < p1 && !split && !cut && levels[i] == levels[i - 1] && scripts[i] == scripts[i - 1] &&
            font_of[i] == font_of[i - 1] && same_shaping(style_of[i - 1], style_of[i]))
            continue;
        if (split) {
            ++mark_splits;
            attached = 1;  // the mark at i starts the next run
        }
        if (cut && ignorables > kMaxIgnorablesPerRun) ++ignorable_splits;
        Run run;
        run.begin = run_begin;
        run.end = i;
        run.script = scripts[run_begin];
        run.font = font_of[run_begin];
        run.style = style_of[run_begin];
        run.level = levels[run_begin];
        run.glyph_begin = shaped.size();
        if (!shape(p0, p1, run.begin, run.end, run.level, run.script, run.font, run.style)) {
            failed = true;
            return;
        }
        run.glyph_end = shaped.size();
        runs.push_back(run);
        run_begin = i;
        ignorables = i < p1 && is_default_ignorable(codepoints[i]) ? 1 : 0;
    }
    for (const ShapedGlyph& glyph : shaped) {
        flags[glyph.cluster] |= kCharClusterStart;
        if (glyph.unsafe_to_break) flags[glyph.cluster] |= kCharUnsafe;
    }
    for (const Run& run : runs) flags[run.begin] |= kCharClusterStart;  // run boundaries were shaped apart

    if (wrap_width > 0.0) {
        std::fill(cluster_advance.begin() + p0, cluster_advance.begin() + p1, 0.0f);
        for (const ShapedGlyph& glyph : shaped) {
            // A tab is at most a full tab stop wide: measuring it so keeps wrapped lines inside.
            const bool tab = (flags[glyph.cluster] & kCharTab) != 0 && tab_measure > 0.0;
            cluster_advance[glyph.cluster] += tab ? static_cast<float>(tab_measure) : glyph.advance;
        }
    }
    break_lines(p0, p1);
    size_t kept = line_ranges.size();
    bool trim = false;
    if (o.max_lines != 0 && lines.size() + kept >= o.max_lines) {
        // The last line max_lines allows: the layout stops after it, and trims it where text
        // (more than line breaks) follows.
        stopped = true;
        kept = o.max_lines - lines.size();
        dropped = kept < line_ranges.size();
        for (size_t i = p1; i < codepoints.size() && !dropped; ++i) dropped = !is_hard_break(codepoints[i]);
        trim = dropped && o.trimming != Trimming::none;
    }
    size_t run_cursor = 0, glyph_cursor = 0;
    for (size_t i = 0; i < kept; ++i) {
        const auto [line_begin, line_end] = line_ranges[i];
        if (trim && i + 1 == kept)
            place_trimmed_line(p0, p1, line_begin, line_end, base_level, run_cursor, glyph_cursor);
        else
            place_line(p0, p1, line_begin, line_end, base_level, run_cursor, glyph_cursor);
        if (failed) return;
    }
}

// The placed glyphs as instances into `out`, line by line: .notdef for glyphs the asset lacks,
// colour glyphs as their layers, blank glyphs kept only when asked, pens beyond kMaxCoordinate
// counted and dropped.
void Layouter::State::emit_glyphs(TextLayout& out) {
    const LayoutOptions& o = *options;

    out.glyphs.reserve(placed.size());
    out.shaped_glyphs = static_cast<uint32_t>(std::min<size_t>(placed.size(), UINT32_MAX));
    out.mark_splits = mark_splits;
    out.ignorable_splits = ignorable_splits;
    size_t p = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
        TextLine& record = out.lines[i];
        record.glyph_begin = static_cast<uint32_t>(out.glyphs.size());
        for (; p < placed.size() && placed[p].line == i; ++p) {
            const PlacedGlyph& placed_glyph = placed[p];
            const FontView& font = font_views[placed_glyph.font];
            uint32_t glyph = placed_glyph.glyph;
            if (glyph == 0 || !font.is_baked(glyph)) {
                // .notdef, or (only with an inconsistent asset) a glyph the asset lacks: show
                // the font's .notdef when it has one.
                ++out.missing_glyphs;
                glyph = 0;
                if (!font.is_baked(0)) continue;
            }
            const GlyphRecord& glyph_record = font.glyphs[glyph];
            // A colour glyph is drawn as its layers (blank when none has an outline), unless the
            // layout's budget of layers is spent: then as its plain outline.
            uint32_t colour_index = kNoColourGlyph;
            std::span<const ColourLayer> layers =
                o.colour_glyphs ? colour_layers(*font.asset, glyph, colour_index) : std::span<const ColourLayer>{};
            const auto drawn_layers = static_cast<uint32_t>(std::count_if(
                layers.begin(), layers.end(), [&](const ColourLayer& layer) { return font.is_drawn(layer); }));
            if (drawn_layers > kMaxColourLayerInstances - out.colour_layers) layers = {};
            const bool blank = layers.empty() ? glyph_record.curve_count == 0 : drawn_layers == 0;
            if (blank) {
                ++out.blank_glyphs;
                if (!o.keep_blank_glyphs) continue;
            }
            const double pen_x = line_x[i] + placed_glyph.x;
            const double pen_y = line_baseline[i] - static_cast<double>(placed_glyph.y_offset);
            if (!(std::abs(pen_x) <= kMaxCoordinate) || !(std::abs(pen_y) <= kMaxCoordinate)) {
                ++out.out_of_range_glyphs;
                continue;
            }
            GlyphInstance instance;
            int32_t whole_x = 0, whole_y = 0;
            quantize(pen_x, o.subpixel_steps, whole_x, instance.key.subpixel_x);
            quantize(pen_y, o.subpixel_steps, whole_y, instance.key.subpixel_y);
            const StyleView& view = styles[style_of[placed_glyph.cluster]];
            instance.key.font = font.id;
            instance.key.size_x = view.size_x_fixed;
            instance.key.size_y = view.size_y_fixed;
            instance.pen_x = static_cast<float>(pen_x);
            instance.pen_y = static_cast<float>(pen_y);
            std::copy(std::begin(view.color), std::end(view.color), std::begin(instance.color));
            instance.depth = view.style->depth;
            instance.cluster = offsets[placed_glyph.cluster];
            instance.line = static_cast<uint32_t>(i);
            // The outline `outline` of glyph index `index` at the glyph's pen, next in paint order.
            auto push = [&](uint32_t index, const GlyphRecord& outline) {
                instance.key.glyph = index;
                const GlyphRect rect = glyph_rect(outline, instance.key);
                instance.x = whole_x + rect.x;
                instance.y = whole_y + rect.y;
                instance.width = rect.width;
                instance.height = rect.height;
                instance.paint_order = o.first_paint_order + static_cast<uint32_t>(out.glyphs.size());
                out.glyphs.push_back(instance);
            };
            if (blank || layers.empty()) {
                // A kept blank colour glyph is the base glyph without its outline (0 x 0, as
                // every kept blank glyph).
                push(glyph, blank ? kNoOutline : glyph_record);
                continue;
            }
            ++out.colour_glyphs;
            out.colour_layers += drawn_layers;
            instance.colour_glyph = colour_index;
            instance.palette = view.style->palette < font.asset->palette_count() ? view.style->palette : 0;
            for (const ColourLayer& layer : layers) {
                if (!font.is_drawn(layer)) continue;
                instance.paint = layer.paint;
                push(layer.glyph, font.glyphs[layer.glyph]);
            }
        }
        record.glyph_count = static_cast<uint32_t>(out.glyphs.size()) - record.glyph_begin;
    }
    out.next_paint_order = o.first_paint_order + static_cast<uint32_t>(out.glyphs.size());
}

void Layouter::State::finish(TextLayout& out) {
    align_lines(out);
    emit_clusters(out);
    emit_glyphs(out);
    decorate(out);
}

Status Layouter::State::layout(std::span<const Font* const> font_list, std::string_view utf8, const TextStyle& style,
                               std::span<const TextSpan> spans, const LayoutOptions& layout_options, TextLayout& out) {
    reset(out, layout_options.first_paint_order);
    if (Status status = validate(font_list, utf8, style, layout_options); !status) return status;

    options = &layout_options;
    failed = stopped = dropped = false;
    failure.clear();
    glyphs_shaped = 0;
    mark_splits = ignorable_splits = 0;
    decode_utf8_with_offsets(utf8, codepoints, offsets);
    const size_t n = codepoints.size();
    style_of.resize(n);
    base_font_count = font_list.size();
    if (!resolve_styles(font_list, style, spans)) return invalid(failure);
    font_views.clear();
    for (const Font* font : fonts) {
        const FontAsset& asset = font->asset();
        font_views.push_back({asset.glyphs.data(), asset.glyphs.size(), font->id(), &asset});
    }
    const double scale = static_cast<double>(layout_options.scale);
    wrap_width = static_cast<double>(layout_options.wrap_width) * scale;
    language = layout_options.language != nullptr && layout_options.language[0] != '\0'
                   ? hb_language_from_string(layout_options.language, -1)
                   : nullptr;
    tab_width = tab_measure = 0.0;
    tab_stops.clear();
    if (utf8.find('\t') != std::string_view::npos) {
        if (layout_options.tab_spaces > 0) {
            const Font& first = *fonts[0];
            const double size_x = styles[0].size_x;
            hb_position_t space = 0;
            const uint32_t space_glyph = first.nominal_glyph(' ');
            if (first.has_glyph_for(' ')) space = hb_font_get_glyph_h_advance(first.harfbuzz_font(), space_glyph);
            double space_width = space / static_cast<double>(first.units_per_em()) * size_x;
            if (!(space_width > 0.0)) space_width = 0.25 * size_x;  // no space glyph: a quarter em
            if (layout_options.snap_to_pixels) space_width = std::max(1.0, std::round(space_width));
            tab_width = space_width * layout_options.tab_spaces;
        }
        tab_measure = tab_width;
        double previous = 0.0;
        for (const float logical : layout_options.tab_stops) {
            double stop = static_cast<double>(logical) * scale;
            if (layout_options.snap_to_pixels) stop = std::round(stop);
            if (!tab_stops.empty() && stop <= tab_stops.back()) continue;  // rounded onto the one before
            tab_stops.push_back(stop);
            tab_measure = std::max(tab_measure, stop - previous);
            previous = stop;
        }
    }
    placed.clear();
    clusters.clear();
    lines.clear();
    if (n == 0) {
        finish(out);
        return {};
    }

    flags.resize(n);
    levels.resize(n);
    scripts.resize(n);
    font_of.resize(n);
    if (wrap_width > 0.0) cluster_advance.resize(n);

    uint32_t begin = 0;
    for (;;) {
        uint32_t end = begin;
        while (end < n && !is_hard_break(codepoints[end])) ++end;
        paragraph(begin, end);
        if (failed) {
            reset(out, layout_options.first_paint_order);
            return invalid(failure);
        }
        if (end == n || stopped) break;
        begin = end + (codepoints[end] == '\r' && end + 1 < n && codepoints[end + 1] == '\n' ? 2 : 1);
    }
    out.trimmed = dropped;
    finish(out);
    return {};
}

Layouter::Layouter() : state_(std::make_unique<State>()) {}
Layouter::Layouter(Layouter&& other) noexcept = default;
Layouter& Layouter::operator=(Layouter&& other) noexcept = default;
Layouter::~Layouter() = default;

Status Layouter::layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                        const LayoutOptions& options, TextLayout& out) {
    return layout(fonts, utf8, style, {}, options, out);
}

Status Layouter::layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                        std::span<const TextSpan> spans, const LayoutOptions& options, TextLayout& out) {
    assert(state_ && "a moved-from Layouter may only be destroyed or assigned to");
    try {
        return state_->layout(fonts, utf8, style, spans, options, out);
    } catch (const std::exception& error) {
        // Only allocation can throw here (a text too large for memory): no exception crosses the API.
        reset(out, options.first_paint_order);
        return invalid(std::string("layout: out of memory: ") + error.what());
    }
}

Result<TextLayout> layout_text(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                               const LayoutOptions& options) {
    return layout_text(fonts, utf8, style, {}, options);
}

Result<TextLayout> layout_text(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                               std::span<const TextSpan> spans, const LayoutOptions& options) {
    Layouter layouter;
    TextLayout layout;
    if (Status status = layouter.layout(fonts, utf8, style, spans, options, layout); !status) return status.error();
    return layout;
}

}  // namespace crisp
