#include "harness/Report.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/March.h"
#include "harness/Session.h"

namespace cb {
namespace {

double Quantile(const std::vector<double>& sorted, double p) {
    double pos = p * double(sorted.size() - 1);
    size_t lo = size_t(std::floor(pos));
    size_t hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - double(lo));
}

// Post-warm-up samples of one stage measured in `mode`: synchronized, its wall
// time; pipelined, its host recording time; or (device) its device time, where
// the backend measured it, from the steps that measured the stage in `mode`.
std::vector<double> StageSamples(const Scene& scene, const BackendRun& run, Stage stage, bool device = false,
                                 TimingMode mode = TimingMode::Synchronized) {
    std::vector<double> out;
    for (const StepRecord& r : run.steps) {
        const std::optional<double>& wall =
            mode == TimingMode::Pipelined ? r.hostMs[size_t(stage)] : r.stageMs[size_t(stage)];
        const std::optional<double>& sample = device ? r.deviceMs[size_t(stage)] : wall;
        if (r.step >= scene.warmupSteps && wall && sample) out.push_back(*sample);
    }
    return out;
}

// Post-warm-up frames of one renderer and camera, with their step, whatever mode drew them.
template <typename Fn>
void ForEachFrame(const BackendRun& run, Stage renderer, const std::string& camera, Fn&& fn) {
    for (const StepRecord& r : run.steps)
        for (const FrameRecord& f : r.frames)
            if (f.renderer == renderer && f.camera == camera) fn(r, f);
}

double CoverFraction(const Scene& scene, uint32_t columns) {
    return double(columns) / (double(scene.grid.size.nx) * scene.grid.size.ny);
}

nlohmann::json SummaryJson(const std::vector<double>& samples) {
    Summary s = Summarize(samples);
    return {{"samples_ms", samples}, {"median_ms", s.median}, {"q1_ms", s.q1},   {"q3_ms", s.q3},
            {"min_ms", s.min},       {"max_ms", s.max},       {"count", s.count}};
}

// The post-warm-up steps timed in `mode`.
std::vector<const StepRecord*> StepsIn(const Scene& scene, const BackendRun& run, TimingMode mode) {
    std::vector<const StepRecord*> out;
    for (const StepRecord& r : run.steps)
        if (r.step >= scene.warmupSteps && r.timing == mode) out.push_back(&r);
    return out;
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
                {pipelined ? "host" : "wall", SummaryJson(StageSamples(scene, run, stage, false, mode))}};
            const std::vector<double> device = StageSamples(scene, run, stage, true, mode);
            if (!device.empty()) entry["device"] = SummaryJson(device);
            stages[std::string(StageName(stage))] = entry;
        }
        nlohmann::json frames = nlohmann::json::object();
        for (Stage renderer : {Stage::RenderSplat, Stage::RenderMarch}) {
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

Summary Summarize(std::vector<double> samples) {
    Summary s;
    s.count = samples.size();
    if (samples.empty()) return s;
    std::sort(samples.begin(), samples.end());
    s.min = samples.front();
    s.max = samples.back();
    s.median = Quantile(samples, 0.5);
    s.q1 = Quantile(samples, 0.25);
    s.q3 = Quantile(samples, 0.75);
    return s;
}

LoopFigures MeasureLoop(const Scene& scene, const BackendRun& run) {
    LoopFigures loop;
    double slowest = 0;
    for (const StepRecord& r : run.steps) {
        if (r.step < scene.warmupSteps) continue;
        ++loop.steps;
        loop.frames += r.framesRendered;
        loop.renderSteps += r.framesRendered > 0 ? 1 : 0;
        loop.wallMs += r.stepMs;
        loop.stepMs.push_back(r.stepMs);
        for (size_t f = 0; f < r.frameMs.size(); ++f) {
            if (loop.frameMs.empty() || r.frameMs[f] > slowest) {
                slowest = r.frameMs[f];
                loop.slowestStep = r.step;
                loop.slowestFrame = uint32_t(f);
                loop.slowestWork = f < r.frameWork.size() ? r.frameWork[f] : (f == 0 ? "the step's work" : "");
            }
            loop.frameMs.push_back(r.frameMs[f]);
        }
    }
    return loop;
}

StageRunCount CountStageRuns(const BackendRun& run, Stage stage) {
    StageRunCount count;
    for (const StepRecord& r : run.steps) {
        if (r.Ran(stage)) {
            ++count.ran;
            if (Describe(stage).renderer) count.frames += r.framesRendered;
        } else if (r.skippedUnchanged[size_t(stage)]) {
            ++count.skippedUnchanged;
        } else {
            ++count.notOutputStep;
        }
    }
    return count;
}

nlohmann::json ResultsJson(const Scene& scene, const std::vector<BackendRun>& runs) {
    nlohmann::json stages = nlohmann::json::array();
    for (Stage stage : kAllStages)
        if (scene.stages.Has(stage)) stages.push_back(StageName(stage));
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
            const std::vector<double> device = StageSamples(scene, run, stage, /*device=*/true);
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
        if (scene.stages.Has(Stage::RenderSplat)) {
            // Per camera: every frame's time and splat count, and their summary.
            nlohmann::json cameras = nlohmann::json::object();
            for (const CameraSettings& camera : scene.render.cameras) {
                std::vector<double> ms;
                nlohmann::json steps = nlohmann::json::array(), splats = nlohmann::json::array(),
                               alphas = nlohmann::json::array(), visited = nlohmann::json::array();
                for (const StepRecord& r : run.steps)
                    for (const FrameRecord& f : r.frames)
                        if (f.renderer == Stage::RenderSplat && f.camera == camera.name) {
                            if (!f.pipelined) ms.push_back(f.ms);  // a pipelined frame's call time is host time
                            steps.push_back(r.step);
                            splats.push_back(f.stats.splats);
                            visited.push_back(f.stats.voxelsVisited);
                            alphas.push_back(f.alpha);
                        }
                nlohmann::json c = SummaryJson(ms);
                c["steps"] = steps;
                c["alphas"] = alphas;
                c["splats"] = splats;
                c["voxels_visited"] = visited;
                c["fps_median"] = ms.empty() ? 0.0 : 1000.0 / Summarize(ms).median;
                cameras[camera.name] = c;
            }
            b["frames"] = cameras;
        }
        if (scene.stages.Has(Stage::RenderMarch)) {
            // Per camera: every march frame's time and counters (MarchStats), and their summary.
            nlohmann::json cameras = nlohmann::json::object();
            for (const CameraSettings& camera : scene.render.cameras) {
                std::vector<double> ms;
                nlohmann::json steps = nlohmann::json::array(), samples = nlohmann::json::array(),
                               lightSamples = nlohmann::json::array(), skipped = nlohmann::json::array(),
                               alphas = nlohmann::json::array();
                for (const StepRecord& r : run.steps)
                    for (const FrameRecord& f : r.frames)
                        if (f.renderer == Stage::RenderMarch && f.camera == camera.name) {
                            if (!f.pipelined) ms.push_back(f.ms);  // a pipelined frame's call time is host time
                            steps.push_back(r.step);
                            alphas.push_back(f.alpha);
                            samples.push_back(f.march.samples);
                            lightSamples.push_back(f.march.lightSamples);
                            skipped.push_back(f.march.bricksSkipped);
                        }
                nlohmann::json c = SummaryJson(ms);
                c["steps"] = steps;
                c["alphas"] = alphas;
                c["samples"] = samples;
                c["light_samples"] = lightSamples;
                c["bricks_skipped"] = skipped;
                c["fps_median"] = ms.empty() ? 0.0 : 1000.0 / Summarize(ms).median;
                cameras[camera.name] = c;
            }
            b["march_frames"] = cameras;
        }
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

namespace {

// The timing table's columns: stage, median, q1, q3, min, max (ms), then two
// notes without a title: the device median and a camera's frame summary.
std::vector<report::Column> TimingColumns() {
    using report::Column;
    std::vector<Column> columns = {Column("stage").Width(18).Separator("  ")};
    for (const char* title : {"median ms", "q1", "q3", "min", "max"})
        columns.push_back(Column(title).Real("%.3f").Unit("ms").Width(10).AlignRight());
    columns.push_back(Column("device median").Real("%.3f").Unit("ms").Separator("   ").Prefix("device ").NoTextTitle());
    columns.push_back(Column("frames").Separator("  ").NoTextTitle());
    return columns;
}

std::vector<report::Cell> TimingRow(const std::string& name, const std::vector<double>& samples,
                                    const std::vector<double>& device, std::string note = "") {
    const Summary s = Summarize(samples);
    std::vector<report::Cell> row = {name, s.median, s.q1, s.q3, s.min, s.max};
    row.push_back(device.empty() ? report::Cell() : report::Cell(Summarize(device).median));
    row.push_back(note.empty() ? report::Cell() : report::Cell(std::move(note)));
    return row;
}

}  // namespace

report::Section TimingSection(const Scene& scene, const BackendRun& run) {
    report::Section section;
    char line[256];
    if (run.steps.size() > scene.warmupSteps)
        std::snprintf(line, sizeof line, "backend %s (%s): %zu steps, statistics over steps %u..%zu", run.name.c_str(),
                      run.device.c_str(), run.steps.size(), scene.warmupSteps, run.steps.size() - 1);
    else
        std::snprintf(line, sizeof line, "backend %s (%s): %zu steps, none after the %u warm-up steps",
                      run.name.c_str(), run.device.c_str(), run.steps.size(), scene.warmupSteps);
    section.title = line;
    // Wall time; "device" follows where the backend measures GPU time.
    report::Table table(TimingColumns(), report::TextLayout::Columns);
    for (Stage stage : kAllStages) {
        if (!scene.stages.Has(stage)) continue;
        table.rows.push_back(TimingRow(std::string(StageName(stage)), StageSamples(scene, run, stage),
                                       StageSamples(scene, run, stage, true)));
    }
    if (scene.stages.Has(Stage::RenderSplat)) {
        for (const CameraSettings& camera : scene.render.cameras) {
            std::vector<double> ms;
            uint64_t lastSplats = 0;
            for (const StepRecord& r : run.steps)
                for (const FrameRecord& f : r.frames)
                    if (f.renderer == Stage::RenderSplat && f.camera == camera.name) {
                        ms.push_back(f.ms);
                        lastSplats = f.stats.splats;
                    }
            const Summary s = Summarize(ms);
            std::snprintf(line, sizeof line, "%zu frames, %.1f fps, %llu splats", s.count,
                          s.median > 0 ? 1000.0 / s.median : 0.0, static_cast<unsigned long long>(lastSplats));
            table.rows.push_back(TimingRow(("  frame " + camera.name).substr(0, 18), ms, {}, line));
        }
    }
    if (scene.stages.Has(Stage::RenderMarch)) {
        for (const CameraSettings& camera : scene.render.cameras) {
            std::vector<double> ms;
            uint64_t lastSamples = 0;
            for (const StepRecord& r : run.steps)
                for (const FrameRecord& f : r.frames)
                    if (f.renderer == Stage::RenderMarch && f.camera == camera.name) {
                        ms.push_back(f.ms);
                        lastSamples = f.march.samples;
                    }
            const Summary s = Summarize(ms);
            std::snprintf(line, sizeof line, "%zu frames, %.1f fps, %llu samples", s.count,
                          s.median > 0 ? 1000.0 / s.median : 0.0, static_cast<unsigned long long>(lastSamples));
            table.rows.push_back(TimingRow(("  march " + camera.name).substr(0, 18), ms, {}, line));
        }
    }
    if (scene.stages.Has(Stage::Region)) {
        std::vector<double> host;
        for (const StepRecord& r : run.steps)
            if (r.step >= scene.warmupSteps) host.push_back(r.ellipsoidUpdateMs);
        table.rows.push_back(TimingRow("(host) ellipsoids", host, {}));
    }
    if (!run.downloadMs.empty()) table.rows.push_back(TimingRow("(transfer) download", run.downloadMs, {}));
    section.blocks.push_back(std::move(table));
    // The whole loop (simulation + frames) and how often each stage ran.
    const LoopFigures loop = MeasureLoop(scene, run);
    if (loop.steps > 0) {
        const Summary st = Summarize(loop.stepMs);
        if (const auto fps = loop.Fps())
            std::snprintf(
                line, sizeof line,
                "  loop: %llu frames (%.4g per render step) in %u steps, %.1f ms: %.1f fps; step median %.3f ms, "
                "max %.3f ms",
                static_cast<unsigned long long>(loop.frames), double(loop.frames) / loop.renderSteps, loop.steps,
                loop.wallMs, *fps, st.median, st.max);
        else
            std::snprintf(line, sizeof line,
                          "  loop: no frames in %u steps, %.1f ms: %.1f steps/s; step median %.3f ms", loop.steps,
                          loop.wallMs, loop.wallMs > 0 ? loop.steps * 1000.0 / loop.wallMs : 0.0, st.median);
        section.blocks.push_back(report::Paragraph{line});
        if (!loop.frameMs.empty()) {
            // The thesis's figure of a loop: the frame the viewer waits longest for, beside the typical one.
            const Summary fr = Summarize(loop.frameMs);
            std::snprintf(
                line, sizeof line,
                "  frames: median %.3f ms [q1 %.3f, q3 %.3f], slowest %.3f ms (step %u frame %u%s%s)%s", fr.median,
                fr.q1, fr.q3, fr.max, loop.slowestStep, loop.slowestFrame, loop.slowestWork.empty() ? "" : ": ",
                loop.slowestWork.c_str(),
                scene.render.slicesPerFrame > 0
                    ? (", time-sliced at " + std::to_string(scene.render.slicesPerFrame) + " slices per frame").c_str()
                    : "");
            section.blocks.push_back(report::Paragraph{line});
        }
    }
    // Each timing mode's step (median [q1, q3]) and what it asked of the device (medians over its steps).
    std::string modes;
    for (TimingMode mode : {TimingMode::Pipelined, TimingMode::Synchronized}) {
        const std::vector<const StepRecord*> steps = StepsIn(scene, run, mode);
        if (steps.empty()) continue;
        std::vector<double> ms, submissions, waits;
        for (const StepRecord* r : steps) {
            ms.push_back(r->stepMs);
            submissions.push_back(double(r->submissions));
            waits.push_back(double(r->hostWaits));
        }
        const Summary st = Summarize(ms);
        const double sub = Summarize(submissions).median, wait = Summarize(waits).median;
        std::snprintf(line, sizeof line, "%s: step %.3f ms [%.3f, %.3f] (%.4g submission%s, %.4g wait%s)",
                      std::string(TimingModeName(mode)).c_str(), st.median, st.q1, st.q3, sub, sub == 1 ? "" : "s",
                      wait, wait == 1 ? "" : "s");
        modes += (modes.empty() ? "  " : "; ") + std::string(line);
    }
    if (!modes.empty()) section.blocks.push_back(report::Paragraph{modes});
    if (!StepsIn(scene, run, TimingMode::Pipelined).empty()) {
        // Pipelined, a stage's call time is the host's recording; its time is the device's.
        bool anyDevice = false;
        for (Stage stage : kAllStages)
            anyDevice |=
                scene.stages.Has(stage) && !StageSamples(scene, run, stage, true, TimingMode::Pipelined).empty();
        std::string stages = anyDevice ? "  pipelined per stage, median device ms (host recording ms):"
                                       : "  pipelined per stage, no device clock; median host recording ms:";
        const char* sep = " ";
        for (Stage stage : kAllStages) {
            if (!scene.stages.Has(stage)) continue;
            const std::vector<double> host = StageSamples(scene, run, stage, false, TimingMode::Pipelined);
            if (host.empty()) continue;
            const std::vector<double> device = StageSamples(scene, run, stage, true, TimingMode::Pipelined);
            const std::string name(StageName(stage));
            if (!anyDevice)
                std::snprintf(line, sizeof line, "%s %.3f", name.c_str(), Summarize(host).median);
            else if (device.empty())
                std::snprintf(line, sizeof line, "%s - (%.3f)", name.c_str(), Summarize(host).median);
            else
                std::snprintf(line, sizeof line, "%s %.3f (%.3f)", name.c_str(), Summarize(device).median,
                              Summarize(host).median);
            stages += sep + std::string(line);
            sep = ", ";
        }
        section.blocks.push_back(report::Paragraph{stages});
    }
    if (!run.steps.empty()) {
        std::string runs = "  stage runs (" + std::to_string(run.steps.size()) + " steps):";
        const char* sep = " ";
        for (Stage stage : kAllStages) {
            if (!scene.stages.Has(stage)) continue;
            const StageRunCount c = CountStageRuns(run, stage);
            runs += sep + std::string(StageName(stage)) + " " + std::to_string(c.ran);
            if (c.skippedUnchanged) runs += " (" + std::to_string(c.skippedUnchanged) + " skipped, unchanged)";
            if (Describe(stage).renderer) runs += " (" + std::to_string(c.frames) + " frames)";
            sep = ", ";
        }
        section.blocks.push_back(report::Paragraph{runs});
    }
    if (scene.stages.Has(Stage::Density) && !run.steps.empty()) {
        std::vector<double> after;
        for (const StepRecord& r : run.steps)
            if (r.step >= scene.warmupSteps && r.coveredColumns)
                after.push_back(CoverFraction(scene, *r.coveredColumns));
        const Summary s = Summarize(after);
        const StepRecord& last = run.steps.back();
        std::snprintf(line, sizeof line, "  cloud cover: last step %.1f %%, median %.1f %% (min %.1f, max %.1f)",
                      last.coveredColumns ? 100.0 * CoverFraction(scene, *last.coveredColumns) : 0.0, 100 * s.median,
                      100 * s.min, 100 * s.max);
        section.blocks.push_back(report::Paragraph{line});
    }
    return section;
}

std::string_view RendererFileName(Stage renderer) {
    switch (renderer) {
        case Stage::RenderSplat:
            return "splat";
        case Stage::RenderMarch:
            return "march";
        default:
            return StageName(renderer);
    }
}

std::string FrameFileStem(Stage renderer, const std::string& camera, const std::string& backend) {
    return "frame-" + std::string(RendererFileName(renderer)) + "-" + camera + (backend.empty() ? "" : "-" + backend);
}

namespace {

// Writes `image` to `path` atomically. OIIO's PNG writer can report success on
// a full disk, so the temporary file is read back whole before it is renamed.
// Errors read "PATH: cannot write: <reason>"; Session::WriteAtomically adds the errno.
Status WriteImage(const std::string& path, const OIIO::ImageBuf& image) {
    return Session::WriteAtomically(path, [&](const std::string& temp) -> Status {
        if (!image.write(temp)) return MakeError(path + ": cannot write: " + image.geterror());
        // Only a regular file is read back (a device could read forever); WriteAtomically refuses the rest.
        std::error_code ec;
        if (!std::filesystem::is_regular_file(temp, ec)) return {};
        // ImageInput, not ImageBuf: the shared image cache could answer with an earlier file of the same name.
        auto in = OIIO::ImageInput::open(temp);
        const OIIO::ImageSpec& want = image.spec();
        std::vector<float> pixels(size_t(want.width) * size_t(want.height) * size_t(want.nchannels));
        const bool whole = in && in->spec().width == want.width && in->spec().height == want.height &&
                           in->spec().nchannels == want.nchannels &&
                           in->read_image(0, 0, 0, want.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
        const std::string why = in ? in->geterror() : OIIO::geterror();
        if (!whole) return MakeError(path + ": cannot write: it does not read back whole (" + why + ")");
        return {};
    });
}

}  // namespace

Status WriteTopView(const std::string& path, const std::vector<float>& columnSum, uint32_t nx, uint32_t ny,
                    uint32_t nz) {
    OIIO::ImageSpec spec(int(nx), int(ny), 1, OIIO::TypeDesc::UINT8);
    OIIO::ImageBuf image(spec);
    // Optical-depth look: brightness 1 - exp(-D / 4); a column of 4 full voxels is ~63 % white.
    (void)nz;
    for (uint32_t y = 0; y < ny; ++y) {
        const uint32_t j = ny - 1 - y;  // top row first, y up
        for (uint32_t i = 0; i < nx; ++i) {
            float v = 1.0f - std::exp(-columnSum[size_t(i) + size_t(nx) * j] / 4.0f);
            image.setpixel(int(i), int(y), &v, 1);
        }
    }
    return WriteImage(path, image);
}

ImageComparison CompareImages(const std::vector<float>& reference, const std::vector<float>& candidate, uint32_t width,
                              uint32_t height, const CompareRule& rule) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf a(spec, const_cast<float*>(reference.data())), b(spec, const_cast<float*>(candidate.data()));
    // failthresh: the limit; warnthresh: the tolerance. A pixel counts once, as a failure or a warning.
    const float limit = std::isinf(rule.limit) ? std::numeric_limits<float>::max() : float(rule.limit);
    const auto result = OIIO::ImageBufAlgo::compare(a, b, limit, float(rule.tolerance));
    ImageComparison c;
    c.rule = rule;
    c.maxError = result.maxerror;
    c.meanError = result.meanerror;
    c.psnr = result.PSNR;
    c.pixelsOverTolerance = size_t(result.nfail + result.nwarn);
    c.pixels = size_t(width) * height;
    c.worstX = result.maxx;
    c.worstY = result.maxy;
    return c;
}

Status WriteDifferenceImage(const std::string& path, const std::vector<float>& reference,
                            const std::vector<float>& candidate, uint32_t width, uint32_t height) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf a(spec, const_cast<float*>(reference.data())), b(spec, const_cast<float*>(candidate.data()));
    OIIO::ImageBuf diff = OIIO::ImageBufAlgo::absdiff(a, b);
    return WriteImage(path, diff);
}

Result<std::vector<std::string>> WriteFrame(const std::string& stem, const std::vector<float>& rgb, uint32_t width,
                                            uint32_t height, bool png, const std::optional<FrameToneMap>& toneMap) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf linear(spec, const_cast<float*>(rgb.data()));  // wraps, does not copy
    std::vector<std::string> written;
    const std::string exr = stem + ".exr";
    CB_TRY(WriteImage(exr, linear));
    written.push_back(exr);
    if (png) {
        std::vector<float> mapped;
        OIIO::ImageBuf display;
        if (toneMap) {
            mapped.resize(rgb.size());
            for (size_t i = 0; i < rgb.size(); ++i)
                mapped[i] = toneMap->reinhard ? ReinhardToneMap(rgb[i], toneMap->exposure)
                                              : std::clamp(rgb[i] * toneMap->exposure, 0.0f, 1.0f);
            display = OIIO::ImageBuf(spec, mapped.data());
        }
        OIIO::ImageBuf srgb;
        if (!OIIO::ImageBufAlgo::colorconvert(srgb, toneMap ? display : linear, "linear", "sRGB"))
            return MakeError(stem + ".png: colour conversion failed: " + srgb.geterror());
        const std::string path = stem + ".png";
        srgb.set_write_format(OIIO::TypeDesc::UINT8);
        CB_TRY(WriteImage(path, srgb));
        written.push_back(path);
    }
    return written;
}

}  // namespace cb
