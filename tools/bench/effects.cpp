// crisp-bench --suite effects: what text effects cost (docs/effects.md). One screen of prose drawn
// plain and with each effect: an outside outline, an outline with a hard drop shadow and with a
// blurred one, a glow, a centred mitered outline, and a weight. Per screen: frame 1 (every glyph and every derived
// outline new: begin_frame, draw and record on the CPU, Renderer::record on the GPU), the frames to converge and their
// GPU time in all, a converged frame, and the tile path's composite of the converged frame (GPU ms), with the effect
// layers, their atlas texels and the derived outlines made and their bytes.
#include "bench.hpp"
#include "frame_loop.hpp"
#include "gpu_tools.hpp"

#include <crisp/bake.hpp>
#include <crisp/compositor.hpp>
#include <crisp/effects.hpp>
#include <crisp/font.hpp>
#include <crisp/renderer.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace crisp::bench {
namespace {

constexpr std::string_view kSuite = "effects";
constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

struct Variant {
    std::string name;
    std::optional<TextEffects> effects;
};

struct VariantResult {
    Variant variant;
    std::vector<Frame> frames;
    bool converged = false;
    double composite_ms = 0.0;  // the tile path's GPU ms for the converged frame
    uint32_t quads = 0;
    RendererStats first, last;  // frame 1's and the converged frame's renderer stats
    uint32_t atlas_entries = 0;
};

std::vector<Variant> variants() {
    TextEffects outline;
    outline.outline = TextOutline{1.0f, OutlinePlacement::outside, LineJoin::round, 4.0f, {0.0f, 0.0f, 0.0f, 1.0f}};
    TextEffects shadowed = outline;
    shadowed.shadow = TextShadow{1.5f, 1.5f, {0.0f, 0.0f, 0.0f, 0.5f}};
    TextEffects centred;
    centred.outline = TextOutline{1.0f, OutlinePlacement::centred, LineJoin::miter, 4.0f, {1.0f, 1.0f, 1.0f, 1.0f}};
    TextEffects bold;
    bold.weight = 0.5f;
    TextEffects blurred = outline;
    blurred.shadow = TextShadow{2.0f, 2.0f, {0.0f, 0.0f, 0.0f, 0.5f}, 3.0f};
    TextEffects glow;
    glow.glow = TextGlow{3.0f, {1.0f, 1.0f, 1.0f, 0.75f}};
    return {{"plain", std::nullopt},
            {"outline 1 px outside, round", outline},
            {"outline 1 px + shadow (1.5, 1.5)", shadowed},
            {"outline 1 px + shadow (2, 2) blurred 3 px", blurred},
            {"glow 3 px", glow},
            {"outline 1 px centred, miter", centred},
            {"weight +0.5 px", bold}};
}

double composite_converged(HeadlessContext& context, const Renderer& renderer, uint32_t width, uint32_t height,
                           uint32_t& quads) {
    CompositorCreateInfo info = compositor_create_info(context);
    info.frames_in_flight = 1;
    auto compositor = Compositor::create(info);
    if (!compositor) fail(kSuite, compositor.error().message);
    ImageDesc desc;
    desc.format = kFormat;
    desc.width = width;
    desc.height = height;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    auto target = context.create_image(desc);
    if (!target) fail(kSuite, target.error().message);
    const std::vector<float> grey(size_t{width} * height * 4, 0.5f);
    if (Status s = context.upload(*target, std::as_bytes(std::span(grey)), VK_IMAGE_LAYOUT_GENERAL); !s) {
        fail(kSuite, s.error().message);
    }
    auto timer = tools::GpuTimer::create(context);
    if (!timer) fail(kSuite, timer.error().message);
    // Twice: the first builds the compositor's pipelines and buffers; the second is timed.
    double ms = 0.0;
    for (int pass = 0; pass < 2; ++pass) {
        Status recorded;
        const Status submitted = context.submit_and_wait([&](VkCommandBuffer cb) {
            timer->begin(cb, true);
            const CompositeTarget t{
                target->view(), kFormat, VK_FORMAT_UNDEFINED, {width, height}, {{0, 0}, {width, height}}};
            recorded = compositor->record(cb, renderer.drawn_frame(), t);
            timer->end(cb);
        });
        if (!recorded) fail(kSuite, recorded.error().message);
        if (!submitted) fail(kSuite, submitted.error().message);
        const Result<double> measured = timer->milliseconds();
        if (!measured) fail(kSuite, measured.error().message);
        ms = *measured;
    }
    quads = compositor->stats().quads;
    return ms;
}

void print_markdown(std::FILE* md, const FrameArgs& args, size_t glyphs, const std::vector<VariantResult>& results) {
    std::fprintf(md,
                 "A %ux%u screen of prose, %s at %.4g px, %zu glyphs, layout %s, %u row samples. Frame 1: every glyph "
                 "and derived outline new (CPU ms: begin_frame, draw, record; GPU ms: Renderer::record between "
                 "timestamp queries). To converge: the frames until every glyph holds its samples and their GPU ms "
                 "in all. Converged: the last frame (nothing left to sample). Composite: the tile path's GPU ms for "
                 "the converged frame over a grey canvas.\n\n",
                 args.width, args.height, args.font.c_str(), static_cast<double>(args.size), glyphs,
                 args.layout.c_str(), args.samples);
    std::fprintf(md,
                 "| screen | frame 1 CPU ms | frame 1 GPU ms | frames | GPU ms to converge | converged GPU ms | "
                 "composite GPU ms | quads | effect layers | effect texels | derived outlines | derived MiB | atlas "
                 "entries |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const VariantResult& r : results) {
        double total = 0.0;
        for (const Frame& f : r.frames) total += f.gpu_ms;
        std::fprintf(md, "| %s | %.2f | %.3f | %zu%s | %.2f | %.4f | %.3f | %u | %u | %llu | %u | %.2f | %u |\n",
                     r.variant.name.c_str(), r.frames.front().cpu_ms, r.frames.front().gpu_ms, r.frames.size(),
                     r.converged ? "" : " (not converged)", total, r.frames.back().gpu_ms, r.composite_ms, r.quads,
                     r.first.effect_layers, static_cast<unsigned long long>(r.first.effect_texels),
                     r.first.derived_made, static_cast<double>(r.first.derived_bytes) / 1048576.0, r.atlas_entries);
    }
}

void write_json(JsonWriter& json, const FrameArgs& args, size_t glyphs, const std::vector<VariantResult>& results) {
    json.begin_object().field("size", args.size).field("samples", args.samples).field("glyphs", glyphs);
    json.key("canvas").begin_array().value(args.width).value(args.height).end_array();
    json.key("screens").begin_array();
    for (const VariantResult& r : results) {
        double total = 0.0;
        for (const Frame& f : r.frames) total += f.gpu_ms;
        json.begin_object()
            .field("name", r.variant.name)
            .field("frame1_cpu_ms", r.frames.front().cpu_ms)
            .field("frame1_gpu_ms", r.frames.front().gpu_ms)
            .field("frames", r.frames.size())
            .field("converged", r.converged)
            .field("gpu_ms_to_converge", total)
            .field("converged_gpu_ms", r.frames.back().gpu_ms)
            .field("composite_gpu_ms", r.composite_ms)
            .field("quads", r.quads)
            .field("effect_layers", r.first.effect_layers)
            .field("effect_texels", r.first.effect_texels)
            .field("failed_effects", r.last.failed_effects)
            .field("derived_made", r.first.derived_made)
            .field("derived_bytes", r.first.derived_bytes)
            .field("atlas_entries", r.atlas_entries)
            .end_object();
    }
    json.end_array().end_object();
}

}  // namespace

