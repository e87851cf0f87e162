// results.json (harness/report/Report.h ResultsJson and TimingJson; the format is in
// docs/results.md): per backend, each stage's timing summary and how often it
// ran, the loop, the frames, the cover, and the timing of each mode.
#include <string>
#include <utility>
#include <vector>

#include "harness/report/Report.h"

namespace cb {
namespace {

// The counters of a renderer that results.json shows: each one's name and its index in FrameRecord::counters.
std::vector<std::pair<std::string, size_t>> ResultsCounters(const RendererDescriptor& renderer) {
    std::vector<std::pair<std::string, size_t>> out;
    for (size_t i = 0; i < renderer.counters.size(); ++i)
        if (renderer.counters[i].shown != CounterShown::ReadBack) out.push_back({std::string(renderer.counters[i].name), i});
    return out;
}

nlohmann::json SummaryJson(const std::vector<double>& samples) {
    Summary s = Summarize(samples);
    return {{"samples_ms", samples}, {"median_ms", s.median}, {"q1_ms", s.q1},   {"q3_ms", s.q3},
            {"min_ms", s.min},       {"max_ms", s.max},       {"count", s.count}};
}

nlohmann::json CountJson(const std::vector<double>& counts) {
    const Summary s = Summarize(counts);
    return {{"median", s.median}, {"min", s.min}, {"max", s.max}};
}

}  // namespace

nlohmann::json TimingJson(const Scene& scene, const BackendRun& run) {
    bool modes[2] = {false, false};
    for (const StepRecord& r : run.steps) modes[size_t(r.timing)] = true;
    nlohmann::json timing = {{"mode", modes[0] && modes[1] ? "both" : modes[1] ? "pipelined" : "synchronized"}};
    for (TimingMode mode : {TimingMode::Synchronized, TimingMode::Pipelined}) {
        if (!modes[size_t(mode)]) continue;
        const std::vector<const StepRecord*> steps = StepsIn(scene, run, mode);
        std::vector<double> stepMs, submissions, waits, batches;
        for (const StepRecord* r : steps) {
            stepMs.push_back(r->stepMs);
            submissions.push_back(double(r->submissions));
            waits.push_back(double(r->hostWaits));
            batches.push_back(double(r->batches));
        }
        const bool pipelined = mode == TimingMode::Pipelined;
        nlohmann::json stages = nlohmann::json::object();
        for (Stage stage : kAllStages) {
            if (!scene.stages.Has(stage)) continue;
            nlohmann::json entry = {
                {pipelined ? "host" : "wall", SummaryJson(StageSamples(scene, run, stage, StageClock::Wall, mode))}};
            const std::vector<double> cpu = StageSamples(scene, run, stage, StageClock::Cpu, mode);
            if (!cpu.empty()) entry["cpu"] = SummaryJson(cpu);
            const std::vector<double> device = StageSamples(scene, run, stage, StageClock::Device, mode);
            if (!device.empty()) entry["device"] = SummaryJson(device);
            stages[std::string(StageName(stage))] = entry;
        }
        nlohmann::json frames = nlohmann::json::object();
        for (Stage renderer : RendererStages()) {
            if (!scene.stages.Has(renderer)) continue;
            for (const CameraSettings& camera : scene.render.cameras) {
                std::vector<double> wall, device;
                ForEachFrame(run, renderer, camera.name, [&](const StepRecord& r, const FrameRecord& f) {
                    if (r.step < scene.warmupSteps || f.pipelined != pipelined) return;
                    wall.push_back(f.ms);
                    if (f.deviceMs) device.push_back(*f.deviceMs);
                });
                nlohmann::json entry = {{pipelined ? "host" : "wall", SummaryJson(wall)}};
                if (!device.empty()) entry["device"] = SummaryJson(device);
                frames[std::string(StageName(renderer)) + " " + camera.name] = entry;
            }
        }
        nlohmann::json m = {
            {"steps", steps.size()},          {"step_ms", SummaryJson(stepMs)}, {"submissions", CountJson(submissions)},
            {"host_waits", CountJson(waits)}, {"batches", CountJson(batches)},  {"stages", stages}};
        if (!frames.empty()) m["frames"] = frames;
        timing[std::string(TimingModeName(mode))] = m;
    }
    return timing;
}

nlohmann::json ResultsJson(const Scene& scene, const std::vector<BackendRun>& runs) {
    nlohmann::json stages = nlohmann::json::array();  // in the order a step runs them, as the reports list them
    for (Stage stage : ScheduleStages(scene.stages)) stages.push_back(StageName(stage));
    nlohmann::json doc = {
        {"format", "cloudbench-results/1"},
        {"scene",
         {{"name", scene.name},
          {"path", scene.path},
          {"grid", {scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz}},
          {"steps", scene.steps},
          {"warmup_steps", scene.warmupSteps},
          {"frames_per_step", scene.render.framesPerStep},
          {"sun_moves", scene.sun.Moves()},
          {"stages", stages}}},
        {"backends", nlohmann::json::object()},
    };
    for (const BackendRun& run : runs) {
        nlohmann::json b = {{"status", run.status}, {"device", run.device}, {"steps_completed", run.steps.size()}};
        if (!run.error.empty()) b["error"] = run.error;
        if (run.plannedBytes) b["planned_bytes"] = *run.plannedBytes;
        nlohmann::json timing = nlohmann::json::object();
        for (Stage stage : kAllStages) {
            if (!scene.stages.Has(stage)) continue;
            nlohmann::json entry = SummaryJson(StageSamples(scene, run, stage));
            const std::vector<double> cpu = StageSamples(scene, run, stage, StageClock::Cpu);
            if (!cpu.empty()) entry["cpu"] = SummaryJson(cpu);  // the process's CPU time over the stage's calls
            const std::vector<double> device = StageSamples(scene, run, stage, StageClock::Device);
            if (!device.empty()) entry["device"] = SummaryJson(device);  // GPU timestamps, without submission
            timing[std::string(StageName(stage))] = entry;
        }
        b["stages"] = timing;
        nlohmann::json runsJson = nlohmann::json::object();
        for (Stage stage : kAllStages) {
            if (!scene.stages.Has(stage)) continue;
            const StageRunCount c = CountStageRuns(run, stage);
            nlohmann::json entry = {
                {"ran", c.ran}, {"skipped_unchanged", c.skippedUnchanged}, {"not_output_step", c.notOutputStep}};
            if (Describe(stage).renderer) entry["frames"] = c.frames;
            runsJson[std::string(StageName(stage))] = entry;
        }
        b["stage_runs"] = runsJson;
        const LoopFigures loop = MeasureLoop(scene, run);
        nlohmann::json loopJson = SummaryJson(loop.stepMs);
        loopJson.erase("samples_ms");
        b["loop"] = {{"steps", loop.steps},
                     {"frames", loop.frames},
                     {"wall_ms", loop.wallMs},
                     {"fps", loop.Fps() ? nlohmann::json(*loop.Fps()) : nlohmann::json(nullptr)},
                     {"steps_per_second",
                      loop.wallMs > 0 ? nlohmann::json(loop.steps * 1000.0 / loop.wallMs) : nlohmann::json(nullptr)},
                     {"step_ms", SummaryJson(loop.stepMs)},
                     {"slices_per_frame", scene.render.slicesPerFrame}};
        if (!loop.frameMs.empty()) {
            nlohmann::json frameJson = SummaryJson(loop.frameMs);
            frameJson["slowest"] = {
                {"step", loop.slowestStep}, {"frame", loop.slowestFrame}, {"work", loop.slowestWork}};
            b["loop"]["frame_ms"] = frameJson;
        }
        std::vector<double> hostSamples;
        for (const StepRecord& r : run.steps)
            if (r.step >= scene.warmupSteps && scene.stages.Has(Stage::Region))
                hostSamples.push_back(r.ellipsoidUpdateMs);
        b["host"] = {{"ellipsoid_update", SummaryJson(hostSamples)}};
        b["transfers"] = {{"download", SummaryJson(run.downloadMs)}};
        // Per camera of a renderer: every frame's time (not a pipelined frame's: its call
        // time is host time), step and alpha, the renderer's counters shown in results.json
        // (`counters`: a field name and a value of a frame each), and their summary.
        auto framesJson = [&](Stage renderer, const std::vector<std::pair<std::string, size_t>>& counters) {
            nlohmann::json cameras = nlohmann::json::object();
            for (const CameraSettings& camera : scene.render.cameras) {
                std::vector<double> ms;
                nlohmann::json c = nlohmann::json::object(), steps = nlohmann::json::array(),
                               alphas = nlohmann::json::array();
                for (const auto& counter : counters) c[counter.first] = nlohmann::json::array();
                ForEachFrame(run, renderer, camera.name, [&](const StepRecord& r, const FrameRecord& f) {
                    if (!f.pipelined) ms.push_back(f.ms);
                    steps.push_back(r.step);
                    alphas.push_back(f.alpha);
                    for (const auto& counter : counters) c[counter.first].push_back(f.counters[counter.second]);
                });
                c.update(SummaryJson(ms));
                c["steps"] = steps;
                c["alphas"] = alphas;
                c["fps_median"] = ms.empty() ? 0.0 : 1000.0 / Summarize(ms).median;
                cameras[camera.name] = c;
            }
            return cameras;
        };
        for (Stage stage : kAllStages)
            if (const RendererDescriptor* renderer = Describe(stage).renderer; renderer && scene.stages.Has(stage))
                b[std::string(renderer->resultsKey)] = framesJson(stage, ResultsCounters(*renderer));
        if (scene.stages.Has(Stage::Density)) {
            nlohmann::json cover = nlohmann::json::array();
            std::vector<double> after;
            for (const StepRecord& r : run.steps) {
                double c = r.coveredColumns ? CoverFraction(scene, *r.coveredColumns) : 0.0;
                cover.push_back(c);
                if (r.step >= scene.warmupSteps) after.push_back(c);
            }
            b["cover"] = cover;
            Summary s = Summarize(after);
            double mean = 0;
            for (double c : after) mean += c;
            b["cover_summary"] = {{"mean", after.empty() ? 0.0 : mean / double(after.size())},
                                  {"median", s.median},
                                  {"min", s.min},
                                  {"max", s.max}};
        }
        b["timing"] = TimingJson(scene, run);
        doc["backends"][run.name] = b;
    }
    return doc;
}

}  // namespace cb
