// The output half of `cloudbench sweep`, shared with `cloudbench merge` (which
// combines the files of `sweep --shard I/N`): the Pareto front and the
// sweep.json, sweep.md and sweep.png writer.
#pragma once

#include <expected>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "harness/accuracy/Measurement.h"
#include "harness/accuracy/SweepFields.h"
#include "harness/accuracy/SweepPareto.h"
#include "harness/run/VaryAxes.h"

namespace cb {

// The --vary PATH=V1,V2,... arguments as axes (values split at commas outside
// brackets, braces and quotes); a usage message when one is malformed. Used by
// sweep and conform.
std::expected<std::vector<SweepAxis>, std::string> ParseVaryAxes(const std::vector<std::string>& vary);

// Writes `path` with `doc` (and whatever provenance the writer adds).
using SweepJsonWriter = std::function<Status(const std::string& path, nlohmann::json doc)>;

// Writes OUTDIR/sweep.json (through `writeJson`), sweep.md and sweep.png, and
// prints the tables. `doc` holds the header fields (format, scene, grid,
// step, metric, repeats, reference_start, references, and shard when there
// is one); "vary", "rows" and "report" are added here. `rows` (their Pareto
// marks already set) go out stage by stage, in their order within a stage,
// each with the settings its stage reads (SettingsRead; "any" in the table's
// other axis columns).
// Returns kExitOk, or kExitFailed after the message when a file cannot be written.
int WriteSweepOutputs(nlohmann::json doc, const std::string& sceneName, const std::string& metric,
                      const std::vector<SweepAxis>& axes, const std::vector<Stage>& stages,
                      const std::vector<Row>& rows, const std::string& outDir, const SweepJsonWriter& writeJson);

}  // namespace cb
