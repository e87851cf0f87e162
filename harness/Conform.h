// `cloudbench conform`: stage-isolated conformance on a scene. The CPU runs the
// scene; at every step each other backend's stages are fed the CPU's inputs of
// that step and their outputs are compared by SPEC's rule for the stage.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Backend.h"
#include "core/Scene.h"

namespace cb {

struct ConformRow {
    std::string stage, backend;
    std::string status = "pass";  // "pass", "fail", "skipped"
    std::string rule;             // the comparison, e.g. "bit-exact" or "|dT| <= 1e-05"
    double worst = 0;             // largest error seen (absolute; voxels differing for exact stages)
    double tolerance = 0;
    std::string detail;           // worst place and both values, or why it was skipped
};

// Compares every backend in `backends` (other than cpu) against the CPU over the scene's steps.
Result<std::vector<ConformRow>> RunConformance(const Scene& scene, const std::vector<std::string>& backends,
                                               const BackendOptions& options);

std::string ConformTable(const std::vector<ConformRow>& rows);
nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows);

}  // namespace cb
