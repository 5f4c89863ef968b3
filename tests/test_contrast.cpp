// The contrast model (include/crisp/contrast.hpp). Two parts: the settings' checks and the CPU
// reference in crisp_tests (label cpu); in crisp_vulkan_tests (CRISP_GPU_TESTS, label gpu, lavapipe
// with validation and synchronization validation on) the compositor against that reference, linear
// frames bit for bit, the ink ratio the default was chosen for, edges and per-draw overrides.
#include "shared.h"

#include <crisp/contrast.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#ifdef CRISP_GPU_TESTS
#include "composite_fixture.hpp"
#include "gpu_tools.hpp"
#include "headless_context.hpp"
#include "test_support.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>

#include <cstring>
#include <memory>
#include <optional>
#include <span>
#endif

namespace crisp {
namespace {

double srgb_encode(double c) {
    c = std::clamp(c, 0.0, 1.0);
    return c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}

#ifndef CRISP_GPU_TESTS

// ---- Settings ----------------------------------------------------------------------------------

TEST(ContrastSettings, ValidationRefusesBadValuesNamingTheField) {
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
    constexpr float kInf = std::numeric_limits<float>::infinity();
    struct Case {
        TextContrast contrast;
        const char* field;  // how the message names it
    };
    const auto with = [](auto set) {
        TextContrast c;
        set(c);
        return c;
    };
    const Case cases[] = {
        {with([&](TextContrast& c) { c.gamma = kNan; }), "gamma"},
        {with([&](TextContrast& c) { c.gamma = kInf; }), "gamma"},
        {with([&](TextContrast& c) { c.gamma = -kInf; }), "gamma"},
        {with([](TextContrast& c) { c.gamma = -2.2f; }), "gamma"},
        {with([](TextContrast& c) { c.gamma = 0.0f; }), "gamma"},
        {with([](TextContrast& c) { c.gamma = 0.99f; }), "gamma"},
        {with([](TextContrast& c) { c.gamma = 4.01f; }), "gamma"},
        {with([&](TextContrast& c) { c.contrast = kNan; }), "contrast: contrast"},
        {with([&](TextContrast& c) { c.contrast = kInf; }), "contrast: contrast"},
        {with([](TextContrast& c) { c.contrast = -0.01f; }), "contrast: contrast"},
        {with([](TextContrast& c) { c.contrast = 4.5f; }), "contrast: contrast"},
        {with([&](TextContrast& c) { c.stem_darkening = kNan; }), "stem_darkening"},
        {with([&](TextContrast& c) { c.stem_darkening = kInf; }), "stem_darkening"},
        {with([](TextContrast& c) { c.stem_darkening = -1.0f; }), "stem_darkening"},
        {with([](TextContrast& c) { c.stem_darkening = 4.25f; }), "stem_darkening"},
        {with([](TextContrast& c) { c.mode = static_cast<ContrastMode>(2); }), "mode"},
        {with([](TextContrast& c) { c.mode = static_cast<ContrastMode>(0xFFFFFFFFu); }), "mode"},
        // Linear mode checks the parameters too: a setting is valid or not whatever its mode.
        {with([&](TextContrast& c) {
             c.mode = ContrastMode::linear;
             c.gamma = kNan;
         }),
         "gamma"},
    };
    for (const Case& c : cases) {
        const Status s = validate_text_contrast(c.contrast);
        ASSERT_FALSE(s) << c.field;
        EXPECT_EQ(s.error().code, ErrorCode::invalid_argument);
        EXPECT_EQ(s.error().message.rfind("contrast: ", 0), 0u) << s.error().message;
        EXPECT_NE(s.error().message.find(c.field), std::string::npos) << s.error().message;
    }
    // The value is in the message: NaN and infinity say what they are.
    EXPECT_NE(validate_text_contrast(cases[0].contrast).error().message.find("nan"), std::string::npos);
    EXPECT_NE(validate_text_contrast(cases[1].contrast).error().message.find("inf"), std::string::npos);

    // The ends of every range, the default and linear are accepted.
    const TextContrast valid[] = {
        TextContrast{},
        TextContrast{.mode = ContrastMode::linear},
        TextContrast{.gamma = 1.0f},
        TextContrast{.gamma = 4.0f},
        TextContrast{.contrast = 4.0f},
        TextContrast{.stem_darkening = 4.0f},
        TextContrast{ContrastMode::corrected, 1.0f, 0.0f, 0.0f},
    };
    for (const TextContrast& c : valid) EXPECT_TRUE(validate_text_contrast(c)) << c.gamma;
}

// ---- The CPU reference -------------------------------------------------------------------------

TEST(ContrastModel, CorrectedCoverageKeepsItsEndsAndIsMonotonic) {
    const float gammas[] = {1.0f, 1.4f, 1.8f, 2.2f, 3.0f, 4.0f};
    const float contrasts[] = {0.0f, 0.5f, 1.0f, 4.0f};
    const float darkenings[] = {1.0f, 1.7f, kMaxStemDarkeningFactor};
    const double luminances[] = {0.0, 0.002, 0.05, 0.2, 0.5, 0.8, 0.9995, 1.0};
    for (float g : gammas) {
        for (float k : contrasts) {
            for (float d : darkenings) {
                const GlyphContrast c{g, k, d};
                for (double lt : luminances) {
                    for (double lb : luminances) {
                        SCOPED_TRACE(::testing::Message() << "gamma " << g << " contrast " << k << " darkening " << d
                                                          << " Lt " << lt << " Lb " << lb);
                        EXPECT_EQ(corrected_coverage(0.0, c, lt, lb), 0.0);
                        EXPECT_EQ(corrected_coverage(1.0, c, lt, lb), 1.0);
                        double last = 0.0;
                        for (int i = 1; i <= 512; ++i) {
                            const double v = corrected_coverage(i / 512.0, c, lt, lb);
                            ASSERT_GE(v, last - 1e-12) << "coverage " << i / 512.0;
                            ASSERT_LE(v, 1.0);
                            last = v;
                        }
                    }
                }
            }
        }
    }
}

TEST(ContrastModel, LinearIsTheIdentityAndEqualLuminancesTheContrastCurve) {
    const GlyphContrast linear;
    ASSERT_TRUE(linear.linear());
    for (int i = 0; i <= 64; ++i) {
        const double k = i / 64.0;
        for (double lt : {0.0, 0.3, 1.0}) {
            for (double lb : {0.0, 0.7, 1.0}) EXPECT_EQ(corrected_coverage(k, linear, lt, lb), k);
        }
        // Text as light as its background: no gamma to blend in, only contrast and darkening act.
        const GlyphContrast c{2.2f, 1.5f, 1.3f};
        const double expected = std::min(1.0, k * 2.5 / (1.0 + 1.5 * k) * double{1.3f});
        for (double l : {0.0, 0.25, 1.0}) {
            EXPECT_DOUBLE_EQ(corrected_coverage(k, c, l, l), expected);
            EXPECT_DOUBLE_EQ(corrected_coverage(k, c, l, l + 0.5 * double{gpu::kContrastSameLuminance}), expected);
        }
        // Gamma 1 and nothing else: linear light, the coverage as it is.
        EXPECT_NEAR(corrected_coverage(k, GlyphContrast{1.0f, 0.0f, 1.0f}, 0.0, 1.0), k, 1e-15);
    }
}

// The model's purpose: at gamma 2.2, black on white and white on black show as much encoded ink as
// the coverage, so the two polarities look alike. Within 2 % where sRGB is close to a 2.2 power
// (coverage 0.15 to 0.85 of either polarity's ink); near black, where sRGB turns into its linear
// toe, it parts from the power by up to 3.4 % (light text's faint fringes, dark text's cores).
TEST(ContrastModel, BlackOnWhiteAndWhiteOnBlackShowTheirCoverageAsInk) {
    const GlyphContrast c = resolve_contrast(TextContrast{}, 16.0f);
    ASSERT_EQ(c.gamma, 2.2f);
    double worst_linear = 0.0;
    for (int i = 0; i <= 200; ++i) {
        const double k = i / 200.0;
        // Black on white: out = 1 - k'; white on black: out = k'.
        const double dark_ink = 1.0 - srgb_encode(1.0 - corrected_coverage(k, c, 0.0, 1.0));
        const double light_ink = srgb_encode(corrected_coverage(k, c, 1.0, 0.0));
        const double allowed = k >= 0.15 && k <= 0.85 ? 0.02 : 0.035;
        EXPECT_NEAR(dark_ink, k, allowed) << "coverage " << k;
        EXPECT_NEAR(light_ink, k, allowed) << "coverage " << k;
        worst_linear = std::max(worst_linear, std::abs((1.0 - srgb_encode(1.0 - k)) - srgb_encode(k)));
    }
    // Linear blending is far from it (the reason for the model).
    EXPECT_GT(worst_linear, 0.3);
}

TEST(ContrastModel, ResolvedSettingsAndStemDarkening) {
    EXPECT_EQ(
        resolve_contrast(TextContrast{.mode = ContrastMode::linear, .contrast = 2.0f, .stem_darkening = 1.0f}, 12.0f),
        GlyphContrast{});
    EXPECT_TRUE(resolve_contrast(TextContrast{.mode = ContrastMode::linear}, 12.0f).linear());
    const GlyphContrast standard = resolve_contrast(TextContrast{}, 12.0f);
    EXPECT_EQ(standard, (GlyphContrast{2.2f, 0.0f, 1.0f}));
    EXPECT_FALSE(standard.linear());
    // Gamma 1 without contrast or darkening is linear whatever the mode says.
    EXPECT_TRUE(resolve_contrast(TextContrast{.gamma = 1.0f}, 12.0f).linear());

    // Off: 1 at every size; on: above 1 at small sizes, decreasing with size, 1 from the size at
    // which the stem reaches 2.333 px (where FreeType no longer darkens) on.
    const float past = 2.333f / kStemDarkeningStem;
    for (float size : {1.0f, 9.0f, 16.0f, 100.0f}) EXPECT_EQ(stem_darkening_factor(0.0f, size), 1.0f);
    for (float strength : {0.5f, 1.0f, 4.0f}) {
        SCOPED_TRACE(strength);
        float last = stem_darkening_factor(strength, 0.5f);
        EXPECT_GT(last, 1.0f);
        EXPECT_LE(last, kMaxStemDarkeningFactor);
        for (float size = 3.0f; size < past - 0.05f; size += 0.25f) {
            const float f = stem_darkening_factor(strength, size);
            EXPECT_LT(f, last) << size;
            EXPECT_GT(f, 1.0f) << size;
            last = f;
        }
        for (float size : {past + 0.01f, 30.0f, 48.0f, 200.0f}) EXPECT_EQ(stem_darkening_factor(strength, size), 1.0f);
        // Stronger darkens more.
        EXPECT_GT(stem_darkening_factor(strength * 2.0f, 10.0f), stem_darkening_factor(strength, 10.0f));
    }
    // Tiny text is darkened as a quarter-pixel stem: the most there is.
    EXPECT_FLOAT_EQ(stem_darkening_factor(4.0f, 0.1f), kMaxStemDarkeningFactor);
    EXPECT_FLOAT_EQ(stem_darkening_factor(4.0f, 0.25f / kStemDarkeningStem), kMaxStemDarkeningFactor);
    // Sizes that are no size darken nothing.
    EXPECT_EQ(stem_darkening_factor(1.0f, 0.0f), 1.0f);
    EXPECT_EQ(stem_darkening_factor(1.0f, -3.0f), 1.0f);
    EXPECT_EQ(stem_darkening_factor(1.0f, std::numeric_limits<float>::quiet_NaN()), 1.0f);
    // resolve_contrast() carries the factor for the glyph's size.
    const GlyphContrast dark = resolve_contrast(TextContrast{.contrast = 0.5f, .stem_darkening = 1.0f}, 10.0f);
    EXPECT_EQ(dark, (GlyphContrast{2.2f, 0.5f, stem_darkening_factor(1.0f, 10.0f)}));
}

#endif  // !CRISP_GPU_TESTS

#ifdef CRISP_GPU_TESTS

using compositing_test::expect_no_validation_messages;
using compositing_test::fixture;
using test::Texel;
using Rgba = std::array<float, 4>;

constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

std::unique_ptr<Font> bake(const std::string& path, std::string_view text, FontId id, uint32_t face = 0) {
    BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = decode_utf8(text);
    options.face_index = face;
    auto baked = bake_font_file(path, options);
    EXPECT_TRUE(baked) << path;
    if (!baked) return nullptr;
    auto font = Font::create(std::move(baked->asset), id);
    return font ? std::make_unique<Font>(std::move(*font)) : nullptr;
}

// One draw() of laid-out text.
struct Line {
    const Font* font;
    std::string text;
    float x, y, size;
    std::array<float, 4> color;  // sRGB, straight alpha
    std::optional<TextContrast> contrast = std::nullopt;
};

// Lines rendered to convergence on a canvas, with the atlas read back.
struct Frame {
    std::unique_ptr<Renderer> renderer;
    std::vector<DrawnGlyph> drawn;
    std::vector<Texel> texels;
    uint32_t atlas_width = 0;
    uint32_t width = 0, height = 0;
};

Frame render(std::span<const Line> lines, uint32_t width, uint32_t height, const char* layout, uint32_t samples,
             const TextContrast& contrast = {}) {
    HeadlessContext& context = *fixture().context;
    Frame frame;
    frame.width = width;
    frame.height = height;
    RendererCreateInfo info = renderer_create_info(context);
    info.atlas.width = info.atlas.height = 512;
    info.atlas.max_samples = samples;
    info.atlas.frame_budget = uint64_t{1} << 40;
    info.layout = *subpixel_preset(layout);
    info.contrast = contrast;
    auto renderer = Renderer::create(info);
    EXPECT_TRUE(renderer) << (renderer ? "" : renderer.error().message);
    if (!renderer) return frame;
    frame.renderer = std::make_unique<Renderer>(std::move(*renderer));
    Renderer& r = *frame.renderer;
    std::vector<const Font*> added;
    std::vector<std::vector<GlyphInstance>> laid_out;
    uint32_t paint_order = 0;
    for (const Line& line : lines) {
        if (std::find(added.begin(), added.end(), line.font) == added.end()) {
            EXPECT_TRUE(r.add_font(*line.font));
            added.push_back(line.font);
        }
        TextStyle style;
        style.size = line.size;
        std::copy(line.color.begin(), line.color.end(), style.color);
        LayoutOptions options;
        options.origin_x = line.x;
        options.origin_y = line.y;
        options.first_paint_order = paint_order;
        const Font* fonts[] = {line.font};
        auto laid = layout_text(fonts, line.text, style, options);
        EXPECT_TRUE(laid);
        laid_out.push_back(laid ? laid->glyphs : std::vector<GlyphInstance>{});
        if (laid) paint_order = laid->next_paint_order;
    }
    const auto draw = [&] {
        for (size_t i = 0; i < lines.size(); ++i) {
            DrawOptions options;
            options.visible = VkRect2D{{0, 0}, {width, height}};
            options.contrast = lines[i].contrast;
            r.draw(laid_out[i], options);
        }
    };
    const Result<uint32_t> frames = test::render_until_converged(context, r, 400, draw);
    EXPECT_TRUE(frames) << frames.error().message;
    EXPECT_TRUE(r.converged());
    frame.drawn.assign(r.drawn().begin(), r.drawn().end());
    frame.atlas_width = r.atlas().config().width;
    Result<std::vector<Texel>> read = test::read_atlas(context, r);
    EXPECT_TRUE(read) << read.error().message;
    if (read) frame.texels = std::move(*read);
    return frame;
}

// The glyphs with their contrast replaced.
std::vector<DrawnGlyph> with_contrast(std::vector<DrawnGlyph> glyphs, const GlyphContrast& contrast) {
    for (DrawnGlyph& g : glyphs) g.contrast = contrast;
    return glyphs;
}

// The glyphs drawn in one colour (linear RGB, alpha).
std::vector<DrawnGlyph> with_color(std::vector<DrawnGlyph> glyphs, const Rgba& color) {
    for (DrawnGlyph& g : glyphs) std::copy(color.begin(), color.end(), g.instance.color);
    return glyphs;
}

// ---- Backgrounds and targets -------------------------------------------------------------------

std::vector<Rgba> flat(uint32_t width, uint32_t height, float value) {
    return std::vector<Rgba>(size_t{width} * height, Rgba{value, value, value, 1.0f});
}

// Every channel ramps its own way, so luminance runs from dark to light across and down.
std::vector<Rgba> gradient(uint32_t width, uint32_t height) {
    std::vector<Rgba> out(size_t{width} * height);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const float u = static_cast<float>(x) / static_cast<float>(width - 1);
            const float v = static_cast<float>(y) / static_cast<float>(height - 1);
            out[size_t{y} * width + x] = {0.05f + 0.9f * u, 0.9f - 0.6f * v + 0.1f * u, 0.2f + 0.6f * u * v, 1.0f};
        }
    }
    return out;
}

