// `cloudbench conform`: stage-isolated conformance on a scene. The CPU runs the
// scene; at every step each other backend's stages are fed the CPU's inputs of
// that step and their outputs are compared by SPEC's rule for the stage.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/Backend.h"
#include "core/Scene.h"
#include "harness/ReportModel.h"
#include "harness/Session.h"

namespace cb {

struct ConformRow {
    std::string stage, backend;
    // "pass", "fail", "skipped"; "failed" (the backend crashed or could not run); after
    // --flake-reruns: "flaky"; after --baseline: "expected-fail", "unexpected-pass".
    std::string status = "pass";
    std::string rule;             // the comparison, e.g. "bit-exact" or "|dT| <= 1e-05"
    double worst = 0;             // largest error seen (absolute; voxels differing for exact stages)
    double tolerance = 0;
    std::string detail;           // worst place and both values, or why it was skipped
    std::string differenceImage;  // renderers: |cpu - backend| of the worst frame (EXR), when written
};

// Called after each step's comparisons with the rows so far (each row's worst over steps 0..step).
using ConformProgress = std::function<void(uint32_t step, const std::vector<ConformRow>& rows)>;

// Compares every available backend in `others` against `cpu` over the scene's
// steps; one that did not open is a row "(all)" skipped with the reason.
// With `differenceDir`, each renderer row's worst frame is written there as
// diff-<stage>-<backend>.exr, |cpu - backend| per channel (linear float).
// `attempt` (0 first, 1.. for --flake-reruns) only feeds the test-only switch
// CLOUDBENCH_TEST_CONFORM_MISMATCH=<backend>:<row stage>[:<attempts>], which
// perturbs that backend's output of that row (its first element; the cover by 1)
// before it is compared, on attempts below <attempts> (default: every attempt).
Result<std::vector<ConformRow>> RunConformance(const Scene& scene, Backend& cpu, std::span<const OpenedBackend> others,
                                               const ConformProgress& afterStep = {},
                                               const std::string& differenceDir = "", uint32_t attempt = 0);

// The row of density's cover count (DensityOutputs::coveredColumns), compared
// bit-exactly: its stage name, and one step's comparison folded into `row`
// (worst = the largest |cpu - backend| count over the steps so far; the detail
// names its step and both counts, or the latest step's while all agree).
inline constexpr const char* kCoverRowStage = "density.cover";
void FoldCoverComparison(ConformRow& row, uint32_t step, uint32_t cpuCover, uint32_t backendCover);

// A failing row: "fail" (a check) or "failed" (broken or crashed).
bool IsConformFailure(const ConformRow& row);

// --flake-reruns: `first` are a backend's rows of its first run, `rerun` of a
// later attempt (1-based). A row of `first` that fails and whose row in
// `rerun` passes becomes "flaky", its detail saying which attempt passed and
// why the first failed. Rows that still fail, or that passed, are kept.
void MergeRerun(std::vector<ConformRow>& first, const std::vector<ConformRow>& rerun, uint32_t attempt);

// --baseline FILE: known failures, one "stage,backend,status" a line (docs/cli.md).
struct ConformBaseline {
    std::vector<std::pair<std::string, std::string>> knownFailures;  // (stage, backend)
    bool Lists(const std::string& stage, const std::string& backend) const;
};
// Parses the text of `file`; errors read "file: line N: reason".
Result<ConformBaseline> ParseConformBaseline(const std::string& file, const std::string& text);
Result<ConformBaseline> LoadConformBaseline(const std::string& file);
// A failure the baseline lists becomes "expected-fail"; a listed row that now
// passes becomes "unexpected-pass". Other rows are unchanged.
void ApplyBaseline(std::vector<ConformRow>& rows, const ConformBaseline& baseline);

// The exit code of a finished conform (docs/cli.md): 1 broken or crashed (a row "failed", "crashed", ...),
// then 5 for a failed check or an unexpected pass, 4 when nothing was compared, else 0.
int ConformExitCode(const std::vector<ConformRow>& rows);

// conform.csv: a header and one row per (stage, backend):
// stage,backend,status,rule,worst,tolerance,detail (RFC 4180 quoting).
std::string ConformCsv(const std::vector<ConformRow>& rows);

// stage x backend: result, rule, worst error and where, as `conform` prints it.
report::Table ConformTable(const std::vector<ConformRow>& rows);
// conform.json: the rows, and "coverage" (ConformCoverage).
nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows);
// Which options each stage was compared under: {stage: {"options": {...},
// "compared_on": [backends]}} for every row stage some backend compared (a
// row neither skipped nor a crash), with the scene's settings that change what
// the stage computes (docs/results.md lists them).
nlohmann::json ConformCoverage(const Scene& scene, const std::vector<ConformRow>& rows);

}  // namespace cb
