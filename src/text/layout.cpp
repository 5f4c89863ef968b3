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
    if (Status status = check_size("style.size", style.size); !status) return status;
    if (style.size_y != 0.0f) {
        if (Status status = check_size("style.size_y", style.size_y); !status) return status;
    }
    const std::pair<const char*, float> finite[] = {
        {"style.color[0]", style.color[0]},     {"style.color[1]", style.color[1]},
        {"style.color[2]", style.color[2]},     {"style.color[3]", style.color[3]},
        {"style.depth", style.depth},           {"options.origin_x", options.origin_x},
        {"options.origin_y", options.origin_y}, {"options.wrap_width", options.wrap_width},
    };
    for (const auto& [name, value] : finite) {
        if (Status status = check_finite(name, value); !status) return status;
    }
    if (options.wrap_width < 0.0f)
        return invalid("layout: options.wrap_width is " + show(options.wrap_width) +
                       "; it must be 0 (no wrapping) or positive");
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
    out.clusters.clear();
    out.x = out.y = out.width = out.height = out.line_height = 0.0f;
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

bool Layouter::State::shape(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level, hb_script_t script,
                            uint16_t font) {
    // HarfBuzz (before 10.2, which lets the caller set it) stops a buffer at max(64 glyphs a
    // character, 16,384): a run it cannot hold is shaped again in halves, cut before a character
    // that starts a cluster, down to pieces of kPieceCharacters.
    constexpr uint32_t kPieceCharacters = 16;
    if (shape_once(p0, p1, begin, end, level, script, font)) {
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
        return shape(p0, p1, begin, middle, level, script, font) && shape(p0, p1, middle, end, level, script, font);
    }
    failure = "layout: shaping characters " + std::to_string(begin) + " to " + std::to_string(end) +
              " makes more glyphs than HarfBuzz's buffer holds (16384 for up to 256 characters, 64 a character "
              "past that): the font's substitutions (GSUB) multiply them";
    return false;
}

bool Layouter::State::shape_once(uint32_t p0, uint32_t p1, uint32_t begin, uint32_t end, uint8_t level,
                                 hb_script_t script, uint16_t font) {
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
    hb_shape(fonts[font]->harfbuzz_font(), buffer, nullptr, 0);
    if (!hb_buffer_allocation_successful(buffer)) return false;

    unsigned count = 0;
    const hb_glyph_info_t* infos = hb_buffer_get_glyph_infos(buffer, &count);
    glyphs_shaped += count;
    if (glyphs_shaped > kMaxLayoutGlyphs) return true;  // shape() says so
    const hb_glyph_position_t* positions = hb_buffer_get_glyph_positions(buffer, nullptr);
    const double per_unit = 1.0 / fonts[font]->units_per_em();
    const double scale_x = per_unit * size_x, scale_y = per_unit * size_y;
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
        shaped.push_back(glyph);
    }
    return true;
}