struct Target {
    Image image;
    uint32_t width = 0, height = 0;
    bool draw = false;  // a colour attachment for the draw path; else a storage image for the tile path
};

Target make_target(uint32_t width, uint32_t height, bool draw = false) {
    Target t;
    t.width = width;
    t.height = height;
    t.draw = draw;
    const VkImageUsageFlags usage =
        VkImageUsageFlags{draw ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT : VK_IMAGE_USAGE_STORAGE_BIT} |
        VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    auto image = fixture().context->create_image({kFormat, width, height, usage});
    EXPECT_TRUE(image) << (image ? "" : image.error().message);
    if (image) t.image = std::move(*image);
    return t;
}

Compositor make_compositor() {
    CompositorCreateInfo info = compositor_create_info(*fixture().context);
    info.draw_format = kFormat;
    auto compositor = Compositor::create(info);
    EXPECT_TRUE(compositor) << (compositor ? "" : compositor.error().message);
    return std::move(*compositor);
}

// `glyphs` composited over `background` into the target (the tile path, or the draw path), read back.
std::vector<Rgba> composite(Compositor& compositor, const Frame& frame, std::span<const DrawnGlyph> glyphs, Target& t,
                            const std::vector<Rgba>& background) {
    HeadlessContext& context = *fixture().context;
    std::vector<std::byte> bytes(background.size() * sizeof(Rgba));
    std::memcpy(bytes.data(), background.data(), bytes.size());
    EXPECT_TRUE(context.upload(t.image, bytes, VK_IMAGE_LAYOUT_GENERAL));
    const crisp::DrawnFrame drawn = frame.renderer->drawn_frame().with_glyphs(glyphs);
    EXPECT_TRUE(context.submit_and_wait([&](VkCommandBuffer cb) {
        Status s;
        if (t.draw) {
            tools::begin_rendering_over(cb, t.image.view(), {{0, 0}, {t.width, t.height}});
            s = compositor.record_draw(cb, drawn, {{0, 0}, {t.width, t.height}});
            vkCmdEndRendering(cb);
        } else {
            s = compositor.record(
                cb, drawn, CompositeTarget{t.image.view(), kFormat, VK_FORMAT_UNDEFINED, {t.width, t.height}, {}});
        }
        EXPECT_TRUE(s) << (s ? "" : s.error().message);
    }));
    auto read = context.read_image(t.image, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_TRUE(read);
    std::vector<Rgba> image(background.size());
    if (read && read->size() == bytes.size()) std::memcpy(image.data(), read->data(), bytes.size());
    return image;
}

// Calls visit(x, y, pixel index) for each pixel of the width x height canvas inside a glyph's rect.
template <class Visit>
void for_each_rect_pixel(std::span<const DrawnGlyph> glyphs, uint32_t width, uint32_t height, Visit&& visit) {
    for (const DrawnGlyph& g : glyphs) {
        for (uint32_t ty = 0; ty < g.instance.height; ++ty) {
            for (uint32_t tx = 0; tx < g.instance.width; ++tx) {
                const int64_t x = int64_t{g.instance.x} + tx, y = int64_t{g.instance.y} + ty;
                if (x < 0 || y < 0 || x >= width || y >= height) continue;
                visit(x, y, static_cast<size_t>(y) * width + static_cast<size_t>(x));
            }
        }
    }
}

// ---- The CPU computation -----------------------------------------------------------------------

struct Fragment {
    float depth;
    uint32_t paint_order;
    double opacity[3];
    double color[3];
};

// The compositing the tile and draw paths do, in double precision: each channel's coverage
// corrected by corrected_coverage() against the background pixel's luminance (the tile path) or
// the far end of the range (`assumed`: the draw path), then each pixel's fragments front to back
// (depth ascending, later paint order in front) over the background; alpha is "over" with each
// fragment's largest opacity. `covered`, where given, says which pixels have a fragment.
std::vector<Rgba> expected_image(const Frame& frame, std::span<const DrawnGlyph> glyphs,
                                 const std::vector<Rgba>& background, bool assumed,
                                 std::vector<bool>* covered = nullptr) {
    const uint32_t width = frame.width, height = frame.height;
    std::vector<std::vector<Fragment>> pixels(size_t{width} * height);
    for (const DrawnGlyph& d : glyphs) {
        const GlyphInstance& g = d.instance;
        const double lt = luminance(g.color[0], g.color[1], g.color[2]);
        for (uint32_t ty = 0; ty < g.height; ++ty) {
            for (uint32_t tx = 0; tx < g.width; ++tx) {
                const int64_t x = int64_t{g.x} + tx, y = int64_t{g.y} + ty;
                if (x < 0 || y < 0 || x >= width || y >= height) continue;
                const size_t at = static_cast<size_t>(y) * width + static_cast<size_t>(x);
                const Texel& t = frame.texels[size_t{d.atlas_y + ty} * frame.atlas_width + d.atlas_x + tx];
                if (t.count == 0) continue;
                const Rgba& back = background[at];
                const double lb = assumed ? assumed_background_luminance(lt) : luminance(back[0], back[1], back[2]);
                Fragment f{g.depth, g.paint_order, {}, {}};
                const uint16_t sums[3] = {t.r, t.g, t.b};
                bool visible = false;
                for (size_t c = 0; c < 3; ++c) {
                    const float coverage = std::min(
                        static_cast<float>(sums[c]) / (float{gpu::kRasterCoverageOne} * static_cast<float>(t.count)),
                        1.0f);
                    f.opacity[c] = double{g.color[3]} * corrected_coverage(coverage, d.contrast, lt, lb);
                    f.color[c] = g.color[c];
                    visible = visible || f.opacity[c] > 0.0;
                }
                if (visible) pixels[at].push_back(f);
            }
        }
    }
    std::vector<Rgba> out = background;
    if (covered) covered->assign(out.size(), false);
    for (size_t at = 0; at < out.size(); ++at) {
        std::vector<Fragment>& list = pixels[at];
        if (covered) (*covered)[at] = !list.empty();
        std::stable_sort(list.begin(), list.end(), [](const Fragment& a, const Fragment& b) {
            return a.depth != b.depth ? a.depth < b.depth : a.paint_order > b.paint_order;
        });
        double light[3] = {}, transmittance[3] = {1, 1, 1}, coverage_transmittance = 1.0;
        for (const Fragment& f : list) {
            for (size_t c = 0; c < 3; ++c) {
                light[c] += transmittance[c] * f.opacity[c] * f.color[c];
                transmittance[c] *= 1.0 - f.opacity[c];
            }
            coverage_transmittance *= 1.0 - std::max({f.opacity[0], f.opacity[1], f.opacity[2]});
        }
        const Rgba back = background[at];
        for (size_t c = 0; c < 3; ++c) out[at][c] = static_cast<float>(light[c] + transmittance[c] * double{back[c]});
        out[at][3] = static_cast<float>(1.0 - (1.0 - double{back[3]}) * coverage_transmittance);
    }
    return out;
}

double worst_difference(const std::vector<Rgba>& a, const std::vector<Rgba>& b) {
    double worst = a.size() == b.size() ? 0.0 : 1.0;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
        for (size_t c = 0; c < 4; ++c) worst = std::max(worst, std::abs(double{a[i][c]} - double{b[i][c]}));
    }
    return worst;
}

