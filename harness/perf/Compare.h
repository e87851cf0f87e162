// What `perf compare` compares: the per-step samples of each scene x backend x
// stage, run by run (and instruction counts), of two sides, each loaded from a
// results.json (or the folder `run --out` wrote), a history record or a
// `count` output, or from interleaved runs (kept or not).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "harness/perf/Stats.h"

namespace cb::perf {

template <typename T>
using ByStage = std::map<std::string, std::map<std::string, std::map<std::string, T>>>;  // scene, backend, stage

// One `cloudbench run`'s per-step samples of one stage: the unit the gate's
// tests draw on, since steps within a run share its machine state.
struct RunSamples {
    int round = -1;  // the interleaved round it ran in (0-based); -1 outside an interleave
    std::vector<double> ms;
};

// Which of a stage's times the samples are: its wall time, or the process's
// CPU time over its calls (results.json's "cpu"; docs/results.md), which does
// not follow other jobs on the machine (docs/performance.md, "The regression gate").
enum class Clock { Wall, Cpu };
inline const char* ClockName(Clock clock) { return clock == Clock::Cpu ? "cpu" : "wall"; }

struct Side {
    std::string label;  // what it was loaded from: "FILE", "FILE@ID"
    Clock clock = Clock::Wall;  // the clock of `runs`, chosen before loading
    std::string date;   // when it was measured (ISO 8601); "" when unknown
    nlohmann::json provenance = nlohmann::json::object();
    ByStage<std::vector<RunSamples>> runs;                               // per-step times, run by run
    std::map<std::string, std::map<std::string, std::string>> failures;  // scene, backend: why it gave no result
    ByStage<double> instructions;                                        // `cloudbench count`: exact per-stage counts
    size_t records = 0;  // the history records pooled into it; 0 when it is not from a history
};

// Every run's samples, one after another.
std::vector<double> Pooled(const std::vector<RunSamples>& runs);

// Adds a results.json document's samples on the side's clock as one more run
// (measured in `round`), its failed backends and, when `side` has none yet, its
// provenance and date. Error: "LABEL: reason" for a document that is not
// cloudbench-results/1, or that lacks a stage's CPU time on the CPU clock.
Status AddResults(Side& side, const nlohmann::json& results, int round = -1);
// Adds an {"instructions": {scene: {backend: {stage: count}}}} section.
Status AddInstructions(Side& side, const nlohmann::json& doc);

// The side a BASE or HEAD argument names: "FILE" (a results.json, a count
// output or a history, whose last record is taken), "FOLDER" (the folder a
// `run --out` wrote: its results.json), "FILE@ID" or "FILE@-N" (a history
// record), "FILE@A:B" (the records from A to B, their runs pooled: History.h's
// SelectRecords). Errors name the argument. On the CPU clock, a record that
// holds no CPU times (written before perf record kept them) is refused, naming
// its id and line.
Result<Side> LoadSide(const std::string& spec, Clock clock = Clock::Wall);

// What `perf compare --interleave --keep FOLDER` keeps (docs/cli.md): every
// run's output folder, and FOLDER/interleave.json listing the runs in the
// order they ran, with their side, scene, round, exit code and the load average.
inline constexpr const char* kInterleaveFormat = "cloudbench-interleave/1";
inline constexpr const char* kInterleaveFile = "interleave.json";
// The live command's verdict, its --json document, kept beside interleave.json when it reached one (`report
// FOLDER` shows it).
inline constexpr const char* kKeptVerdictFile = "compare.json";

// A run of an interleave that failed: it exited other than 0, or wrote no valid results.json.
// Either makes `perf compare` exit 1 when nothing regressed, live or from the kept folder.
struct FailedRun {
    std::string side;       // "base" or "head"
    std::string scene;      // as the command line named it
    int round = 0;          // 0-based
    int exit = 0;           // the run's exit code
    bool compared = false;  // its results.json was read and its samples compared
};

// `perf compare --interleave --plant STAGE:FACTOR` (docs/cli.md): HEAD runs with
// CLOUDBENCH_TEST_SLOWDOWN=STAGE:FACTOR and BASE with STAGE:1, the control; kept in interleave.json's "plant".
struct PlantedSlowdown {
    std::string stage;
    double factor = 1;  // in [1, 1000]
};

// What `perf compare FOLDER` judges: both sides, each run in its round, and what the live command
// would have ended with besides the comparison.
struct KeptInterleave {
    std::array<Side, 2> sides;
    std::vector<FailedRun> failedRuns;  // in the order they ran
    int rounds = 0;                     // the rounds with a recorded run (the highest round + 1)
    std::string order = "ABBA";         // how each round's two runs were ordered: "random" or "ABBA"
    size_t recordedRuns = 0;
    size_t plannedRuns = 0;  // rounds x scenes x 2: fewer recorded means the interleave was cut short
    double peakLoad = 0;     // the highest 1-minute load average a run started at
    std::optional<PlantedSlowdown> plant;  // --plant, when the interleave was run with it
};

// The kept interleave in `folder`. Errors name the file and field: no interleave.json, one that is not
// the format, a run's folder outside its side's, a run that exited 0 without its results.json, and
// "FOLDER/interleave.json: /runs: no run was recorded; nothing to compare".
Result<KeptInterleave> LoadInterleave(const std::string& folder, Clock clock = Clock::Wall);

// "base run of ci-small in round 1 exited 1" (the round 1-based, as the kept folders are named), with
// "and wrote no valid results.json" when it was not compared.
std::string DescribeFailedRun(const FailedRun& run);

// A history record's "results", "failures" and "instructions" sections from a
// side on the wall clock: each stage's pooled "samples_ms" and "median_ms", and
// "runs_ms" (the samples run by run) when there was more than one run; and
// beside them "cpu", the same of `cpu` (the same runs on the CPU clock) where
// it has the stage with as many runs.
nlohmann::json RecordSections(const Side& side, const Side& cpu);

// How `perf compare` judges a stage's time (docs/cli.md, "perf"; why, in
// docs/performance.md, "The regression gate"). The run is the sample: each run
// gives one statistic of its steps (their `runQuantile`). Interleaved sides
// are paired by round, and the test is a sign-flip permutation test over the
// rounds' log-ratios; other sides of several runs each take a two-sample
// permutation test over the runs' logs. Only a side of a single run falls back
// to its steps (a Mann-Whitney U test that takes them as independent, which
// they are not: hence the wider separate threshold and the floor).
struct CompareSettings {
    double threshold = 1.1;  // a slowdown ratio above this (and significant) is a regression
    // Per backend, instead of `threshold`: OpenGL and Vulkan run on software drivers (llvmpipe, lavapipe)
    // that share the CPU, and moved up to 2.28x between identical builds (reports/perf/walltime.md).
    std::map<std::string, double> backendThreshold = {{"gl", 3.0}, {"vk", 3.0}};
    double separateThreshold = 2.0;  // used instead when the sides were not measured interleaved
    bool interleaved = false;
    double runQuantile = 0.5;            // the statistic of a run's steps
    double floorMs = 0.05;               // one run a side: and the medians differ by more than this
    double alpha = 0.01;                 // family-wise, after Holm's correction
    double instructionThreshold = 0.02;  // relative change of an exact count
    double confidence = 0.95;
    int resamples = 2000;
    int permutations = 9999;  // where a permutation test is not drawn exactly
    uint64_t seed = 20260101;
    size_t minSamples = 20;  // one run a side: fewer steps on a side cannot be tested
};

struct Comparison {
    std::string scene, backend, stage;
    std::string metric;  // "time" (ms) or "instructions"
    std::string test;    // "rounds" (paired by round), "runs" (two samples of runs), "steps" (one run a side)
    size_t baseRuns = 0, headRuns = 0, pairs = 0;            // runs a side; rounds with a run on both sides
    size_t baseCount = 0, headCount = 0;                     // steps (samples) a side, over its runs
    double baseMedian = NAN, headMedian = NAN, ratio = NAN;  // ratio = head / base
    double threshold = NAN;                                  // the ratio a regression must exceed
    Interval interval{NAN, NAN};
    double pSlower = NAN, pFaster = NAN;          // one-sided
    double pSlowerHolm = NAN, pFasterHolm = NAN;  // Holm-adjusted over every time comparison
    // + slower, - faster, ~ not significant or within the threshold, ? cannot be judged (too few runs or
    // samples to reach alpha), x failed or missing in HEAD, ! new
    char mark = '~';
    bool regression = false;
    std::string note;
};

struct CompareOutcome {
    std::vector<Comparison> rows;
    double threshold = 0;  // the wall-time threshold applied to backends without their own
    bool separate = false;
    bool headFailed = false;  // some row is 'x'
    size_t Regressions() const;
    size_t Unjudged() const;  // rows marked '?'
};

// The wall-time threshold of `backend`: its own or the default, at least
// separateThreshold when the sides were not interleaved.
double ThresholdOf(const CompareSettings& settings, const std::string& backend);

// The fewest runs a side (as many on each) whose two-sample permutation test
// can reach `alpha` after Holm's correction over `comparisons` tests: the
// smallest n with comparisons x SmallestPermutationP(n, n) < alpha; 0 when no
// number of runs can (alpha at or below comparisons / (permutations + 1)).
size_t RunsToJudge(size_t comparisons, const CompareSettings& settings);

// The advice that ends the warning on stages marked '?': more rounds for
// interleaved sides; for history records, how many runs a side would be
// judged and how to get them (a range of records a side, or perf record
// --repeat); for results files, more steps or --interleave.
std::string UnjudgedAdvice(const Side& base, const Side& head, const CompareSettings& settings,
                           const CompareOutcome& outcome);

CompareOutcome Compare(const Side& base, const Side& head, const CompareSettings& settings);

}  // namespace cb::perf
