// crisp-bench --suite transform: transformed text (docs/transforms.md), its price and its error
// together. Animated: a screen of text at a new rotation every frame (every frame a first frame),
// drawn plain and as a named (moving) draw, each frame timed on the GPU and the CPU and its atlas
// texels measured on a subset of its glyphs against the exact area of their transformed outlines
// (support/transform_reference.hpp). Still: one rotation held until the screen converges, and a
// small grid of rotations, scales and shears at 8, 64 and 512 samples. Perspective: a block of text
// on a plane tilted away from a perspective camera, each glyph's local-affine error and how many
// keep their perspective, and the atlas against the exact projective area.
#include "bench.hpp"
#include "frame_loop.hpp"
#include "gpu_tools.hpp"
#include "harness.hpp"
#include "transform_reference.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>
#include <crisp/transform.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "transform";
// Degrees the animated screen turns each frame: no two frames of a run share a key.
constexpr double kDegreesPerFrame = 7.3;
constexpr double kStillDegrees = 37.0;
constexpr uint32_t kMaxStillFrames = 4000;
constexpr uint32_t kMaxStillCanvas[2] = {1280, 720};
// The perspective camera's vertical field of view.
constexpr double kFieldOfViewDegrees = 60.0;

using Clock = std::chrono::steady_clock;

struct Args {
    std::string font = "fonts/DejaVuSans.ttf";
    std::string layout_name = "rgb";
    SubpixelLayout layout;
    float size = 16.0f;
    uint32_t width = 1920, height = 1080;
    uint32_t samples = 512;
    uint32_t frames = 60;  // animated frames per variant
    uint32_t subset = 64;  // glyphs measured per frame
    uint32_t atlas_budget_mib = 512;
    uint64_t frame_budget = uint64_t{1} << 50;
    bool quick = false;
};

// Texel channels against the exact transformed area: mean absolute error over the channels either
// side covers, and the worst single channel.
struct TexelError {
    double sum = 0.0;
    double worst = 0.0;
    uint64_t channels = 0;
    uint32_t glyphs = 0;
    uint32_t wrong_counts = 0;  // texels that did not hold the samples their glyph was drawn with

    double mean() const { return channels ? sum / static_cast<double>(channels) : 0.0; }
    void add(const TexelError& other) {
        sum += other.sum;
        worst = std::max(worst, other.worst);
        channels += other.channels;
        glyphs += other.glyphs;
        wrong_counts += other.wrong_counts;
    }
};

// A measured subset: all of it, and the part whose keys keep a perspective.
struct SubsetError {
    TexelError all, projective;
    TexelError intended;  // against the still steps' key (subset_error()'s `intended`)
};

double percentile(std::vector<double> values, double p) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const auto rank = static_cast<size_t>(std::ceil(p * static_cast<double>(values.size())));
    return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

// Rotation by `degrees` (clockwise on screen), times scale, times a shear of x by y.
TextTransform linear_transform(double degrees, double scale, double shear, float pivot_x, float pivot_y) {
    const double c = std::cos(radians(degrees)), s = std::sin(radians(degrees));
    // {c, -s; s, c} {scale, scale shear; 0, scale}
    return {static_cast<float>(c * scale),
            static_cast<float>((c * shear - s) * scale),
            static_cast<float>(s * scale),
            static_cast<float>((s * shear + c) * scale),
            pivot_x,
            pivot_y};
}

Renderer make_transform_renderer(const HeadlessContext& context, const Args& args, uint32_t atlas_side,
                                 std::vector<uint32_t> ramp, uint64_t atlas_budget) {
    RendererCreateInfo info = renderer_create_info(context);
    info.layout = args.layout;
    info.atlas.width = info.atlas.height = atlas_side;
    info.atlas.max_samples = args.samples;
    info.atlas.frame_budget = args.frame_budget;
    if (!ramp.empty()) info.atlas.ramp = std::move(ramp);
    for (uint32_t& n : info.atlas.ramp) n = std::min(n, args.samples);  // the default ramp under --samples 2, say
    info.atlas_memory_budget = atlas_budget;
    auto renderer = Renderer::create(info);
    if (!renderer) fail(kSuite, renderer.error().message);
    return std::move(*renderer);
}

// The sample counts measured after each frame of a ramp that ends on them: 8, 64 and 512 where
// max_samples allows, and max_samples.
std::vector<uint32_t> checkpoints(uint32_t max_samples) {
    std::vector<uint32_t> points;
    for (const uint32_t n : {8u, 64u, 512u}) {
        if (n < max_samples) points.push_back(n);
    }
    points.push_back(max_samples);
    return points;
}

std::vector<uint32_t> ramp_through(const std::vector<uint32_t>& points) {
    std::vector<uint32_t> ramp;
    uint32_t held = 0;
    for (const uint32_t n : points) {
        ramp.push_back(n - held);
        held = n;
    }
    return ramp;
}

// A draw's glyphs as laid out and its options (TransformSuite::subset_error()).
struct Intended {
    std::span<const GlyphInstance> laid_out;
    const DrawOptions* options = nullptr;
};

class TransformSuite {
public:
    TransformSuite(Session& session, const Args& args, const Font& font)
        : session_(session), context_(*session.context), args_(args), font_(font) {
        auto timer = tools::GpuTimer::create(context_);
        if (!timer) fail(kSuite, timer.error().message);
        timer_.emplace(std::move(*timer));
    }

