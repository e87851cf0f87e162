// The harness's two ways to time a step (docs/performance.md,
// "Two ways to time a step"), against a CPU backend that plays a device: it
// logs every stage call with the batch and the interval it fell in, gives each
// call a known device cost (its number in the log), and counts a submission
// and a host wait per call outside a batch and per batch. From that log alone
// the test works out what the Simulation must report: one batch per step (one
// per frame time-sliced), one mark before every stage call in schedule order,
// each interval's time given to the stage (and frame) that made it, a batch
// ended when a call fails, and the counts' differences per step.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <span>
#include <utility>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/report/Report.h"
#include "harness/run/RunTransfer.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

class BatchLoggingCpu : public cpu::BackendCpu {
  public:
    struct Call {
        std::string stage;
        int batch = -1;     // the batch it was recorded in (0, 1, ... over the backend's life), -1 outside
        int interval = -1;  // its interval in that batch (-1: before any mark)
        double cost = 0;    // its device time: its number in the log, from 1
    };
    std::vector<Call> calls;
    // The calls logged from index `first` on (a step's, when `first` was the size before it).
    std::span<const Call> CallsSince(size_t first) const { return std::span(calls).subspan(first); }
    int begins = 0, ends = 0;
    bool open = false, nested = false, markOutside = false;
    std::vector<int> marksPerBatch;
    uint64_t submissions = 0, waits = 0;
    // A fault: the call of `failStage` numbered `failAt` (from 1) fails.
    std::string failStage;
    int failAt = 0, failSeen = 0;
    // EndBatch returns this many extra times (after the intervals'), or, with leading, one time in front.
    int extraTimes = 0;
    bool leading = false;
    // In a batch, density's cover and render_splat's stats are deferred (core/pipeline/Backend.h): the call leaves
    // the caller's values and TakeDeferredResults gives them, by mark, after EndBatch.
    bool deferResults = false;

    Status BeginBatch() override {
        nested |= open;
        open = true;
        ++begins;
        mIntervals.clear();
        marksPerBatch.push_back(0);
        return {};
    }
    void MarkBatch() override {
        markOutside |= !open;
        if (!open) return;
        mIntervals.push_back(0);
        ++marksPerBatch.back();
    }
    Result<std::vector<double>> EndBatch() override {
        open = false;
        ++ends;
        ++submissions;
        ++waits;
        std::vector<double> times = mIntervals;
        if (leading) times.insert(times.begin(), 1e6);
        for (int i = 0; i < extraTimes; ++i) times.push_back(1e6);
        return times;
    }
    std::vector<DeferredHostResult> TakeDeferredResults() override { return std::exchange(mDeferred, {}); }
    SubmissionCounts Submissions() const override { return {submissions, waits}; }
    std::optional<double> LastDeviceMs() const override { return mLast; }

