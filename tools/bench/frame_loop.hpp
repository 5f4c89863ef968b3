// The frames suite's measurement, which the scaling suite repeats on other screens: a screen of
// prose drawn frame after frame, each frame's GPU time from timestamp queries around the
// renderer's record().
#pragma once

#include "headless_context.hpp"

#include <crisp/font.hpp>
#include <crisp/renderer.hpp>
#include <crisp/subpixel.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace crisp::bench {

struct FrameArgs {
    std::string font = "fonts/DejaVuSans.ttf";
    std::string layout = "rgb";
    float size = 16.0f;
    uint32_t width = 1920, height = 1080;
    uint32_t samples = 512;
    uint32_t max_frames = 1000;
    uint32_t atlas_budget_mib = 0;              // 0: the atlas keeps its 2048x2048
    uint64_t frame_budget = uint64_t{1} << 50;  // curve tests per frame; default: unbounded (raw throughput)
    bool no_shared_rows = false;
    SampleKind sample_kind = SampleKind::rows;
};

struct Frame {
    uint32_t index = 0;
    uint64_t samples = 0;
    uint32_t items = 0;
    uint64_t curve_tests = 0;
    double gpu_ms = 0.0;
    double cpu_ms = 0.0;  // begin_frame, draw and record on the CPU
};

// A screen of prose: lines of text at args.size, wrapped at the canvas, until the canvas is full.
std::vector<GlyphInstance> screen_of_text(const FrameArgs& args, const Font& font);

// A renderer for the benchmark: args' samples, frame budget, layout, atlas budget, shared rows and
// sample kind, with `font` added.
Renderer make_renderer(const HeadlessContext& context, const FrameArgs& args, const SubpixelLayout& layout,
                       const Font& font);

// Draws the screen frame after frame (with `options` where given), each timed on the GPU, until it
// converges or max_frames.
std::vector<Frame> run_frames(HeadlessContext& context, Renderer& renderer, const std::vector<GlyphInstance>& screen,
                              uint32_t max_frames, const DrawOptions* options = nullptr);

}  // namespace crisp::bench
