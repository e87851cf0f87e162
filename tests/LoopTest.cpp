// The real-time loop: frames between steps and a
// moving sun. Shade and shadow re-run exactly when the sun's direction or
// their density input changed; every frame of a step has its own alpha; the
// run's loop figures and stage counts add up.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/report/Report.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// A CPU backend that counts the calls of the stages the loop schedules, and
// keeps the alpha of every splat call.
class LoopCountingCpu : public cpu::BackendCpu {
  public:
    Status CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) override {
        ++caSteps;
        return cpu::BackendCpu::CaStep(params, in, region, out);
    }
    Status Shade(const ShadeParams& params, const Buffer& q, Buffer& T) override {
        ++shades;
        return cpu::BackendCpu::Shade(params, q, T);
    }
    Status RenderSplat(const SplatParams& params, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        alphas.push_back(params.alpha);
        return cpu::BackendCpu::RenderSplat(params, in, image, stats);
    }
    int caSteps = 0, shades = 0;
    std::vector<float> alphas;
};

// scenes/ci-small.json with `overrides` applied as --set does; a value "null" removes the field instead.
Scene LoopScene(std::vector<SceneOverride> overrides) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    nlohmann::json root = nlohmann::json::parse(file);
    std::vector<SceneOverride> sets;
    for (const SceneOverride& o : overrides) {
        if (o.value != "null") {
            sets.push_back(o);
            continue;
        }
        const size_t dot = o.path.find('.');
        root[o.path.substr(0, dot)].erase(o.path.substr(dot + 1));
    }
    auto scene = ParseScene(root.dump(), "ci-small.json", sets);
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return scene ? *scene : Scene{};
}

// Static noise (no drift) for q: after step 0 nothing but the sun can change the lighting's inputs.
std::vector<SceneOverride> StaticDensity(uint32_t steps, std::vector<SceneOverride> more = {}) {
    std::vector<SceneOverride> o = {{"steps", std::to_string(steps)},
                                    {"warmup_steps", "0"},
                                    {"stages", R"(["noise", "density", "shade", "shadow"])"}};
    o.insert(o.end(), more.begin(), more.end());
    return o;
}

// Runs every step; returns the steps on which `stage` ran and on which it skipped for unchanged inputs.
struct StageSteps {
    std::set<uint32_t> ran, skipped;
};
StageSteps RunAndCollect(const Scene& scene, Stage stage, bool everyStepOutputs = false) {
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend, everyStepOutputs);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    StageSteps out;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord r;
        Status s = (*sim)->Step(r);
        EXPECT_TRUE(s.has_value()) << s.error().message;
        if (r.stageMs[size_t(stage)]) out.ran.insert(t);
        if (r.skippedUnchanged[size_t(stage)]) out.skipped.insert(t);
    }
    return out;
}

std::set<uint32_t> Range(uint32_t from, uint32_t to) {
    std::set<uint32_t> s;
    for (uint32_t t = from; t < to; ++t) s.insert(t);
    return s;
}

// Test that a path's angles are interpolated linearly between keyframes and
// held outside them, and that a speed adds degrees per step (values by hand).
TEST(Loop, SunPathEvaluation) {
    SunSettings sun;
    sun.path = {{2, 10, 0}, {6, 30, 80}, {9, 30, 80}};
    EXPECT_EQ(sun.ElevationAt(0), 10.0);
    EXPECT_EQ(sun.AzimuthAt(1), 0.0);
    EXPECT_EQ(sun.ElevationAt(4), 20.0);  // halfway from step 2 to 6
    EXPECT_EQ(sun.AzimuthAt(4), 40.0);
    EXPECT_EQ(sun.ElevationAt(5), 25.0);  // three quarters
    EXPECT_EQ(sun.AzimuthAt(5), 60.0);
    EXPECT_EQ(sun.ElevationAt(7), 30.0);  // held between two equal keyframes
    EXPECT_EQ(sun.AzimuthAt(8), 80.0);
    EXPECT_EQ(sun.ElevationAt(1000), 30.0);  // held after the last
    EXPECT_TRUE(sun.Moves());

    SunSettings speed;
    speed.elevationDeg = 5;
    speed.azimuthDeg = 100;
    speed.elevationSpeedDeg = 1.5;
    speed.azimuthSpeedDeg = -10;
    EXPECT_EQ(speed.ElevationAt(4), 11.0);
    EXPECT_EQ(speed.AzimuthAt(4), 60.0);
    const Vec3 s = speed.DirectionAt(4);  // SPEC 0: (cos el cos az, cos el sin az, sin el)
    const double el = 11.0 * M_PI / 180, az = 60.0 * M_PI / 180;
    EXPECT_NEAR(s[0], std::cos(el) * std::cos(az), 1e-6);
    EXPECT_NEAR(s[1], std::cos(el) * std::sin(az), 1e-6);
    EXPECT_NEAR(s[2], std::sin(el), 1e-6);

    SunSettings fixed;
    EXPECT_FALSE(fixed.Moves());
    fixed.path = {{5, 20, 20}};  // one keyframe: a fixed sun
    EXPECT_FALSE(fixed.Moves());
}

