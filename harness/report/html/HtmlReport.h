// What `cloudbench report` shows, built as a report model (harness/report/ReportModel.h)
// from the JSON outputs of run, conform, accuracy and sweep (docs/results.md),
// a perf history (JSON Lines of cloudbench-perf/1 records) and the source documents'
// timing figures (docs/seed-timings.json), then rendered by
// harness/report/html/HtmlRender.h. docs/cli.md describes the page.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "harness/report/ReportModel.h"
#include "harness/report/html/ReportInput.h"

namespace cb::html {

// The whole page's model: provenance and verdict, the conformance matrix,
// timing tables with the source documents' figures, timing distributions, history plots
// (change points marked where a record lists them in "change_points"), the
// accuracy Pareto plots, the frames, then each input's own report block.
report::Report BuildReport(const std::vector<ReportInput>& inputs, const std::vector<nlohmann::json>& history,
                           const std::string& historyPath);

}  // namespace cb::html
