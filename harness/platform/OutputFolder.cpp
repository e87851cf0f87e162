#include "harness/platform/OutputFolder.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "core/base/PathPolicy.h"
#include "harness/platform/PosixIo.h"

namespace cb {
namespace fs = std::filesystem;
namespace {

constexpr const char* kLockName = ".cloudbench.lock";

struct ClaimedFolder {
    fs::path root;       // absolute and lexically normal
    std::string dir;     // as the command was given it, for messages
    int rootFd = -1;     // the folder itself, opened once by name; every name in it is opened from here
    int lockFd = -1;     // held open (and locked) until the process exits
    int journalFd = -1;  // O_APPEND: whole lines from the parent and forked children never interleave
    std::string journalPath;
};

std::mutex gMutex;
std::vector<ClaimedFolder> gClaimed;  // never shrinks: a claim lasts as long as the process

fs::path Normal(const std::string& path) {
    std::error_code ec;
    fs::path absolute = fs::absolute(path, ec);
    return (ec ? fs::path(path) : absolute).lexically_normal();
}

// `path` relative to `root` when it lies inside it (not `root` itself), else "".
std::string InsideRelative(const fs::path& root, const fs::path& path) {
    const fs::path relative = path.lexically_relative(root);
    if (relative.empty() || relative == "." || *relative.begin() == "..") return {};
    return relative.generic_string();
}

// A journal entry is only acted on when it names a file strictly inside the folder.
bool SafeRelative(const std::string& relative) {
    if (relative.empty() || relative.front() == '/' || relative.find('\0') != std::string::npos) return false;
    const fs::path p(relative);
    if (p.lexically_normal().generic_string() != relative) return false;
    return std::none_of(p.begin(), p.end(), [](const fs::path& part) { return part == ".." || part == "."; });
}

ClaimedFolder* FindClaim(const fs::path& root) {
    for (ClaimedFolder& claim : gClaimed)
        if (claim.root == root) return &claim;
    return nullptr;
}

// The claimed folder that holds `path` (the deepest, should claims nest), or is `path` when `orRoot`.
ClaimedFolder* FindClaimHolding(const fs::path& path, bool orRoot = false) {
    ClaimedFolder* found = nullptr;
    for (ClaimedFolder& claim : gClaimed)
        if ((!InsideRelative(claim.root, path).empty() || (orRoot && claim.root == path)) &&
            (!found || claim.root.native().size() > found->root.native().size()))
            found = &claim;
    return found;
}

Error Cannot(const std::string& shown, int error) { return Error{shown + ": cannot write: " + std::strerror(error)}; }

// Whether `name` in the folder `dirFd` is a symbolic link (the name itself, not what it points to).
bool IsLinkAt(int dirFd, const std::string& name) {
    struct stat info {};
    return fstatat(dirFd, name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(info.st_mode);
}

// Opens the folders of `relative` (plain names: no "." or "..") below `from`, one name at a time, never
// following a link; creates each missing one first when `create`. `absent` is set when, without `create`,
// a folder on the way does not exist or is not a folder (then nothing below it exists either).
Result<OpenFolder> WalkDown(OpenFolder from, const fs::path& relative, bool create, bool& absent) {
    absent = false;
    OpenFolder current = std::move(from);
    for (const fs::path& part : relative) {
        const std::string name = part.string();
        if (name.empty() || name == ".") continue;
        const std::string shown = current.ShownChild(name);
        int fd = OpenFolderAt(current.Fd(), name);
        if (fd < 0 && errno == ENOENT && create) {
            if (mkdirat(current.Fd(), name.c_str(), 0777) != 0 && errno != EEXIST)
                return std::unexpected(Cannot(shown, errno));
            fd = OpenFolderAt(current.Fd(), name);
        }
        if (fd < 0) {
            const int error = errno;
            if (IsLinkAt(current.Fd(), name)) return std::unexpected(LinkRefused(shown));
            absent = !create && (error == ENOENT || error == ENOTDIR);
            return std::unexpected(Cannot(shown, error));
        }
        current = OpenFolder(fd, shown);
    }
    return current;
}

Result<std::string> ReadWhole(int fd, const std::string& name) {
    std::string text;
    char chunk[65536];
    for (off_t at = 0;;) {
        const ssize_t n = pread(fd, chunk, sizeof chunk, at);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return MakeError(name + ": cannot read: " + std::strerror(errno));
        if (n == 0) return text;
        text.append(chunk, size_t(n));
        at += n;
    }
}

struct JournalEntry {
    OutputEvent event;
    std::string relative;
};

std::vector<JournalEntry> ParseJournal(const std::string& text) {
    std::vector<JournalEntry> entries;
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) break;  // a line cut short by a kill is ignored
        const std::string_view line(text.data() + at, end - at);
        at = end + 1;
        if (line.size() < 3 || line[1] != ' ') continue;
        const char kind = line[0];
        if (kind != char(OutputEvent::Writing) && kind != char(OutputEvent::Placing) &&
            kind != char(OutputEvent::NotPlaced))
            continue;
        std::string relative(line.substr(2));
        if (SafeRelative(relative)) entries.push_back({OutputEvent(kind), std::move(relative)});
    }
    return entries;
}

// Removes the file the journal entry `relative` names below `root`, walking down without following links. A
// folder on the way that is gone (or is a file) leaves nothing to remove; a folder at the name itself is not the
// file the journal recorded: it is left in place with a warning (the journal lists only files), so a folder put
// there later never blocks every later run.
Status RemoveJournalled(const OpenFolder& root, const std::string& relative) {
    const fs::path path(relative);
    bool absent = false;
    auto folder = WalkDown(OpenFolder(fcntl(root.Fd(), F_DUPFD_CLOEXEC, 0), root.Shown()), path.parent_path(),
                           /*create=*/false, absent);
    if (!folder && absent) return {};
    if (!folder) return std::unexpected(folder.error());
    const std::string name = path.filename().string();
    Status removed = RemoveFileAt(*folder, name, "the previous run's file");
    struct stat info {};
    if (!removed && fstatat(folder->Fd(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0 && S_ISDIR(info.st_mode)) {
        std::fprintf(stderr,
                     "warning: %s: a folder where the previous run wrote a file; left in place (the journal lists "
                     "only files)\n",
                     folder->ShownChild(name).c_str());
        return {};
    }
    return removed;
}

// Removes what the previous journal lists: the placed JSON outputs first (they
// name the other files, so a removal cut short never leaves one naming a file
// already gone), then the other placed files, then every temporary name, then
// the folders that removal left empty.
Status RemovePreviousOutputs(const OpenFolder& root, const std::vector<JournalEntry>& entries) {
    std::vector<std::string> placed, temporaries;
    std::set<std::string> seenPlaced, seenTemporary;
    for (const JournalEntry& e : entries) {
        if (e.event == OutputEvent::Placing && seenPlaced.insert(e.relative).second) placed.push_back(e.relative);
        if (seenTemporary.insert(e.relative).second) temporaries.push_back(e.relative);
    }
    std::stable_partition(placed.begin(), placed.end(),
                          [](const std::string& r) { return fs::path(r).extension() == ".json"; });
    for (const std::string& relative : placed) CB_TRY(RemoveJournalled(root, relative));
    std::set<std::string, std::greater<>> folders;  // deepest first
    for (const std::string& relative : temporaries) {
        CB_TRY(RemoveJournalled(root, TemporaryNameOf(relative)));
        for (fs::path parent = fs::path(relative).parent_path(); parent.has_relative_path();
             parent = parent.parent_path())
            folders.insert(parent.generic_string());
    }
    // Only folders left empty go (AT_REMOVEDIR removes no other); one that is now a link is never followed.
    for (const std::string& folder : folders) {
        bool absent = false;
        const fs::path path(folder);
        auto parent = WalkDown(OpenFolder(fcntl(root.Fd(), F_DUPFD_CLOEXEC, 0), root.Shown()), path.parent_path(),
                               /*create=*/false, absent);
        if (parent && !IsLinkAt(parent->Fd(), path.filename().string()))
            unlinkat(parent->Fd(), path.filename().c_str(), AT_REMOVEDIR);
    }
    return {};
}

// The holder's "PID COMMAND" line, for the message of a command that finds the folder locked.
std::string DescribeHolder(int lockFd) {
    auto text = ReadWhole(lockFd, "");
    if (!text) return "";
    const std::string line = text->substr(0, text->find('\n'));
    const size_t space = line.find(' ');
    if (space == std::string::npos || space == 0 || line.size() > 200) return "";
    const std::string pid = line.substr(0, space), command = line.substr(space + 1);
    if (!std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; })) return "";
    if (!std::all_of(command.begin(), command.end(), [](char c) { return (c >= 'a' && c <= 'z') || c == '-'; }))
        return "";
    return " (pid " + pid + ", " + command + ")";
}

// Opens (creating) the regular file `name` in `folder` for reading and writing, never through a link:
// the lock and the journal, the two files cloudbench writes in place.
Result<int> OpenInPlace(const OpenFolder& folder, const std::string& name, WriteMode mode) {
    return OpenFileAt(folder.Fd(), folder.ShownChild(name), name, mode);
}

}  // namespace

