// `cloudbench perf history` (docs/cli.md, "perf"): finds step changes in each
// stage's time over a history's records, says for each series why it found
// one or none, and what changed in the provenance at each step.
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "core/base/ShownText.h"
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


// A record's time of one stage on `clock`: the median of its runs' median steps ("runs_ms", else
// "samples_ms" as one run), so that one run of three that a load made odd does not move it; NaN when it
// has no samples. `entry` is the record's stage entry.
double HistoryRecordTime(const json& entry, perf::Clock clock) {
    const json& times = clock == perf::Clock::Cpu ? entry.at("cpu") : entry;
    std::vector<double> medians;
    auto add = [&](const json& run) {
        const double median = perf::Median(run.get<std::vector<double>>());
        if (median > 0) medians.push_back(median);  // an empty run, or a zero time, has no ratio
    };
    if (times.contains("runs_ms"))
        for (const json& run : times.at("runs_ms")) add(run);
    else
        add(times.at("samples_ms"));
    return perf::Median(medians);
}

// The first record, and the stage in it, that has wall-time samples without CPU times beside them.
struct HistoryMissingCpu {
    const input::HistoryRecord* record = nullptr;
    std::string where;  // "/results/SCENE/BACKEND/STAGE"
};
std::optional<HistoryMissingCpu> FirstWithoutCpu(const std::vector<input::HistoryRecord>& records) {
    for (const input::HistoryRecord& r : records) {
        const json& results = r.record["results"];
        for (const auto& [scene, backends] : results.items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, entry] : stages.items())
                    if (!entry["samples_ms"].empty() && !entry.contains("cpu"))
                        return HistoryMissingCpu{&r, "/results/" + scene + "/" + backend + "/" + stage};
    }
    return std::nullopt;
}

// The smallest p the permutation test can give for a clean step splitting n records into nL and nR:
// the arrangements with the same values at either end, 2 / C(n, nL) (C(n, nL) when nL = nR, where the
// two ends are the same split).
double HistoryReachableP(size_t nL, size_t nR) {
    const double n = double(nL + nR);
    const double logC = std::lgamma(n + 1) - std::lgamma(double(nL) + 1) - std::lgamma(double(nR) + 1);
    return std::min(1.0, 2 * std::exp(-logC));
}

// The fewest records on each side of a step whose clean split reaches p <= threshold.
size_t HistoryRecordsToReach(double threshold, size_t minSegment) {
    size_t k = std::max<size_t>(minSegment, 1);
    while (HistoryReachableP(k, k) > threshold && k < 100000) ++k;
    return k;
}

}  // namespace

