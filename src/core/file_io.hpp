// Whole-file reads, and writes that never leave a half-written file.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <filesystem>
#include <functional>
#include <vector>

namespace crisp {

// Reads a whole regular file of at most `max_bytes` (core/limits.hpp says how much for each kind of
// input). Errors (ErrorCode::io) name the path and the reason: a directory, device, FIFO or socket
// is refused before any byte is read (opened without blocking: a FIFO with no writer does not
// hang), and a larger file before it is read whole.
Result<std::vector<std::byte>> read_file(const std::filesystem::path& path, uint64_t max_bytes);

// Writes `bytes` to `path` atomically, as write_files_atomically() below writes several: flushed to
// a temporary file and renamed over `path` only when complete. On failure (ErrorCode::io) an
// existing file at `path` is untouched. A new file gets the usual permissions (0666 less the umask);
// a file replaced passes on its mode (less setuid, setgid and sticky bits) and owner. Where `path`
// is a symbolic link, the regular file it leads to is replaced and the link kept.
Status write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

// Writes an output too large to hold in pieces: calls `put` with each piece in turn (put appends it
// to the file and returns the write's error, which the writer passes on). Its error fails the write
// as a write error does.
using OutputWriter = std::function<Status(const std::function<Status(std::span<const std::byte> piece)>& put)>;

// One output of a run: where, and its bytes (or, where `writer` is set, what writes them).
struct OutputFile {
    std::filesystem::path path;
    std::span<const std::byte> bytes;
    OutputWriter writer;
};

// Writes every file as write_file_atomically() writes one, and puts them in place together: all
// are written and flushed first (into unnamed O_TMPFILE files where the file system has them, so
// that a process killed while writing leaves nothing behind; else hidden temporaries beside each
// target), then all given hidden names `.NAME.crisp-tmp-PID-RANDOM`, then the old files of all but
// the first removed, and only then renamed over their targets: a kill never leaves a new output
// beside an old one (those after the first may be missing, their contents in hidden temporaries
// that nothing removes later: no file is ever removed for its name). A failure while writing
// leaves every target untouched; a failed rename (a fault of the file system) can leave the
// outputs after the first removed. Errors: ErrorCode::io naming the path.
Status write_files_atomically(std::span<const OutputFile> files);

// Refuses, before any work, an output path that write_file_atomically() could not or must not
// replace: an existing non-regular file (a device node such as /dev/null, a directory, a FIFO), a
// symbolic link to one, to nothing or to an open descriptor (/dev/stdout), a directory that does not
// exist, a name longer than its file system takes (NAME_MAX, pathconf) or a path past PATH_MAX (the
// temporary's too), an existing file that is read-only (no write bit), that this user may not write
// or (unless root) that is another user's, and any of `inputs` (same_file()). ErrorCode::io, naming
// the path and the reason.
Status check_output_path(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs = {});

// Whether two names are one file: the same device and inode where both exist, else the same
// canonical path (every symbolic link in it followed), so that a file not yet written is one file
// under all its names too.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace crisp
