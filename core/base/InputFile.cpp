#include "core/base/InputFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

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

}  // namespace

std::string_view FileKindName(unsigned mode) {
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a file";
}

OpenedInput::~OpenedInput() {
    if (mFd >= 0) ::close(mFd);
}

Result<OpenedInput> OpenInputFile(const std::string& path, const InputKind& kind) {
    // A FIFO is refused before it is opened (opening one blocks until a writer comes without O_NONBLOCK, and
    // with it a reader would see an empty file); O_NONBLOCK covers a path swapped for a FIFO after the check.
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode))
        return MakeError(path + ": not a regular file (" + std::string(FileKindName(info.st_mode)) + ")");
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return MakeError(CannotRead(path, errno));
    auto refuse = [fd](std::string message) {
        ::close(fd);
        return MakeError(std::move(message));
    };
    if (::fstat(fd, &info) != 0) return refuse(CannotRead(path, errno));
    if (!S_ISREG(info.st_mode))
        return refuse(path + ": not a regular file (" + std::string(FileKindName(info.st_mode)) + ")");
    if (uint64_t(info.st_size) > kind.maxBytes) return refuse(TooLarge(path, uint64_t(info.st_size), kind));
    // Before any of it is read: what reading it takes against what this process may still allocate.
    const uint64_t needed = SaturatingMul(uint64_t(info.st_size), kind.memoryPerByte);
    if (const std::optional<MemoryFigure> free = ProcessAvailableMemory(); free && needed > free->bytes)
        return refuse(path + ": reading its " + std::to_string(info.st_size) + " bytes takes about " +
                      FormatGiB(needed) + " GiB, more than the " + FormatGiB(free->bytes) +
                      " GiB this process may still use (" + free->source + ")");
    // Blocking reads from here on: O_NONBLOCK was only for the open.
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags >= 0) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    return OpenedInput(fd, uint64_t(info.st_size));
}

Result<std::string> ReadInputFile(const std::string& path, const InputKind& kind) {
    Result<OpenedInput> opened = OpenInputFile(path, kind);
    if (!opened) return std::unexpected(opened.error());
    // Read at most one byte past the limit, in case the file grew since fstat.
    std::string text(size_t(opened->Bytes()), '\0');
    size_t used = 0;
    for (;;) {
        if (used == text.size())
            text.resize(size_t(std::min<uint64_t>(kind.maxBytes + 1, uint64_t(text.size()) + (1 << 16))));
        if (used == text.size()) break;
        const ssize_t n = ::read(opened->Fd(), text.data() + used, text.size() - used);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return MakeError(CannotRead(path, errno));
        if (n == 0) break;
        used += size_t(n);
    }
    if (used > kind.maxBytes) return MakeError(TooLarge(path, used, kind));
    text.resize(used);
    return text;
}

Status CheckInputFile(const std::string& path, const InputKind& kind) {
    Result<OpenedInput> opened = OpenInputFile(path, kind);
    if (!opened) return std::unexpected(opened.error());
    return {};
}

}  // namespace cb
