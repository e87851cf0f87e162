// Save and restore (the metamorphic invariant "a split run
// equals the unsplit run"): a run of N steps, against k steps, the state saved
// to a folder, read back into a FRESH Simulation and N-k more steps. Every
// buffer the observer sees and every image must be bit-equal at every later
// step, with and without time-slicing, saved in the middle of a run or at its
// end, on every backend; restored on another backend, the integer stages stay
// bit-equal and the float ones too once a step has recomputed them (only the
// first resumed step's images interpolate from the saving backend's q).
// The scene lets ellipsoids die and be born after the split and jitters them
// every step, so the list's Pcg32 state matters. Also every refusal of a bad
// state folder: the file, the field and the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "core/base/Npy.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "harness/run/SimulationState.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/BackendTestUtil.h"

namespace cb {
namespace {

namespace fs = std::filesystem;

// scenes/ci-small.json on an odd 23 x 19 x 7 grid, a small view of all of it rendered every step (two frames per
// step, so frames interpolate q_{t-1} and q_t), a lit ground (G), a sun that moves every step (shade and shadow re-run),
// clouds from step 1, and short-lived, jittered ellipsoids: some die and are born after any split.
Scene SavedRunScene(std::vector<SceneOverride> more) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    nlohmann::json root = nlohmann::json::parse(file);
    root["sun"].erase("elevation_deg");
    root["sun"].erase("azimuth_deg");
    std::vector<SceneOverride> sets = {
        {"grid.size", "[23, 19, 7]"},
        {"steps", "7"},
        {"warmup_steps", "1"},
        {"ca.act0", "0.03"},
        {"ca.p_act", "0.02"},
        {"density.tile", "8"},
        {"density.band", "3"},
        {"ellipsoids.target_count", "5"},
        {"ellipsoids.size_mean", "[6, 6, 3]"},
        {"ellipsoids.size_variance", "[2, 2, 1]"},
        {"ellipsoids.margin", "3"},
        {"ellipsoids.lifetime_mean", "3"},
        {"ellipsoids.lifetime_variance", "1"},
        {"ellipsoids.shrink_steps", "1"},
        {"ellipsoids.jitter", "0.4"},
        {"render.width", "40"},
        {"render.height", "30"},
        {"render.every_steps", "1"},
        {"render.frames_per_step", "2"},
        {"render.ground", R"({"albedo": [0.3, 0.35, 0.3]})"},
        {"render.cameras",
         R"([{"name": "a", "eye": [575, -700, 1100], "target": [575, 475, 150], "up": [0, 0, 1], "fov_deg": 70,
              "near": 1, "far": 20000}])"},
        {"sun.path",
         R"([{"step": 0, "elevation_deg": 20, "azimuth_deg": 10}, {"step": 6, "elevation_deg": 75, "azimuth_deg": 100}])"},
    };
    sets.insert(sets.end(), more.begin(), more.end());
    auto scene = ParseScene(root.dump(), "ci-small.json", sets);
    EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
    return scene ? *scene : Scene{};
}

constexpr const char* kStateTestHash = "0123456789abcdef";

// A fresh folder of its own for `name` in the running test: ctest runs the tests in parallel processes, and two tests
// of one backend must not share a folder.
std::string StateTestDir(const std::string& name) {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::ranges::replace(test, '/', '_');
    const std::string dir = ::testing::TempDir() + "/simstate_" + test + "_" + name;
    fs::remove_all(dir);
    return dir;
}

// Everything the observer sees at one step, and the record's results.
struct SavedRunView {
    std::map<std::string, std::vector<std::byte>> bytes;  // "q#0", "image_splat#0", ...
    std::map<std::string, BufferFormat> formats;
    std::optional<uint32_t> cover;
    std::array<bool, kStageCount> skipped{};
    uint32_t frames = 0;
    // Every frame's splat counters: the frames before the step's last (alpha < 1) show Previous; the observer
    // sees only the last frame's image.
    std::vector<FrameCounters> frameStats;
};