// Pixels of the image that differ from the background.
size_t changed_pixels(const std::vector<Rgba>& image, const std::vector<Rgba>& background) {
    size_t changed = 0;
    for (size_t i = 0; i < image.size(); ++i) changed += image[i] != background[i];
    return changed;
}

// Text of several colours, one of them translucent, for the fixture's font (DejaVu Sans,
// "Hamburgefonstiv@&1"), spread over a 72 x 40 canvas.
std::vector<Line> mixed_lines(const Font& font, float x = 0.0f) {
    return {
        {&font, "Hamburg", x + 1.25f, 12.0f, 13.0f, {0.05f, 0.05f, 0.1f, 1.0f}},
        {&font, "efonts", x + 3.6f, 24.3f, 13.0f, {0.95f, 0.9f, 0.8f, 1.0f}},
        {&font, "stiv@&1", x + 0.7f, 36.1f, 13.0f, {0.9f, 0.2f, 0.1f, 0.8f}},
    };
}

constexpr uint32_t kWidth = 72, kHeight = 40, kSamples = 16;

// ---- Tests -------------------------------------------------------------------------------------

// Linear glyphs in a frame that also corrects others (so that the contrast pipelines run) give the
// pixels of a frame where every glyph is linear, bit for bit; that frame is what the compositing
// tests' CPU reference expects (blending coverage as it is).
TEST(ContrastCompositing, LinearGlyphsAreBitIdenticalBesideCorrectedOnes) {
    ASSERT_TRUE(fixture().context);
    const Font& font = *fixture().font;
    std::vector<Line> lines = mixed_lines(font);
    for (const Line& line : mixed_lines(font, static_cast<float>(kWidth))) lines.push_back(line);
    const Frame frame = render(lines, 2 * kWidth, kHeight, "rgb", kSamples, TextContrast{.mode = ContrastMode::linear});
    ASSERT_FALSE(frame.drawn.empty());
    const GlyphContrast corrected = resolve_contrast(TextContrast{}, 13.0f);
    std::vector<DrawnGlyph> mixed = frame.drawn;
    size_t corrected_glyphs = 0;
    for (DrawnGlyph& g : mixed) {
        EXPECT_TRUE(g.contrast.linear());
        if (g.instance.x >= static_cast<int32_t>(kWidth)) {
            g.contrast = corrected;
            ++corrected_glyphs;
        }
    }
    ASSERT_GT(corrected_glyphs, 0u);
    ASSERT_LT(corrected_glyphs, mixed.size());
    Compositor compositor = make_compositor();
    Target t = make_target(2 * kWidth, kHeight);
    const std::vector<Rgba> background = gradient(2 * kWidth, kHeight);
    const std::vector<Rgba> linear = composite(compositor, frame, frame.drawn, t, background);
    const std::vector<Rgba> both = composite(compositor, frame, mixed, t, background);
    size_t right_differs = 0;
    for (uint32_t y = 0; y < kHeight; ++y) {
        const size_t row = size_t{y} * 2 * kWidth;
        EXPECT_EQ(std::memcmp(&linear[row], &both[row], kWidth * sizeof(Rgba)), 0) << "row " << y;
        for (uint32_t x = kWidth; x < 2 * kWidth; ++x) right_differs += linear[row + x] != both[row + x];
    }
    EXPECT_GT(right_differs, 20u);  // the corrected half was corrected
    EXPECT_GT(changed_pixels(linear, background), 200u);
    EXPECT_LE(worst_difference(linear, expected_image(frame, frame.drawn, background, false)), 4e-5);
    // The draw path too: linear glyphs beside corrected ones draw as in an all-linear frame.
    Target d = make_target(2 * kWidth, kHeight, true);
    const std::vector<Rgba> drawn_linear = composite(compositor, frame, frame.drawn, d, background);
    const std::vector<Rgba> drawn_both = composite(compositor, frame, mixed, d, background);
    for (uint32_t y = 0; y < kHeight; ++y) {
        const size_t row = size_t{y} * 2 * kWidth;
        EXPECT_EQ(std::memcmp(&drawn_linear[row], &drawn_both[row], kWidth * sizeof(Rgba)), 0) << "row " << y;
    }
    EXPECT_NE(drawn_linear, drawn_both);
    expect_no_validation_messages();
}

