#include "harness/html/HtmlReport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "cloudbench_seed_timings.h"
#include "harness/html/SvgPlot.h"
#include "harness/perf/Stats.h"

namespace cb::html {
namespace {

using nlohmann::json;
using report::Cell;
using report::Column;
using report::Section;
using report::Table;

const json& EmptyObject() {
    static const json empty = json::object();
    return empty;
}

// doc[key] when it is an object, else an empty object: the inputs are read tolerantly.
const json& Obj(const json& doc, const char* key) {
    if (!doc.is_object()) return EmptyObject();
    auto it = doc.find(key);
    return it != doc.end() && it->is_object() ? *it : EmptyObject();
}

const json& Arr(const json& doc, const char* key) {
    static const json empty = json::array();
    if (!doc.is_object()) return empty;
    auto it = doc.find(key);
    return it != doc.end() && it->is_array() ? *it : empty;
}

// doc[key] as text: a string as it is, a number or boolean as JSON writes it, else `fallback`.
std::string Str(const json& doc, const char* key, const std::string& fallback = "") {
    if (!doc.is_object()) return fallback;
    auto it = doc.find(key);
    if (it == doc.end() || it->is_null() || it->is_object() || it->is_array()) return fallback;
    return it->is_string() ? it->get<std::string>() : it->dump();
}

std::optional<double> Number(const json& doc, const char* key) {
    if (!doc.is_object()) return std::nullopt;
    auto it = doc.find(key);
    if (it == doc.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
}

std::vector<double> Numbers(const json& doc, const char* key) {
    std::vector<double> out;
    for (const json& v : Arr(doc, key))
        if (v.is_number()) out.push_back(v.get<double>());
    return out;
}

std::string FileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string Fixed(double value, const char* format = "%.3f") {
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

Result<ReportInput> ReadOne(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return MakeError(path + ": cannot read: " + std::strerror(errno));
    std::stringstream text;
    text << in.rdbuf();
    if (in.bad()) return MakeError(path + ": cannot read: " + std::strerror(errno));
    ReportInput input{path, InputKind::Results, {}};
    try {
        input.doc = json::parse(text.str());
    } catch (const json::exception& e) {
        return MakeError(path + ": not JSON: " + e.what());
    }
    const std::string format = Str(input.doc, "format");
    static const std::array<std::pair<std::string_view, InputKind>, 4> kFormats = {{
        {"cloudbench-results/1", InputKind::Results},
        {"cloudbench-conform/1", InputKind::Conform},
        {"cloudbench-accuracy/1", InputKind::Accuracy},
        {"cloudbench-sweep/1", InputKind::Sweep},
    }};
    for (const auto& [name, kind] : kFormats)
        if (format == name) {
            input.kind = kind;
            // The report block is read back into the page: check its shape here, where the file can be named.
            if (input.doc.contains("report")) try {
                    (void)report::ReportFromJson(input.doc["report"]);
                } catch (const json::exception& e) {
                    return MakeError(path + ": report: " + e.what());
                }
            return input;
        }
    return MakeError(path + ": not a cloudbench results, conform, accuracy or sweep file (\"format\" is " +
                     (format.empty() ? std::string("missing") : "'" + format + "'") + ")");
}

// ---- Provenance and verdict ----

report::KeyValues ProvenanceItems(const json& provenance) {
    report::KeyValues kv;
    const json& git = Obj(provenance, "git");
    const std::string dirty = Str(git, "dirty");
    kv.items.emplace_back("commit", Str(git, "commit", "unknown") + (dirty == "true" ? " (dirty)" : ""));
    const json& build = Obj(provenance, "build");
    kv.items.emplace_back("build", Str(build, "type", "?") + ", " + Str(build, "compiler", "?"));
    kv.items.emplace_back("flags", Str(build, "flags"));
    const json& machine = Obj(provenance, "machine");
    kv.items.emplace_back("machine",
                          Str(machine, "cpu", "?") + ", " + Str(machine, "threads", "?") + " hardware threads");
    kv.items.emplace_back("os", Str(machine, "os"));
    kv.items.emplace_back("date", Str(provenance, "date"));
    std::string backends;
    for (const json& b : Arr(provenance, "backends")) {
        backends += (backends.empty() ? "" : "; ") + Str(b, "name") + " " + Str(b, "status");
        const std::string device = Str(b, "device"), reason = Str(b, "reason");
        if (!device.empty()) backends += " (" + device + ")";
        if (!reason.empty()) backends += ": " + reason;
    }
    kv.items.emplace_back("backends", backends);
    const json& scene = Obj(provenance, "scene");
    std::string overrides;
    for (const json& o : Arr(scene, "overrides"))
        overrides += (overrides.empty() ? "" : ", ") + Str(o, "path") + "=" + Str(o, "value");
    kv.items.emplace_back("scene", Str(scene, "path") + (overrides.empty() ? "" : " with " + overrides));
    std::string commandLine;
    for (const json& arg : Arr(provenance, "command_line"))
        commandLine += (commandLine.empty() ? "" : " ") + (arg.is_string() ? arg.get<std::string>() : arg.dump());
    kv.items.emplace_back("command line", commandLine);
    return kv;
}

bool Finished(const std::string& status) { return status == "ok" || status == "unavailable" || status == "unsupported"; }

// ---- Timing ----

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

// The seeds' figures for a stage of a run of `scene`: those for every scene, and those for this one.
std::vector<std::string> SeedFiguresFor(const std::string& stage, const std::string& scene) {
    std::vector<std::string> out;
    for (const json& f : Arr(SeedTimings(), "figures")) {
        const std::string forScene = Str(f, "scene");
        if (Str(f, "stage") == stage && (forScene.empty() || forScene == scene)) out.push_back(SeedText(f));
    }
    return out;
}

Table TimingTable(const json& doc) {
    const std::vector<std::string> backends = BackendNames(doc);
    const std::string scene = Str(Obj(doc, "scene"), "name");
    std::vector<Column> columns = {Column("stage")};
    for (const std::string& b : backends) {
        columns.push_back(Column(b + " median").Real("%.3f").Unit("ms"));
        columns.push_back(Column(b + " q1-q3").Unit("ms"));
    }
    columns.push_back(Column("seeds' figures"));
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
    Table table({Column("seed"), Column("table"), Column("stage"), Column("what"), Column("time").Real("%.3f").Unit("ms"),
                 Column("as printed"), Column("hardware")});
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

// ---- History ----

// Whether `entry` of a record's "change_points" names (scene, backend, stage): an object whose
// "scene", "backend" and "stage" (each optional) match, or a string "scene/backend/stage".
bool MarksSeries(const json& entry, const std::string& scene, const std::string& backend, const std::string& stage) {
    if (entry.is_string()) return entry.get<std::string>() == scene + "/" + backend + "/" + stage;
    if (!entry.is_object()) return false;
    auto matches = [&](const char* key, const std::string& value) {
        const std::string given = Str(entry, key);
        return given.empty() || given == value;
    };
    return matches("scene", scene) && matches("backend", backend) && matches("stage", stage);
}

std::string RecordLabel(const json& record, size_t index) {
    std::string label = "#" + std::to_string(index) + " " + Str(record, "id") + " " + Str(record, "time");
    const std::string commit = Str(Obj(Obj(record, "provenance"), "git"), "commit");
    if (!commit.empty()) label += " " + commit.substr(0, 12);
    return label;
}

std::vector<report::Block> HistoryBlocks(const std::vector<json>& history, const std::string& path) {
    std::vector<report::Block> blocks;
    // scene -> stage -> backend -> points; std::map keeps a stable order.
    std::map<std::string, std::map<std::string, std::map<std::string, Series>>> series;
    std::map<std::string, std::map<std::string, Series>> instructions;  // scene -> stage
    size_t marked = 0;
    for (size_t r = 0; r < history.size(); ++r) {
        const json& record = history[r];
        for (const auto& [scene, backends] : Obj(record, "results").items()) {
            if (!backends.is_object()) continue;
            for (const auto& [backend, stages] : backends.items()) {
                if (!stages.is_object()) continue;
                for (const auto& [stage, s] : stages.items()) {
                    if (!s.is_object()) continue;
                    std::optional<double> median = Number(s, "median_ms");
                    if (!median) {
                        std::vector<double> samples = Numbers(s, "samples_ms");
                        if (samples.empty()) continue;
                        median = BoxStatsOf(samples).median;
                    }
                    Series& line = series[scene][stage][backend];
                    line.name = backend;
                    line.x.push_back(double(r));
                    line.y.push_back(*median);
                    line.pointLabels.push_back(RecordLabel(record, r) + ": " + Fixed(*median) + " ms");
                    for (const json& entry : Arr(record, "change_points"))
                        if (MarksSeries(entry, scene, backend, stage)) {
                            line.marks.push_back(line.x.size() - 1);
                            ++marked;
                            break;
                        }
                }
            }
        }
        for (const auto& [scene, perBackend] : Obj(record, "instructions").items())
            for (const auto& [stage, count] : Obj(perBackend, "cpu").items()) {
                if (!count.is_number()) continue;
                Series& line = instructions[scene][stage];
                line.name = stage;
                line.x.push_back(double(r));
                line.y.push_back(count.get<double>());
                line.pointLabels.push_back(RecordLabel(record, r) + ": " + count.dump() + " instructions");
            }
    }
    // Step changes found in each series by `perf history`'s detector, with its defaults (a change of
    // 10 % or more in the median, segments of 4 records or more), added to those the records list.
    perf::ChangePointSettings settings;
    settings.minChange = std::log1p(0.1);
    auto detect = [&](Series& line) {
        std::vector<double> logs;
        for (double v : line.y) logs.push_back(v > 0 ? std::log(v) : 0.0);
        for (size_t at : perf::ChangePoints(logs, settings))
            if (std::ranges::find(line.marks, at) == line.marks.end()) {
                line.marks.push_back(at);
                ++marked;
            }
    };
    for (auto& [scene, stages] : series)
        for (auto& [stage, backends] : stages)
            for (auto& [backend, line] : backends) detect(line);
    for (auto& [scene, stages] : instructions)
        for (auto& [stage, line] : stages) detect(line);
    blocks.emplace_back(report::Paragraph{
        std::to_string(history.size()) + " records from " + path + ", oldest first. " +
        (marked ? std::to_string(marked) +
                      " change point(s) marked (dashed lines): listed by the records or found by perf history's "
                      "detector (a step of 10 % or more in the median, segments of 4 records or more)."
                : "No change point listed or found.")});
    for (auto& [scene, stages] : series)
        for (auto& [stage, backends] : stages) {
            LinePlot plot{scene + ": " + stage + ", median per record", "record (oldest first)", "median ms", {}};
            for (auto& [backend, line] : backends) plot.series.push_back(std::move(line));
            blocks.emplace_back(report::Figure{"history", RenderHistoryPlot(plot),
                                               "History of " + stage + " on " + scene + ": one point per record."});
        }
    for (auto& [scene, stages] : instructions) {
        LinePlot plot{scene + ": instructions per stage (cpu, 1 thread)", "record (oldest first)", "instructions", {}};
        for (auto& [stage, line] : stages) plot.series.push_back(std::move(line));
        blocks.emplace_back(report::Figure{"history", RenderHistoryPlot(plot),
                                           "Instruction counts of the CPU stages on " + scene + " per record."});
    }
    return blocks;
}

// ---- Accuracy ----

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
                    settings += (settings.empty() ? "" : ", ") + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
                s.pointLabels.push_back(backend + " " + settings + ": " + Fixed(*t) + " ms, error " + Fixed(*e, "%.3g"));
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
            "Error against time for " + stage + ", one point per setting and backend; the dashed line joins the "
            "points no other point beats in both (" +
                std::string(sweep ? "as sweep.json marks them" : "computed over the rows of accuracy.json") + ")."});
    }
    return blocks;
}

}  // namespace

