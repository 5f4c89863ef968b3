#include "core/file_io.hpp"

#include "core/utf8.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <string_view>
#include <system_error>

#include <fcntl.h>
#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/vfs.h>
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

// The random part of a temporary's name. O_EXCL already refuses an existing name (and a planted
// symlink); being unpredictable keeps another process from taking the names first.
std::string random_suffix(size_t length) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    std::random_device device;
    std::string suffix(length, 'X');
    for (char& c : suffix) c = kAlphabet[device() % 62];
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

// What a name stands for: the device and inode of the file it reaches (through any links) where
// one exists, else the canonical path it would be created at (links in its directories followed),
// so that every name of one file, relative, absolute, through symbolic or hard links, compares equal.
struct FileIdentity {
    bool exists = false;
    dev_t device = 0;
    ino_t inode = 0;
    std::filesystem::path canonical;
};

FileIdentity identify(const std::filesystem::path& path) {
    FileIdentity identity;
    struct stat info = {};
    if (::stat(path.c_str(), &info) == 0) {
        identity.exists = true;
        identity.device = info.st_dev;
        identity.inode = info.st_ino;
        return identity;
    }
    std::error_code error;
    const std::filesystem::path absolute = std::filesystem::absolute(path, error);
    identity.canonical = std::filesystem::weakly_canonical(absolute, error);
    if (error) identity.canonical = absolute.lexically_normal();
    return identity;
}

Error refusal(const std::filesystem::path& path, std::string_view reason) {
    return Error{ErrorCode::io, "refusing to write " + path.string() + ": " + std::string(reason)};
}

// /proc's links to open descriptors (/dev/stdout, /dev/fd/N) name a file that is open, which may
// be a pipe, a terminal or no longer have a name: not a place a rename can put a file.
bool on_proc(const std::filesystem::path& directory) {
    struct statfs info = {};
    return ::statfs(directory.c_str(), &info) == 0 && info.f_type == PROC_SUPER_MAGIC;
}

// The file that writing `path` replaces: `path` itself, or where it is a symbolic link, the regular
// file the link leads to, which keeps the link (the rename that puts the new file in place would
// otherwise replace the link itself: `-o /dev/stdout` as root replaced /dev's link with a file). A
// link to anything but a regular file, to nothing, or through /proc's descriptors is refused.
Result<std::filesystem::path> write_target(const std::filesystem::path& path) {
    std::error_code error;
    if (!std::filesystem::is_symlink(std::filesystem::symlink_status(path, error))) return path;
    std::filesystem::path at = path;
    for (int hop = 0; hop < 40 && std::filesystem::is_symlink(std::filesystem::symlink_status(at, error)); ++hop) {
        const std::filesystem::path directory =
            std::filesystem::canonical(at.parent_path().empty() ? "." : at.parent_path(), error);
        if (error) break;  // canonical(path) below names the fault
        if (on_proc(directory)) {
            return refusal(path, "it is a link to an open file descriptor (" + (directory / at.filename()).string() +
                                     "), not a file a rename can replace: name the file itself");
        }
        const std::filesystem::path link = std::filesystem::read_symlink(at, error);
        if (error) break;
        at = link.is_absolute() ? link : directory / link;
    }
    const std::filesystem::path target = std::filesystem::canonical(path, error);
    if (error) return refusal(path, "it is a symbolic link that leads to no file (" + errno_text(error.value()) + ")");
    if (!std::filesystem::is_regular_file(target, error)) {
        return refusal(path, "it is a symbolic link to " + target.string() +
                                 ", which is not a regular file (a device, directory, FIFO or socket)");
    }
    return target;
}