// Steps `sim` until `to` (exclusive), keeping each step's view.
std::vector<SavedRunView> StepAndKeep(Simulation& sim, Backend& backend, uint32_t to) {
    std::vector<SavedRunView> views;
    while (sim.CurrentStep() < to) {
        SavedRunView view;
        StepRecord record;
        Status s = sim.Step(record, [&](const Simulation& at) -> Status {
            for (Resource r : kAllResources)
                for (size_t n = 0; at.Get(r, n); ++n) {
                    const std::string key = std::string(ResourceName(r)) + "#" + std::to_string(n);
                    std::vector<std::byte> data(at.Get(r, n)->CanonicalBytes());
                    CB_TRY(backend.Download(*at.Get(r, n), data));
                    view.bytes[key] = std::move(data);
                    view.formats[key] = at.Get(r, n)->Format();
                }
            return {};
        });
        EXPECT_TRUE(s.has_value()) << "step " << sim.CurrentStep() << ": " << s.error().message;
        if (!s) break;
        view.cover = record.coveredColumns;
        view.skipped = record.skippedUnchanged;
        view.frames = record.framesRendered;
        for (const FrameRecord& f : record.frames)
            view.frameStats.push_back(f.counters);
        views.push_back(std::move(view));
    }
    return views;
}

std::unique_ptr<Simulation> MakeSim(const Scene& scene, Backend& backend) {
    auto sim = Simulation::Create(scene, backend);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    return sim ? std::move(*sim) : nullptr;
}

// The ellipsoids of `sim` now (through a captured state): how many were born after step `since`.
size_t BornSince(const Simulation& sim, uint32_t since) {
    auto state = CaptureSimulationState(sim, kStateTestHash);
    EXPECT_TRUE(state.has_value());
    size_t born = 0;
    if (state)
        for (const Ellipsoid& e : state->ellipsoids) born += e.age < sim.CurrentStep() - since;
    return born;
}

// How a resumed run's step must compare with the unsplit run's.
enum class SameAs { Bits, OtherBackend };

void ExpectSameSteps(const std::vector<SavedRunView>& expected, const std::vector<SavedRunView>& got, uint32_t split,
                     const Scene& scene, SameAs same) {
    ASSERT_EQ(got.size(), expected.size() - split);
    for (size_t i = 0; i < got.size(); ++i) {
        const uint32_t t = split + uint32_t(i);
        const SavedRunView &a = expected[t], &b = got[i];
        SCOPED_TRACE("step " + std::to_string(t) + " (split at " + std::to_string(split) + ")");
        ASSERT_EQ(b.bytes.size(), a.bytes.size());
        for (const auto& [name, data] : a.bytes) {
            ASSERT_TRUE(b.bytes.count(name)) << name;
            const std::vector<std::byte>& other = b.bytes.at(name);
            ASSERT_EQ(other.size(), data.size()) << name;
            // On another backend the first resumed step's frames interpolate from the saving backend's q_{t-1}:
            // within the renderer's rule. Every other buffer (and every later image) is this backend's own.
            if (same == SameAs::OtherBackend && t == split && name.starts_with("image") &&
                a.formats.at(name) == BufferFormat::F32) {
                const double tolerance = Describe(Stage::RenderSplat).rule(scene).tolerance;
                const auto* x = reinterpret_cast<const float*>(data.data());
                const auto* y = reinterpret_cast<const float*>(other.data());
                double worst = 0;
                for (size_t v = 0; v < data.size() / 4; ++v) worst = std::max(worst, double(std::abs(x[v] - y[v])));
                EXPECT_LE(worst, tolerance) << name;
                continue;
            }
            EXPECT_TRUE(other == data) << name << " differs from the unsplit run";
        }
        EXPECT_EQ(b.cover, a.cover);
        EXPECT_EQ(b.frames, a.frames);
        if (same == SameAs::Bits || t > split) {
            EXPECT_EQ(b.frameStats, a.frameStats) << "splats, voxels visited, fragments";
        }
        for (Stage stage : kAllStages)
            EXPECT_EQ(b.skipped[size_t(stage)], a.skipped[size_t(stage)]) << StageName(stage) << " skipped";
    }
}

