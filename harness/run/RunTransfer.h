// The JSON round trips of what a run records (harness/platform/TransferJson.h):
// a step of the simulation and a backend's provenance.
#pragma once

#include <nlohmann/json.hpp>

#include "harness/platform/Provenance.h"
#include "harness/run/Simulation.h"

namespace cb::transfer {

nlohmann::json ToJson(const StepRecord& record);
StepRecord StepFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const BackendProvenance& record);
BackendProvenance ProvenanceFromJson(const nlohmann::json& j);

}  // namespace cb::transfer