    // One frame: begin_frame, draw and record timed on the CPU (recording only), the record on the GPU.
    struct Timed {
        double gpu_ms = 0.0;
        double cpu_ms = 0.0;
    };
    Timed frame(Renderer& renderer, std::span<const GlyphInstance> glyphs, const DrawOptions& options) {
        Timed timed;
        Status recorded;
        const Status submitted = context_.submit_and_wait([&](VkCommandBuffer cb) {
            const Clock::time_point start = Clock::now();
            renderer.begin_frame();
            renderer.draw(glyphs, options);
            timer_->begin(cb);
            recorded = renderer.record(cb);
            timer_->end(cb);
            timed.cpu_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        });
        if (!recorded) fail(kSuite, recorded.error().message);
        if (!submitted) fail(kSuite, submitted.error().message);
        const Result<double> ms = timer_->milliseconds();
        if (!ms) fail(kSuite, ms.error().message);
        timed.gpu_ms = *ms;
        return timed;
    }

    // The samples this frame's glyphs hold once its work has run: the first whole glyph's (with an
    // unbounded frame budget every glyph drawn gets the same).
    static uint32_t frame_samples(const Renderer& renderer) {
        for (const DrawnGlyph& d : renderer.drawn()) {
            if (d.instance.width != 0) return d.samples;
        }
        return 0;
    }

    // Up to `count` distinct atlas entries drawn this frame, picked evenly through drawn(), whole
    // glyphs only (a clipped glyph's entry holds its visible part), each texel channel of them
    // against the exact area of its key's transformed outline. With `intended` (the draw's glyphs as
    // laid out and its draw options), each also against the exact area at the still steps' key of the
    // same instance: what coarse (moving) keys add to the rasterizer's error.
    SubsetError subset_error(const Renderer& renderer, uint32_t count, const Intended& intended = {}) {
        const FontAsset& asset = font_.asset();
        std::vector<const DrawnGlyph*> whole;
        std::set<std::pair<uint32_t, uint32_t>> seen;
        for (const DrawnGlyph& d : renderer.drawn()) {
            if (d.instance.key.glyph >= asset.glyphs.size() || d.instance.width == 0) continue;
            const GlyphRect rect = glyph_rect(asset.glyphs[d.instance.key.glyph], d.instance.key);
            if (d.part_x != 0 || d.part_y != 0 || rect.width != d.instance.width || rect.height != d.instance.height) {
                continue;
            }
            if (seen.emplace(d.atlas_x, d.atlas_y).second) whole.push_back(&d);
        }
        SubsetError out;
        if (whole.empty()) return out;
        Result<std::vector<harness::Texel>> atlas = harness::read_atlas(context_, renderer);
        if (!atlas) fail(kSuite, atlas.error().message);
        const size_t picks = std::min<size_t>(count, whole.size());
        for (size_t i = 0; i < picks; ++i) {
            const DrawnGlyph& d = *whole[i * whole.size() / picks];
            const TexelError e = glyph_error(renderer, *atlas, d, d.instance);
            out.all.add(e);
            const GlyphKey& key = d.instance.key;
            if (key.perspective[0] != 0 || key.perspective[1] != 0) out.projective.add(e);
            if (const std::optional<GlyphInstance> fine = still_instance(d, intended)) {
                out.intended.add(glyph_error(renderer, *atlas, d, *fine));
            }
        }
        if (out.all.wrong_counts > 0) {
            session_.warn(kSuite, std::to_string(out.all.wrong_counts) +
                                      " measured texels did not hold their glyph's samples when read");
        }
        return out;
    }

    const Args& args() const { return args_; }
    HeadlessContext& context() { return context_; }

private:
    // Drawn glyph `d`'s atlas texels against the exact area of `reference`'s key, over the target
    // pixels either rect covers (the two rects are where each instance lands on the target).
    TexelError glyph_error(const Renderer& renderer, const std::vector<harness::Texel>& atlas, const DrawnGlyph& d,
                           const GlyphInstance& reference) const {
        const FontAsset& asset = font_.asset();
        const TransformedCoverage exact(asset, asset.glyphs[reference.key.glyph], reference.key);
        const uint32_t atlas_width = renderer.atlas().config().width;
        const auto inside = [](const GlyphInstance& g, int64_t x, int64_t y) {
            return x >= g.x && y >= g.y && x < int64_t{g.x} + g.width && y < int64_t{g.y} + g.height;
        };
        const GlyphInstance& drawn = d.instance;
        const int64_t x0 = std::min(drawn.x, reference.x), y0 = std::min(drawn.y, reference.y);
        const int64_t x1 = std::max(int64_t{drawn.x} + drawn.width, int64_t{reference.x} + reference.width);
        const int64_t y1 = std::max(int64_t{drawn.y} + drawn.height, int64_t{reference.y} + reference.height);
        TexelError e;
        e.glyphs = 1;
        for (int64_t y = y0; y < y1; ++y) {
            for (int64_t x = x0; x < x1; ++x) {
                std::array<double, 3> got{}, truth{};
                if (inside(drawn, x, y)) {
                    const auto tx = static_cast<uint32_t>(x - drawn.x), ty = static_cast<uint32_t>(y - drawn.y);
                    const harness::Texel& t = atlas[size_t{d.atlas_y + ty} * atlas_width + d.atlas_x + tx];
                    if (t.count != d.samples) ++e.wrong_counts;
                    const uint16_t sums[3] = {t.r, t.g, t.b};
                    for (size_t c = 0; c < 3; ++c) {
                        got[c] = static_cast<double>(sums[c]) /
                                 (static_cast<double>(kCoverageOne) * std::max<uint16_t>(t.count, 1));
                    }
                }
                if (inside(reference, x, y)) {
                    truth = exact.texel(args_.layout, static_cast<uint32_t>(x - reference.x),
                                        static_cast<uint32_t>(y - reference.y));
                }
                for (size_t c = 0; c < 3; ++c) {
                    if (truth[c] == 0.0 && got[c] == 0.0) continue;
                    const double error = std::fabs(got[c] - truth[c]);
                    e.sum += error;
                    e.worst = std::max(e.worst, error);
                    ++e.channels;
                }
            }
        }
        return e;
    }

