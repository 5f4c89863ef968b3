// Shared by the tests: where the fonts are, and reading files.
#pragma once

#include "harness.hpp"
#include "headless_context.hpp"
#include "core/utf8.hpp"

#include <crisp/bake.hpp>
#include <crisp/font.hpp>
#include <crisp/layout.hpp>
#include <crisp/renderer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace crisp::test {

using harness::Texel;

inline std::string source_path(const std::string& relative) {
    return std::string(CRISP_SOURCE_DIR) + "/" + relative;
}

inline const std::string kDejaVuSans = source_path("fonts/DejaVuSans.ttf");          // TrueType, 2048 upem
inline const std::string kInterCff = source_path("fonts/Inter-Regular.otf");         // CFF
inline const std::string kInterVariable = source_path("fonts/Inter-roman.var.ttf");  // gvar: wght, opsz
// From Debian packages that scripts/setup.sh installs.
inline const std::string kNotoCjk = "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc";       // CFF collection
inline const std::string kCantarell = "/usr/share/fonts/opentype/cantarell/Cantarell-Regular.otf";  // CFF, 1000 upem

// The key of `glyph` at `pixels` px per em and a subpixel offset (1/256 px).
inline GlyphKey key_at(uint32_t glyph, uint32_t pixels, uint8_t subpixel_x, uint8_t subpixel_y) {
    GlyphKey key;
    key.glyph = glyph;
    key.size_x = key.size_y = pixels * kSizeOne;
    key.subpixel_x = subpixel_x;
    key.subpixel_y = subpixel_y;
    return key;
}

// DejaVu Sans baked with only the glyphs of `text`, as FontId `id`; null when baking fails (the
// test's own checks then fail).
inline std::unique_ptr<Font> bake_test_font(std::string_view text, FontId id = 1) {
    BakeOptions bake;
    bake.all_glyphs = false;
    bake.codepoints = decode_utf8(text);
    auto baked = bake_font_file(kDejaVuSans, bake);
    if (!baked) return nullptr;
    auto font = Font::create(std::move(baked->asset), id);
    return font ? std::make_unique<Font>(std::move(*font)) : nullptr;
}

// The font at `path` baked with the glyphs of `codepoints` (all of them when empty), as FontId `id`;
// null, with a failure of the test naming the path, when baking or loading fails.
inline std::unique_ptr<Font> bake_font_or_fail(const std::string& path, FontId id, std::vector<uint32_t> codepoints) {
    BakeOptions options;
    options.all_glyphs = codepoints.empty();
    options.codepoints = std::move(codepoints);
    Result<BakeResult> baked = bake_font_file(path, options);
    if (!baked) {
        ADD_FAILURE() << path << ": " << baked.error().message;
        return nullptr;
    }
    Result<Font> font = Font::create(std::move(baked.value().asset), id);
    if (!font) {
        ADD_FAILURE() << path << ": " << font.error().message;
        return nullptr;
    }
    return std::make_unique<Font>(std::move(font).value());
}

// `text` laid out with `fonts`; where that fails, a failure of the test (with the message) and an
// empty layout.
inline TextLayout layout_or_fail(const std::vector<const Font*>& fonts, std::string_view text,
                                 const TextStyle& style = {}, const LayoutOptions& options = {}) {
    Result<TextLayout> layout = layout_text(fonts, text, style, options);
    if (!layout) {
        ADD_FAILURE() << layout.error().message;
        return {};
    }
    return std::move(layout).value();
}

// A context with the validation layer on whose device was created with what crisp's renderer and
// tile path need (add_crisp_features(), as an engine would), or options.crisp_needs where given:
// crisp checks the device as created.
inline Result<HeadlessContext> create_renderer_context(HeadlessContextOptions options = {}) {
    options.validation = true;
    if (!options.crisp_needs) options.crisp_needs = CrispFeatureNeeds{};
    return HeadlessContext::create(options);
}