void Layouter::State::paragraph(uint32_t p0, uint32_t p1) {
    const LayoutOptions& o = *options;
    if (p0 == p1) {
        lines.push_back({p0, p1, 0.0, o.direction == Direction::rtl});
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
    choose_fonts(fonts, text, paragraph_flags, std::span(font_of.data() + p0, n));

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
            font_of[i] == font_of[i - 1])
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
        run.level = levels[run_begin];
        run.glyph_begin = shaped.size();
        if (!shape(p0, p1, run.begin, run.end, run.level, run.script, run.font)) {
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

    if (o.wrap_width > 0.0f) {
        std::fill(cluster_advance.begin() + p0, cluster_advance.begin() + p1, 0.0f);
        for (const ShapedGlyph& glyph : shaped) {
            // A tab is at most a full tab stop wide: measuring it so keeps wrapped lines inside.
            const bool tab = (flags[glyph.cluster] & kCharTab) != 0 && tab_width > 0.0;
            cluster_advance[glyph.cluster] += tab ? static_cast<float>(tab_width) : glyph.advance;
        }
    }
    break_lines(p0, p1);
    size_t run_cursor = 0, glyph_cursor = 0;
    for (const auto& [line_begin, line_end] : line_ranges) {
        place_line(p0, p1, line_begin, line_end, base_level, run_cursor, glyph_cursor);
        if (failed) return;
    }
}

// The placed glyphs as instances into `out`, line by line: .notdef for glyphs the asset lacks,
// colour glyphs as their layers, blank glyphs kept only when asked, pens beyond kMaxCoordinate
// counted and dropped.
void Layouter::State::emit_glyphs(const TextStyle& style, TextLayout& out) {
    const LayoutOptions& o = *options;
    float color[4];
    for (int c = 0; c < 3; ++c) color[c] = srgb_to_linear(std::clamp(style.color[c], 0.0f, 1.0f));
    color[3] = std::clamp(style.color[3], 0.0f, 1.0f);
    const uint32_t size_x_fixed = key_size(size_x), size_y_fixed = key_size(size_y);

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
            instance.key.font = font.id;
            instance.key.size_x = size_x_fixed;
            instance.key.size_y = size_y_fixed;
            instance.pen_x = static_cast<float>(pen_x);
            instance.pen_y = static_cast<float>(pen_y);
            std::copy(std::begin(color), std::end(color), std::begin(instance.color));
            instance.depth = style.depth;
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
            instance.palette = font.palette;
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

void Layouter::State::finish(const TextStyle& style, TextLayout& out) {
    align_lines(out);
    emit_clusters(out);
    emit_glyphs(style, out);
}

Status Layouter::State::layout(std::span<const Font* const> font_list, std::string_view utf8, const TextStyle& style,
                               const LayoutOptions& layout_options, TextLayout& out) {
    reset(out, layout_options.first_paint_order);
    if (Status status = validate(font_list, utf8, style, layout_options); !status) return status;

    fonts = font_list;
    font_views.clear();
    for (const Font* font : fonts) {
        const FontAsset& asset = font->asset();
        const uint32_t palette = style.palette < asset.palette_count() ? style.palette : 0;
        font_views.push_back({asset.glyphs.data(), asset.glyphs.size(), font->id(), &asset, palette});
    }
    options = &layout_options;
    failed = false;
    failure.clear();
    glyphs_shaped = 0;
    mark_splits = ignorable_splits = 0;
    size_x = static_cast<double>(key_size(static_cast<double>(style.size))) / kSizeOne;
    const float size_y_asked = style.size_y == 0.0f ? style.size : style.size_y;
    size_y = static_cast<double>(key_size(static_cast<double>(size_y_asked))) / kSizeOne;
    language = layout_options.language != nullptr && layout_options.language[0] != '\0'
                   ? hb_language_from_string(layout_options.language, -1)
                   : nullptr;
    tab_width = 0.0;
    if (layout_options.tab_spaces > 0 && utf8.find('\t') != std::string_view::npos) {
        const Font& first = *fonts[0];
        hb_position_t space = 0;
        const uint32_t space_glyph = first.nominal_glyph(' ');
        if (first.has_glyph_for(' ')) space = hb_font_get_glyph_h_advance(first.harfbuzz_font(), space_glyph);
        double space_width = space / static_cast<double>(first.units_per_em()) * size_x;
        if (!(space_width > 0.0)) space_width = 0.25 * size_x;  // no space glyph: a quarter em
        if (layout_options.snap_to_pixels) space_width = std::max(1.0, std::round(space_width));
        tab_width = space_width * layout_options.tab_spaces;
    }
    placed.clear();
    clusters.clear();
    lines.clear();
    if (utf8.empty()) {
        finish(style, out);
        return {};
    }

    decode_utf8_with_offsets(utf8, codepoints, offsets);
    const size_t n = codepoints.size();
    flags.resize(n);
    levels.resize(n);
    scripts.resize(n);
    font_of.resize(n);
    if (layout_options.wrap_width > 0.0f) cluster_advance.resize(n);

    uint32_t begin = 0;
    for (;;) {
        uint32_t end = begin;
        while (end < n && !is_hard_break(codepoints[end])) ++end;
        paragraph(begin, end);
        if (failed) {
            reset(out, layout_options.first_paint_order);
            return invalid(failure);
        }
        if (end == n) break;
        begin = end + (codepoints[end] == '\r' && end + 1 < n && codepoints[end + 1] == '\n' ? 2 : 1);
    }
    finish(style, out);
    return {};
}

Layouter::Layouter() : state_(std::make_unique<State>()) {}
Layouter::Layouter(Layouter&& other) noexcept = default;
Layouter& Layouter::operator=(Layouter&& other) noexcept = default;
Layouter::~Layouter() = default;

Status Layouter::layout(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                        const LayoutOptions& options, TextLayout& out) {
    assert(state_ && "a moved-from Layouter may only be destroyed or assigned to");
    try {
        return state_->layout(fonts, utf8, style, options, out);
    } catch (const std::exception& error) {
        // Only allocation can throw here (a text too large for memory): no exception crosses the API.
        reset(out, options.first_paint_order);
        return invalid(std::string("layout: out of memory: ") + error.what());
    }
}

Result<TextLayout> layout_text(std::span<const Font* const> fonts, std::string_view utf8, const TextStyle& style,
                               const LayoutOptions& options) {
    Layouter layouter;
    TextLayout layout;
    if (Status status = layouter.layout(fonts, utf8, style, options, layout); !status) return status.error();
    return layout;
}

}  // namespace crisp