    // The instance `d` would be at the still steps (kStillTransformSteps), placed from its glyph
    // as laid out (found by its paint order) as the renderer places a transformed draw's glyphs.
    std::optional<GlyphInstance> still_instance(const DrawnGlyph& d, const Intended& intended) const {
        if (!intended.options || !intended.options->transform) return std::nullopt;
        const auto found =
            std::find_if(intended.laid_out.begin(), intended.laid_out.end(),
                         [&](const GlyphInstance& g) { return g.paint_order == d.instance.paint_order; });
        if (found == intended.laid_out.end()) return std::nullopt;
        const GlyphRecord& record = font_.asset().glyphs[found->key.glyph];
        const GlyphPlacement placement = place_transformed(
            *intended.options->transform, static_cast<double>(found->pen_x), static_cast<double>(found->pen_y),
            static_cast<double>(found->key.size_x) / kSizeOne, static_cast<double>(found->key.size_y) / kSizeOne,
            static_cast<double>(intended.options->offset_x), static_cast<double>(intended.options->offset_y));
        GlyphInstance fine = *found;
        fine.key.subpixel_x = fine.key.subpixel_y = 0;
        if (!place_glyph(record, placement, kStillTransformSteps, fine)) return std::nullopt;
        return fine;
    }

    Session& session_;
    HeadlessContext& context_;
    const Args& args_;
    const Font& font_;
    std::optional<tools::GpuTimer> timer_;
};

// ---- Animated: a new rotation every frame.

struct AnimatedFrame {
    double degrees = 0.0;
    TransformSuite::Timed timed;
    RendererStats stats;
    uint64_t allocations = 0;
    uint64_t evictions = 0;
    TexelError error;     // against its own keys
    TexelError intended;  // against the still steps' keys of the same instances
};

struct AnimatedRun {
    std::string variant;  // "plain", "named"
    std::vector<AnimatedFrame> frames;
};

// A square of prose with the canvas's diagonal as its side, turned about its centre and moved onto
// the canvas's centre: whatever the angle, text covers the canvas.
struct RotatingScreen {
    std::vector<GlyphInstance> glyphs;
    float side = 0.0f;
};

RotatingScreen rotating_screen(const Args& args, const Font& font) {
    FrameArgs frame_args;
    frame_args.size = args.size;
    const double diagonal = std::hypot(static_cast<double>(args.width), static_cast<double>(args.height));
    frame_args.width = frame_args.height = static_cast<uint32_t>(std::ceil(diagonal));
    return {screen_of_text(frame_args, font), static_cast<float>(frame_args.width)};
}

DrawOptions rotating_options(const Args& args, const RotatingScreen& screen, double degrees) {
    DrawOptions options;
    const float half = 0.5f * screen.side;
    options.transform = linear_transform(degrees, 1.0, 0.0, half, half);
    options.offset_x = 0.5f * static_cast<float>(args.width) - half;
    options.offset_y = 0.5f * static_cast<float>(args.height) - half;
    options.visible = VkRect2D{{0, 0}, {args.width, args.height}};
    return options;
}

AnimatedRun animate(TransformSuite& suite, const RotatingScreen& screen, Renderer& renderer, bool named) {
    const Args& args = suite.args();
    AnimatedRun run;
    run.variant = named ? "named" : "plain";
    // One frame first, untimed: lavapipe compiles the rasterizer at its first dispatch, and a named
    // draw is moving only from its second frame.
    DrawOptions warm = rotating_options(args, screen, 0.5 * kDegreesPerFrame);
    warm.id = named ? 1 : 0;
    suite.frame(renderer, screen.glyphs, warm);
    for (uint32_t f = 0; f < args.frames; ++f) {
        AnimatedFrame frame;
        frame.degrees = std::fmod(static_cast<double>(f + 1) * kDegreesPerFrame, 360.0);
        DrawOptions options = rotating_options(args, screen, frame.degrees);
        options.id = named ? 1 : 0;
        frame.timed = suite.frame(renderer, screen.glyphs, options);
        frame.stats = renderer.stats();
        frame.allocations = renderer.atlas().stats().frame.allocations;
        frame.evictions = renderer.atlas().stats().frame.evictions;
        const SubsetError error = suite.subset_error(renderer, args.subset, {screen.glyphs, &options});
        frame.error = error.all;
        frame.intended = error.intended;
        run.frames.push_back(frame);
        if ((f + 1) % 8 == 0 || f + 1 == args.frames) {
            progress(kSuite, run.variant + ": frame " + std::to_string(f + 1) + " of " + std::to_string(args.frames));
        }
    }
    return run;
}

