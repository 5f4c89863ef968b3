// crisp-bench --suite coverage: how far crisp's atlas is from exact area coverage after N samples
// (N = 1, 2, 4, ..., --samples), per sample kind (rows, points) and layout (gray, rgb thirds), on a
// varied set of glyphs, with FreeType's CPU rasterizer as a peer on the same texels. The reference
// is not crisp's own sampler: FreeType's area coverage of the original outline on a grid of S x S
// cells per texel (support/freetype_reference.hpp, docs/coverage.md). At the largest sample count
// each glyph's error is split into sampling, cubic lowering and the reference's own error.
#include "bench.hpp"
#include "coverage.hpp"
#include "freetype_reference.hpp"
#include "harness.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "coverage";

// One entry of the glyph set: the glyphs of `text` in a font at a size.
struct GlyphSpec {
    std::string path;
    uint32_t face = 0;
    std::vector<Variation> variations;
    std::string text;
    float size = 16.0f;
    std::string what;
};

constexpr uint32_t tag(const char (&name)[5]) {
    return uint32_t(uint8_t(name[0])) << 24 | uint32_t(uint8_t(name[1])) << 16 | uint32_t(uint8_t(name[2])) << 8 |
           uint32_t(uint8_t(name[3]));
}

const char* const kNotoCjk = "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc";
const char* const kDejaVuSerifItalic = "/usr/share/fonts/truetype/dejavu/DejaVuSerif-Italic.ttf";
const char* const kCantarellThin = "/usr/share/fonts/opentype/cantarell/Cantarell-Thin.otf";

// The glyph set: TrueType and CFF, a hairline (Inter at weight 100), a variable font's overlapping
// contours (Inter's default instance keeps them), italic, a thin CFF face, CJK, and 4 to 240 px.
// The system fonts (scripts/setup.sh installs them) are left out, with a warning, where they are
// missing. --glyph replaces the set.
std::vector<GlyphSpec> glyph_set(const Options& options) {
    std::vector<GlyphSpec> set;
    if (!options.coverage_glyphs.empty()) {
        for (const Options::CoverageGlyph& g : options.coverage_glyphs)
            set.push_back({g.path, 0, {}, g.text, g.size, "--glyph"});
        return set;
    }
    if (options.quick) {
        set = {{data_file("fonts/DejaVuSans.ttf"), 0, {}, "g", 13.0f, "TrueType"},
               {data_file("fonts/Inter-Regular.otf"), 0, {}, "S", 9.0f, "CFF"},
               {data_file("fonts/Inter-roman.var.ttf"),
                0,
                {{tag("wght"), 100.0f}},
                "k",
                12.0f,
                "variable, wght 100 (hairline)"}};
    } else {
        set = {
            {data_file("fonts/DejaVuSans.ttf"), 0, {}, "g@", 13.0f, "TrueType"},
            {data_file("fonts/DejaVuSans.ttf"), 0, {}, "e&", 4.0f, "TrueType, 4 px"},
            {data_file("fonts/DejaVuSans.ttf"), 0, {}, "a", 48.0f, "TrueType"},
            {data_file("fonts/DejaVuSans.ttf"), 0, {}, "e", 240.0f, "TrueType, 240 px"},
            {data_file("fonts/Inter-Regular.otf"), 0, {}, "Sa", 9.0f, "CFF"},
            {data_file("fonts/Inter-Regular.otf"), 0, {}, "R", 16.0f, "CFF"},
            {data_file("fonts/Inter-roman.var.ttf"),
             0,
             {{tag("wght"), 100.0f}},
             "kM",
             16.0f,
             "variable, wght 100 (hairline)"},
            {data_file("fonts/Inter-roman.var.ttf"), 0, {}, "Ak$", 20.0f, "variable, overlapping contours"},
            {kDejaVuSerifItalic, 0, {}, "fy", 18.0f, "italic"},
            {kCantarellThin, 0, {}, "S", 23.3f, "thin CFF (issue 31's worst texel)"},
            {kNotoCjk, 0, {}, "\u6c38", 13.0f, "CJK, CFF"},
            {kNotoCjk, 0, {}, "\u9f98", 24.0f, "CJK, hundreds of curves"},
        };
    }
    for (const std::string& path : options.fonts) set.push_back({path, 0, {}, "Ag&", 16.0f, "--font"});
    return set;
}