    Status Region(std::span<const RasterEllipsoid> e, Buffer& region, SliceRange slices) override {
        CB_TRY(Note("region"));
        return cpu::BackendCpu::Region(e, region, slices);
    }
    Status CaStep(const CaStepParams& p, ConstCaFields in, const Buffer& region, CaFields out) override {
        CB_TRY(Note("ca"));
        return cpu::BackendCpu::CaStep(p, in, region, out);
    }
    Status Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) override {
        CB_TRY(Note("smooth"));
        return cpu::BackendCpu::Smooth(radius, cld, q, slices);
    }
    Status Density(const DensityParams& p, const Buffer& q, const Buffer* cld, DensityOutputs& out) override {
        CB_TRY(Note("density"));
        if (!Deferring()) return cpu::BackendCpu::Density(p, q, cld, out);
        const uint32_t callers = out.coveredColumns;
        CB_TRY(cpu::BackendCpu::Density(p, q, cld, out));
        mDeferred.push_back({uint32_t(mIntervals.size()), out.coveredColumns, std::nullopt});
        out.coveredColumns = callers;
        return {};
    }
    Status Shade(const ShadeParams& p, const Buffer& q, Buffer& T) override {
        CB_TRY(Note("shade"));
        return cpu::BackendCpu::Shade(p, q, T);
    }
    Status Shadow(const ShadowParams& p, const Buffer& d, Buffer& G) override {
        CB_TRY(Note("shadow"));
        return cpu::BackendCpu::Shadow(p, d, G);
    }
    Status RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        CB_TRY(Note("render_splat"));
        if (!Deferring() || !stats) return cpu::BackendCpu::RenderSplat(p, in, image, stats);
        SplatStats counted;
        CB_TRY(cpu::BackendCpu::RenderSplat(p, in, image, &counted));
        mDeferred.push_back({uint32_t(mIntervals.size()), std::nullopt, ToFrameCounters(counted, kSplatCounters)});
        return {};
    }

  private:
    bool Deferring() const { return deferResults && open; }
    Status Note(const std::string& stage) {
        Call call{stage, open ? begins - 1 : -1, open ? int(mIntervals.size()) - 1 : -1, double(calls.size() + 1)};
        calls.push_back(call);
        if (open && !mIntervals.empty()) mIntervals.back() += call.cost;
        if (!open) {
            ++submissions;
            ++waits;
            mLast = call.cost;
        }
        if (stage == failStage && ++failSeen == failAt) return MakeError("injected fault");
        return {};
    }
    std::vector<double> mIntervals;
    std::optional<double> mLast;
    std::vector<DeferredHostResult> mDeferred;
};

// scenes/ci-small.json, small: 4 steps, no warm-up, a render every step of 2 frames, two cameras.
Scene BatchScene(std::vector<SceneOverride> more = {}) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::vector<SceneOverride> sets = {
        {"grid.size", "[32, 24, 8]"},
        {"steps", "4"},
        {"warmup_steps", "0"},
        {"ca.act0", "0.03"},
        {"density.tile", "8"},
        {"render.width", "40"},
        {"render.height", "30"},
        {"render.every_steps", "1"},
        {"render.frames_per_step", "2"},
        {"render.cameras",
         R"([{"name": "a", "eye": [800, -700, 1100], "target": [800, 600, 200], "up": [0, 0, 1], "fov_deg": 70,
              "near": 1, "far": 20000},
             {"name": "b", "eye": [-500, 600, 900], "target": [800, 600, 200], "up": [0, 0, 1], "fov_deg": 60,
              "near": 1, "far": 20000}])"},
    };
    sets.insert(sets.end(), more.begin(), more.end());
    auto scene = ParseScene(text, "ci-small.json", sets);
    EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
    return scene ? *scene : Scene{};
}

std::vector<std::string> Names(std::span<const BatchLoggingCpu::Call> calls) {
    std::vector<std::string> names;
    for (const auto& c : calls) names.push_back(c.stage);
    return names;
}

// What an unsliced step must call, in order (harness/run/Simulation.h): the stages that ran that neither render nor
// advance the state, in schedule order; each frame's renderers, one call per camera; then the state's advance.
std::vector<std::string> ExpectedOrder(const Simulation& sim, const StepRecord& r) {
    std::vector<std::string> order;
    for (Stage s : sim.Schedule())
        if (!Describe(s).renderer && !Describe(s).advancesState && r.Ran(s)) order.emplace_back(StageName(s));
    for (uint32_t f = 0; f < r.framesRendered; ++f)
        for (Stage s : sim.Schedule())
            if (Describe(s).renderer)
                for (size_t n = 0; n < sim.GetScene().render.cameras.size(); ++n) order.emplace_back(StageName(s));
    for (Stage s : sim.Schedule())
        if (Describe(s).advancesState) order.emplace_back(StageName(s));
    return order;
}

// Each stage's device time as the log says: the sum of its calls' costs; and the renderer calls' costs in order.
std::map<std::string, double> CostByStage(std::span<const BatchLoggingCpu::Call> calls) {
    std::map<std::string, double> cost;
    for (const auto& c : calls) cost[c.stage] += c.cost;
    return cost;
}

