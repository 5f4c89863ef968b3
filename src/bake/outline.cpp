#include "bake/outline.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <algorithm>

namespace crisp {

OutlineBuilder::OutlineBuilder(const OutlineOptions& options, OutlineCounters& counters)
    : options_(options), counters_(counters) {}

void OutlineBuilder::move_to(Vec2 p) {
    close_contour();
    start_ = pen_ = scaled(p);
    open_ = true;
}

void OutlineBuilder::line_to(Vec2 p) {
    ensure_open();
    const Vec2 end = scaled(p);
    ++counters_.lines;
    add(line_to_quad(pen_, end));
    pen_ = end;
}

void OutlineBuilder::quad_to(Vec2 control, Vec2 p) {
    ensure_open();
    const Vec2 end = scaled(p);
    ++counters_.quadratics;
    add({pen_, scaled(control), end});
    pen_ = end;
}

void OutlineBuilder::cubic_to(Vec2 control1, Vec2 control2, Vec2 p) {
    ensure_open();
    const Cubic cubic{pen_, scaled(control1), scaled(control2), scaled(p)};
    ++counters_.cubics;
    std::vector<Quad> pieces;
    const double deviation = lower_cubic(cubic, options_.tolerance, pieces);
    counters_.max_deviation = std::max(counters_.max_deviation, deviation);
    counters_.cubic_pieces += pieces.size();
    if (options_.measure_seed) {
        Quad seed[2];
        seed_split_cubic(cubic, seed);
        const double seed_deviation =
            std::max(sampled_deviation(cubic, 0.0, 0.5, seed[0], 32), sampled_deviation(cubic, 0.5, 1.0, seed[1], 32));
        counters_.seed_max_deviation = std::max(counters_.seed_max_deviation, seed_deviation);
    }
    for (const Quad& q : pieces) add(q);
    pen_ = cubic.p3;
}

void OutlineBuilder::ensure_open() {
    // A path that draws before its first move starts at the pen, as PostScript's would.
    if (!open_) {
        start_ = pen_;
        open_ = true;
    }
}

void OutlineBuilder::add(const Quad& q) {
    if (is_zero_length(q)) {
        ++counters_.dropped_zero_length;
        return;
    }
    if (options_.split_y_extrema) {
        Quad halves[2];
        const int count = split_at_y_extremum(q, halves);
        counters_.y_splits += static_cast<uint64_t>(count - 1);
        for (int i = 0; i < count; ++i) current_.push_back(halves[i]);
        return;
    }
    current_.push_back(q);
}

void OutlineBuilder::close_contour() {
    if (!open_) return;
    open_ = false;
    if (pen_ != start_) {
        ++counters_.closed_contours;
        ++counters_.lines;
        add(line_to_quad(pen_, start_));
        pen_ = start_;
    }
    if (!current_.empty()) contours_.push_back(std::move(current_));
    current_.clear();
}

std::vector<Contour> OutlineBuilder::finish() {
    close_contour();
    return std::move(contours_);
}

namespace {

Vec2 to_vec(const FT_Vector* v) {
    return {static_cast<double>(v->x), static_cast<double>(v->y)};
}

int on_move(const FT_Vector* to, void* user) {
    static_cast<OutlineBuilder*>(user)->move_to(to_vec(to));
    return 0;
}
int on_line(const FT_Vector* to, void* user) {
    static_cast<OutlineBuilder*>(user)->line_to(to_vec(to));
    return 0;
}
int on_conic(const FT_Vector* control, const FT_Vector* to, void* user) {
    static_cast<OutlineBuilder*>(user)->quad_to(to_vec(control), to_vec(to));
    return 0;
}
int on_cubic(const FT_Vector* control1, const FT_Vector* control2, const FT_Vector* to, void* user) {
    static_cast<OutlineBuilder*>(user)->cubic_to(to_vec(control1), to_vec(control2), to_vec(to));
    return 0;
}

}  // namespace

bool decompose_outline(const FT_Outline_& outline, OutlineBuilder& builder, std::string& error) {
    FT_Outline_Funcs funcs{};
    funcs.move_to = on_move;
    funcs.line_to = on_line;
    funcs.conic_to = on_conic;
    funcs.cubic_to = on_cubic;
    FT_Outline copy = outline;  // FT_Outline_Decompose takes a non-const pointer but only reads
    const FT_Error status = FT_Outline_Decompose(&copy, &funcs, &builder);
    if (status != 0) {
        error = "FreeType could not walk the outline: " + freetype_error(status);
        return false;
    }
    return true;
}

namespace {

// FreeType's words for its error codes, from its own list (the switch fterrors.h documents):
// FT_Error_String has them only in a FreeType built with FT_CONFIG_OPTION_ERROR_STRINGS, which
// Debian's is not, and a bare "FreeType error 8" says nothing to a user.
const char* freetype_error_text(int error_code) {
#undef FTERRORS_H_
#define FT_ERROR_START_LIST switch (FT_ERROR_BASE(error_code)) {
#define FT_ERRORDEF(e, v, s) \
    case v:                  \
        return s;
#define FT_ERROR_END_LIST }
#include FT_ERRORS_H
    return nullptr;
}

}  // namespace

std::string freetype_error(int error) {
    const char* text = freetype_error_text(error);
    return "FreeType error " + std::to_string(error) + (text ? std::string(" (") + text + ")" : std::string());
}

}  // namespace crisp
