// crisp-bench --suite contrast: how heavy the same coverage looks dark on light beside light on
// dark, per contrast setting and size (docs/contrast.md). Per font and size, one line of prose is
// rendered in gray to convergence, then composited on the tile path over an opaque white canvas in
// black and over a black one in white, under each setting (DrawOptions::contrast: the atlas is the
// same for all). FreeType's rasterizer is the peer: its gray coverage on the same pixels, blended
// glyph after glyph linearly and on sRGB-encoded values, as applications do. Per image: the ink
// (the mean over the canvas of |enc(out) - enc(bg)| / |enc(text) - enc(bg)|, enc = sRGB: how much
// darker or lighter the text makes its canvas, as the eye compares them) and the stem contrast (the
// same mean over the pixels whose linear coverage is at least 1/2). Pictures: the first font at
// kPictureSize px, dark and light, linear and default, magnified kMagnify times.
#include "bench.hpp"
#include "core/utf8.hpp"
#include "freetype_reference.hpp"
#include "image_io.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/contrast.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "contrast";
constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
// Samples each glyph converges to, all in the first frame: the coverage is converged well within
// what an 8-bit picture shows, and the measurement is of compositing, not of sampling.
constexpr uint32_t kSamples = 256;
constexpr float kPictureSize = 11.0f;
constexpr uint32_t kMagnify = 3;
// Pixels whose linear coverage reaches this are a stem's: the cores of stems and bowls.
constexpr double kStemCoverage = 0.5;

const char* const kProse = "It was the best of times, it was the worst of times,";
// Noto Sans CJK is measured on CJK strokes too.
const char* const kCjkProse = "It was the best of times, 永字八法の文字は同じ重さ。";

struct FontSpec {
    std::string name;
    std::string path;
    uint32_t face = 0;
    const char* text = kProse;
};

struct Setting {
    std::string name;
    TextContrast contrast;
};

std::vector<Setting> crisp_settings() {
    std::vector<Setting> settings;
    TextContrast linear;
    linear.mode = ContrastMode::linear;
    settings.push_back({"linear", linear});
    settings.push_back({"default", TextContrast{}});
    TextContrast gamma;
    gamma.gamma = 1.8f;
    settings.push_back({"gamma 1.8", gamma});
    TextContrast enhanced;
    enhanced.contrast = 0.5f;
    settings.push_back({"contrast 0.5", enhanced});
    TextContrast darkened;
    darkened.stem_darkening = 1.0f;
    settings.push_back({"stem darkening 1", darkened});
    return settings;
}

// An opaque image in linear light: width * height RGB, top row first.
struct Canvas {
    uint32_t width = 0, height = 0;
    std::vector<float> rgb;
};

struct Ink {
    double ink = 0.0;   // the mean encoded ink over the canvas
    double stem = 0.0;  // the same over the stem pixels
};

struct Row {
    std::string setting;
    float size = 0.0f;
    Ink dark, light;  // black on white, white on black
};

// `image`'s encoded ink for text of linear value `text` over `background` (0 or 1, all channels),
// over the canvas and over the pixels whose gray coverage (`coverage`, one value a pixel) is a stem's.
Ink measure(const Canvas& image, const std::vector<float>& coverage, double text, double background) {
    const double enc_text = linear_to_srgb(text), enc_background = linear_to_srgb(background);
    const size_t pixels = size_t{image.width} * image.height;
    double sum = 0.0, stem_sum = 0.0;
    size_t stems = 0;
    for (size_t p = 0; p < pixels; ++p) {
        double ink = 0.0;
        for (size_t c = 0; c < 3; ++c) {
            ink +=
                std::abs(linear_to_srgb(image.rgb[p * 3 + c]) - enc_background) / std::abs(enc_text - enc_background);
        }
        ink /= 3.0;
        sum += ink;
        if (double{coverage[p]} >= kStemCoverage) {
            stem_sum += ink;
            ++stems;
        }
    }
    return {sum / static_cast<double>(pixels), stems ? stem_sum / static_cast<double>(stems) : 0.0};
}

// The first font's pictures, magnified with nearest neighbour.
Status write_picture(const std::filesystem::path& path, const Canvas& image) {
    const uint32_t width = image.width * kMagnify, height = image.height * kMagnify;
    std::vector<float> rgb(size_t{width} * height * 3);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const size_t from = (size_t{y / kMagnify} * image.width + x / kMagnify) * 3;
            std::copy_n(&image.rgb[from], 3, &rgb[(size_t{y} * width + x) * 3]);
        }
    }
    return write_png_srgb8(path, width, height, 3, rgb);
}

