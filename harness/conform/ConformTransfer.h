// The JSON round trip of a conformance row (harness/platform/TransferJson.h).
#pragma once

#include <nlohmann/json.hpp>

#include "harness/conform/Conform.h"

namespace cb::transfer {

nlohmann::json ToJson(const ConformRow& row);
ConformRow ConformRowFromJson(const nlohmann::json& j);

}  // namespace cb::transfer
