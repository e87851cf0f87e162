// The parts of `cloudbench report`'s page that BuildReport (HtmlReport.cpp)
// assembles, one file each (internal to harness/report/html): timing tables, the
// source documents' figures and timing distributions (HtmlTiming.cpp), history plots
// (HtmlHistory.cpp), the frames (HtmlFrames.cpp), the accuracy Pareto plots
// (HtmlPareto.cpp) and the regression gate's verdict (HtmlCompare.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/report/ReportModel.h"
#include "harness/report/html/ReportInput.h"

namespace cb::html {

// A results.json's stage times per backend (median, q1-q3) beside the source documents' figures for each stage;
// under a renderer's row (its time per step, every camera), its time per camera frame beside the documents'
// figures for a frame.
report::Table TimingTable(const nlohmann::json& doc);
// The frames of one camera that a step of renderer `stage` draws on `backend` in a results.json: its cameras (its
// frames block) times the frames of a rendering step (stage_runs' frames over runs, else the scene's
// frames_per_step). nullopt for a stage that is not a renderer or a backend without frames.
std::optional<double> FramesPerStep(const nlohmann::json& doc, const std::string& backend, const std::string& stage);
// `run`'s lines under a backend's timing table, one per renderer: its time per camera frame (the step's median
// over FramesPerStep) and the source documents' figures for a frame of the scene.
std::vector<std::string> FrameFigureLines(const nlohmann::json& doc, const std::string& backend);
// `run`'s lines for the other stages: each stage's figures in the source documents (docs/seed-timings.json),
// with the settings a figure was measured at, by document and table.
std::vector<std::string> StageFigureLines(const nlohmann::json& doc, const std::string& backend);
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

// A `perf compare --json` file (a kept interleave's compare.json): the verdict and its exit code, the gate's
// settings, every comparison with its mark, ratio, interval and Holm-adjusted p-values, the rows not judged (?),
// the failed runs and whether the interleave was cut short (HtmlCompare.cpp).
std::vector<report::Block> CompareBlocks(const ReportInput& input);

// Per stage of an accuracy.json or sweep.json: error against time, with the Pareto front.
std::vector<report::Block> ParetoBlocks(const ReportInput& input);

}  // namespace cb::html