// Saves at step `split` of a run (a run of `split` steps when `atEnd`, else mid-way through the N-step run) on
// `saver`, reads the folder back and resumes on `resumer` in a fresh Simulation up to N; the views of the resumed steps.
std::vector<SavedRunView> SplitRun(const Scene& scene, uint32_t split, bool atEnd, Backend& saver, Backend& resumer,
                                   const std::string& dir) {
    Scene first = scene;
    if (atEnd) first.steps = split;
    auto a = MakeSim(first, saver);
    if (!a) return {};
    StepAndKeep(*a, saver, split);
    Status saved = SaveSimulationState(*a, dir, kStateTestHash);
    EXPECT_TRUE(saved.has_value()) << saved.error().message;
    a.reset();
    auto state = ReadSimulationState(dir, scene, kStateTestHash);
    EXPECT_TRUE(state.has_value()) << state.error().message;
    if (!state) return {};
    EXPECT_EQ(state->step, split);
    auto b = MakeSim(scene, resumer);
    if (!b) return {};
    Status restored = RestoreSimulationState(*b, *state);
    EXPECT_TRUE(restored.has_value()) << restored.error().message;
    EXPECT_EQ(b->CurrentStep(), split);
    auto views = StepAndKeep(*b, resumer, scene.steps);
    // The list's random births (and every step's jitter) happened after the split.
    EXPECT_GT(BornSince(*b, split), 0u) << "the test needs ellipsoids born after the split";
    return views;
}

using SimulationStateSplit = test::BackendTest;

TEST_P(SimulationStateSplit, SplitRunEqualsTheUnsplitRun) {
    for (const char* slices : {"0", "2"}) {
        const Scene scene = SavedRunScene({{"render.slices_per_frame", slices}});
        auto whole = MakeSim(scene, *mBackend);
        ASSERT_TRUE(whole);
        const std::vector<SavedRunView> expected = StepAndKeep(*whole, *mBackend, scene.steps);
        ASSERT_EQ(expected.size(), scene.steps);
        EXPECT_GT(expected.back().cover.value_or(0), 0u) << "the test needs clouds";
        for (uint32_t split : {2u, 4u})
            for (bool atEnd : {false, true}) {
                SCOPED_TRACE(std::string("slices per frame ") + slices + (atEnd ? ", saved at the end of a run" : ", saved mid-run"));
                const auto got = SplitRun(scene, split, atEnd, *mBackend, *mBackend, StateTestDir(GetParam()));
                ExpectSameSteps(expected, got, split, scene, SameAs::Bits);
            }
    }
}

// Placed ellipsoids (SPEC 17) across a split: one drifting along keyframes over the whole run, one born at step 3
// (after the first split) that lives across the second, one that dies at step 3. The resumed list must be at the
// saved list step, or the placed ellipsoids would start over and the region differ.
TEST_P(SimulationStateSplit, SplitRunWithPlacedEllipsoids) {
    for (const char* slices : {"0", "2"}) {
        const Scene scene = SavedRunScene({{"render.slices_per_frame", slices},
                                           {"ellipsoids.placed",
                                            R"([{"semi_axes": [5, 3, 2], "yaw_deg": 40, "persistent": true,
                   "keyframes": [{"step": 0, "center": [3, 4, 3]}, {"step": 6, "center": [19, 14, 4]}]},
                  {"center": [16, 5, 3], "semi_axes": [4, 4, 2], "start": 3, "lifetime": 3},
                  {"center": [6, 15, 3], "semi_axes": [4, 3, 2], "start": 1, "lifetime": 2}])"}});
        ASSERT_EQ(scene.ellipsoids.placed.size(), 3u);
        auto whole = MakeSim(scene, *mBackend);
        ASSERT_TRUE(whole);
        const std::vector<SavedRunView> expected = StepAndKeep(*whole, *mBackend, scene.steps);
        ASSERT_EQ(expected.size(), scene.steps);
        for (uint32_t split : {2u, 4u}) {
            SCOPED_TRACE(std::string("slices per frame ") + slices + ", split at " + std::to_string(split));
            const auto got = SplitRun(scene, split, false, *mBackend, *mBackend, StateTestDir(GetParam()));
            ExpectSameSteps(expected, got, split, scene, SameAs::Bits);
        }
    }
}

