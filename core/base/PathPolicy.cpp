#include "core/base/PathPolicy.h"

#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/base/ProcessMemory.h"

namespace cb {
namespace {

std::string MiB(uint64_t bytes) {
    return bytes % (uint64_t(1) << 20) == 0 ? std::to_string(bytes >> 20) + " MiB" : std::to_string(bytes) + " bytes";
}

std::string TooLarge(const std::string& path, uint64_t bytes, const InputKind& kind) {
    return path + ": " + std::to_string(bytes) + " bytes, more than the " + MiB(kind.maxBytes) + " " +
           std::string(kind.what) + " may have";
}

std::string CannotRead(const std::string& path, int error) {
    return path + ": cannot read the file: " + std::strerror(error);
}

std::string NotAFile(const std::string& shown, unsigned mode) {
    return shown + ": not a regular file (" + std::string(FileKindName(mode)) + ")";
}

// The checks every input gets on its open descriptor `fd` (closed on failure): a regular file, of at most the
// kind's size, whose reading fits in what the process may still allocate; then blocking reads.
Result<OpenedInput> CheckOpened(int fd, const std::string& shown, const InputKind& kind) {
    auto refuse = [fd](std::string message) {
        ::close(fd);
        return MakeError(std::move(message));
    };
    struct stat info {};
    if (::fstat(fd, &info) != 0) return refuse(CannotRead(shown, errno));
    if (!S_ISREG(info.st_mode)) return refuse(NotAFile(shown, info.st_mode));
    if (uint64_t(info.st_size) > kind.maxBytes) return refuse(TooLarge(shown, uint64_t(info.st_size), kind));
    // Before any of it is read: what reading it takes against what this process may still allocate.
    const uint64_t needed = SaturatingMul(uint64_t(info.st_size), kind.memoryPerByte);
    if (const std::optional<MemoryFigure> free = ProcessAvailableMemory(); free && needed > free->bytes)
        return refuse(shown + ": reading its " + std::to_string(info.st_size) + " bytes takes about " +
                      FormatGiB(needed) + " GiB, more than the " + FormatGiB(free->bytes) +
                      " GiB this process may still use (" + free->source + ")");
    // Blocking reads from here on: O_NONBLOCK was only for the open.
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags >= 0) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    return OpenedInput(fd, uint64_t(info.st_size));
}

constexpr int kReadFlags = O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY;

// openat2 with RESOLVE_BENEATH: -1 with errno ENOSYS where the kernel (or a sandbox's filter) lacks it.
int OpenBeneath(int folderFd, const std::string& name) {
    open_how how{};
    how.flags = uint64_t(kReadFlags);
    how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
    for (;;) {
        const long fd = ::syscall(SYS_openat2, folderFd, name.c_str(), &how, sizeof how);
        if (fd >= 0 || errno != EAGAIN) return int(fd);
    }
}

// Without openat2: `name`'s folders one at a time and then the file, none of them through a link, no "..".
int OpenWithoutLinks(int folderFd, const std::string& name) {
    if (name.empty() || name.front() == '/') {
        errno = EXDEV;
        return -1;
    }
    const std::filesystem::path path(name);
    int current = ::fcntl(folderFd, F_DUPFD_CLOEXEC, 0);
    if (current < 0) return -1;
    const std::string leaf = path.filename().string();
    for (const std::filesystem::path& part : path.parent_path()) {
        if (part == "..") {
            ::close(current);
            errno = EXDEV;
            return -1;
        }
        const int next = OpenFolderAt(current, part.string());
        const int error = errno;
        ::close(current);
        if (next < 0) {
            errno = error == ELOOP ? EXDEV : error;
            return -1;
        }
        current = next;
    }
    if (leaf == "..") {
        ::close(current);
        errno = EXDEV;
        return -1;
    }
    const int fd = ::openat(current, leaf.c_str(), kReadFlags | O_NOFOLLOW);
    const int error = errno;
    ::close(current);
    errno = fd < 0 && error == ELOOP ? EXDEV : error;
    return fd;
}

std::string Joined(const std::string& folder, const std::string& name) {
    if (folder.empty() || folder == ".") return name;
    return folder + (folder.back() == '/' ? "" : "/") + name;
}

}  // namespace

std::string_view FileKindName(unsigned mode) {
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISLNK(mode)) return "a symbolic link";
    return "not a file";
}

OpenedInput::~OpenedInput() {
    if (mFd >= 0) ::close(mFd);
}

Result<OpenedInput> OpenInputFile(const std::string& path, const InputKind& kind) {
    // A FIFO or a device is refused before it is opened (opening one may block or act); O_NONBLOCK and the
    // descriptor's own check cover a path swapped after this look.
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode)) return MakeError(NotAFile(path, info.st_mode));
    const int fd = ::open(path.c_str(), kReadFlags);
    if (fd < 0) return MakeError(CannotRead(path, errno));
    return CheckOpened(fd, path, kind);
}

