#include "harness/run/SimulationState.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sstream>

#include "core/base/Npy.h"
#include "harness/platform/OutputFolder.h"
#include "harness/platform/PosixIo.h"
#include "harness/run/RunTransfer.h"
#include "harness/run/SimulationStateDetail.h"

namespace cb {

namespace fs = std::filesystem;
using nlohmann::json;

using namespace simulation_state_detail;

namespace {

Status FsyncFd(int fd, const std::string& shown) {
    if (fsync(fd) != 0) return MakeError(shown + ": cannot write: " + std::strerror(errno));
    return {};
}

// Creates the file `name` in `folder` (exclusively, never through a link) and writes it through `write`.
Status WriteNewFile(const OpenFolder& folder, const std::string& name, const std::function<Status(int)>& write) {
    const std::string shown = folder.ShownChild(name);
    auto opened = OpenFileAt(folder.Fd(), shown, name, WriteMode::CreateNew);
    if (!opened) return std::unexpected(opened.error());
    const int fd = *opened;
    Status written = write(fd);
    if (written) written = FsyncFd(fd, shown);
    if (close(fd) != 0 && written) written = MakeError(shown + ": cannot write: " + std::strerror(errno));
    return written;
}

json RasterJson(const std::vector<RasterEllipsoid>& list) {
    json a = json::array();
    for (const RasterEllipsoid& e : list)
        a.push_back(
            {e.center[0], e.center[1], e.center[2], e.semiAxes[0], e.semiAxes[1], e.semiAxes[2], e.cosYaw, e.sinYaw});
    return a;
}

json OptionalJson(const std::optional<uint32_t>& v) { return v ? json(*v) : json(nullptr); }

}  // namespace

std::string SceneSettingsHash(json resolved) {
    if (resolved.is_object()) {
        resolved.erase("steps");
        resolved.erase("description");
    }
    const std::string text = resolved.dump();
    return Hex64(Fnv1a64(std::as_bytes(std::span(text))));
}

// The friend of Simulation that reads and writes its private state.
struct SimulationStateAccess {
    // The members saved as they are, each simulation member beside its state field: the one
    // list Capture (copy(from sim, to state)) and Restore (copy(to sim, from state)) share.
    template <typename Sim, typename State, typename Copy>
    static void PlainFields(Sim& sim, State& s, Copy&& copy) {
        copy(sim.mRaster, s.raster);
        copy(sim.mRasterAhead, s.rasterAhead);
        copy(sim.mLastRendered, s.lastRendered);
        copy(sim.mFramesDrawn, s.framesDrawn);
        copy(sim.mLastCoveredColumns, s.lastCoveredColumns);
        copy(sim.mInputsAtLastRun, s.inputsAtLastRun);
        copy(sim.mAheadComputed, s.aheadComputed);
        copy(sim.mAdvanceOwed, s.advanceOwed);
        copy(sim.mAhead, s.aheadRecord);
    }
    // The same for one resource's slot.
    template <typename Slot, typename State, typename Copy>
    static void SlotFields(Slot& slot, State& s, Resource r, Copy&& copy) {
        copy(slot.version, s.versions[size_t(r)]);
        copy(slot.ahead, s.ahead[size_t(r)]);
        copy(slot.previousIsCurrent, s.previousIsCurrent[size_t(r)]);
    }

    static Result<SimulationState> Capture(const Simulation& sim, std::string_view sceneHash) {
        if (sim.mBatchOpen) return MakeError("saving the state: a batch is open (save between steps)");
        SimulationState s;
        s.sceneName = sim.mScene.name;
        s.sceneHash = std::string(sceneHash);
        s.step = sim.mStep;
        for (Resource r : kAllResources) {
            const Simulation::Slot& slot = sim.mSlots[size_t(r)];
            auto add = [&](const std::unique_ptr<Buffer>& buffer, BufferRole role, uint32_t camera) -> Status {
                if (!buffer) return {};
                SavedBuffer saved{r, role, camera, buffer->Format(), buffer->Extent(), {}};
                saved.data.resize(buffer->CanonicalBytes());
                CB_TRY(sim.mBackend.Download(*buffer, saved.data));
                s.buffers.push_back(std::move(saved));
                return {};
            };
            for (size_t n = 0; n < slot.current.size(); ++n)
                CB_TRY(add(slot.current[n], BufferRole::Current, uint32_t(n)));
            // `previous` is not saved: the next step either rewrites it (its writer runs and swaps the current value
            // in) or does not read it (the writer skips: previous_is_current).
            // The next step's third set holds a value only while time-sliced work is ahead.
            if (slot.ahead) {
                CB_TRY(add(slot.next, BufferRole::Next, 0));
                CB_TRY(add(slot.pending, BufferRole::Pending, 0));
            }
            SlotFields(slot, s, r, [](const auto& from, auto& to) { to = from; });
        }
        s.ellipsoids = sim.mEllipsoids.Items();
        s.rngState = sim.mEllipsoids.Rng().StateWord();
        s.rngIncrement = sim.mEllipsoids.Rng().Increment();
        s.listStep = sim.mEllipsoids.ListStep();
        PlainFields(sim, s, [](const auto& from, auto& to) { to = from; });
        return s;
    }

