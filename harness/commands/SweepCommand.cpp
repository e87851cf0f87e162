// `cloudbench sweep`: the cartesian product of --vary values, each point's
// shade and shadow stages timed and compared with the exact reference on
// every backend, the Pareto front marked; writes sweep.json, sweep.md and the
// plot sweep.png (tools/plot_sweep.py).
#include <cstdio>
#include <cstdlib>
#include <expected>

#include "harness/IsolatedMeasurement.h"
#include "harness/Measurement.h"

namespace cb {
namespace {

using nlohmann::json;

constexpr const char* kHelpText = R"(usage: cloudbench sweep [SCENE] --vary PATH=V1,V2,... [--vary ...] [options]

Runs the cartesian product of the --vary values (dotted scene paths, as for
--set; a value may be JSON, e.g. --vary grid.size=[32,32,8],[64,64,16]). At
each point: the CPU simulates the scene to its last step, the Embree
reference is computed for that q and sun, and every backend's shade and
shadow stages are timed (median of --repeat calls, with quartiles) and
compared with it. Marks the Pareto front (no other point as fast and as
accurate) per stage and writes DIR/sweep.json, DIR/sweep.md and DIR/sweep.png
(error against time, one series per backend; needs python3 with matplotlib,
otherwise the plot is skipped with a message).

Options:
  --vary PATH=V1,... a field and its values; repeat for more fields
  --backend LIST     backends to measure (default: all built)
  --metric M         error for the Pareto front: max (default), mean or p99
  --repeat N         timed calls per point, after one warm-up (default 5)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/sweep)
  --set PATH=VALUE   override a scene field for every point
  --threads N        CPU backend and reference threads (default: all)
  --vk-device DEV    Vulkan device: index or part of the name
  --gl-context CTX   OpenGL context: osmesa (default) or egl
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

struct Axis {
    std::string path;
    std::vector<std::string> values;
};

// Pareto front per stage: no other ok row is at least as fast and as accurate
// and strictly better in one.
void MarkPareto(std::vector<Row>& rows, const std::string& metric) {
    auto error = [&](const Row& r) {
        return metric == "mean" ? r.result.all.mean : metric == "p99" ? r.result.all.p99 : r.result.all.max;
    };
    for (Row& r : rows) {
        if (r.result.status != "ok") continue;
        r.pareto = true;
        for (const Row& o : rows) {
            if (&o == &r || o.stage != r.stage || o.result.status != "ok") continue;
            const double t = o.result.timeMs.median, e = error(o);
            const double tr = r.result.timeMs.median, er = error(r);
            if (t <= tr && e <= er && (t < tr || e < er)) {
                r.pareto = false;
                break;
            }
        }
    }
}

// The --vary arguments as axes; a usage message when one is malformed.
std::expected<std::vector<Axis>, std::string> ParseAxes(const std::vector<std::string>& vary) {
    std::vector<Axis> axes;
    for (const std::string& arg : vary) {
        const size_t eq = arg.find('=');
        if (eq == std::string::npos || eq == 0)
            return std::unexpected("--vary '" + arg + "': expected PATH=V1,V2,... (a dotted scene path, '=', values)");
        Axis axis{arg.substr(0, eq), SplitValues(arg.substr(eq + 1))};
        for (const std::string& v : axis.values)
            if (v.empty()) return std::unexpected("--vary '" + arg + "': empty value in the list");
        for (const Axis& other : axes)
            if (other.path == axis.path)
                return std::unexpected("--vary '" + arg + "': " + axis.path + " is varied twice");
        axes.push_back(std::move(axis));
    }
    return axes;
}

// The cartesian product of the axes' values, every point validated against the
// scene before anything runs; kExitBadScene (after the message) on a bad point.
std::expected<std::vector<std::vector<SceneOverride>>, int> Points(const Session& session,
                                                                   const std::vector<Axis>& axes) {
    std::vector<std::vector<SceneOverride>> points = {{}};
    for (const Axis& axis : axes) {
        std::vector<std::vector<SceneOverride>> next;
        for (const auto& p : points)
            for (const std::string& v : axis.values) {
                auto q = p;
                q.push_back({axis.path, v});
                next.push_back(std::move(q));
            }
        points = std::move(next);
    }
    for (const auto& point : points) {
        if (auto s = session.LoadVariant(point); !s) {
            std::fprintf(stderr, "sweep: --vary point %s:\n%s\n", SettingsLabel(point).c_str(),
                         s.error().message.c_str());
            return std::unexpected(kExitBadScene);
        }
    }
    return points;
}

// Plots sweep.json into `pngPath` with tools/plot_sweep.py (matplotlib); says
// why on stderr and returns false when it cannot. The JSON and the table stand without it.
bool Plot(const std::string& jsonPath, const std::string& mdPath, const std::string& pngPath) {
    auto quote = [](const std::string& s) {
        std::string out = "'";
        for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return out + "'";
    };
    // Debian's python3-matplotlib is for /usr/bin/python3, which another python3
    // on the PATH (a virtual environment, pyenv) may hide: the first that has it.
    std::string python;
    for (const char* candidate : {"/usr/bin/python3", "python3"})
        if (std::system((std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            python = candidate;
            break;
        }
    const std::string script = std::string(CLOUDBENCH_TOOLS_DIR) + "/plot_sweep.py";
    std::string command;
    const bool plotted = !python.empty() && Session::WriteAtomically(pngPath, [&](const std::string& temp) -> Status {
        command = python + " " + quote(script) + " " + quote(jsonPath) + " " + quote(temp);
        if (std::system(command.c_str()) != 0) return MakeError(pngPath + ": plot_sweep.py failed");
        return {};
    });
    if (python.empty())
        std::fprintf(stderr,
                     "sweep: no plot: python3 with matplotlib was not found (apt-get install "
                     "python3-matplotlib); %s and %s are written\n",
                     jsonPath.c_str(), mdPath.c_str());
    else if (!plotted)
        std::fprintf(stderr, "sweep: no plot: '%s' failed; %s and %s are written\n", command.c_str(), jsonPath.c_str(),
                     mdPath.c_str());
    return plotted;
}

int Sweep(const CommonOptions& options) {
    if (options.vary.empty()) {
        std::fprintf(stderr, "sweep: needs at least one --vary PATH=V1,V2,...\n");
        return kExitUsage;
    }
    if (options.metric != "max" && options.metric != "mean" && options.metric != "p99") {
        std::fprintf(stderr, "sweep: --metric: must be max, mean or p99, got '%s'\n", options.metric.c_str());
        return kExitUsage;
    }
    auto axes = ParseAxes(options.vary);
    if (!axes) {
        std::fprintf(stderr, "sweep: %s\n", axes.error().c_str());
        return kExitUsage;
    }
    auto session = Session::Open(options, "sweep");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    auto points = Points(**session, *axes);
    if (!points) return points.error();
    if (!(*session)->MakeOutDir()) return kExitFailed;
    const std::vector<std::string> names = (*session)->RequestedBackends(BuiltBackends());

    std::printf(
        "sweep of scene %s: %zu points x %zu backends, %d timed calls each, Pareto front on median time and "
        "%s error\n",
        scene.name.c_str(), points->size(), names.size(), options.repeats, options.metric.c_str());
    // A stage is left out when every varied field belongs to the other one
    // (shadow's beer form reads shade.sigma, so that one counts for both).
    bool onlyShade = true, onlyShadow = true;
    for (const Axis& a : *axes) {
        onlyShade &= a.path.starts_with("shade.") && a.path != "shade.sigma";
        onlyShadow &= a.path.starts_with("shadow.");
    }
    std::vector<Stage> stages;
    if (!onlyShadow) stages.push_back(Stage::Shade);
    if (!onlyShade) stages.push_back(Stage::Shadow);
    // Each backend measures every point in a process of its own (harness/IsolatedMeasurement.h).
    std::vector<PlannedSetting> plan;
    for (const auto& point : *points) plan.push_back({point, stages});
    auto parts = MeasureEachBackend(**session, names, plan, {}, [&](size_t n) {
        if (!options.quiet) std::fprintf(stderr, "sweep: point %zu/%zu done\n", n + 1, points->size());
    });
    if (!parts) {
        std::fprintf(stderr, "sweep: %s\n", parts.error().message.c_str());
        return kExitFailed;
    }
    if (std::ranges::none_of(*parts, [](const BackendMeasurement& p) { return p.available; })) return kExitNoBackend;
    const bool anyCrashed =
        std::ranges::any_of(*parts, [](const BackendMeasurement& p) { return p.failure.has_value(); });
    std::vector<Row> rows = MergeRows(scene, plan, *parts);
    MarkPareto(rows, options.metric);

    json doc = {{"format", "cloudbench-sweep/1"},
                {"scene", scene.name},
                {"grid", {scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz}},
                {"step", scene.steps - 1},
                {"metric", options.metric},
                {"repeats", options.repeats},
                {"reference_start", "voxel-exit"},
                {"vary", json::array()},
                {"rows", json::array()}};
    for (const Axis& a : *axes) doc["vary"].push_back({{"path", a.path}, {"values", a.values}});
    report::Report report("Sweep of " + scene.name);
    report.sections.push_back({"",
                               {report::Paragraph{"Pareto front (*) on median time and " + options.metric +
                                                  " |error| over all elements, per stage."}}});
    for (Stage stage : stages) {
        report::Table table;
        for (const Axis& a : *axes) table.columns.emplace_back(a.path);
        for (report::Column& c : ErrorColumns({}, stage)) table.columns.push_back(std::move(c));
        table.columns.insert(table.columns.begin() + ptrdiff_t(axes->size()) + 1, report::Column("pareto"));
        for (const Row& r : rows) {
            if (r.stage != stage) continue;
            doc["rows"].push_back(RowJson(r));
            doc["rows"].back()["pareto"] = r.pareto;
            std::vector<report::Cell> cells;
            for (const SceneOverride& o : r.settings) cells.push_back(o.value);
            for (report::Cell& cell : RowCells(r)) cells.push_back(std::move(cell));
            cells.insert(cells.begin() + ptrdiff_t(axes->size()) + 1, r.pareto ? "*" : "");
            table.rows.push_back(std::move(cells));
        }
        if (table.rows.empty()) continue;
        report::Section section{std::string(StageName(stage)), {std::move(table)}};
        std::printf("\n%s", report::RenderText(section).c_str());
        report.sections.push_back(std::move(section));
    }
    doc["references"] = ReferencesJson(FirstRecords(*parts), options.cpuThreads);
    doc["report"] = report::RenderJson(report);

    const std::string& outDir = (*session)->OutDir();
    const std::string jsonPath = outDir + "/sweep.json", mdPath = outDir + "/sweep.md", pngPath = outDir + "/sweep.png";
    if (Status s = (*session)->WriteJson(jsonPath, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    const bool plotted = Plot(jsonPath, mdPath, pngPath);
    if (plotted) report.sections.push_back({"Plot", {report::Image{"sweep.png", "error against time"}}});
    if (Status s = Session::WriteText(mdPath, report::RenderMarkdown(report)); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s %s%s\n", jsonPath.c_str(), mdPath.c_str(), plotted ? (" " + pngPath).c_str() : "");
    return anyCrashed ? kExitFailed : kExitOk;
}

const CommandRegistration kRegistration({
    .name = "sweep",
    .summary = "Vary scene fields over a cartesian product: time and error, Pareto front, plot",
    .help = kHelp,
    .helpOrder = 5,
    .extraOptions = WithIsolationOptions(
        {ListOption("--vary", &CommonOptions::vary, "--vary needs PATH=V1,V2,..., e.g. --vary shade.resolution=1,2,4"),
         TextOption("--metric", &CommonOptions::metric, "--metric needs max, mean or p99"), RepeatOption()}),
    .run = Sweep,
});

}  // namespace
}  // namespace cb