// The tile path corrects each channel against the luminance of the caller's pixel, over a
// background that is nowhere flat.
TEST(ContrastCompositing, TilePathMatchesTheCpuModelPerChannel) {
    ASSERT_TRUE(fixture().context);
    Compositor compositor = make_compositor();
    for (const char* layout : {"rgb", "gray"}) {
        SCOPED_TRACE(layout);
        const Frame frame = render(mixed_lines(*fixture().font), kWidth, kHeight, layout, kSamples);
        ASSERT_FALSE(frame.drawn.empty());
        for (const DrawnGlyph& g : frame.drawn) EXPECT_EQ(g.contrast, resolve_contrast(TextContrast{}, 13.0f));
        Target t = make_target(kWidth, kHeight);
        const std::vector<Rgba> background = gradient(kWidth, kHeight);
        const std::vector<Rgba> image = composite(compositor, frame, frame.drawn, t, background);
        EXPECT_GT(changed_pixels(image, background), 200u);
        std::vector<bool> covered;
        const std::vector<Rgba> expected = expected_image(frame, frame.drawn, background, false, &covered);
        EXPECT_LE(worst_difference(image, expected), 1e-4);
        // Where nothing is covered (texels of the glyphs' rects among them) the background stays,
        // bit for bit: no coverage stays no opacity through the gamma space.
        size_t uncovered_in_rects = 0;
        for_each_rect_pixel(frame.drawn, kWidth, kHeight, [&](int64_t x, int64_t y, size_t at) {
            if (covered[at]) return;
            ++uncovered_in_rects;
            EXPECT_EQ(image[at], background[at]) << "pixel " << x << ", " << y;
        });
        EXPECT_GT(uncovered_in_rects, 20u);
        // The correction did change the image: the linear expectation is far from it.
        const std::vector<DrawnGlyph> linear = with_contrast(frame.drawn, GlyphContrast{});
        EXPECT_GT(worst_difference(image, expected_image(frame, linear, background, false)), 0.05);
        // Contrast and stem darkening too.
        const std::vector<DrawnGlyph> heavy = with_contrast(
            frame.drawn,
            resolve_contrast(TextContrast{.gamma = 1.8f, .contrast = 1.0f, .stem_darkening = 1.0f}, 13.0f));
        EXPECT_LE(worst_difference(composite(compositor, frame, heavy, t, background),
                                   expected_image(frame, heavy, background, false)),
                  1e-4);
    }
    expect_no_validation_messages();
}

