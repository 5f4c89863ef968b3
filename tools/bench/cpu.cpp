// crisp-bench --suite cpu (formerly crisp-bench-cpu): measures the CPU half of crisp's run time
// (no GPU) and prints Markdown tables.
//
// Layout: a UI-like frame of about 10,000 glyphs in many short strings (labels, buttons, numbers,
// a wrapped paragraph), with one font and with a fallback chain; and one million characters as
// one wrapped paragraph and as 80-column lines. Atlas: the same UI frame laid out and looked up
// in a warm atlas, and allocation and eviction throughput (how many atlas entries a page of text
// needs at each subpixel quantization is the atlas suite's). Each timed case is warmed up, then
// timed N times; the tables show the median and the fastest run.
#include "bench.hpp"

#include <crisp/atlas.hpp>
#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>

#include <hb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <random>
#include <thread>
#include <unordered_set>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Args {
    std::string dejavu = crisp::bench::data_file("fonts/DejaVuSans.ttf");
    std::string inter = crisp::bench::data_file("fonts/Inter-Regular.otf");
    std::string cjk = "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc";
    int runs = 21;
    int warmup = 3;
    std::string only;  // run only the cases whose name contains this
};

std::unique_ptr<crisp::Font> load(const std::string& path, crisp::FontId id, std::vector<uint32_t> codepoints) {
    crisp::BakeOptions options;
    options.all_glyphs = codepoints.empty();
    options.codepoints = std::move(codepoints);
    auto baked = crisp::bake_font_file(path, options);
    if (!baked) {
        std::fprintf(stderr, "crisp-bench: cpu: %s: %s\n", path.c_str(), baked.error().message.c_str());
        return nullptr;
    }
    auto font = crisp::Font::create(std::move(baked.value().asset), id);
    if (!font) {
        std::fprintf(stderr, "crisp-bench: cpu: %s: %s\n", path.c_str(), font.error().message.c_str());
        return nullptr;
    }
    return std::make_unique<crisp::Font>(std::move(font).value());
}

struct Label {
    std::string text;
    crisp::TextStyle style;
    crisp::LayoutOptions options;
};

// A UI frame: menus, buttons, a table of numbers, status lines and a wrapped paragraph, repeated
// in panels until the frame holds at least `target_glyphs` glyphs.
std::vector<Label> ui_frame(bool multilingual, size_t target_glyphs, const std::vector<const crisp::Font*>& fonts) {
    const char* words[] = {"File",
                           "Edit",
                           "View",
                           "Window",
                           "Help",
                           "Save as\u2026",
                           "Cancel",
                           "OK",
                           "Apply",
                           "Settings",
                           "Brightness",
                           "Anti-aliasing: 8x",
                           "Subpixel layout",
                           "Reset to defaults",
                           "Quit without saving?",
                           "Inventory",
                           "Health 100/100",
                           "Level 12",
                           "Gold: 1,024"};
    const char* foreign[] = {"\u05E9\u05DE\u05D5\u05E8 \u05D1\u05E9\u05DD",
                             "\u0625\u0644\u063A\u0627\u0621",
                             "\u8A2D\u5B9A",
                             "\u4FDD\u5B58",
                             "\u041D\u0430\u0441\u0442\u0440\u043E\u0439\u043A\u0438",
                             "\u0395\u03C0\u03B9\u03BB\u03BF\u03B3\u03AD\u03C2"};
    const char* paragraph =
        "Text in crisp is rasterized from its outlines on the GPU and refined over several frames, so static "
        "labels converge to very high quality while moving text stays smooth. This paragraph wraps at four "
        "hundred pixels, like a tooltip or a dialog's body text.";
    std::vector<Label> labels;
    size_t glyphs = 0;
    crisp::Layouter layouter;
    crisp::TextLayout scratch;
    float y = 20.0f;
    for (int panel = 0; glyphs < target_glyphs; ++panel) {
        auto add = [&](std::string text, float size, float x, float wrap) {
            Label label;
            label.text = std::move(text);
            label.style.size = size;
            label.options.origin_x = x + 0.37f * static_cast<float>(panel % 3);
            label.options.origin_y = y;
            label.options.wrap_width = wrap;
            if (!layouter.layout(fonts, label.text, label.style, label.options, scratch)) return;
            glyphs += scratch.glyphs.size();
            labels.push_back(std::move(label));
        };
        for (size_t i = 0; i < std::size(words); ++i) {
            add(words[i], 13.0f + static_cast<float>(i % 3), 10.0f + 90.0f * static_cast<float>(i % 8), 0.0f);
            y += i % 8 == 7 ? 18.0f : 0.0f;
        }
        for (int row = 0; row < 8; ++row) {
            char number[64];
            std::snprintf(number, sizeof(number), "%d.%02d ms  %5d  %+.3f", 3 + row * panel % 17, (row * 37) % 100,
                          1000 + row * 251 + panel, 0.125 * row - 0.5);
            add(number, 12.0f, 600.0f, 0.0f);
            y += 15.0f;
        }
        if (multilingual)
            for (size_t i = 0; i < std::size(foreign); ++i)
                add(foreign[i], 14.0f, 10.0f + 100.0f * static_cast<float>(i), 0.0f);
        add(paragraph, 14.0f, 10.0f, 400.0f);
        y += 120.0f;
    }
    return labels;
}

