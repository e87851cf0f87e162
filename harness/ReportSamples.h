// The post-warm-up samples of a BackendRun that results.json
// (harness/ResultsJson.cpp) and `run`'s timing section
// (harness/TimingSection.cpp) both read; defined in harness/Report.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "harness/Report.h"

namespace cb {

// Post-warm-up samples of one stage measured in `mode`: synchronized, its wall
// time; pipelined, its host recording time; or (device) its device time, where
// the backend measured it, from the steps that measured the stage in `mode`.
std::vector<double> StageSamples(const Scene& scene, const BackendRun& run, Stage stage, bool device = false,
                                 TimingMode mode = TimingMode::Synchronized);

// The share of the grid's columns that `columns` covered columns are.
double CoverFraction(const Scene& scene, uint32_t columns);

// The post-warm-up steps timed in `mode`.
std::vector<const StepRecord*> StepsIn(const Scene& scene, const BackendRun& run, TimingMode mode);

// fn(step, frame) for the post-warm-up frames of one renderer and camera, in
// order, whatever mode drew them.
template <typename Fn>
void ForEachFrame(const BackendRun& run, Stage renderer, const std::string& camera, Fn&& fn) {
    for (const StepRecord& r : run.steps)
        for (const FrameRecord& f : r.frames)
            if (f.renderer == renderer && f.camera == camera) fn(r, f);
}

}  // namespace cb
