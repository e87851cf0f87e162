// The perf gate's file schemas (harness/report/PerfSchemas.h); docs/results.md describes the files.
#include "harness/report/PerfSchemas.h"

#include <string>
#include <vector>

namespace cb::input::detail {

using namespace schema;

namespace {

// --plant STAGE:FACTOR: HEAD ran with the slowdown, BASE with factor 1 (harness/perf/Compare.h PlantedSlowdown).
Node PerfSchemaPlant() {
    return Object({{"stage", TextOf(SchemaStageNames()), true}, {"factor", Number(1, 1000), true}});
}

}  // namespace

// What `perf compare --interleave --keep` keeps (harness/perf/Compare.h): each run's folder is
// "base/NAME" or "head/NAME", a name of its own inside the kept folder.
Node InterleaveSchema() {
    const Node run = Object({{"side", TextOf({"base", "head"}), true},
                             {"scene", Text(), true},
                             {"round", Integer(0, 1e6), true},
                             {"folder", Text(), true},
                             {"exit", Integer(-1, 255)},
                             {"seconds", Number(0, 1e12)},
                             {"load", ArrayOf(Number(0, 1e6), 3, 3)}});
    return Object({{"format", TextOf({"cloudbench-interleave/1"}), true},
                   {"base", Text(), true},
                   {"head", Text(), true},
                   {"scenes", ArrayOf(Text()), true},
                   {"rounds", Integer(1, 1e6), true},
                   {"order", TextOf({"random", "ABBA"})},
                   {"run_options", ArrayOf(Text())},
                   {"plant", PerfSchemaPlant()},
                   {"runs", ArrayOf(run), true}});
}

// `perf compare --json` (harness/commands/PerfCompare.cpp PrintComparison). A number a comparison could not
// give (a ratio with no BASE) is null.
Node PerfCompareSchema() {
    const Node count = Integer(0, 9007199254740992.0);
    const Node time = Nullable(Number(0));
    const Node probability = Nullable(Number(0, 1));
    const Node comparison = Object({{"scene", Text(), true},
                                    {"backend", Text(), true},
                                    {"stage", TextOf(SchemaStageNames()), true},
                                    {"metric", TextOf({"time", "instructions"}), true},
                                    {"test", TextOf({"", "rounds", "runs", "steps"})},
                                    {"base_runs", count},
                                    {"head_runs", count},
                                    {"pairs", count},
                                    {"base_count", count},
                                    {"head_count", count},
                                    {"base_median", time},
                                    {"head_median", time},
                                    {"ratio", time},
                                    {"threshold", time},
                                    {"ratio_ci", ArrayOf(time, 2, 2)},
                                    {"p_slower", probability},
                                    {"p_faster", probability},
                                    {"p_slower_holm", probability},
                                    {"p_faster_holm", probability},
                                    {"mark", TextOf({"+", "-", "~", "?", "x", "!"}), true},
                                    {"regression", Boolean(), true},
                                    {"note", Text()}});
    const Node side = Object({{"label", Text(), true}, {"date", Text()}, {"provenance", ProvenanceSchema()}});
    const Node failedRun = Object({{"side", TextOf({"base", "head"}), true},
                                   {"scene", Text(), true},
                                   {"round", Integer(0, 1e6), true},
                                   {"exit", Integer(-1, 255), true},
                                   {"compared", Boolean(), true}});
    return Object({{"format", TextOf({"cloudbench-perf-compare/1"}), true},
                   {"base", side, true},
                   {"head", side, true},
                   {"mode", Text(), true},
                   {"clock", TextOf({"wall", "cpu"})},
                   {"separate", Boolean()},
                   {"threshold", Number(0)},
                   {"backend_thresholds", MapOf(KeyRule::Backend, Number(0))},
                   {"floor_ms", Number(0)},
                   {"alpha", Number(0, 1)},
                   {"instruction_threshold", Number(0)},
                   {"comparisons", ArrayOf(comparison), true},
                   {"run_statistic", Text()},
                   {"regressions", count},
                   {"unjudged", ArrayOf(Text())},
                   {"failed_runs", ArrayOf(failedRun)},
                   {"cut_short", Text()},
                   {"plant", PerfSchemaPlant()},
                   {"exit_code", Integer(0, 255), true},
                   {"report", ReportBlockSchema()}});
}

}  // namespace cb::input::detail
