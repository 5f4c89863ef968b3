#include "output_files.hpp"

#include "core/file_io.hpp"

#include <cassert>

namespace crisp {

OutputFiles::OutputFiles(std::vector<std::filesystem::path> inputs) : inputs_(std::move(inputs)) {}

Status OutputFiles::add(std::filesystem::path path) {
    if (Status checked = check_output_path(path, inputs_); !checked) return checked;
    paths_.push_back(std::move(path));
    return {};
}

Status OutputFiles::write(std::span<const std::span<const std::byte>> contents) const {
    assert(contents.size() == paths_.size());
    std::vector<OutputFile> files;
    for (size_t i = 0; i < paths_.size() && i < contents.size(); ++i) files.push_back({paths_[i], contents[i]});
    return write_files_atomically(files);
}

}  // namespace crisp