// ---- Still: one rotation held until converged.

struct Checkpoint {
    uint32_t samples = 0;
    uint32_t frame = 0;  // 1-based
    double cumulative_gpu_ms = 0.0;
    TexelError error;
};

struct StillRun {
    uint32_t frames = 0;  // the last that refined a glyph
    bool converged = false;
    double first_gpu_ms = 0.0;
    double total_gpu_ms = 0.0;
    uint32_t drawn = 0;
    std::vector<Checkpoint> points;
};

StillRun hold_still(TransformSuite& suite, const RotatingScreen& screen, Renderer& renderer) {
    const Args& args = suite.args();
    const DrawOptions options = rotating_options(args, screen, kStillDegrees);
    const std::vector<uint32_t> wanted = checkpoints(args.samples);
    StillRun run;
    for (uint32_t frame = 1; frame <= kMaxStillFrames; ++frame) {
        const TransformSuite::Timed timed = suite.frame(renderer, screen.glyphs, options);
        if (frame == 1) run.first_gpu_ms = timed.gpu_ms;
        run.total_gpu_ms += timed.gpu_ms;
        if (renderer.stats().work_items > 0) run.frames = frame;
        const uint32_t held = TransformSuite::frame_samples(renderer);
        const bool measured =
            std::any_of(run.points.begin(), run.points.end(), [&](const Checkpoint& p) { return p.samples == held; });
        if (!measured && std::find(wanted.begin(), wanted.end(), held) != wanted.end()) {
            progress(kSuite, "still: " + std::to_string(held) + " samples at frame " + std::to_string(frame));
            run.points.push_back({held, frame, run.total_gpu_ms, suite.subset_error(renderer, args.subset).all});
        }
        if (renderer.converged() && renderer.stats().work_items == 0) break;
    }
    run.converged = renderer.converged();
    run.drawn = renderer.stats().drawn_glyphs;
    return run;
}

// ---- The accuracy grid: rotation x scale x shear, a few glyphs each.

struct GridCell {
    double degrees = 0.0, scale = 1.0, shear = 0.0;
    uint32_t drawn = 0;
    std::vector<Checkpoint> points;
};

std::vector<GridCell> accuracy_grid(TransformSuite& suite, const Font& font) {
    const Args& args = suite.args();
    const std::vector<uint32_t> points = checkpoints(args.samples);
    // One renderer for the grid (each cell's keys are new to it), its ramp ending on each checkpoint.
    Renderer renderer = make_transform_renderer(suite.context(), args, 1024, ramp_through(points), 0);
    if (Status s = renderer.add_font(font); !s) fail(kSuite, s.error().message);
    const Font* fonts[] = {&font};
    TextStyle style;
    style.size = args.size;
    LayoutOptions layout_options;
    layout_options.origin_x = 300.3f;
    layout_options.origin_y = 300.6f;
    auto laid = layout_text(fonts, args.quick ? "Ag" : "Ag&@e", style, layout_options);
    if (!laid) fail(kSuite, laid.error().message);
    const std::vector<double> angles =
        args.quick ? std::vector<double>{37.0, 211.0} : std::vector<double>{0, 37, 90, 211};
    const std::vector<double> scales =
        args.quick ? std::vector<double>{0.25, 8.0} : std::vector<double>{0.25, 1.0, 8.0};
    std::vector<GridCell> cells;
    for (const double degrees : angles) {
        for (const double scale : scales) {
            for (const double shear : {0.0, 0.5}) {
                GridCell cell{degrees, scale, shear, 0, {}};
                DrawOptions options;
                options.transform =
                    linear_transform(degrees, scale, shear, layout_options.origin_x, layout_options.origin_y);
                double ms = 0.0;
                for (size_t k = 0; k < points.size(); ++k) {
                    ms += suite.frame(renderer, laid->glyphs, options).gpu_ms;
                    cell.points.push_back({TransformSuite::frame_samples(renderer), static_cast<uint32_t>(k + 1), ms,
                                           suite.subset_error(renderer, 1000).all});
                }
                cell.drawn = renderer.stats().drawn_glyphs;
                cells.push_back(cell);
            }
        }
        progress(kSuite, "grid: " + std::to_string(static_cast<int>(degrees)) + " degrees done");
    }
    return cells;
}

// ---- Perspective: a block of text on a plane tilted about the x axis.

struct TiltRun {
    double degrees = 0.0;
    uint32_t glyphs = 0;      // laid out, with outlines
    uint32_t culled = 0;      // a bbox corner behind the eye or out of the depth range
    uint32_t projective = 0;  // past kMaxLocalAffineError: exact projective keys
    std::vector<double> affine_error;
    std::vector<Checkpoint> points;
    std::vector<TexelError> projective_points;  // the projective keys of each checkpoint's subset
    uint32_t drawn = 0;
    RendererStats stats;  // the last frame's: its own count of projective glyphs and largest affine error
};

