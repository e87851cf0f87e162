// `cloudbench conform`: stage-isolated conformance on a scene. The CPU runs the
// scene; at every step each other backend's stages are fed the CPU's inputs of
// that step and their outputs are compared by SPEC's rule for the stage.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/report/ReportModel.h"
#include "harness/run/Session.h"

namespace cb {

struct ConformRow {
    std::string stage, backend;
    // "pass", "fail", "skipped"; "failed" (the backend crashed or could not run); after
    // --flake-reruns: "flaky"; after --baseline: "expected-fail", "unexpected-pass".
    std::string status = "pass";
    std::string rule;  // the comparison, e.g. "bit-exact" or "|dT| <= 1e-05"
    double worst = 0;  // largest error seen (absolute; voxels differing for exact stages)
    double tolerance = 0;
    std::string detail;           // worst place and both values, or why it was skipped
    std::string differenceImage;  // renderers: |cpu - backend| of the worst frame (EXR), when written
    // conform --matrix / --vary: the case (harness/conform/ConformMatrix.h) the row was compared in; "" without.
    std::string caseName;
};

// Called after each step's comparisons with the rows so far (each row's worst over steps 0..step).
using ConformProgress = std::function<void(uint32_t step, const std::vector<ConformRow>& rows)>;

// Compares every available backend in `others` against `cpu` over the scene's
// steps; one that did not open is a row "(all)" skipped with the reason.
// With `differenceDir`, each renderer row's worst frame is written there as
// diff-<stage>-<backend>.exr, |cpu - backend| per channel (linear float).
// `attempt` (0 first, 1.. for --flake-reruns) and `caseName` (--matrix) only feed
// the test-only switch CLOUDBENCH_TEST_CONFORM_MISMATCH=<backend>:<row stage>[:<attempts>][@<case>],
// which perturbs that backend's output of that row (its first element: a float by 1, down from 0.5 up, so that a code
// stored clamped to [0, 1] changes too; a byte by flipping its top bit; the cover by 1) before it is compared, on
// attempts below <attempts> (default: every attempt), in the case named after '@' (default: every case). With
// CLOUDBENCH_TEST_CONFORM_MISMATCH_EVERY=1 a byte row has every element one code off instead; with
// CLOUDBENCH_TEST_CONFORM_MISMATCH_VALUE=nan, inf or -inf a float row's first element is set to that value.
// A NaN or Inf in a float output, the backend's or the CPU's, fails its row whatever the rule: worst = inf and
// the detail names the step, the voxel (or camera, pixel and channel) and both values.
Result<std::vector<ConformRow>> RunConformance(const Scene& scene, Backend& cpu, std::span<const OpenedBackend> others,
                                               const ConformProgress& afterStep = {},
                                               const std::string& differenceDir = "", uint32_t attempt = 0,
                                               const std::string& caseName = "");

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

// --baseline FILE: known failures, one "stage,backend,status" a line, or, after a
// header line "case,stage,backend,status" (a --matrix conform.csv's), one
// "case,stage,backend,status" a line (docs/cli.md). Fields may be quoted as in
// conform.csv. An entry matches the rows of its case only ("" = no --matrix).
struct ConformBaseline {
    struct Entry {
        std::string caseName, stage, backend;
        bool operator==(const Entry&) const = default;
    };
    std::vector<Entry> knownFailures;
    bool Lists(const std::string& stage, const std::string& backend) const { return Lists("", stage, backend); }
    bool Lists(const std::string& caseName, const std::string& stage, const std::string& backend) const;
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
// The last line conform prints, so that a failed run ends with its verdict too:
// "16 rows: 14 pass, 1 fail, 1 skipped; exit 5, a row does not conform" (the
// statuses in the order they first occur).
std::string ConformSummary(const std::vector<ConformRow>& rows);

// conform.csv: a header and one row per (stage, backend):
// stage,backend,status,rule,worst,tolerance,detail (RFC 4180 quoting); when a
// row has a case (--matrix), every row starts with its case: case,stage,...
std::string ConformCsv(const std::vector<ConformRow>& rows);

// conform --junit: JUnit XML for CI systems, one testsuite `suite` ("conform SCENE") and one testcase per row,
// named by its stage, classname "SCENE.BACKEND" (with the case: "SCENE.CASE.BACKEND"). fail and
// unexpected-pass are <failure> (the message names the worst difference, the tolerance and the rule; the text
// holds the detail), failed (the backend broke or crashed) is <error>, skipped and expected-fail are
// <skipped> with the reason, pass and flaky pass (flaky with a <system-out> that says which attempt passed).
std::string ConformJUnit(const std::vector<ConformRow>& rows, const std::string& scene);

// stage x backend: result, rule, worst error and where, as `conform` prints it
// (a first column "case" when a row has one).
report::Table ConformTable(const std::vector<ConformRow>& rows);
// conform.json: the rows (each with "case" when it has one), and "coverage" (ConformCoverage).
nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows);
// Which options each stage was compared under: {stage: {"options": {...},
// "compared_on": [backends]}} for every row stage some backend compared (a
// row neither skipped nor a crash), with the scene's settings that change what
// the stage computes (docs/results.md lists them).
nlohmann::json ConformCoverage(const Scene& scene, const std::vector<ConformRow>& rows);

// The scene settings of one stage that conform's coverage lists, e.g. for
// shade {"attenuation": "beer", "filter": ..., "phase": ...}; {} for a stage with none.
nlohmann::json ConformStageOptions(const Scene& scene, const std::string& stage);

// The coverage of a run over several cases (--matrix, --vary): for each row stage
// some backend compared, {"options": {option: {value: [backends]}}, "compared_on":
// [backends], "cases": [case names]}: every value each option was compared under,
// and on which backends. `caseScenes` holds each case's name and scene; a
// case's gl automaton layout, when set, is the option "gl_ca_layout" of "ca" on gl,
// and shade also lists "principal_axis" ("x", "y" or "z": the sun's at step 0).
struct ConformCaseScene {
    std::string name;
    const Scene* scene = nullptr;
    std::string glCaLayout;  // the gl automaton layout's name
};
nlohmann::json ConformMatrixCoverage(const std::vector<ConformCaseScene>& caseScenes,
                                     const std::vector<ConformRow>& rows);

}  // namespace cb