// The draw path cannot read the target: it corrects against the far end of the range from the
// text, whatever the background holds.
TEST(ContrastCompositing, DrawPathMatchesTheCpuModelWithTheAssumedBackground) {
    ASSERT_TRUE(fixture().context);
    Compositor compositor = make_compositor();
    const Frame frame = render(mixed_lines(*fixture().font), kWidth, kHeight, "rgb", kSamples);
    ASSERT_FALSE(frame.drawn.empty());
    Target t = make_target(kWidth, kHeight, true);
    const std::vector<Rgba> background = gradient(kWidth, kHeight);
    const std::vector<Rgba> image = composite(compositor, frame, frame.drawn, t, background);
    EXPECT_GT(changed_pixels(image, background), 200u);
    EXPECT_LE(worst_difference(image, expected_image(frame, frame.drawn, background, true)), 1e-4);
    EXPECT_GT(worst_difference(image, expected_image(frame, frame.drawn, background, false)), 0.01);
    expect_no_validation_messages();
}

// Encoded ink over rows [y0, y1): mean |enc(out) - enc(bg)| / |enc(text) - enc(bg)| over pixels and
// channels, for text and background of one grey each.
double encoded_ink(const std::vector<Rgba>& image, uint32_t width, uint32_t y0, uint32_t y1, double text,
                   double background) {
    const double scale = std::abs(srgb_encode(text) - srgb_encode(background));
    double sum = 0.0;
    for (size_t i = size_t{y0} * width; i < size_t{y1} * width; ++i) {
        for (size_t c = 0; c < 3; ++c) sum += std::abs(srgb_encode(image[i][c]) - srgb_encode(background)) / scale;
    }
    return sum / (3.0 * static_cast<double>(y1 - y0) * width);
}

