#include "core/file_io.hpp"

#include "core/utf8.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace crisp {

namespace {

std::string errno_text(int error) {
    return std::generic_category().message(error);
}

Error io_error(std::string_view what, const std::filesystem::path& path, int error) {
    return Error{ErrorCode::io,
                 std::string(what) + " " + printable(path.string(), kPrintablePath) + ": " + errno_text(error)};
}

// Unpredictability is not needed: O_EXCL refuses an existing name (and a planted symlink), and a
// collision just tries the next name.
std::string temporary_suffix(uint64_t seed) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    uint64_t z = seed + 0x9E3779B97F4A7C15ull;  // splitmix64
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    std::string suffix(6, 'X');
    for (char& c : suffix) {
        c = kAlphabet[z % 62];
        z /= 62;
    }
    return suffix;
}

Status write_all(int fd, std::span<const std::byte> bytes) {
    const std::byte* data = bytes.data();
    size_t left = bytes.size();
    while (left > 0) {
        // Linux writes at most ~2 GiB per call; stay below it.
        ssize_t written = ::write(fd, data, std::min<size_t>(left, size_t{1} << 30));
        if (written < 0) {
            if (errno == EINTR) continue;
            return Error{ErrorCode::io, errno_text(errno)};
        }
        if (written == 0) return Error{ErrorCode::io, errno_text(EIO)};
        data += written;
        left -= static_cast<size_t>(written);
    }
    return {};
}

}  // namespace

Status check_output_path(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs) {
    const std::filesystem::path file_name = path.filename();
    if (file_name.empty() || file_name == "." || file_name == "..")
        return Error{ErrorCode::io, "cannot write " + path.string() + ": not a file name"};
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        return Error{ErrorCode::io, "refusing to write " + path.string() +
                                        ": it exists and is not a regular file (a device, directory, FIFO or socket), "
                                        "which writing would replace"};
    }
    std::filesystem::path directory = path.parent_path();
    if (directory.empty()) directory = ".";
    if (!std::filesystem::is_directory(directory, error)) {
        const int reason = std::filesystem::exists(directory, error) ? ENOTDIR : ENOENT;
        return Error{ErrorCode::io,
                     "cannot write " + path.string() + ": " + directory.string() + ": " + errno_text(reason)};
    }
    for (const std::filesystem::path& input : inputs) {
        if (std::filesystem::exists(status) && std::filesystem::equivalent(path, input, error)) {
            return Error{ErrorCode::io, "refusing to write " + path.string() + ": it is the input " + input.string()};
        }
    }
    return {};
}