// The camera at the origin looking down +z (x right, y down, as Vulkan's NDC), the text block's
// centre straight ahead at the distance where one layout pixel is one target pixel at tilt 0; the
// block tilts about its centre's horizontal line, its lower lines towards the eye.
TextPlane tilted_plane(const Args& args, double degrees, float block_width, float block_height) {
    const double f = 1.0 / std::tan(radians(0.5 * kFieldOfViewDegrees));
    const double aspect = static_cast<double>(args.width) / static_cast<double>(args.height);
    const double distance = f * 0.5 * static_cast<double>(args.height);
    const double near = 1.0, far = 4.0 * distance;
    const double c = std::cos(radians(degrees)), s = std::sin(radians(degrees));
    TextPlane plane;
    plane.axis_x = {1.0f, 0.0f, 0.0f};
    plane.axis_y = {0.0f, static_cast<float>(c), static_cast<float>(-s)};
    const double half_w = 0.5 * static_cast<double>(block_width), half_h = 0.5 * static_cast<double>(block_height);
    plane.origin = {static_cast<float>(-half_w), static_cast<float>(-half_h * c),
                    static_cast<float>(distance + half_h * s)};
    plane.view_projection = {};
    plane.view_projection[0] = static_cast<float>(f / aspect);
    plane.view_projection[5] = static_cast<float>(f);
    plane.view_projection[10] = static_cast<float>(far / (far - near));
    plane.view_projection[11] = 1.0f;
    plane.view_projection[14] = static_cast<float>(-near * far / (far - near));
    plane.viewport = {0.0f, 0.0f, static_cast<float>(args.width), static_cast<float>(args.height)};
    return plane;
}

std::vector<TiltRun> perspective(TransformSuite& suite, const Font& font) {
    const Args& args = suite.args();
    FrameArgs block_args;
    block_args.size = args.size;
    block_args.width = std::max(16u, args.width * 4 / 5);
    block_args.height = std::max(16u, args.height * 4 / 5);
    const std::vector<GlyphInstance> block = screen_of_text(block_args, font);
    const std::vector<uint32_t> points = checkpoints(args.samples);
    Renderer renderer = make_transform_renderer(suite.context(), args, 2048, ramp_through(points),
                                                uint64_t{args.atlas_budget_mib} << 20);
    if (Status s = renderer.add_font(font); !s) fail(kSuite, s.error().message);
    const std::vector<double> tilts = args.quick ? std::vector<double>{45, 80} : std::vector<double>{0, 45, 70, 80};
    std::vector<TiltRun> runs;
    for (const double degrees : tilts) {
        TiltRun run;
        run.degrees = degrees;
        DrawOptions options;
        options.plane =
            tilted_plane(args, degrees, static_cast<float>(block_args.width), static_cast<float>(block_args.height));
        options.visible = VkRect2D{{0, 0}, {args.width, args.height}};
        for (const GlyphInstance& g : block) {
            const GlyphRecord& record = font.asset().glyphs[g.key.glyph];
            if (record.curve_count == 0) continue;
            ++run.glyphs;
            const PlanePlacement p = place_on_plane(
                *options.plane, record, static_cast<double>(g.pen_x), static_cast<double>(g.pen_y),
                static_cast<double>(g.key.size_x) / kSizeOne, static_cast<double>(g.key.size_y) / kSizeOne);
            if (!p.visible) {
                ++run.culled;
                continue;
            }
            run.affine_error.push_back(p.affine_error);
            if (p.projective) ++run.projective;
        }
        double ms = 0.0;
        for (size_t k = 0; k < points.size(); ++k) {
            ms += suite.frame(renderer, block, options).gpu_ms;
            const SubsetError e = suite.subset_error(renderer, args.subset);
            run.points.push_back({TransformSuite::frame_samples(renderer), static_cast<uint32_t>(k + 1), ms, e.all});
            run.projective_points.push_back(e.projective);
        }
        run.drawn = renderer.stats().drawn_glyphs;
        run.stats = renderer.stats();
        progress(kSuite, "perspective: " + std::to_string(static_cast<int>(degrees)) + " degrees, " +
                             std::to_string(run.projective) + " of " + std::to_string(run.glyphs) + " projective");
        runs.push_back(std::move(run));
    }
    return runs;
}

// ---- The report.

template <class Get>
std::vector<double> column(const AnimatedRun& run, Get&& get) {
    std::vector<double> values;
    for (const AnimatedFrame& f : run.frames) values.push_back(static_cast<double>(get(f)));
    return values;
}

