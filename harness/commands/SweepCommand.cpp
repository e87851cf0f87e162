// `cloudbench sweep`: the cartesian product of --vary values; each stage the
// varied fields reach (harness/accuracy/SweepFields.h) timed and compared with
// the exact reference on every backend once per distinct setting of what it
// reads, the Pareto front marked with its ties; writes sweep.json, sweep.md and
// the plot sweep.png (tools/plot_sweep.py); exits as `report` judges sweep.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <expected>
#include <optional>

#include "core/base/ShownText.h"
#include "core/plan/StageGraph.h"
#include "harness/accuracy/AccuracyTransfer.h"
#include "harness/accuracy/IsolatedMeasurement.h"
#include "harness/accuracy/Measurement.h"
#include "harness/accuracy/SweepFields.h"
#include "harness/accuracy/SweepPareto.h"
#include "harness/commands/SweepOutput.h"
#include "harness/report/html/ReportInput.h"
#include "harness/report/html/ReportJson.h"
#include "harness/run/RunTransfer.h"

namespace cb {
namespace {

using nlohmann::json;

const std::string kHelpText = R"(usage: cloudbench sweep [SCENE] --vary PATH=V1,V2,... [--vary ...] [options]

Runs the cartesian product of the --vary values (dotted scene paths, as for
--set; a value may be JSON, e.g. --vary grid.size=[32,32,8],[64,64,16]). At
each point: the CPU simulates the scene to its last step, the Embree
reference is computed for that q and sun, and every backend's shade and
shadow stages are timed (median of --repeat calls, with quartiles) and
compared with it. Marks the Pareto front (no other point clearly as fast and
as accurate; ties within the timing noise marked *=) per stage and writes
DIR/sweep.json, DIR/sweep.md and DIR/sweep.png (error against time, one
series per backend; needs python3 with matplotlib, otherwise the plot is
skipped with a message).

When a varied field is one a renderer's image depends on (its descriptor's
image fields), the scene's renderers
()" + RendererNames(", ") + R"() are measured too, against the
exact reference render (see cloudbench help accuracy): per-pixel error = max
over channels of |C - C_ref|, and PSNR; the renderers share one Pareto front
and one panel of the plot. A stage is measured only when a varied field can
change its rows (the fields its descriptor reads, those of the stages that
feed it, and for a renderer its reference), once per distinct setting of those
fields; its rows list only them.

Exit codes: 0 when a row was measured and none failed, 1 for a failed or
crashed row, 4 when no row was measured (every row unsupported or
unavailable), as `cloudbench report` judges sweep.json.

Options:
  --vary PATH=V1,... a field and its values; repeat for more fields
  --backend LIST     backends to measure (default: all built); also --backends
  --metric M         error for the Pareto front: max (default), mean or p99 of
                     |error|, or psnr (renderers only; higher is better)
  --within E         also print (and write in sweep.json's "within") the fastest
                     setting of each stage and backend whose error is within E:
                     |error| <= E, or PSNR >= E dB with --metric psnr
  --repeat N         timed calls per point, after one warm-up (default 5)
  --reference-step X the exact reference render's step in voxel edges
                     (default 0.125), when images are measured
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/sweep)
  --set PATH=VALUE   override a scene field for every point
  --threads N        CPU backend and reference threads (default: all)
  --cpu-isa ISA      CPU kernels' SIMD target: auto (default: the best here), scalar, sse4, avx2, avx512
  --vk-device DEV    Vulkan device: index or part of the name
  --gl-context CTX   OpenGL context: osmesa (default) or egl
  --gl-ca-layout L   OpenGL automaton layout: packed (default) or rgba8
  --shard I/N        measure only share I of N (1 <= I <= N): the points whose
                     index k (0-based, in the order above) has k % N == I-1;
                     every point is still validated. sweep.json gains a
                     "shard" block for `cloudbench merge`; the Pareto marks
                     of a shard are within the shard only
  --quiet            no progress lines
)";
const std::string kHelp = kHelpText + IsolationOptionsHelp();

