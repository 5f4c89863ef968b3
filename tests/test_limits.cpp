// Bounded inputs and safe outputs (docs/limits.md): reads only of regular files within a limit,
// writes that refuse to replace what is not a regular file or is an input, and font containers
// the baker refuses up front with what to do instead.
#include "core/file_io.hpp"
#include "core/limits.hpp"
#include "output_files.hpp"
#include "scene.hpp"
#include "test_support.hpp"

#include <crisp/asset.hpp>
#include <crisp/bake.hpp>
#include <crisp/layout.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <string>
#include <utility>
#include <vector>

#include <climits>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace crisp {
namespace {

namespace fs = std::filesystem;
using test::TemporaryDirectory;

std::vector<std::byte> bytes_of(std::string_view text) {
    std::vector<std::byte> out(text.size());
    for (size_t i = 0; i < text.size(); ++i) out[i] = static_cast<std::byte>(text[i]);
    return out;
}

TEST(Limits, ReadsOnlyRegularFiles) {
    TemporaryDirectory directory;
    ASSERT_FALSE(directory.path().empty());
    const fs::path fifo = directory.path() / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    // A FIFO with no writer would block a reader forever: it is refused before it is opened for
    // reading... and /dev/zero, which never ends, before a byte is read.
    for (const fs::path& path : {fs::path("/dev/zero"), directory.path()}) {
        auto read = read_file(path, limits::kFontFileBytes);
        ASSERT_FALSE(read) << path;
        EXPECT_EQ(read.error().code, ErrorCode::io);
    }
    EXPECT_NE(read_file("/dev/zero", limits::kFontFileBytes).error().message.find("not a regular file"),
              std::string::npos);
    auto asset = load_asset_file("/dev/zero");
    ASSERT_FALSE(asset);
    EXPECT_NE(asset.error().message.find("not a regular file"), std::string::npos);
}

TEST(Limits, ReadsNoMoreThanTheLimit) {
    TemporaryDirectory directory;
    const fs::path file = directory.path() / "big.bin";
    ASSERT_TRUE(write_file_atomically(file, std::vector<std::byte>(2048, std::byte{7})));
    auto refused = read_file(file, 2047);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("2047 bytes allowed"), std::string::npos);
    auto read = read_file(file, 2048);
    ASSERT_TRUE(read);
    EXPECT_EQ(read->size(), 2048u);
}

TEST(Limits, WritesNeverReplaceWhatIsNotARegularFile) {
    TemporaryDirectory directory;
    const fs::path fifo = directory.path() / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const fs::path folder = directory.path() / "folder";
    fs::create_directory(folder);
    for (const fs::path& target : {fifo, folder}) {
        const Status written = write_file_atomically(target, bytes_of("x"));
        ASSERT_FALSE(written) << target;
        EXPECT_NE(written.error().message.find("not a regular file"), std::string::npos);
    }
    EXPECT_TRUE(fs::is_fifo(fifo));
    EXPECT_TRUE(fs::is_directory(folder));
    EXPECT_EQ(directory.entries(), (std::vector<std::string>{"fifo", "folder"}));  // no temporary left
    // The same checks, before any work: and the input itself, under any of its names.
    const fs::path input = directory.path() / "font.ttf";
    ASSERT_TRUE(write_file_atomically(input, bytes_of("font")));
    const fs::path link = directory.path() / "link.ttf";
    fs::create_symlink(input, link);
    const fs::path inputs[] = {input};
    EXPECT_FALSE(check_output_path(input, inputs));
    EXPECT_FALSE(check_output_path(link, inputs));
    EXPECT_FALSE(check_output_path(directory.path() / "missing" / "out.crisp", inputs));
    EXPECT_FALSE(check_output_path(fifo, inputs));
    EXPECT_TRUE(check_output_path(directory.path() / "out.crisp", inputs));
    EXPECT_TRUE(check_output_path("/dev/null").error().message.find("not a regular file") != std::string::npos);
}

