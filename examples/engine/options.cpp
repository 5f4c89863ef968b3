#include "options.hpp"

#include <algorithm>
#include <charconv>
#include <functional>
#include <string_view>

namespace engine {
namespace {

// The whole of `text` as an unsigned number, or nullopt.
template <class T>
std::optional<T> parse_unsigned(std::string_view text) {
    T value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
    return value;
}

// "F:AxB" (resize) or "F:N" (minimize): the frame, then one or two numbers.
std::optional<ResizeAt> parse_resize(std::string_view text) {
    const size_t colon = text.find(':'), x = text.find('x', colon);
    if (colon == std::string_view::npos || x == std::string_view::npos) return std::nullopt;
    const auto frame = parse_unsigned<uint64_t>(text.substr(0, colon));
    const auto width = parse_unsigned<uint32_t>(text.substr(colon + 1, x - colon - 1));
    const auto height = parse_unsigned<uint32_t>(text.substr(x + 1));
    if (!frame || !width || !height || *width < 64 || *height < 64 || *width > 8192 || *height > 8192)
        return std::nullopt;
    return ResizeAt{*frame, *width, *height};
}

std::optional<MinimizeAt> parse_minimize(std::string_view text) {
    const size_t colon = text.find(':');
    if (colon == std::string_view::npos) return std::nullopt;
    const auto frame = parse_unsigned<uint64_t>(text.substr(0, colon));
    const auto polls = parse_unsigned<uint32_t>(text.substr(colon + 1));
    if (!frame || !polls || *polls == 0) return std::nullopt;
    return MinimizeAt{*frame, *polls};
}

struct OptionSpec {
    const char* name;
    const char* value;  // nullptr: a flag
    const char* help;
    // Applies the value; false when it is malformed.
    std::function<bool(Options&, std::string_view)> apply;
};

const std::vector<OptionSpec>& option_table() {
    static const std::vector<OptionSpec> table = {
        {"--frames", "N", "exit after N presented frames (default: when the window closes)",
         [](Options& o, std::string_view v) { return (o.frames = parse_unsigned<uint64_t>(v).value_or(0)) > 0; }},
        {"--size", "WxH", "the window's initial size in pixels (default 960x540)",
         [](Options& o, std::string_view v) {
             const std::optional<ResizeAt> size = parse_resize("0:" + std::string(v));
             if (size) o.width = size->width, o.height = size->height;
             return size.has_value();
         }},
        {"--screenshot", "PATH.png", "write the last presented frame as a PNG (needs --frames)",
         [](Options& o, std::string_view v) { return !(o.screenshot = v).empty(); }},
        {"--report", "PATH.json",
         "write what happened (frames, drops, resizes), where text was drawn and the last frame's glyphs",
         [](Options& o, std::string_view v) { return !(o.report = v).empty(); }},
        {"--font", "PATH", "the font for all text (TrueType/OpenType; default: crisp's DejaVu Sans)",
         [](Options& o, std::string_view v) { return !(o.font = v).empty(); }},
        {"--emoji-font", "PATH",
         "a colour font (COLR or bitmap emoji) for the emoji in the HUD's title (default: Noto Color Emoji, "
         "/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf, where that file exists; without it the title has no "
         "emoji)",
         [](Options& o, std::string_view v) {
             o.emoji_font_given = true;
             return !(o.emoji_font = v).empty();
         }},
        {"--validation", nullptr,
         "VK_LAYER_KHRONOS_validation with synchronization validation; any warning or error it reports makes the "
         "exit code 4",
         [](Options& o, std::string_view) { return o.validation = true; }},
        {"--drop-every", "N", "record every Nth frame, then abandon it instead of submitting it (N >= 2)",
         [](Options& o, std::string_view v) { return (o.drop_every = parse_unsigned<uint32_t>(v).value_or(0)) >= 2; }},
        {"--resize-at", "F:WxH", "resize the window to W x H before presented frame F (repeatable)",
         [](Options& o, std::string_view v) {
             const std::optional<ResizeAt> resize = parse_resize(v);
             if (resize) o.resizes.push_back(*resize);
             return resize.has_value();
         }},
        {"--minimize-at", "F:N",
         "minimize the window before presented frame F and restore it after N polls of 10 ms (repeatable; "
         "without a window manager, as under Xvfb, the example treats the window as minimized for those polls)",
         [](Options& o, std::string_view v) {
             const std::optional<MinimizeAt> minimize = parse_minimize(v);
             if (minimize) o.minimizes.push_back(*minimize);
             return minimize.has_value();
         }},
        {"--caret-blink", "MS",
         "the text field's caret is shown MS milliseconds, then hidden as long (default 530, at most 60000; 0: never "
         "hidden)",
         [](Options& o, std::string_view v) {
             const std::optional<uint32_t> ms = parse_unsigned<uint32_t>(v);
             if (ms) o.caret_blink_ms = *ms;
             return ms.has_value() && *ms <= 60000;
         }},
        {"--snapshots", "PREFIX",
         "F9 writes the next presented frame as PREFIX-N.png and its report as PREFIX-N.json, N = 1, 2, ... "
         "(for scripted input: each snapshot follows every event before the key)",
         [](Options& o, std::string_view v) { return !(o.snapshots = v).empty(); }},
        {"--help", nullptr, "this text", [](Options& o, std::string_view) { return o.help = true; }},
    };
    return table;
}

}  // namespace

std::string usage() {
    std::string text =
        "Usage: crisp-engine-example [options]\n\n"
        "A small engine that draws a lit 3D scene with its own Vulkan device and puts crisp's text in it:\n"
        "labels that follow the shapes, a HUD with a paragraph, a frame counter and a scrolling list, a\n"
        "label below the HUD that turns every frame, a sign in perspective on a face of the cube, and a\n"
        "text field of Latin and Arabic text under the HUD.\n\n"
        "Options:\n";
    for (const OptionSpec& option : option_table()) {
        std::string left = std::string("  ") + option.name + (option.value ? std::string(" ") + option.value : "");
        left.resize(std::max<size_t>(left.size() + 2, 24), ' ');
        text += left + option.help + "\n";
    }
    text +=
        "\nKeys: Ctrl+Q closes the window; F9 takes a snapshot (--snapshots). The text field: a click in it\n"
        "gives it the focus and places the caret, a drag selects, Shift+click extends the selection, a click\n"
        "outside or Escape takes the focus away. With the focus: typing replaces the selection, Backspace and\n"
        "Delete remove a grapheme, Left and Right move on screen (Ctrl: by word), Home and End go to the\n"
        "line's ends, Shift extends the selection with any motion, Ctrl+A selects all.\n";
    text +=
        "\nExit codes: 0 success; 1 bad command line; 2 the font could not be loaded; 3 no window, no suitable\n"
        "Vulkan device or a Vulkan failure; 4 the validation layer reported a message; 5 the screenshot or\n"
        "report could not be written.\n";
    return text;
}

ParseResult parse_options(int argc, const char* const* argv, const std::string& default_font) {
    ParseResult result;
    result.options.font = default_font;
    result.options.emoji_font = kDefaultEmojiFont;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        const OptionSpec* spec = nullptr;
        for (const OptionSpec& option : option_table()) {
            if (arg == option.name) spec = &option;
        }
        if (!spec) {
            result.error = "unknown argument " + std::string(arg);
            return result;
        }
        std::string_view value;
        if (spec->value) {
            if (i + 1 >= argc) {
                result.error = std::string(arg) + " needs a value (" + spec->value + ")";
                return result;
            }
            value = argv[++i];
        }
        if (!spec->apply(result.options, value)) {
            result.error = std::string(arg) + " " + std::string(value) + ": expected " + spec->value;
            return result;
        }
    }
    if (!result.options.screenshot.empty() && result.options.frames == 0)
        result.error = "--screenshot needs --frames N";
    return result;
}

}  // namespace engine
