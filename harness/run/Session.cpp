#include "harness/run/Session.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/base/Npy.h"
#include "core/plan/MemoryPlan.h"
#include "core/plan/SceneLoad.h"
#include "harness/platform/OutputFolder.h"
#include "harness/platform/PosixIo.h"

namespace cb {
namespace fs = std::filesystem;

std::string_view BackendStatusName(BackendStatus status) {
    switch (status) {
        case BackendStatus::Available:
            return "available";
        case BackendStatus::Unavailable:
            return "unavailable";
        case BackendStatus::Unsupported:
            return "unsupported";
    }
    return "unknown";
}

Status MakeFolder(const std::string& dir) {
    auto folder = OpenFolderForWriting(dir, /*create=*/true);
    if (!folder) return std::unexpected(folder.error());
    return {};
}

Session::Session(const CommonOptions& options, std::string scenePath, Scene scene, std::string outDir)
    : mOptions(options), mScenePath(std::move(scenePath)), mScene(std::move(scene)), mOutDir(std::move(outDir)) {}

std::expected<std::unique_ptr<Session>, int> Session::Open(const CommonOptions& options,
                                                           std::string_view outSubfolder) {
    // The one command-line check left to here: main() stores the SCENE argument unchecked.
    if (options.scene && options.scene->empty()) {
        std::fprintf(stderr, "cloudbench: SCENE: must not be empty (leave it out for %s)\n", kDefaultScene);
        return std::unexpected(kExitUsage);
    }
    Result<std::string> path = ResolveScenePath(options.scene.value_or(kDefaultScene));
    if (!path) {
        std::fprintf(stderr, "cloudbench: %s\n", path.error().message.c_str());
        return std::unexpected(kExitBadScene);
    }
    Result<Scene> scene = LoadScene(*path, options.overrides);
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message.c_str());
        return std::unexpected(kExitBadScene);
    }
    std::string outDir = options.outDir;
    if (outDir.empty()) outDir = "out/" + scene->name + (outSubfolder.empty() ? "" : "/" + std::string(outSubfolder));
    return std::unique_ptr<Session>(new Session(options, std::move(*path), std::move(*scene), std::move(outDir)));
}

Result<Scene> Session::LoadVariant(std::span<const SceneOverride> extra) const {
    std::vector<SceneOverride> all = mOptions.overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    return LoadScene(mScenePath, all);
}

Status CheckWritableFolder(const std::string& dir) {
    auto folder = OpenFolderForWriting(dir, /*create=*/true);
    if (!folder) return std::unexpected(folder.error());
    auto cannot = [&](int error) { return MakeError(dir + ": cannot write: " + std::strerror(error)); };
    // A probe file proves that files can be created, written and removed here.
    const std::string probe = ".cloudbench-probe-" + std::to_string(getpid());
    CB_TRY(RemoveFileAt(*folder, probe, "a stale probe file"));
    auto opened = OpenFileAt(folder->Fd(), folder->ShownChild(probe), probe, WriteMode::CreateNew);
    if (!opened) {
        // The probe is this process's own name: a failure to create it is the folder's, and names the folder.
        const std::string message = opened.error().message, shown = folder->ShownChild(probe);
        return MakeError(message.starts_with(shown) ? dir + message.substr(shown.size()) : message);
    }
    const int fd = *opened;
    const char byte = 0;
    const bool wrote = write(fd, &byte, 1) == 1;
    int error = wrote ? 0 : errno;
    if (close(fd) != 0 && error == 0) error = errno;
    if (unlinkat(folder->Fd(), probe.c_str(), 0) != 0 && error == 0) error = errno;
    if (error != 0) return cannot(error);
    return {};
}

bool Session::MakeOutDir() const {
    // The command's name is argv[1] (main.cpp); it names the journal of the files it writes.
    const std::string command = mOptions.commandLine.size() > 1 ? mOptions.commandLine[1] : "command";
    Status s = CheckWritableFolder(mOutDir);
    if (s) s = ClaimOutputFolder(mOutDir, command);
    if (!s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return false;
    }
    return true;
}

std::vector<std::string> Session::RequestedBackends(const std::vector<std::string>& defaults) const {
    return mOptions.backends.empty() ? defaults : mOptions.backends;
}