TEST(Limits, FontContainersThatCannotBeShapedAreRefusedUpFront) {
    const std::pair<const char*, const char*> cases[] = {
        {"wOFF\x00\x01\x00\x00", "decompress"},
        {"wOF2\x00\x01\x00\x00", "woff2_decompress"},
        {"\x80\x01\x10\x00\x00\x00%!PS-AdobeFont-1.0", "Type 1"},
        {"%!PS-AdobeFont-1.0: Test 001", "Type 1"},
        {"%!FontType1-1.0: Test", "Type 1"},
    };
    for (const auto& [magic, advice] : cases) {
        std::vector<std::byte> bytes =
            bytes_of(std::string_view(magic, std::string_view(magic).size() + (magic[0] == 'w' ? 4 : 0)));
        bytes.resize(bytes.size() + 64);
        auto baked = bake_font(bytes, BakeOptions{});
        ASSERT_FALSE(baked) << magic;
        EXPECT_EQ(baked.error().code, ErrorCode::font_unsupported) << magic;
        EXPECT_NE(baked.error().message.find(advice), std::string::npos) << baked.error().message;
    }
    // A real TrueType font passes the check.
    EXPECT_TRUE(check_font_container(test::read_file(test::kDejaVuSans)));
}

// Curves per glyph are bounded in the baker and the loader alike: a glyph's cost in every sample
// grows with them.
TEST(Limits, CurvesPerGlyphAreBoundedInTheBakerAndTheLoader) {
    BakeOptions options;
    EXPECT_EQ(options.max_curves_per_glyph, kMaxCurvesPerGlyph);
    options.max_curves_per_glyph = kMaxCurvesPerGlyph + 1;
    const std::vector<std::byte> font = test::read_file(test::kDejaVuSans);
    auto refused = bake_font(font, options);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument);

    options = BakeOptions{};
    options.all_glyphs = false;
    options.codepoints = {'a'};
    auto baked = bake_font(font, options);
    ASSERT_TRUE(baked) << baked.error().message;
    FontAsset asset = baked->asset;
    ASSERT_TRUE(validate_asset(asset));
    for (GlyphRecord& glyph : asset.glyphs) {
        if (glyph.curve_count == 0) continue;
        glyph.curve_count = 2 * kMaxCurvesPerGlyph + 1;
        break;
    }
    const Status invalid = validate_asset(asset);
    ASSERT_FALSE(invalid);
    EXPECT_NE(invalid.error().message.find("curve slots, at most"), std::string::npos) << invalid.error().message;
}

// Runs per scene and bytes of text per layout are bounded, each refusal naming its limit.
TEST(Limits, ScenesAndTextAreBounded) {
    std::string json = R"({"fonts": ["a.crisp"], "canvas": [8, 8], "runs": [)";
    for (uint32_t i = 0; i <= kMaxSceneRuns; ++i) {
        json += i ? "," : "";
        json += R"({"text": "a", "size": 8, "origin": [0, 8]})";
    }
    json += "]}";
    auto scene = parse_scene(json);
    ASSERT_FALSE(scene);
    EXPECT_NE(scene.error().message.find("at most 65536 runs"), std::string::npos) << scene.error().message;

    auto font = test::bake_test_font("a");
    ASSERT_TRUE(font);
    const Font* fonts[] = {font.get()};
    const std::string text(kMaxTextBytes + 1, 'a');
    auto laid = layout_text(fonts, text, TextStyle{}, LayoutOptions{});
    ASSERT_FALSE(laid);
    EXPECT_EQ(laid.error().code, ErrorCode::invalid_argument);
}