// The hidden name a file is written under before it takes its own: `.NAME.crisp-tmp-PID-RANDOM`,
// NAME cut (at a UTF-8 character's start) so that the whole fits the file system's `name_max`. No
// user's file is mistaken for one: crisp removes only the temporaries it has just created.
std::string temporary_name(const std::string& file_name, size_t name_max, std::string_view random) {
    // (Appended piece by piece: GCC 12 at -O3 warns falsely about "." + string + "..." (-Wrestrict).)
    std::string suffix = ".crisp-tmp-";
    suffix += std::to_string(::getpid());
    suffix += '-';
    suffix += random;
    size_t kept = std::min(file_name.size(), name_max > suffix.size() + 1 ? name_max - suffix.size() - 1 : 0);
    while (kept > 0 && kept < file_name.size() && (static_cast<unsigned char>(file_name[kept]) & 0xC0) == 0x80) --kept;
    std::string name = ".";
    name += std::string_view(file_name).substr(0, kept);
    name += suffix;
    return name;
}

constexpr size_t kTemporaryRandom = 8;  // base-62 characters of a temporary's name

// Where an output goes, once check_output_path() has found it writable.
struct Target {
    std::filesystem::path file;       // the file replaced (write_target())
    std::filesystem::path directory;  // its directory, "." for a bare name
    size_t name_max = NAME_MAX;       // the longest name the directory's file system takes
};

Result<Target> checked_target(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs) {
    const std::filesystem::path file_name = path.filename();
    if (file_name.empty() || file_name == "." || file_name == "..")
        return Error{ErrorCode::io, "cannot write " + path.string() + ": not a file name"};
    Result<std::filesystem::path> file = write_target(path);
    if (!file) return file.error();
    Target target{*file, file->parent_path().empty() ? std::filesystem::path(".") : file->parent_path()};
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(target.file, error);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        return refusal(path,
                       "it exists and is not a regular file (a device, directory, FIFO or socket), which writing "
                       "would replace");
    }
    if (!std::filesystem::is_directory(target.directory, error)) {
        const int reason = std::filesystem::exists(target.directory, error) ? ENOTDIR : ENOENT;
        return Error{ErrorCode::io,
                     "cannot write " + path.string() + ": " + target.directory.string() + ": " + errno_text(reason)};
    }
    // Too long a name used to fail only after all the work, when the file was created.
    const long name_max = ::pathconf(target.directory.c_str(), _PC_NAME_MAX);
    if (name_max > 0) target.name_max = static_cast<size_t>(name_max);
    const std::string name = target.file.filename().string();
    const std::string temporary =
        (target.directory / temporary_name(name, target.name_max, std::string(kTemporaryRandom, 'X'))).string();
    if (name.size() > target.name_max) {
        return Error{ErrorCode::io, "cannot write " + path.string() + ": its name is " + std::to_string(name.size()) +
                                        " bytes, past the " + std::to_string(target.name_max) +
                                        " its file system allows (" + errno_text(ENAMETOOLONG) + ")"};
    }
    if (std::max(target.file.string().size(), temporary.size()) >= PATH_MAX) {
        return Error{ErrorCode::io, "cannot write " + path.string() + ": the path (or its temporary's, " +
                                        std::to_string(temporary.size()) + " bytes) reaches the " +
                                        std::to_string(PATH_MAX) + " bytes of PATH_MAX (" + errno_text(ENAMETOOLONG) +
                                        ")"};
    }
    // A file that exists is replaced only as this process could have written it in place: its
    // replacement keeps its mode and owner (stage()), which a file of another user's would not.
    struct stat info = {};
    if (::stat(target.file.c_str(), &info) == 0) {
        if ((info.st_mode & 0222) == 0) {
            char mode[8];
            std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(info.st_mode & 07777));
            return refusal(path, std::string("it is read-only (mode ") + mode +
                                     "); make it writable (chmod u+w) or remove it to have it replaced");
        }
        if (::faccessat(AT_FDCWD, target.file.c_str(), W_OK, AT_EACCESS) != 0)
            return refusal(path, "this user may not write it (" + errno_text(errno) + ")");
        if (::geteuid() != 0 && info.st_uid != ::geteuid()) {
            return refusal(path, "it belongs to another user (uid " + std::to_string(info.st_uid) +
                                     "), and its replacement would be this user's");
        }
    }
    for (const std::filesystem::path& input : inputs) {
        if (same_file(path, input)) return refusal(path, "it is the input " + input.string());
    }
    return target;
}

}  // namespace

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
    const FileIdentity first = identify(a), second = identify(b);
    if (first.exists != second.exists) return false;
    return first.exists ? first.device == second.device && first.inode == second.inode
                        : first.canonical == second.canonical;
}

