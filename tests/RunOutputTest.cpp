// What `run` prints beside its results (docs/cli.md, "run"): the progress lines and their estimate of the time
// left (an injected clock, no real timing), the timing table's order and its "-" for a stage with no sample, and a
// renderer's time per camera frame beside the source documents' figures in `run` and `report`. Expected values are
// worked by hand from the inputs below.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/plan/SceneLoad.h"
#include "harness/report/Report.h"
#include "harness/report/html/ReportSections.h"
#include "harness/run/Progress.h"

namespace cb {
namespace {

// A progress whose clock is `now` and whose lines go to `lines`.
struct RunOutputFake {
    double now = 0;
    std::vector<std::string> lines;
    Progress Make(uint32_t total, bool quiet, bool terminal) {
        return Progress(
            "vk", total, quiet, terminal, [this] { return now; },
            [this](std::string_view text) { lines.emplace_back(text); });
    }
};

// Test the log's lines: the first step takes 4 s and every other 0.25 s, so step k ends at 4 + 0.25 (k - 1) s; a
// line at most every 10 s (at 10, 20, 30, 40, 50 s: steps 25, 65, 105, 145, 185), the rate from the steps after the
// first (0.25 s), and the end line at 53.75 s.
TEST(RunOutputProgress, LogLinesEveryTenSecondsWithTheTimeLeft) {
    RunOutputFake p;
    {
        Progress progress = p.Make(200, false, false);
        for (uint32_t k = 1; k <= 200; ++k) {
            p.now = 4 + 0.25 * (k - 1);
            progress.Update(k);
        }
        progress.Finish();
        progress.Finish();  // once
    }
    ASSERT_EQ(p.lines.size(), 6u);
    EXPECT_EQ(p.lines[0], "vk: step 25 of 200, about 44 s left\n");  // 175 steps x 0.25 s = 43.75 s
    EXPECT_EQ(p.lines[1], "vk: step 65 of 200, about 34 s left\n");  // 135 x 0.25 = 33.75
    EXPECT_EQ(p.lines[4], "vk: step 185 of 200, about 4 s left\n");  // 15 x 0.25 = 3.75
    EXPECT_EQ(p.lines[5], "vk: 200 steps in 54 s\n");
}

// Test the interval's boundary: a line 9.75 s after the start is too soon, one at 10 s is not.
TEST(RunOutputProgress, NoLineBeforeTheInterval) {
    RunOutputFake p;
    Progress progress = p.Make(101, false, false);
    p.now = 9.75;
    progress.Update(1);
    EXPECT_TRUE(p.lines.empty());
    p.now = 10;
    progress.Update(2);
    ASSERT_EQ(p.lines.size(), 1u);
    // The rate since step 1: 0.25 s a step, 99 steps to go: 24.75 s.
    EXPECT_EQ(p.lines[0], "vk: step 2 of 101, about 25 s left\n");
}

// Test a terminal: one line rewritten at most every second; with one step done its own time is the rate (4 s a
// step, 199 to go: 796 s); the end line covers the longer line before it and ends it.
TEST(RunOutputProgress, TerminalRewritesOneLine) {
    RunOutputFake p;
    Progress progress = p.Make(200, false, true);
    p.now = 4;
    progress.Update(1);
    p.now = 4.5;
    progress.Update(2);  // 0.5 s after the last line: none
    p.now = 5.5;
    progress.Finish();
    ASSERT_EQ(p.lines.size(), 2u);
    EXPECT_EQ(p.lines[0], "\rvk: step 1 of 200, about 13 min 16 s left");
    const std::string end = "vk: stopped after 2 of 200 steps, 5.5 s";
    EXPECT_EQ(p.lines[1], "\r" + end + std::string(p.lines[0].size() - 1 - end.size(), ' ') + "\n");
}

// Test --quiet: nothing, not even the end line (which the destructor would print).
TEST(RunOutputProgress, QuietPrintsNothing) {
    RunOutputFake p;
    {
        Progress progress = p.Make(50, true, false);
        for (uint32_t k = 1; k <= 50; ++k) {
            p.now = 30.0 * k;
            progress.Update(k);
        }
    }
    EXPECT_TRUE(p.lines.empty());
}

// Test a resumed run (its first step is 51) and a run that stops: each end line says which steps it covered.
TEST(RunOutputProgress, ResumedAndStoppedRunsEndLines) {
    RunOutputFake p;
    {
        Progress progress = p.Make(60, false, false);
        for (uint32_t k = 51; k <= 60; ++k) {
            p.now = 0.5 * (k - 50);
            progress.Update(k);
        }
    }  // the destructor ends it
    p.now = 0;
    {
        Progress progress = p.Make(60, false, false);
        p.now = 8;
        progress.Update(1);
        p.now = 72;
        progress.Finish();
    }
    ASSERT_EQ(p.lines.size(), 2u);
    EXPECT_EQ(p.lines[0], "vk: steps 51 to 60 in 5.0 s\n");
    EXPECT_EQ(p.lines[1], "vk: stopped after 1 of 60 steps, 1 min 12 s\n");
}

// Test the estimate at its edges: nothing done, the first step only, the last step.
TEST(RunOutputProgress, EstimateEdges) {
    ProgressEstimate e;
    e.startS = 10;
    EXPECT_FALSE(e.SecondsLeft(0, 100, 11).has_value());
    e.firstDone = 1;
    e.firstDoneS = 13;                                    // the first step took 3 s
    EXPECT_DOUBLE_EQ(*e.SecondsLeft(1, 100, 13), 297.0);  // 99 x 3
    EXPECT_DOUBLE_EQ(*e.SecondsLeft(5, 100, 15), 47.5);   // (15 - 13) / 4 = 0.5 s a step, 95 to go
    EXPECT_DOUBLE_EQ(*e.SecondsLeft(100, 100, 40), 0.0);
    EXPECT_EQ(ProgressDuration(59.4), "59 s");
    EXPECT_EQ(ProgressDuration(59.6), "1 min 00 s");
    EXPECT_EQ(ProgressDuration(3725), "1 h 02 min");
}

// layers-small (noise, shade, render_layers; 3 cameras) with one warm-up step: noise and shade run at step 0 only.
Scene RunOutputScene() {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/layers-small.json",
                           {{"steps", "4"}, {"warmup_steps", "1"}, {"render.every_steps", "1"}});
    EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
    return scene ? *scene : Scene{};
}

BackendRun RunOutputRun(const Scene& scene) {
    BackendRun run;
    run.name = "cpu";
    run.device = "test";
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord r;
        r.step = t;
        if (t == 0) {
            r.stageMs[size_t(Stage::Noise)] = 50;
            r.stageMs[size_t(Stage::Shade)] = 20;
        }
        r.stageMs[size_t(Stage::RenderLayers)] = 30.0 + 3 * t;  // 33, 36, 39 ms after warm-up
        r.framesRendered = 1;
        run.steps.push_back(r);
    }
    return run;
}

