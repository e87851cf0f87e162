// A run's whole state between two steps, saved to a folder and restored into
// a fresh Simulation of the same scene, on the same or another backend
// (`cloudbench run --save-state DIR`, `--resume DIR`; docs/cli.md; the format:
// docs/results.md, "Saved simulation state").
//
// The state is what Simulation holds between steps (harness/run/Simulation.h):
// the step; every buffer it holds that a later step reads (each resource's
// current buffers, per-camera images included; the next step's third set
// while time-sliced work is ahead; not the previous step's, which the next
// step rewrites before a renderer reads it, or does not read at all), read
// back in the canonical layout of SPEC 0, so any backend can upload it; the
// ellipsoid list with its Pcg32 state and its list step (where the placed
// ellipsoids are); the ellipsoids step t's region came
// from (and, time-sliced, step t+1's); the last rendered step
// and cover; each resource's write count and each stage's input versions at
// its last run (so that stages skip exactly as in the unsplit run); and the
// time-slicing state. A run resumed from it continues exactly as the unsplit
// run would (tests/SimulationStateTest.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"

namespace cb {

inline constexpr std::string_view kSimulationStateFormat = "cloudbench-simulation-state";
inline constexpr uint32_t kSimulationStateVersion = 1;
inline constexpr std::string_view kSimulationStateManifest = "manifest.json";

// The settings a resumed run must share with the run that saved: a hash of the
// resolved scene (the scene file's JSON with --set applied) without "steps"
// (a resumed run may run longer) and "description": FNV-1a 64 of its compact
// dump (keys sorted), 16 hex digits.
std::string SceneSettingsHash(nlohmann::json resolved);

// One saved buffer: which buffer of the Simulation, and its canonical bytes.
struct SavedBuffer {
    Resource resource = Resource::Region;
    BufferRole role = BufferRole::Current;
    uint32_t camera = 0;
    BufferFormat format = BufferFormat::U8;
    Extent3 extent{};
    std::vector<std::byte> data;
};

struct SimulationState {
    std::string sceneName;
    std::string sceneHash;
    uint32_t step = 0;  // the next step to run
    std::vector<SavedBuffer> buffers;
    std::vector<Ellipsoid> ellipsoids;  // the random ones; the placed ones are the scene's, at listStep
    uint64_t rngState = 0, rngIncrement = 0;
    uint32_t listStep = 0;  // the list's updates so far (EllipsoidList::ListStep)
    std::vector<RasterEllipsoid> raster, rasterAhead;
    std::optional<uint32_t> lastRendered, lastCoveredColumns;
    uint32_t framesDrawn = 0;  // the next frame's number (a camera's track and the reprojection run on it)
    std::array<std::optional<std::vector<uint64_t>>, kStageCount> inputsAtLastRun{};
    std::array<uint64_t, kResourceCount> versions{};
    std::array<bool, kResourceCount> ahead{};
    std::array<bool, kResourceCount> previousIsCurrent{};  // not written since the step before
    bool aheadComputed = false, advanceOwed = false;
    StepRecord aheadRecord;  // time-sliced: what the next step's stages recorded so far
};

// The state of `sim` between two steps (reads back every buffer it holds).
Result<SimulationState> CaptureSimulationState(const Simulation& sim, std::string_view sceneHash);

// Writes `state` as the folder `dir`: manifest.json and one .npy per buffer.
// Atomic: everything is written (and fsync'ed) into a new sibling folder, which
// then takes the place of `dir` in one rename (RENAME_EXCHANGE when `dir`
// exists), so `dir` always holds either the previous state or the new one, whole.
Status WriteSimulationState(const SimulationState& state, const std::string& dir);

// CaptureSimulationState, then WriteSimulationState.
Status SaveSimulationState(const Simulation& sim, const std::string& dir, std::string_view sceneHash);

// Reads the folder `dir` and checks it whole against `scene` (its buffers, as
// PlanBuffers(scene) makes them) and `sceneHash` before anything is restored.
// Errors read "FILE: FIELD: reason", e.g. "DIR/manifest.json: version: ...",
// "DIR/q.current.npy: shape: expected [4, 8, 16], got [4, 8, 15]".
Result<SimulationState> ReadSimulationState(const std::string& dir, const Scene& scene, std::string_view sceneHash);

// Puts `state` (from ReadSimulationState or CaptureSimulationState of the same
// scene) into `sim`, a Simulation fresh from Create that has run no step.
Status RestoreSimulationState(Simulation& sim, const SimulationState& state);

}  // namespace cb