void ExpectDeviceTimesFromLog(const StepRecord& r, std::span<const BatchLoggingCpu::Call> calls) {
    const auto cost = CostByStage(calls);
    for (Stage s : kAllStages) {
        const auto it = cost.find(std::string(StageName(s)));
        if (it == cost.end()) {
            EXPECT_FALSE(r.deviceMs[size_t(s)].has_value()) << StageName(s);
            continue;
        }
        ASSERT_TRUE(r.deviceMs[size_t(s)].has_value()) << StageName(s);
        EXPECT_EQ(*r.deviceMs[size_t(s)], it->second) << StageName(s) << " at step " << r.step;
    }
    std::vector<double> renders;
    for (const auto& c : calls)
        if (c.stage == "render_splat") renders.push_back(c.cost);
    ASSERT_EQ(r.frames.size(), renders.size());
    for (size_t i = 0; i < renders.size(); ++i) {
        ASSERT_TRUE(r.frames[i].deviceMs.has_value()) << "frame " << i;
        EXPECT_EQ(*r.frames[i].deviceMs, renders[i]) << "frame " << i << " (" << r.frames[i].camera << ")";
    }
}

// Test that a pipelined step is one batch with one mark before each call, in schedule order, and that each interval's
// time goes to the stage and frame whose call followed the mark; stage call times are host time; 1 submission, 1 wait.
TEST(PipelinedTiming, OneBatchPerStepOneMarkPerCallTimesToTheirStagesAndFrames) {
    const Scene scene = BatchScene();
    BatchLoggingCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    (*sim)->SetTiming(TimingMode::Pipelined);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        const size_t first = backend.calls.size();
        const int begins = backend.begins;
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        const std::span<const BatchLoggingCpu::Call> calls = backend.CallsSince(first);
        EXPECT_EQ(backend.begins, begins + 1) << "one batch per step";
        EXPECT_EQ(backend.ends, backend.begins);
        EXPECT_EQ(r.batches, 1u);
        EXPECT_EQ(r.timing, TimingMode::Pipelined);
        // Every call in the step's batch, each in its own interval, opened just before it: one mark per call.
        ASSERT_FALSE(calls.empty());
        EXPECT_EQ(backend.marksPerBatch.back(), int(calls.size()));
        for (size_t i = 0; i < calls.size(); ++i) {
            EXPECT_EQ(calls[i].batch, backend.begins - 1) << calls[i].stage;
            EXPECT_EQ(calls[i].interval, int(i)) << calls[i].stage;
        }
        EXPECT_EQ(Names(calls), ExpectedOrder(**sim, r)) << "step " << t;
        EXPECT_EQ(r.framesRendered, 2u);
        EXPECT_EQ(r.frames.size(), 4u);  // 2 frames x 2 cameras
        ExpectDeviceTimesFromLog(r, calls);
        // A stage's call time is host recording time, not stage time.
        for (Stage s : kAllStages) {
            EXPECT_FALSE(r.stageMs[size_t(s)].has_value()) << StageName(s);
            EXPECT_EQ(r.hostMs[size_t(s)].has_value(), CostByStage(calls).count(std::string(StageName(s))) == 1)
                << StageName(s);
        }
        for (const FrameRecord& f : r.frames) EXPECT_TRUE(f.pipelined);
        EXPECT_EQ(r.submissions, 1u);
        EXPECT_EQ(r.hostWaits, 1u);
    }
    EXPECT_FALSE(backend.nested);
    EXPECT_FALSE(backend.markOutside);
}