// Splits "V1,V2,..." at commas outside brackets, braces and quotes.
std::vector<std::string> SplitValues(const std::string& text) {
    std::vector<std::string> out;
    std::string current;
    int depth = 0;
    bool quoted = false;
    for (char ch : text) {
        if (ch == '"')
            quoted = !quoted;
        else if (!quoted && (ch == '[' || ch == '{'))
            ++depth;
        else if (!quoted && (ch == ']' || ch == '}'))
            --depth;
        if (ch == ',' && depth == 0 && !quoted) {
            out.push_back(current);
            current.clear();
        } else
            current += ch;
    }
    out.push_back(current);
    return out;
}

}  // namespace

using Axis = SweepAxis;

std::expected<std::vector<Axis>, std::string> ParseVaryAxes(const std::vector<std::string>& vary) {
    std::vector<Axis> axes;
    for (const std::string& arg : vary) {
        const size_t eq = arg.find('=');
        if (eq == std::string::npos || eq == 0)
            return std::unexpected("--vary '" + ShownArgument(arg) +
                                   "': expected PATH=V1,V2,... (a dotted scene path, '=', values)");
        Axis axis{arg.substr(0, eq), SplitValues(arg.substr(eq + 1))};
        for (const std::string& v : axis.values)
            if (v.empty()) return std::unexpected("--vary '" + ShownArgument(arg) + "': empty value in the list");
        for (const Axis& other : axes)
            if (other.path == axis.path)
                return std::unexpected("--vary '" + ShownArgument(arg) + "': " + ShownArgument(axis.path) +
                                       " is varied twice");
        axes.push_back(std::move(axis));
    }
    // Before the product is made: 10 axes of 10 values would be 10^10 points.
    if (auto why = VaryTooLarge(axes)) return std::unexpected(*why);
    return axes;
}