// What the GPU tests of one test file share, made once on first use: a context and a font.
struct GpuFixture {
    std::unique_ptr<HeadlessContext> context;  // null when no device qualifies (the tests then fail)
    std::unique_ptr<Font> font;                // null when no text was asked for
};

// A GpuFixture: a context with the validation layer on (and its synchronization validation when
// asked for) whose device has what `needs` asks of crisp, and DejaVu Sans with `text`'s glyphs.
inline GpuFixture make_gpu_fixture(const CrispFeatureNeeds& needs, bool synchronization_validation,
                                   std::string_view text) {
    GpuFixture made;
    HeadlessContextOptions options;
    options.synchronization_validation = synchronization_validation;
    options.crisp_needs = needs;
    auto context = create_renderer_context(options);
    if (context) {
        made.context = std::make_unique<HeadlessContext>(std::move(*context));
    } else {
        ADD_FAILURE() << "no Vulkan device for the tests: " << context.error().message;
    }
    if (!text.empty()) made.font = bake_test_font(text);
    return made;
}

// The harness tools use too (support/harness.hpp).
using harness::read_atlas;
using harness::render_until_converged;

inline std::vector<std::byte> read_file(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    std::vector<char> chars((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::vector<std::byte> bytes(chars.size());
    for (size_t i = 0; i < chars.size(); ++i) bytes[i] = static_cast<std::byte>(chars[i]);
    return bytes;
}

// A fresh directory under the system temporary directory, removed with everything in it.
class TemporaryDirectory {
public:
    TemporaryDirectory() {
        std::string pattern = (std::filesystem::temp_directory_path() / "crisp-test-XXXXXX").string();
        if (::mkdtemp(pattern.data()) != nullptr) path_ = pattern;
    }
    ~TemporaryDirectory() {
        std::error_code ignored;
        if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
    }
    TemporaryDirectory(const TemporaryDirectory&) = delete;
    TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

    const std::filesystem::path& path() const { return path_; }

    // Every name in the directory, hidden ones (temporaries) included, sorted.
    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& entry : std::filesystem::directory_iterator(path_))
            names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

private:
    std::filesystem::path path_;
};

// A pool of resettable command buffers on `context`'s queue family (destroying it frees them), and
// `count` primary buffers from it; false when a call fails.
inline bool create_command_buffers(const HeadlessContext& context, VkCommandPool& pool, VkCommandBuffer* buffers,
                                   uint32_t count) {
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = context.queue_family();
    if (vkCreateCommandPool(context.device(), &pool_info, nullptr, &pool) != VK_SUCCESS) return false;
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = count;
    return vkAllocateCommandBuffers(context.device(), &allocate, buffers) == VK_SUCCESS;
}

// A command buffer from a pool of its own, for frames a test records and never submits (dropped
// frames). record() begins it, runs `commands`, ends it; drop() resets it for the next frame.
class UnsubmittedCommandBuffer {
public:
    explicit UnsubmittedCommandBuffer(const HeadlessContext& context) : device_(context.device()) {
        ok_ = create_command_buffers(context, pool_, &buffer_, 1);
    }
    UnsubmittedCommandBuffer(const UnsubmittedCommandBuffer&) = delete;
    UnsubmittedCommandBuffer& operator=(const UnsubmittedCommandBuffer&) = delete;
    ~UnsubmittedCommandBuffer() {
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);  // frees the buffer
    }
    bool ok() const { return ok_; }

    // True when every call succeeded.
    template <typename Commands>
    bool record_and_drop(Commands&& commands) {
        VkCommandBufferBeginInfo begin{};
        begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        if (vkBeginCommandBuffer(buffer_, &begin) != VK_SUCCESS) return false;
        commands(buffer_);
        const bool ended = vkEndCommandBuffer(buffer_) == VK_SUCCESS;
        return vkResetCommandBuffer(buffer_, 0) == VK_SUCCESS && ended;
    }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer buffer_ = VK_NULL_HANDLE;
    bool ok_ = false;
};

}  // namespace crisp::test