// Test that host results a backend defers to the batch's end (the cover, each frame's splat stats) reach the
// records of their calls: a pipelined run with deferral reports what a synchronized run reports, unsliced (one
// whole density a step) and time-sliced (density in shares whose covers add up, one batch a frame).
TEST(PipelinedTiming, DeferredCoverAndSplatStatsReachTheirRecords) {
    for (const char* slices : {"0", "2"}) {
        const Scene scene = BatchScene({{"render.slices_per_frame", slices}, {"density.tile", "4"}});
        BatchLoggingCpu deferring, plain;
        deferring.deferResults = true;
        auto a = Simulation::Create(scene, deferring), b = Simulation::Create(scene, plain);
        ASSERT_TRUE(a.has_value() && b.has_value());
        (*a)->SetTiming(TimingMode::Pipelined);
        bool anyCover = false, anySplats = false;
        for (uint32_t t = 0; t < scene.steps; ++t) {
            StepRecord ra, rb;
            ASSERT_TRUE((*a)->Step(ra).has_value());
            ASSERT_TRUE((*b)->Step(rb).has_value());
            ASSERT_TRUE(rb.coveredColumns.has_value());
            anyCover |= *rb.coveredColumns > 0;
            EXPECT_EQ(ra.coveredColumns, rb.coveredColumns) << "slices " << slices << ", step " << t;
            ASSERT_EQ(ra.frames.size(), rb.frames.size());
            for (size_t f = 0; f < ra.frames.size(); ++f) {
                // The splat counters in kSplatCounters' order: splats, voxels visited, fragments.
                anySplats |= rb.frames[f].counters[0] > 0;
                EXPECT_EQ(ra.frames[f].counters, rb.frames[f].counters) << "frame " << f;
            }
        }
        EXPECT_GT(deferring.begins, 0);
        // Zeros everywhere would not tell a lost result.
        EXPECT_TRUE(anyCover && anySplats) << "slices " << slices;
    }
}

// Test that a synchronized step (the default) opens no batch, takes device times from LastDeviceMs and reports the
// backend's counts over the step: here one submission and one wait per call.
TEST(PipelinedTiming, SynchronizedStepsOpenNoBatchAndCountEveryCall) {
    const Scene scene = BatchScene();
    BatchLoggingCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    EXPECT_EQ((*sim)->Timing(), TimingMode::Synchronized);  // the default
    for (uint32_t t = 0; t < scene.steps; ++t) {
        const size_t first = backend.calls.size();
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        const std::span<const BatchLoggingCpu::Call> calls = backend.CallsSince(first);
        EXPECT_EQ(r.batches, 0u);
        EXPECT_EQ(Names(calls), ExpectedOrder(**sim, r)) << "step " << t;
        // Outside a batch each call is a submission and a wait (the fake's counts); LastDeviceMs gives its time.
        EXPECT_EQ(r.submissions, calls.size());
        EXPECT_EQ(r.hostWaits, calls.size());
        ExpectDeviceTimesFromLog(r, calls);
        for (Stage s : kAllStages) EXPECT_FALSE(r.hostMs[size_t(s)].has_value()) << StageName(s);
        for (const auto& c : calls) {
            EXPECT_EQ(c.batch, -1);
            EXPECT_TRUE(r.stageMs[size_t(*ParseStage(c.stage))].has_value()) << c.stage;
        }
    }
    EXPECT_EQ(backend.begins, 0);
    EXPECT_FALSE(backend.markOutside);
}

// Test that an observer (dump, conform) sees no open batch: the step's stages and frames are one batch, the
// automaton's advance after the observer another.
TEST(PipelinedTiming, AnObserverEndsTheBatchBeforeItAndAnotherHoldsTheRest) {
    const Scene scene = BatchScene({{"steps", "2"}});
    BatchLoggingCpu backend;
    auto sim = Simulation::Create(scene, backend, /*everyStepOutputs=*/true);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    (*sim)->SetTiming(TimingMode::Pipelined);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        const size_t first = backend.calls.size();
        const int begins = backend.begins;
        size_t callsBeforeObserver = 0;
        StepRecord r;
        const Status status = (*sim)->Step(r, [&](const Simulation&) -> Status {
            EXPECT_FALSE(backend.open) << "the observer reads finished buffers";
            callsBeforeObserver = backend.calls.size();
            return {};
        });
        ASSERT_TRUE(status.has_value()) << status.error().message;
        EXPECT_EQ(backend.begins, begins + 2);
        EXPECT_EQ(r.batches, 2u);
        EXPECT_EQ(r.submissions, 2u);
        EXPECT_EQ(r.hostWaits, 2u);
        const std::span<const BatchLoggingCpu::Call> calls = backend.CallsSince(first);
        for (size_t i = 0; i < calls.size(); ++i) {
            // Before the observer: the first batch; after it (the automaton): the second.
            const bool before = first + i < callsBeforeObserver;
            EXPECT_EQ(calls[i].batch, before ? begins : begins + 1) << calls[i].stage;
            EXPECT_EQ(calls[i].stage == "ca", !before) << calls[i].stage;
        }
        ExpectDeviceTimesFromLog(r, calls);
    }
}

