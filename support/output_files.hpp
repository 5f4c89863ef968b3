// The files one run of a tool writes: each refused before any work if it cannot or must not be
// written, and all put in place together at the end, so that a failed run replaces none of them.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <filesystem>
#include <span>
#include <vector>

namespace crisp {

class OutputFiles {
public:
    // `inputs`: the files the run reads, which no output may replace (under any name).
    explicit OutputFiles(std::vector<std::filesystem::path> inputs);

    // Declares the next output and checks it now: an existing non-regular file (a device node, a
    // directory, a FIFO), a directory that does not exist, or one of the inputs is refused
    // (ErrorCode::io, naming the path and the reason).
    Status add(std::filesystem::path path);

    // Writes `contents[i]` to the i-th output added, every file flushed before any is renamed
    // into place; on failure (ErrorCode::io, naming the path) every existing output is kept.
    // `contents` has one entry per output added.
    Status write(std::span<const std::span<const std::byte>> contents) const;

private:
    std::vector<std::filesystem::path> inputs_;
    std::vector<std::filesystem::path> paths_;
};

}  // namespace crisp