// Test the scene fields: a path, a speed and frames per step are read; the
// path's step-0 angles become the sun's; defaults leave today's loop.
TEST(Loop, SceneFieldsAreRead) {
    const Scene plain = LoopScene({});
    EXPECT_EQ(plain.render.framesPerStep, 1u);
    EXPECT_FALSE(plain.sun.Moves());
    EXPECT_EQ(plain.render.FrameAlpha(0), float(plain.render.alpha));

    const Scene path = LoopScene({{"sun.elevation_deg", "null"},
                                  {"sun.azimuth_deg", "null"},
                                  {"sun.path", R"([{"step": 0, "elevation_deg": 50, "azimuth_deg": 10},
                                                   {"step": 4, "elevation_deg": 10, "azimuth_deg": 90}])"},
                                  {"render.alpha", "null"},
                                  {"render.frames_per_step", "4"}});
    ASSERT_EQ(path.sun.path.size(), 2u);
    EXPECT_EQ(path.sun.elevationDeg, 50.0);
    EXPECT_EQ(path.sun.azimuthDeg, 10.0);
    EXPECT_EQ(path.sun.ElevationAt(1), 40.0);
    EXPECT_EQ(path.render.framesPerStep, 4u);
    EXPECT_EQ(path.render.FrameAlpha(0), 0.25f);
    EXPECT_EQ(path.render.FrameAlpha(3), 1.0f);

    const Scene speed = LoopScene({{"sun.speed", R"({"elevation_deg": -0.5, "azimuth_deg": 2})"}});
    EXPECT_EQ(speed.sun.elevationSpeedDeg, -0.5);
    EXPECT_EQ(speed.sun.azimuthSpeedDeg, 2.0);
    EXPECT_TRUE(speed.sun.Moves());
}

// Test that with a static density and a fixed sun, shade and shadow (and the
// density stage) run once, on step 0, and skip every later step.
TEST(Loop, FixedSunStaticDensityShadesOnce) {
    const Scene scene = LoopScene(StaticDensity(6));
    for (Stage stage : {Stage::Shade, Stage::Shadow, Stage::Density}) {
        const StageSteps s = RunAndCollect(scene, stage);
        EXPECT_EQ(s.ran, (std::set<uint32_t>{0})) << StageName(stage);
        EXPECT_EQ(s.skipped, Range(1, 6)) << StageName(stage);
    }
}

// Keyframes: the sun holds at (30, 40) to step 2, moves to (50, 80) by step 6
// (steps 3, 4, 5, 6 each move it), and holds to the end.
const char* kHoldMoveHold = R"([{"step": 0, "elevation_deg": 30, "azimuth_deg": 40},
                                {"step": 2, "elevation_deg": 30, "azimuth_deg": 40},
                                {"step": 6, "elevation_deg": 50, "azimuth_deg": 80},
                                {"step": 8, "elevation_deg": 50, "azimuth_deg": 80}])";

std::vector<SceneOverride> HoldMoveHold(uint32_t steps) {
    return StaticDensity(steps, {{"sun.elevation_deg", "null"}, {"sun.azimuth_deg", "null"}, {"sun.path", kHoldMoveHold}});
}

// Test that shade and shadow re-run exactly on the steps where the sun moved
// (and on step 0), and that keyframes holding still cause no re-run.
TEST(Loop, MovingSunReshadesExactlyWhereItMoved) {
    const Scene scene = LoopScene(HoldMoveHold(10));
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        const StageSteps s = RunAndCollect(scene, stage);
        EXPECT_EQ(s.ran, (std::set<uint32_t>{0, 3, 4, 5, 6})) << StageName(stage);
        EXPECT_EQ(s.skipped, (std::set<uint32_t>{1, 2, 7, 8, 9})) << StageName(stage);
    }
    // The density does not depend on the sun: it still runs once.
    EXPECT_EQ(RunAndCollect(scene, Stage::Density).ran, (std::set<uint32_t>{0}));
}