// Test that a time-sliced pipelined step opens one batch per frame (and step 0 one more for its own stages), each
// frame's renders in its frame's batch with their own times.
TEST(PipelinedTiming, TimeSlicedOneBatchPerFrame) {
    const Scene scene = BatchScene({{"render.slices_per_frame", "3"}, {"steps", "3"}});
    BatchLoggingCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    (*sim)->SetTiming(TimingMode::Pipelined);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        const size_t first = backend.calls.size();
        const int begins = backend.begins;
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        const std::span<const BatchLoggingCpu::Call> calls = backend.CallsSince(first);
        // Step 0 computes its own stages first, in a batch of their own; then one batch per frame.
        const int before = t == 0 ? 1 : 0;
        EXPECT_GE(r.frameMs.size(), 2u);
        EXPECT_EQ(backend.begins - begins, before + int(r.frameMs.size())) << "step " << t;
        EXPECT_EQ(r.batches, uint32_t(backend.begins - begins));
        EXPECT_EQ(r.submissions, r.batches);
        EXPECT_EQ(r.hostWaits, r.batches);
        // Frame f's renders are in batch begins + before + f, each call in its own interval.
        size_t render = 0;
        for (const auto& c : calls) {
            EXPECT_GE(c.batch, begins) << c.stage;
            EXPECT_GE(c.interval, 0) << c.stage;
            if (c.stage != "render_splat") continue;
            ASSERT_LT(render, r.frames.size());
            EXPECT_EQ(c.batch, begins + before + int(r.frames[render].frame)) << "frame " << r.frames[render].frame;
            ASSERT_TRUE(r.frames[render].deviceMs.has_value());
            EXPECT_EQ(*r.frames[render].deviceMs, c.cost);
            ++render;
        }
        EXPECT_EQ(render, r.frames.size());
        for (size_t b = size_t(begins); b < size_t(backend.begins); ++b) {
            int inBatch = 0;
            for (const auto& c : calls) inBatch += c.batch == int(b) ? 1 : 0;
            EXPECT_EQ(backend.marksPerBatch[b], inBatch) << "batch " << b;
        }
    }
    EXPECT_FALSE(backend.nested);
    EXPECT_FALSE(backend.markOutside);
}

// Test that a stage that fails inside a batch still ends the batch, and the step reports the stage's error.
TEST(PipelinedTiming, AFailedCallEndsItsBatchAndReportsTheStage) {
    const Scene scene = BatchScene();
    BatchLoggingCpu backend;
    backend.failStage = "smooth";
    backend.failAt = 2;  // step 1's smooth
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    (*sim)->SetTiming(TimingMode::Pipelined);
    StepRecord r;
    ASSERT_TRUE((*sim)->Step(r).has_value());
    const Status failed = (*sim)->Step(r);
    ASSERT_FALSE(failed.has_value());
    EXPECT_NE(failed.error().message.find("smooth: injected fault"), std::string::npos) << failed.error().message;
    EXPECT_FALSE(backend.open);
    EXPECT_EQ(backend.begins, 2);
    EXPECT_EQ(backend.ends, 2);
}

// Test that EndBatch may give one leading time (before the first mark), which is dropped, and that any other
// count of times that is not one per mark fails the step, naming the counts.
TEST(PipelinedTiming, EndBatchTimesMustMatchTheMarks) {
    const Scene scene = BatchScene({{"steps", "1"}});
    {
        BatchLoggingCpu backend;
        backend.leading = true;  // one time in front, before the first mark: dropped
        auto sim = Simulation::Create(scene, backend);
        ASSERT_TRUE(sim.has_value());
        (*sim)->SetTiming(TimingMode::Pipelined);
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        ExpectDeviceTimesFromLog(r, std::span(backend.calls).subspan(0));
    }
    {
        BatchLoggingCpu backend;
        backend.extraTimes = 2;
        auto sim = Simulation::Create(scene, backend);
        ASSERT_TRUE(sim.has_value());
        (*sim)->SetTiming(TimingMode::Pipelined);
        StepRecord r;
        const Status status = (*sim)->Step(r);
        ASSERT_FALSE(status.has_value());
        EXPECT_NE(status.error().message.find("returned"), std::string::npos) << status.error().message;
        EXPECT_FALSE(backend.open);
    }
}

