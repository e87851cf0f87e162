// The parts of `cloudbench report`'s page that BuildReport (HtmlReport.cpp)
// assembles, one file each (internal to harness/report/html): timing tables, the
// source documents' figures and timing distributions (HtmlTiming.cpp), history plots
// (HtmlHistory.cpp), the frames (HtmlFrames.cpp) and the accuracy Pareto plots
// (HtmlPareto.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/report/ReportModel.h"
#include "harness/report/html/ReportInput.h"

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

// The source documents' figures compiled in from docs/seed-timings.json.
const nlohmann::json& SeedTimings();

// The frames of a results.json (the PNGs its "files" list, beside it) and,
// per camera, each backend's difference from the first backend in
// results.json's order that has the frame (the CPU's, when it ran): |a - b|
// of the linear EXR frames, scaled so that SPEC 8's limit (8/255) is white,
// computed by the image module and embedded as PNG. A frame that cannot be read
// is named in a paragraph instead.
std::vector<report::Block> FrameBlocks(const ReportInput& results);

// Per stage of an accuracy.json or sweep.json: error against time, with the Pareto front.
std::vector<report::Block> ParetoBlocks(const ReportInput& input);

}  // namespace cb::html
