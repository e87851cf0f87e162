// Time-slicing in the loop (SPEC 13): a run that spreads
// each step over the frames of the step before must see, step by step, the
// same state, q, D, occupancy, T, G and images as the unsliced run, bit for
// bit, on every backend; only when the work is done may differ. Also the
// frame plan (which shares each frame computes), the frames' alpha, the
// third buffer set and the scene rules, worked out by hand.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "core/pipeline/ShadePlan.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "core/stages/shade/Shade.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// scenes/ci-small.json on an odd 23 x 19 x 7 grid (tile 8: 3 rows of tiles, the last partial), a small view of all
// of it, clouds from step 1, a sun that turns from the x to the y principal axis and climbs to the z axis (so shade
// re-runs every step and its slice count changes), with `more` applied as --set does.
Scene SlicedLoopScene(std::vector<SceneOverride> more) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    nlohmann::json root = nlohmann::json::parse(file);
    root["sun"].erase("elevation_deg");  // the path gives the angles
    root["sun"].erase("azimuth_deg");
    const std::string text = root.dump();
    std::vector<SceneOverride> sets = {
        {"grid.size", "[23, 19, 7]"},
        {"steps", "6"},
        {"warmup_steps", "1"},
        {"ca.act0", "0.03"},
        {"ca.p_act", "0.02"},
        {"density.tile", "8"},
        {"density.band", "3"},
        {"render.width", "40"},
        {"render.height", "30"},
        {"render.every_steps", "1"},
        {"render.cameras",
         R"([{"name": "a", "eye": [575, -700, 1100], "target": [575, 475, 150], "up": [0, 0, 1], "fov_deg": 70,
              "near": 1, "far": 20000}])"},
        {"sun.path",
         R"([{"step": 0, "elevation_deg": 20, "azimuth_deg": 10}, {"step": 2, "elevation_deg": 30, "azimuth_deg": 80},
                        {"step": 5, "elevation_deg": 75, "azimuth_deg": 100}])"},
    };
    sets.insert(sets.end(), more.begin(), more.end());
    auto scene = ParseScene(text, "ci-small.json", sets);
    EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
    return scene ? *scene : Scene{};
}

// The slices of shade's sweep at `step`'s sun.
uint32_t SweepSlicesAt(const Scene& scene, uint32_t step) {
    return MakeShadePlan(MakeShadeParams(scene, step), scene.grid.size).nw;
}

// Everything the observer sees at each step: each resource's bytes (images per camera) and the step's records.
struct StepView {
    std::map<std::string, std::vector<std::byte>> bytes;
    StepRecord record;
};

std::vector<StepView> RunAndKeepEveryStep(const Scene& scene, Backend& backend) {
    auto sim = Simulation::Create(scene, backend);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    if (!sim) return {};
    std::vector<StepView> views;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepView view;
        Status s = (*sim)->Step(view.record, [&](const Simulation& at) -> Status {
            for (Resource r : kAllResources)
                for (size_t n = 0; at.Get(r, n); ++n) {
                    std::vector<std::byte> data(at.Get(r, n)->CanonicalBytes());
                    CB_TRY(backend.Download(*at.Get(r, n), data));
                    view.bytes[std::string(ResourceName(r)) + "#" + std::to_string(n)] = std::move(data);
                }
            return {};
        });
        EXPECT_TRUE(s.has_value()) << s.error().message;
        views.push_back(std::move(view));
    }
    return views;
}

