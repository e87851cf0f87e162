// The inputs of `cloudbench report`: each a JSON file cloudbench wrote (or a
// folder of them), read and checked, and the verdict each records.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"

namespace cb::html {

enum class InputKind { Results, Conform, Accuracy, Sweep, Compare };
std::string_view InputKindName(InputKind kind);  // "results", "conform", "accuracy", "sweep", "perf compare"

struct ReportInput {
    std::string path;
    InputKind kind = InputKind::Results;
    nlohmann::json doc;
};

// Reads one input: a JSON file recognised by its "format"
// (cloudbench-results/1, cloudbench-conform/1, cloudbench-accuracy/1,
// cloudbench-sweep/1, cloudbench-perf-compare/1) and checked against its schema
// (harness/report/InputFormats.h), or a folder, which stands for the known file
// names in it (results.json, conform.json, accuracy.json, sweep.json,
// compare.json; one at least). A kept interleave (a folder with interleave.json)
// stands for its compare.json, the live command's verdict; one without it (cut
// short before the verdict) is refused, naming the file. Errors name the file
// and the field.
Result<std::vector<ReportInput>> ReadReportInput(const std::string& path);

// The verdict one input records, as the exit code its command gave (docs/cli.md):
// results: 1 when a backend did not finish ("failed", "crashed", ...) or the run is
// incomplete, 4 when no backend was available, else 0; conform: 1 for a backend
// that failed or crashed, 5 for a failed check, 4 when nothing was compared;
// accuracy and sweep: 1 for a row that failed or crashed, 4 when no row was measured; perf compare: the
// exit code it recorded (6 for a regression).
struct Verdict {
    int exitCode = 0;
    std::string reason;  // "" when 0
};
Verdict VerdictOf(const ReportInput& input);
// Of several: 0 when every one is 0, else the first non-zero code in the order 1, 5, 6, 4.
int CombinedExitCode(const std::vector<Verdict>& verdicts);

}  // namespace cb::html