Status check_output_path(const std::filesystem::path& path, std::span<const std::filesystem::path> inputs) {
    Result<Target> target = checked_target(path, inputs);
    if (!target) return target.error();
    return {};
}

namespace {

// A file written but not yet in place: an unnamed O_TMPFILE in the target's directory (nothing is
// left behind if the process dies), or where the file system has none, a hidden temporary beside it.
struct Staged {
    std::filesystem::path path;  // as the caller named it, for messages
    Target target;
    std::string temporary;  // the hidden temporary's path; empty for an unnamed file
    int fd = -1;
};

// Gives `staged` a hidden temporary name in its target's directory: opens a new file there
// (`link_unnamed` false) or links its unnamed file there. O_EXCL and linkat() refuse an existing
// name (and a planted symlink); a collision tries another. Returns 0, or an errno.
int name_temporary(Staged& staged, bool link_unnamed) {
    const std::string file_name = staged.target.file.filename().string();
    const std::string proc = "/proc/self/fd/" + std::to_string(staged.fd);
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string name = (staged.target.directory /
                                  temporary_name(file_name, staged.target.name_max, random_suffix(kTemporaryRandom)))
                                     .string();
        // Mode 0666, so that a new file gets the umask's usual permissions.
        const int done = link_unnamed ? ::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW)
                                      : ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (done >= 0) {
            if (!link_unnamed) staged.fd = done;
            staged.temporary = name;
            return 0;
        }
        if (errno != EEXIST) return errno;
    }
    return EEXIST;
}

void discard(Staged& staged) {
    if (staged.fd >= 0) ::close(staged.fd);
    staged.fd = -1;
    // Only a temporary this process created: nothing is ever removed by its name's pattern.
    if (!staged.temporary.empty()) ::unlink(staged.temporary.c_str());
    staged.temporary.clear();
}

Status stage(const std::filesystem::path& path, std::span<const std::byte> bytes, const OutputWriter& writer,
             Staged& staged) {
    Result<Target> target = checked_target(path, {});
    if (!target) return target.error();
    staged.path = path;
    staged.target = std::move(*target);
    auto fail = [&](std::string_view what, int error) -> Status {
        discard(staged);
        return Error{ErrorCode::io,
                     "cannot write " + path.string() + ": " + std::string(what) + ": " + errno_text(error)};
    };
    // An unnamed file is later given its name through /proc/self/fd: without /proc, a named one.
    static const bool can_link_unnamed = ::access("/proc/self/fd", X_OK) == 0;
    const char* directory = staged.target.directory.c_str();
    staged.fd = can_link_unnamed ? ::open(directory, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666) : -1;
    if (staged.fd < 0) {
        if (can_link_unnamed && errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) {
            return io_error("cannot create a temporary file to write", path, errno);
        }
        if (const int error = name_temporary(staged, false); error != 0)
            return io_error("cannot create a temporary file to write", path, error);
    }
    // The file replaced passes its owner and mode on (checked_target() refused a file whose owner
    // this process could not keep); the group too where this user may give it.
    struct stat old = {}, mine = {};
    if (::stat(staged.target.file.c_str(), &old) == 0 && ::fstat(staged.fd, &mine) == 0) {
        if ((old.st_uid != mine.st_uid || old.st_gid != mine.st_gid) &&
            ::fchown(staged.fd, old.st_uid, old.st_gid) != 0 && (::geteuid() == 0 || old.st_uid != mine.st_uid))
            return fail("keeping its owner", errno);
        if (::fchmod(staged.fd, old.st_mode & 0777) != 0) return fail("keeping its mode", errno);
    }
    const int fd = staged.fd;
    const Status written =
        writer ? writer([fd](std::span<const std::byte> piece) { return write_all(fd, piece); }) : write_all(fd, bytes);
    if (Status status = written; !status) {
        discard(staged);
        return Error{ErrorCode::io, "cannot write " + path.string() + ": " + status.error().message};
    }
    // Flushed before it takes the name: otherwise a crash could leave the name on empty contents.
    while (::fsync(staged.fd) != 0)
        if (errno != EINTR) return fail("flushing", errno);
    return {};
}

