// The post-warm-up samples of a BackendRun that results.json
// (harness/ResultsJson.cpp) and `run`'s timing section
// (harness/TimingSection.cpp) both read; defined in harness/Report.cpp.
#pragma once

#include <cstdint>
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

}  // namespace cb