void run_effects(Session& session) {
    const Options& o = session.options;
    FrameArgs args;
    args.font = o.dejavu;
    if (!o.fonts.empty()) args.font = o.fonts.front();
    args.size = o.size.value_or(16.0f);
    args.width = o.width.value_or(o.quick ? 256 : session.cpu_device ? 640 : 3840);
    args.height = o.height.value_or(o.quick ? 128 : session.cpu_device ? 360 : 2160);
    args.samples = o.samples.value_or(o.quick ? 16 : 512);
    args.max_frames = o.frames.value_or(1000);
    args.layout = o.layout.value_or("rgb");
    // Room for three layers of every glyph: the atlas may grow to 1 GiB rather than coarsen.
    args.atlas_budget_mib = std::max<uint32_t>(o.atlas_budget_mib, 1024);
    const Result<SubpixelLayout> layout = subpixel_preset(args.layout);
    if (!layout) fail(kSuite, layout.error().message);
    auto baked = bake_font_file(args.font, BakeOptions{});
    if (!baked) fail(kSuite, baked.error().message);
    auto font = Font::create(std::move(baked->asset), 1);
    if (!font) fail(kSuite, font.error().message);
    HeadlessContext& context = *session.context;
    const std::vector<GlyphInstance> screen = screen_of_text(args, *font);

    std::vector<VariantResult> results;
    for (const Variant& v : variants()) {
        progress(kSuite, v.name + ": " + std::to_string(screen.size()) + " glyphs on a " + std::to_string(args.width) +
                             "x" + std::to_string(args.height) + " canvas");
        Renderer renderer = make_renderer(context, args, *layout, *font);
        DrawOptions options;
        options.effects = v.effects;
        VariantResult r;
        r.variant = v;
        if (v.effects) {
            // The derived glyphs' pipelines are made at the first frame that draws one, a cost of an
            // application's first frames rather than of a new screen: one glyph with the effects at
            // other widths (other derived outlines) first, untimed.
            TextEffects other = *v.effects;
            other.weight *= 0.37f;
            if (other.outline) other.outline->width *= 0.37f;
            if (other.shadow) other.shadow->blur *= 0.37f;
            if (other.glow) other.glow->radius *= 0.37f;
            DrawOptions warm;
            warm.effects = other;
            run_frames(context, renderer, {screen.front()}, 1, &warm);
        }
        // Frame 1 on its own, for its stats; then the rest until converged.
        r.frames = run_frames(context, renderer, screen, 1, &options);
        r.first = renderer.stats();
        const std::vector<Frame> rest = run_frames(context, renderer, screen, args.max_frames - 1, &options);
        r.frames.insert(r.frames.end(), rest.begin(), rest.end());
        r.last = renderer.stats();
        r.converged = renderer.converged();
        r.atlas_entries = renderer.atlas().stats().resident_glyphs;
        r.composite_ms = composite_converged(context, renderer, args.width, args.height, r.quads);
        results.push_back(std::move(r));
    }
    print_markdown(session.md, args, screen.size(), results);
    write_json(session.json, args, screen.size(), results);
}

}  // namespace crisp::bench