Result<OpenedInput> OpenInputBeneath(const std::string& folder, const std::string& name, const InputKind& kind) {
    const std::string shown = Joined(folder, name);
    const int folderFd = OpenNamedFolder(folder.empty() ? "." : folder);
    if (folderFd < 0) return MakeError(CannotRead(folder, errno));
    int fd = OpenBeneath(folderFd, name);
    if (fd < 0 && (errno == ENOSYS || errno == EPERM)) fd = OpenWithoutLinks(folderFd, name);
    const int error = errno;
    ::close(folderFd);
    if (fd < 0 && error == EXDEV)
        return MakeError(shown + ": leads out of " + (folder.empty() ? "." : folder) +
                         " (a symbolic link, an absolute name or ..); cloudbench reads nothing outside the folder "
                         "it was given");
    if (fd < 0) return MakeError(CannotRead(shown, error));
    return CheckOpened(fd, shown, kind);
}

Result<std::string> ReadOpenedInput(OpenedInput& input, const std::string& shown, const InputKind& kind) {
    // Read at most one byte past the limit, in case the file grew since fstat (a system file shows no size).
    std::string text(size_t(input.Bytes()), '\0');
    size_t used = 0;
    for (;;) {
        if (used == text.size())
            text.resize(size_t(std::min<uint64_t>(kind.maxBytes + 1, uint64_t(text.size()) + (1 << 16))));
        if (used == text.size()) break;
        const ssize_t n = ::read(input.Fd(), text.data() + used, text.size() - used);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return MakeError(CannotRead(shown, errno));
        if (n == 0) break;
        used += size_t(n);
    }
    if (used > kind.maxBytes) return MakeError(TooLarge(shown, used, kind));
    text.resize(used);
    return text;
}

Result<std::string> ReadInputFile(const std::string& path, const InputKind& kind) {
    Result<OpenedInput> opened = OpenInputFile(path, kind);
    if (!opened) return std::unexpected(opened.error());
    return ReadOpenedInput(*opened, path, kind);
}

Result<std::string> ReadInputBeneath(const std::string& folder, const std::string& name, const InputKind& kind) {
    Result<OpenedInput> opened = OpenInputBeneath(folder, name, kind);
    if (!opened) return std::unexpected(opened.error());
    return ReadOpenedInput(*opened, Joined(folder, name), kind);
}

Error LinkRefused(const std::string& shown) {
    return Error{shown + ": is a symbolic link; cloudbench does not write through links (remove it)"};
}

Result<int> OpenFileAt(int folderFd, const std::string& shown, const std::string& name, WriteMode mode) {
    int flags = O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | O_CREAT;
    switch (mode) {
        case WriteMode::CreateNew:
            flags |= O_RDWR | O_EXCL;
            break;
        case WriteMode::InPlace:
            flags |= O_RDWR;
            break;
        case WriteMode::Append:
            flags |= O_RDWR | O_APPEND;
            break;
    }
    const int fd = ::openat(folderFd, name.c_str(), flags, 0644);
    if (fd < 0) {
        const int error = errno;
        struct stat info {};
        const bool there = ::fstatat(folderFd, name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0;
        if (error == ELOOP || (there && S_ISLNK(info.st_mode))) return std::unexpected(LinkRefused(shown));
        if (there && !S_ISREG(info.st_mode) && mode != WriteMode::CreateNew)
            return MakeError(shown + ": not a regular file (" + std::string(FileKindName(info.st_mode)) +
                             "); cloudbench writes only regular files (remove it)");
        return MakeError(shown + ": cannot write: " + std::strerror(error));
    }
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
        const unsigned kind = info.st_mode;
        ::close(fd);
        return MakeError(shown + ": not a regular file (" + std::string(FileKindName(kind)) +
                         "); cloudbench writes only regular files (remove it)");
    }
    const int status = ::fcntl(fd, F_GETFL);
    if (status >= 0) (void)::fcntl(fd, F_SETFL, status & ~O_NONBLOCK);
    return fd;
}

int OpenFolderAt(int folderFd, const std::string& name) {
    return ::openat(folderFd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
}

int OpenNamedFolder(const std::string& path) { return ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); }

Status RefuseNonFileAt(int folderFd, const std::string& shown, const std::string& name) {
    struct stat info {};
    if (::fstatat(folderFd, name.c_str(), &info, AT_SYMLINK_NOFOLLOW) != 0 || S_ISREG(info.st_mode)) return {};
    if (S_ISLNK(info.st_mode)) return std::unexpected(LinkRefused(shown));
    return MakeError(shown + ": not a regular file (" + std::string(FileKindName(info.st_mode)) +
                     "); cloudbench replaces only regular files (remove it)");
}

Result<int> OpenAppendFile(const std::string& path) {
    const std::filesystem::path target(path);
    const std::string name = target.filename().string(), folder = target.parent_path().string();
    if (name.empty() || name == "." || name == "..") return MakeError(path + ": cannot write: not a file name");
    std::error_code ec;
    if (!folder.empty()) std::filesystem::create_directories(folder, ec);
    const int folderFd = OpenNamedFolder(folder.empty() ? "." : folder);
    if (folderFd < 0) return MakeError(path + ": cannot write: " + std::strerror(errno));
    Result<int> fd = OpenFileAt(folderFd, path, name, WriteMode::Append);
    ::close(folderFd);
    return fd;
}

}  // namespace cb