class ContrastSuite {
public:
    explicit ContrastSuite(Session& session) : session_(session), context_(*session.context) {
        CompositorCreateInfo info = compositor_create_info(context_);
        info.frames_in_flight = 1;
        auto compositor = Compositor::create(info);
        if (!compositor) fail(kSuite, compositor.error().message);
        if (!compositor->supports_target_format(kFormat)) fail(kSuite, "the device cannot store to RGBA32F");
        compositor_.emplace(std::move(*compositor));
    }

    // Every size of `spec`: its rows, and the pictures where `pictures` (the first font).
    std::vector<Row> run_font(const FontSpec& spec, const std::vector<float>& sizes, bool pictures) {
        BakeOptions bake;
        bake.all_glyphs = false;
        bake.codepoints = decode_utf8(spec.text);
        bake.face_index = spec.face;
        auto baked = bake_font_file(spec.path, bake);
        if (!baked) fail(kSuite, spec.path + ": " + baked.error().message);
        auto font = Font::create(std::move(baked->asset), 1);
        if (!font) fail(kSuite, spec.path + ": " + font.error().message);
        auto face = freetype::Face::open_file(spec.path, spec.face);
        if (!face) fail(kSuite, spec.path + ": FreeType: " + face.error().message);
        std::vector<Row> rows;
        for (const float size : sizes) {
            progress(kSuite, spec.name + " at " + format_size(size) + " px");
            const std::vector<Row> at_size = run_size(spec, *font, *face, size, pictures && size == kPictureSize);
            rows.insert(rows.end(), at_size.begin(), at_size.end());
        }
        return rows;
    }

    const std::vector<std::string>& pictures() const { return pictures_; }

    static std::string format_size(float size) { return std::to_string(static_cast<int>(size)); }

private:
    std::vector<Row> run_size(const FontSpec& spec, const Font& font, freetype::Face& face, float size, bool pictures) {
        const Font* fonts[] = {&font};
        TextStyle style;
        style.size = size;
        LayoutOptions layout_options;
        layout_options.origin_x = 4.25f;
        layout_options.origin_y = std::ceil(size * 1.15f) + 1.0f;
        auto laid = layout_text(fonts, spec.text, style, layout_options);
        if (!laid) fail(kSuite, laid.error().message);
        const std::vector<GlyphInstance>& glyphs = laid->glyphs;
        int32_t right = 0, bottom = 0;
        for (const GlyphInstance& g : glyphs) {
            if (g.y < 0) fail(kSuite, "a glyph rises above the canvas");
            right = std::max(right, g.x + static_cast<int32_t>(g.width));
            bottom = std::max(bottom, g.y + static_cast<int32_t>(g.height));
        }
        const uint32_t width = static_cast<uint32_t>(right) + 4, height = static_cast<uint32_t>(bottom) + 2;

        auto layout = resolve_subpixel_layout("gray");
        if (!layout) fail(kSuite, layout.error().message);
        RendererCreateInfo info = renderer_create_info(context_);
        info.layout = *layout;
        info.atlas.width = info.atlas.height = 512;
        info.atlas.max_samples = kSamples;
        info.atlas.ramp = {kSamples};
        info.atlas.frame_budget = uint64_t{1} << 50;
        auto renderer = Renderer::create(info);
        if (!renderer) fail(kSuite, renderer.error().message);
        if (Status s = renderer->add_font(font); !s) fail(kSuite, s.error().message);
        for (uint32_t frame = 0; frame == 0 || !renderer->converged(); ++frame) {
            if (frame == 8) fail(kSuite, "the text did not converge in 8 frames");
            renderer->begin_frame();
            renderer->draw(glyphs);
            Status recorded;
            const Status submitted =
                context_.submit_and_wait([&](VkCommandBuffer cb) { recorded = renderer->record(cb); });
            if (!recorded) fail(kSuite, recorded.error().message);
            if (!submitted) fail(kSuite, submitted.error().message);
        }

        ImageDesc desc;
        desc.format = kFormat;
        desc.width = width;
        desc.height = height;
        desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        auto target = context_.create_image(desc);
        if (!target) fail(kSuite, target.error().message);

        // Each setting dark and light; the coverage of a pixel is what linear black on white removes.
        std::vector<Row> rows;
        std::vector<float> coverage;
        for (const Setting& setting : crisp_settings()) {
            Row row{setting.name, size, {}, {}};
            for (const bool dark : {true, false}) {
                const Canvas image = composite(*renderer, glyphs, *target, width, height, setting.contrast, dark);
                if (coverage.empty()) {
                    coverage.resize(size_t{width} * height);
                    for (size_t p = 0; p < coverage.size(); ++p) coverage[p] = 1.0f - image.rgb[p * 3 + 1];
                }
                (dark ? row.dark : row.light) = measure(image, coverage, dark ? 0.0 : 1.0, dark ? 1.0 : 0.0);
                if (pictures && (setting.name == "linear" || setting.name == "default")) {
                    const Options& o = session_.options;
                    const std::filesystem::path dir = o.pictures_dir.empty() ? o.out_dir : o.pictures_dir;
                    const std::filesystem::path path =
                        dir / (session_.name + (dark ? "-dark-" : "-light-") + setting.name + ".png");
                    if (o.write_files) {
                        std::error_code ec;
                        std::filesystem::create_directories(dir, ec);
                        if (Status s = write_picture(path, image); !s) fail(kSuite, s.error().message);
                    }
                    // As the report links it: from the directory it is written in.
                    pictures_.push_back(std::filesystem::proximate(path, o.out_dir).generic_string());
                }
            }
            rows.push_back(row);
        }
        freetype_rows(face, font, glyphs, width, height, size, rows);
        return rows;
    }