std::vector<OpenedBackend> Session::OpenBackends(const std::vector<std::string>& names, const Scene* scene,
                                                 bool report) {
    std::vector<OpenedBackend> out;
    for (const std::string& name : names) {
        OpenedBackend opened{name, nullptr, BackendStatus::Unavailable, "", std::nullopt};
        BackendProvenance record{name, "", "", ""};
        auto backend = CreateBackend(name, mOptions.Backend());
        if (!backend) {
            opened.reason = backend.error().message;
            if (report) std::fprintf(stderr, "backend %s unavailable: %s\n", name.c_str(), opened.reason.c_str());
        } else {
            record.device = (*backend)->Device();
            // A backend that lacks one of the scene's stages is skipped, not failed.
            std::string missing;
            for (Stage stage : kAllStages)
                if (scene && scene->stages.Has(stage) && !(*backend)->Supports(stage))
                    missing += (missing.empty() ? "" : ", ") + std::string(StageName(stage));
            Status fits;
            if (scene) {
                opened.plannedBytes = PlannedBytes(*scene, **backend);
                fits = CheckDeviceLimits(*scene, **backend);
                if (fits) fits = CheckPlannedBytesFit(*scene, **backend);
            }
            if (missing.empty() && fits) {
                opened.status = BackendStatus::Available;
                opened.backend = std::move(*backend);
            } else if (missing.empty()) {
                opened.reason = fits.error().message;
                if (report) std::fprintf(stderr, "backend %s unavailable: %s\n", name.c_str(), opened.reason.c_str());
            } else {
                opened.status = BackendStatus::Unsupported;
                opened.reason = name + " does not implement " + missing + " yet";
                if (report) std::fprintf(stderr, "backend %s skipped: %s\n", name.c_str(), opened.reason.c_str());
            }
        }
        record.status = BackendStatusName(opened.status);
        record.reason = opened.reason;
        mBackends.push_back(std::move(record));
        out.push_back(std::move(opened));
    }
    return out;
}

void Session::AddBackendRecord(BackendProvenance record) {
    for (const BackendProvenance& known : mBackends)
        if (known.name == record.name) return;
    mBackends.push_back(std::move(record));
}