void print_animated(std::FILE* md, const Args& args, size_t laid_out, const std::vector<AnimatedRun>& runs) {
    std::fprintf(
        md,
        "A %ux%u canvas of %s at %.4g px (a square of prose with the canvas's diagonal as its side, "
        "%zu glyphs, turned about its centre and clipped to the canvas), layout %s, at a new rotation every "
        "frame: %.1f degrees times the frame, so every frame is a first frame (ramp 8 samples, %s frame "
        "budget). plain: an unnamed draw (still keys, 1/256 px per em); named: a named draw, moving from "
        "its second frame (coarse keys, kMovingTransformSteps). One untimed frame first. GPU ms: timestamps "
        "around Renderer::record; CPU ms: begin_frame, draw and record. Error: each frame's atlas against "
        "the exact area of its keys' transformed outlines (support/transform_reference.hpp) on %u whole "
        "glyphs picked evenly (all their texels): the frame's mean per channel and its worst channel; "
        "median, p90 and max over the %u frames.\n\n",
        args.width, args.height, args.font.c_str(), double{args.size}, laid_out, args.layout_name.c_str(),
        kDegreesPerFrame,
        args.frame_budget >= (uint64_t{1} << 50) ? "an unbounded" : ("a " + std::to_string(args.frame_budget)).c_str(),
        args.subset, args.frames);
    std::fprintf(md,
                 "| draw | glyphs drawn | GPU ms median | p90 | CPU ms median | p90 | mean error median | p90 | max | "
                 "worst texel median | max | still keys: mean median | max | worst texel max | samples | curve tests | "
                 "atlas allocations | coarsened | failed |\n"
                 "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const AnimatedRun& r : runs) {
        const auto mean = column(r, [](const AnimatedFrame& f) { return f.error.mean(); });
        const auto worst = column(r, [](const AnimatedFrame& f) { return f.error.worst; });
        const auto gpu = column(r, [](const AnimatedFrame& f) { return f.timed.gpu_ms; });
        const auto cpu = column(r, [](const AnimatedFrame& f) { return f.timed.cpu_ms; });
        const auto intended_mean = column(r, [](const AnimatedFrame& f) { return f.intended.mean(); });
        const auto intended_worst = column(r, [](const AnimatedFrame& f) { return f.intended.worst; });
        std::fprintf(
            md,
            "| %s | %.0f | %.3f | %.3f | %.2f | %.2f | %.4f | %.4f | %.4f | %.3f | %.3f | %.4f | %.4f | %.3f | %.3g | "
            "%.3g | %.0f | %.0f | %.0f |\n",
            r.variant.c_str(), percentile(column(r, [](const AnimatedFrame& f) { return f.stats.drawn_glyphs; }), 0.5),
            percentile(gpu, 0.5), percentile(gpu, 0.9), percentile(cpu, 0.5), percentile(cpu, 0.9),
            percentile(mean, 0.5), percentile(mean, 0.9), percentile(mean, 1.0), percentile(worst, 0.5),
            percentile(worst, 1.0), percentile(intended_mean, 0.5), percentile(intended_mean, 1.0),
            percentile(intended_worst, 1.0),
            percentile(column(r, [](const AnimatedFrame& f) { return f.stats.samples; }), 0.5),
            percentile(column(r, [](const AnimatedFrame& f) { return f.stats.curve_tests; }), 0.5),
            percentile(column(r, [](const AnimatedFrame& f) { return f.allocations; }), 0.5),
            percentile(column(r, [](const AnimatedFrame& f) { return f.stats.coarsened_glyphs; }), 0.5),
            percentile(column(r, [](const AnimatedFrame& f) { return f.stats.failed_glyphs; }), 0.5));
    }
    std::fprintf(md,
                 "\nStill keys: the same texels against the exact area at the key the instance has when still "
                 "(kStillTransformSteps), over the target pixels either covers: for the named draw, what its coarse "
                 "keys and quarter-pixel pens add. Medians per frame for glyphs drawn, samples, curve tests, "
                 "allocations, coarsened and failed glyphs; every frame is in the JSON.\n");
}

void print_checkpoints(std::FILE* md, const std::vector<Checkpoint>& points) {
    for (const Checkpoint& p : points) {
        std::fprintf(md, " %.4f | %.4f | %.2f |", p.error.mean(), p.error.worst, p.cumulative_gpu_ms);
    }
}

void print_still(std::FILE* md, const Args& args, const StillRun& still, const std::vector<GridCell>& grid) {
    std::fprintf(md,
                 "\nStill: a %ux%u screen (the canvas, at most 1280x720) held at %.0f degrees, the default ramp (8, 4, "
                 "2, then 1 sample a frame), "
                 "until every glyph holds %u samples: %u frames (%s), %.3f GPU ms in frame 1 and %.1f ms in all, "
                 "%u glyphs drawn. The error on %u whole glyphs when they hold N samples, with the GPU ms "
                 "summed to that frame:\n\n| samples | frame | mean | worst texel | cumulative GPU ms |\n"
                 "|---:|---:|---:|---:|---:|\n",
                 args.width, args.height, kStillDegrees, args.samples, still.frames,
                 still.converged ? "converged" : "NOT converged", still.first_gpu_ms, still.total_gpu_ms, still.drawn,
                 args.subset);
    for (const Checkpoint& p : still.points) {
        std::fprintf(md, "| %u | %u | %.5f | %.5f | %.1f |\n", p.samples, p.frame, p.error.mean(), p.error.worst,
                     p.cumulative_gpu_ms);
    }
    if (grid.empty()) return;
    std::fprintf(md,
                 "\nAccuracy grid: the glyphs below at %.4g px under rotation x scale x shear (L = R(angle) "
                 "{s, s shear; 0, s}), every texel of each, a ramp ending on each sample count; per count: mean, "
                 "worst texel, cumulative GPU ms of the cell's frames.\n\n| angle | scale | shear | glyphs |",
                 double{args.size});
    for (const Checkpoint& p : grid.front().points) std::fprintf(md, " %u: mean | worst | GPU ms |", p.samples);
    std::fprintf(md, "\n|---:|---:|---:|---:|");
    for (size_t k = 0; k < grid.front().points.size(); ++k) std::fprintf(md, "---:|---:|---:|");
    std::fprintf(md, "\n");
    TexelError last;
    for (const GridCell& cell : grid) {
        std::fprintf(md, "| %.0f | %.4g | %.4g | %u |", cell.degrees, cell.scale, cell.shear, cell.drawn);
        print_checkpoints(md, cell.points);
        std::fprintf(md, "\n");
        last.add(cell.points.back().error);
    }
    std::fprintf(md, "\nOver the grid at %u samples: mean %.5f, worst texel %.5f.\n",
                 grid.front().points.back().samples, last.mean(), last.worst);
}