    // One composite of the converged glyphs over an opaque canvas: black on white or white on black.
    Canvas composite(Renderer& renderer, const std::vector<GlyphInstance>& glyphs, const Image& target, uint32_t width,
                     uint32_t height, const TextContrast& contrast, bool dark) {
        const float background = dark ? 1.0f : 0.0f, text = dark ? 0.0f : 1.0f;
        const std::vector<float> backdrop(size_t{width} * height * 4, background);
        std::vector<float> opaque = backdrop;
        for (size_t p = 3; p < opaque.size(); p += 4) opaque[p] = 1.0f;
        DrawOptions options;
        options.color = std::array<float, 4>{text, text, text, 1.0f};
        options.contrast = contrast;
        const VkRect2D rect{{0, 0}, {width, height}};
        // Twice: the compositor sizes a frame's bins from the one before.
        for (int frame = 0; frame < 2; ++frame) {
            if (Status s = context_.upload(target, std::as_bytes(std::span(opaque)), VK_IMAGE_LAYOUT_GENERAL); !s) {
                fail(kSuite, s.error().message);
            }
            renderer.begin_frame();
            renderer.draw(glyphs, options);
            Status recorded;
            const Status submitted = context_.submit_and_wait([&](VkCommandBuffer cb) {
                recorded = renderer.record(cb);
                if (!recorded) return;
                const CompositeTarget composite_target{target.view(), kFormat, VK_FORMAT_UNDEFINED, rect.extent, rect};
                recorded = compositor_->record(cb, renderer.drawn_frame(), composite_target);
            });
            if (!recorded) fail(kSuite, recorded.error().message);
            if (!submitted) fail(kSuite, submitted.error().message);
        }
        auto bytes = context_.read_image(target, VK_IMAGE_LAYOUT_GENERAL);
        if (!bytes) fail(kSuite, bytes.error().message);
        std::vector<float> rgba(size_t{width} * height * 4);
        std::memcpy(rgba.data(), bytes->data(), rgba.size() * sizeof(float));
        Canvas image{width, height, std::vector<float>(size_t{width} * height * 3)};
        for (size_t p = 0; p < size_t{width} * height; ++p) std::copy_n(&rgba[p * 4], 3, &image.rgb[p * 3]);
        return image;
    }

