// The output half of `cloudbench sweep` (harness/commands/SweepOutput.h).
#include "harness/commands/SweepOutput.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "harness/Command.h"
#include "harness/Session.h"

namespace cb {

using nlohmann::json;

void MarkPareto(std::vector<Row>& rows, const std::string& metric) {
    auto error = [&](const Row& r) {
        return metric == "mean" ? r.result.all.mean : metric == "p99" ? r.result.all.p99 : r.result.all.max;
    };
    // The two renderers share one front: they make the same image.
    auto group = [](Stage s) { return s == Stage::RenderSplat ? Stage::RenderMarch : s; };
    for (Row& r : rows) {
        if (r.result.status != "ok") continue;
        r.pareto = true;
        for (const Row& o : rows) {
            if (&o == &r || group(o.stage) != group(r.stage) || o.result.status != "ok") continue;
            const double t = o.result.timeMs.median, e = error(o);
            const double tr = r.result.timeMs.median, er = error(r);
            if (t <= tr && e <= er && (t < tr || e < er)) {
                r.pareto = false;
                break;
            }
        }
    }
}

std::vector<Stage> SweepStages(const std::vector<SweepAxis>& axes) {
    // Fields of the image sections: the renderers are measured (the scene's own,
    // MeasureSetting skips the others); fields that only a renderer reads measure nothing else.
    auto imagePath = [](const std::string& p, bool withPhase) {
        for (const char* prefix : {"march.", "render.", "lightning.", "phase."})
            if (p.starts_with(prefix) && (withPhase || std::string_view(prefix) != "phase.")) return true;
        return false;
    };
    const bool images = std::ranges::any_of(axes, [&](const SweepAxis& a) { return imagePath(a.path, true); });
    const bool onlyImages = std::ranges::all_of(axes, [&](const SweepAxis& a) { return imagePath(a.path, false); });
    std::vector<Stage> renderers;
    if (images) renderers = {Stage::RenderMarch, Stage::RenderSplat};
    if (onlyImages) return renderers;
    bool onlyShade = true, onlyShadow = true;
    for (const SweepAxis& a : axes) {
        onlyShade &= a.path.starts_with("shade.") && a.path != "shade.sigma";
        onlyShadow &= a.path.starts_with("shadow.");
    }
    std::vector<Stage> stages;
    if (!onlyShadow) stages.push_back(Stage::Shade);
    if (!onlyShade) stages.push_back(Stage::Shadow);
    stages.insert(stages.end(), renderers.begin(), renderers.end());
    return stages;
}

namespace {

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

}  // namespace

int WriteSweepOutputs(json doc, const std::string& sceneName, const std::string& metric,
                      const std::vector<SweepAxis>& axes, const std::vector<Stage>& stages,
                      const std::vector<Row>& rows, const std::string& outDir, const SweepJsonWriter& writeJson) {
    doc["vary"] = json::array();
    doc["rows"] = json::array();
    for (const SweepAxis& a : axes) doc["vary"].push_back({{"path", a.path}, {"values", a.values}});
    report::Report report("Sweep of " + sceneName);
    report.sections.push_back({"",
                               {report::Paragraph{"Pareto front (*) on median time and " + metric +
                                                  " |error| over all elements, per stage."}}});
    for (Stage stage : stages) {
        report::Table table;
        for (const SweepAxis& a : axes) table.columns.emplace_back(a.path);
        for (report::Column& c : ErrorColumns({}, stage)) table.columns.push_back(std::move(c));
        table.columns.insert(table.columns.begin() + ptrdiff_t(axes.size()) + 1, report::Column("pareto"));
        for (const Row& r : rows) {
            if (r.stage != stage) continue;
            doc["rows"].push_back(RowJson(r));
            doc["rows"].back()["pareto"] = r.pareto;
            std::vector<report::Cell> cells;
            for (const SceneOverride& o : r.settings) cells.push_back(o.value);
            for (report::Cell& cell : RowCells(r)) cells.push_back(std::move(cell));
            cells.insert(cells.begin() + ptrdiff_t(axes.size()) + 1, r.pareto ? "*" : "");
            table.rows.push_back(std::move(cells));
        }
        if (table.rows.empty()) continue;
        report::Section section{std::string(StageName(stage)), {std::move(table)}};
        std::printf("\n%s", report::RenderText(section).c_str());
        report.sections.push_back(std::move(section));
    }
    doc["report"] = report::RenderJson(report);

    const std::string jsonPath = outDir + "/sweep.json", mdPath = outDir + "/sweep.md", pngPath = outDir + "/sweep.png";
    if (Status s = writeJson(jsonPath, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    // Nothing to plot without a measured row (an empty shard, or every backend unavailable).
    const bool measured = std::ranges::any_of(rows, [](const Row& r) { return r.result.status == "ok"; });
    const bool plotted = measured && Plot(jsonPath, mdPath, pngPath);
    if (plotted) report.sections.push_back({"Plot", {report::Image{"sweep.png", "error against time"}}});
    if (Status s = Session::WriteText(mdPath, report::RenderMarkdown(report)); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s %s%s\n", jsonPath.c_str(), mdPath.c_str(), plotted ? (" " + pngPath).c_str() : "");
    return kExitOk;
}

}  // namespace cb
