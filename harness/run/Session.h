// The work every command shares: the resolved scene, the output folder,
// atomic output files (each written under a temporary name in its folder,
// then renamed), the backends opened with their status, canonical read-backs
// and the provenance block of the JSON outputs (docs/results.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/platform/Command.h"
#include "harness/platform/Provenance.h"
#include "harness/run/Progress.h"  // the commands' progress lines

namespace cb {

enum class BackendStatus { Available, Unavailable, Unsupported };
std::string_view BackendStatusName(BackendStatus status);  // "available", "unavailable", "unsupported"

// One requested backend; `backend` is set only when it is available.
struct OpenedBackend {
    std::string name;
    std::unique_ptr<Backend> backend;
    BackendStatus status = BackendStatus::Unavailable;
    std::string reason;  // why it is unavailable or unsupported
    // PlannedBytes of the scene on this backend, when it was opened for a scene.
    std::optional<uint64_t> plannedBytes;
};

class Session {
  public:
    // Resolves options.scene and loads it with options.overrides. On a bad
    // scene prints the loader's "file: field: reason" and returns kExitBadScene;
    // an empty SCENE argument is refused first with kExitUsage.
    // The output folder defaults to out/<scene name>[/<outSubfolder>].
    static std::expected<std::unique_ptr<Session>, int> Open(const CommonOptions& options,
                                                             std::string_view outSubfolder);

    const CommonOptions& Options() const { return mOptions; }
    const Scene& GetScene() const { return mScene; }
    const std::string& ScenePath() const { return mScenePath; }
    const std::string& OutDir() const { return mOutDir; }

    // The same scene file with options.overrides followed by `extra`.
    Result<Scene> LoadVariant(std::span<const SceneOverride> extra) const;

    // Creates OutDir(), proves it writable with a probe file (CheckWritableFolder), then
    // locks it for this command and removes the previous run's outputs of the same command
    // (ClaimOutputFolder, harness/platform/OutputFolder.h). Prints "DIR: cannot write: <reason>" or
    // "DIR: in use by another cloudbench command (pid N, COMMAND)" and returns false on failure.
    // Every writing command calls it before opening backends or computing anything.
    bool MakeOutDir() const;

    // options.backends, or `defaults` when none were given.
    std::vector<std::string> RequestedBackends(const std::vector<std::string>& defaults) const;
    // Opens `names` and records them for the provenance. With `scene`, a
    // backend that lacks one of its stages is Unsupported, and one whose
    // available memory the scene's planned bytes exceed is Unavailable. With `report`,
    // each backend not available is named on stderr with the reason.
    std::vector<OpenedBackend> OpenBackends(const std::vector<std::string>& names, const Scene* scene = nullptr,
                                            bool report = true);

    // The temporary file a writer fills. `fd` is open for reading and writing at
    // offset 0 (owned by WriteAtomically); `path` is "/proc/self/fd/N" of that
    // descriptor, for a library that opens by name (OpenImageIO, a child
    // process): opening it opens this same file, so no link planted under the
    // temporary name can redirect the library's write (docs/results.md#output-folders).
    struct TemporaryFile {
        int fd = -1;
        std::string path;
    };
    // Writes `path` through `write`, which is given the temporary file
    // ".<stem>.partial<ext>" in the same folder, created exclusively
    // (O_CREAT | O_EXCL | O_NOFOLLOW) in the folder's descriptor after a stale
    // one is removed (OpenFolderForWriting, harness/platform/OutputFolder.h: inside an
    // output folder no link is followed). The finished file is checked (a
    // regular file, fsync'ed; a .npy reads back whole) and renamed to `path`
    // (renameat in the same folder). A symbolic link at `path` or at its
    // temporary name is refused, and so is a `path` that is a FIFO, a device
    // or a folder (core/base/PathPolicy.h RefuseNonFileAt). On any failure the temporary file is removed,
    // `path` keeps its old contents, and the error names `path` (never the
    // temporary name) and the system's reason (strerror of errno).
    static Status WriteAtomically(const std::string& path, const std::function<Status(const TemporaryFile&)>& write);
    // Errors read "PATH: cannot write: <strerror(errno)>".
    static Status WriteText(const std::string& path, const std::string& text);
    // Writes `doc` with a "provenance" block added.
    Status WriteJson(const std::string& path, nlohmann::json doc) const;
    // Reads `buffer` back and writes it as .npy shaped (nz, ny, nx).
    static Status WriteNpy(const std::string& path, Backend& backend, const Buffer& buffer);

    // The backends opened so far, for the provenance.
    const std::vector<BackendProvenance>& BackendRecords() const { return mBackends; }
    // Records a backend opened elsewhere (in an isolated child); one already recorded by name is kept.
    void AddBackendRecord(BackendProvenance record);

    // The provenance of this run: build, machine, backends opened so far, scene, command line.
    nlohmann::json Provenance() const;

  private:
    Session(const CommonOptions& options, std::string scenePath, Scene scene, std::string outDir);

    const CommonOptions& mOptions;
    std::string mScenePath;
    Scene mScene;
    std::string mOutDir;
    std::vector<BackendProvenance> mBackends;
};

// Creates `dir` and its parents (inside a claimed output folder one name at a
// time, refusing a link: OpenFolderForWriting); the error reads
// "DIR: cannot write: <strerror(errno)>" or names the link.
Status MakeFolder(const std::string& dir);
// Creates `dir` and its parents, then creates (exclusively, never through a
// link), writes and removes a probe file in it; the error reads
// "DIR: cannot write: <strerror(errno)>".
Status CheckWritableFolder(const std::string& dir);

// Reads a buffer back in canonical form; adds the time it took to `timesMs` when given.
template <typename T>
Result<std::vector<T>> Download(Backend& backend, const Buffer& buffer, std::vector<double>* timesMs = nullptr) {
    std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
    const auto start = std::chrono::steady_clock::now();
    CB_TRY(backend.Download(buffer, std::as_writable_bytes(std::span(data))));
    if (timesMs)
        timesMs->push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    return data;
}

}  // namespace cb