// Test the order of `run --timing both`, S P P S repeated, worked by hand, and why: over every four steps the
// mean step index of each mode is the same, so a cost that grows linearly with the step weighs the same on both.
TEST(PipelinedTiming, BothAlternatesSPPSSoADriftWeighsTheSame) {
    const char* expected = "SPPSSPPSSPPS";
    for (uint32_t t = 0; t < 12; ++t)
        EXPECT_EQ(TimingOfStep("both", t), expected[t] == 'P' ? TimingMode::Pipelined : TimingMode::Synchronized)
            << "step " << t;
    for (uint32_t blocks = 1; blocks <= 5; ++blocks) {
        double sumS = 0, sumP = 0;
        for (uint32_t t = 0; t < 4 * blocks; ++t) (TimingOfStep("both", t) == TimingMode::Pipelined ? sumP : sumS) += t;
        EXPECT_EQ(sumS, sumP) << blocks << " blocks";
    }
    for (uint32_t t = 0; t < 8; ++t) {
        EXPECT_EQ(TimingOfStep("pipelined", t), TimingMode::Pipelined);
        EXPECT_EQ(TimingOfStep("synchronized", t), TimingMode::Synchronized);
    }
}

// `run --timing both` (here even steps synchronized, odd pipelined, set by the test); results.json reports each mode
// apart.
TEST(PipelinedTiming, ResultsJsonReportsEachModeWithItsCounts) {
    const Scene scene = BatchScene({{"steps", "6"}, {"warmup_steps", "2"}});
    BatchLoggingCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    BackendRun run;
    run.name = "cpu";
    std::map<std::string, std::vector<double>> callsPerStep;  // by mode, after warm-up
    std::vector<double> regionDevicePipelined, regionSync, frameDevicePipelined;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        const bool pipelined = t % 2 == 1;
        (*sim)->SetTiming(pipelined ? TimingMode::Pipelined : TimingMode::Synchronized);
        const size_t first = backend.calls.size();
        StepRecord r;
        ASSERT_TRUE((*sim)->Step(r).has_value());
        run.steps.push_back(r);
        if (t < scene.warmupSteps) continue;
        callsPerStep[pipelined ? "pipelined" : "synchronized"].push_back(double(backend.calls.size() - first));
        for (size_t i = first; i < backend.calls.size(); ++i) {
            const auto& c = backend.calls[i];
            if (pipelined && c.stage == "region") regionDevicePipelined.push_back(c.cost);
            if (pipelined && c.stage == "render_splat") frameDevicePipelined.push_back(c.cost);
        }
        if (!pipelined) regionSync.push_back(*r.stageMs[size_t(Stage::Region)]);
    }
    // Through the worker-process transfer, as `run` gets them.
    for (StepRecord& r : run.steps) r = transfer::StepFromJson(nlohmann::json::parse(transfer::ToJson(r).dump()));
    const nlohmann::json b = ResultsJson(scene, {run})["backends"]["cpu"];
    const nlohmann::json& timing = b["timing"];
    EXPECT_EQ(timing["mode"], "both");
    const nlohmann::json& sync = timing["synchronized"];
    const nlohmann::json& pipe = timing["pipelined"];
    EXPECT_EQ(sync["steps"], 2);  // steps 2 and 4
    EXPECT_EQ(pipe["steps"], 2);  // steps 3 and 5
    const auto sorted = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v;
    };
    const std::vector<double> syncCalls = sorted(callsPerStep["synchronized"]);
    EXPECT_EQ(sync["submissions"]["min"], syncCalls.front());
    EXPECT_EQ(sync["submissions"]["max"], syncCalls.back());
    EXPECT_EQ(sync["submissions"]["median"], (syncCalls[0] + syncCalls[1]) / 2);
    EXPECT_EQ(sync["host_waits"]["max"], syncCalls.back());
    for (const char* count : {"submissions", "host_waits", "batches"})
        EXPECT_EQ(pipe[count], (nlohmann::json{{"median", 1.0}, {"min", 1.0}, {"max", 1.0}})) << count;
    EXPECT_EQ(sync["batches"]["max"], 0.0);
    // Pipelined: the region's device times are its calls' costs; its call time is "host", not "wall".
    EXPECT_EQ(pipe["stages"]["region"]["device"]["samples_ms"].get<std::vector<double>>(), regionDevicePipelined);
    EXPECT_EQ(pipe["stages"]["region"]["host"]["count"], 2);
    EXPECT_FALSE(pipe["stages"]["region"].contains("wall"));
    EXPECT_EQ(pipe["frames"]["render_splat a"]["device"]["count"].get<int>() +
                  pipe["frames"]["render_splat b"]["device"]["count"].get<int>(),
              int(frameDevicePipelined.size()));
    EXPECT_EQ(sync["stages"]["region"]["wall"]["samples_ms"].get<std::vector<double>>(), regionSync);
    // The thesis's fields keep the synchronized measurements alone.
    EXPECT_EQ(b["stages"]["region"]["samples_ms"].get<std::vector<double>>(), regionSync);
    EXPECT_EQ(b["stages"]["region"]["device"]["count"], 2);
    EXPECT_EQ(b["frames"]["a"]["samples_ms"].size(), 4u);  // 2 synchronized steps x 2 frames
    EXPECT_EQ(b["frames"]["a"]["steps"].size(), 8u);       // every frame, either mode (steps 2..5 render)
    EXPECT_EQ(b["stage_runs"]["region"]["ran"], 6);        // either mode counts as a run
    // The report's line per backend.
    const std::string text = report::RenderText(TimingSection(scene, run));
    EXPECT_NE(text.find("pipelined: step "), std::string::npos) << text;
    EXPECT_NE(text.find("(1 submission, 1 wait); synchronized: step "), std::string::npos) << text;
    EXPECT_NE(text.find("pipelined per stage, median device ms (host recording ms): region "), std::string::npos)
        << text;
}

