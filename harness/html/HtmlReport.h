// What `cloudbench report` shows, built as a report model (harness/ReportModel.h)
// from the JSON outputs of run, conform, accuracy and sweep (docs/results.md),
// a perf history (JSON Lines of cloudbench-perf/1 records) and the source documents'
// timing figures (docs/seed-timings.json), then rendered by
// harness/html/HtmlRender.h. docs/cli.md describes the page.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Error.h"
#include "harness/ReportModel.h"

namespace cb::html {

enum class InputKind { Results, Conform, Accuracy, Sweep };
std::string_view InputKindName(InputKind kind);  // "results", "conform", "accuracy", "sweep"

struct ReportInput {
    std::string path;
    InputKind kind = InputKind::Results;
    nlohmann::json doc;
};

// Reads one input: a JSON file recognised by its "format"
// (cloudbench-results/1, cloudbench-conform/1, cloudbench-accuracy/1,
// cloudbench-sweep/1) and checked against its schema (harness/InputFormats.h),
// or a folder, which stands for the known file names in it (results.json,
// conform.json, accuracy.json, sweep.json; one at least). Errors name the file
// and the field.
Result<std::vector<ReportInput>> ReadReportInput(const std::string& path);

// The verdict one input records, as the exit code its command gave (docs/cli.md):
// results: 1 when a backend did not finish ("failed", "crashed", ...) or the run is
// incomplete, 4 when no backend was available, else 0; conform: 1 for a backend
// that failed or crashed, 5 for a failed check, 4 when nothing was compared;
// accuracy and sweep: 1 for a row that failed or crashed, 4 when no row was measured.
struct Verdict {
    int exitCode = 0;
    std::string reason;  // "" when 0
};
Verdict VerdictOf(const ReportInput& input);
// Of several: 0 when every one is 0, else the first non-zero code in the order 1, 5, 4.
int CombinedExitCode(const std::vector<Verdict>& verdicts);

// The source documents' figures compiled in from docs/seed-timings.json.
const nlohmann::json& SeedTimings();

// The frames of a results.json (the PNGs its "files" list, beside it) and,
// per camera, each backend's difference from the first backend in
// results.json's order that has the frame (the CPU's, when it ran): |a - b|
// of the linear EXR frames, scaled so that SPEC 8's limit (8/255) is white,
// computed with OpenImageIO and embedded as PNG. A frame that cannot be read
// is named in a paragraph instead.
std::vector<report::Block> FrameBlocks(const ReportInput& results);

// The whole page's model: provenance and verdict, the conformance matrix,
// timing tables with the source documents' figures, timing distributions, history plots
// (change points marked where a record lists them in "change_points"), the
// accuracy Pareto plots, the frames, then each input's own report block.
report::Report BuildReport(const std::vector<ReportInput>& inputs, const std::vector<nlohmann::json>& history,
                           const std::string& historyPath);

}  // namespace cb::html
