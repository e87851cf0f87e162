// The one way cloudbench opens a file it was given to read (scenes, results,
// histories, count outputs, sweep shards, suites, baselines, saved states,
// images for the report; docs/cli.md#input-files): only a regular file of at
// most the kind's size is read, so a FIFO cannot block, a device cannot fill
// memory and a folder is not mistaken for a file. The check is made on the
// opened descriptor (opened O_NONBLOCK), so a path swapped after a check
// cannot slip through.
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

// Opens `path` for reading when it is a regular file of at most `kind.maxBytes`; the errors of ReadInputFile.
Result<OpenedInput> OpenInputFile(const std::string& path, const InputKind& kind);

// The whole text of the file at `path`. Errors:
//   "PATH: not a regular file (a FIFO)" (a device, a folder, a socket);
//   "PATH: N bytes, more than the M MiB KIND may have";
//   "PATH: reading its N bytes takes about X GiB, more than the Y GiB this process may still use (SOURCE)";
//   "PATH: cannot read the file: <strerror>".
Result<std::string> ReadInputFile(const std::string& path, const InputKind& kind);

// The same checks for a file a library opens by name (OpenImageIO, the .npy reader), without reading it.
Status CheckInputFile(const std::string& path, const InputKind& kind);

}  // namespace cb