// A still field: noise forms q once (step 0) and skips after, so q, D, tiles and bands keep their step-0 values and
// the renderer interpolates the current value (q_0) with itself at every step: the saved previous_is_current flags
// and skip state are read at every resumed step here (in the automaton scene each step's smooth runs).
TEST_P(SimulationStateSplit, SplitRunOfAStillField) {
    if (!mBackend->Supports(Stage::Noise)) GTEST_SKIP() << GetParam() << " has no noise stage";
    const Scene scene = SavedRunScene({
        {"stages", R"(["noise", "density", "shade", "shadow", "render_splat"])"},
        {"noise", R"({"seed": 3, "basis": "perlin", "frequency": [4, 4, 2], "octaves": 2, "threshold": 0.1})"},
        {"grid.size", "[32, 32, 8]"},
        {"steps", "5"},
    });
    auto whole = MakeSim(scene, *mBackend);
    ASSERT_TRUE(whole);
    const std::vector<SavedRunView> expected = StepAndKeep(*whole, *mBackend, scene.steps);
    ASSERT_EQ(expected.size(), scene.steps);
    EXPECT_TRUE(expected[3].skipped[size_t(Stage::Noise)]) << "the test needs noise to skip";
    ASSERT_FALSE(expected[3].frameStats.empty());
    EXPECT_GT(expected[3].frameStats[0][0], 0u) << "the test needs splats";
    for (bool atEnd : {false, true}) {
        SCOPED_TRACE(atEnd ? "saved at the end of a run" : "saved mid-run");
        const uint32_t split = 2;
        Scene first = scene;
        if (atEnd) first.steps = split;
        auto a = MakeSim(first, *mBackend);
        ASSERT_TRUE(a);
        StepAndKeep(*a, *mBackend, split);
        const std::string dir = StateTestDir("still_" + GetParam());
        ASSERT_TRUE(SaveSimulationState(*a, dir, kStateTestHash).has_value());
        auto state = ReadSimulationState(dir, scene, kStateTestHash);
        ASSERT_TRUE(state.has_value()) << state.error().message;
        auto b = MakeSim(scene, *mBackend);
        ASSERT_TRUE(b);
        ASSERT_TRUE(RestoreSimulationState(*b, *state).has_value());
        ExpectSameSteps(expected, StepAndKeep(*b, *mBackend, scene.steps), split, scene, SameAs::Bits);
    }
}

// A reprojecting march along a camera track (two frames a step): each frame reads the frame before from its image and
// its camera from the frames drawn so far, so a resumed run must restore both, the count among the state's fields.
TEST_P(SimulationStateSplit, SplitRunOfAReprojectedFlight) {
    const Scene scene = SavedRunScene({
        {"stages", R"(["noise", "density", "shade", "shadow", "render_march"])"},
        {"noise", R"({"seed": 3, "basis": "perlin", "frequency": [4, 4, 2], "octaves": 2, "threshold": 0.1})"},
        {"grid.size", "[32, 32, 8]"},
        {"steps", "5"},
        {"warmup_steps", "0"},
        {"march.reprojection", R"({"block": 2})"},
        {"render.cameras", R"([{"name": "a", "fov_deg": 70, "far": 20000, "track": [
            {"frame": 0, "eye": [575, -700, 1100], "target": [575, 475, 150]},
            {"frame": 9, "eye": [700, -500, 1000], "target": [600, 500, 150]}]}])"},
    });
    if (auto unbuilt = mBackend->ExceededLimit(scene)) GTEST_SKIP() << unbuilt->reason;
    auto whole = MakeSim(scene, *mBackend);
    ASSERT_TRUE(whole);
    const std::vector<SavedRunView> expected = StepAndKeep(*whole, *mBackend, scene.steps);
    ASSERT_EQ(expected.size(), scene.steps);
    const uint32_t split = 2;
    auto a = MakeSim(scene, *mBackend);
    ASSERT_TRUE(a);
    StepAndKeep(*a, *mBackend, split);
    const std::string dir = StateTestDir("flight_" + GetParam());
    ASSERT_TRUE(SaveSimulationState(*a, dir, kStateTestHash).has_value());
    auto state = ReadSimulationState(dir, scene, kStateTestHash);
    ASSERT_TRUE(state.has_value()) << state.error().message;
    EXPECT_EQ(state->framesDrawn, 2 * split);
    auto b = MakeSim(scene, *mBackend);
    ASSERT_TRUE(b);
    ASSERT_TRUE(RestoreSimulationState(*b, *state).has_value());
    ExpectSameSteps(expected, StepAndKeep(*b, *mBackend, scene.steps), split, scene, SameAs::Bits);
}

INSTANTIATE_TEST_SUITE_P(Backends, SimulationStateSplit, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const auto& info) { return info.param; });

// Saved on one backend, resumed on another: the state is backend-neutral (canonical bytes, host state in JSON).
class SimulationStateAcross : public ::testing::TestWithParam<std::pair<std::string, std::string>> {};