// The default was chosen for this (issue 23): dark on light shows as much ink as light on dark, at
// 9 to 16 px on DejaVu Sans, Inter and Noto Sans CJK; blending linearly does not.
TEST(ContrastCompositing, DefaultKeepsTheInkRatioOfBothPolaritiesNearOne) {
    ASSERT_TRUE(fixture().context);
    const std::string latin = "Hamburgefonts", cjk = "永字文組版書";
    const auto dejavu = bake(test::kDejaVuSans, latin, 1);
    const auto inter = bake(test::kInterCff, latin, 2);
    const auto noto = bake(test::kNotoCjk, cjk, 3, 0);  // face 0: Japanese
    ASSERT_TRUE(dejavu && inter && noto);
    struct Face {
        const Font* font;
        const char* name;
        const std::string* text;
    };
    const Face faces[] = {
        {dejavu.get(), "DejaVu Sans", &latin}, {inter.get(), "Inter", &latin}, {noto.get(), "Noto Sans CJK", &cjk}};
    const float sizes[] = {9.0f, 12.0f, 16.0f};
    constexpr uint32_t kPitch = 24, kCanvasWidth = 150;
    std::vector<Line> lines;
    for (const Face& face : faces) {
        for (float size : sizes) {
            const float baseline = static_cast<float>(lines.size() * kPitch) + 18.0f;
            lines.push_back({face.font, *face.text, 3.0f, baseline, size, {0.0f, 0.0f, 0.0f, 1.0f}});
        }
    }
    const uint32_t height = static_cast<uint32_t>(lines.size()) * kPitch;
    const Frame frame = render(lines, kCanvasWidth, height, "gray", 64);
    ASSERT_FALSE(frame.drawn.empty());
    Compositor compositor = make_compositor();
    Target t = make_target(kCanvasWidth, height);
    const std::vector<Rgba> white = flat(kCanvasWidth, height, 1.0f), black = flat(kCanvasWidth, height, 0.0f);
    const auto ratios = [&](const std::vector<DrawnGlyph>& glyphs) {
        const std::vector<Rgba> dark = composite(compositor, frame, with_color(glyphs, {0, 0, 0, 1}), t, white);
        const std::vector<Rgba> light = composite(compositor, frame, with_color(glyphs, {1, 1, 1, 1}), t, black);
        std::vector<double> out;
        for (uint32_t i = 0; i < lines.size(); ++i) {
            const double dark_ink = encoded_ink(dark, kCanvasWidth, i * kPitch, (i + 1) * kPitch, 0.0, 1.0);
            const double light_ink = encoded_ink(light, kCanvasWidth, i * kPitch, (i + 1) * kPitch, 1.0, 0.0);
            EXPECT_GT(light_ink, 0.02) << "line " << i;  // text is there
            out.push_back(dark_ink / light_ink);
        }
        return out;
    };
    const std::vector<double> corrected = ratios(frame.drawn);
    const std::vector<double> linear = ratios(with_contrast(frame.drawn, GlyphContrast{}));
    for (size_t i = 0; i < lines.size(); ++i) {
        SCOPED_TRACE(::testing::Message() << faces[i / 3].name << " " << sizes[i % 3] << " px");
        EXPECT_GE(corrected[i], 0.9);
        EXPECT_LE(corrected[i], 1.1);
        EXPECT_LT(linear[i], 0.7);
    }
    expect_no_validation_messages();
}

