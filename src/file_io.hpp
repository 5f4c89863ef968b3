// Whole-file reads, and writes that never leave a half-written file.
#pragma once

#include <crisp/result.hpp>

#include <cstddef>
#include <filesystem>
#include <vector>

namespace crisp {

// Reads a whole file. Errors (ErrorCode::io) name the path and the reason; a directory is refused.
Result<std::vector<std::byte>> read_file(const std::filesystem::path& path);

}  // namespace crisp
