#include "harness/Session.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/MemoryPlan.h"
#include "core/Npy.h"

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
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return MakeError(dir + ": cannot create the output folder: " + ec.message());
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
    std::string path = ResolveScenePath(options.scene.value_or(kDefaultScene));
    Result<Scene> scene = LoadScene(path, options.overrides);
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message.c_str());
        return std::unexpected(kExitBadScene);
    }
    std::string outDir = options.outDir;
    if (outDir.empty()) outDir = "out/" + scene->name + (outSubfolder.empty() ? "" : "/" + std::string(outSubfolder));
    return std::unique_ptr<Session>(new Session(options, std::move(path), std::move(*scene), std::move(outDir)));
}

Result<Scene> Session::LoadVariant(std::span<const SceneOverride> extra) const {
    std::vector<SceneOverride> all = mOptions.overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    return LoadScene(mScenePath, all);
}

Status CheckWritableFolder(const std::string& dir) {
    auto cannot = [&](int error) { return MakeError(dir + ": cannot write: " + std::strerror(error)); };
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return cannot(ec.value());
    // A probe file proves that files can be created, written and removed here.
    const std::string probe = dir + "/.cloudbench-probe-" + std::to_string(getpid());
    const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return cannot(errno);
    const char byte = 0;
    const bool wrote = write(fd, &byte, 1) == 1;
    int error = wrote ? 0 : errno;
    if (close(fd) != 0 && error == 0) error = errno;
    if (unlink(probe.c_str()) != 0 && error == 0) error = errno;
    if (error != 0) return cannot(error);
    return {};
}

bool Session::MakeOutDir() const {
    if (Status s = CheckWritableFolder(mOutDir); !s) {
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
                fits = CheckPlannedBytesFit(*scene, **backend);
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

Status Session::WriteAtomically(const std::string& path, const std::function<Status(const std::string&)>& write) {
    const fs::path target(path);
    // Same folder (so the rename cannot cross file systems), same extension (image writers go by it).
    const fs::path temp =
        target.parent_path() / ("." + target.stem().string() + ".partial" + target.extension().string());
    Status written = write(temp.string());
    std::error_code ec;
    if (written) fs::rename(temp, target, ec);
    if (!written || ec) {
        fs::remove(temp, ec);
        if (!written) return written;
        return MakeError(path + ": cannot move the finished file into place: " + ec.message());
    }
    return {};
}

Status Session::WriteText(const std::string& path, const std::string& text) {
    return WriteAtomically(path, [&](const std::string& temp) -> Status {
        std::ofstream file(temp);
        file << text;
        file.close();
        if (!file) return MakeError(path + ": cannot write");
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
    return WriteAtomically(path, [&](const std::string& temp) { return cb::WriteNpy(temp, type, shape, data); });
}

nlohmann::json Session::Provenance() const {
    return MakeProvenance(mOptions.commandLine, {mScenePath, &mScene, mOptions.overrides}, mBackends);
}

Progress::Progress(std::string label, uint32_t total, bool quiet)
    : mLabel(std::move(label)), mTotal(total), mQuiet(quiet), mTty(isatty(STDERR_FILENO)) {}

void Progress::Update(uint32_t done) {
    if (mQuiet || mTotal < 20) return;
    if (mTty) {
        std::fprintf(stderr, "\r%s: step %u/%u", mLabel.c_str(), done, mTotal);
        if (done == mTotal) std::fprintf(stderr, "\n");
    } else if (done * 10 / mTotal != (done - 1) * 10 / mTotal) {
        std::fprintf(stderr, "%s: step %u/%u\n", mLabel.c_str(), done, mTotal);
    }
}

}  // namespace cb
