// Turning a glyph outline (lines, quadratics, cubics; FreeType or any other source) into closed
// contours of quadratic curves in em units.
#pragma once

#include "asset/curves.hpp"

#include <cstdint>
#include <string>
#include <vector>

struct FT_Outline_;

namespace crisp {

struct OutlineCounters {
    uint64_t lines = 0;
    uint64_t quadratics = 0;
    uint64_t cubics = 0;
    uint64_t cubic_pieces = 0;
    uint64_t dropped_zero_length = 0;
    uint64_t closed_contours = 0;
    uint64_t y_splits = 0;
    double max_deviation = 0.0;       // em
    double seed_max_deviation = 0.0;  // em, the seed's split in two, measured the same way
};

struct OutlineOptions {
    double scale = 1.0;               // input units to em
    double tolerance = 1.0 / 4096.0;  // em
    bool split_y_extrema = false;
    bool measure_seed = true;  // also measure the seed's two-way split, for the report
};

// Receives the path of one glyph, command by command, and builds its contours. Zero-length
// curves are dropped and every contour is closed (with a line back to its start when the path
// leaves it open).
class OutlineBuilder {
public:
    OutlineBuilder(const OutlineOptions& options, OutlineCounters& counters);

    void move_to(Vec2 p);
    void line_to(Vec2 p);
    void quad_to(Vec2 control, Vec2 p);
    void cubic_to(Vec2 control1, Vec2 control2, Vec2 p);

    // Closes the last contour and hands over all contours with at least one curve.
    std::vector<Contour> finish();

private:
    void ensure_open();
    void add(const Quad& q);
    void close_contour();
    Vec2 scaled(Vec2 p) const { return options_.scale * p; }

    OutlineOptions options_;
    OutlineCounters& counters_;
    std::vector<Contour> contours_;
    Contour current_;
    Vec2 start_{};
    Vec2 pen_{};
    bool open_ = false;
};

// Walks a FreeType outline through `builder`. Returns false with `error` set when FreeType
// rejects the outline.
bool decompose_outline(const FT_Outline_& outline, OutlineBuilder& builder, std::string& error);

// "FreeType error N (its text)", for the baker's messages.
std::string freetype_error(int error);

}  // namespace crisp
