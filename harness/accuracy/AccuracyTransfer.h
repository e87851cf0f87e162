// The JSON round trips of the accuracy records (harness/platform/TransferJson.h):
// error statistics, a measured row and a reference's build record.
#pragma once

#include <nlohmann/json.hpp>

#include "harness/accuracy/Accuracy.h"
#include "harness/accuracy/Measurement.h"

namespace cb::transfer {

nlohmann::json ToJson(const ErrorStats& stats);
ErrorStats ErrorStatsFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const Row& row);
Row RowFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const ReferenceRecord& record);
ReferenceRecord ReferenceRecordFromJson(const nlohmann::json& j);

}  // namespace cb::transfer