// Every resource of every step of `got` equals `expected`'s, bit for bit (the warm-up steps shade nothing and draw
// nothing: their T, G and images are not written yet).
void ExpectSameBytesEveryStep(const std::vector<StepView>& got, const std::vector<StepView>& expected,
                              uint32_t warmupSteps) {
    ASSERT_EQ(got.size(), expected.size());
    for (size_t t = 0; t < got.size(); ++t) {
        SCOPED_TRACE("step " + std::to_string(t));
        ASSERT_EQ(got[t].bytes.size(), expected[t].bytes.size());
        for (const auto& [name, data] : expected[t].bytes) {
            ASSERT_TRUE(got[t].bytes.count(name)) << name;
            const bool output = name.starts_with("T#") || name.starts_with("G#") || name.starts_with("image");
            if (output && t < warmupSteps) continue;
            EXPECT_TRUE(got[t].bytes.at(name) == data) << name << " differs from the unsliced loop";
        }
    }
}

using TimeSliceLoop = test::BackendTest;

// Frames per step well above what the shares take, so the sliced steps draw as many frames, at the same alphas, as
// the unsliced ones: then every resource and every image must be equal at every step.
TEST_P(TimeSliceLoop, EveryStepEqualsTheUnslicedLoop) {
    // The ground lit by G too: the frames read the current G while the shares compute the next one.
    const SceneOverride ground{"render.ground", R"({"albedo": [0.3, 0.35, 0.3]})"};
    const Scene whole = SlicedLoopScene({{"render.frames_per_step", "56"}, ground});
    const std::vector<StepView> expected = RunAndKeepEveryStep(whole, *mBackend);
    ASSERT_EQ(expected.size(), whole.steps);
    EXPECT_GT(expected.back().record.coveredColumns.value_or(0), 0u) << "the test needs clouds";
    for (const char* slices : {"1", "3"}) {
        const Scene sliced =
            SlicedLoopScene({{"render.frames_per_step", "56"}, {"render.slices_per_frame", slices}, ground});
        const std::vector<StepView> got = RunAndKeepEveryStep(sliced, *mBackend);
        SCOPED_TRACE(std::string("slices per frame ") + slices);
        ExpectSameBytesEveryStep(got, expected, whole.warmupSteps);
        ASSERT_EQ(got.size(), expected.size());
        for (size_t t = 0; t < got.size(); ++t) {
            SCOPED_TRACE("step " + std::to_string(t));
            const StepRecord &a = expected[t].record, &b = got[t].record;
            EXPECT_EQ(b.framesRendered, a.framesRendered);
            EXPECT_EQ(b.coveredColumns, a.coveredColumns);
            for (Stage stage : kAllStages) {
                EXPECT_EQ(b.skippedUnchanged[size_t(stage)], a.skippedUnchanged[size_t(stage)]) << StageName(stage);
                // The sliced loop does not advance past its last step (nothing would show it).
                if (stage == Stage::Ca && t + 1 == got.size()) continue;
                EXPECT_EQ(b.stageMs[size_t(stage)].has_value(), a.stageMs[size_t(stage)].has_value())
                    << StageName(stage) << " ran in one loop and not in the other";
            }
        }
    }
}

// Placed ellipsoids (SPEC 17) in the sliced loop: the frames update the list for the next step ahead of it, so the
// placed ones must follow the list's step there too. One drifts along keyframes over the run, one is born at step
// 2, one dies at step 3; every resource at every step equals the unsliced loop's.
TEST_P(TimeSliceLoop, PlacedEllipsoidsEqualTheUnslicedLoop) {
    const SceneOverride placed{"ellipsoids.placed",
                               R"([{"semi_axes": [5, 3, 2], "yaw_deg": 40, "persistent": true,
                                    "keyframes": [{"step": 0, "center": [3, 4, 3]}, {"step": 5, "center": [19, 14, 4]}]},
                                   {"center": [16, 5, 3], "semi_axes": [4, 4, 2], "start": 2, "lifetime": 3},
                                   {"center": [6, 15, 3], "semi_axes": [4, 3, 2], "start": 1, "lifetime": 2}])"};
    const Scene whole = SlicedLoopScene({{"render.frames_per_step", "56"}, placed});
    ASSERT_EQ(whole.ellipsoids.placed.size(), 3u);
    const std::vector<StepView> expected = RunAndKeepEveryStep(whole, *mBackend);
    ASSERT_EQ(expected.size(), whole.steps);
    for (const char* slices : {"1", "3"}) {
        const Scene sliced =
            SlicedLoopScene({{"render.frames_per_step", "56"}, {"render.slices_per_frame", slices}, placed});
        SCOPED_TRACE(std::string("slices per frame ") + slices);
        ExpectSameBytesEveryStep(RunAndKeepEveryStep(sliced, *mBackend), expected, whole.warmupSteps);
    }
}

