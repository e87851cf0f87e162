// The accuracy part of `cloudbench report` (ParetoBlocks,
// harness/report/html/ReportSections.h): error against time per stage, with the
// Pareto front. The renderers (RendererStages) make the same image, so they
// share one plot and one front, a series per renderer and backend, as
// sweep.json's marks and tools/plot_sweep.py do.
#include <algorithm>

#include "core/plan/StageGraph.h"
#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {
namespace {

bool IsRendererName(const std::string& stage) {
    const std::optional<Stage> s = ParseStage(stage);
    return s && Describe(*s).renderer;
}

// One measured setting: its plot ("images" for every renderer), series, time and error.
struct ParetoPoint {
    std::string plot, series, label;
    double time = 0, error = 0;
    bool marked = false;
};

std::string SettingsText(const json& row) {
    std::string settings;
    for (const auto& [k, v] : Obj(row, "settings").items())
        settings += (settings.empty() ? "" : ", ") + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
    return settings;
}

// The rows of sweep.json or accuracy.json (its stage rows, then its renderers' image rows) as points.
std::vector<ParetoPoint> Points(const json& doc, const std::string& metric) {
    std::vector<ParetoPoint> points;
    // psnr (sweep --metric psnr, renderers only) is the row's psnr_db; an infinite one (null: the image equals
    // the reference) has no place on the axis and is left out of the plot.
    auto add = [&](const json& row, const std::string& stage, const json& error) {
        if (Str(row, "status") != "ok") return;
        const auto t = Number(Obj(row, "time"), "median_ms");
        const auto e = metric == "psnr" ? Number(Obj(row, "error"), "psnr_db") : Number(error, metric.c_str());
        if (!t || !e) return;
        const std::string backend = Str(row, "backend");
        const bool image = IsRendererName(stage);
        const std::string series = image ? stage.substr(7) + " " + backend : backend;
        points.push_back({image ? "images" : stage, series,
                          series + " " + SettingsText(row) + ": " + Fixed(*t) + " ms, error " + Fixed(*e, "%.3g"), *t,
                          *e, row.value("pareto", false)});
    };
    for (const json& row : Arr(doc, "rows")) add(row, Str(row, "stage"), Obj(Obj(row, "error"), "all"));
    for (const json& row : Arr(doc, "image_rows")) add(row, Str(row, "renderer"), Obj(row, "error"));
    return points;
}

}  // namespace

std::vector<report::Block> ParetoBlocks(const ReportInput& input) {
    std::vector<report::Block> blocks;
    const json& doc = input.doc;
    const bool sweep = input.kind == InputKind::Sweep;
    // A sweep's own metric; accuracy.json's max and mean each (a stage whose worst cell is wrong whatever the
    // setting, as the ground shadow's edges are, shows its max pinned near 1 and its settings apart in the mean).
    const std::vector<std::string> metrics =
        sweep ? std::vector<std::string>{Str(doc, "metric", "max")} : std::vector<std::string>{"max", "mean"};
    for (const std::string& metric : metrics) {
        const std::vector<ParetoPoint> points = Points(doc, metric);
        std::vector<std::string> plots, series;
        for (const ParetoPoint& p : points) {
            if (std::ranges::find(plots, p.plot) == plots.end()) plots.push_back(p.plot);
            if (std::ranges::find(series, p.series) == series.end()) series.push_back(p.series);
        }
        std::ranges::sort(series);
        for (const std::string& name : plots) {
            ScatterPlot plot;
            const std::string what = name == "images" ? "the renderers' images" : name;
            plot.title = Str(doc, "scene") + ": " + what + ", " + metric + " (" + FileName(input.path) + ")";
            plot.xLabel = "median time of the stage (ms, log)";
            plot.yLabel = metric == "psnr" ? "PSNR (dB) vs the exact reference render, higher is better"
                                           : metric + " |error| vs the Embree reference";
            plot.logY = metric != "psnr";  // decibels are a logarithm already
            std::vector<std::pair<double, double>> all, marked;
            for (const std::string& seriesName : series) {
                Series s{seriesName, {}, {}, {}, {}};
                for (const ParetoPoint& p : points) {
                    if (p.plot != name || p.series != seriesName) continue;
                    s.x.push_back(p.time);
                    s.y.push_back(p.error);
                    s.pointLabels.push_back(p.label);
                    all.emplace_back(p.time, p.error);
                    if (p.marked) marked.emplace_back(p.time, p.error);
                }
                if (!s.x.empty()) plot.series.push_back(std::move(s));
            }
            // sweep.json marks its front (ties and PSNR's direction included); for accuracy.json it is computed here
            // over every point of the plot.
            plot.front = sweep ? marked : ParetoFront(all);
            if (sweep) std::ranges::sort(plot.front);
            blocks.emplace_back(report::Figure{
                "pareto", RenderParetoPlot(plot),
                "Error against time for " + what +
                    ", one point per setting, renderer and backend; the dashed line joins the "
                    "points no other point beats in both (" +
                    std::string(sweep ? "as sweep.json marks them" : "computed over the rows of accuracy.json") +
                    ")."});
        }
    }
    return blocks;
}

}  // namespace cb::html
