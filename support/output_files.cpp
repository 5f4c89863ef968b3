#include "output_files.hpp"

#include "core/file_io.hpp"

#include <cassert>
#include <string>

namespace crisp {

OutputFiles::OutputFiles(std::vector<std::filesystem::path> inputs) : inputs_(std::move(inputs)) {}

Status OutputFiles::add(std::filesystem::path path) {
    if (Status checked = check_output_path(path, inputs_); !checked) return checked;
    for (const std::filesystem::path& earlier : paths_) {
        // `-o x.png --coverage-out $PWD/x.png` used to leave the PFM where the PNG should be.
        if (same_file(path, earlier)) {
            return Error{ErrorCode::io,
                         "refusing to write " + path.string() + ": it is also the output " + earlier.string()};
        }
    }
    paths_.push_back(std::move(path));
    return {};
}

Status OutputFiles::add_input(std::filesystem::path path) {
    for (const std::filesystem::path& output : paths_) {
        if (same_file(output, path)) {
            return Error{ErrorCode::io, "refusing to write " + output.string() + ": it is the input " + path.string()};
        }
    }
    inputs_.push_back(std::move(path));
    return {};
}

Status OutputFiles::write(std::span<const std::span<const std::byte>> contents) const {
    assert(contents.size() == paths_.size());
    std::vector<OutputFile> files;
    for (size_t i = 0; i < paths_.size() && i < contents.size(); ++i) files.push_back({paths_[i], contents[i], {}});
    return write_files_atomically(files);
}

Status OutputFiles::write_streamed(std::span<const OutputWriter> writers) const {
    assert(writers.size() == paths_.size());
    std::vector<OutputFile> files;
    for (size_t i = 0; i < paths_.size() && i < writers.size(); ++i) files.push_back({paths_[i], {}, writers[i]});
    return write_files_atomically(files);
}

}  // namespace crisp
