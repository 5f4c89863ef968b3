#include "file_io.hpp"

#include <crisp/asset.hpp>

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
    return Error{ErrorCode::io, std::string(what) + " " + path.string() + ": " + errno_text(error)};
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

Status write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
    if (Status checked = check_output_path(path); !checked) return checked;
    std::filesystem::path file_name = path.filename();
    std::filesystem::path directory = path.parent_path();
    if (directory.empty()) directory = ".";

    // The temporary lives beside the target so the rename stays within one file system. It is
    // opened with mode 0666 and O_EXCL rather than made by mkstemp, whose 0600 the rename would
    // carry over to the file: this way it gets the umask's usual permissions.
    // (Appended piece by piece: GCC 12 at -O3 warns falsely about "." + string + "..." (-Wrestrict).)
    std::string hidden = ".";
    hidden += file_name.string();
    hidden += ".tmp-";
    std::string temporary_prefix = (directory / hidden).string();
    auto seed = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
                (static_cast<uint64_t>(::getpid()) << 40);
    std::string temporary;
    int fd = -1;
    for (uint64_t attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        temporary = temporary_prefix + temporary_suffix(seed + attempt);
        fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) return io_error("cannot create a temporary file to write", path, errno);

    // Every failure from here on removes the temporary, so `path` is either untouched or replaced
    // whole.
    auto fail = [&](std::string_view what, std::string_view reason) -> Status {
        if (fd >= 0) ::close(fd);
        ::unlink(temporary.c_str());
        return Error{ErrorCode::io,
                     "cannot write " + path.string() + ": " + std::string(what) + ": " + std::string(reason)};
    };

    if (Status status = write_all(fd, bytes); !status) return fail("writing " + temporary, status.error().message);
    // Flushed before the rename: otherwise a crash could leave the new name on empty contents.
    while (::fsync(fd) != 0)
        if (errno != EINTR) return fail("flushing " + temporary, errno_text(errno));
    // close() can report a deferred write error (NFS); it is not retried, the descriptor is gone.
    int closed = ::close(fd);
    fd = -1;
    if (closed != 0) return fail("closing " + temporary, errno_text(errno));
    if (::rename(temporary.c_str(), path.c_str()) != 0)
        return fail("renaming " + temporary + " over it", errno_text(errno));

    // Makes the rename itself durable. Best effort: the new file is already in place, and
    // reporting a failure now would claim that `path` was left untouched.
    int directory_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (directory_fd >= 0) {
        (void)::fsync(directory_fd);
        ::close(directory_fd);
    }
    return {};
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