// A sun that stands on each principal axis in turn, one keyframe a step from step 1 on: x, y, z, -x, z, -y, x
// (el, az in degrees; the direction (cos el cos az, cos el sin az, sin el) worked by hand beside each). Each ordered
// pair of axes follows once, so the sweep's length on the 23 x 19 x 7 grid (23 slices along x, 19 along y, 7 along
// z) grows on three steps (z -> x, z -> y, y -> x) and shrinks on three.
struct AxisSun {
    double elevation, azimuth;
    uint32_t slices;  // shade's sweep on the 23 x 19 x 7 grid at resolution 1: the cells along the principal axis
};
constexpr AxisSun kAxisSuns[] = {
    {15, 20, 23},   // (0.908, 0.330, 0.259): x
    {15, 20, 23},   // step 1, the same: x
    {20, 110, 19},  // (-0.321, 0.883, 0.342): y
    {70, 200, 7},   // (-0.321, -0.117, 0.940): z
    {25, 170, 23},  // (-0.893, 0.157, 0.423): -x
    {65, 340, 7},   // (0.397, -0.145, 0.906): z
    {10, 260, 19},  // (-0.171, -0.970, 0.174): -y
    {30, 350, 23},  // (0.853, -0.150, 0.500): x
    {30, 350, 23},  // step 8, the last: the same
};

std::vector<SceneOverride> AxisCrossingSun() {
    std::string path = "[";
    for (size_t t = 0; t < std::size(kAxisSuns); ++t)
        path += (t ? ", " : "") + std::string(R"({"step": )") + std::to_string(t) + R"(, "elevation_deg": )" +
                std::to_string(kAxisSuns[t].elevation) + R"(, "azimuth_deg": )" + std::to_string(kAxisSuns[t].azimuth) +
                "}";
    return {{"steps", std::to_string(std::size(kAxisSuns))}, {"sun.path", path + "]"}};
}

// Test that the sliced loop equals the unsliced loop, every resource at every step, while the sun crosses every
// boundary between principal axes, at 1, 2, 3 and 5 slices a frame: the next step's shade shares must be counted
// with the next step's sun, whose sweep may be longer than this step's.
TEST_P(TimeSliceLoop, SunCrossingEveryAxisBoundaryEqualsTheUnslicedLoop) {
    const SceneOverride ground{"render.ground", R"({"albedo": [0.3, 0.35, 0.3]})"};
    std::vector<SceneOverride> sets = AxisCrossingSun();
    sets.push_back({"render.frames_per_step", "56"});  // above the 48 shares of one slice a frame
    sets.push_back(ground);
    const Scene whole = SlicedLoopScene(sets);
    for (uint32_t t = 0; t < whole.steps; ++t)
        ASSERT_EQ(SweepSlicesAt(whole, t), kAxisSuns[t].slices) << "step " << t << ": the sun is not where intended";
    const std::vector<StepView> expected = RunAndKeepEveryStep(whole, *mBackend);
    ASSERT_EQ(expected.size(), whole.steps);
    EXPECT_GT(expected.back().record.coveredColumns.value_or(0), 0u) << "the test needs clouds";
    for (const char* slices : {"1", "2", "3", "5"}) {
        std::vector<SceneOverride> slicedSets = sets;
        slicedSets.push_back({"render.slices_per_frame", slices});
        const std::vector<StepView> got = RunAndKeepEveryStep(SlicedLoopScene(slicedSets), *mBackend);
        SCOPED_TRACE(std::string("slices per frame ") + slices);
        ExpectSameBytesEveryStep(got, expected, whole.warmupSteps);
        ASSERT_EQ(got.size(), expected.size());
        for (size_t t = whole.warmupSteps; t < got.size(); ++t)
            EXPECT_EQ(got[t].record.framesRendered, expected[t].record.framesRendered) << "step " << t;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, TimeSliceLoop, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const auto& info) { return info.param; });

