// The JSON round trips of the report's records (harness/platform/TransferJson.h):
// a timing summary and a row of table cells.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "harness/report/Report.h"
#include "harness/report/ReportModel.h"

namespace cb::transfer {

nlohmann::json ToJson(const Summary& summary);
Summary SummaryFromJson(const nlohmann::json& j);

nlohmann::json ToJson(const std::vector<report::Cell>& cells);
std::vector<report::Cell> CellsFromJson(const nlohmann::json& j);

}  // namespace cb::transfer
