// What an isolated backend's child sends back to its parent (harness/Isolation.h):
// JSON round trips of the records the commands merge. FromJson(ToJson(x)) == x
// for every field the commands read; doubles keep their exact value.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "harness/Conform.h"
#include "harness/Measurement.h"
#include "harness/Provenance.h"
#include "harness/Report.h"
#include "harness/ReportModel.h"
#include "harness/Simulation.h"

namespace cb::transfer {

nlohmann::json ToJson(const StepRecord& record);
StepRecord StepFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const BackendProvenance& record);
BackendProvenance ProvenanceFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const ConformRow& row);
ConformRow ConformRowFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const Row& row);
Row RowFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const ReferenceRecord& record);
ReferenceRecord ReferenceRecordFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const std::vector<report::Cell>& cells);
std::vector<report::Cell> CellsFromJson(const nlohmann::json& j);

}  // namespace cb::transfer