// A CPU backend that keeps the alpha of every splat call.
class AlphaKeepingCpu : public cpu::BackendCpu {
  public:
    Status RenderSplat(const SplatParams& params, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        alphas.push_back(params.alpha);
        return cpu::BackendCpu::RenderSplat(params, in, image, stats);
    }
    std::vector<float> alphas;
};

// The frame plan at 3 slices per frame, by hand. Step 1 (a render step; step 0 is warm-up and computes step 1
// whole) computes step 2 over its frames: ca over nz = 7 slices (3 frames: 0-2, 3-5, 6), the ellipsoid list with
// region's first share, region (3), smooth (3), density over 3 rows of tiles (1 frame: whole), shade over the
// sweep at step 2's sun (el 30, az 80: y principal, 19 slices -> 7 frames), shadow (1 frame): 18 frames, each
// drawn at alpha (f + 1) / 18. Their times add up to the step's.
TEST(TimeSliceLoopPlan, FramesComputeTheNextStepsShares) {
    const Scene scene = SlicedLoopScene({{"render.slices_per_frame", "3"}});
    ShadeParams sun2 = MakeShadeParams(scene, 2);
    ASSERT_EQ(MakeShadePlan(sun2, scene.grid.size).nw, 19u) << "the sun at step 2 is y-principal";
    AlphaKeepingCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    StepRecord warmup, step1;
    ASSERT_TRUE((*sim)->Step(warmup));
    EXPECT_EQ(warmup.framesRendered, 0u);
    EXPECT_TRUE(warmup.frameWork.empty());
    ASSERT_TRUE((*sim)->Step(step1));
    const std::vector<std::string> plan = {"ca 0-2",      "ca 3-5",     "ca 6-6",      "ellipsoid list, region 0-2",
                                           "region 3-5",  "region 6-6", "smooth 0-2",  "smooth 3-5",
                                           "smooth 6-6",  "density",    "shade 0-2",   "shade 3-5",
                                           "shade 6-8",   "shade 9-11", "shade 12-14", "shade 15-17",
                                           "shade 18-18", "shadow"};
    EXPECT_EQ(step1.frameWork, plan);
    ASSERT_EQ(step1.framesRendered, plan.size());
    ASSERT_EQ(backend.alphas.size(), plan.size());
    for (size_t f = 0; f < plan.size(); ++f) EXPECT_EQ(backend.alphas[f], float(double(f + 1) / plan.size())) << f;
    double sum = 0;
    for (double ms : step1.frameMs) sum += ms;
    EXPECT_NEAR(sum, step1.stepMs, 1e-9 * step1.stepMs + 1e-12);
    // The last step computes nothing ahead: its frames are render.frames_per_step (1), alpha 1.
    StepRecord r;
    for (uint32_t t = 2; t < scene.steps; ++t) ASSERT_TRUE((*sim)->Step(r));
    EXPECT_EQ(r.framesRendered, 1u);
    EXPECT_TRUE(r.frameWork.empty());
    EXPECT_EQ(backend.alphas.back(), 1.0f);
}

