// A run's statistics (harness/report/Report.h): order
// statistics of a sample, the post-warm-up samples of a stage, the whole
// loop's figures and how often each stage ran. results.json is written in
// ResultsJson.cpp, `run`'s timing section in TimingSection.cpp, images in
// ReportImages.cpp.
#include "harness/report/Report.h"

#include <algorithm>
#include <cmath>

namespace cb {
namespace {

double Quantile(const std::vector<double>& sorted, double p) {
    double pos = p * double(sorted.size() - 1);
    size_t lo = size_t(std::floor(pos));
    size_t hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - double(lo));
}

}  // namespace

std::vector<double> StageSamples(const Scene& scene, const BackendRun& run, Stage stage, StageClock clock,
                                 TimingMode mode) {
    std::vector<double> out;
    for (const StepRecord& r : run.steps) {
        const std::optional<double>& wall =
            mode == TimingMode::Pipelined ? r.hostMs[size_t(stage)] : r.stageMs[size_t(stage)];
        const std::optional<double>& sample = clock == StageClock::Device ? r.deviceMs[size_t(stage)]
                                              : clock == StageClock::Cpu  ? r.cpuMs[size_t(stage)]
                                                                          : wall;
        if (r.step >= scene.warmupSteps && wall && sample) out.push_back(*sample);
    }
    return out;
}

double CoverFraction(const Scene& scene, uint32_t columns) {
    return double(columns) / (double(scene.grid.size.nx) * scene.grid.size.ny);
}

std::vector<const StepRecord*> StepsIn(const Scene& scene, const BackendRun& run, TimingMode mode) {
    std::vector<const StepRecord*> out;
    for (const StepRecord& r : run.steps)
        if (r.step >= scene.warmupSteps && r.timing == mode) out.push_back(&r);
    return out;
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
}  // namespace cb
