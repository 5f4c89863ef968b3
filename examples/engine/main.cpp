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
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace engine;

// crisp bakes the font's outlines at start-up (an engine would ship a .crisp asset made offline by
// crisp-bake and load it with crisp::load_asset_file): printable ASCII and the few other
// characters the example shows.
std::optional<crisp::Font> load_font(const std::string& path) {
    crisp::BakeOptions options;
    options.all_glyphs = false;
    for (uint32_t c = 0x20; c < 0x7F; ++c) options.codepoints.push_back(c);
    options.codepoints.push_back(0x00D7);  // multiplication sign
    options.allow_failed = true;
    crisp::Result<crisp::BakeResult> baked = crisp::bake_font_file(path, options);
    if (!baked) {
        std::fprintf(stderr, "crisp-engine-example: --font %s: %s\n", path.c_str(), baked.error().message.c_str());
        return std::nullopt;
    }
    crisp::Result<crisp::Font> font = crisp::Font::create(std::move(baked->asset), 1);
    if (!font) {
        std::fprintf(stderr, "crisp-engine-example: --font %s: %s\n", path.c_str(), font.error().message.c_str());
        return std::nullopt;
    }
    return std::move(*font);
}

// The window's life. Every Vulkan object is gone when it returns, so that the validation layer's
// count includes the teardown.
int run(const Options& options, crisp::Font font, std::atomic<uint32_t>& messages, RunReport& report) {
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
    crisp::Result<std::unique_ptr<App>> app = App::create(**device, std::move(font));
    if (!app) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", app.error().message.c_str());
        return kExitVulkan;
    }
    const crisp::Status status = (*app)->run(options);
    report = (*app)->report();
    if (!status) {
        std::fprintf(stderr, "crisp-engine-example: %s\n", status.error().message.c_str());
        return kExitVulkan;
    }
    return kExitOk;
}

int write_outputs(const Options& options, const RunReport& report, uint32_t messages) {
    if (!options.screenshot.empty()) {
        if (report.screenshot.empty()) {
            std::fprintf(stderr, "crisp-engine-example: --screenshot: the swapchain's images cannot be copied from\n");
            return kExitOutput;
        }
        if (crisp::Status s =
                write_png(options.screenshot, report.extent.width, report.extent.height, report.screenshot);
            !s) {
            std::fprintf(stderr, "crisp-engine-example: --screenshot %s\n", s.error().message.c_str());
            return kExitOutput;
        }
    }
    if (!options.report.empty()) {
        if (crisp::Status s = write_report(options.report, report, messages); !s) {
            std::fprintf(stderr, "crisp-engine-example: --report %s\n", s.error().message.c_str());
            return kExitOutput;
        }
    }
    return kExitOk;
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
    std::optional<crisp::Font> font = load_font(options.font);
    if (!font) return kExitFont;
    std::atomic<uint32_t> messages{0};
    RunReport report;
    const int code = run(options, std::move(*font), messages, report);
    if (code != kExitOk) return code;
    if (const int written = write_outputs(options, report, messages.load()); written != kExitOk) return written;
    if (messages.load() > 0) {
        std::fprintf(stderr, "crisp-engine-example: the validation layer reported %u message(s)\n", messages.load());
        return kExitValidation;
    }
    return kExitOk;
}
