// crisp-layout-editor: the CPU-drawn part of each frame (panels, widgets, the magnified views),
// 8-bit sRGB-encoded RGBA, top row first. crisp composites the text over it on the GPU.
// Drawing is in interface pixels: `scale` window pixels each (the window's content scale, or
// less in a window smaller than the interface needs).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

namespace crisp::editor {

struct Color {
    uint8_t r = 0, g = 0, b = 0;
    friend bool operator==(const Color&, const Color&) = default;
};

struct Rect {
    float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
    bool contains(float px, float py) const { return px >= x && py >= y && px < x + width && py < y + height; }
};

// Draws into memory it does not own (the mapped upload buffer).
class Canvas {
public:
    Canvas(std::span<uint8_t> rgba, uint32_t width, uint32_t height, float scale = 1.0f)
        : rgba_(rgba), width_(width), height_(height), scale_(scale) {}
    // Window pixels.
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }

    void clear(Color color) {
        fill({0, 0, static_cast<float>(width_) / scale_, static_cast<float>(height_) / scale_}, color);
    }

    // Pixels whose centre lies in `rect` take `color`.
    void fill(const Rect& rect, Color color) {
        each_pixel(rect, [&](uint8_t* p) {
            p[0] = color.r;
            p[1] = color.g;
            p[2] = color.b;
            p[3] = 255;
        });
    }

    // Adds `color` scaled by `weight` (0..1) to the pixels in `rect`, saturating: overlapping
    // red, green and blue light adds up to white, as on a screen.
    void add(const Rect& rect, Color color, float weight) {
        const float w = std::clamp(weight, 0.0f, 1.0f);
        each_pixel(rect, [&](uint8_t* p) {
            p[0] = saturate(p[0] + static_cast<float>(color.r) * w);
            p[1] = saturate(p[1] + static_cast<float>(color.g) * w);
            p[2] = saturate(p[2] + static_cast<float>(color.b) * w);
        });
    }

    // A frame `thickness` pixels wide just inside `rect`, at least one window pixel.
    void outline(const Rect& rect, Color color, float thickness = 1.0f) {
        thickness = std::max(thickness, 1.0f / scale_);
        fill({rect.x, rect.y, rect.width, thickness}, color);
        fill({rect.x, rect.y + rect.height - thickness, rect.width, thickness}, color);
        fill({rect.x, rect.y, thickness, rect.height}, color);
        fill({rect.x + rect.width - thickness, rect.y, thickness, rect.height}, color);
    }

private:
    static uint8_t saturate(float value) { return static_cast<uint8_t>(std::min(255.0f, value + 0.5f)); }

    template <class F>
    void each_pixel(const Rect& rect, F&& f) {
        const auto first = [](float v, uint32_t limit) {
            return static_cast<uint32_t>(std::clamp(std::ceil(v - 0.5f), 0.0f, static_cast<float>(limit)));
        };
        const float s = scale_;
        const uint32_t x0 = first(rect.x * s, width_), x1 = first((rect.x + rect.width) * s, width_);
        const uint32_t y0 = first(rect.y * s, height_), y1 = first((rect.y + rect.height) * s, height_);
        for (uint32_t y = y0; y < y1; ++y) {
            uint8_t* row = rgba_.data() + (size_t{y} * width_ + x0) * 4;
            for (uint32_t x = x0; x < x1; ++x, row += 4) f(row);
        }
    }

    std::span<uint8_t> rgba_;
    uint32_t width_ = 0;
    uint32_t height_ = 0;
    float scale_ = 1.0f;
};

}  // namespace crisp::editor