TEST_P(SimulationStateAcross, ResumedOnAnotherBackend) {
    const auto& [saverName, resumerName] = GetParam();
    auto saver = test::MakeTestBackend(saverName);
    if (!saver) GTEST_SKIP() << "unsupported here: " << saver.error().message;
    auto resumer = test::MakeTestBackend(resumerName);
    if (!resumer) GTEST_SKIP() << "unsupported here: " << resumer.error().message;
    for (const char* slices : {"0", "2"}) {
        SCOPED_TRACE(std::string("slices per frame ") + slices);
        const Scene scene = SavedRunScene({{"render.slices_per_frame", slices}});
        auto whole = MakeSim(scene, **resumer);
        ASSERT_TRUE(whole);
        const std::vector<SavedRunView> expected = StepAndKeep(*whole, **resumer, scene.steps);
        const uint32_t split = 3;
        const auto got = SplitRun(scene, split, /*atEnd=*/true, **saver, **resumer,
                                  StateTestDir(saverName + "_to_" + resumerName));
        ExpectSameSteps(expected, got, split, scene, SameAs::OtherBackend);
    }
    test::ExpectNoValidationMessages(saver->get());
    test::ExpectNoValidationMessages(resumer->get());
}

std::vector<std::pair<std::string, std::string>> BackendPairs() {
    std::vector<std::pair<std::string, std::string>> pairs;
    for (const std::string& a : cb::test::TestBackends())
        for (const std::string& b : cb::test::TestBackends())
            if (a != b && (a == "cpu" || b == "cpu")) pairs.push_back({a, b});
    return pairs;
}

INSTANTIATE_TEST_SUITE_P(Backends, SimulationStateAcross, ::testing::ValuesIn(BackendPairs()),
                         [](const auto& info) { return info.param.first + "_to_" + info.param.second; });

// ---- The folder: atomic replacement, and every refusal names the file, the field and the reason.

class SimulationStateFiles : public ::testing::Test {
  protected:
    void SetUp() override {
        mScene = SavedRunScene({});
        mDir = StateTestDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        auto sim = MakeSim(mScene, mCpu);
        ASSERT_TRUE(sim);
        StepRecord r;
        for (int t = 0; t < 3; ++t) ASSERT_TRUE(sim->Step(r));
        Status s = SaveSimulationState(*sim, mDir, kStateTestHash);
        ASSERT_TRUE(s.has_value()) << s.error().message;
    }
    std::string Manifest() const { return mDir + "/manifest.json"; }
    nlohmann::json ReadManifest() const {
        std::ifstream in(Manifest());
        return nlohmann::json::parse(in);
    }
    void WriteManifest(const nlohmann::json& m) const { std::ofstream(Manifest()) << m.dump(1); }
    // The error of reading the folder back (and a failure when it was accepted).
    std::string ErrorOfRead(const Scene& scene, const std::string& hash = kStateTestHash) const {
        auto state = ReadSimulationState(mDir, scene, hash);
        if (state) {
            ADD_FAILURE() << "the state was accepted";
            return "";
        }
        return state.error().message;
    }
    std::string ErrorOfRead() const { return ErrorOfRead(mScene); }

    Scene mScene;
    std::string mDir;
    cpu::BackendCpu mCpu;
};

TEST_F(SimulationStateFiles, ReadsBackWhatWasSaved) {
    auto state = ReadSimulationState(mDir, mScene, kStateTestHash);
    ASSERT_TRUE(state.has_value()) << state.error().message;
    EXPECT_EQ(state->step, 3u);
    EXPECT_EQ(state->listStep, 3u);  // three unsliced steps: three list updates
    // q_t, the state, the image; not q_{t-1} (the next step rewrites or does not read it); no third set unsliced.
    std::set<std::string> files;
    for (const auto& entry : fs::directory_iterator(mDir)) files.insert(entry.path().filename().string());
    for (const char* f : {"manifest.json", "hum.current.npy", "act.current.npy", "cld.current.npy", "q.current.npy",
                          "region.current.npy", "T.current.npy", "G.current.npy",
                          "image_splat.current.0.npy"})
        EXPECT_TRUE(files.count(f)) << f;
    for (const std::string& f : files) {
        EXPECT_EQ(f.find("pending"), std::string::npos) << f;
        EXPECT_EQ(f.find("previous"), std::string::npos) << f;
    }
    // The .npy files are plain NumPy arrays shaped (nz, ny, nx).
    auto q = ReadNpy(mDir + "/q.current.npy");
    ASSERT_TRUE(q.has_value());
    EXPECT_EQ(q->shape, (std::vector<uint64_t>{7, 19, 23}));
}

