// `run`'s report section of one backend (TimingSection, harness/report/Report.h): the
// per-stage timing table with each camera's frames, the loop, each timing
// mode's step, the stage runs and the cloud cover.
#include <cstdio>

#include "harness/report/Report.h"

namespace cb {
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
    // No sample (a stage that ran only in warm-up, or pipelined): "-", never a time of 0.
    std::vector<report::Cell> row = {name};
    for (double value : {s.median, s.q1, s.q3, s.min, s.max})
        row.push_back(s.count == 0 ? report::Cell("-") : report::Cell(value));
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
    // The stages in the order a step runs them.
    const std::vector<Stage> schedule = ScheduleStages(scene.stages);
    for (Stage stage : schedule) {
        table.rows.push_back(TimingRow(std::string(StageName(stage)), StageSamples(scene, run, stage),
                                       StageSamples(scene, run, stage, StageClock::Device)));
    }
    // One row per camera for each renderer the scene runs: its frames' ms, and the last frame's reported counter.
    for (Stage renderer : RendererStages()) {
        const RendererDescriptor* d = Describe(renderer).renderer;
        if (!scene.stages.Has(renderer)) continue;
        const size_t reported = ReportedCounterIndex(d->counters);
        const std::string_view what = reported < d->counters.size() ? d->counters[reported].name : "";
        for (const CameraSettings& camera : scene.render.cameras) {
            std::vector<double> ms;
            uint64_t last = 0;
            ForEachFrame(run, renderer, camera.name, [&](const StepRecord&, const FrameRecord& f) {
                ms.push_back(f.ms);
                last = reported < f.counters.size() ? f.counters[reported] : 0;
            });
            const Summary s = Summarize(ms);
            std::snprintf(line, sizeof line, "%zu frames, %.1f fps, %llu %.*s", s.count,
                          s.median > 0 ? 1000.0 / s.median : 0.0, static_cast<unsigned long long>(last),
                          int(what.size()), what.data());
            table.rows.push_back(
                TimingRow(("  " + std::string(d->rowLabel) + " " + camera.name).substr(0, 18), ms, {}, line));
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
            anyDevice |= scene.stages.Has(stage) &&
                         !StageSamples(scene, run, stage, StageClock::Device, TimingMode::Pipelined).empty();
        std::string stages = anyDevice ? "  pipelined per stage, median device ms (host recording ms):"
                                       : "  pipelined per stage, no device clock; median host recording ms:";
        const char* sep = " ";
        for (Stage stage : schedule) {
            const std::vector<double> host = StageSamples(scene, run, stage, StageClock::Wall, TimingMode::Pipelined);
            if (host.empty()) continue;
            const std::vector<double> device =
                StageSamples(scene, run, stage, StageClock::Device, TimingMode::Pipelined);
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
        for (Stage stage : schedule) {
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

}  // namespace cb
