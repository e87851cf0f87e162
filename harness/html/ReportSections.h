// The parts of `cloudbench report`'s page that BuildReport (HtmlReport.cpp)
// assembles, one file each (internal to harness/html): timing tables, the
// source documents' figures and timing distributions (HtmlTiming.cpp), history plots
// (HtmlHistory.cpp) and the accuracy Pareto plots (HtmlPareto.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/ReportModel.h"
#include "harness/html/HtmlReport.h"

namespace cb::html {

// A results.json's stage times per backend (median, q1-q3) beside the source documents' figures for each stage.
report::Table TimingTable(const nlohmann::json& doc);
// Every figure of docs/seed-timings.json, and the document and setup of each seed.
report::Table SeedTable();
report::KeyValues SeedSources();
// Box plots of a results.json's per-step stage times.
report::Figure TimingBoxes(const ReportInput& input);

// A paragraph, then one plot per scene and stage of the records' medians and
// one per scene of the CPU's instruction counts, change points marked.
std::vector<report::Block> HistoryBlocks(const std::vector<nlohmann::json>& history, const std::string& path);

// Per stage of an accuracy.json or sweep.json: error against time, with the Pareto front.
std::vector<report::Block> ParetoBlocks(const ReportInput& input);

}  // namespace cb::html
