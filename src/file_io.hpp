// Whole-file reads, and writes that never leave a half-written file.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <filesystem>
#include <vector>

namespace crisp {

// Reads a whole regular file of at most `max_bytes` (limits.hpp says how much for each kind of
// input). Errors (ErrorCode::io) name the path and the reason: a directory, device, FIFO or socket
// is refused before any byte is read, and a larger file before it is read whole.
Result<std::vector<std::byte>> read_file(const std::filesystem::path& path, uint64_t max_bytes);

// Refuses, before any work, an output path that write_file_atomically() could not or must not
// replace: an existing non-regular file (a device node such as /dev/null, a directory, a FIFO), a
// directory that does not exist, and any of `inputs` (the same file under another name too).
// ErrorCode::io, naming the path and the reason.
Status check_output_path(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs = {});

}  // namespace crisp