// A font of the set, baked with the text it draws, its FreeType face, and its FontId (index + 1).
struct LoadedFont {
    std::string path;
    std::vector<Variation> variations;
    std::unique_ptr<Font> font;
    std::unique_ptr<freetype::Face> face;
    // The same glyphs baked at kFineToleranceEm: the outline with no lowering error to speak of.
    FontAsset fine;
};

// The tolerance of the bake that stands for the unlowered outline in the split of the error:
// 1e-6 em is 2.4e-4 px at 240 px, far below every other part measured.
constexpr float kFineToleranceEm = 1e-6f;

// One glyph instance of the set, where it is drawn, and what it is.
struct SetGlyph {
    GlyphInstance instance;
    const GlyphSpec* spec = nullptr;
    uint32_t codepoint = 0;
};

std::string describe_variations(const std::vector<Variation>& variations) {
    std::string text;
    for (const Variation& v : variations) {
        const char name[5] = {char(v.tag >> 24), char(v.tag >> 16), char(v.tag >> 8), char(v.tag), 0};
        text += std::string(text.empty() ? "" : ",") + name + "=" + std::to_string(static_cast<int>(v.value));
    }
    return text;
}

class Coverage {
public:
    Coverage(Session& session, std::vector<GlyphSpec> specs)
        : session_(session), options_(session.options), specs_(std::move(specs)) {}

    // Bakes the fonts and lays out the set; a missing font file is left out with a warning.
    void load() {
        uint32_t line = 0;
        for (const GlyphSpec& spec : specs_) {
            if (!std::filesystem::exists(spec.path)) {
                session_.warn(kSuite,
                              spec.path + " is missing (scripts/setup.sh installs it): its glyphs are left out");
                continue;
            }
            LoadedFont& font = font_for(spec);
            const Font* fonts[] = {font.font.get()};
            TextStyle style;
            style.size = spec.size;
            LayoutOptions layout_options;
            layout_options.origin_x = 3.37f;
            layout_options.origin_y = 0.61f + static_cast<float>(++line) * 300.0f;
            auto laid = layout_text(fonts, spec.text, style, layout_options);
            if (!laid) fail(kSuite, spec.path + ": " + laid.error().message);
            for (const GlyphInstance& g : laid->glyphs) {
                if (g.width == 0) continue;
                const std::vector<uint32_t> from_cluster = decode_utf8(std::string_view(spec.text).substr(g.cluster));
                glyphs_.push_back({g, &spec, from_cluster.empty() ? 0 : from_cluster.front()});
            }
        }
        if (glyphs_.empty()) fail(kSuite, "no glyph of the set could be loaded");
    }