std::string_view InputKindName(InputKind kind) {
    switch (kind) {
        case InputKind::Results: return "results";
        case InputKind::Conform: return "conform";
        case InputKind::Accuracy: return "accuracy";
        case InputKind::Sweep: return "sweep";
    }
    return "";
}

Result<std::vector<ReportInput>> ReadReportInput(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_directory(path, ec)) {
        auto one = ReadOne(path);
        if (!one) return std::unexpected(one.error());
        return std::vector<ReportInput>{std::move(*one)};
    }
    std::vector<ReportInput> inputs;
    for (const char* name : {"results.json", "conform.json", "accuracy.json", "sweep.json"}) {
        const std::string file = (std::filesystem::path(path) / name).string();
        if (!std::filesystem::exists(file, ec)) continue;
        auto one = ReadOne(file);
        if (!one) return std::unexpected(one.error());
        inputs.push_back(std::move(*one));
    }
    if (inputs.empty())
        return MakeError(path + ": no results.json, conform.json, accuracy.json or sweep.json in this folder");
    return inputs;
}

Result<std::vector<json>> ReadHistory(const std::string& path, std::vector<std::string>& warnings) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return MakeError(path + ": cannot read: " + std::strerror(errno));
    std::vector<json> records;
    std::string line;
    for (size_t number = 1; std::getline(in, line); ++number) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        json record = json::parse(line, nullptr, false);
        std::string reason;
        if (record.is_discarded())
            reason = "not JSON (a half-written record?)";
        else if (!record.is_object())
            reason = "not a JSON object";
        else if (Str(record, "format") != "cloudbench-perf/1")
            reason = "\"format\" is not cloudbench-perf/1";
        if (!reason.empty()) {
            warnings.push_back(path + ":" + std::to_string(number) + ": skipped: " + reason);
            continue;
        }
        records.push_back(std::move(record));
    }
    if (in.bad()) return MakeError(path + ": cannot read: " + std::strerror(errno));
    return records;
}