// Across a vertical stem ('H' at 16 px, gray, at four subpixel positions) the encoded output moves
// monotonically from the background to the text colour and back, dark on light and light on dark.
TEST(ContrastCompositing, StemEdgesStayMonotonic) {
    ASSERT_TRUE(fixture().context);
    const Font& font = *fixture().font;
    std::vector<Line> lines;
    for (int i = 0; i < 4; ++i) {
        lines.push_back({&font, "H", 2.0f + 15.25f * static_cast<float>(i), 18.0f, 16.0f, {0, 0, 0, 1}});
    }
    const Frame frame = render(lines, kWidth, 24, "gray", 32);
    ASSERT_EQ(frame.drawn.size(), 4u);
    Compositor compositor = make_compositor();
    Target t = make_target(kWidth, 24);
    const GlyphContrast settings[] = {resolve_contrast(TextContrast{}, 16.0f),
                                      resolve_contrast(TextContrast{.contrast = 1.0f, .stem_darkening = 1.0f}, 16.0f)};
    for (const GlyphContrast& setting : settings) {
        for (bool dark : {true, false}) {
            SCOPED_TRACE(::testing::Message() << (dark ? "dark on light" : "light on dark") << ", contrast "
                                              << setting.contrast << ", darkening " << setting.darkening);
            const float text = dark ? 0.0f : 1.0f, back = dark ? 1.0f : 0.0f;
            const std::vector<Rgba> bg = flat(kWidth, 24, back);
            const std::vector<DrawnGlyph> glyphs =
                with_color(with_contrast(frame.drawn, setting), {text, text, text, 1});
            const std::vector<Rgba> image = composite(compositor, frame, glyphs, t, bg);
            const auto ink = [&](int64_t x, uint32_t y) {
                return std::abs(srgb_encode(image[size_t{y} * kWidth + static_cast<size_t>(x)][1]) - srgb_encode(back));
            };
            for (const DrawnGlyph& g : frame.drawn) {
                const int64_t x0 = std::max<int64_t>(0, g.instance.x),
                              x1 = std::min<int64_t>(kWidth, int64_t{g.instance.x} + g.instance.width);
                // Rows of the stems above the bar: the cap height is 6.3 px, the bar 5.1 px above the baseline.
                for (uint32_t y = 7; y <= 10; ++y) {
                    // The left stem: from the rect's left up to the row's first peak; the right
                    // stem from the rect's right.
                    const int64_t middle = (x0 + x1) / 2;
                    int64_t peak = x0;
                    for (int64_t x = x0; x < middle; ++x) peak = ink(x, y) > ink(peak, y) ? x : peak;
                    EXPECT_GT(ink(peak, y), 0.7) << "row " << y;
                    for (int64_t x = x0; x < peak; ++x) EXPECT_LE(ink(x, y), ink(x + 1, y) + 1e-6) << x << ", " << y;
                    int64_t right_peak = x1 - 1;
                    for (int64_t x = x1 - 1; x >= middle; --x)
                        right_peak = ink(x, y) > ink(right_peak, y) ? x : right_peak;
                    EXPECT_GT(ink(right_peak, y), 0.7) << "row " << y;
                    for (int64_t x = x1 - 1; x > right_peak; --x) {
                        EXPECT_LE(ink(x, y), ink(x - 1, y) + 1e-6) << x << ", " << y;
                    }
                }
            }
        }
    }
    expect_no_validation_messages();
}

// One luminance serves the three channels of a pixel, so the model is one monotonic function of
// coverage there and a subpixel edge keeps its channel order: over a background that differs per
// channel and per pixel, wherever one channel's ink is clearly above another's when blended
// linearly, it is not below it corrected. Ink per channel is |out - bg| / |text - bg| (the
// opacity the channel shows), so that channels of unequal text-to-background contrast compare.
TEST(ContrastCompositing, SubpixelEdgesKeepTheirChannelOrder) {
    ASSERT_TRUE(fixture().context);
    const Font& font = *fixture().font;
    Compositor compositor = make_compositor();
    for (const char* layout : {"rgb", "bgr", "vrgb"}) {
        SCOPED_TRACE(layout);
        std::vector<Line> lines;
        for (int i = 0; i < 4; ++i) {
            const float x = 2.0f + 17.3f * static_cast<float>(i);
            lines.push_back({&font, "H", x, 17.0f, 14.0f, {0.05f, 0.05f, 0.08f, 1.0f}});
            lines.push_back({&font, "H", x + 0.5f, 35.0f, 14.0f, {0.97f, 0.95f, 0.9f, 1.0f}});
        }
        const Frame frame = render(lines, kWidth, kHeight, layout, kSamples);
        ASSERT_EQ(frame.drawn.size(), lines.size());
        Target t = make_target(kWidth, kHeight);
        const std::vector<Rgba> background = gradient(kWidth, kHeight);
        const std::vector<Rgba> corrected = composite(compositor, frame, frame.drawn, t, background);
        const std::vector<Rgba> linear =
            composite(compositor, frame, with_contrast(frame.drawn, GlyphContrast{}), t, background);
        size_t compared = 0;
        for (const DrawnGlyph& g : frame.drawn) {
            for_each_rect_pixel({&g, 1}, kWidth, kHeight, [&](int64_t x, int64_t y, size_t at) {
                double ink_linear[3], ink_corrected[3];
                for (size_t c = 0; c < 3; ++c) {
                    const double span = double{g.instance.color[c]} - double{background[at][c]};
                    if (std::abs(span) < 0.2) return;
                    ink_linear[c] = (double{linear[at][c]} - double{background[at][c]}) / span;
                    ink_corrected[c] = (double{corrected[at][c]} - double{background[at][c]}) / span;
                }
                for (size_t a = 0; a < 3; ++a) {
                    for (size_t b = 0; b < 3; ++b) {
                        if (ink_linear[a] < ink_linear[b] + 0.02) continue;
                        ++compared;
                        EXPECT_GE(ink_corrected[a], ink_corrected[b] - 1e-4)
                            << "pixel " << x << ", " << y << " channels " << a << " > " << b;
                    }
                }
            });
        }
        EXPECT_GT(compared, 50u);  // the layouts' channels do differ at the edges
    }
    expect_no_validation_messages();
}