    // Every layout and sample kind measured, the report's tables and the JSON written.
    void run() {
        const uint32_t max_samples = options_.samples.value_or(options_.quick ? 16 : 512);
        std::vector<SampleKind> kinds = {SampleKind::rows, SampleKind::points};
        if (options_.sample_kind) kinds = {*options_.sample_kind};
        print_glyph_set();
        session_.json.begin_object();
        write_glyph_set_json(max_samples);
        session_.json.key("runs").begin_array();
        for (const char* layout_name : {"gray", "rgb"}) {
            const SubpixelLayout layout = *subpixel_preset(layout_name);
            const uint32_t cells = std::string(layout_name) == "gray" ? options_.cells_gray : options_.cells_rgb;
            progress(kSuite, std::string(layout_name) + ": reference coverage, " + std::to_string(cells) + "x" +
                                 std::to_string(cells) + " cells per texel, " + std::to_string(glyphs_.size()) +
                                 " glyphs");
            const std::vector<freetype::CoverageImage> references = reference_images(layout, cells);
            session_.heading(std::string("coverage: ") + layout_name);
            std::map<std::string, std::vector<ErrorPoint>> by_kind;
            for (const SampleKind kind : kinds) {
                by_kind[sample_kind_name(kind)] = measure_crisp(layout, layout_name, kind, max_samples, references);
            }
            print_table(layout_name, kinds, by_kind);
            peers(layout_name, references);
            std::fputs(split_md_.c_str(), session_.md);
            split_md_.clear();
        }
        session_.json.end_array();
        write_peers_json();
        session_.json.end_object();
    }

private:
    LoadedFont& font_for(const GlyphSpec& spec) {
        for (LoadedFont& f : fonts_) {
            if (f.path == spec.path && describe_variations(f.variations) == describe_variations(spec.variations)) {
                return f;
            }
        }
        std::string text;
        float largest = 0.0f;
        for (const GlyphSpec& s : specs_) {
            if (s.path == spec.path && describe_variations(s.variations) == describe_variations(spec.variations)) {
                text += s.text;
                largest = std::max(largest, s.size);
            }
        }
        BakeOptions bake;
        // Baked for the largest size it is drawn at, as an application bakes for its sizes
        // (crisp-bake --max-size); --tolerance instead sets the tolerance in em.
        bake.max_size_px = std::clamp(largest, 1.0f, kMaxBakeSizePx);
        bake.all_glyphs = false;
        bake.codepoints = decode_utf8(text);
        bake.face_index = spec.face;
        bake.variations = spec.variations;
        if (options_.tolerance) {
            bake.tolerance_em = *options_.tolerance;
            bake.max_size_px = 0.0f;
        }
        auto baked = bake_font_file(spec.path, bake);
        if (!baked) fail(kSuite, spec.path + ": " + baked.error().message);
        bake_notes_.push_back({std::filesystem::path(spec.path).filename().string(), baked->report});
        bake.max_size_px = 0.0f;
        bake.tolerance_em = kFineToleranceEm;
        auto fine = bake_font_file(spec.path, bake);
        if (!fine) fail(kSuite, spec.path + ": " + fine.error().message);
        auto font = Font::create(std::move(baked->asset), static_cast<FontId>(fonts_.size() + 1));
        if (!font) fail(kSuite, spec.path + ": " + font.error().message);
        auto face = freetype::Face::open_file(spec.path, spec.face, spec.variations);
        if (!face) fail(kSuite, spec.path + ": FreeType: " + face.error().message);
        fonts_.push_back({spec.path, spec.variations, std::make_unique<Font>(std::move(*font)),
                          std::make_unique<freetype::Face>(std::move(*face)), std::move(fine->asset)});
        return fonts_.back();
    }

    LoadedFont& font_of(const GlyphInstance& g) { return fonts_[g.key.font - 1]; }
    GlyphRect rect_of(const GlyphInstance& g) {
        return glyph_rect(font_of(g).font->asset().glyphs[g.key.glyph], g.key);
    }

    std::vector<freetype::CoverageImage> reference_images(const SubpixelLayout& layout, uint32_t cells) {
        std::vector<freetype::CoverageImage> images;
        for (const SetGlyph& g : glyphs_) {
            auto image = freetype::reference_coverage(*font_of(g.instance).face, g.instance.key, rect_of(g.instance),
                                                      layout, cells);
            if (!image) fail(kSuite, g.spec->path + ": reference: " + image.error().message);
            images.push_back(std::move(*image));
        }
        return images;
    }