// The harness's pipelined path changes when work is done, never what it computes: every image and resource the
// observer sees is the same, bit for bit, on the CPU (time-sliced too).
TEST(PipelinedTiming, OutputsIdenticalBetweenModes) {
    for (const char* slices : {"0", "3"}) {
        const Scene scene = BatchScene({{"render.slices_per_frame", slices}});
        std::vector<std::vector<std::vector<std::byte>>> seen[2];
        for (int mode = 0; mode < 2; ++mode) {
            BatchLoggingCpu backend;  // logs, and forwards to the CPU
            auto sim = Simulation::Create(scene, backend, /*everyStepOutputs=*/true);
            ASSERT_TRUE(sim.has_value()) << sim.error().message;
            (*sim)->SetTiming(mode ? TimingMode::Pipelined : TimingMode::Synchronized);
            for (uint32_t t = 0; t < scene.steps; ++t) {
                StepRecord r;
                const Status status = (*sim)->Step(r, [&](const Simulation& s) -> Status {
                    std::vector<std::vector<std::byte>> step;
                    for (Resource res : kAllResources)
                        for (size_t n = 0; n < (IsPerCamera(res) ? scene.render.cameras.size() : 1); ++n)
                            if (const Buffer* buffer = s.Get(res, n)) {
                                step.emplace_back(buffer->CanonicalBytes());
                                CB_TRY(backend.Download(*buffer, step.back()));
                            }
                    seen[mode].push_back(std::move(step));
                    return {};
                });
                ASSERT_TRUE(status.has_value()) << status.error().message;
            }
        }
        ASSERT_EQ(seen[0].size(), seen[1].size());
        for (size_t t = 0; t < seen[0].size(); ++t) EXPECT_TRUE(seen[0][t] == seen[1][t]) << "step " << t;
    }
}

}  // namespace
}  // namespace cb