// The frame plan under the sun of kAxisSuns, one frame a step and 4 slices a frame: each render step t computes
// step t+1's shade in ceil(n / 4) frames of 4 slices, n being the sweep at step t+1's sun (23, 19 or 7 by hand),
// whatever the sweep at step t's sun.
TEST(TimeSliceLoopPlan, ShadeSharesFollowTheNextStepsSun) {
    std::vector<SceneOverride> sets = AxisCrossingSun();
    sets.push_back({"render.slices_per_frame", "4"});
    const Scene scene = SlicedLoopScene(sets);
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r));
        if (t < scene.warmupSteps || t + 1 == scene.steps) continue;
        std::vector<std::string> shade, want;
        for (const std::string& work : r.frameWork)
            if (work.starts_with("shade")) shade.push_back(work);
        const uint32_t n = kAxisSuns[t + 1].slices;
        for (uint32_t b = 0; b < n; b += 4)
            want.push_back("shade " + std::to_string(b) + "-" + std::to_string(std::min(b + 4, n) - 1));
        EXPECT_EQ(shade, want) << "step " << t << " computes step " << t + 1 << "'s shade, sweep of " << n;
    }
}

// Without time-slicing the whole step is charged to its first frame (the thesis's drop in frame rate).
TEST(TimeSliceLoopPlan, UnslicedStepChargesItsWorkToTheFirstFrame) {
    const Scene scene = SlicedLoopScene({{"render.frames_per_step", "4"}});
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    StepRecord r;
    ASSERT_TRUE((*sim)->Step(r));
    ASSERT_TRUE((*sim)->Step(r));
    ASSERT_EQ(r.frameMs.size(), 4u);
    double renders0 = 0, sum = 0;
    for (const FrameRecord& f : r.frames)
        if (f.frame == 0) renders0 += f.ms;
    for (double ms : r.frameMs) sum += ms;
    EXPECT_NEAR(sum, r.stepMs, 1e-9 * r.stepMs + 1e-12);
    double simulation = 0;
    for (Stage stage : kAllStages)
        if (!Describe(stage).renderer && r.stageMs[size_t(stage)]) simulation += *r.stageMs[size_t(stage)];
    EXPECT_GE(r.frameMs[0], renders0 + simulation);
}

// The third buffer set: one pending buffer per resource the stages write, but not for the automaton's state (its
// `next` is the third set) or the images; none without time-slicing.
TEST(TimeSliceLoopPlan, ThirdBufferSetOnlyWhenSliced) {
    auto pendingOf = [](const Scene& scene) {
        std::set<Resource> pending;
        for (const PlannedBuffer& b : PlanBuffers(scene))
            if (b.role == BufferRole::Pending) pending.insert(b.resource);
        return pending;
    };
    EXPECT_TRUE(pendingOf(SlicedLoopScene({})).empty());
    const std::set<Resource> expected = {Resource::Region, Resource::Q, Resource::ColumnSum, Resource::Tiles,
                                         Resource::Bands,  Resource::T, Resource::Shadow};
    EXPECT_EQ(pendingOf(SlicedLoopScene({{"render.slices_per_frame", "4"}})), expected);
}

TEST(TimeSliceLoopPlan, SceneRules) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    auto noRenderer = ParseScene(text, "ci-small.json",
                                 {{"render.slices_per_frame", "2"}, {"stages", R"(["region", "ca", "smooth"])"}});
    ASSERT_FALSE(noRenderer.has_value());
    EXPECT_NE(noRenderer.error().message.find("render.slices_per_frame"), std::string::npos)
        << noRenderer.error().message;
    auto withAlpha = ParseScene(text, "ci-small.json", {{"render.slices_per_frame", "2"}, {"render.alpha", "0.3"}});
    ASSERT_FALSE(withAlpha.has_value());
    EXPECT_NE(withAlpha.error().message.find("render.alpha"), std::string::npos) << withAlpha.error().message;
    auto negative = ParseScene(text, "ci-small.json", {{"render.slices_per_frame", "-1"}});
    ASSERT_FALSE(negative.has_value());
}

}  // namespace
}  // namespace cb