    // The atlas after every power-of-two sample count: a renderer whose ramp adds 1, 1, 2, 4, ...
    // samples, so that frame k ends on 2^(k-1) samples, with an unbounded frame budget.
    std::vector<ErrorPoint> measure_crisp(const SubpixelLayout& layout, const char* layout_name, SampleKind kind,
                                          uint32_t max_samples,
                                          const std::vector<freetype::CoverageImage>& references) {
        HeadlessContext& context = *session_.context;
        RendererCreateInfo info = renderer_create_info(context);
        info.layout = layout;
        info.sample_kind = kind;
        info.atlas.width = info.atlas.height = 1024;
        info.atlas.max_samples = max_samples;
        info.atlas.frame_budget = uint64_t{1} << 50;
        info.atlas.ramp = {1};
        for (uint32_t n = 1; 2 * n <= max_samples; n *= 2) info.atlas.ramp.push_back(n);
        info.atlas.steady = 1;
        auto renderer = Renderer::create(info);
        if (!renderer) fail(kSuite, renderer.error().message);
        for (const LoadedFont& f : fonts_) {
            if (Status s = renderer->add_font(*f.font); !s) fail(kSuite, s.error().message);
        }
        std::vector<GlyphInstance> instances;
        for (const SetGlyph& g : glyphs_) instances.push_back(g.instance);

        std::vector<ErrorPoint> points;
        session_.json.begin_object()
            .field("layout", layout_name)
            .field("sample_kind", sample_kind_name(kind))
            .key("points")
            .begin_array();
        uint32_t expected = 0;
        for (size_t frame = 0; frame < info.atlas.ramp.size() || expected < max_samples; ++frame) {
            expected += frame < info.atlas.ramp.size() ? info.atlas.ramp[frame] : info.atlas.steady;
            expected = std::min(expected, max_samples);
            const Result<uint32_t> rendered =
                harness::render_until_converged(context, *renderer, 1, [&] { renderer->draw(instances); });
            if (!rendered) fail(kSuite, rendered.error().message);
            if ((expected & (expected - 1)) != 0 && expected != max_samples) continue;
            progress(kSuite, std::string(layout_name) + ", " + sample_kind_name(kind) + ": " +
                                 std::to_string(expected) + " samples");
            points.push_back(errors_at(*renderer, expected, references));
            if (expected == max_samples) break;
        }
        session_.json.end_array().key("split");
        split(layout, layout_name, kind, last_images_, references);
        session_.json.end_object();
        session_.coverage_error[{layout_name, sample_kind_name(kind)}] = points;
        return points;
    }

    // The atlas read back, each glyph's texels against its reference.
    ErrorPoint errors_at(const Renderer& renderer, uint32_t samples,
                         const std::vector<freetype::CoverageImage>& references) {
        Result<std::vector<harness::Texel>> atlas = harness::read_atlas(*session_.context, renderer);
        if (!atlas) fail(kSuite, atlas.error().message);
        const uint32_t atlas_width = renderer.atlas().config().width;
        std::vector<freetype::CoverageImage> images(glyphs_.size());
        for (size_t i = 0; i < glyphs_.size(); ++i) {
            const GlyphRect rect = rect_of(glyphs_[i].instance);
            images[i].width = rect.width;
            images[i].height = rect.height;
            images[i].values.assign(size_t{rect.width} * rect.height * 3, 0.0f);
        }
        uint64_t wrong_counts = 0;
        for (const DrawnGlyph& d : renderer.drawn()) {
            size_t i = 0;
            while (i < glyphs_.size() && !(glyphs_[i].instance.key == d.instance.key)) ++i;
            if (i == glyphs_.size()) continue;
            freetype::CoverageImage& image = images[i];
            for (uint32_t ty = 0; ty < d.instance.height; ++ty) {
                for (uint32_t tx = 0; tx < d.instance.width; ++tx) {
                    const harness::Texel& t = (*atlas)[size_t{d.atlas_y + ty} * atlas_width + d.atlas_x + tx];
                    if (t.count != samples) ++wrong_counts;
                    const float scale =
                        static_cast<float>(kCoverageOne) * static_cast<float>(std::max<uint16_t>(t.count, 1));
                    const uint16_t sums[3] = {t.r, t.g, t.b};
                    const size_t column = tx + d.part_x, row = ty + d.part_y;
                    if (column >= image.width || row >= image.height) continue;
                    for (size_t c = 0; c < 3; ++c) {
                        image.values[(row * image.width + column) * 3 + c] = static_cast<float>(sums[c]) / scale;
                    }
                }
            }
        }
        last_images_ = images;
        if (wrong_counts > 0) {
            session_.warn(kSuite, std::to_string(wrong_counts) + " texels did not hold " + std::to_string(samples) +
                                      " samples when read");
        }
        ErrorPoint point;
        point.samples = samples;
        last_samples_ = samples;
        std::vector<double> means, worsts;
        for (size_t i = 0; i < glyphs_.size(); ++i) {
            auto error = freetype::compare_coverage(images[i], references[i]);
            if (!error) fail(kSuite, error.error().message);
            means.push_back(error->mean);
            worsts.push_back(error->worst);
            point.mean += error->mean / static_cast<double>(glyphs_.size());
            point.worst = std::max(point.worst, error->worst);
        }
        session_.json.begin_object()
            .field("samples", samples)
            .field("mean", point.mean)
            .field("worst", point.worst)
            .field("glyph_mean", means)
            .field("glyph_worst", worsts)
            .end_object();
        return point;
    }