Verdict VerdictOf(const ReportInput& input) {
    const json& doc = input.doc;
    switch (input.kind) {
        case InputKind::Results: {
            bool anyAvailable = false;
            std::string broken;
            for (const auto& [name, b] : Obj(doc, "backends").items()) {
                const std::string status = Str(b, "status");
                if (!Finished(status)) broken += (broken.empty() ? "" : ", ") + name + " " + status;
                anyAvailable |= status != "unavailable" && status != "unsupported";
            }
            if (!broken.empty()) return {1, "backend " + broken};
            if (doc.contains("complete") && !doc.value("complete", true))
                return {1, "the run did not finish (complete: false)"};
            if (!anyAvailable) return {4, "no backend was available"};
            return {};
        }
        case InputKind::Conform: {
            std::string broken, failed;
            bool compared = false;
            for (const json& r : Arr(doc, "results")) {
                const std::string status = Str(r, "status"), what = Str(r, "stage") + " on " + Str(r, "backend");
                // As conform's exit code (harness/Conform.h ConformExitCode): flaky and expected-fail rows
                // (--flake-reruns, --baseline) are not failures; an unexpected pass is.
                if (status == "fail" || status == "unexpected-pass")
                    failed += (failed.empty() ? "" : ", ") + what + (status == "fail" ? "" : " " + status);
                if (status != "pass" && status != "fail" && status != "skipped" && status != "flaky" &&
                    status != "expected-fail" && status != "unexpected-pass")
                    broken += (broken.empty() ? "" : ", ") + what + " " + status;
                compared |= status != "skipped";
            }
            if (!broken.empty()) return {1, broken};
            if (!failed.empty()) return {5, "failed: " + failed};
            if (!compared) return {4, "nothing was compared"};
            return {};
        }
        case InputKind::Accuracy:
        case InputKind::Sweep: {
            std::string broken;
            bool measured = false;
            for (const json& r : Arr(doc, "rows")) {
                const std::string status = Str(r, "status");
                measured |= status == "ok";
                if (!Finished(status))
                    broken += (broken.empty() ? "" : ", ") + Str(r, "stage") + " on " + Str(r, "backend") + " " + status;
            }
            if (!broken.empty()) return {1, broken};
            if (!measured) return {4, "no row was measured"};
            return {};
        }
    }
    return {};
}