TEST_F(SimulationStateFiles, ReplacesAStateWholeAndNothingElse) {
    auto sim = MakeSim(mScene, mCpu);
    ASSERT_TRUE(sim);
    StepRecord r;
    ASSERT_TRUE(sim->Step(r));
    ASSERT_TRUE(SaveSimulationState(*sim, mDir, kStateTestHash).has_value());
    EXPECT_EQ(ReadManifest()["step"], 1);
    // No partial or old folder is left beside it.
    for (const auto& entry : fs::directory_iterator(fs::path(mDir).parent_path()))
        EXPECT_EQ(entry.path().filename().string().find(".simstate_ReplacesAStateWholeAndNothingElse"),
                  std::string::npos)
            << entry.path();
    // A folder that is not a saved state is never replaced.
    const std::string other = StateTestDir("not_a_state");
    fs::create_directories(other);
    std::ofstream(other + "/keep.txt") << "mine";
    Status s = SaveSimulationState(*sim, other, kStateTestHash);
    ASSERT_FALSE(s.has_value());
    EXPECT_EQ(s.error().message, other + ": exists and is not a saved state (no manifest.json); not replaced");
    EXPECT_TRUE(fs::exists(other + "/keep.txt"));
}

TEST_F(SimulationStateFiles, NoManifest) {
    fs::remove(Manifest());
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": cannot read the file: No such file or directory");
}

TEST_F(SimulationStateFiles, NotJson) {
    std::ofstream(Manifest()) << "{\"format\": ";
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": not a JSON object (a damaged file?)");
}

TEST_F(SimulationStateFiles, OtherFormat) {
    nlohmann::json m = ReadManifest();
    m["format"] = "something-else";
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": format: must be \"cloudbench-simulation-state\", got \"something-else\"");
}

TEST_F(SimulationStateFiles, BadVersion) {
    nlohmann::json m = ReadManifest();
    m["version"] = 2;
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": version: this build reads version 1, got 2");
}

TEST_F(SimulationStateFiles, OtherSceneSettings) {
    EXPECT_EQ(ErrorOfRead(mScene, "fedcba9876543210"),
              Manifest() + ": scene.settings_hash: saved with other scene settings (" + kStateTestHash +
                  "; this run's: fedcba9876543210): resume with the scene file and --set options the state was saved "
                  "with (only steps may differ)");
}

TEST_F(SimulationStateFiles, OtherScene) {
    Scene other = mScene;
    other.name = "thesis-medium";
    EXPECT_EQ(ErrorOfRead(other), Manifest() + ": scene.name: saved from scene 'ci-small', not 'thesis-medium'");
}

TEST_F(SimulationStateFiles, NothingLeftToRun) {
    Scene shorter = mScene;
    shorter.steps = 3;
    EXPECT_EQ(ErrorOfRead(shorter), Manifest() + ": step: the state is at step 3, so the resumed run needs steps > 3 (got 3)");
}

TEST_F(SimulationStateFiles, MissingField) {
    nlohmann::json m = ReadManifest();
    m["ellipsoids"].erase("rng");
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": ellipsoids.rng: missing");
}

TEST_F(SimulationStateFiles, BadRngState) {
    nlohmann::json m = ReadManifest();
    m["ellipsoids"]["rng"]["state"] = "0xZZ";
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": ellipsoids.rng.state: must be 1 to 16 lowercase hex digits, got \"0xZZ\"");
}

TEST_F(SimulationStateFiles, BadItemField) {
    nlohmann::json m = ReadManifest();
    m["ellipsoids"]["items"][1]["age"] = -1;
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": ellipsoids.items[1].age: must be a non-negative integer, got -1");
}

TEST_F(SimulationStateFiles, BadListStep) {
    nlohmann::json m = ReadManifest();
    m["ellipsoids"]["list_step"] = "3";
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": ellipsoids.list_step: must be a non-negative integer, got \"3\"");
}