    // The exact area coverage of the glyph's curves in `asset` over the texels of its rect as the
    // GPU drew it, per channel rectangle of `layout` (the mapping of test_accuracy.cpp).
    freetype::CoverageImage exact_image(const FontAsset& asset, const GlyphInstance& g, const SubpixelLayout& layout) {
        const GlyphRect rect = rect_of(g);
        const ExactCoverage exact(asset, asset.glyphs[g.key.glyph]);
        const TexelToEm map = texel_to_em(rect, g.key);
        freetype::CoverageImage image;
        image.width = rect.width;
        image.height = rect.height;
        image.values.assign(size_t{rect.width} * rect.height * 3, 0.0f);
        const double ox = map.offset_x, oy = map.offset_y, sx = map.scale_x, sy = map.scale_y;
        for (uint32_t row = 0; row < rect.height; ++row) {
            for (uint32_t column = 0; column < rect.width; ++column) {
                for (size_t c = 0; c < 3; ++c) {
                    const SampleRect& r = layout.channels[c];
                    const double x0 = ox + sx * (column + static_cast<double>(r.x0));
                    const double x1 = ox + sx * (column + static_cast<double>(r.x1));
                    const double ya = oy + sy * (row + static_cast<double>(r.y0));
                    const double yb = oy + sy * (row + static_cast<double>(r.y1));
                    image.values[(size_t{row} * rect.width + column) * 3 + c] =
                        static_cast<float>(exact.coverage(x0, std::min(ya, yb), x1, std::max(ya, yb)));
                }
            }
        }
        return image;
    }

