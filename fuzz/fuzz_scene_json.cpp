// Fuzzes the scene file reader: what parses must keep every documented limit.
#include "scene.hpp"

#include <cmath>
#include <cstdint>
#include <string_view>

namespace {

bool in_unit_range(const float (&color)[4]) {
    for (const float c : color) {
        if (!(c >= 0.0f && c <= 1.0f)) return false;
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto scene = crisp::parse_scene(text);
    if (!scene) {
        if (scene.error().code != crisp::ErrorCode::invalid_argument) __builtin_trap();
        if (!std::string_view(scene.error().message).starts_with("scene: ")) __builtin_trap();
        return 0;
    }
    if (scene->fonts.empty() || scene->fonts.size() > crisp::kMaxSceneFonts) __builtin_trap();
    for (const std::string& font : scene->fonts) {
        if (font.empty() || font.find('\0') != std::string::npos) __builtin_trap();
    }
    if (scene->width < 1 || scene->width > crisp::kMaxSceneCanvas) __builtin_trap();
    if (scene->height < 1 || scene->height > crisp::kMaxSceneCanvas) __builtin_trap();
    if (!in_unit_range(scene->background)) __builtin_trap();
    if (scene->layout.empty() || scene->layout.find('\0') != std::string::npos) __builtin_trap();
    if (scene->contrast && !crisp::validate_text_contrast(*scene->contrast)) __builtin_trap();
    for (const crisp::SceneRun& run : scene->runs) {
        if (run.font >= scene->fonts.size()) __builtin_trap();
        if (!(run.size > 0.0f && run.size <= crisp::kMaxSceneTextSize)) __builtin_trap();
        if (!std::isfinite(run.origin_x) || !std::isfinite(run.origin_y)) __builtin_trap();
        if (!in_unit_range(run.color)) __builtin_trap();
        if (!(run.depth >= 0.0f && run.depth <= 1.0f)) __builtin_trap();
        if (run.contrast && !crisp::validate_text_contrast(*run.contrast)) __builtin_trap();
    }
    // The reader is a function of its input.
    auto again = crisp::parse_scene(text);
    if (!again || !(*again == *scene)) __builtin_trap();
    return 0;
}