    // FreeType's gray coverage of the same glyphs on the same pixels, blended glyph after glyph
    // linearly and on sRGB-encoded values (coverage as the weight of the encoded colours).
    void freetype_rows(freetype::Face& face, const Font& font, const std::vector<GlyphInstance>& glyphs, uint32_t width,
                       uint32_t height, float size, std::vector<Row>& rows) {
        struct Peer {
            const char* name;
            bool encoded;
        };
        std::vector<freetype::CoverageImage> images;
        for (const GlyphInstance& g : glyphs) {
            if (g.width == 0) {
                images.emplace_back();
                continue;
            }
            const GlyphRect rect = glyph_rect(font.asset().glyphs[g.key.glyph], g.key);
            auto render = freetype::render_peer(face, g.key, rect, freetype::PeerMode::gray, 1);
            if (!render) fail(kSuite, "FreeType: " + render.error().message);
            images.push_back(std::move(render->image));
        }
        const size_t pixels = size_t{width} * height;
        std::vector<float> coverage(pixels, 0.0f);
        for (size_t i = 0; i < glyphs.size(); ++i) {
            place(glyphs[i], images[i], width, height,
                  [&](size_t p, float c) { coverage[p] = 1.0f - (1.0f - coverage[p]) * (1.0f - c); });
        }
        for (const Peer peer : {Peer{"FreeType, linear", false}, Peer{"FreeType, sRGB", true}}) {
            Row row{peer.name, size, {}, {}};
            for (const bool dark : {true, false}) {
                const float background = dark ? 1.0f : 0.0f, text = dark ? 0.0f : 1.0f;
                // sRGB's ends are 0 and 1 too, so the encoded blend runs on the same values.
                std::vector<float> value(pixels, background);
                for (size_t i = 0; i < glyphs.size(); ++i) {
                    place(glyphs[i], images[i], width, height,
                          [&](size_t p, float c) { value[p] = value[p] * (1.0f - c) + text * c; });
                }
                Canvas image{width, height, std::vector<float>(pixels * 3)};
                for (size_t p = 0; p < pixels; ++p) {
                    const float linear = peer.encoded ? srgb_to_linear(value[p]) : value[p];
                    std::fill_n(&image.rgb[p * 3], 3, linear);
                }
                (dark ? row.dark : row.light) = measure(image, coverage, text, background);
            }
            rows.push_back(row);
        }
    }

    // Calls visit(pixel, coverage) for each texel of `image` on the canvas, at the glyph's rect.
    template <class Visit>
    static void place(const GlyphInstance& g, const freetype::CoverageImage& image, uint32_t width, uint32_t height,
                      Visit&& visit) {
        for (uint32_t row = 0; row < image.height; ++row) {
            for (uint32_t column = 0; column < image.width; ++column) {
                const int64_t x = int64_t{g.x} + column, y = int64_t{g.y} + row;
                if (x < 0 || y < 0 || x >= width || y >= height) continue;
                const float c = image.at(column, row, 1);
                if (c > 0.0f) visit(static_cast<size_t>(y) * width + static_cast<size_t>(x), c);
            }
        }
    }

    Session& session_;
    HeadlessContext& context_;
    std::optional<Compositor> compositor_;
    std::vector<std::string> pictures_;
};

double ratio(const Row& row) {
    return row.light.ink > 0.0 ? row.dark.ink / row.light.ink : 0.0;
}

