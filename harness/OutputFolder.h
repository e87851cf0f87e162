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
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/Error.h"

namespace cb {

// Locks `dir` (which must exist) for `command` ("run", "dump", ...), removes the
// outputs the previous `command` in `dir` recorded, and starts a new journal.
// Claiming a folder this process already holds does nothing. Errors:
//   "DIR: in use by another cloudbench command (pid N, COMMAND)" when another process holds it;
//   "DIR: cannot write: <strerror>" when the lock or journal cannot be created;
//   "DIR/FILE: cannot remove the previous run's file: <strerror>".
Status ClaimOutputFolder(const std::string& dir, std::string_view command);

// What Session::WriteAtomically records about a file it writes.
enum class OutputEvent : char {
    Writing = '+',  // before its temporary file is created: the next claim removes the temporary name
    Placing = '=',  // before the finished file is renamed into place: the next claim removes the file
    NotPlaced = '-',  // the rename failed: the file is not one of this command's outputs
};
// Appends `event` for `path` to the journal of the claimed folder that holds
// `path`; does nothing when no claimed folder holds it. The error names `path`.
Status RecordOutput(const std::string& path, OutputEvent event);

// The files this command (with any forked children) has placed in the claimed
// folder `dir` so far, relative to `dir`, in the order first placed, without
// `except`. Empty when `dir` is not claimed.
std::vector<std::string> WrittenOutputs(const std::string& dir, std::string_view except = {});

// The temporary name a file is written under before it is renamed into place:
// ".<stem>.partial<ext>" in the same folder.
std::string TemporaryNameOf(const std::string& path);

}  // namespace cb
