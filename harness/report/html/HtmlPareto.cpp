// The accuracy part of `cloudbench report` (ParetoBlocks,
// harness/report/html/ReportSections.h): error against time per stage, with the
// Pareto front.
#include <algorithm>

#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {

std::vector<report::Block> ParetoBlocks(const ReportInput& input) {
    std::vector<report::Block> blocks;
    const json& doc = input.doc;
    const bool sweep = input.kind == InputKind::Sweep;
    const std::string metric = sweep ? Str(doc, "metric", "max") : "max";
    std::vector<std::string> stages, backends;
    for (const json& row : Arr(doc, "rows")) {
        if (Str(row, "status") != "ok") continue;
        const std::string stage = Str(row, "stage"), backend = Str(row, "backend");
        if (std::ranges::find(stages, stage) == stages.end()) stages.push_back(stage);
        if (std::ranges::find(backends, backend) == backends.end()) backends.push_back(backend);
    }
    std::ranges::sort(backends);
    for (const std::string& stage : stages) {
        ScatterPlot plot;
        plot.title = Str(doc, "scene") + ": " + stage + " (" + FileName(input.path) + ")";
        plot.xLabel = "median time of the stage (ms, log)";
        plot.yLabel = metric + " |error| vs the Embree reference";
        std::vector<std::pair<double, double>> all, marked;
        for (const std::string& backend : backends) {
            Series s{backend, {}, {}, {}, {}};
            for (const json& row : Arr(doc, "rows")) {
                if (Str(row, "status") != "ok" || Str(row, "stage") != stage || Str(row, "backend") != backend)
                    continue;
                const auto t = Number(Obj(row, "time"), "median_ms");
                const auto e = Number(Obj(Obj(row, "error"), "all"), metric.c_str());
                if (!t || !e) continue;
                s.x.push_back(*t);
                s.y.push_back(*e);
                std::string settings;
                for (const auto& [k, v] : Obj(row, "settings").items())
                    settings +=
                        (settings.empty() ? "" : ", ") + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
                s.pointLabels.push_back(backend + " " + settings + ": " + Fixed(*t) + " ms, error " +
                                        Fixed(*e, "%.3g"));
                all.emplace_back(*t, *e);
                if (row.value("pareto", false)) marked.emplace_back(*t, *e);
            }
            if (!s.x.empty()) plot.series.push_back(std::move(s));
        }
        // sweep.json marks its front; for accuracy.json it is computed here over every backend's points.
        plot.front = sweep ? ParetoFront(marked) : ParetoFront(all);
        if (sweep) std::ranges::sort(plot.front);
        blocks.emplace_back(report::Figure{
            "pareto", RenderParetoPlot(plot),
            "Error against time for " + stage +
                ", one point per setting and backend; the dashed line joins the "
                "points no other point beats in both (" +
                std::string(sweep ? "as sweep.json marks them" : "computed over the rows of accuracy.json") + ")."});
    }
    return blocks;
}

}  // namespace cb::html