namespace {

// Replaces every occurrence of `from` in `text` with `to`.
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
    for (size_t at = text.find(from); !from.empty() && at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

// Checks a finished temporary file before it is renamed into place: it must be
// a regular file whose data reach the disk (fsync), and a .npy must read back
// whole, which catches a write lost in a stream's final flush. Errors name `path`.
Status CheckFinished(const Session::TemporaryFile& temp, const std::string& path) {
    auto cannot = [&](const std::string& why) { return MakeError(path + ": cannot write: " + why); };
    struct stat info {};
    if (fstat(temp.fd, &info) != 0) return cannot(std::strerror(errno));
    if (!S_ISREG(info.st_mode)) return cannot("the temporary file is not a regular file");
    if (fsync(temp.fd) != 0) return cannot(std::strerror(errno));
    if (fs::path(path).extension() == ".npy")
        if (auto back = ReadNpy(temp.path); !back)
            return cannot("it does not read back whole (" + ReplaceAll(back.error().message, temp.path, path) + ")");
    return {};
}

// Whether the file system holding the folder `fd` has no block left for an unprivileged writer.
bool FileSystemFull(int fd) {
    struct statvfs info {};
    return fstatvfs(fd, &info) == 0 && info.f_bavail == 0;
}

}  // namespace

Status Session::WriteAtomically(const std::string& path, const std::function<Status(const TemporaryFile&)>& write) {
    const fs::path target(path);
    const std::string name = target.filename().string();
    if (name.empty() || name == "." || name == "..") return MakeError(path + ": cannot write: not a file name");
    // Same folder (so the rename cannot cross file systems), same extension (image writers go by it).
    const std::string tempName = TemporaryNameOf(name);
    CB_TRY(RecordOutput(path, OutputEvent::Writing));  // the output folder's journal (harness/platform/OutputFolder.h)
    auto folder = OpenFolderForWriting(target.parent_path().string(), /*create=*/false);
    if (!folder) return std::unexpected(folder.error());
    CB_TRY(RefuseNonFileAt(folder->Fd(), path, name));  // a link, a FIFO, a device or a folder is never replaced
    // A temporary file left by a killed write is removed (a link there is refused), then the new one is
    // created exclusively: O_EXCL fails on any name already there, a link included, so nothing is opened
    // through a link planted after the removal.
    CB_TRY(RemoveFileAt(*folder, tempName, "a stale temporary file"));
    TemporaryFile temp;
    auto created = OpenFileAt(folder->Fd(), folder->ShownChild(tempName), tempName, WriteMode::CreateNew);
    if (!created) {
        if (Status link = RefuseLinkAt(*folder, tempName); !link) return link;
        return MakeError(ReplaceAll(created.error().message, folder->ShownChild(tempName), path));
    }
    temp.fd = *created;
    temp.path = "/proc/self/fd/" + std::to_string(temp.fd);
    errno = 0;
    Status written =
        PlantedFsFailure("write", name) ? MakeError(path + ": cannot write: " + std::strerror(EIO)) : write(temp);
    const int writeErrno = errno;  // what the failed system call said, when the writer does not say it
    if (written) written = CheckFinished(temp, path);
    // The temporary name must still be the file created above: what took its place since (a link) is never
    // renamed into place.
    struct stat mine {
    }, named{};
    if (written &&
        (fstat(temp.fd, &mine) != 0 || fstatat(folder->Fd(), tempName.c_str(), &named, AT_SYMLINK_NOFOLLOW) != 0 ||
         mine.st_ino != named.st_ino || mine.st_dev != named.st_dev))
        written = MakeError(path + ": cannot write: its temporary file " + folder->ShownChild(tempName) +
                            " was replaced while it was written");
    if (close(temp.fd) != 0 && written) written = MakeError(path + ": cannot write: " + std::strerror(errno));
    if (written) written = RecordOutput(path, OutputEvent::Placing);
    const bool plantedRename = written && PlantedFsFailure("rename", name);
    if (plantedRename) errno = EIO;
    if (written && (plantedRename || renameat(folder->Fd(), tempName.c_str(), folder->Fd(), name.c_str()) != 0)) {
        const int error = errno;
        (void)RecordOutput(path, OutputEvent::NotPlaced);
        written = MakeError(path + ": cannot move the finished file into place: " + std::strerror(error));
    }
    if (!written) {
        unlinkat(folder->Fd(), tempName.c_str(), 0);  // the old file, if any, stays as it was
        std::string message = ReplaceAll(written.error().message, temp.path, path);
        // A library writer (OIIO) may fail without saying why, and leave a stale errno from
        // an unrelated call: a full file system is checked first, and named as such.
        const int reason = FileSystemFull(folder->Fd()) ? ENOSPC : writeErrno;
        if (reason != 0 && message.find(std::strerror(reason)) == std::string::npos)
            message += std::string(": ") + std::strerror(reason);
        return MakeError(message);
    }
    return {};
}

Status Session::WriteText(const std::string& path, const std::string& text) {
    return WriteAtomically(path, [&](const TemporaryFile& temp) -> Status {
        if (!WriteAll(temp.fd, text)) return MakeError(path + ": cannot write: " + std::strerror(errno));
        return {};
    });
}

Status Session::WriteJson(const std::string& path, nlohmann::json doc) const {
    doc["provenance"] = Provenance();
    return WriteText(path, doc.dump(1) + "\n");
}

Status Session::WriteNpy(const std::string& path, Backend& backend, const Buffer& buffer) {
    std::vector<std::byte> data(buffer.CanonicalBytes());
    CB_TRY(backend.Download(buffer, data));
    const Extent3 e = buffer.Extent();
    const uint64_t shape[3] = {e.nz, e.ny, e.nx};
    const NpyType type = buffer.Format() == BufferFormat::F32 ? NpyType::F32 : NpyType::U8;
    return WriteAtomically(path,
                           [&](const TemporaryFile& temp) { return cb::WriteNpy(temp.fd, path, type, shape, data); });
}

nlohmann::json Session::Provenance() const {
    return MakeProvenance(mOptions.commandLine, {mScenePath, &mScene, mOptions.overrides}, mBackends);
}

}  // namespace cb
