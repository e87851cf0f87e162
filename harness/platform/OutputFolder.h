// The claim a writing command holds on its output folder (docs/results.md#output-folders):
//
// - a lock: an exclusive, non-blocking flock on DIR/.cloudbench.lock, held for
//   the life of the process, so that two commands never write into one folder
//   at once. The kernel drops it when the last holder exits, however it exits:
//   a killed command never leaves a stale lock. The descriptor is O_CLOEXEC; a
//   forked child (a backend run in a process of its own) shares the lock, which
//   is released only when the parent and every such child have exited.
// - a journal, DIR/.cloudbench-<command>.files, of every file the command
//   writes, each recorded before it is written. When the next run of the same
//   command claims the folder, it first removes what the journal lists (the
//   JSON outputs first, then the rest, then the temporary files of writes cut
//   short), so a previous run's outputs never survive next to the new ones,
//   even after a kill. Nothing the journal does not list is removed.
//
// No link is followed inside the folder: the folder is opened once (by the
// name the user gave, links in it followed: the user named it) and every file
// and subfolder cloudbench creates, replaces, locks or removes in it is opened
// from that descriptor one name at a time with O_NOFOLLOW. A symbolic link at
// any such name is refused with LinkRefused's message, so a link planted in a
// shared folder (/tmp, a CI cache) cannot make a command write, truncate or
// remove anything outside it. The same rule holds for a file the user names
// directly (report -o FILE, perf ... --json FILE): its folder is followed, a
// link at the file's own name is refused.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
#include "core/base/PathPolicy.h"

namespace cb {

// Locks `dir` (which must exist) for `command` ("run", "dump", ...), removes the
// outputs the previous `command` in `dir` recorded, and starts a new journal.
// Claiming a folder this process already holds does nothing. A journal entry
// that now names a folder (the journal only ever lists files) is left in
// place with a warning on stderr, and the claim goes on. Errors:
//   "DIR: in use by another cloudbench command (pid N, COMMAND)" when another process holds it;
//   "DIR: cannot write: <strerror>" when the lock or journal cannot be created;
//   "DIR/NAME: is a symbolic link; cloudbench does not write through links (remove it)" for the lock, the
//   journal, or a name (or a folder on the way to it) the journal lists;
//   "DIR/FILE: cannot remove the previous run's file: <strerror>".
Status ClaimOutputFolder(const std::string& dir, std::string_view command);

// What Session::WriteAtomically records about a file it writes.
enum class OutputEvent : char {
    Writing = '+',    // before its temporary file is created: the next claim removes the temporary name
    Placing = '=',    // before the finished file is renamed into place: the next claim removes the file
    NotPlaced = '-',  // the rename failed: the file is not one of this command's outputs
};
// Appends `event` for `path` to the journal of the claimed folder that holds
// `path`; does nothing when no claimed folder holds it. The error names `path`.
Status RecordOutput(const std::string& path, OutputEvent event);

// The files this command (with any forked children) has placed in the claimed
// folder `dir` so far, relative to `dir`, in the order first placed, without
// `except`. Empty when `dir` is not claimed.
std::vector<std::string> WrittenOutputs(const std::string& dir, std::string_view except = {});

// The test-only switch CLOUDBENCH_TEST_FAIL_FS=<op>:<NAME>, read once (docs/cli.md): whether `op` ("write",
// "rename" or "remove") on a file whose own name is NAME (no folder) is to fail as with EIO. Never set otherwise.
bool PlantedFsFailure(std::string_view op, std::string_view name);

// The temporary name a file is written under before it is renamed into place:
// ".<stem>.partial<ext>" in the same folder.
std::string TemporaryNameOf(const std::string& path);

// A folder open for creating, replacing and removing the names in it (an
// O_DIRECTORY descriptor, closed with the object), and the path messages show it by.
class OpenFolder {
  public:
    OpenFolder(int fd, std::string shown) : mFd(fd), mShown(std::move(shown)) {}
    OpenFolder(OpenFolder&& other) noexcept : mFd(other.mFd), mShown(std::move(other.mShown)) { other.mFd = -1; }
    OpenFolder& operator=(OpenFolder&& other) noexcept;
    ~OpenFolder();
    int Fd() const { return mFd; }
    const std::string& Shown() const { return mShown; }
    // "SHOWN/NAME", or NAME alone when the folder is shown as ".".
    std::string ShownChild(std::string_view name) const;

  private:
    int mFd;
    std::string mShown;
};

// Opens the folder `dir` to write in it. Inside a folder this process has
// claimed, the folders below the claimed one are opened from its descriptor one
// at a time with O_DIRECTORY | O_NOFOLLOW, each created (mkdirat) first when
// `create` and missing; a link among them is refused (LinkRefused). Any other
// folder is one the user named: it is created with its parents when `create`
// and opened by name, links in its path followed. Errors name the folder:
//   "PATH: is a symbolic link; ...", "PATH: cannot write: <strerror>".
Result<OpenFolder> OpenFolderForWriting(const std::string& dir, bool create);

// Fails with LinkRefused when `name` in `folder` is a symbolic link; a missing name is not an error.
Status RefuseLinkAt(const OpenFolder& folder, const std::string& name);

// Removes the file `name` from `folder` (unlinkat, which never follows a link)
// when it is there; a missing name is not an error. A link is refused
// (LinkRefused); a folder is not removed: the error says so, with `what`
// ("the previous run's file") naming the role of the file in the message.
Status RemoveFileAt(const OpenFolder& folder, const std::string& name, std::string_view what);

// Removes `name` from `folder` and, when it is a folder, everything in it,
// walking down with O_NOFOLLOW (links inside it are removed as names, never
// followed). A link at `name` itself is refused; a missing name is not an error.
Status RemoveTreeAt(const OpenFolder& folder, const std::string& name);

}  // namespace cb