OpenFolder::~OpenFolder() {
    if (mFd >= 0) close(mFd);
}

OpenFolder& OpenFolder::operator=(OpenFolder&& other) noexcept {
    if (this != &other) {
        if (mFd >= 0) close(mFd);
        mFd = other.mFd;
        mShown = std::move(other.mShown);
        other.mFd = -1;
    }
    return *this;
}

std::string OpenFolder::ShownChild(std::string_view name) const {
    if (mShown.empty() || mShown == ".") return std::string(name);
    return mShown + (mShown.back() == '/' ? "" : "/") + std::string(name);
}

Result<OpenFolder> OpenFolderForWriting(const std::string& dir, bool create) {
    const fs::path target = Normal(dir);
    std::optional<OpenFolder> root;
    fs::path relative;
    {
        std::lock_guard guard(gMutex);
        if (ClaimedFolder* claim = FindClaimHolding(target, /*orRoot=*/true)) {
            const int fd = fcntl(claim->rootFd, F_DUPFD_CLOEXEC, 0);
            if (fd < 0) return std::unexpected(Cannot(claim->dir, errno));
            root.emplace(fd, claim->dir);
            relative = InsideRelative(claim->root, target);
        }
    }
    bool absent = false;
    if (root) return WalkDown(std::move(*root), relative, create, absent);
    // A folder the user named (or the folder of a file the user named): its path is followed as given.
    const std::string shown = dir.empty() ? "." : dir;
    if (create) {
        std::error_code ec;
        fs::create_directories(shown, ec);
        if (ec) return std::unexpected(Cannot(shown, ec.value()));
    }
    const int fd = OpenNamedFolder(shown);
    if (fd < 0) return std::unexpected(Cannot(shown, errno));
    return OpenFolder(fd, shown);
}