// Names a staged file: an unnamed file is linked to a hidden name (a file cannot be linked over an
// existing one, so it takes its own name by a rename), then the descriptor is closed.
Status name(Staged& staged) {
    auto fail = [&](std::string_view what, int error) -> Status {
        discard(staged);
        return Error{ErrorCode::io,
                     "cannot write " + staged.path.string() + ": " + std::string(what) + ": " + errno_text(error)};
    };
    if (staged.temporary.empty()) {
        if (const int error = name_temporary(staged, true); error != 0) return fail("linking the written file", error);
    }
    // close() can report a deferred write error (NFS); it is not retried, the descriptor is gone.
    const int closed = ::close(staged.fd);
    staged.fd = -1;
    if (closed != 0) return fail("closing", errno);
    return {};
}

Status put_in_place(Staged& staged) {
    if (::rename(staged.temporary.c_str(), staged.target.file.c_str()) != 0) {
        const int error = errno;
        discard(staged);
        return Error{ErrorCode::io,
                     "cannot write " + staged.path.string() + ": renaming it into place: " + errno_text(error)};
    }
    staged.temporary.clear();
    // Makes the rename itself durable. Best effort: the new file is already in place, and
    // reporting a failure now would claim that `path` was left untouched.
    const int directory_fd = ::open(staged.target.directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (directory_fd >= 0) {
        (void)::fsync(directory_fd);
        ::close(directory_fd);
    }
    return {};
}

}  // namespace

Status write_files_atomically(std::span<const OutputFile> files) {
    std::vector<Staged> staged(files.size());
    auto failed = [&](Status status) {
        for (Staged& file : staged) discard(file);
        return status;
    };
    for (size_t i = 0; i < files.size(); ++i) {
        if (Status status = stage(files[i].path, files[i].bytes, files[i].writer, staged[i]); !status)
            return failed(status);
    }
    for (Staged& file : staged) {
        if (Status status = name(file); !status) return failed(status);
    }
    // Every file is written, flushed and named. The old files of the outputs after the first go
    // before the first rename, so that a kill between two renames leaves the outputs before it new
    // and the rest missing (their new contents in their hidden temporaries): never a new file beside
    // an old one it does not match (a new PNG with an old PFM).
    for (size_t i = 1; i < staged.size(); ++i) {
        if (::unlink(staged[i].target.file.c_str()) != 0 && errno != ENOENT) {
            const int error = errno;
            return failed(Error{ErrorCode::io, "cannot write " + staged[i].path.string() +
                                                   ": removing the old file: " + errno_text(error)});
        }
    }
    for (Staged& file : staged) {
        if (Status status = put_in_place(file); !status) return failed(status);
    }
    return {};
}

Status write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
    const OutputFile file{path, bytes, {}};
    return write_files_atomically(std::span(&file, 1));
}

Result<std::vector<std::byte>> read_file(const std::filesystem::path& path, uint64_t max_bytes) {
    // O_NONBLOCK: opening a FIFO waits for a writer, for ever if none comes; fstat() below refuses
    // it, and the flag is cleared for the regular file's reads. O_NOCTTY: a terminal is not adopted.
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
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
    if (const int flags = ::fcntl(fd, F_GETFL); flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        int error = errno;
        ::close(fd);
        return io_error("cannot read", path, error);
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
