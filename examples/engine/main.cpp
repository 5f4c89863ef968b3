// crisp-engine-example: crisp inside a small engine that owns its Vulkan device (docs/integration.md).
#include "app.hpp"
#include "device.hpp"
#include "options.hpp"
#include "png_writer.hpp"
#include "report.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace engine;

// crisp bakes the font's outlines at start-up (an engine would ship a .crisp asset made offline by
// crisp-bake and load it with crisp::load_asset_file): only the characters the example shows.
std::optional<crisp::Font> load_font(const char* option, const std::string& path, std::vector<uint32_t> codepoints,
                                     crisp::FontId id) {
    crisp::BakeOptions options;
    options.all_glyphs = false;
    options.codepoints = std::move(codepoints);
    options.allow_failed = true;
    crisp::Result<crisp::BakeResult> baked = crisp::bake_font_file(path, options);
    if (!baked) {
        std::fprintf(stderr, "crisp-engine-example: %s %s: %s\n", option, path.c_str(), baked.error().message.c_str());
        return std::nullopt;
    }
    crisp::Result<crisp::Font> font = crisp::Font::create(std::move(baked->asset), id);
    if (!font) {
        std::fprintf(stderr, "crisp-engine-example: %s %s: %s\n", option, path.c_str(), font.error().message.c_str());
        return std::nullopt;
    }
    return std::move(*font);
}

// The text font (printable ASCII, Latin-1, combining marks and Arabic, for what the text field shows and
// what may be typed into it), then the emoji font where there is one: the layouts' fallback chain,
// in which emoji presentation picks the colour font.
std::optional<std::vector<crisp::Font>> load_fonts(const Options& options) {
    std::vector<uint32_t> text;
    for (uint32_t c = 0x20; c < 0x7F; ++c) text.push_back(c);
    for (uint32_t c = 0xA0; c <= 0xFF; ++c) text.push_back(c);    // Latin-1, the multiplication sign among them
    for (uint32_t c = 0x300; c <= 0x36F; ++c) text.push_back(c);  // combining marks, for "e" + U+0301 and the like
    for (uint32_t c = 0x600; c <= 0x6FF; ++c) text.push_back(c);  // Arabic; its joining forms come with the closure
    std::optional<crisp::Font> font = load_font("--font", options.font, std::move(text), 1);
    if (!font) return std::nullopt;
    std::vector<crisp::Font> fonts;
    fonts.push_back(std::move(*font));
    if (!options.emoji_font_given && !std::filesystem::exists(options.emoji_font)) return fonts;
    std::optional<crisp::Font> emoji = load_font("--emoji-font", options.emoji_font, {kHudEmoji}, 2);
    if (!emoji) return std::nullopt;
    fonts.push_back(std::move(*emoji));
    return fonts;
}

// The window's life. Every Vulkan object is gone when it returns, so that the validation layer's
// count includes the teardown.
int run(const Options& options, std::vector<crisp::Font> fonts, std::atomic<uint32_t>& messages, RunReport& report,
        const SnapshotWriter& snapshot) {
    DeviceOptions device_options;
    device_options.width = options.width;
    device_options.height = options.height;
    device_options.validation = options.validation;
    device_options.message_count = &messages;
    crisp::Result<std::unique_ptr<Device>> device = Device::create(device_options);
    if (!device) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", device.error().message.c_str());
        return kExitVulkan;
    }
    crisp::Result<std::unique_ptr<App>> app = App::create(**device, std::move(fonts), options.caret_blink_ms);
    if (!app) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", app.error().message.c_str());
        return kExitVulkan;
    }
    const crisp::Status status = (*app)->run(options, snapshot);
    report = (*app)->report();
    if (!status) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", status.error().message.c_str());
        return kExitVulkan;
    }
    return kExitOk;
}

// The screenshot and the report, each where a path is given; the options named in the messages
// are those that asked for them.
struct Outputs {
    const char* screenshot_option;
    std::string screenshot;
    const char* report_option;
    std::string report;
};

crisp::Status write_outputs(const Outputs& outputs, const RunReport& report, uint32_t messages) {
    const std::string& screenshot = outputs.screenshot;
    const std::string& report_path = outputs.report;
    if (!screenshot.empty()) {
        if (report.screenshot.empty()) {
            return crisp::Error{crisp::ErrorCode::io, std::string(outputs.screenshot_option) +
                                                          ": the swapchain's images cannot be copied from"};
        }
        if (crisp::Status s = write_png(screenshot, report.extent.width, report.extent.height, report.screenshot); !s)
            return crisp::Error{crisp::ErrorCode::io, std::string(outputs.screenshot_option) + " " + s.error().message};
    }
    if (!report_path.empty()) {
        if (crisp::Status s = write_report(report_path, report, messages); !s)
            return crisp::Error{crisp::ErrorCode::io, std::string(outputs.report_option) + " " + s.error().message};
    }
    return {};
}

}  // namespace

int main(int argc, char** argv) {
    const ParseResult parsed = parse_options(argc, argv, CRISP_ENGINE_EXAMPLE_FONT);
    if (parsed.error) {
        std::fprintf(stderr, "crisp-engine-example: %s (see --help)\n", parsed.error->c_str());
        return kExitUsage;
    }
    const Options& options = parsed.options;
    if (options.help) {
        std::fputs(usage().c_str(), stdout);
        return kExitOk;
    }
    std::optional<std::vector<crisp::Font>> fonts = load_fonts(options);
    if (!fonts) return kExitFont;
    std::atomic<uint32_t> messages{0};
    // A failed snapshot ends the run (App::run returns its error, which run() prints) with kExitOutput.
    bool snapshot_failed = false;
    const SnapshotWriter snapshot = [&](const RunReport& frame, uint32_t number) -> crisp::Status {
        const std::string stem = options.snapshots + "-" + std::to_string(number);
        crisp::Status s =
            write_outputs({"--snapshots", stem + ".png", "--snapshots", stem + ".json"}, frame, messages.load());
        snapshot_failed = !s;
        return s;
    };
    RunReport report;
    const int code = run(options, std::move(*fonts), messages, report, snapshot);
    if (snapshot_failed) return kExitOutput;
    if (code != kExitOk) return code;
    if (crisp::Status s =
            write_outputs({"--screenshot", options.screenshot, "--report", options.report}, report, messages.load());
        !s) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", s.error().message.c_str());
        return kExitOutput;
    }
    if (messages.load() > 0) {
        std::fprintf(stderr, "crisp-engine-example: the validation layer reported %u message(s)\n", messages.load());
        return kExitValidation;
    }
    return kExitOk;
}
