// `cloudbench perf`: performance tracking (docs/cli.md, "perf"). `record`
// appends one record of a fixed suite to a history, `compare` compares two
// result files, two records or interleaved runs of two binaries with a
// regression verdict, `history` finds step changes over a history, `export`
// writes Google Benchmark's JSON. Every measurement is a `cloudbench run` in a
// child process, so the numbers are those `run` reports.
// The subcommands are one file each (PerfRecord.cpp, PerfCompare.cpp,
// PerfHistory.cpp, PerfExport.cpp); what they share is in PerfCommon.h.
#include <cstdio>

#include "core/base/ShownText.h"
#include "harness/commands/PerfCommon.h"

namespace cb::perf_command {
namespace {

constexpr const char* kHelp = R"(usage: cloudbench perf record [--suite FILE] [--history FILE] [--repeat N]
                              [--backend LIST] [--instructions FILE]
       cloudbench perf compare BASE HEAD [compare options]
       cloudbench perf compare --interleave BASE_BINARY HEAD_BINARY SCENE...
                              [--rounds K] [--keep DIR] [--backend LIST] [--steps N]
                              [--set PATH=VALUE]... [--plant STAGE:FACTOR]
                              [compare options]
       cloudbench perf compare DIR [compare options]
       cloudbench perf history FILE [--metric time|instructions] [--clock wall|cpu]
                              [--alpha A] [--min-change F] [--min-segment N] [--json FILE]
       cloudbench perf export --gbench OUT SOURCE...

record   runs the suite (default: thesis-low, thesis-medium, thesis-high, each as
         `cloudbench run` with its own steps, on every built backend; --suite
         FILE: docs/cli.md) and appends one record to the history (default:
         $CLOUDBENCH_HISTORY, else $XDG_DATA_HOME/cloudbench/history.jsonl, else
         ~/.local/share/cloudbench/history.jsonl). --repeat N runs each scene N
         times and keeps each run's samples, wall and CPU time; for CI, record
         with --repeat 3 and keep at least 8 records on each side of a step
         (docs/cli.md, "perf record"). It also counts each scene's CPU
         instructions (`cloudbench count`) when this build can (no
         -march=native, as by default; valgrind installed), else the
         record's "instructions_not_counted" says why; --instructions FILE
         merges a `cloudbench count` output instead.
compare  compares stage times run by run, each run's median step (a
         ratio with a 95 % bootstrap interval, one-sided permutation tests
         over the runs, Holm's correction) and instruction counts. BASE and
         HEAD: a results.json, a `run --out` folder, a count output, a
         history (its last record), FILE@ID or FILE@-N (N-th record from the
         end), FILE@A:B (records A to B, their runs pooled: FILE@-8:-5).
         --interleave runs BASE_BINARY and HEAD_BINARY in K rounds
         (default: enough for every stage to be judged), one run each in
         an order drawn at random every round, and pairs the runs by
         round; --keep DIR keeps every run, DIR/interleave.json, which
         `perf compare DIR` judges again, and the verdict, DIR/compare.json,
         which `cloudbench report DIR` shows. --plant STAGE:FACTOR plants a
         known slowdown to try the gate: HEAD's STAGE does FACTOR (in
         [1, 1000]) times its work, BASE runs the factor-1 control (the
         test-only CLOUDBENCH_TEST_SLOWDOWN, set in each side's
         environment); interleave.json and the verdict record it. Marks:
         + slower, - faster, ~ not significant or within the threshold,
         ? cannot be judged (too few rounds or samples), x failed or missing
         in HEAD, ! new.
  --threshold [BACKEND=]R  a time regression needs a ratio above R
                  (default 1.1; gl and vk 3, software drivers here)
  --separate-threshold R  used instead when BASE and HEAD were not run
                  interleaved (default 2.0)
  --alpha A       and a Holm-adjusted p below A (default 0.01)
  --run-quantile Q  each run's statistic: this quantile of its steps
                  (default 0.5, the median)
  --clock wall|cpu  the stage time compared: wall (default) or the
                  process's CPU time over the stage's calls, which other
                  jobs on a shared machine do not change (results.json files,
                  run folders, records written with CPU times, interleaved runs)
  --floor MS      one run a side (its steps tested): and the medians to
                  differ by more than MS (default 0.05)
  --instruction-threshold F  an instruction count regresses above 1 + F
                  (default 0.02)
  --json FILE     also write every comparison as JSON
  --junit FILE    also write them as JUnit XML for a CI system: a test case
                  per stage x backend, a regression a failure, a stage that
                  cannot be judged skipped with the reason
history  marks step changes in each stage's time over the records (binary
         segmentation, permutation test at p <= A / series, --alpha A default
         0.01) and what changed in the provenance; --json gives each series'
         verdict and why. --clock: cpu by default where every record holds
         CPU times (a shared runner's other jobs do not move them), else wall.
export   writes the SOURCEs (as for compare, their runs pooled) as Google
         Benchmark JSON for compare.py, a run per repetition.

Exit codes: 0 no regression (an inconclusive result passes, with a warning
naming each stage marked ?), 1 a run failed or an output could not be
written, 2 bad command line, 3 a bad input file, 6 a confirmed regression.
)";

}  // namespace

int Usage(const std::string& message) {
    std::fprintf(stderr, "cloudbench: %s\n\n%s", ShownMessage(message).c_str(), kHelp);
    return kExitUsage;
}

namespace {

int Perf(const CommonOptions& options) {
    const std::vector<std::string>& args = options.arguments;
    if (args.empty()) return Usage("perf needs a subcommand: record, compare, history or export");
    const std::string& sub = args[0];
    if (sub == "record") return Record(args, options);
    if (sub == "compare") return ComparePerf(args);
    if (sub == "history") return History(args);
    if (sub == "export") return Export(args);
    return Usage("perf: unknown subcommand '" + ShownArgument(sub) + "' (record, compare, history, export)");
}

const CommandRegistration kRegistration({
    .name = "perf",
    .summary = "Performance history and regression gate: record, compare, history, export",
    .help = kHelp,
    .helpOrder = 6,
    .takesScene = false,
    .rawArguments = true,
    .run = RunWith(Perf),
});

}  // namespace
}  // namespace cb::perf_command
