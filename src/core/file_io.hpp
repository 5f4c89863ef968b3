// Whole-file reads, and writes that never leave a half-written file.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <filesystem>
#include <vector>

namespace crisp {

// Reads a whole regular file of at most `max_bytes` (core/limits.hpp says how much for each kind of
// input). Errors (ErrorCode::io) name the path and the reason: a directory, device, FIFO or socket
// is refused before any byte is read (opened without blocking: a FIFO with no writer does not
// hang), and a larger file before it is read whole.
Result<std::vector<std::byte>> read_file(const std::filesystem::path& path, uint64_t max_bytes);

// Writes `bytes` to `path` atomically, as write_files_atomically() below writes several: flushed to
// a temporary file and renamed over `path` only when complete. On failure (ErrorCode::io) an
// existing file at `path` is untouched. The file gets the usual permissions (0666 less the umask).
Status write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

// One output of a run: where, and its bytes.
struct OutputFile {
    std::filesystem::path path;
    std::span<const std::byte> bytes;
};

// Writes every file as write_file_atomically() writes one, and puts them in place together: all
// are written and flushed first (into unnamed O_TMPFILE files where the file system has them, so
// that a killed process leaves nothing behind; else hidden temporaries beside each target, which
// a later write removes once they are a minute old), and only then renamed over their targets. A
// failure while writing leaves every target untouched. Errors: ErrorCode::io naming the path.
Status write_files_atomically(std::span<const OutputFile> files);

// Refuses, before any work, an output path that write_file_atomically() could not or must not
// replace: an existing non-regular file (a device node such as /dev/null, a directory, a FIFO), a
// directory that does not exist, and any of `inputs` (the same file under another name too).
// ErrorCode::io, naming the path and the reason.
Status check_output_path(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs = {});

}  // namespace crisp
