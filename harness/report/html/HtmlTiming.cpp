// The timing parts of `cloudbench report` (harness/report/html/ReportSections.h): a
// results.json's stage times beside the source documents' figures, their box plots, and
// the source documents' own table.
#include <algorithm>
#include <cstdio>

#include "cloudbench_seed_timings.h"
#include "harness/report/Report.h"
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

// The source documents' figures (docs/seed-timings.json) for a stage of a run of `scene`: those for every scene,
// and those for this one.
std::vector<const json*> SeedFigures(const std::string& stage, const std::string& scene) {
    std::vector<const json*> out;
    for (const json& f : Arr(SeedTimings(), "figures")) {
        const std::string forScene = Str(f, "scene");
        if (Str(f, "stage") == stage && (forScene.empty() || forScene == scene)) out.push_back(&f);
    }
    return out;
}

std::vector<std::string> SeedFiguresFor(const std::string& stage, const std::string& scene) {
    std::vector<std::string> out;
    for (const json* f : SeedFigures(stage, scene)) out.push_back(SeedText(*f));
    return out;
}

// A renderer's block of per-camera frames in results.json (as ResultsJson.cpp names them); "" for another stage.
std::string FramesKey(const std::string& stage) {
    const std::optional<Stage> parsed = ParseStage(stage);
    const RendererDescriptor* renderer = parsed ? Describe(*parsed).renderer : nullptr;
    return renderer ? std::string(renderer->resultsKey) : "";
}

// A stage's per-step summary in one backend: from its samples (the median and quartiles as Summarize takes them),
// else from the summary's fields.
std::optional<Summary> StageSummary(const json& stage) {
    const std::vector<double> samples = Numbers(stage, "samples_ms");
    if (!samples.empty()) return Summarize(samples);
    const auto median = Number(stage, "median_ms"), q1 = Number(stage, "q1_ms"), q3 = Number(stage, "q3_ms");
    if (!median || Number(stage, "count").value_or(1) == 0) return std::nullopt;
    Summary s;
    s.count = size_t(Number(stage, "count").value_or(1));
    s.median = *median;
    s.q1 = q1.value_or(*median);
    s.q3 = q3.value_or(*median);
    return s;
}
}  // namespace

std::optional<double> FramesPerStep(const json& doc, const std::string& backend, const std::string& stage) {
    const std::string key = FramesKey(stage);
    if (key.empty()) return std::nullopt;
    const json& b = Obj(Obj(doc, "backends"), backend.c_str());
    const size_t cameras = Obj(b, key.c_str()).size();
    if (cameras == 0) return std::nullopt;
    // Frames of each camera a rendering step draws: render.frames_per_step, or more when time-sliced.
    const json& runs = Obj(Obj(b, "stage_runs"), stage.c_str());
    const double ran = Number(runs, "ran").value_or(0), frames = Number(runs, "frames").value_or(0);
    const double perStep =
        ran > 0 && frames > 0 ? frames / ran : std::max(1.0, Number(Obj(doc, "scene"), "frames_per_step").value_or(1));
    return perStep * double(cameras);
}

std::vector<std::string> StageFigureLines(const json& doc, const std::string& backend) {
    std::vector<std::string> lines;
    const std::string scene = Str(Obj(doc, "scene"), "name");
    const json& stages = Obj(Obj(Obj(doc, "backends"), backend.c_str()), "stages");
    for (const std::string& stage : ResultStages(doc)) {
        if (!FramesKey(stage).empty() || !stages.contains(stage)) continue;  // a renderer: FrameFigureLines
        // By document and table: "8.696 ms at shade.resolution 1, 2.174 ms at shade.resolution 2 (seed 000, ...)".
        std::vector<std::pair<std::string, std::string>> groups;  // (seed + table, the group's figures)
        for (const json* f : SeedFigures(stage, scene)) {
            std::string figure = Fixed(Number(*f, "ms").value_or(0)) + " ms";
            for (const auto& [key, value] : Obj(*f, "settings").items()) figure += " at " + key + " " + value.dump();
            const json& source = Obj(Obj(SeedTimings(), "sources"), Str(*f, "seed").c_str());
            const std::string where =
                "seed " + Str(*f, "seed") + ", " + Str(*f, "table") + ", " + Str(source, "hardware");
            auto group = std::ranges::find(groups, where, &std::pair<std::string, std::string>::first);
            if (group == groups.end())
                groups.push_back({where, figure});
            else
                group->second += ", " + figure;
        }
        if (groups.empty()) continue;
        std::string line = "  " + stage + " in the source documents:";
        for (size_t n = 0; n < groups.size(); ++n)
            line += (n ? ";" : "") + std::string(" ") + groups[n].second + " (" + groups[n].first + ")";
        lines.push_back(line);
    }
    return lines;
}