// Test that a sun that moved on a step that was not an output step still
// re-shades on the next output step: renders on steps 0, 4 and 8 only, the sun
// moves from (30, 40) to (50, 80) on step 2 and holds, so shade runs on 0 and
// 4 (its direction differs from step 0's run) and skips 8.
TEST(Loop, SunMovedBetweenOutputStepsReshadesOnTheNext) {
    const Scene scene = LoopScene({{"steps", "9"},
                                   {"warmup_steps", "0"},
                                   {"stages", R"(["noise", "density", "shade", "shadow", "render_splat"])"},
                                   {"render.every_steps", "4"},
                                   {"sun.elevation_deg", "null"},
                                   {"sun.azimuth_deg", "null"},
                                   {"sun.path", R"([{"step": 1, "elevation_deg": 30, "azimuth_deg": 40},
                                                    {"step": 2, "elevation_deg": 50, "azimuth_deg": 80}])"}});
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        const StageSteps s = RunAndCollect(scene, stage);
        EXPECT_EQ(s.ran, (std::set<uint32_t>{0, 4})) << StageName(stage);
        EXPECT_EQ(s.skipped, (std::set<uint32_t>{8})) << StageName(stage);
    }
    EXPECT_EQ(RunAndCollect(scene, Stage::RenderSplat).ran, (std::set<uint32_t>{0, 4, 8}));
}

// Test that a constant angular speed re-shades on every step.
TEST(Loop, SunSpeedReshadesEveryStep) {
    const Scene scene = LoopScene(StaticDensity(5, {{"sun.speed", R"({"azimuth_deg": 3})"}}));
    EXPECT_EQ(RunAndCollect(scene, Stage::Shade).ran, Range(0, 5));
    EXPECT_EQ(RunAndCollect(scene, Stage::Shadow).ran, Range(0, 5));
}

// Test that with the automaton (q changes every step) and a fixed sun shade and shadow run every step.
TEST(Loop, AutomatonReshadesEveryStep) {
    const Scene scene = LoopScene({{"steps", "5"}, {"warmup_steps", "0"}});
    EXPECT_EQ(RunAndCollect(scene, Stage::Shade, /*everyStepOutputs=*/true).ran, Range(0, 5));
    EXPECT_EQ(RunAndCollect(scene, Stage::Shadow, /*everyStepOutputs=*/true).ran, Range(0, 5));
}

// T and G of each step of the moving sun, and of the same steps with the sun fixed at given angles.
struct Lit {
    std::vector<std::vector<float>> T, G;
};
Lit RunLit(const Scene& scene) {
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    Lit lit;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord r;
        Status s = (*sim)->Step(r, [&](const Simulation& at) -> Status {
            lit.T.push_back(test::Read<float>(backend, *at.T()));
            lit.G.push_back(test::Read<float>(backend, *at.Shadow()));
            return {};
        });
        EXPECT_TRUE(s.has_value()) << s.error().message;
    }
    return lit;
}

size_t CountDiffering(const std::vector<float>& a, const std::vector<float>& b, float by) {
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) n += std::fabs(a[i] - b[i]) > by;
    return n;
}

// Test that T and G really follow the sun: at steps 4 and 6 of the path they
// are identical to runs with the sun fixed at (40, 60) and (50, 80) (the
// path's angles there, by hand), and they differ from step 0's.
TEST(Loop, ShadingFollowsTheSun) {
    const Lit moving = RunLit(LoopScene(HoldMoveHold(8)));
    const Lit at4 = RunLit(LoopScene(StaticDensity(1, {{"sun.elevation_deg", "40"}, {"sun.azimuth_deg", "60"}})));
    const Lit at6 = RunLit(LoopScene(StaticDensity(1, {{"sun.elevation_deg", "50"}, {"sun.azimuth_deg", "80"}})));
    const Lit at0 = RunLit(LoopScene(StaticDensity(1, {{"sun.elevation_deg", "30"}, {"sun.azimuth_deg", "40"}})));
    ASSERT_EQ(moving.T.size(), 8u);
    EXPECT_EQ(moving.T[4], at4.T[0]);
    EXPECT_EQ(moving.G[4], at4.G[0]);
    EXPECT_EQ(moving.T[6], at6.T[0]);
    EXPECT_EQ(moving.G[6], at6.G[0]);
    EXPECT_EQ(moving.T[7], at6.T[0]);  // held: the step-6 shading stays
    EXPECT_EQ(moving.T[2], at0.T[0]);
    EXPECT_GT(CountDiffering(moving.T[4], moving.T[0], 1e-3f), 100u);
    EXPECT_GT(CountDiffering(moving.G[6], moving.G[0], 1e-3f), 10u);
}

