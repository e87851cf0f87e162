// The timing parts of `cloudbench report` (harness/report/html/ReportSections.h): a
// results.json's stage times beside the source documents' figures, their box plots, and
// the source documents' own table.
#include <algorithm>

#include "cloudbench_seed_timings.h"
#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {
namespace {

using report::Cell;
using report::Column;
using report::Table;

// The scene's stages in order, from results.json's scene block, else from the backends' stages.
std::vector<std::string> ResultStages(const json& doc) {
    std::vector<std::string> stages;
    for (const json& s : Arr(Obj(doc, "scene"), "stages"))
        if (s.is_string()) stages.push_back(s.get<std::string>());
    for (const auto& [name, backend] : Obj(doc, "backends").items())
        for (const auto& [stage, summary] : Obj(backend, "stages").items())
            if (std::ranges::find(stages, stage) == stages.end()) stages.push_back(stage);
    return stages;
}

std::vector<std::string> BackendNames(const json& doc) {
    std::vector<std::string> names;
    for (const auto& [name, backend] : Obj(doc, "backends").items()) names.push_back(name);
    // nlohmann orders keys alphabetically; the provenance keeps the order the backends were asked for.
    std::vector<std::string> ordered;
    for (const json& b : Arr(Obj(doc, "provenance"), "backends")) {
        const std::string name = Str(b, "name");
        if (std::ranges::find(names, name) != names.end() && std::ranges::find(ordered, name) == ordered.end())
            ordered.push_back(name);
    }
    for (const std::string& name : names)
        if (std::ranges::find(ordered, name) == ordered.end()) ordered.push_back(name);
    return ordered;
}

std::string SeedText(const json& figure) {
    const json& source = Obj(Obj(SeedTimings(), "sources"), Str(figure, "seed").c_str());
    return Fixed(Number(figure, "ms").value_or(0)) + " ms: " + Str(figure, "what") + " (seed " + Str(figure, "seed") +
           ", " + Str(figure, "table") + ", " + Str(source, "hardware") + ")";
}

// The source documents' figures for a stage of a run of `scene`: those for every scene, and those for this one.
std::vector<std::string> SeedFiguresFor(const std::string& stage, const std::string& scene) {
    std::vector<std::string> out;
    for (const json& f : Arr(SeedTimings(), "figures")) {
        const std::string forScene = Str(f, "scene");
        if (Str(f, "stage") == stage && (forScene.empty() || forScene == scene)) out.push_back(SeedText(f));
    }
    return out;
}
}  // namespace

Table TimingTable(const json& doc) {
    const std::vector<std::string> backends = BackendNames(doc);
    const std::string scene = Str(Obj(doc, "scene"), "name");
    std::vector<Column> columns = {Column("stage")};
    for (const std::string& b : backends) {
        columns.push_back(Column(b + " median").Real("%.3f").Unit("ms"));
        columns.push_back(Column(b + " q1-q3").Unit("ms"));
    }
    columns.push_back(Column("source documents' figures"));
    Table table(columns);
    for (const std::string& stage : ResultStages(doc)) {
        std::vector<Cell> row = {stage};
        for (const std::string& b : backends) {
            const json& s = Obj(Obj(Obj(Obj(doc, "backends"), b.c_str()), "stages"), stage.c_str());
            const auto median = Number(s, "median_ms"), q1 = Number(s, "q1_ms"), q3 = Number(s, "q3_ms");
            row.push_back(median && Number(s, "count").value_or(1) > 0 ? Cell(*median) : Cell());
            row.push_back(q1 && q3 ? Cell(Fixed(*q1) + " - " + Fixed(*q3)) : Cell());
        }
        std::string seeds;
        for (const std::string& f : SeedFiguresFor(stage, scene)) seeds += (seeds.empty() ? "" : "; ") + f;
        row.push_back(seeds.empty() ? Cell() : Cell(seeds));
        table.rows.push_back(std::move(row));
    }
    return table;
}

Table SeedTable() {
    Table table({Column("seed"), Column("table"), Column("stage"), Column("what"),
                 Column("time").Real("%.3f").Unit("ms"), Column("as printed"), Column("hardware")});
    for (const json& f : Arr(SeedTimings(), "figures")) {
        const json& source = Obj(Obj(SeedTimings(), "sources"), Str(f, "seed").c_str());
        std::string what = Str(f, "what");
        if (const std::string scene = Str(f, "scene"); !scene.empty()) what += " [" + scene + "]";
        table.rows.push_back({Str(f, "seed"), Str(f, "table"), Str(f, "stage"), what, Number(f, "ms").value_or(0),
                              Str(f, "rate"), Str(source, "hardware")});
    }
    return table;
}

report::KeyValues SeedSources() {
    report::KeyValues kv;
    for (const auto& [seed, source] : Obj(SeedTimings(), "sources").items())
        kv.items.emplace_back("seed " + seed, Str(source, "document") + "; " + Str(source, "setup"));
    return kv;
}

report::Figure TimingBoxes(const ReportInput& input) {
    const json& doc = input.doc;
    BoxPlot plot;
    plot.title = "Stage times of " + Str(Obj(doc, "scene"), "name") + " (" + FileName(input.path) + ")";
    plot.yLabel = "ms per call (log)";
    plot.series = BackendNames(doc);
    for (const std::string& stage : ResultStages(doc)) {
        BoxPlot::Group group{stage, {}};
        for (size_t b = 0; b < plot.series.size(); ++b) {
            const json& s = Obj(Obj(Obj(Obj(doc, "backends"), plot.series[b].c_str()), "stages"), stage.c_str());
            std::vector<double> samples = Numbers(s, "samples_ms");
            if (!samples.empty()) group.boxes.push_back({b, std::move(samples)});
        }
        if (!group.boxes.empty()) plot.groups.push_back(std::move(group));
    }
    return {"box", RenderBoxPlot(plot),
            "Per-step stage times after warm-up: boxes from the first to the third quartile, the median as a line, "
            "whiskers to the furthest sample within 1.5 IQR, circles beyond."};
}

const json& SeedTimings() {
    static const json timings = json::parse(kSeedTimingsJson);
    return timings;
}

}  // namespace cb::html