    // The error at the largest sample count split into its parts, per glyph, on the CPU: sampling
    // (the atlas against the exact area of the curves it was drawn from), lowering (those curves'
    // exact area against the same glyph baked at kFineToleranceEm) and the reference's own error
    // (FreeType's cells against that fine bake). At the worst texel of the total (atlas against
    // FreeType), the three signed parts add up to it.
    void split(const SubpixelLayout& layout, const char* layout_name, SampleKind kind,
               const std::vector<freetype::CoverageImage>& atlas,
               const std::vector<freetype::CoverageImage>& references) {
        split_md_ += format(
            "\nThe error at %u samples (%s, %s) split into its parts: sampling (atlas against the exact "
            "area of the baked curves), lowering (baked curves against the glyph baked at %g em), "
            "reference (FreeType's cells against that). Worst of each over the glyph's texels; then the "
            "worst texel of the total and its three signed parts.\n\n"
            "| glyph | px | total: mean | worst | sampling: worst | lowering: worst | reference: worst "
            "| worst texel: total = sampling + lowering + reference |\n"
            "|---|---:|---:|---:|---:|---:|---:|---|\n",
            last_samples_, layout_name, sample_kind_name(kind), static_cast<double>(kFineToleranceEm));
        session_.json.begin_object()
            .field("layout", layout_name)
            .field("sample_kind", sample_kind_name(kind))
            .field("samples", last_samples_)
            .field("fine_tolerance_em", static_cast<double>(kFineToleranceEm))
            .key("glyphs")
            .begin_array();
        for (size_t i = 0; i < glyphs_.size(); ++i) {
            const GlyphInstance& g = glyphs_[i].instance;
            const freetype::CoverageImage baked = exact_image(font_of(g).font->asset(), g, layout);
            const freetype::CoverageImage fine = exact_image(font_of(g).fine, g, layout);
            auto total = freetype::compare_coverage(atlas[i], references[i]);
            auto sampling = freetype::compare_coverage(atlas[i], baked);
            auto lowering = freetype::compare_coverage(baked, fine);
            auto reference = freetype::compare_coverage(fine, references[i]);
            if (!total || !sampling || !lowering || !reference) fail(kSuite, "split: images of different sizes");
            const uint32_t at_column = total->worst_column, at_row = total->worst_row,
                           at_channel = total->worst_channel;
            auto at = [&](const freetype::CoverageImage& image) {
                return static_cast<double>(image.at(at_column, at_row, at_channel));
            };
            const double part_sampling = at(atlas[i]) - at(baked);
            const double part_lowering = at(baked) - at(fine);
            const double part_reference = at(fine) - at(references[i]);
            const std::string name =
                std::filesystem::path(glyphs_[i].spec->path).filename().string() + " U+" + hex(glyphs_[i].codepoint);
            split_md_ += format("| %s | %g | %.4f | %.4f | %.4f | %.4f | %.4f | %+.4f = %+.4f %+.4f %+.4f |\n",
                                name.c_str(), static_cast<double>(glyphs_[i].spec->size), total->mean, total->worst,
                                sampling->worst, lowering->worst, reference->worst, at(atlas[i]) - at(references[i]),
                                part_sampling, part_lowering, part_reference);
            session_.json.begin_object()
                .field("glyph", name)
                .field("size", glyphs_[i].spec->size)
                .field("total_mean", total->mean)
                .field("total_worst", total->worst)
                .field("sampling_mean", sampling->mean)
                .field("sampling_worst", sampling->worst)
                .field("lowering_mean", lowering->mean)
                .field("lowering_worst", lowering->worst)
                .field("reference_mean", reference->mean)
                .field("reference_worst", reference->worst)
                .field("worst_texel_sampling", part_sampling)
                .field("worst_texel_lowering", part_lowering)
                .field("worst_texel_reference", part_reference)
                .end_object();
        }
        session_.json.end_array().end_object();
    }

    template <class... Args>
    static std::string format(const char* pattern, Args... args) {
        const int n = std::snprintf(nullptr, 0, pattern, args...);
        std::string text(static_cast<size_t>(std::max(n, 0)) + 1, '\0');
        std::snprintf(text.data(), text.size(), pattern, args...);
        text.pop_back();
        return text;
    }

    static std::string hex(uint32_t codepoint) {
        char text[16];
        std::snprintf(text, sizeof text, "%04X", codepoint);
        return text;
    }