// Test the table: stages in the order a step runs them (noise writes the q that shade reads, though CB_STAGES
// lists shade first), and "-" for noise and shade, which have no sample after warm-up.
TEST(RunOutputTable, RunOrderAndDashForNoSample) {
    const Scene scene = RunOutputScene();
    const std::string text = report::RenderText(TimingSection(scene, RunOutputRun(scene)));
    const size_t noise = text.find("\n  noise "), shade = text.find("\n  shade "),
                 layers = text.find("\n  render_layers ");
    ASSERT_NE(noise, std::string::npos) << text;
    ASSERT_NE(shade, std::string::npos) << text;
    ASSERT_NE(layers, std::string::npos) << text;
    EXPECT_LT(noise, shade);
    EXPECT_LT(shade, layers);
    const std::string noiseRow = text.substr(noise + 1, text.find('\n', noise + 1) - noise - 1);
    EXPECT_EQ(noiseRow.find("0.000"), std::string::npos) << noiseRow;
    size_t dashes = 0;
    for (size_t at = noiseRow.find(" -"); at != std::string::npos; at = noiseRow.find(" -", at + 1)) ++dashes;
    EXPECT_EQ(dashes, 5u) << noiseRow;  // median, q1, q3, min, max
    // render_layers: the median of 33, 36, 39.
    EXPECT_NE(text.find("render_layers          36.000"), std::string::npos) << text;
}