void print_perspective(std::FILE* md, const Args& args, const std::vector<TiltRun>& runs) {
    if (runs.empty()) return;
    std::fprintf(md,
                 "\nPerspective: a block of prose (4/5 of the canvas each way) on a TextPlane tilted about its "
                 "horizontal centre line, seen by a perspective camera (%.0f degree vertical field of view, one "
                 "layout pixel one target pixel at tilt 0). Per glyph place_on_plane()'s local-affine error "
                 "(pixels, at the bbox corners): median, p90, max; past kMaxLocalAffineError = 1/128 px the key "
                 "keeps its perspective (projective). The atlas on %u whole glyphs against the exact (projective) "
                 "area, a ramp ending on each sample count: mean, worst texel, cumulative GPU ms; last: the "
                 "projective keys among them at %u samples.\n\n| tilt | glyphs | culled | projective | affine error "
                 "median | p90 | max |",
                 kFieldOfViewDegrees, args.subset, args.samples);
    for (const Checkpoint& p : runs.front().points) std::fprintf(md, " %u: mean | worst | GPU ms |", p.samples);
    std::fprintf(md, " projective: glyphs | mean | worst |\n|---:|---:|---:|---:|---:|---:|---:|");
    for (size_t k = 0; k < runs.front().points.size(); ++k) std::fprintf(md, "---:|---:|---:|");
    std::fprintf(md, "---:|---:|---:|\n");
    for (const TiltRun& r : runs) {
        std::fprintf(md, "| %.0f | %u | %u | %u | %.2e | %.2e | %.2e |", r.degrees, r.glyphs, r.culled, r.projective,
                     percentile(r.affine_error, 0.5), percentile(r.affine_error, 0.9), percentile(r.affine_error, 1.0));
        print_checkpoints(md, r.points);
        const TexelError& p = r.projective_points.back();
        std::fprintf(md, " %u | %.4f | %.4f |\n", p.glyphs, p.mean(), p.worst);
    }
}

void write_error(JsonWriter& json, const TexelError& e) {
    json.field("mean", e.mean()).field("worst", e.worst).field("glyphs", e.glyphs).field("channels", e.channels);
}

void write_checkpoints(JsonWriter& json, const std::vector<Checkpoint>& points) {
    json.key("points").begin_array();
    for (const Checkpoint& p : points) {
        json.begin_object()
            .field("samples", p.samples)
            .field("frame", p.frame)
            .field("cumulative_gpu_ms", p.cumulative_gpu_ms);
        write_error(json, p.error);
        json.end_object();
    }
    json.end_array();
}

void write_json(JsonWriter& json, const Args& args, size_t laid_out, const std::vector<AnimatedRun>& animated,
                const StillRun& still, const std::vector<GridCell>& grid, const std::vector<TiltRun>& tilts) {
    json.begin_object()
        .field("font", args.font)
        .field("size", args.size)
        .field("layout", args.layout_name)
        .field("samples", args.samples)
        .field("subset", args.subset)
        .field("frame_budget", args.frame_budget)
        .field("atlas_budget_mib", args.atlas_budget_mib)
        .field("degrees_per_frame", kDegreesPerFrame)
        .field("laid_out_glyphs", laid_out);
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.key("animated").begin_array();
    for (const AnimatedRun& r : animated) {
        json.begin_object().field("variant", r.variant).key("frames").begin_array();
        for (const AnimatedFrame& f : r.frames) {
            json.begin_object()
                .field("degrees", f.degrees)
                .field("gpu_ms", f.timed.gpu_ms)
                .field("cpu_ms", f.timed.cpu_ms)
                .field("samples", f.stats.samples)
                .field("curve_tests", f.stats.curve_tests)
                .field("glyphs_drawn", f.stats.drawn_glyphs)
                .field("glyphs_refined", f.stats.work_items)
                .field("culled", f.stats.culled_glyphs)
                .field("moving", f.stats.moving_glyphs)
                .field("transformed", f.stats.transformed_glyphs)
                .field("coarsened", f.stats.coarsened_glyphs)
                .field("failed", f.stats.failed_glyphs)
                .field("atlas_allocations", f.allocations)
                .field("atlas_evictions", f.evictions)
                .field("atlas_grown", f.stats.atlas_grown)
                .field("atlas_width", f.stats.atlas_width)
                .field("still_key_mean", f.intended.mean())
                .field("still_key_worst", f.intended.worst);
            write_error(json, f.error);
            json.end_object();
        }
        json.end_array().end_object();
    }
    json.end_array();
    json.key("still")
        .begin_object()
        .field("degrees", kStillDegrees)
        .field("frames", still.frames)
        .field("converged", still.converged)
        .field("first_gpu_ms", still.first_gpu_ms)
        .field("total_gpu_ms", still.total_gpu_ms)
        .field("glyphs_drawn", still.drawn);
    write_checkpoints(json, still.points);
    json.end_object();
    json.key("grid").begin_array();
    for (const GridCell& cell : grid) {
        json.begin_object()
            .field("degrees", cell.degrees)
            .field("scale", cell.scale)
            .field("shear", cell.shear)
            .field("glyphs_drawn", cell.drawn);
        write_checkpoints(json, cell.points);
        json.end_object();
    }
    json.end_array().key("perspective").begin_array();
    for (const TiltRun& r : tilts) {
        json.begin_object()
            .field("tilt_degrees", r.degrees)
            .field("glyphs", r.glyphs)
            .field("culled", r.culled)
            .field("projective", r.projective)
            .field("glyphs_drawn", r.drawn)
            .field("renderer_projective_glyphs", r.stats.projective_glyphs)
            .field("renderer_max_affine_error", r.stats.max_affine_error)
            .field("affine_error_median", percentile(r.affine_error, 0.5))
            .field("affine_error_p90", percentile(r.affine_error, 0.9))
            .field("affine_error_max", percentile(r.affine_error, 1.0))
            .field("affine_error", r.affine_error);
        write_checkpoints(json, r.points);
        json.key("projective_points").begin_array();
        for (const TexelError& e : r.projective_points) {
            json.begin_object();
            write_error(json, e);
            json.end_object();
        }
        json.end_array().end_object();
    }
    json.end_array().end_object();
}

}  // namespace

