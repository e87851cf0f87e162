// `cloudbench conform`: stage-isolated conformance on a scene. The CPU runs the
// scene; at every step each other backend's stages are fed the CPU's inputs of
// that step and their outputs are compared by SPEC's rule for the stage.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/Backend.h"
#include "core/Scene.h"
#include "harness/ReportModel.h"
#include "harness/Session.h"

namespace cb {

struct ConformRow {
    std::string stage, backend;
    std::string status = "pass";  // "pass", "fail", "skipped"
    std::string rule;             // the comparison, e.g. "bit-exact" or "|dT| <= 1e-05"
    double worst = 0;             // largest error seen (absolute; voxels differing for exact stages)
    double tolerance = 0;
    std::string detail;           // worst place and both values, or why it was skipped
    std::string differenceImage;  // renderers: |cpu - backend| of the worst frame (EXR), when written
};

// Called after each step's comparisons with the rows so far (each row's worst over steps 0..step).
using ConformProgress = std::function<void(uint32_t step, const std::vector<ConformRow>& rows)>;

// Compares every available backend in `others` against `cpu` over the scene's
// steps; one that did not open is a row "(all)" skipped with the reason.
// With `differenceDir`, each renderer row's worst frame is written there as
// diff-<stage>-<backend>.exr, |cpu - backend| per channel (linear float).
Result<std::vector<ConformRow>> RunConformance(const Scene& scene, Backend& cpu, std::span<const OpenedBackend> others,
                                               const ConformProgress& afterStep = {},
                                               const std::string& differenceDir = "");

// stage x backend: result, rule, worst error and where, as `conform` prints it.
report::Table ConformTable(const std::vector<ConformRow>& rows);
nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows);

}  // namespace cb
