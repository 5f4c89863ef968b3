// crisp-engine-example's command line: one table gives both --help and the parsing.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace engine {

// Exit codes (also in --help).
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 1;
inline constexpr int kExitFont = 2;
inline constexpr int kExitVulkan = 3;
inline constexpr int kExitValidation = 4;
inline constexpr int kExitOutput = 5;

struct ResizeAt {
    uint64_t frame = 0;  // before presented frame `frame` (0-based) is drawn
    uint32_t width = 0;
    uint32_t height = 0;
};

struct MinimizeAt {
    uint64_t frame = 0;
    uint32_t polls = 0;  // event polls (10 ms each) before the window is restored
};

struct Options {
    uint64_t frames = 0;  // presented frames before exiting; 0: until the window closes
    uint32_t width = 960;
    uint32_t height = 540;
    std::string screenshot;  // PNG of the last presented frame
    std::string report;      // JSON: what happened, and where text was drawn
    std::string font;
    std::string emoji_font;         // a colour font for the HUD's emoji
    bool emoji_font_given = false;  // --emoji-font: a font that cannot be loaded is an error
    bool validation = false;
    uint32_t drop_every = 0;  // every Nth frame is recorded, then abandoned
    std::vector<ResizeAt> resizes;
    std::vector<MinimizeAt> minimizes;
    uint32_t caret_blink_ms = 530;  // the text field's caret: on this long, off this long; 0: steady
    std::string snapshots;          // F9 writes PREFIX-N.json and PREFIX-N.png of the next frame
    bool help = false;
};

// The emoji font unless --emoji-font is given: Debian's fonts-noto-color-emoji, used where installed.
inline constexpr const char* kDefaultEmojiFont = "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf";

// The parsed command line, or a message for a person (the caller prints it and exits kExitUsage).
// `default_font` is used unless --font is given.
struct ParseResult {
    Options options;
    std::optional<std::string> error;
};
ParseResult parse_options(int argc, const char* const* argv, const std::string& default_font);

// The --help text.
std::string usage();

}  // namespace engine
