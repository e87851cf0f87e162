// `cloudbench perf history` (docs/cli.md, "perf"): finds step changes in each
// stage's median over a history's records and what changed in the provenance.
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "harness/commands/PerfCommon.h"
#include "harness/perf/History.h"
#include "harness/perf/Stats.h"

namespace cb::perf_command {
namespace {

// The provenance fields that say what produced a record, flattened: "git.commit", "backends.vk.device", ...
std::map<std::string, std::string> FlatProvenance(const json& p) {
    std::map<std::string, std::string> flat;
    if (!p.is_object()) return flat;
    for (const auto& [key, value] : p.items()) {
        if (key == "date" || key == "command_line" || key == "scene") continue;
        if (key == "backends" && value.is_array()) {
            for (const json& b : value)
                for (const auto& [field, v] : b.items())
                    if (field != "name") flat["backends." + b.value("name", "?") + "." + field] = v.dump();
        } else if (value.is_object()) {
            for (const auto& [field, v] : value.items())
                flat[key + "." + field] = v.is_string() ? v.get<std::string>() : v.dump();
        } else {
            flat[key] = value.dump();
        }
    }
    return flat;
}

std::vector<std::string> ProvenanceChanges(const json& before, const json& after) {
    const auto a = FlatProvenance(before), b = FlatProvenance(after);
    std::set<std::string> keys;
    for (const auto& [k, v] : a) keys.insert(k);
    for (const auto& [k, v] : b) keys.insert(k);
    std::vector<std::string> changes;
    for (const std::string& k : keys) {
        const std::string x = a.count(k) ? a.at(k) : "(none)", y = b.count(k) ? b.at(k) : "(none)";
        if (x != y) changes.push_back(k + ": " + x + " -> " + y);
    }
    return changes;
}

}  // namespace

int History(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--metric", "--min-change", "--min-segment", "--json"}, {}, a)) return Usage(*m);
    if (a.positional.size() != 1 || a.positional[0].empty()) return Usage("perf history needs one history FILE");
    const std::string metric = a.Value("--metric", "time");
    if (metric != "time" && metric != "instructions") return Usage("--metric needs time or instructions");
    perf::ChangePointSettings settings;
    double minChange = 0.1;
    long long minSegment = settings.minSegment;
    if (auto m = NumberOption(a, "--min-change", 0, 100, minChange)) return Usage(*m);
    if (auto m = WholeNumberOption(a, "--min-segment", 1, 1000000, minSegment)) return Usage(*m);
    settings.minChange = std::log1p(minChange);
    settings.minSegment = int(minSegment);
    auto records = perf::ReadHistory(a.positional[0]);
    if (!records) {
        std::fprintf(stderr, "%s\n", records.error().message.c_str());
        return kExitBadScene;
    }
    // Each key's series of (record index, value).
    std::map<std::array<std::string, 3>, std::vector<std::pair<size_t, double>>> series;
    for (size_t i = 0; i < records->size(); ++i) {
        const json& r = (*records)[i].record;
        const json& section = metric == "time" ? r["results"] : r.value("instructions", json::object());
        if (!section.is_object()) continue;
        for (const auto& [scene, backends] : section.items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, entry] : stages.items()) {
                    double v = NAN;
                    if (metric == "instructions" && entry.is_number()) v = entry.get<double>();
                    if (metric == "time" && entry.is_object() && entry.contains("median_ms") &&
                        entry["median_ms"].is_number())
                        v = entry["median_ms"].get<double>();
                    if (v > 0) series[{scene, backend, stage}].emplace_back(i, v);
                }
    }
    json changes = json::array();
    for (const auto& [key, points] : series) {
        std::vector<double> logs;
        for (const auto& [index, v] : points) logs.push_back(std::log(v));
        for (size_t at : perf::ChangePoints(logs, settings)) {
            // The medians of the segments either side, up to the neighbouring changes.
            std::vector<double> before, after;
            for (size_t k = 0; k < at; ++k) before.push_back(points[k].second);
            for (size_t k = at; k < points.size(); ++k) after.push_back(points[k].second);
            const json& first = (*records)[points[at].first].record;
            const json& last = (*records)[points[at - 1].first].record;
            const double b = perf::Median(before), h = perf::Median(after);
            const std::vector<std::string> what =
                ProvenanceChanges(last.value("provenance", json::object()), first.value("provenance", json::object()));
            std::printf("%s/%s/%s: step at record %s (line %zu): %s -> %s (x%.2f)\n", key[0].c_str(), key[1].c_str(),
                        key[2].c_str(), first.value("id", "?").c_str(), (*records)[points[at].first].line,
                        Num(metric == "time" ? "%.3f ms" : "%.0f", b).c_str(),
                        Num(metric == "time" ? "%.3f ms" : "%.0f", h).c_str(), h / b);
            std::printf("  changed since the record before (%s): %s\n", last.value("id", "?").c_str(),
                        what.empty() ? "nothing in the provenance" : "");
            for (const std::string& w : what) std::printf("    %s\n", w.c_str());
            changes.push_back({{"scene", key[0]},
                               {"backend", key[1]},
                               {"stage", key[2]},
                               {"metric", metric},
                               {"record", first.value("id", "")},
                               {"line", (*records)[points[at].first].line},
                               {"index", points[at].first},
                               {"before", b},
                               {"after", h},
                               {"provenance_changes", what}});
        }
    }
    std::printf("%zu change point%s in %zu series over %zu records\n", changes.size(), changes.size() == 1 ? "" : "s",
                series.size(), records->size());
    if (a.Has("--json") && !WriteJsonFile(a.Value("--json"), {{"format", "cloudbench-perf-history/1"},
                                                              {"history", a.positional[0]},
                                                              {"records", records->size()},
                                                              {"metric", metric},
                                                              {"change_points", changes}}))
        return kExitFailed;
    return kExitOk;
}

}  // namespace cb::perf_command