std::vector<std::string> FrameFigureLines(const json& doc, const std::string& backend) {
    std::vector<std::string> lines;
    const std::string scene = Str(Obj(doc, "scene"), "name");
    for (const std::string& stage : ResultStages(doc)) {
        const auto frames = FramesPerStep(doc, backend, stage);
        const auto summary =
            StageSummary(Obj(Obj(Obj(Obj(doc, "backends"), backend.c_str()), "stages"), stage.c_str()));
        if (!frames || !summary) continue;
        char text[256];
        std::snprintf(text, sizeof text, "  %s per camera frame: %.3f ms (the step's median %.3f ms over %.4g frame%s)",
                      stage.c_str(), summary->median / *frames, summary->median, *frames, *frames == 1 ? "" : "s");
        std::string line = text;
        // The documents' figures, by document: each time, or their range when there are more than three.
        std::vector<std::string> seeds;
        for (const json* f : SeedFigures(stage, scene))
            if (std::ranges::find(seeds, Str(*f, "seed")) == seeds.end()) seeds.push_back(Str(*f, "seed"));
        std::string papers;
        for (const std::string& seed : seeds) {
            std::vector<double> ms;
            for (const json* f : SeedFigures(stage, scene))
                if (Str(*f, "seed") == seed) ms.push_back(Number(*f, "ms").value_or(0));
            std::string times;
            if (ms.size() > 3)
                times = Fixed(*std::ranges::min_element(ms)) + " to " + Fixed(*std::ranges::max_element(ms));
            else
                for (double t : ms) times += (times.empty() ? "" : ", ") + Fixed(t);
            const json& source = Obj(Obj(SeedTimings(), "sources"), seed.c_str());
            papers += (papers.empty() ? "" : "; ") + times + " ms (seed " + seed + ", " + Str(source, "hardware") + ")";
        }
        if (!papers.empty()) line += "; the source documents' frame: " + papers + "; cloudbench report compares them";
        lines.push_back(line);
    }
    return lines;
}

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
            if (Number(s, "count") == 0.0) {  // no sample after warm-up: "-", as `run` prints it, never 0
                row.insert(row.end(), {Cell("-"), Cell("-")});
                continue;
            }
            row.push_back(median ? Cell(*median) : Cell());
            row.push_back(q1 && q3 ? Cell(Fixed(*q1) + " - " + Fixed(*q3)) : Cell());
        }
        std::string seeds;
        for (const std::string& f : SeedFiguresFor(stage, scene)) seeds += (seeds.empty() ? "" : "; ") + f;
        // A renderer's step draws every camera: the documents' figures, a frame each, go beside its time per frame.
        std::vector<Cell> perFrame = {stage + " per camera frame"};
        bool anyFrame = false;
        for (const std::string& b : backends) {
            const auto frames = FramesPerStep(doc, b, stage);
            const auto s = StageSummary(Obj(Obj(Obj(Obj(doc, "backends"), b.c_str()), "stages"), stage.c_str()));
            anyFrame |= frames && s;
            perFrame.push_back(frames && s ? Cell(s->median / *frames) : Cell());
            perFrame.push_back(frames && s ? Cell(Fixed(s->q1 / *frames) + " - " + Fixed(s->q3 / *frames)) : Cell());
        }
        const bool renderer = !FramesKey(stage).empty();
        row.push_back(seeds.empty() || renderer ? Cell() : Cell(seeds));
        table.rows.push_back(std::move(row));
        if (renderer && (anyFrame || !seeds.empty())) {
            perFrame.push_back(seeds.empty() ? Cell() : Cell(seeds));
            table.rows.push_back(std::move(perFrame));
        }
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