TEST_F(SimulationStateFiles, MissingBufferEntry) {
    nlohmann::json m = ReadManifest();
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& b : m["buffers"])
        if (b["file"] != "q.current.npy") kept.push_back(b);
    m["buffers"] = kept;
    WriteManifest(m);
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": buffers: no entry for q.current.npy");
}

TEST_F(SimulationStateFiles, TruncatedNpy) {
    const std::string q = mDir + "/q.current.npy";
    fs::resize_file(q, fs::file_size(q) - 10);
    EXPECT_EQ(ErrorOfRead(), q + ": npy: truncated .npy data");
}

TEST_F(SimulationStateFiles, WrongShape) {
    // A whole, valid .npy of another grid's size.
    const std::string q = mDir + "/q.current.npy";
    const uint64_t shape[3] = {7, 19, 22};
    std::vector<float> data(7 * 19 * 22, 0.5f);
    ASSERT_TRUE(WriteNpy(q, NpyType::F32, shape, std::as_bytes(std::span(data))).has_value());
    EXPECT_EQ(ErrorOfRead(), q + ": shape: expected [7, 19, 23] (the scene's q), got [7, 19, 22]");
}

TEST_F(SimulationStateFiles, WrongDtype) {
    const std::string cld = mDir + "/cld.current.npy";
    const uint64_t shape[3] = {7, 19, 23};
    std::vector<float> data(7 * 19 * 23, 0.0f);
    ASSERT_TRUE(WriteNpy(cld, NpyType::F32, shape, std::as_bytes(std::span(data))).has_value());
    EXPECT_EQ(ErrorOfRead(), cld + ": dtype: expected |u1 for bits data");
}

TEST_F(SimulationStateFiles, ChangedData) {
    const std::string cld = mDir + "/cld.current.npy";
    auto array = ReadNpy(cld);
    ASSERT_TRUE(array.has_value());
    array->data[5] = std::byte(array->data[5] == std::byte{0} ? 1 : 0);
    ASSERT_TRUE(WriteNpy(cld, NpyType::U8, array->shape, array->data).has_value());
    EXPECT_EQ(ErrorOfRead(),
              cld + ": fnv1a64: the data do not match the manifest's hash (a changed or damaged file)");
}

TEST_F(SimulationStateFiles, OtherGridSize) {
    // The same settings hash given, a scene of another size: the buffers' shapes refuse it.
    const Scene bigger = SavedRunScene({{"grid.size", "[24, 19, 7]"}});
    const std::string message = ErrorOfRead(bigger);
    EXPECT_NE(message.find(": shape: expected [7, 19, 24]"), std::string::npos) << message;
}

TEST_F(SimulationStateFiles, SlicedStateIntoUnslicedScene) {
    // A state saved time-sliced with work ahead needs the third buffer set: refused by a scene without one.
    const Scene sliced = SavedRunScene({{"render.slices_per_frame", "2"}});
    auto sim = MakeSim(sliced, mCpu);
    ASSERT_TRUE(sim);
    StepRecord r;
    for (int t = 0; t < 2; ++t) ASSERT_TRUE(sim->Step(r));
    ASSERT_TRUE(SaveSimulationState(*sim, mDir, kStateTestHash).has_value());
    EXPECT_EQ(ErrorOfRead(), Manifest() + ": time_slicing: the state was saved time-sliced; this scene is not");
}

TEST(SimulationStateHash, IgnoresStepsAndDescriptionOnly) {
    const nlohmann::json a = {{"steps", 10}, {"description", "x"}, {"grid", {{"size", {8, 4, 2}}}}};
    nlohmann::json b = a;
    b["steps"] = 99;
    b["description"] = "y";
    EXPECT_EQ(SceneSettingsHash(a), SceneSettingsHash(b));
    b["grid"]["size"][2] = 3;
    EXPECT_NE(SceneSettingsHash(a), SceneSettingsHash(b));
    EXPECT_EQ(SceneSettingsHash(a).size(), 16u);
    // FNV-1a 64 of the compact dump, by its published constants: {"grid":{"size":[8,4,2]}}.
    uint64_t h = 0xcbf29ce484222325ull;
    for (char c : std::string(R"({"grid":{"size":[8,4,2]}})")) {
        h ^= uint8_t(c);
        h *= 0x100000001b3ull;
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    EXPECT_EQ(SceneSettingsHash(a), hex);
}

}  // namespace
}  // namespace cb