int CombinedExitCode(const std::vector<Verdict>& verdicts) {
    for (int code : {1, 5, 4})
        for (const Verdict& v : verdicts)
            if (v.exitCode == code) return code;
    for (const Verdict& v : verdicts)
        if (v.exitCode != 0) return v.exitCode;
    return 0;
}

const json& SeedTimings() {
    static const json timings = json::parse(kSeedTimingsJson);
    return timings;
}

report::Report BuildReport(const std::vector<ReportInput>& inputs, const std::vector<json>& history,
                           const std::string& historyPath) {
    std::string scenes;
    for (const ReportInput& input : inputs) {
        const json& scene = input.doc.contains("scene") ? input.doc["scene"] : json();
        const std::string name = scene.is_object() ? Str(scene, "name") : scene.is_string() ? scene.get<std::string>() : "";
        if (!name.empty() && scenes.find(name) == std::string::npos) scenes += (scenes.empty() ? "" : ", ") + name;
    }
    report::Report out("cloudbench report" + (scenes.empty() ? std::string() : ": " + scenes));

    // Verdict: each input's, then the combined code.
    Section verdict{"Verdict", {}};
    std::vector<Verdict> verdicts;
    Table verdictTable({Column("input"), Column("kind"), Column("exit code").Integer(), Column("verdict"),
                        Column("why")});
    for (const ReportInput& input : inputs) {
        const Verdict v = VerdictOf(input);
        verdicts.push_back(v);
        verdictTable.rows.push_back({input.path, std::string(InputKindName(input.kind)), int64_t(v.exitCode),
                                     v.exitCode == 0 ? "pass" : "fail", v.reason});
    }
    const int combined = CombinedExitCode(verdicts);
    verdict.blocks.emplace_back(report::Paragraph{
        combined == 0 ? "Verdict: pass (exit code 0)." : "Verdict: fail (exit code " + std::to_string(combined) + ")."});
    verdict.blocks.emplace_back(std::move(verdictTable));
    if (!inputs.empty()) {
        // The first input's provenance in short; every input's in full under "Provenance".
        report::KeyValues summary = ProvenanceItems(Obj(inputs.front().doc, "provenance"));
        std::erase_if(summary.items, [](const auto& item) {
            return item.first != "commit" && item.first != "build" && item.first != "machine" && item.first != "date";
        });
        verdict.blocks.emplace_back(std::move(summary));
    }
    out.sections.push_back(std::move(verdict));

    // Conformance: stage x backend.
    for (const ReportInput& input : inputs) {
        if (input.kind != InputKind::Conform) continue;
        std::vector<std::string> stages, backends;
        std::map<std::pair<std::string, std::string>, std::string> status;
        for (const json& r : Arr(input.doc, "results")) {
            const std::string stage = Str(r, "stage"), backend = Str(r, "backend");
            if (std::ranges::find(stages, stage) == stages.end()) stages.push_back(stage);
            if (std::ranges::find(backends, backend) == backends.end()) backends.push_back(backend);
            status[{stage, backend}] = Str(r, "status");
        }
        std::vector<Column> columns = {Column("stage")};
        for (const std::string& b : backends) columns.push_back(Column(b));
        Table matrix(columns);
        for (const std::string& stage : stages) {
            std::vector<Cell> row = {stage};
            for (const std::string& b : backends) {
                auto it = status.find({stage, b});
                row.push_back(it == status.end() ? Cell() : Cell(it->second));
            }
            matrix.rows.push_back(std::move(row));
        }
        out.sections.push_back({"Conformance matrix: " + Str(input.doc, "scene") + " (" + input.path + ")",
                                {report::Paragraph{"Each backend's stages against the CPU's by SPEC's rule, over " +
                                                   Str(input.doc, "steps", "?") +
                                                   " steps; the rule, worst error and place are in the conform "
                                                   "report below."},
                                 std::move(matrix)}});
    }

    // Timing: tables beside the seeds' figures, distributions, frames.
    for (const ReportInput& input : inputs) {
        if (input.kind != InputKind::Results) continue;
        const std::string scene = Str(Obj(input.doc, "scene"), "name");
        Section timing{"Stage times: " + scene + " (" + input.path + ")", {}};
        std::string backends;
        for (const auto& [name, b] : Obj(input.doc, "backends").items())
            backends += (backends.empty() ? "" : "; ") + name + ": " + Str(b, "status") +
                        (Str(b, "device").empty() ? "" : ", " + Str(b, "device")) +
                        (Str(b, "error").empty() ? "" : ", " + Str(b, "error"));
        timing.blocks.emplace_back(report::Paragraph{
            "Median and quartiles of each stage's wall time per call over the steps after warm-up (" +
            Str(Obj(input.doc, "scene"), "steps", "?") + " steps, " +
            Str(Obj(input.doc, "scene"), "warmup_steps", "?") + " warm-up). Backends: " + backends +
            ". The seeds' figures were measured on other hardware and scenes (the thesis's 256x32x256 volume; "
            "seed 001's are whole ray-marched frames): a sense of scale, not a comparison of methods."});
        timing.blocks.emplace_back(TimingTable(input.doc));
        timing.blocks.emplace_back(TimingBoxes(input));
        out.sections.push_back(std::move(timing));
    }

    if (!historyPath.empty()) out.sections.push_back({"History", HistoryBlocks(history, historyPath)});

    for (const ReportInput& input : inputs)
        if (input.kind == InputKind::Accuracy || input.kind == InputKind::Sweep)
            out.sections.push_back({"Accuracy against time: " + Str(input.doc, "scene") + " (" + input.path + ")",
                                    ParetoBlocks(input)});

    for (const ReportInput& input : inputs)
        if (input.kind == InputKind::Results)
            out.sections.push_back(
                {"Frames: " + Str(Obj(input.doc, "scene"), "name") + " (" + input.path + ")", FrameBlocks(input)});

    out.sections.push_back({"The seeds' figures",
                            {report::Paragraph{"From docs/seed-timings.json (the seeds' TABLES.md), with the hardware "
                                               "each was measured on."},
                             SeedSources(), SeedTable()}});

    Section provenance{"Provenance", {}};
    for (const ReportInput& input : inputs) {
        provenance.blocks.emplace_back(report::Paragraph{input.path + " (" + std::string(InputKindName(input.kind)) + ")"});
        provenance.blocks.emplace_back(ProvenanceItems(Obj(input.doc, "provenance")));
    }
    out.sections.push_back(std::move(provenance));

    // Each input's own tables, as its command printed them.
    for (const ReportInput& input : inputs) {
        if (!input.doc.contains("report")) continue;
        const report::Report own = report::ReportFromJson(input.doc["report"]);
        for (const Section& s : own.sections)
            out.sections.push_back(
                {own.title + (s.title.empty() ? "" : ": " + s.title) + " (" + FileName(input.path) + ")", s.blocks});
    }
    return out;
}

}  // namespace cb::html