// 'a' and 100,000 combining acutes took 21 s to shape (HarfBuzz is quadratic in a cluster's marks):
// past kMaxMarksPerCluster a new run starts, so it takes linear time, and every mark is kept.
TEST(Limits, LongClustersOfMarksAreShapedInRunsOfBoundedLength) {
    auto font = test::bake_test_font("a\u0301");
    ASSERT_TRUE(font);
    const Font* fonts[] = {font.get()};
    const uint32_t marks = 100000;
    std::string text = "a";
    for (uint32_t i = 0; i < marks; ++i) text += "\u0301";
    LayoutOptions options;
    options.keep_blank_glyphs = true;
    const auto start = std::chrono::steady_clock::now();
    auto laid = layout_text(fonts, text, TextStyle{}, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(laid) << laid.error().message;
    EXPECT_EQ(laid->mark_splits, marks / kMaxMarksPerCluster);  // (marks + 1 - 1) / K runs past the first
    EXPECT_EQ(laid->shaped_glyphs, marks + 1);
    std::printf("100,000 marks laid out in %.3f s\n", seconds);  // not asserted: a test holds no timing
    // Marks within the limit stay one cluster, uncut.
    auto few = layout_text(fonts, "a\u0301\u0301\u0301", TextStyle{}, options);
    ASSERT_TRUE(few);
    EXPECT_EQ(few->mark_splits, 0u);
}

// An output written in pieces (crisp-render's coverage PFM, band by band) lands whole, and a writer
// that fails part way replaces nothing and leaves no temporary.
TEST(Limits, OutputsWrittenInPiecesLandWholeOrNotAtAll) {
    TemporaryDirectory directory;
    const fs::path out = directory.path() / "out.pfm";
    ASSERT_TRUE(write_file_atomically(out, bytes_of("old")));
    auto pieces = [](int count, bool fail_after) -> OutputWriter {
        return [=](const std::function<Status(std::span<const std::byte>)>& put) -> Status {
            for (int i = 0; i < count; ++i) {
                const std::vector<std::byte> piece = bytes_of("piece" + std::to_string(i) + ";");
                if (Status s = put(piece); !s) return s;
            }
            if (fail_after) return Error{ErrorCode::io, "the writer failed"};
            return {};
        };
    };
    const OutputFile failing[] = {{out, {}, pieces(3, true)}};
    const Status failed = write_files_atomically(failing);
    ASSERT_FALSE(failed);
    EXPECT_NE(failed.error().message.find("the writer failed"), std::string::npos) << failed.error().message;
    EXPECT_EQ(test::read_file(out.string()), bytes_of("old"));
    EXPECT_EQ(directory.entries(), std::vector<std::string>{"out.pfm"});
    const OutputFile written[] = {{out, {}, pieces(3, false)}};
    ASSERT_TRUE(write_files_atomically(written));
    EXPECT_EQ(test::read_file(out.string()), bytes_of("piece0;piece1;piece2;"));
}

// A run's outputs are put in place together: when one cannot be written, none is replaced, and no
// temporary is left; no file is ever removed for its name (a killed writer's temporaries stay).
TEST(Limits, OutputsAreReplacedTogetherOrNotAtAll) {
    TemporaryDirectory directory;
    const fs::path png = directory.path() / "out.png";
    const fs::path pfm = directory.path() / "out.pfm";
    ASSERT_TRUE(write_file_atomically(png, bytes_of("old png")));
    const std::vector<std::byte> new_png = bytes_of("new png"), new_pfm = bytes_of("new pfm");
    const OutputFile refused[] = {{png, new_png, {}}, {directory.path() / "missing" / "out.pfm", new_pfm, {}}};
    EXPECT_FALSE(write_files_atomically(refused));
    EXPECT_EQ(test::read_file(png.string()), bytes_of("old png"));
    EXPECT_EQ(directory.entries(), std::vector<std::string>{"out.png"});
    const OutputFile both[] = {{png, new_png, {}}, {pfm, new_pfm, {}}};
    ASSERT_TRUE(write_files_atomically(both));
    EXPECT_EQ(test::read_file(png.string()), new_png);
    EXPECT_EQ(test::read_file(pfm.string()), new_pfm);

    // A user's files named as temporaries were (`.out.png.tmp-XXXXXX`) and as they are now, two
    // minutes old: no write removes them (a write used to remove the first two).
    const fs::path files[] = {directory.path() / ".out.png.tmp-ABCDEF", directory.path() / ".out.png.tmp-GHIJKL",
                              directory.path() / ".out.png.crisp-tmp-1-ABCDEFGH"};
    for (const fs::path& file : files) {
        ASSERT_TRUE(write_file_atomically(file, bytes_of("x")));
        fs::last_write_time(file, fs::file_time_type::clock::now() - std::chrono::minutes(2));
    }
    ASSERT_TRUE(write_file_atomically(png, new_png));
    for (const fs::path& file : files) EXPECT_TRUE(fs::exists(file)) << file;
    EXPECT_EQ(directory.entries().size(), 5u);
}

// Opening a FIFO for reading waits for a writer: read_file() opens without blocking and refuses it.
// (A read that blocks is unblocked by a writer after 10 s, so that the test fails rather than hangs.)
TEST(Limits, AFifoIsRefusedWithoutWaitingForAWriter) {
    TemporaryDirectory directory;
    const fs::path fifo = directory.path() / "font.ttf";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    auto read = std::async(std::launch::async, [&] { return read_file(fifo, limits::kFontFileBytes); });
    if (read.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        ADD_FAILURE() << "read_file() blocked on a FIFO";
        const int writer = ::open(fifo.c_str(), O_WRONLY);
        if (writer >= 0) ::close(writer);
    }
    const Result<std::vector<std::byte>> result = read.get();
    ASSERT_FALSE(result);
    EXPECT_NE(result.error().message.find("not a regular file"), std::string::npos) << result.error().message;
}

// An input under any of its names is refused as an output, and two outputs that are one file: a
// relative and an absolute name, a symbolic link to the directory, a hard link, also for files
// that do not exist yet.
TEST(Limits, NoOutputIsAnInputOrAnotherOutputUnderAnyName) {
    TemporaryDirectory directory;
    const fs::path real = directory.path() / "real";
    fs::create_directory(real);
    const fs::path alias = directory.path() / "alias";
    fs::create_directory_symlink(real, alias);
    const fs::path asset = real / "a.crisp";
    ASSERT_TRUE(write_file_atomically(asset, bytes_of("asset")));
    const fs::path hard = directory.path() / "hard.crisp";
    fs::create_hard_link(asset, hard);
    const fs::path inputs[] = {asset, real / "layout.json"};  // the layout does not exist
    for (const fs::path& name :
         {alias / "a.crisp", hard, fs::path(alias / ".." / "real" / "a.crisp"), alias / "layout.json"}) {
        const Status checked = check_output_path(name, inputs);
        ASSERT_FALSE(checked) << name;
        EXPECT_NE(checked.error().message.find("it is the input"), std::string::npos) << checked.error().message;
    }
    EXPECT_TRUE(check_output_path(alias / "b.crisp", inputs));

    // Relative names, from wherever the test runs.
    const fs::path here = fs::relative(real, fs::current_path());
    ASSERT_TRUE(here.is_relative());
    EXPECT_TRUE(same_file(here / "x.png", real / "x.png"));
    EXPECT_TRUE(same_file(here / "a.crisp", hard));
    EXPECT_FALSE(same_file(here / "x.png", here / "y.png"));
    OutputFiles outputs({});
    ASSERT_TRUE(outputs.add(here / "x.png"));
    const Status twice = outputs.add(alias / "x.png");
    ASSERT_FALSE(twice);
    EXPECT_NE(twice.error().message.find("also the output " + (here / "x.png").string()), std::string::npos)
        << twice.error().message;
    EXPECT_TRUE(outputs.add(here / "x.pfm"));
    // An input known later (a scene's font) is checked against the outputs declared before.
    EXPECT_FALSE(outputs.add_input(real / "x.pfm"));
    EXPECT_TRUE(outputs.add_input(here / "a.crisp"));
}

// A symbolic link is written through to the regular file it leads to, and kept; a link to a
// device, a FIFO, nothing or an open descriptor (/dev/stdout) is refused like a device.
TEST(Limits, OutputLinksLeadToARegularFileOrAreRefused) {
    TemporaryDirectory directory;
    const fs::path fifo = directory.path() / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const std::pair<fs::path, const char*> refused[] = {{"/dev/null", "not a regular file"},
                                                        {fifo, "not a regular file"},
                                                        {directory.path() / "missing" / "x", "leads to no file"},
                                                        {"/proc/self/fd/1", "open file descriptor"},
                                                        {"/dev/stdout", "open file descriptor"}};
    for (const auto& [target, reason] : refused) {
        const fs::path link = directory.path() / "link";
        fs::remove(link);
        fs::create_symlink(target, link);
        const Status written = write_file_atomically(link, bytes_of("x"));
        ASSERT_FALSE(written) << target;
        EXPECT_NE(written.error().message.find(reason), std::string::npos) << written.error().message;
        EXPECT_TRUE(fs::is_symlink(link));
    }
    const fs::path file = directory.path() / "file.png";
    const fs::path link = directory.path() / "link.png";
    ASSERT_TRUE(write_file_atomically(file, bytes_of("old")));
    fs::create_symlink("file.png", link);
    ASSERT_TRUE(write_file_atomically(link, bytes_of("new")));
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_EQ(test::read_file(file.string()), bytes_of("new"));
}

// A read-only file is refused, not replaced; a writable one is replaced with its mode and owner.
TEST(Limits, ReplacedFilesKeepTheirModeAndOwnerAndReadOnlyOnesAreRefused) {
    TemporaryDirectory directory;
    const fs::path read_only = directory.path() / "read-only.crisp";
    ASSERT_TRUE(write_file_atomically(read_only, bytes_of("old")));
    ASSERT_EQ(::chmod(read_only.c_str(), 0444), 0);
    const Status refused = write_file_atomically(read_only, bytes_of("new"));
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("read-only (mode 0444)"), std::string::npos) << refused.error().message;
    EXPECT_EQ(test::read_file(read_only.string()), bytes_of("old"));
    EXPECT_FALSE(check_output_path(read_only));

    const fs::path kept = directory.path() / "kept.crisp";
    ASSERT_TRUE(write_file_atomically(kept, bytes_of("old")));
    ASSERT_EQ(::chmod(kept.c_str(), 0604), 0);
    // Root (as in CI's containers) gives the file away and must get it back.
    const bool root = ::geteuid() == 0;
    if (root) {
        ASSERT_EQ(::chown(kept.c_str(), 65534, 65534), 0);
    }
    ASSERT_TRUE(write_file_atomically(kept, bytes_of("new")));
    EXPECT_EQ(test::read_file(kept.string()), bytes_of("new"));
    struct stat info = {};
    ASSERT_EQ(::stat(kept.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 07777, 0604u);
    if (root) {
        EXPECT_EQ(info.st_uid, 65534u);
        EXPECT_EQ(info.st_gid, 65534u);
    }
}

// A name longer than the file system takes is refused before any work; one that it takes is
// written, though its temporary's name would be longer still.
TEST(Limits, OutputNamesAreCheckedAgainstTheFileSystemsLimit) {
    TemporaryDirectory directory;
    const long name_max = ::pathconf(directory.path().c_str(), _PC_NAME_MAX);
    ASSERT_GT(name_max, 16);
    const fs::path longest = directory.path() / std::string(static_cast<size_t>(name_max), 'n');
    const fs::path too_long = directory.path() / std::string(static_cast<size_t>(name_max) + 1, 'n');
    const Status checked = check_output_path(too_long);
    ASSERT_FALSE(checked);
    EXPECT_NE(checked.error().message.find("File name too long"), std::string::npos) << checked.error().message;
    ASSERT_TRUE(check_output_path(longest));
    ASSERT_TRUE(write_file_atomically(longest, bytes_of("x")));
    ASSERT_TRUE(write_file_atomically(longest, bytes_of("y")));  // over an existing one: through a hidden name
    EXPECT_EQ(test::read_file(longest.string()), bytes_of("y"));
    EXPECT_EQ(directory.entries().size(), 1u);
    // Past PATH_MAX: refused by name, not by the file system after the work.
    fs::path deep = directory.path();
    while (deep.string().size() < PATH_MAX) deep /= std::string(200, 'd');
    EXPECT_FALSE(check_output_path(deep / "x.png"));
}

}  // namespace
}  // namespace crisp