// Test frames between steps: with F = 4 each render step draws 4 frames per
// camera at alpha 1/4, 2/4, 3/4, 1 while the automaton and shade run once a
// step; the last frame is the frame a single render at alpha 1 draws, and the
// frame at alpha 1/2 draws the splats a single render at alpha 1/2 draws.
TEST(Loop, FramesBetweenSteps) {
    const std::vector<SceneOverride> base = {{"steps", "4"}, {"warmup_steps", "0"}, {"render.every_steps", "1"}};
    auto with = [&](std::vector<SceneOverride> more) {
        std::vector<SceneOverride> o = base;
        o.insert(o.end(), more.begin(), more.end());
        return LoopScene(o);
    };
    const Scene four = with({{"render.alpha", "null"}, {"render.frames_per_step", "4"}});
    const size_t cameras = four.render.cameras.size();
    ASSERT_GE(cameras, 1u);

    LoopCountingCpu backend;
    auto sim = Simulation::Create(four, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    std::vector<StepRecord> records;
    for (uint32_t t = 0; t < four.steps; ++t) {
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        EXPECT_EQ(r.framesRendered, 4u);
        ASSERT_EQ(r.frames.size(), 4 * cameras);
        for (size_t i = 0; i < r.frames.size(); ++i) {
            EXPECT_EQ(r.frames[i].frame, i / cameras);
            EXPECT_EQ(r.frames[i].alpha, float(i / cameras + 1) / 4.0f);
        }
        records.push_back(r);
    }
    EXPECT_EQ(backend.caSteps, 4);
    EXPECT_EQ(backend.shades, 4);
    std::vector<float> expected;
    for (int t = 0; t < 4; ++t)
        for (float a : {0.25f, 0.5f, 0.75f, 1.0f})
            for (size_t c = 0; c < cameras; ++c) expected.push_back(a);
    EXPECT_EQ(backend.alphas, expected);
    const std::vector<float> last = test::Read<float>(backend, *(*sim)->Image(0));

    // One frame a step at alpha 1, and at alpha 1/2: the same steps' frames.
    for (const char* alpha : {"1", "0.5"}) {
        const Scene one = with({{"render.alpha", alpha}});
        cpu::BackendCpu single;
        auto ref = Simulation::Create(one, single);
        ASSERT_TRUE(ref.has_value());
        for (uint32_t t = 0; t < one.steps; ++t) {
            StepRecord r;
            ASSERT_TRUE((*ref)->Step(r).has_value());
            ASSERT_EQ(r.frames.size(), cameras);
            const uint32_t f = std::string(alpha) == "1" ? 3 : 1;
            for (size_t c = 0; c < cameras; ++c)
                EXPECT_EQ(r.frames[c].counters[0], records[t].frames[f * cameras + c].counters[0])
                    << "step " << t << " alpha " << alpha;
        }
        if (std::string(alpha) == "1") {
            EXPECT_EQ(test::Read<float>(single, *(*ref)->Image(0)), last);
        }
    }
    // The alphas matter: the splat counts of frames 0 and 3 differ on some step after the first.
    bool differ = false;
    for (uint32_t t = 1; t < four.steps; ++t) differ |= records[t].frames[0].counters[0] != records[t].frames[3 * cameras].counters[0];
    EXPECT_TRUE(differ);
}

// Test the loop figures and the stage counts from hand-made step records:
// 3 timed steps of 4 frames in 10 + 10 + 20 ms are 12 frames in 40 ms, 300 fps.
TEST(Loop, LoopFiguresAndCounts) {
    Scene scene = LoopScene({{"warmup_steps", "1"}});
    BackendRun run;
    for (uint32_t t = 0; t < 4; ++t) {
        StepRecord r;
        r.step = t;
        r.framesRendered = 4;
        r.stepMs = t == 3 ? 20 : (t == 0 ? 1000 : 10);  // step 0 is warm-up
        r.stageMs[size_t(Stage::RenderSplat)] = 1;
        if (t % 2 == 0)
            r.stageMs[size_t(Stage::Shade)] = 1;
        else
            r.skippedUnchanged[size_t(Stage::Shade)] = true;
        run.steps.push_back(r);
    }
    const LoopFigures loop = MeasureLoop(scene, run);
    EXPECT_EQ(loop.steps, 3u);
    EXPECT_EQ(loop.frames, 12u);
    EXPECT_DOUBLE_EQ(loop.wallMs, 40.0);
    ASSERT_TRUE(loop.Fps().has_value());
    EXPECT_DOUBLE_EQ(*loop.Fps(), 300.0);
    const StageRunCount shade = CountStageRuns(run, Stage::Shade);
    EXPECT_EQ(shade.ran, 2u);
    EXPECT_EQ(shade.skippedUnchanged, 2u);
    EXPECT_EQ(shade.notOutputStep, 0u);
    EXPECT_EQ(CountStageRuns(run, Stage::RenderSplat).frames, 16u);
    EXPECT_EQ(CountStageRuns(run, Stage::Shadow).notOutputStep, 4u);

    const nlohmann::json doc = ResultsJson(scene, {run});
    const nlohmann::json& b = doc["backends"][""];
    EXPECT_EQ(b["loop"]["frames"], 12);
    EXPECT_DOUBLE_EQ(b["loop"]["fps"].get<double>(), 300.0);
    EXPECT_EQ(b["stage_runs"]["shade"]["skipped_unchanged"], 2);
}

}  // namespace
}  // namespace cb