    static Status Restore(Simulation& sim, const SimulationState& s) {
        if (sim.mStep != 0 || sim.mLastRendered) return MakeError("restoring a state: the simulation has already run");
        if (s.sceneName != sim.mScene.name)
            return MakeError("restoring a state: saved from scene '" + s.sceneName + "', not '" + sim.mScene.name +
                             "'");
        for (const SavedBuffer& saved : s.buffers) {
            Simulation::Slot& slot = sim.mSlots[size_t(saved.resource)];
            Buffer* target = nullptr;
            switch (saved.role) {
                case BufferRole::Current:
                    if (saved.camera < slot.current.size()) target = slot.current[saved.camera].get();
                    break;
                case BufferRole::Next:
                    target = slot.next.get();
                    break;
                case BufferRole::Previous:
                    break;  // never saved: the next step rewrites it or does not read it
                case BufferRole::Pending:
                    target = slot.pending.get();
                    break;
            }
            const std::string file = FileOf(saved.resource, saved.role, saved.camera);
            if (!target) return MakeError("restoring a state: " + file + ": this simulation holds no such buffer");
            if (target->Format() != saved.format || !(target->Extent() == saved.extent) ||
                target->CanonicalBytes() != saved.data.size())
                return MakeError("restoring a state: " + file +
                                 ": its format or extent differs from this simulation's");
            CB_TRY(sim.mBackend.Upload(*target, saved.data));
        }
        for (Resource r : kAllResources)
            SlotFields(sim.mSlots[size_t(r)], s, r, [](auto& to, const auto& from) { to = from; });
        Pcg32 rng(0);
        rng.Restore(s.rngState, s.rngIncrement);
        sim.mEllipsoids.Restore(s.ellipsoids, rng, s.listStep);
        PlainFields(sim, s, [](auto& to, const auto& from) { to = from; });
        sim.mStep = s.step;
        return {};
    }
};

Result<SimulationState> CaptureSimulationState(const Simulation& sim, std::string_view sceneHash) {
    return SimulationStateAccess::Capture(sim, sceneHash);
}

Status RestoreSimulationState(Simulation& sim, const SimulationState& state) {
    return SimulationStateAccess::Restore(sim, state);
}

namespace {

json ManifestOf(const SimulationState& s) {
    json items = json::array();
    for (const Ellipsoid& e : s.ellipsoids)
        items.push_back({{"center", {e.center[0], e.center[1], e.center[2]}},
                         {"semi_axes", {e.semiAxes[0], e.semiAxes[1], e.semiAxes[2]}},
                         {"yaw", e.yaw},
                         {"age", e.age},
                         {"lifetime", e.lifetime}});
    json resources = json::object();
    for (Resource r : kAllResources)
        resources[std::string(ResourceName(r))] = {{"version", s.versions[size_t(r)]},
                                                   {"ahead", s.ahead[size_t(r)]},
                                                   {"previous_is_current", s.previousIsCurrent[size_t(r)]}};
    json inputs = json::object();
    for (Stage stage : kAllStages)
        if (const auto& v = s.inputsAtLastRun[size_t(stage)]) inputs[std::string(StageName(stage))] = *v;
    json buffers = json::array();
    for (const SavedBuffer& b : s.buffers)
        buffers.push_back({{"file", FileOf(b.resource, b.role, b.camera)},
                           {"resource", ResourceName(b.resource)},
                           {"role", BufferRoleName(b.role)},
                           {"camera", b.camera},
                           {"format", FormatName(b.format)},
                           {"shape", ShapeOf(b.extent)},
                           {"fnv1a64", Hex64(Fnv1a64(b.data))}});
    return {
        {"format", kSimulationStateFormat},
        {"version", kSimulationStateVersion},
        {"scene", {{"name", s.sceneName}, {"settings_hash", s.sceneHash}}},
        {"step", s.step},
        {"ellipsoids",
         {{"rng", {{"state", Hex64(s.rngState)}, {"increment", Hex64(s.rngIncrement)}}},
          {"list_step", s.listStep},
          {"items", items}}},
        {"raster", RasterJson(s.raster)},
        {"raster_ahead", RasterJson(s.rasterAhead)},
        {"last_rendered_step", OptionalJson(s.lastRendered)},
        {"frames_drawn", s.framesDrawn},
        {"last_covered_columns", OptionalJson(s.lastCoveredColumns)},
        {"resources", resources},
        {"inputs_at_last_run", inputs},
        {"time_slicing",
         {{"ahead_computed", s.aheadComputed},
          {"advance_owed", s.advanceOwed},
          {"ahead_record", transfer::ToJson(s.aheadRecord)}}},
        {"buffers", buffers},
    };
}

}  // namespace

Status WriteSimulationState(const SimulationState& state, const std::string& dir) {
    const fs::path target = fs::path(dir).lexically_normal();
    const std::string name = target.filename().string();
    if (name.empty() || name == "." || name == "..") return MakeError(dir + ": not a folder name to save a state as");
    // The folder that holds DIR is the user's (followed as named); DIR itself is replaced, so it is never
    // followed: a link at DIR, at its temporary name or inside them is refused or removed as a name
    // (harness/platform/OutputFolder.h).
    auto parent = OpenFolderForWriting(target.parent_path().string(), /*create=*/true);
    if (!parent) return std::unexpected(parent.error());
    CB_TRY(RefuseLinkAt(*parent, name));
    struct stat info {};
    const bool exists = fstatat(parent->Fd(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0;
    // Never replace something that is not a saved state.
    if (exists) {
        struct stat manifest {};
        const int fd = S_ISDIR(info.st_mode)
                           ? OpenFolderAt(parent->Fd(), name)
                           : -1;
        const bool saved =
            fd >= 0 && fstatat(fd, std::string(kSimulationStateManifest).c_str(), &manifest, AT_SYMLINK_NOFOLLOW) == 0;
        if (fd >= 0) close(fd);
        if (!saved)
            return MakeError(dir + ": exists and is not a saved state (no " + std::string(kSimulationStateManifest) +
                             "); not replaced");
    }
    const std::string tempName = "." + name + ".partial-" + std::to_string(getpid());
    CB_TRY(RemoveTreeAt(*parent, tempName));
    const std::string tempShown = parent->ShownChild(tempName);
    if (mkdirat(parent->Fd(), tempName.c_str(), 0777) != 0)
        return MakeError(dir + ": cannot write: cannot create " + tempShown + ": " + std::strerror(errno));
    auto written = [&]() -> Status {
        const int tempFd = OpenFolderAt(parent->Fd(), tempName);
        if (tempFd < 0) return MakeError(dir + ": cannot write: " + tempShown + ": " + std::strerror(errno));
        const OpenFolder temp(tempFd, tempShown);
        for (const SavedBuffer& b : state.buffers) {
            const std::string file = FileOf(b.resource, b.role, b.camera);
            const std::vector<uint64_t> shape = ShapeOf(b.extent);
            const NpyType type = b.format == BufferFormat::F32 ? NpyType::F32 : NpyType::U8;
            CB_TRY(WriteNewFile(temp, file,
                                [&](int fd) { return WriteNpy(fd, temp.ShownChild(file), type, shape, b.data); }));
        }
        // The manifest last: a folder with a whole manifest has every buffer it lists.
        const std::string manifest(kSimulationStateManifest);
        CB_TRY(WriteNewFile(temp, manifest, [&](int fd) -> Status {
            if (!WriteAll(fd, ManifestOf(state).dump(1) + "\n"))
                return MakeError(temp.ShownChild(manifest) + ": cannot write: " + std::strerror(errno));
            return {};
        }));
        CB_TRY(FsyncFd(temp.Fd(), tempShown));
        if (exists) {
            // One atomic swap; the previous state then sits in the temporary name and is removed.
            if (renameat2(parent->Fd(), tempName.c_str(), parent->Fd(), name.c_str(), RENAME_EXCHANGE) != 0) {
                if (errno != EINVAL && errno != ENOSYS)
                    return MakeError(dir + ": cannot replace the previous state: " + std::strerror(errno));
                // A file system without RENAME_EXCHANGE: two renames (the old state survives as .old until the end).
                const std::string old = "." + name + ".old-" + std::to_string(getpid());
                CB_TRY(RemoveTreeAt(*parent, old));
                if (renameat(parent->Fd(), name.c_str(), parent->Fd(), old.c_str()) != 0 ||
                    renameat(parent->Fd(), tempName.c_str(), parent->Fd(), name.c_str()) != 0)
                    return MakeError(dir + ": cannot replace the previous state: " + std::strerror(errno));
                (void)RemoveTreeAt(*parent, old);
                return FsyncFd(parent->Fd(), parent->Shown());
            }
        } else if (renameat(parent->Fd(), tempName.c_str(), parent->Fd(), name.c_str()) != 0) {
            return MakeError(dir + ": cannot write: " + std::strerror(errno));
        }
        return FsyncFd(parent->Fd(), parent->Shown());
    }();
    (void)RemoveTreeAt(*parent, tempName);  // on success: the previous state, if any; on failure: the partial one
    return written;
}

Status SaveSimulationState(const Simulation& sim, const std::string& dir, std::string_view sceneHash) {
    auto state = CaptureSimulationState(sim, sceneHash);
    if (!state) return std::unexpected(state.error());
    return WriteSimulationState(*state, dir);
}

}  // namespace cb