    // FreeType as an application renders: gray against the gray reference; LCD, with and without
    // its default filter, against the rgb one.
    void peers(const std::string& layout_name, const std::vector<freetype::CoverageImage>& references) {
        struct Peer {
            freetype::PeerMode mode;
            const char* name;
        };
        const std::vector<Peer> modes = layout_name == "gray"
                                            ? std::vector<Peer>{{freetype::PeerMode::gray, "gray"}}
                                            : std::vector<Peer>{{freetype::PeerMode::lcd, "lcd"},
                                                                {freetype::PeerMode::lcd_unfiltered, "lcd-unfiltered"}};
        for (const Peer& peer : modes) {
            ErrorPoint point;
            double seconds = 0.0;
            std::vector<double> means, worsts, times;
            for (size_t i = 0; i < glyphs_.size(); ++i) {
                const GlyphInstance& g = glyphs_[i].instance;
                auto render = freetype::render_peer(*font_of(g).face, g.key, rect_of(g), peer.mode);
                if (!render) fail(kSuite, "FreeType " + std::string(peer.name) + ": " + render.error().message);
                auto error = freetype::compare_coverage(render->image, references[i]);
                if (!error) fail(kSuite, error.error().message);
                means.push_back(error->mean);
                worsts.push_back(error->worst);
                times.push_back(render->seconds_per_glyph * 1e6);
                point.mean += error->mean / static_cast<double>(glyphs_.size());
                point.worst = std::max(point.worst, error->worst);
                seconds += render->seconds_per_glyph / static_cast<double>(glyphs_.size());
            }
            session_.freetype_error[peer.name] = point;
            std::fprintf(session_.md, "| FreeType %s (CPU, %.3g µs a glyph) | %.4f | %.4f |\n", peer.name,
                         seconds * 1e6, point.mean, point.worst);
            freetype_json_.push_back({peer.name, layout_name, point, seconds * 1e6, means, worsts, times});
        }
    }

    void print_glyph_set() {
        std::fprintf(session_.md,
                     "crisp's atlas texels after N samples (read back from the GPU; the renderer's ramp set to 1, 1, "
                     "2, 4, ... so that a frame ends on every power of two; rows and points are the two "
                     "RendererCreateInfo::sample_kind) against FreeType's area coverage of the original outline, cut "
                     "into %ux%u cells per texel for gray and %ux%u for rgb thirds (support/freetype_reference.hpp). "
                     "Error: mean absolute error per texel channel over the texels either image touches, averaged "
                     "over the glyphs; worst: the largest single texel channel of any glyph. FreeType as a peer: "
                     "unhinted, as an application renders, its time per glyph the median of 9 "
                     "FT_Load_Glyph + FT_Render_Glyph, averaged over the glyphs.\n\n"
                     "| glyphs | font | px | what | texels |\n|---|---|---:|---|---:|\n",
                     options_.cells_gray, options_.cells_gray, options_.cells_rgb, options_.cells_rgb);
        for (const GlyphSpec& spec : specs_) {
            uint64_t texels = 0;
            bool present = false;
            for (const SetGlyph& g : glyphs_) {
                if (g.spec != &spec) continue;
                present = true;
                texels += uint64_t{g.instance.width} * g.instance.height;
            }
            if (!present) continue;
            const std::string variations = describe_variations(spec.variations);
            std::fprintf(session_.md, "| %s | %s%s | %g | %s | %llu |\n", spec.text.c_str(),
                         std::filesystem::path(spec.path).filename().c_str(),
                         variations.empty() ? "" : (" " + variations).c_str(), static_cast<double>(spec.size),
                         spec.what.c_str(), static_cast<unsigned long long>(texels));
        }
        std::fprintf(session_.md,
                     "\nEach font baked with the glyphs it draws here, for the largest size it draws them at "
                     "(BakeOptions::max_size_px, crisp-bake --max-size) unless --tolerance is given:\n\n"
                     "| font | tolerance (em) | cubics | quadratic pieces | largest deviation (px at size) | curves "
                     "|\n|---|---:|---:|---:|---:|---:|\n");
        for (const BakeNote& note : bake_notes_) {
            const BakeReport& r = note.report;
            std::fprintf(session_.md, "| %s | %.3g | %llu | %llu | %.5f at %g | %llu |\n", note.font.c_str(),
                         r.tolerance_em, static_cast<unsigned long long>(r.cubic_count),
                         static_cast<unsigned long long>(r.cubic_pieces), r.max_deviation_px, r.report_size_px,
                         static_cast<unsigned long long>(r.curve_count));
        }
        std::fprintf(session_.md, "\n");
    }