void print_markdown(std::FILE* md, const std::vector<FontSpec>& fonts, const std::vector<std::vector<Row>>& rows,
                    const std::vector<std::string>& pictures) {
    std::fprintf(md,
                 "One line of prose per font and size, gray, %u samples (converged), composited on the tile path in "
                 "black over opaque white (dark) and in white over opaque black (light), under each setting: linear; "
                 "default (corrected, gamma 2.2); gamma 1.8; contrast 0.5 and stem darkening 1 (each with gamma "
                 "2.2). FreeType: its gray coverage (unhinted) on the same pixels, blended glyph after glyph in "
                 "linear light, and on sRGB-encoded values (coverage as the weight of the encoded colours, as "
                 "blending into an sRGB target without conversion does). Ink: the mean over the canvas (the line's "
                 "box and a margin) of |enc(out) - enc(bg)| / |enc(text) - enc(bg)|, enc = sRGB; ratio: dark / "
                 "light (1: equally heavy). Stem: the same mean over the pixels whose linear coverage is at least "
                 "%.1f (crisp's own, FreeType's for its rows): how dark stems get, not only how much ink there is "
                 "(docs/contrast.md).\n",
                 kSamples, kStemCoverage);
    std::fprintf(md, "\n### contrast: ink ratio (dark / light) over the sizes, lowest to highest\n\n| setting |");
    for (const FontSpec& font : fonts) std::fprintf(md, " %s |", font.name.c_str());
    std::fprintf(md, "\n|---|");
    for (size_t f = 0; f < fonts.size(); ++f) std::fprintf(md, "---:|");
    std::fprintf(md, "\n");
    for (const Row& first : rows[0]) {
        if (first.size != rows[0][0].size) break;
        std::fprintf(md, "| %s |", first.setting.c_str());
        for (const std::vector<Row>& font_rows : rows) {
            double low = 1e9, high = 0.0;
            for (const Row& row : font_rows) {
                if (row.setting != first.setting) continue;
                low = std::min(low, ratio(row));
                high = std::max(high, ratio(row));
            }
            std::fprintf(md, " %.2f-%.2f |", low, high);
        }
        std::fprintf(md, "\n");
    }
    for (size_t f = 0; f < fonts.size(); ++f) {
        std::fprintf(md, "\n### contrast: %s\n\n", fonts[f].name.c_str());
        std::fprintf(md,
                     "| setting | px | ink dark | ink light | ratio | stem dark | stem light |\n"
                     "|---|---:|---:|---:|---:|---:|---:|\n");
        for (const Row& row : rows[f]) {
            std::fprintf(md, "| %s | %.0f | %.4f | %.4f | %.2f | %.3f | %.3f |\n", row.setting.c_str(),
                         double{row.size}, row.dark.ink, row.light.ink, ratio(row), row.dark.stem, row.light.stem);
        }
    }
    if (!pictures.empty()) {
        std::fprintf(md, "\n### contrast: pictures (%s at %.0f px, magnified %ux)\n\n", fonts[0].name.c_str(),
                     double{kPictureSize}, kMagnify);
        for (const std::string& picture : pictures) {
            const std::string name = std::filesystem::path(picture).filename().string();
            std::fprintf(md, "![%s](%s)\n\n", name.c_str(), picture.c_str());
        }
    }
}

void write_json(JsonWriter& json, const std::vector<FontSpec>& fonts, const std::vector<std::vector<Row>>& rows,
                const std::vector<std::string>& pictures) {
    json.begin_object()
        .field("samples", kSamples)
        .field("layout", "gray")
        .field("stem_coverage", kStemCoverage)
        .field("picture_size", kPictureSize)
        .field("magnify", kMagnify)
        .field("pictures", pictures);
    json.key("fonts").begin_array();
    for (size_t f = 0; f < fonts.size(); ++f) {
        json.begin_object()
            .field("name", fonts[f].name)
            .field("path", fonts[f].path)
            .field("face", fonts[f].face)
            .field("text", std::string(fonts[f].text));
        json.key("rows").begin_array();
        for (const Row& row : rows[f]) {
            json.begin_object()
                .field("setting", row.setting)
                .field("size", row.size)
                .field("ink_dark", row.dark.ink)
                .field("ink_light", row.light.ink)
                .field("ratio", ratio(row))
                .field("stem_dark", row.dark.stem)
                .field("stem_light", row.light.stem)
                .end_object();
        }
        json.end_array().end_object();
    }
    json.end_array().end_object();
}

}  // namespace

void run_contrast(Session& session) {
    const Options& o = session.options;
    std::vector<FontSpec> fonts = {{"DejaVu Sans", o.dejavu, 0, kProse}};
    std::vector<float> sizes = {9.0f, kPictureSize, 16.0f};
    if (!o.quick) {
        fonts.push_back({"Inter", o.inter, 0, kProse});
        fonts.push_back({"Noto Sans CJK", o.cjk, 0, kCjkProse});
        sizes.clear();
        for (int size = 9; size <= 16; ++size) sizes.push_back(static_cast<float>(size));
    }
    std::fprintf(session.md, "Device: %s, driver %s (%s).\n\n", session.context->device_name().c_str(),
                 session.context->driver_name().c_str(), session.context->driver_info().c_str());
    ContrastSuite suite(session);
    std::vector<std::vector<Row>> rows;
    for (size_t f = 0; f < fonts.size(); ++f) rows.push_back(suite.run_font(fonts[f], sizes, f == 0));
    print_markdown(session.md, fonts, rows, suite.pictures());
    write_json(session.json, fonts, rows, suite.pictures());
}

}  // namespace crisp::bench