struct Measurement {
    double median_ms = 0.0;
    double fastest_ms = 0.0;
};

Measurement measure(int warmup, int runs, const std::function<void()>& body) {
    for (int i = 0; i < warmup; ++i) body();
    std::vector<double> ms;
    for (int i = 0; i < runs; ++i) {
        const auto start = Clock::now();
        body();
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    if (ms.empty()) return {0.0, 0.0};  // runs < 1 (also keeps GCC 12 -O3 from a false -Wnull-dereference)
    std::sort(ms.begin(), ms.end());
    return {ms[ms.size() / 2], ms.front()};
}

void print_row(std::FILE* out, const std::string& name, size_t strings, size_t glyphs, Measurement m) {
    std::fprintf(out, "| %s | %zu | %zu | %.3f | %.3f | %.1f |\n", name.c_str(), strings, glyphs, m.median_ms,
                 m.fastest_ms, m.median_ms * 1e6 / static_cast<double>(std::max<size_t>(glyphs, 1)));
}

void print_atlas_row(std::FILE* out, const std::string& name, size_t glyphs, Measurement m) {
    std::fprintf(out, "| %s | %zu | %.3f | %.3f | %.1f |\n", name.c_str(), glyphs, m.median_ms, m.fastest_ms,
                 m.median_ms * 1e6 / static_cast<double>(std::max<size_t>(glyphs, 1)));
}

// The baked fonts and the scratch state the cases share; each group of cases prints its table.
class Bench {
public:
    Bench(std::FILE* out, const Args& args, const crisp::Font& dejavu, const crisp::Font& inter, const crisp::Font& cjk,
          const crisp::Font& dejavu_again)
        : out_(out),
          args_(args),
          all_fonts_{&dejavu, &inter, &cjk},
          one_{&dejavu},
          chain_{&inter, &dejavu, &cjk},
          dejavu_again_(dejavu_again) {}

    // Layout: the UI frame with one font and with the fallback chain, against bare hb_shape.
    void layout_cases() {
        std::fprintf(out_, "| case | strings | glyphs out | median ms | fastest ms | ns per glyph (median) |\n");
        std::fprintf(out_, "|---|---:|---:|---:|---:|---:|\n");
        const crisp::Font& dejavu = *all_fonts_[0];
        const crisp::Font& inter = *all_fonts_[1];
        latin_ = ui_frame(false, 10'000, one_);
        harfbuzz_case("UI frame, DejaVu Sans, bare hb_shape (floor; glyphs shaped, spaces included)", latin_, dejavu);
        const std::vector<Label> mixed = ui_frame(true, 10'000, chain_);
        ui_case("UI frame, DejaVu Sans, reused Layouter", latin_, one_, false, true);
        ui_case("UI frame, DejaVu Sans, snapped pens", latin_, one_, true, true);
        ui_case("UI frame, DejaVu Sans, layout_text (fresh Layouter per string)", latin_, one_, false, false);
        const std::vector<const crisp::Font*> inter_only = {&inter};
        harfbuzz_case("UI frame, Inter, bare hb_shape (floor; glyphs shaped, spaces included)", latin_, inter);
        ui_case("UI frame, Inter (CFF, many OpenType features)", latin_, inter_only, false, true);
        ui_case("UI frame, Latin only, Inter > DejaVu > Noto CJK", latin_, chain_, false, true);
        ui_case("UI frame, multilingual, Inter > DejaVu > Noto CJK", mixed, chain_, false, true);
    }

    // The atlas: the UI frame looked up in a warm atlas, and allocation and eviction throughput.
    void atlas_cases() {
        std::fprintf(out_, "\n| atlas case | glyphs | median ms | fastest ms | ns per glyph (median) |\n");
        std::fprintf(out_, "|---|---:|---:|---:|---:|\n");
        std::string warm_note;
        if (selected("UI frame + warm atlas")) warm_note = warm_atlas_case();
        if (selected("allocation and eviction")) eviction_case();
        if (!warm_note.empty()) std::fprintf(out_, "\n%s\n", warm_note.c_str());
    }

    // A million characters: one paragraph, 80-column lines, one line, and mixed scripts.
    void large_text_cases() {
        std::fprintf(out_,
                     "\n| large text | strings | glyphs out | median ms | fastest ms | ns per glyph (median) |\n");
        std::fprintf(out_, "|---|---:|---:|---:|---:|---:|\n");
        std::string million;
        million.reserve(1'000'100);
        const std::string words = "Lorem ipsum dolor sit amet, consectetur adipiscing elit, sed do eiusmod tempor. ";
        while (million.size() < 1'000'000) million += words;
        million.resize(1'000'000);
        std::string columns = million;
        for (size_t i = 80; i < columns.size(); i += 81) columns[i] = '\n';
        std::string multilingual;
        const std::string sentence =
            "Hello \u05E9\u05DC\u05D5\u05DD \u0645\u0631\u062D\u0628\u0627 \u041F\u0440\u0438\u0432\u0435\u0442 "
            "\u6F22\u5B57 world, 123. ";
        while (multilingual.size() < 1'000'000) multilingual += sentence;
        big_case("1M characters, one paragraph wrapped at 1000 px, DejaVu Sans", million, one_, 1000.0f);
        big_case("1M characters, 80-column lines, DejaVu Sans", columns, one_, 0.0f);
        big_case("1M characters, one unwrapped line, DejaVu Sans", million, one_, 0.0f);
        big_case("1M bytes mixed LTR/RTL/CJK, wrapped at 1000 px, Inter > DejaVu > Noto CJK", multilingual, chain_,
                 1000.0f);
    }

    // A 10,000-glyph paragraph wrapped at 600 px, unstyled and with a style change every 20
    // glyphs: colour only (shaping runs go on across them), colour and underline, the size, and
    // the font (DejaVu Sans and Inter alternating: runs cut at each change).
    void styled_text_cases() {
        std::fprintf(out_,
                     "\n| styled paragraph | spans | glyphs out | median ms | fastest ms | ns per glyph (median) |\n");
        std::fprintf(out_, "|---|---:|---:|---:|---:|---:|\n");
        const std::string words = "Lorem ipsum dolor sit amet, consectetur adipiscing elit, sed do eiusmod tempor. ";
        std::string text;
        while (text.size() < 11'800) text += words;  // about 10,000 glyphs (spaces are not emitted)
        const std::vector<const crisp::Font*> inter = {all_fonts_[1], all_fonts_[0]};
        // Spans over every other 20 characters: as many boundaries as a change every 20 glyphs.
        auto spans_of = [&](auto&& style_of) {
            std::vector<crisp::TextSpan> spans;
            for (uint32_t begin = 20; begin + 20 <= text.size(); begin += 40)
                spans.push_back({begin, begin + 20, style_of()});
            return spans;
        };
        crisp::TextStyle base{.size = 14.0f};
        const auto coloured = [&] {
            crisp::TextStyle style = base;
            style.color[0] = 0.8f;
            return style;
        };
        styled_case("unstyled", text, {}, base);
        styled_case("colour every 20 glyphs", text, spans_of(coloured), base);
        styled_case("colour and underline every 20 glyphs", text, spans_of([&] {
                        crisp::TextStyle style = coloured();
                        style.underline = true;
                        return style;
                    }),
                    base);
        styled_case("size every 20 glyphs (14 and 18 px)", text, spans_of([&] {
                        crisp::TextStyle style = base;
                        style.size = 18.0f;
                        return style;
                    }),
                    base);
        const std::vector<const crisp::Font*> again = {&dejavu_again_};
        styled_case("font every 20 glyphs (DejaVu Sans and a second DejaVu Sans Font)", text, spans_of([&] {
                        crisp::TextStyle style = base;
                        style.fonts = again;
                        return style;
                    }),
                    base);
        crisp::TextStyle inter_base = base;
        inter_base.fonts = inter;
        styled_case("unstyled, Inter (the other font of the next case)", text, {}, inter_base);
        styled_case("font every 20 glyphs (DejaVu Sans and Inter)", text, spans_of([&] {
                        crisp::TextStyle style = base;
                        style.fonts = inter;
                        return style;
                    }),
                    base);
    }

    // Every case measured, for the JSON.
    void write_json(crisp::JsonWriter& json) const {
        json.key("cases").begin_array();
        for (const Case& c : cases_) {
            json.begin_object()
                .field("name", c.name)
                .field("strings", c.strings)
                .field("glyphs", c.glyphs)
                .field("median_ms", c.m.median_ms)
                .field("fastest_ms", c.m.fastest_ms)
                .end_object();
        }
        json.end_array();
    }

private:
    struct Case {
        std::string name;
        size_t strings = 0;
        size_t glyphs = 0;
        Measurement m;
    };

    void print_row(const std::string& name, size_t strings, size_t glyphs, Measurement m) {
        ::print_row(out_, name, strings, glyphs, m);
        cases_.push_back({name, strings, glyphs, m});
    }
    void print_atlas_row(const std::string& name, size_t glyphs, Measurement m) {
        ::print_atlas_row(out_, name, glyphs, m);
        cases_.push_back({name, 0, glyphs, m});
    }

    bool selected(const std::string& name) const { return name.find(args_.only) != std::string::npos; }

    // Lays out every label into frame_, as an engine would before uploading it.
    void layout_labels(const std::vector<Label>& labels, const std::vector<const crisp::Font*>& fonts, bool snap,
                       bool reuse) {
        frame_.clear();
        for (const Label& label : labels) {
            crisp::LayoutOptions options = label.options;
            options.snap_to_pixels = snap;
            options.first_paint_order = static_cast<uint32_t>(frame_.size());
            if (reuse) {
                if (!layouter_.layout(fonts, label.text, label.style, options, layout_)) std::abort();
                frame_.insert(frame_.end(), layout_.glyphs.begin(), layout_.glyphs.end());
            } else {
                auto fresh = crisp::layout_text(fonts, label.text, label.style, options);
                if (!fresh) std::abort();
                frame_.insert(frame_.end(), fresh->glyphs.begin(), fresh->glyphs.end());
            }
        }
    }

    void ui_case(const char* name, const std::vector<Label>& labels, const std::vector<const crisp::Font*>& fonts,
                 bool snap, bool reuse) {
        if (!selected(name)) return;
        const Measurement m = measure(args_.warmup, args_.runs, [&] { layout_labels(labels, fonts, snap, reuse); });
        print_row(name, labels.size(), frame_.size(), m);
    }

    // The floor: HarfBuzz alone shaping the same strings (one run each, no bidi, no fallback, no
    // line breaking, no keys), to show what crisp's layout adds on top.
    void harfbuzz_case(const char* name, const std::vector<Label>& labels, const crisp::Font& font) {
        if (!selected(name)) return;
        hb_buffer_t* buffer = hb_buffer_create();
        size_t glyphs = 0;
        const Measurement m = measure(args_.warmup, args_.runs, [&] {
            glyphs = 0;
            for (const Label& label : labels) {
                hb_buffer_clear_contents(buffer);
                hb_buffer_add_utf8(buffer, label.text.data(), static_cast<int>(label.text.size()), 0,
                                   static_cast<int>(label.text.size()));
                hb_buffer_guess_segment_properties(buffer);
                hb_shape(font.harfbuzz_font(), buffer, nullptr, 0);
                glyphs += hb_buffer_get_length(buffer);
            }
        });
        hb_buffer_destroy(buffer);
        print_row(name, labels.size(), glyphs, m);
    }

    void big_case(const char* name, const std::string& text, const std::vector<const crisp::Font*>& fonts, float wrap) {
        if (!selected(name)) return;
        const int runs = std::max(1, args_.runs / 4);
        crisp::LayoutOptions options;
        options.wrap_width = wrap;
        const Measurement m = measure(1, runs, [&] {
            if (!layouter_.layout(fonts, text, {.size = 14.0f}, options, layout_)) std::abort();
        });
        char label[160];
        std::snprintf(label, sizeof(label), "%s (%zu bytes, %zu lines, widest %.2g px)", name, text.size(),
                      layout_.lines.size(), static_cast<double>(layout_.width));
        print_row(label, 1, layout_.glyphs.size(), m);
    }

    void styled_case(const std::string& what, const std::string& text, const std::vector<crisp::TextSpan>& spans,
                     const crisp::TextStyle& style) {
        const std::string name = "10k-glyph paragraph, " + what;
        if (!selected(name)) return;
        crisp::LayoutOptions options;
        options.wrap_width = 600.0f;
        const Measurement m = measure(args_.warmup, args_.runs, [&] {
            if (!layouter_.layout(one_, text, style, spans, options, layout_)) std::abort();
        });
        ::print_row(out_, name, spans.size(), layout_.glyphs.size(), m);
        cases_.push_back({name, spans.size(), layout_.glyphs.size(), m});
    }

    void acquire_all(crisp::GlyphAtlas& atlas, const std::vector<crisp::GlyphInstance>& glyphs) const {
        for (const crisp::GlyphInstance& glyph : glyphs) {
            uint64_t cost = 0;
            if (atlas.find(glyph.key) == crisp::kNoAtlasEntry) {  // only a new glyph needs its cost
                const crisp::Font& font = *all_fonts_[glyph.key.font - 1];
                cost = crisp::curve_tests_per_sample(font.asset(), font.asset().glyphs[glyph.key.glyph], glyph.key);
            }
            atlas.acquire(glyph.key, glyph.width, glyph.height, cost);
        }
        atlas.schedule();
    }

    // The UI frame laid out and looked up in a warm atlas, every frame; returns a note on the atlas.
    std::string warm_atlas_case() {
        auto atlas = crisp::GlyphAtlas::create();
        if (!atlas) std::abort();
        atlas->begin_frame();
        layout_labels(latin_, one_, false, true);
        acquire_all(*atlas, frame_);  // the atlas is warm from here on
        const Measurement lookup_only = measure(args_.warmup, args_.runs, [&] {
            atlas->begin_frame();
            acquire_all(*atlas, frame_);
        });
        print_atlas_row("UI frame, atlas look-up only (warm, DejaVu Sans)", frame_.size(), lookup_only);
        const Measurement whole = measure(args_.warmup, args_.runs, [&] {
            atlas->begin_frame();
            layout_labels(latin_, one_, false, true);
            acquire_all(*atlas, frame_);
        });
        print_atlas_row("UI frame, layout + atlas look-up + schedule (warm, DejaVu Sans)", frame_.size(), whole);
        return "The warm atlas holds " + std::to_string(atlas->stats().resident_glyphs) + " glyphs, " +
               std::to_string(atlas->stats().used_cells) + " of its 16384 cells.";
    }

    // A small atlas and far more distinct glyphs than fit, so nearly every acquire allocates and
    // most allocations evict.
    void eviction_case() {
        crisp::AtlasConfig config;
        config.width = config.height = 512;
        auto atlas = crisp::GlyphAtlas::create(config);
        if (!atlas) std::abort();
        std::mt19937 random(12345);
        std::uniform_int_distribution<uint32_t> side(4, 40);
        std::vector<std::array<uint32_t, 3>> requests;  // glyph id, width, height
        for (uint32_t i = 0; i < 200'000; ++i) requests.push_back({i, side(random), side(random) + 8});
        size_t next = 0;
        const size_t per_frame = 500;
        const Measurement m = measure(args_.warmup, args_.runs, [&] {
            for (int f = 0; f < 10; ++f) {
                atlas->begin_frame();
                for (size_t k = 0; k < per_frame; ++k, next = (next + 1) % requests.size()) {
                    crisp::GlyphKey key;
                    key.font = 1;
                    key.glyph = requests[next][0];
                    key.size_x = key.size_y = 16 * crisp::kSizeOne;
                    atlas->acquire(key, requests[next][1], requests[next][2], 1000);
                }
                atlas->schedule();
            }
        });
        const crisp::AtlasCounters& total = atlas->stats().total;
        char name[200];
        std::snprintf(name, sizeof name,
                      "allocation and eviction, 512x512 atlas, 10 frames of 500 new 4-40 px glyphs "
                      "(%.0f %% of acquires evicted)",
                      100.0 * static_cast<double>(total.evictions) /
                          static_cast<double>(std::max<uint64_t>(total.allocations, 1)));
        print_atlas_row(name, 10 * per_frame, m);
    }

    std::FILE* out_;
    const Args& args_;
    std::vector<const crisp::Font*> all_fonts_;  // by FontId - 1
    std::vector<const crisp::Font*> one_;        // DejaVu Sans alone
    std::vector<const crisp::Font*> chain_;      // Inter > DejaVu Sans > Noto Sans CJK
    const crisp::Font& dejavu_again_;            // DejaVu Sans as another Font: runs cut where spans switch
    std::vector<Label> latin_;                   // the Latin UI frame
    crisp::Layouter layouter_;
    crisp::TextLayout layout_;
    std::vector<crisp::GlyphInstance> frame_;  // what an engine would upload
    std::vector<Case> cases_;
};

}  // namespace

void crisp::bench::run_cpu(Session& session) {
    const Options& o = session.options;
    Args args;
    args.dejavu = o.dejavu;
    args.inter = o.inter;
    args.cjk = o.cjk;
    args.runs = o.runs.value_or(o.quick ? 1 : args.runs);
    args.warmup = static_cast<int>(o.warmup.value_or(o.quick ? 0 : static_cast<uint32_t>(args.warmup)));
    args.only = o.only;

    const auto bake_start = Clock::now();
    auto dejavu = load(args.dejavu, 1, {});
    auto inter = load(args.inter, 2, {});
    // A subset: the CJK characters the frame uses, like an asset pipeline would bake.
    auto cjk = load(args.cjk, 3, {0x8A2D, 0x5B9A, 0x4FDD, 0x5B58, 0x6F22, 0x5B57});
    auto dejavu_again = load(args.dejavu, 4, {});
    if (!dejavu || !inter || !cjk || !dejavu_again) fail("cpu", "a font did not load (the message is above)");
    const double bake_ms = std::chrono::duration<double, std::milli>(Clock::now() - bake_start).count();

    std::fprintf(session.md,
                 "Machine: %s, %u hardware threads (one used). Compiler: %s. Fonts baked in %.0f ms. %d timed runs per "
                 "case after %d untimed (the large-text cases a quarter as many).\n\n",
                 bench::cpu_model().c_str(), std::max(1u, static_cast<unsigned>(std::thread::hardware_concurrency())),
                 __VERSION__, bake_ms, args.runs, args.warmup);
    Bench bench(session.md, args, *dejavu, *inter, *cjk, *dejavu_again);
    progress("cpu", "layout cases");
    bench.layout_cases();
    progress("cpu", "atlas cases");
    bench.atlas_cases();
    progress("cpu", "large text cases");
    bench.large_text_cases();
    progress("cpu", "styled text cases");
    bench.styled_text_cases();
    session.json.begin_object().field("runs", args.runs).field("warmup", args.warmup);
    bench.write_json(session.json);
    session.json.end_object();
}