void run_transform(Session& session) {
    const Options& o = session.options;
    Args args;
    if (!o.fonts.empty()) args.font = o.fonts.front();
    args.quick = o.quick;
    args.size = o.size.value_or(16.0f);
    args.width = o.width.value_or(o.quick ? 256 : session.cpu_device ? 480 : 1920);
    args.height = o.height.value_or(o.quick ? 128 : session.cpu_device ? 270 : 1080);
    args.samples = o.samples.value_or(o.quick ? 16 : 512);
    args.frames = o.frames.value_or(o.quick ? 3 : session.cpu_device ? 16 : 60);
    args.subset = o.quick ? 8 : 64;
    // A rotating screen needs an entry per instance every frame: unless --atlas-budget says, the
    // atlas may grow to 512 MiB (8192 x 8192) to hold a frame's.
    args.atlas_budget_mib = o.atlas_budget_mib ? o.atlas_budget_mib : 512;
    args.frame_budget = o.frame_budget;
    args.layout_name = o.layout.value_or("rgb");
    auto layout = resolve_subpixel_layout(args.layout_name);
    if (!layout) fail(kSuite, layout.error().message);
    args.layout = *layout;

    auto baked = bake_font_file(args.font, BakeOptions{});
    if (!baked) fail(kSuite, baked.error().message);
    auto font = Font::create(std::move(baked->asset), 1);
    if (!font) fail(kSuite, font.error().message);
    TransformSuite suite(session, args, *font);
    const RotatingScreen screen = rotating_screen(args, *font);
    const uint64_t atlas_budget = uint64_t{args.atlas_budget_mib} << 20;

    std::vector<AnimatedRun> animated;
    for (const bool named : {false, true}) {
        progress(kSuite, std::string(named ? "named" : "plain") + ": " + std::to_string(screen.glyphs.size()) +
                             " glyphs turning on a " + std::to_string(args.width) + "x" + std::to_string(args.height) +
                             " canvas, " + std::to_string(args.frames) + " frames");
        Renderer renderer = make_transform_renderer(*session.context, args, 2048, {}, atlas_budget);
        if (Status s = renderer.add_font(*font); !s) fail(kSuite, s.error().message);
        animated.push_back(animate(suite, screen, renderer, named));
    }
    print_animated(session.md, args, screen.glyphs.size(), animated);

    // Convergence is per glyph, not per screen: the still screen is at most kMaxStillCanvas, so that a
    // 4K run's hundreds of frames to 512 samples (each read back at its checkpoints) stay minutes.
    Args still_args = args;
    still_args.width = std::min(args.width, kMaxStillCanvas[0]);
    still_args.height = std::min(args.height, kMaxStillCanvas[1]);
    TransformSuite still_suite(session, still_args, *font);
    const RotatingScreen still_screen = rotating_screen(still_args, *font);
    progress(kSuite, "still: " + std::to_string(static_cast<int>(kStillDegrees)) + " degrees until converged, " +
                         std::to_string(still_args.width) + "x" + std::to_string(still_args.height));
    Renderer still_renderer = make_transform_renderer(*session.context, still_args, 2048, {}, atlas_budget);
    if (Status s = still_renderer.add_font(*font); !s) fail(kSuite, s.error().message);
    const StillRun still = hold_still(still_suite, still_screen, still_renderer);
    const std::vector<GridCell> grid = accuracy_grid(suite, *font);
    print_still(session.md, still_args, still, grid);

    const std::vector<TiltRun> tilts = perspective(suite, *font);
    print_perspective(session.md, args, tilts);
    write_json(session.json, args, screen.glyphs.size(), animated, still, grid, tilts);
}

}  // namespace crisp::bench