int History(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--metric", "--clock", "--alpha", "--min-change", "--min-segment", "--json"}, {}, a))
        return Usage(*m);
    if (a.positional.size() != 1 || a.positional[0].empty()) return Usage("perf history needs one history FILE");
    const std::string path = a.positional[0];
    const std::string metric = a.Value("--metric", "time");
    if (metric != "time" && metric != "instructions") return Usage("--metric needs time or instructions");
    const std::string clockName = a.Value("--clock");
    if (a.Has("--clock") && clockName != "wall" && clockName != "cpu")
        return Usage("--clock: needs wall or cpu, got '" + ShownArgument(clockName) + "'");
    if (a.Has("--clock") && metric != "time") return Usage("--clock is for --metric time");
    perf::ChangePointSettings settings;
    double minChange = 0.1, alpha = settings.alpha;
    long long minSegment = settings.minSegment;
    if (auto m = NumberOption(a, "--alpha", 1e-12, 1, alpha)) return Usage(*m);
    if (auto m = NumberOption(a, "--min-change", 0, 100, minChange)) return Usage(*m);
    if (auto m = WholeNumberOption(a, "--min-segment", 1, 1000000, minSegment)) return Usage(*m);
    settings.minChange = std::log1p(minChange);
    settings.minSegment = int(minSegment);
    auto records = perf::ReadHistory(path);
    if (!records) {
        std::fprintf(stderr, "%s\n", records.error().message.c_str());
        return kExitBadScene;
    }
    // The clock: CPU time where every record holds it (other jobs on a shared runner do not move it), else
    // wall time; --clock cpu on a record without CPU times is refused, naming it.
    perf::Clock clock = perf::Clock::Wall;
    std::string clockWhy;
    if (metric == "time") {
        const std::optional<HistoryMissingCpu> missing = FirstWithoutCpu(*records);
        if (clockName == "cpu" && missing) {
            std::fprintf(stderr,
                         "%s:%zu: record %s: %s: has no \"cpu\" time (recorded before perf record kept CPU times); "
                         "use --clock wall, or a history of records written since\n",
                         path.c_str(), missing->record->line, missing->record->record.value("id", "?").c_str(),
                         missing->where.c_str());
            return kExitBadScene;
        }
        if (clockName == "cpu" || (clockName.empty() && !missing && !records->empty())) clock = perf::Clock::Cpu;
        if (clockName.empty())
            clockWhy = clock == perf::Clock::Cpu ? "every record holds CPU times"
                       : missing ? "record " + missing->record->record.value("id", "?") + " (line " +
                                       std::to_string(missing->record->line) + ") holds no CPU times"
                                 : "no record";
        else
            clockWhy = "--clock " + clockName;
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
                    if (metric == "time" && entry.is_object() && !entry["samples_ms"].empty())
                        v = HistoryRecordTime(entry, clock);
                    if (v > 0) series[{scene, backend, stage}].emplace_back(i, v);
                }
    }
    // Bonferroni over the series: the chance of a false first change point in any of them is at most alpha.
    // Enough shuffles that a clean step's p lies well below each series' threshold (shuffling stops early
    // where p cannot reach it).
    const size_t family = std::max<size_t>(series.size(), 1);
    settings.alpha = alpha / double(family);
    settings.permutations = int(std::min(1e8, std::max(999.0, std::ceil(10 / settings.alpha) - 1)));
    const std::string thresholdText = Num("%.2g", settings.alpha) + " (--alpha " + Num("%g", alpha) + " over " +
                                      std::to_string(family) + " series)";
    auto recordId = [&](size_t index) { return (*records)[index].record.value("id", "?"); };
    json changes = json::array(), verdicts = json::array();
    std::vector<std::string> advice;
    for (const auto& [key, points] : series) {
        const std::string name = key[0] + "/" + key[1] + "/" + key[2];
        std::vector<double> logs;
        for (const auto& [index, v] : points) logs.push_back(std::log(v));
        const perf::ChangePointSearch search = perf::SearchChangePoints(logs, settings);
        json verdict = {{"scene", key[0]},         {"backend", key[1]},     {"stage", key[2]},
                        {"records", points.size()}, {"p_threshold", settings.alpha}, {"change_points", json::array()}};
        for (size_t at : search.points) {
            // The medians of the segments either side, up to the neighbouring changes.
            std::vector<double> before, after;
            for (size_t k = 0; k < at; ++k) before.push_back(points[k].second);
            for (size_t k = at; k < points.size(); ++k) after.push_back(points[k].second);
            const json& first = (*records)[points[at].first].record;
            const json& last = (*records)[points[at - 1].first].record;
            const double b = perf::Median(before), h = perf::Median(after);
            double p = NAN;
            for (const perf::SegmentTest& t : search.tests)
                if (t.split == at && t.outcome == perf::SegmentTest::Outcome::Change) p = t.p;
            const std::vector<std::string> what =
                ProvenanceChanges(last.value("provenance", json::object()), first.value("provenance", json::object()));
            std::printf("%s: step at record %s (line %zu): %s -> %s (x%.2f, p = %.2g)\n", name.c_str(),
                        first.value("id", "?").c_str(), (*records)[points[at].first].line,
                        Num(metric == "time" ? "%.3f ms" : "%.0f", b).c_str(),
                        Num(metric == "time" ? "%.3f ms" : "%.0f", h).c_str(), h / b, p);
            std::printf("  changed since the record before (%s): %s\n", last.value("id", "?").c_str(),
                        what.empty() ? "nothing in the provenance" : "");
            for (const std::string& w : what) std::printf("    %s\n", w.c_str());
            json change = {{"scene", key[0]},
                           {"backend", key[1]},
                           {"stage", key[2]},
                           {"metric", metric},
                           {"record", first.value("id", "")},
                           {"line", (*records)[points[at].first].line},
                           {"index", points[at].first},
                           {"before", b},
                           {"after", h},
                           {"ratio", h / b},
                           {"p", p},
                           {"provenance_changes", what}};
            changes.push_back(change);
            verdict["change_points"].push_back(change);
        }
        // Why the whole series' search ended as it did: its first test.
        const perf::SegmentTest& top = search.tests.front();
        const size_t n = points.size();
        std::string reason;
        if (!search.points.empty()) {
            verdict["verdict"] = "change";
            reason = std::to_string(search.points.size()) + " change point" + (search.points.size() == 1 ? "" : "s");
            verdict["reason"] = "change";
        } else if (top.outcome == perf::SegmentTest::Outcome::TooShort) {
            verdict["verdict"] = "none";
            verdict["reason"] = "too_few_records";
            reason = std::to_string(n) + " records: a step needs at least " + std::to_string(minSegment) +
                     " on each side (--min-segment); record " + std::to_string(2 * minSegment - static_cast<long long>(n)) +
                     " more";
            advice.push_back(name + ": " + reason);
        } else {
            verdict["verdict"] = "none";
            const size_t nL = top.split - top.begin, nR = top.end - top.split;
            const double reachable = HistoryReachableP(nL, nR);
            verdict["best_split"] = {{"record", recordId(points[top.split].first)},
                                     {"line", (*records)[points[top.split].first].line},
                                     {"index", points[top.split].first},
                                     {"ratio", std::exp(top.change)},
                                     {"p", top.outcome == perf::SegmentTest::Outcome::NotSignificant ? json(top.p)
                                                                                                       : json(nullptr)},
                                     {"reachable_p", reachable}};
            const std::string at = "the best split (" + std::to_string(nL) + " records | " + std::to_string(nR) +
                                   ", at record " + recordId(points[top.split].first) + ") changes the median x" +
                                   Num("%.3f", std::exp(top.change));
            if (top.outcome == perf::SegmentTest::Outcome::BelowMinChange) {
                verdict["reason"] = "below_min_change";
                reason = at + ", less than --min-change " + Num("%g", minChange);
            } else if (reachable > settings.alpha) {
                const size_t need = HistoryRecordsToReach(settings.alpha, size_t(minSegment));
                verdict["reason"] = "cannot_reach";
                verdict["records_needed_each_side"] = need;
                reason = at + "; a clean step between " + std::to_string(nL) + " and " + std::to_string(nR) +
                         " records reaches p = " + Num("%.2g", reachable) + " at best, above " + thresholdText +
                         ": about " + std::to_string(need) +
                         " records on each side are needed (more perf record --repeat makes each record steadier, "
                         "not this p smaller)";
                advice.push_back(name + ": " + reason);
            } else {
                verdict["reason"] = "p_too_large";
                reason = at + ", p = " + Num("%.2g", top.p) + " above " + thresholdText;
            }
        }
        verdict["why"] = reason;
        verdicts.push_back(verdict);
    }
    for (const std::string& line : advice) std::printf("no change point: %s\n", line.c_str());
    std::printf("%zu change point%s in %zu series over %zu records", changes.size(), changes.size() == 1 ? "" : "s",
                series.size(), records->size());
    if (metric == "time") std::printf(" (clock %s: %s)", perf::ClockName(clock), clockWhy.c_str());
    std::printf("; each series tested at p <= %s\n", thresholdText.c_str());
    json doc = {{"format", "cloudbench-perf-history/1"},
                {"history", path},
                {"records", records->size()},
                {"metric", metric},
                {"alpha", alpha},
                {"p_threshold", settings.alpha},
                {"min_change", minChange},
                {"min_segment", minSegment},
                {"change_points", changes},
                {"series", verdicts}};
    if (metric == "time") doc["clock"] = perf::ClockName(clock);
    if (a.Has("--json") && !WriteJsonFile(a.Value("--json"), doc)) return kExitFailed;
    return kExitOk;
}

}  // namespace cb::perf_command