// Test the time per camera frame in results.json's terms: the step's median (36 ms) over 3 cameras x 1 frame is
// 12 ms, quartiles 34.5 and 37.5 over 3; with 2 frames a step (stage_runs: 6 frames in 3 runs), 6 ms.
TEST(RunOutputTable, PerCameraFrameBesideTheDocuments) {
    Scene scene = RunOutputScene();
    scene.name = "wang-20km";  // the figures of Wang, Ji and Zhang apply to this scene
    nlohmann::json doc = ResultsJson(scene, {RunOutputRun(scene)});
    ASSERT_EQ(doc["backends"]["cpu"]["layers_frames"].size(), 3u);
    const auto frames = html::FramesPerStep(doc, "cpu", "render_layers");
    ASSERT_TRUE(frames.has_value());
    EXPECT_DOUBLE_EQ(*frames, 3.0);
    EXPECT_FALSE(html::FramesPerStep(doc, "cpu", "shade").has_value());

    const std::vector<std::string> lines = html::FrameFigureLines(doc, "cpu");
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_NE(lines[0].find("render_layers per camera frame: 12.000 ms"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("2.564 ms (seed 002, NVIDIA GTX 260+)"), std::string::npos) << lines[0];

    const report::Table table = html::TimingTable(doc);
    // noise has no sample after warm-up: "-" in its median and quartiles, not 0.
    const auto noise = std::ranges::find_if(table.rows, [](const auto& r) { return r[0].text == "noise"; });
    ASSERT_NE(noise, table.rows.end());
    EXPECT_EQ((*noise)[1].text, "-");
    EXPECT_EQ((*noise)[2].text, "-");
    const auto row = std::ranges::find_if(table.rows, [](const auto& r) { return r[0].text == "render_layers"; });
    ASSERT_NE(row, table.rows.end());
    EXPECT_DOUBLE_EQ((*row)[1].real, 36.0);
    EXPECT_EQ(row->back().kind, report::Cell::Kind::Empty);  // the documents' frame figures are not per step
    const auto& perFrame = *(row + 1);
    EXPECT_EQ(perFrame[0].text, "render_layers per camera frame");
    EXPECT_DOUBLE_EQ(perFrame[1].real, 12.0);
    EXPECT_EQ(perFrame[2].text, "11.500 - 12.500");
    EXPECT_NE(perFrame.back().text.find("2.564 ms"), std::string::npos);

    doc["backends"]["cpu"]["stage_runs"]["render_layers"]["frames"] = 6;
    doc["backends"]["cpu"]["stage_runs"]["render_layers"]["ran"] = 3;
    EXPECT_DOUBLE_EQ(*html::FramesPerStep(doc, "cpu", "render_layers"), 6.0);
    EXPECT_NE(html::FrameFigureLines(doc, "cpu")[0].find("frame: 6.000 ms"), std::string::npos);
}

// Test the other stages' lines: shade's two figures in the thesis's section 8.2 (8.696 ms at full resolution,
// 2.174 ms at half), each with its setting, in one line; none for noise, which no document times; none for the
// renderer, whose figure is FrameFigureLines's.
TEST(RunOutputTable, StageFiguresBesideTheDocuments) {
    Scene scene = RunOutputScene();
    scene.name = "wang-20km";
    const nlohmann::json doc = ResultsJson(scene, {RunOutputRun(scene)});
    const std::vector<std::string> lines = html::StageFigureLines(doc, "cpu");
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_EQ(lines[0],
              "  shade in the source documents: 8.696 ms at shade.resolution 1, 2.174 ms at shade.resolution 2 "
              "(seed 000, section 8.2, NVIDIA GeForce 8700M GT)");
}

// Test that the shipped wang scenes measure warm steps: a warm-up step (noise and shade, once), then at least 5
// steps that each render every camera, so that the quartiles are not one cold sample.
TEST(RunOutputScenes, WangScenesHaveWarmRenderedSteps) {
    for (const char* name : {"wang-20km", "wang-90km"}) {
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json");
        ASSERT_TRUE(scene.has_value()) << name << ": " << scene.error().message;
        EXPECT_GE(scene->warmupSteps, 1u) << name;
        EXPECT_GE(scene->steps, scene->warmupSteps + 5) << name;
        EXPECT_EQ(scene->render.everySteps, 1u) << name;
        EXPECT_EQ(scene->render.cameras.size(), 3u) << name;
    }
}

}  // namespace
}  // namespace cb
