// The perf history in `cloudbench report`: reading a history file
// (ReadHistory, harness/report/html/HtmlReport.h) and its plots (HistoryBlocks,
// harness/report/html/ReportSections.h).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>

#include "harness/perf/Stats.h"
#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {
namespace {

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

}  // namespace

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

}  // namespace cb::html