Status RefuseLinkAt(const OpenFolder& folder, const std::string& name) {
    if (IsLinkAt(folder.Fd(), name)) return std::unexpected(LinkRefused(folder.ShownChild(name)));
    return {};
}

Status RemoveFileAt(const OpenFolder& folder, const std::string& name, std::string_view what) {
    const std::string shown = folder.ShownChild(name);
    auto cannot = [&](const std::string& why) {
        return MakeError(shown + ": cannot remove " + std::string(what) + ": " + why);
    };
    struct stat info {};
    if (fstatat(folder.Fd(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) != 0)
        return errno == ENOENT ? Status{} : cannot(std::strerror(errno));
    if (S_ISLNK(info.st_mode)) return std::unexpected(LinkRefused(shown));
    if (S_ISDIR(info.st_mode)) return cannot("it is a folder");
    if (PlantedFsFailure("remove", name)) return cannot(std::strerror(EIO));
    // A name swapped for a link since the check is removed as a name: unlinkat never follows it.
    if (unlinkat(folder.Fd(), name.c_str(), 0) != 0 && errno != ENOENT) return cannot(std::strerror(errno));
    return {};
}

Status RemoveTreeAt(const OpenFolder& folder, const std::string& name) {
    const std::string shown = folder.ShownChild(name);
    auto cannot = [&](int error) { return MakeError(shown + ": cannot remove: " + std::strerror(error)); };
    struct stat info {};
    if (fstatat(folder.Fd(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) != 0)
        return errno == ENOENT ? Status{} : cannot(errno);
    if (S_ISLNK(info.st_mode)) return std::unexpected(LinkRefused(shown));
    if (!S_ISDIR(info.st_mode)) {
        if (unlinkat(folder.Fd(), name.c_str(), 0) != 0 && errno != ENOENT) return cannot(errno);
        return {};
    }
    const int fd = OpenFolderAt(folder.Fd(), name);
    if (fd < 0) return IsLinkAt(folder.Fd(), name) ? std::unexpected(LinkRefused(shown)) : cannot(errno);
    OpenFolder inside(fd, shown);
    const int listFd = fcntl(fd, F_DUPFD_CLOEXEC, 0);
    DIR* list = listFd >= 0 ? fdopendir(listFd) : nullptr;
    if (!list) {
        if (listFd >= 0) close(listFd);
        return cannot(errno);
    }
    std::vector<std::string> names;
    while (const dirent* entry = readdir(list))
        if (std::strcmp(entry->d_name, ".") != 0 && std::strcmp(entry->d_name, "..") != 0)
            names.emplace_back(entry->d_name);
    closedir(list);
    for (const std::string& child : names) {
        // A link inside is removed as a name (unlinkat), never followed.
        if (IsLinkAt(inside.Fd(), child)) {
            if (unlinkat(inside.Fd(), child.c_str(), 0) != 0 && errno != ENOENT) return cannot(errno);
            continue;
        }
        CB_TRY(RemoveTreeAt(inside, child));
    }
    if (unlinkat(folder.Fd(), name.c_str(), AT_REMOVEDIR) != 0 && errno != ENOENT) return cannot(errno);
    return {};
}

bool PlantedFsFailure(std::string_view op, std::string_view name) {
    static const std::string planted = [] {
        const char* value = std::getenv("CLOUDBENCH_TEST_FAIL_FS");
        return std::string(value ? value : "");
    }();
    return !planted.empty() && planted.size() == op.size() + 1 + name.size() && planted.starts_with(op) &&
           planted[op.size()] == ':' && planted.ends_with(name);
}

std::string TemporaryNameOf(const std::string& path) {
    const fs::path target(path);
    return (target.parent_path() / ("." + target.stem().string() + ".partial" + target.extension().string())).string();
}

Status ClaimOutputFolder(const std::string& dir, std::string_view command) {
    std::lock_guard guard(gMutex);
    const fs::path root = Normal(dir);
    if (FindClaim(root)) return {};
    auto cannot = [&](int error) { return MakeError(dir + ": cannot write: " + std::strerror(error)); };

    // The folder itself is opened by the name the user gave, following links in it: the user named it.
    // Every name below it is then opened from this descriptor, without following links.
    const int rootFd = OpenNamedFolder(dir);
    if (rootFd < 0) return cannot(errno);
    const OpenFolder folder(fcntl(rootFd, F_DUPFD_CLOEXEC, 0), dir);
    auto lockFd = OpenInPlace(folder, kLockName, WriteMode::InPlace);
    if (!lockFd) {
        close(rootFd);
        return std::unexpected(lockFd.error());
    }
    while (flock(*lockFd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EINTR) continue;
        const int error = errno;
        const std::string holder = error == EWOULDBLOCK ? DescribeHolder(*lockFd) : "";
        close(*lockFd);
        close(rootFd);
        if (error == EWOULDBLOCK) return MakeError(dir + ": in use by another cloudbench command" + holder);
        return MakeError(dir + ": cannot lock " + kLockName + ": " + std::strerror(error));
    }
    // Who holds it, for the message of a command that finds it locked; informative only, so a
    // failure here (a full disk) is not an error.
    const std::string holder = std::to_string(getpid()) + " " + std::string(command) + "\n";
    if (ftruncate(*lockFd, 0) == 0) (void)!pwrite(*lockFd, holder.data(), holder.size(), 0);

    const std::string journalName = ".cloudbench-" + std::string(command) + ".files";
    ClaimedFolder claim{root, dir, rootFd, *lockFd, -1, folder.ShownChild(journalName)};
    auto fail = [&](Error error) -> Status {
        if (claim.journalFd >= 0) close(claim.journalFd);
        close(claim.lockFd);
        close(claim.rootFd);
        return std::unexpected(std::move(error));
    };
    auto journalFd = OpenInPlace(folder, journalName, WriteMode::Append);
    if (!journalFd) return fail(journalFd.error());
    claim.journalFd = *journalFd;
    auto previous = ReadWhole(claim.journalFd, claim.journalPath);
    if (!previous) return fail(previous.error());
    // The journal is emptied only once every file it lists is gone: a claim cut short by a kill is redone.
    if (Status removed = RemovePreviousOutputs(folder, ParseJournal(*previous)); !removed) return fail(removed.error());
    if (ftruncate(claim.journalFd, 0) != 0) return fail(cannot(errno).error());
    gClaimed.push_back(std::move(claim));
    return {};
}

Status RecordOutput(const std::string& path, OutputEvent event) {
    std::lock_guard guard(gMutex);
    const fs::path target = Normal(path);
    ClaimedFolder* claim = FindClaimHolding(target);
    if (!claim) return {};
    const std::string line = std::string(1, char(event)) + " " + InsideRelative(claim->root, target) + "\n";
    if (line.find('\n') != line.size() - 1) return MakeError(path + ": cannot write: a line break in the name");
    if (!WriteAll(claim->journalFd, line))
        return MakeError(path + ": cannot write: cannot record it in " + claim->journalPath + ": " +
                         std::strerror(errno));
    return {};
}

std::vector<std::string> WrittenOutputs(const std::string& dir, std::string_view except) {
    std::lock_guard guard(gMutex);
    ClaimedFolder* claim = FindClaim(Normal(dir));
    if (!claim) return {};
    auto text = ReadWhole(claim->journalFd, claim->journalPath);
    if (!text) return {};
    // A file is in place when one of its placements did not fail (each NotPlaced follows its Placing).
    std::vector<std::string> order;
    std::map<std::string, int> inPlace;
    for (const JournalEntry& e : ParseJournal(*text)) {
        if (e.event == OutputEvent::Writing) continue;
        if (!inPlace.contains(e.relative)) order.push_back(e.relative);
        inPlace[e.relative] += e.event == OutputEvent::Placing ? 1 : -1;
    }
    std::vector<std::string> placed;
    for (const std::string& relative : order)
        if (inPlace[relative] > 0 && relative != except) placed.push_back(relative);
    return placed;
}

}  // namespace cb