    void print_table(const char* layout_name, const std::vector<SampleKind>& kinds,
                     const std::map<std::string, std::vector<ErrorPoint>>& by_kind) {
        std::fprintf(session_.md, "%s layout, %zu glyphs.\n\n| samples |", layout_name, glyphs_.size());
        for (const SampleKind kind : kinds) std::fprintf(session_.md, " %s: mean | worst |", sample_kind_name(kind));
        std::fprintf(session_.md, "\n|---|");
        for (size_t k = 0; k < kinds.size(); ++k) std::fprintf(session_.md, "---:|---:|");
        std::fprintf(session_.md, "\n");
        const std::vector<ErrorPoint>& first = by_kind.at(sample_kind_name(kinds.front()));
        for (size_t p = 0; p < first.size(); ++p) {
            std::fprintf(session_.md, "| %u |", first[p].samples);
            for (const SampleKind kind : kinds) {
                const ErrorPoint& e = by_kind.at(sample_kind_name(kind))[p];
                std::fprintf(session_.md, " %.4f | %.4f |", e.mean, e.worst);
            }
            std::fprintf(session_.md, "\n");
        }
        std::fprintf(session_.md, "\n| peer | mean | worst |\n|---|---:|---:|\n");
    }

    void write_glyph_set_json(uint32_t max_samples) {
        session_.json.field("max_samples", max_samples)
            .field("cells_gray", options_.cells_gray)
            .field("cells_rgb", options_.cells_rgb);
        session_.json.key("bakes").begin_array();
        for (const BakeNote& note : bake_notes_) {
            session_.json.begin_object()
                .field("font", note.font)
                .field("tolerance_em", note.report.tolerance_em)
                .field("size_px", note.report.report_size_px)
                .field("max_deviation_px", note.report.max_deviation_px)
                .field("cubics", note.report.cubic_count)
                .field("cubic_pieces", note.report.cubic_pieces)
                .field("curves", note.report.curve_count)
                .end_object();
        }
        session_.json.end_array().key("glyphs").begin_array();
        for (const SetGlyph& g : glyphs_) {
            session_.json.begin_object()
                .field("font", g.spec->path)
                .field("variations", describe_variations(g.spec->variations))
                .field("codepoint", g.codepoint)
                .field("glyph", g.instance.key.glyph)
                .field("size", g.spec->size)
                .field("what", g.spec->what)
                .field("subpixel_x", g.instance.key.subpixel_x)
                .field("subpixel_y", g.instance.key.subpixel_y)
                .field("width", g.instance.width)
                .field("height", g.instance.height)
                .end_object();
        }
        session_.json.end_array();
    }

    void write_peers_json() {
        session_.json.key("freetype").begin_array();
        for (const PeerJson& p : freetype_json_) {
            session_.json.begin_object()
                .field("mode", p.mode)
                .field("layout", p.layout)
                .field("mean", p.error.mean)
                .field("worst", p.error.worst)
                .field("us_per_glyph", p.us_per_glyph)
                .field("glyph_mean", p.means)
                .field("glyph_worst", p.worsts)
                .field("glyph_us", p.times)
                .end_object();
        }
        session_.json.end_array();
    }

    struct PeerJson {
        std::string mode, layout;
        ErrorPoint error;
        double us_per_glyph = 0.0;
        std::vector<double> means, worsts, times;
    };
    Session& session_;
    const Options& options_;
    std::vector<GlyphSpec> specs_;  // glyphs_ point into it
    std::vector<LoadedFont> fonts_;
    std::vector<SetGlyph> glyphs_;
    std::vector<PeerJson> freetype_json_;
    std::vector<freetype::CoverageImage> last_images_;  // the atlas's texels at the last count read
    uint32_t last_samples_ = 0;
    std::string split_md_;  // split()'s tables, printed after the layout's table and peers
    struct BakeNote {
        std::string font;
        BakeReport report;
    };
    std::vector<BakeNote> bake_notes_;  // each font's bake: its tolerance, deviation and curves
};

}  // namespace

void run_coverage(Session& session) {
    Coverage coverage(session, glyph_set(session.options));
    coverage.load();
    coverage.run();
}

}  // namespace crisp::bench
