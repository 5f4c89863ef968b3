// The files one run of a tool writes: each refused before any work if it cannot or must not be
// written, and all put in place together at the end, so that a failed run replaces none of them.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <vector>

namespace crisp {

// Writes an output in pieces, each through `put` (which appends it and returns the write's error,
// to be passed on). The type src/core/file_io.hpp's writes take (that header is the library's own).
using OutputWriter = std::function<Status(const std::function<Status(std::span<const std::byte> piece)>& put)>;

class OutputFiles {
public:
    // `inputs`: the files the run reads, which no output may replace (under any name).
    explicit OutputFiles(std::vector<std::filesystem::path> inputs);

    // Declares the next output and checks it now: what check_output_path() refuses (an existing
    // non-regular file or a link to one, a directory that does not exist, a name too long, a
    // read-only file, one of the inputs), and an output already added under any name (same_file())
    // is refused (ErrorCode::io, naming the path and the reason).
    Status add(std::filesystem::path path);

    // Declares one more input, known only once the run has read another (the fonts and layout a
    // scene names): refused, as add() refuses, when it is one of the outputs already added.
    Status add_input(std::filesystem::path path);

    // Writes `contents[i]` to the i-th output added, every file flushed before any is renamed
    // into place (write_files_atomically()); on failure (ErrorCode::io, naming the path) every
    // existing output is kept. `contents` has one entry per output added.
    Status write(std::span<const std::span<const std::byte>> contents) const;

    // As write(), each output's bytes written in pieces by `writers[i]` (an output too large to
    // hold whole); a writer's error fails the write as a write error does, every output kept.
    Status write_streamed(std::span<const OutputWriter> writers) const;

private:
    std::vector<std::filesystem::path> inputs_;
    std::vector<std::filesystem::path> paths_;
};

}  // namespace crisp
