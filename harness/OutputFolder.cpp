#include "harness/OutputFolder.h"
#include "harness/PosixIo.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>

namespace cb {
namespace fs = std::filesystem;
namespace {

constexpr const char* kLockName = ".cloudbench.lock";

struct ClaimedFolder {
    fs::path root;  // absolute and lexically normal
    std::string dir;  // as the command was given it, for messages
    int lockFd = -1;  // held open (and locked) until the process exits
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

ClaimedFolder* FindClaimHolding(const fs::path& path) {
    for (ClaimedFolder& claim : gClaimed)
        if (!InsideRelative(claim.root, path).empty()) return &claim;
    return nullptr;
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

// Removes `path` (a file or a link, never a folder); a missing file is not an error.
Status RemoveIfPresent(const std::string& path) {
    if (unlink(path.c_str()) == 0 || errno == ENOENT) return {};
    return MakeError(path + ": cannot remove the previous run's file: " + std::strerror(errno));
}

// Removes what the previous journal lists: the placed JSON outputs first (they
// name the other files, so a removal cut short never leaves one naming a file
// already gone), then the other placed files, then every temporary name, then
// the folders that removal left empty.
Status RemovePreviousOutputs(const std::string& dir, const std::vector<JournalEntry>& entries) {
    std::vector<std::string> placed, temporaries;
    std::set<std::string> seenPlaced, seenTemporary;
    for (const JournalEntry& e : entries) {
        if (e.event == OutputEvent::Placing && seenPlaced.insert(e.relative).second) placed.push_back(e.relative);
        if (seenTemporary.insert(e.relative).second) temporaries.push_back(e.relative);
    }
    std::stable_partition(placed.begin(), placed.end(),
                          [](const std::string& r) { return fs::path(r).extension() == ".json"; });
    for (const std::string& relative : placed) CB_TRY(RemoveIfPresent(dir + "/" + relative));
    std::set<std::string, std::greater<>> folders;  // deepest first
    for (const std::string& relative : temporaries) {
        CB_TRY(RemoveIfPresent(TemporaryNameOf(dir + "/" + relative)));
        for (fs::path parent = fs::path(relative).parent_path(); parent.has_relative_path();
             parent = parent.parent_path())
            folders.insert(parent.generic_string());
    }
    for (const std::string& folder : folders) rmdir((dir + "/" + folder).c_str());  // only when empty
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

}  // namespace

std::string TemporaryNameOf(const std::string& path) {
    const fs::path target(path);
    return (target.parent_path() / ("." + target.stem().string() + ".partial" + target.extension().string()))
        .string();
}

Status ClaimOutputFolder(const std::string& dir, std::string_view command) {
    std::lock_guard guard(gMutex);
    const fs::path root = Normal(dir);
    if (FindClaim(root)) return {};
    auto cannot = [&](int error) { return MakeError(dir + ": cannot write: " + std::strerror(error)); };

    const std::string lockPath = dir + "/" + kLockName;
    const int lockFd = open(lockPath.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lockFd < 0) return cannot(errno);
    while (flock(lockFd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EINTR) continue;
        const int error = errno;
        const std::string holder = error == EWOULDBLOCK ? DescribeHolder(lockFd) : "";
        close(lockFd);
        if (error == EWOULDBLOCK) return MakeError(dir + ": in use by another cloudbench command" + holder);
        return MakeError(dir + ": cannot lock " + kLockName + ": " + std::strerror(error));
    }
    // Who holds it, for the message of a command that finds it locked; informative only, so a
    // failure here (a full disk) is not an error.
    const std::string holder = std::to_string(getpid()) + " " + std::string(command) + "\n";
    if (ftruncate(lockFd, 0) == 0) (void)!pwrite(lockFd, holder.data(), holder.size(), 0);

    ClaimedFolder claim{root, dir, lockFd, -1, dir + "/.cloudbench-" + std::string(command) + ".files"};
    claim.journalFd = open(claim.journalPath.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (claim.journalFd < 0) {
        const int error = errno;
        close(lockFd);
        return cannot(error);
    }
    auto fail = [&](Error error) -> Status {
        close(claim.journalFd);
        close(lockFd);
        return std::unexpected(std::move(error));
    };
    auto previous = ReadWhole(claim.journalFd, claim.journalPath);
    if (!previous) return fail(previous.error());
    // The journal is emptied only once every file it lists is gone: a claim cut short by a kill is redone.
    if (Status removed = RemovePreviousOutputs(dir, ParseJournal(*previous)); !removed) return fail(removed.error());
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
    if (line.find('\n') != line.size() - 1)
        return MakeError(path + ": cannot write: a line break in the name");
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