namespace {

// The cartesian product of the axes' values, every point validated against the
// scene before anything runs; kExitBadScene (after the message) on a bad point.
std::expected<std::vector<std::vector<SceneOverride>>, int> Points(const Session& session,
                                                                   const std::vector<Axis>& axes) {
    std::vector<std::vector<SceneOverride>> points = VaryPoints(axes);
    for (const auto& point : points) {
        if (auto s = session.LoadVariant(point); !s) {
            std::fprintf(stderr, "sweep: --vary point %s:\n%s\n", SettingsLabel(point).c_str(),
                         s.error().message.c_str());
            return std::unexpected(kExitBadScene);
        }
    }
    return points;
}

// sweep's own options (docs/cli.md), besides --repeat and --reference-step.
// "fastest within max |error| <= 0.01: shade on cpu: shade shade.resolution=2, 0.412 ms, error 0.0087", a line
// per front (a stage; the renderers together) and backend measured, "none" where no row is within the bound.
void PrintFastestWithin(const std::vector<Row>& rows, const std::string& metric, double within,
                        const std::vector<const Row*>& fastest) {
    const std::string bound = metric == "psnr" ? "PSNR >= " + html::Fixed(within) + " dB"
                                               : metric + " |error| <= " + html::Fixed(within, "%.6g");
    std::vector<std::pair<Stage, std::string>> fronts;
    for (const Row& r : rows)
        if (r.result.status == "ok" && MetricApplies(metric, r.stage) &&
            std::ranges::none_of(
                fronts, [&](const auto& f) { return f.second == r.backend && SameParetoFront(f.first, r.stage); }))
            fronts.push_back({r.stage, r.backend});
    for (const auto& [stage, backend] : fronts) {
        const auto pick = std::ranges::find_if(
            fastest, [&](const Row* f) { return f->backend == backend && SameParetoFront(f->stage, stage); });
        const std::string front = Describe(stage).renderer ? "the renderers" : std::string(StageName(stage));
        if (pick == fastest.end()) {
            std::printf("fastest within %s: %s on %s: none\n", bound.c_str(), front.c_str(), backend.c_str());
            continue;
        }
        const Row& r = **pick;
        const double error = metric == "psnr" ? -MetricLoss(r, metric) : MetricLoss(r, metric);
        std::printf("fastest within %s: %s on %s: %s %s, %s ms, error %s\n", bound.c_str(), front.c_str(),
                    backend.c_str(), std::string(StageName(r.stage)).c_str(), SettingsLabel(r.settings).c_str(),
                    html::Fixed(r.result.timeMs.median).c_str(), html::Fixed(error, "%.4g").c_str());
    }
}

struct SweepOptions : MeasurementOptions {
    std::vector<std::string> vary;  // --vary PATH=V1,V2,...
    std::string metric = "max";     // --metric: max, mean, p99 or psnr
    std::optional<double> within;   // --within E: the fastest setting with an error within E
    int shardIndex = 0;             // --shard I/N: share I (1-based) of N; shardCount 0 = not sharded
    int shardCount = 0;
};

// What a stage list reads of the axes, for messages: "shade (shade.resolution), shadow (shade.sigma)".
std::string SweepStagesText(const std::vector<Stage>& stages, const std::vector<Axis>& axes) {
    std::string out;
    for (Stage stage : stages) {
        std::string read;
        for (const Axis& a : axes)
            if (RowDependsOn(stage, a.path)) read += (read.empty() ? "" : ", ") + a.path;
        out += (out.empty() ? "" : "; ") + std::string(StageName(stage)) + " (" + read + ")";
    }
    return out;
}

int Sweep(const CommonOptions& options, const SweepOptions& own) {
    if (own.vary.empty()) {
        std::fprintf(stderr, "sweep: needs at least one --vary PATH=V1,V2,...\n");
        return kExitUsage;
    }
    if (!IsSweepMetric(own.metric)) {
        std::fprintf(stderr, "sweep: --metric: must be max, mean, p99 or psnr, got '%s'\n",
                     ShownArgument(own.metric).c_str());
        return kExitUsage;
    }
    auto axes = ParseVaryAxes(own.vary);
    if (!axes) {
        std::fprintf(stderr, "sweep: %s\n", axes.error().c_str());
        return kExitUsage;
    }
    const std::vector<Stage> reached = SweepStages(*axes);
    if (reached.empty()) {
        std::string paths;
        for (const Axis& a : *axes) paths += (paths.empty() ? "" : ", ") + ShownArgument(a.path);
        std::fprintf(stderr,
                     "sweep: --vary: no measured stage (shade, shadow, the renderers) reads %s, so every point "
                     "would measure the same; vary a field a stage reads (cloudbench help sweep)\n",
                     paths.c_str());
        return kExitUsage;
    }
    if (own.metric == "psnr")
        for (Stage stage : reached)
            if (!MetricApplies(own.metric, stage)) {
                std::fprintf(stderr,
                             "sweep: --metric psnr: PSNR is defined for the renderers' images only, and this sweep "
                             "measures %s; use max, mean or p99, or vary only march., render., lightning. or "
                             "layers. fields\n",
                             SweepStagesText({stage}, *axes).c_str());
                return kExitUsage;
            }
    const bool sharded = own.shardCount > 0;
    if (sharded)
        for (const Axis& a : *axes)
            for (size_t i = 0; i < a.values.size(); ++i)
                if (std::find(a.values.begin(), a.values.begin() + ptrdiff_t(i), a.values[i]) !=
                    a.values.begin() + ptrdiff_t(i)) {
                    std::fprintf(stderr, "sweep: --vary %s: value %s given twice (not allowed with --shard)\n",
                                 a.path.c_str(), a.values[i].c_str());
                    return kExitUsage;
                }
    auto session = Session::Open(options, "sweep");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    auto points = Points(**session, *axes);
    if (!points) return points.error();
    if (!(*session)->MakeOutDir()) return kExitFailed;
    const std::vector<std::string> names = (*session)->RequestedBackends(BuiltBackends());

    // The scene's stages among them (all of them when the stage list varies), each once per distinct setting
    // of the fields it reads, at the first point that has it.
    const bool stagesVary = std::ranges::any_of(*axes, [](const Axis& a) { return FieldsOverlap(a.path, "stages"); });
    std::vector<Stage> stages;
    for (Stage stage : reached)
        if (stagesVary || scene.stages.Has(stage)) stages.push_back(stage);
    if (stages.empty()) {
        std::fprintf(stderr, "sweep: scene %s runs none of the stages the varied fields reach: %s; no row to measure\n",
                     scene.name.c_str(), SweepStagesText(reached, *axes).c_str());
        return kExitNoBackend;
    }
    const std::vector<std::vector<Stage>> measured = DistinctMeasurements(*points, stages);
    size_t measurements = 0;
    for (const auto& m : measured) measurements += m.size();
    std::printf(
        "sweep of scene %s: %zu points x %zu backends, %zu stage measurements (%s), %d timed calls each, Pareto "
        "front on median time and %s%s\n",
        scene.name.c_str(), points->size(), names.size(), measurements, SweepStagesText(stages, *axes).c_str(),
        own.repeats, own.metric.c_str(), own.metric == "psnr" ? " (higher is better)" : " error");
    if (sharded)
        std::printf("shard %d/%d: points k with k %% %d == %d (the Pareto marks are within the shard)\n",
                    own.shardIndex, own.shardCount, own.shardCount, own.shardIndex - 1);
    // With --shard I/N, the points whose global index k has k % N == I-1; a point measures the stages whose
    // setting it is the first to have.
    std::vector<size_t> planPoint;
    std::vector<PlannedSetting> plan;
    for (size_t k = 0; k < points->size(); ++k)
        if ((!sharded || int(k % size_t(own.shardCount)) == own.shardIndex - 1) && !measured[k].empty()) {
            planPoint.push_back(k);
            plan.push_back({(*points)[k], measured[k]});
        }
    // Each backend measures every point in a process of its own (harness/accuracy/IsolatedMeasurement.h).
    auto parts = MeasureEachBackend(**session, own, names, plan, {}, [&](size_t n) {
        if (!options.quiet) std::fprintf(stderr, "sweep: point %zu/%zu done\n", n + 1, plan.size());
    });
    if (!parts) {
        std::fprintf(stderr, "sweep: %s\n", parts.error().message.c_str());
        return kExitFailed;
    }
    if (std::ranges::none_of(*parts, [](const BackendMeasurement& p) { return p.available; })) return kExitNoBackend;
    std::vector<size_t> rowItem;
    std::vector<Row> rows = MergeRows(scene, plan, *parts, &rowItem);
    MarkPareto(rows, own.metric);
    const std::vector<const Row*> fastest =
        own.within ? FastestWithin(rows, own.metric, *own.within) : std::vector<const Row*>{};
    if (own.within) PrintFastestWithin(rows, own.metric, *own.within, fastest);

    json doc = {{"format", "cloudbench-sweep/1"},
                {"scene", scene.name},
                {"grid", {scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz}},
                {"step", scene.steps - 1},
                {"metric", own.metric},
                {"repeats", own.repeats},
                {"reference_start", "voxel-exit"},
                {"references", ReferencesJson(FirstRecords(*parts), options.cpuThreads)}};
    if (own.within) {
        json picks = json::array();
        for (const Row* r : fastest) picks.push_back(RowJson(*r));
        doc["within"] = {{"bound", *own.within}, {"fastest", std::move(picks)}};
    }
    if (sharded) {
        // Every measured row with its point's global index, for `cloudbench merge`.
        json shardRows = json::array();
        for (size_t i = 0; i < rows.size(); ++i) {
            shardRows.push_back(transfer::ToJson(rows[i]));
            shardRows.back()["point"] = planPoint[rowItem[i]];
        }
        doc["shard"] = {{"index", own.shardIndex},
                        {"count", own.shardCount},
                        {"points", points->size()},
                        {"rows", std::move(shardRows)}};
    }
    const int written =
        WriteSweepOutputs(std::move(doc), scene.name, own.metric, *axes, stages, rows, (*session)->OutDir(),
                          [&](const std::string& path, json d) { return (*session)->WriteJson(path, std::move(d)); });
    if (written != kExitOk) return written;
    // The exit code `cloudbench report` gives this sweep.json (html::VerdictOf): 1 for a row that failed or
    // crashed, 4 when none was measured.
    html::ReportInput verdictInput{"sweep.json", html::InputKind::Sweep, {{"rows", json::array()}}};
    for (const Row& r : rows) verdictInput.doc["rows"].push_back(RowJson(r));
    const html::Verdict verdict = html::VerdictOf(verdictInput);
    if (verdict.exitCode != kExitOk) {
        // The verdict names the rows; for a failure, each distinct reason too (the verdict of no row names them).
        std::string why;
        for (const Row& r : rows)
            if (verdict.exitCode == kExitFailed && r.result.status != "ok" && !r.result.detail.empty() &&
                why.find(r.result.detail) == std::string::npos)
                why += "\n  " + std::string(StageName(r.stage)) + " on " + r.backend + " " + r.result.status + ": " +
                       r.result.detail;
        std::fprintf(stderr, "sweep: %s (exit %d)%s\n", verdict.reason.c_str(), verdict.exitCode, why.c_str());
    }
    return verdict.exitCode;
}

const CommandRegistration kRegistration({
    .name = "sweep",
    .summary = "Vary scene fields over a cartesian product: time and error, Pareto front, plot",
    .help = kHelp,
    .helpOrder = 5,
    .extraOptions = WithIsolationOptions(
        {ListOption("--vary", &SweepOptions::vary, "--vary needs PATH=V1,V2,..., e.g. --vary shade.resolution=1,2,4"),
         TextOption("--metric", &SweepOptions::metric, "--metric needs max, mean, p99 or psnr"), RepeatOption(),
         OwnOption<SweepOptions>("--within", true,
                                 [](SweepOptions& o, const char* v) -> std::optional<std::string> {
                                     const std::string bad =
                                         "--within needs a number, the error bound in the "
                                         "--metric's unit (dB for psnr), e.g. --within 0.01";
                                     if (!v) return bad;
                                     char* end = nullptr;
                                     const double e = std::strtod(v, &end);
                                     if (end == v || *end != '\0' || !std::isfinite(e))
                                         return bad + ", got '" + ShownArgument(v) + "'";
                                     o.within = e;
                                     return std::nullopt;
                                 }),
         ReferenceStepOption(),
         OwnOption<SweepOptions>("--shard", true,
                                 [](SweepOptions& o, const char* v) -> std::optional<std::string> {
                                     const std::string bad =
                                         "--shard needs I/N with 1 <= I <= N <= 1000000, e.g. --shard 2/8";
                                     if (!v) return bad;
                                     int index = 0, count = 0, used = 0;
                                     if (std::sscanf(v, "%d/%d%n", &index, &count, &used) != 2 || v[used] != '\0' ||
                                         index < 1 || count < index || count > 1000000)
                                         return bad + ", got '" + v + "'";
                                     o.shardIndex = index;
                                     o.shardCount = count;
                                     return std::nullopt;
                                 })}),
    .makeOptions = MakeOwnOptions<SweepOptions>,
    .run = RunWith(Sweep),
});

}  // namespace
}  // namespace cb