// DrawOptions::contrast per draw: linear glyphs in a corrected renderer composite as in an
// all-linear frame; an invalid setting draws nothing. set_contrast() and create() refuse invalid
// settings, naming the field.
TEST(ContrastCompositing, PerDrawOverridesAndRefusedSettings) {
    ASSERT_TRUE(fixture().context);
    const Font& font = *fixture().font;
    TextContrast nan_gamma;
    nan_gamma.gamma = std::numeric_limits<float>::quiet_NaN();
    const std::vector<Line> lines = {
        {&font, "Hamburg", 1.25f, 14.0f, 13.0f, {0.05f, 0.05f, 0.1f, 1.0f}, TextContrast{.mode = ContrastMode::linear}},
        {&font, "efonts", 3.6f, 34.0f, 13.0f, {0.05f, 0.05f, 0.1f, 1.0f}},
        {&font, "stiv", 5.0f, 24.0f, 13.0f, {0.05f, 0.05f, 0.1f, 1.0f}, nan_gamma},
    };
    Frame frame = render(lines, kWidth, kHeight, "rgb", kSamples);
    ASSERT_TRUE(frame.renderer);
    Renderer& r = *frame.renderer;
    EXPECT_EQ(r.stats().skipped_glyphs, 4u);  // "stiv"
    size_t overridden = 0, defaults = 0;
    for (const DrawnGlyph& g : frame.drawn) {
        if (g.instance.y + static_cast<int32_t>(g.instance.height) <= 20) {
            EXPECT_TRUE(g.contrast.linear());
            ++overridden;
        } else {
            EXPECT_GE(g.instance.y, 20);
            EXPECT_EQ(g.contrast, resolve_contrast(TextContrast{}, 13.0f));
            ++defaults;
        }
    }
    EXPECT_EQ(overridden, 7u);
    EXPECT_EQ(defaults, 6u);
    Compositor compositor = make_compositor();
    Target t = make_target(kWidth, kHeight);
    const std::vector<Rgba> background = gradient(kWidth, kHeight);
    const std::vector<Rgba> mixed = composite(compositor, frame, frame.drawn, t, background);
    const std::vector<Rgba> linear =
        composite(compositor, frame, with_contrast(frame.drawn, GlyphContrast{}), t, background);
    EXPECT_EQ(std::memcmp(linear.data(), mixed.data(), 20 * kWidth * sizeof(Rgba)), 0);  // the top rows: "Hamburg"
    EXPECT_NE(linear, mixed);

    // set_contrast() refuses what validate_text_contrast() refuses, naming the field, and keeps the
    // old setting; a valid one holds from the next draw() on.
    const TextContrast before = r.contrast();
    TextContrast bad;
    bad.gamma = -2.2f;
    const Status refused = r.set_contrast(bad);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(refused.error().message.find("gamma"), std::string::npos) << refused.error().message;
    EXPECT_EQ(r.contrast(), before);
    bad = TextContrast{.stem_darkening = std::numeric_limits<float>::infinity()};
    EXPECT_NE(r.set_contrast(bad).error().message.find("stem_darkening"), std::string::npos);
    EXPECT_EQ(r.contrast(), before);
    const TextContrast heavier{.contrast = 0.5f};
    ASSERT_TRUE(r.set_contrast(heavier));
    EXPECT_EQ(r.contrast(), heavier);
    TextStyle style;
    style.size = 13.0f;
    const Font* fonts[] = {&font};
    auto laid = layout_text(fonts, "Ham", style, LayoutOptions{.origin_x = 2.0f, .origin_y = 20.0f});
    ASSERT_TRUE(laid);
    r.begin_frame();
    r.draw(laid->glyphs);
    EXPECT_TRUE(fixture().context->submit_and_wait([&](VkCommandBuffer cb) { EXPECT_TRUE(r.record(cb)); }));
    ASSERT_FALSE(r.drawn().empty());
    for (const DrawnGlyph& g : r.drawn()) EXPECT_EQ(g.contrast, resolve_contrast(heavier, 13.0f));

    // create() refuses a bad RendererCreateInfo::contrast.
    RendererCreateInfo info = renderer_create_info(*fixture().context);
    info.contrast.contrast = 4.5f;
    auto made = Renderer::create(info);
    ASSERT_FALSE(made);
    EXPECT_EQ(made.error().code, ErrorCode::invalid_argument);
    EXPECT_NE(made.error().message.find("contrast: contrast"), std::string::npos) << made.error().message;
    info.contrast = TextContrast{.mode = static_cast<ContrastMode>(7)};
    made = Renderer::create(info);
    ASSERT_FALSE(made);
    EXPECT_NE(made.error().message.find("mode"), std::string::npos) << made.error().message;
    expect_no_validation_messages();
}

#endif  // CRISP_GPU_TESTS

}  // namespace
}  // namespace crisp
