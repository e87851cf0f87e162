// The one rule for every path cloudbench reads or writes (docs/reliability.md,
// "Paths"), and the only code that opens files for it:
//
// - A path the user names (a scene, a results file or folder, a history, a
//   suite, a baseline, --out, --json, --keep) is taken as named: links on the
//   way to it are followed, since the user chose them. A file the user names
//   for writing is never written through a link at its own name.
// - A name found inside what the user gave (the frames a results.json lists,
//   the runs of a kept interleave, the arrays of a saved state) is opened
//   beneath the folder that holds it (OpenInputBeneath): a link that stays
//   inside the folder is followed, one that leads out of it (or an absolute
//   name, or ".." that climbs out) is refused, so a folder from elsewhere
//   cannot pull this machine's files into a report or a comparison.
// - Inside an output folder no link is followed at all (OpenFileAt,
//   OpenFolderAt: O_NOFOLLOW, one name at a time from the folder's descriptor).
// - Where a file is expected only a regular file is read or written: a FIFO,
//   a device, a folder or a socket is refused without blocking (every open is
//   O_NONBLOCK and checked on the descriptor), and an input is read only up to
//   its kind's size and what the process may still allocate.
//
// The checks are made on the opened descriptor, so a path swapped after a
// check cannot slip through. tests/check_path_calls.py fails the build's tests
// when a source file outside this module opens a file by other means.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/base/Error.h"

namespace cb {

// What an input is, for its size limit, the memory reading it takes, and its messages.
struct InputKind {
    std::string_view what;  // "a scene", "a history": "... more than the 16 MiB a scene may have"
    uint64_t maxBytes;
    // Bytes of memory per byte of file while it is read and parsed (the text and what is made of it): checked
    // against what the process may still allocate before the file is read.
    uint64_t memoryPerByte;
};

// JSON text parsed into nlohmann's DOM: a perf history of 3000 records (5.8 MB) took 31 MB more to read (5.4 per
// byte, the text kept beside the DOM); 8 leaves room for documents of many small numbers.
inline constexpr uint64_t kJsonMemoryPerByte = 8;

inline constexpr InputKind kSceneInput{"a scene", uint64_t(16) << 20, kJsonMemoryPerByte};
// results.json, conform.json, accuracy.json, sweep.json, count outputs, suites, state manifests: a thesis-high
// results.json is about 1 MiB.
inline constexpr InputKind kDocumentInput{"a cloudbench JSON file", uint64_t(256) << 20, kJsonMemoryPerByte};
// A perf history grows by one record (2 to 100 KiB) per recorded commit.
inline constexpr InputKind kHistoryInput{"a history", uint64_t(1) << 30, kJsonMemoryPerByte};
// A conform --baseline list: the text and one entry per line.
inline constexpr InputKind kBaselineInput{"a baseline", uint64_t(16) << 20, 4};
// What a tool cloudbench runs writes for it to read (valgrind's log and callgrind's dump): the text and its parse.
inline constexpr InputKind kToolOutputInput{"a tool's output", uint64_t(1) << 30, 4};
// A .npy array of a saved state or a dump, and the images the report embeds (at most a 16384^2 RGBA float
// image): the file and the array or pixels made of it.
inline constexpr InputKind kArrayInput{"an array or image", uint64_t(4) << 30, 2};

// "a FIFO", "a device", "a folder", "a socket", "not a file": what a path that is not a regular file is.
std::string_view FileKindName(unsigned mode);

// ---- Reading ---------------------------------------------------------------------

// A regular file of at most the kind's size, open for reading (closed with the object).
class OpenedInput {
  public:
    OpenedInput(int fd, uint64_t bytes) : mFd(fd), mBytes(bytes) {}
    OpenedInput(OpenedInput&& other) noexcept : mFd(other.mFd), mBytes(other.mBytes) { other.mFd = -1; }
    OpenedInput& operator=(OpenedInput&&) = delete;
    ~OpenedInput();
    int Fd() const { return mFd; }
    uint64_t Bytes() const { return mBytes; }  // its size when opened

  private:
    int mFd;
    uint64_t mBytes;
};

// Opens `path`, a path the user named, for reading when it is a regular file of at most `kind.maxBytes`. Errors:
//   "PATH: not a regular file (a FIFO)" (a device, a folder, a socket);
//   "PATH: N bytes, more than the M MiB KIND may have";
//   "PATH: reading its N bytes takes about X GiB, more than the Y GiB this process may still use (SOURCE)";
//   "PATH: cannot read the file: <strerror>".
Result<OpenedInput> OpenInputFile(const std::string& path, const InputKind& kind);

// Opens `name`, a relative name found inside the folder `folder` (a file a
// results.json lists, a run of a kept interleave), beneath that folder: as
// OpenInputFile, and further refused, shown as "FOLDER/NAME", when it leads
// out of the folder:
//   "FOLDER/NAME: leads out of FOLDER (a symbolic link, an absolute name or ..); cloudbench reads nothing
//    outside the folder it was given".
// Where the kernel cannot resolve beneath a folder (openat2, Linux 5.6), no link is followed at all.
Result<OpenedInput> OpenInputBeneath(const std::string& folder, const std::string& name, const InputKind& kind);

// The whole text of the file at `path` (OpenInputFile's checks and errors).
Result<std::string> ReadInputFile(const std::string& path, const InputKind& kind);
// The whole text of `name` beneath `folder` (OpenInputBeneath's checks and errors).
Result<std::string> ReadInputBeneath(const std::string& folder, const std::string& name, const InputKind& kind);
// The whole text of an opened input; `shown` names it in errors.
Result<std::string> ReadOpenedInput(OpenedInput& input, const std::string& shown, const InputKind& kind);

// ---- Writing ---------------------------------------------------------------------

// "PATH: is a symbolic link; cloudbench does not write through links (remove it)".
Error LinkRefused(const std::string& shown);

// How OpenFileAt opens a name in a folder for writing.
enum class WriteMode {
    CreateNew,  // created exclusively (a temporary file, a probe): fails on any name already there
    InPlace,    // read and written in place, created when missing (a lock, a journal)
    Append,     // appended to, created when missing (a log, a history)
};

// Opens the regular file `name` in the folder `folderFd` for writing, never
// through a link (O_NOFOLLOW) and without blocking on a FIFO; `shown` is
// "FOLDER/NAME" for messages. Errors:
//   LinkRefused(shown) for a link at the name;
//   "SHOWN: not a regular file (a FIFO); cloudbench writes only regular files (remove it)";
//   "SHOWN: cannot write: <strerror>".
Result<int> OpenFileAt(int folderFd, const std::string& shown, const std::string& name, WriteMode mode);

// The folder `name` in the folder `folderFd`, opened without following a link at the name
// (O_DIRECTORY | O_NOFOLLOW); -1 with errno set when it cannot be.
int OpenFolderAt(int folderFd, const std::string& name);

// The folder `path`, a folder the user named, opened by name with links followed; -1 with errno set.
int OpenNamedFolder(const std::string& path);

// Fails when `name` in the folder `folderFd` is there and is not a regular file, so that nothing is ever renamed
// over a link, a FIFO, a device or a folder: LinkRefused(shown), or
// "SHOWN: not a regular file (a device); cloudbench replaces only regular files (remove it)".
// A missing name is not an error.
Status RefuseNonFileAt(int folderFd, const std::string& shown, const std::string& name);

// Opens the file `path`, a file the user named, to append to it, created (with its folders) when missing: its
// folder is followed as named, the file itself is opened as OpenFileAt opens it (WriteMode::Append).
Result<int> OpenAppendFile(const std::string& path);

}  // namespace cb