namespace {

// A file written but not yet in place: an unnamed O_TMPFILE in the target's directory (nothing is
// left behind if the process dies), or where the file system has none, a hidden temporary beside it.
struct Staged {
    std::filesystem::path path;
    std::filesystem::path directory;
    std::string temporary;  // the hidden temporary's name; empty for an unnamed file
    int fd = -1;
};

std::string hidden_prefix(const std::filesystem::path& path, const std::filesystem::path& directory) {
    // (Appended piece by piece: GCC 12 at -O3 warns falsely about "." + string + "..." (-Wrestrict).)
    std::string hidden = ".";
    hidden += path.filename().string();
    hidden += ".tmp-";
    return (directory / hidden).string();
}

// A hidden temporary `.NAME.tmp-XXXXXX` beside `path`, opened with O_EXCL (which refuses an existing
// name and a planted symlink; a collision tries the next name) and mode 0666, so that it gets the
// umask's usual permissions. Returns the descriptor, or -1 with errno set.
int open_named_temporary(const std::string& prefix, std::string& name) {
    auto seed = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
                (static_cast<uint64_t>(::getpid()) << 40);
    for (uint64_t attempt = 0; attempt < 100; ++attempt) {
        name = prefix + temporary_suffix(seed + attempt);
        const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    return -1;
}

// Temporaries of this name pattern that a killed writer left behind (on a file system without
// O_TMPFILE, or between naming an unnamed file and renaming it), older than a minute (younger ones
// may be another writer's, still at work).
void remove_stale_temporaries(const std::string& prefix) {
    const std::filesystem::path pattern(prefix);
    const std::string stem = pattern.filename().string();
    std::error_code error;
    const auto now = std::filesystem::file_time_type::clock::now();
    for (const auto& entry : std::filesystem::directory_iterator(pattern.parent_path(), error)) {
        const std::string name = entry.path().filename().string();
        if (name.size() != stem.size() + 6 || name.compare(0, stem.size(), stem) != 0) continue;
        const auto written = entry.last_write_time(error);
        if (!error && now - written > std::chrono::minutes(1)) std::filesystem::remove(entry.path(), error);
    }
}

void discard(Staged& staged) {
    if (staged.fd >= 0) ::close(staged.fd);
    staged.fd = -1;
    if (!staged.temporary.empty()) ::unlink(staged.temporary.c_str());
}

Status stage(const std::filesystem::path& path, std::span<const std::byte> bytes, Staged& staged) {
    if (Status checked = check_output_path(path); !checked) return checked;
    staged.path = path;
    staged.directory = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
    remove_stale_temporaries(hidden_prefix(path, staged.directory));
    auto fail = [&](std::string_view what, int error) -> Status {
        discard(staged);
        return Error{ErrorCode::io,
                     "cannot write " + path.string() + ": " + std::string(what) + ": " + errno_text(error)};
    };
    // An unnamed file is later given its name through /proc/self/fd: without /proc, a named one.
    static const bool can_link_unnamed = ::access("/proc/self/fd", X_OK) == 0;
    staged.fd = can_link_unnamed ? ::open(staged.directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666) : -1;
    if (staged.fd < 0) {
        if (can_link_unnamed && errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) {
            return io_error("cannot create a temporary file to write", path, errno);
        }
        staged.fd = open_named_temporary(hidden_prefix(path, staged.directory), staged.temporary);
        if (staged.fd < 0) {
            staged.temporary.clear();
            return io_error("cannot create a temporary file to write", path, errno);
        }
    }
    if (Status status = write_all(staged.fd, bytes); !status) {
        discard(staged);
        return Error{ErrorCode::io, "cannot write " + path.string() + ": " + status.error().message};
    }
    // Flushed before it takes the name: otherwise a crash could leave the name on empty contents.
    while (::fsync(staged.fd) != 0)
        if (errno != EINTR) return fail("flushing", errno);
    return {};
}

// Puts a staged file in place: an unnamed file is linked to a hidden name first (a file cannot
// be linked over an existing one), then renamed over `path`.
Status commit(Staged& staged) {
    auto fail = [&](std::string_view what, int error) -> Status {
        discard(staged);
        return Error{ErrorCode::io,
                     "cannot write " + staged.path.string() + ": " + std::string(what) + ": " + errno_text(error)};
    };
    if (staged.temporary.empty()) {
        std::string name;
        const std::string prefix = hidden_prefix(staged.path, staged.directory);
        const std::string proc = "/proc/self/fd/" + std::to_string(staged.fd);
        for (int attempt = 0; attempt < 100; ++attempt) {
            name =
                prefix + temporary_suffix(static_cast<uint64_t>(attempt) * 7919u + static_cast<uint64_t>(::getpid()));
            if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0) break;
            if (errno != EEXIST) return fail("linking the written file", errno);
            name.clear();
        }
        if (name.empty()) return fail("linking the written file", EEXIST);
        staged.temporary = name;
    }
    // close() can report a deferred write error (NFS); it is not retried, the descriptor is gone.
    const int closed = ::close(staged.fd);
    staged.fd = -1;
    if (closed != 0) return fail("closing", errno);
    if (::rename(staged.temporary.c_str(), staged.path.c_str()) != 0) return fail("renaming it into place", errno);
    staged.temporary.clear();
    // Makes the rename itself durable. Best effort: the new file is already in place, and
    // reporting a failure now would claim that `path` was left untouched.
    const int directory_fd = ::open(staged.directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (directory_fd >= 0) {
        (void)::fsync(directory_fd);
        ::close(directory_fd);
    }
    return {};
}

}  // namespace

Status write_files_atomically(std::span<const OutputFile> files) {
    std::vector<Staged> staged(files.size());
    for (size_t i = 0; i < files.size(); ++i) {
        if (Status status = stage(files[i].path, files[i].bytes, staged[i]); !status) {
            for (size_t j = 0; j < i; ++j) discard(staged[j]);
            return status;
        }
    }
    for (size_t i = 0; i < files.size(); ++i) {
        if (Status status = commit(staged[i]); !status) {
            for (size_t j = i + 1; j < files.size(); ++j) discard(staged[j]);
            return status;
        }
    }
    return {};
}

Status write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
    const OutputFile file{path, bytes};
    return write_files_atomically(std::span(&file, 1));
}

Result<std::vector<std::byte>> read_file(const std::filesystem::path& path, uint64_t max_bytes) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return io_error("cannot read", path, errno);

    std::vector<std::byte> bytes;
    struct stat info = {};
    if (::fstat(fd, &info) != 0) {
        int error = errno;
        ::close(fd);
        return io_error("cannot read", path, error);
    }
    if (S_ISDIR(info.st_mode)) {
        ::close(fd);
        return io_error("cannot read", path, EISDIR);
    }
    if (!S_ISREG(info.st_mode)) {
        ::close(fd);
        return Error{ErrorCode::io, "cannot read " + path.string() +
                                        ": not a regular file (a device, FIFO or socket has no size to check, and may "
                                        "never end)"};
    }
    auto too_large = [&] {
        return Error{ErrorCode::io, "cannot read " + path.string() + ": larger than the " + std::to_string(max_bytes) +
                                        " bytes allowed for this kind of input (docs/limits.md)"};
    };
    if (static_cast<uint64_t>(info.st_size) > max_bytes) {
        ::close(fd);
        return too_large();
    }
    // One byte more than the size fstat gives, so the file is read in one call and its end is seen
    // without growing; a file that grows while it is read grows the buffer up to the limit.
    bytes.resize(static_cast<size_t>(info.st_size) + 1);
    size_t used = 0;
    for (;;) {
        if (used == bytes.size()) {
            if (used > max_bytes) {
                ::close(fd);
                return too_large();
            }
            bytes.resize(static_cast<size_t>(std::min<uint64_t>(uint64_t{bytes.size()} * 2, max_bytes + 1)));
        }
        ssize_t got = ::read(fd, bytes.data() + used, std::min<size_t>(bytes.size() - used, size_t{1} << 30));
        if (got == 0) break;
        if (got < 0) {
            if (errno == EINTR) continue;
            int error = errno;
            ::close(fd);
            return io_error("cannot read", path, error);
        }
        used += static_cast<size_t>(got);
    }
    ::close(fd);
    bytes.resize(used);
    return bytes;
}

}  // namespace crisp
