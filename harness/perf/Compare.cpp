#include "harness/perf/Compare.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "core/base/ShownText.h"
#include "harness/perf/History.h"
#include "harness/report/InputFormats.h"

namespace cb::perf {
namespace {

using nlohmann::json;

// One stage's samples in a history record: "runs_ms" run by run when the
// record has it, otherwise "samples_ms" as one run.
std::vector<RunSamples> RecordRuns(const json& entry) {
    std::vector<RunSamples> runs;
    if (entry.contains("runs_ms")) {
        for (const json& run : entry.at("runs_ms")) runs.push_back({-1, run.get<std::vector<double>>()});
    } else {
        runs.push_back({-1, entry.at("samples_ms").get<std::vector<double>>()});
    }
    return runs;
}

// Adds a record's runs on the side's clock. `name`: "FILE@ID (line L)", for errors.
Status AddRecord(Side& side, const json& record, const std::string& name) {
    try {
        for (const auto& [scene, backends] : record.at("results").items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, entry] : stages.items()) {
                    const bool timed = !entry.at("samples_ms").empty();
                    if (side.clock == Clock::Cpu && timed && !entry.contains("cpu"))
                        return MakeError(name + ": /results/" + scene + "/" + backend + "/" + stage +
                                         ": has no \"cpu\" time (recorded before perf record kept CPU times); "
                                         "compare wall times (--clock wall), or records written since");
                    auto& runs = side.runs[scene][backend][stage];
                    const json& times = side.clock == Clock::Cpu && timed ? entry.at("cpu") : entry;
                    for (RunSamples& run : RecordRuns(times)) runs.push_back(std::move(run));
                }
        if (record.contains("failures"))
            for (const auto& [scene, backends] : record["failures"].items())
                for (const auto& [backend, why] : backends.items())
                    side.failures[scene][backend] = why.get<std::string>();
        if (record.contains("instructions")) CB_TRY(AddInstructions(side, record));
        side.provenance = record.value("provenance", json::object());
        side.date = record.value("time", "");
    } catch (const json::exception& e) {
        return MakeError(name + ": not a valid " + kRecordFormat + " record: " + e.what());
    }
    ++side.records;
    return {};
}

}  // namespace

std::vector<double> Pooled(const std::vector<RunSamples>& runs) {
    std::vector<double> pooled;
    for (const RunSamples& run : runs) pooled.insert(pooled.end(), run.ms.begin(), run.ms.end());
    return pooled;
}

Status AddResults(Side& side, const json& results, int round) {
    if (!results.is_object() || results.value("format", json()) != "cloudbench-results/1")
        return MakeError(side.label + ": not a results.json (format cloudbench-results/1)");
    try {
        const std::string scene = results.at("scene").at("name").get<std::string>();
        for (const auto& [backend, entry] : results.at("backends").items()) {
            const std::string status = entry.value("status", "");
            if (status == "unavailable" || status == "unsupported") continue;  // not measured here: absent
            if (status != "ok") {
                side.failures[scene][backend] =
                    status + (entry.contains("error") ? ": " + entry.value("error", "") : "");
            }
            if (!entry.contains("stages")) continue;
            for (const auto& [stage, stats] : entry["stages"].items()) {
                std::vector<double> samples = stats.at("samples_ms").get<std::vector<double>>();
                if (side.clock == Clock::Cpu && !samples.empty()) {
                    // A stage with wall-time samples has its CPU time beside them, from cloudbench 2026-12 on.
                    if (!stats.contains("cpu"))
                        return MakeError(side.label + ": /backends/" + backend + "/stages/" + stage +
                                         ": has no \"cpu\" time (written before cloudbench measured it); "
                                         "compare wall times (--clock wall) or run it again");
                    samples = stats["cpu"].at("samples_ms").get<std::vector<double>>();
                }
                side.runs[scene][backend][stage].push_back({round, std::move(samples)});
            }
        }
        if (side.provenance.empty() && results.contains("provenance")) {
            side.provenance = results["provenance"];
            side.date = side.provenance.value("date", "");
        }
    } catch (const json::exception& e) {
        return MakeError(side.label + ": not a valid results.json: " + e.what());
    }
    return {};
}

Status AddInstructions(Side& side, const json& doc) {
    try {
        for (const auto& [scene, backends] : doc.at("instructions").items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, count] : stages.items())
                    side.instructions[scene][backend][stage] = count.get<double>();
    } catch (const json::exception& e) {
        return MakeError(side.label + ": \"instructions\" must map scene, backend and stage to a count: " + e.what());
    }
    return {};
}

Result<Side> LoadSide(const std::string& spec, Clock clock) {
    // "FILE@SELECTOR" names a record of a history; a file whose own name holds '@' is taken whole.
    std::string path = spec, selector;
    bool selected = false;
    struct stat st {};
    if (const size_t at = spec.rfind('@'); at != std::string::npos && at > 0 && ::stat(spec.c_str(), &st) != 0) {
        path = spec.substr(0, at);
        selector = spec.substr(at + 1);
        selected = true;
    }
    if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
        if (selected) return MakeError(spec + ": '@' selects a record of a history, and " + path + " is a folder");
        if (::stat((path + "/" + kInterleaveFile).c_str(), &st) == 0)
            return MakeError(path + ": is a kept interleave (it holds " + kInterleaveFile +
                             "); compare it alone: perf compare " + path);
        path += "/results.json";  // the folder a `run --out` wrote
        if (::stat(path.c_str(), &st) != 0)
            return MakeError(spec + ": is a folder without a results.json (a `run --out` folder has one)");
    }
    Side side;
    side.label = spec;
    side.clock = clock;
    // A record alone is read as a history of one (input::ReadDocumentOrHistory).
    static constexpr input::Format kSides[] = {input::Format::Results, input::Format::Count,
                                               input::Format::Instructions};
    auto read = input::ReadDocumentOrHistory(path, kSides);
    if (!read) return std::unexpected(read.error());
    if (auto* one = std::get_if<input::Document>(&*read)) {
        if (selected) return MakeError(spec + ": '@' selects a record of a history, and " + path + " is not one");
        const json& doc = one->doc;
        switch (one->format) {
            case input::Format::Results:
                CB_TRY(AddResults(side, doc));
                break;
            default:  // a count output or an instruction file
                CB_TRY(AddInstructions(side, doc));
                side.provenance = doc.value("provenance", json::object());
                side.date = side.provenance.value("date", "");
                break;
        }
        return side;
    }
    auto& history = std::get<input::History>(*read);
    input::PrintWarnings(history);
    auto chosen = SelectRecords(history.records, path, selected ? selector : "-1");
    if (!chosen) return std::unexpected(chosen.error());
    // One record's runs, or a range's pooled; the side's provenance and date are its last record's.
    const std::string firstId = chosen->front()->record.value("id", "?");
    const std::string lastId = chosen->back()->record.value("id", "?");
    side.label = path + "@" + firstId + (chosen->size() > 1 ? ":" + lastId : "");
    for (const HistoryRecord* r : *chosen)
        CB_TRY(AddRecord(side, r->record,
                         path + "@" + r->record.value("id", "?") + " (line " + std::to_string(r->line) + ")"));
    return side;
}

Result<KeptInterleave> LoadInterleave(const std::string& folder, Clock clock) {
    const std::string manifestPath = folder + "/" + kInterleaveFile;
    if (struct stat st{}; ::lstat(manifestPath.c_str(), &st) != 0 && errno == ENOENT)
        return MakeError(folder + ": not a kept interleave (it has no " + kInterleaveFile +
                         "); perf compare takes BASE and HEAD, or a folder that --interleave --keep wrote");
    static constexpr input::Format kManifest[] = {input::Format::Interleave};
    auto manifest = input::ReadCloudbenchFileBeneath(folder, kInterleaveFile, kManifest);
    if (!manifest) return std::unexpected(manifest.error());
    const json& doc = manifest->doc;
    // The live command writes the file after each run: a file without one was not written by it.
    if (doc["runs"].empty()) return MakeError(manifestPath + ": /runs: no run was recorded; nothing to compare");
    KeptInterleave kept;
    std::array<Side, 2>& sides = kept.sides;
    sides[0].label = doc["base"].get<std::string>() + " (BASE)";
    sides[1].label = doc["head"].get<std::string>() + " (HEAD)";
    for (Side& side : sides) side.clock = clock;
    kept.order = doc.value("order", "ABBA");
    if (doc.contains("plant"))
        kept.plant = PlantedSlowdown{doc["plant"]["stage"].get<std::string>(), doc["plant"]["factor"].get<double>()};
    kept.recordedRuns = doc["runs"].size();
    kept.plannedRuns = doc["rounds"].get<size_t>() * doc["scenes"].size() * 2;
    for (size_t n = 0; n < doc["runs"].size(); ++n) {
        const json& run = doc["runs"][n];
        const std::string side = run["side"].get<std::string>(), name = run["folder"].get<std::string>();
        const int round = run["round"].get<int>(), exit = run.value("exit", 0);
        kept.rounds = std::max(kept.rounds, round + 1);
        if (run.contains("load") && !run["load"].empty())
            kept.peakLoad = std::max(kept.peakLoad, run["load"][0].get<double>());
        // A run's folder is its side's, one name deep: nothing outside the kept folder is read.
        const std::string prefix = side + "/", leaf = name.substr(std::min(name.size(), prefix.size()));
        if (name.rfind(prefix, 0) != 0 || leaf.empty() || leaf[0] == '.' || leaf.find('/') != std::string::npos)
            return MakeError(manifestPath + ": /runs/" + std::to_string(n) + "/folder: must be " + prefix +
                             "NAME, got '" + ShownText(name, false, 200) + "'");
        FailedRun failed{side, run["scene"].get<std::string>(), round, exit, false};
        static constexpr input::Format kResults[] = {input::Format::Results};
        // Beneath the kept folder (core/base/PathPolicy.h): a run's folder linked out of it is refused.
        auto results = input::ReadCloudbenchFileBeneath(folder, name + "/results.json", kResults);
        if (!results) {
            // A failed run may have written nothing; one that exited 0 wrote its results, so their loss is damage.
            if (exit == 0) return std::unexpected(results.error());
            kept.failedRuns.push_back(std::move(failed));
            continue;
        }
        CB_TRY(AddResults(sides[side == "head"], results->doc, round));
        if (exit != 0) {
            failed.compared = true;
            kept.failedRuns.push_back(std::move(failed));
        }
    }
    return kept;
}

std::string DescribeFailedRun(const FailedRun& run) {
    return run.side + " run of " + ShownText(run.scene, false, 200) + " in round " + std::to_string(run.round + 1) +
           " exited " + std::to_string(run.exit) + (run.compared ? "" : " and wrote no valid results.json");
}

namespace {
std::string General(double v);
template <typename T>
const T* Find(const ByStage<T>& map, const std::string& scene, const std::string& backend, const std::string& stage);
}  // namespace

json RecordSections(const Side& side, const Side& cpu) {
    json results = json::object(), failures = json::object(), instructions = json::object();
    auto times = [](const std::vector<RunSamples>& runs) {
        const std::vector<double> samples = Pooled(runs);
        json entry = {{"samples_ms", samples}, {"median_ms", Median(samples)}};
        if (runs.size() > 1) {
            entry["runs_ms"] = json::array();
            for (const RunSamples& run : runs) entry["runs_ms"].push_back(run.ms);
        }
        return entry;
    };
    for (const auto& [scene, backends] : side.runs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, runs] : stages) {
                json& entry = results[scene][backend][stage];
                entry = times(runs);
                const std::vector<RunSamples>* onCpu = Find(cpu.runs, scene, backend, stage);
                if (onCpu && onCpu->size() == runs.size() && !entry["samples_ms"].empty()) entry["cpu"] = times(*onCpu);
            }
    for (const auto& [scene, backends] : side.failures)
        for (const auto& [backend, why] : backends) failures[scene][backend] = why;
    for (const auto& [scene, backends] : side.instructions)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, count] : stages) instructions[scene][backend][stage] = count;
    return {{"results", results}, {"failures", failures}, {"instructions", instructions}};
}

size_t CompareOutcome::Regressions() const {
    return size_t(std::count_if(rows.begin(), rows.end(), [](const Comparison& c) { return c.regression; }));
}

namespace {

// Why `side` has no samples for scene/backend, or "" when it has them.
std::string Failure(const Side& side, const std::string& scene, const std::string& backend) {
    if (auto s = side.failures.find(scene); s != side.failures.end())
        if (auto b = s->second.find(backend); b != s->second.end()) return b->second;
    return "";
}

template <typename T>
const T* Find(const ByStage<T>& map, const std::string& scene, const std::string& backend, const std::string& stage) {
    auto s = map.find(scene);
    if (s == map.end()) return nullptr;
    auto b = s->second.find(backend);
    if (b == s->second.end()) return nullptr;
    auto t = b->second.find(stage);
    return t == b->second.end() ? nullptr : &t->second;
}

// Every key of either map, in order.
template <typename T>
std::vector<std::array<std::string, 3>> Keys(const ByStage<T>& a, const ByStage<T>& b) {
    std::vector<std::array<std::string, 3>> keys;
    for (const ByStage<T>* map : {&a, &b})
        for (const auto& [scene, backends] : *map)
            for (const auto& [backend, stages] : backends)
                for (const auto& [stage, unused] : stages) keys.push_back({scene, backend, stage});
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    return keys;
}

}  // namespace

double ThresholdOf(const CompareSettings& s, const std::string& backend) {
    auto own = s.backendThreshold.find(backend);
    const double threshold = own == s.backendThreshold.end() ? s.threshold : own->second;
    return s.interleaved ? threshold : std::max(threshold, s.separateThreshold);
}

std::string UnjudgedAdvice(const Side& base, const Side& head, const CompareSettings& s, const CompareOutcome& outcome) {
    if (s.interleaved) return "more rounds (--rounds) or more samples a run make them testable";
    if (!base.records && !head.records)
        return "one run a side needs at least " + std::to_string(s.minSamples) +
               " steps after warm-up; run with more steps, or compare interleaved runs (perf compare --interleave)";
    size_t family = 0, runs = 0, records = 0;
    for (const Comparison& c : outcome.rows)
        if (c.metric == "time" && !std::isnan(c.pSlower)) {
            ++family;
            runs = std::max({runs, c.baseRuns, c.headRuns});
        }
    for (const Side* side : {&base, &head}) records = std::max(records, side->records);
    const size_t needed = RunsToJudge(family, s);
    if (needed == 0)
        return "no number of runs reaches Holm-adjusted p < " + General(s.alpha) + " over " + std::to_string(family) +
               " tests with " + std::to_string(s.permutations) + " permutations; raise --alpha";
    // The runs a record holds: its --repeat.
    const size_t perRecord = std::max<size_t>(1, records ? runs / records : 1);
    const size_t k = (needed + perRecord - 1) / perRecord;
    return "over " + std::to_string(family) + " tests, " + std::to_string(needed) +
           " runs a side can reach Holm-adjusted p < " + General(s.alpha) + ": compare " + std::to_string(k) +
           " records of perf record --repeat " + std::to_string(perRecord) + " a side (FILE@-" + std::to_string(2 * k) +
           ":-" + std::to_string(k + 1) + " against FILE@-" + std::to_string(k) + ":-1 pools their runs), or record with --repeat " +
           std::to_string(needed);
}

size_t RunsToJudge(size_t comparisons, const CompareSettings& s) {
    const double family = double(std::max<size_t>(comparisons, 1));
    if (family / double(s.permutations + 1) >= s.alpha) return 0;
    size_t runs = 1;
    while (family * SmallestPermutationP(runs, runs, s.permutations) >= s.alpha) ++runs;
    return runs;
}

namespace {

// The statistic of each run's steps, as logs, for the runs that have steps.
std::vector<std::pair<int, double>> RunLogs(const std::vector<RunSamples>& runs, double quantile) {
    std::vector<std::pair<int, double>> logs;
    for (const RunSamples& run : runs) {
        const double v = Quantile(run.ms, quantile);
        if (run.ms.empty() || !(v > 0)) continue;  // a zero time has no ratio
        logs.emplace_back(run.round, std::log(v));
    }
    return logs;
}

// `v` as printf's %g.
std::string General(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

double MeanOf(const std::vector<double>& v) {
    return v.empty() ? NAN : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
}

// Fills c's test of time from the runs of both sides: pSlower, pFaster, the
// ratio, its interval and `test`; returns the smallest p the test could give
// (1 when it cannot test). Rows whose sides are single runs test the steps.
double TestTime(Comparison& c, const std::vector<RunSamples>& baseRuns, const std::vector<RunSamples>& headRuns,
                const CompareSettings& s) {
    const auto b = RunLogs(baseRuns, s.runQuantile), h = RunLogs(headRuns, s.runQuantile);
    c.baseRuns = b.size(), c.headRuns = h.size();
    std::vector<double> bl, hl;
    for (const auto& [round, v] : b) bl.push_back(v);
    for (const auto& [round, v] : h) hl.push_back(v);
    c.baseMedian = std::exp(MeanOf(bl)), c.headMedian = std::exp(MeanOf(hl));
    // Interleaved: the rounds both sides ran in, each a pair.
    std::vector<double> d;
    if (s.interleaved)
        for (const auto& [round, hv] : h)
            if (round >= 0)
                for (const auto& [baseRound, bv] : b)
                    if (baseRound == round) d.push_back(hv - bv);
    if (!d.empty()) {
        c.test = "rounds";
        c.pairs = d.size();
        c.ratio = std::exp(MeanOf(d));
        c.interval = BootstrapExpMean(d, s.confidence, s.resamples, s.seed);
        std::vector<double> negated(d.size());
        std::transform(d.begin(), d.end(), negated.begin(), [](double v) { return -v; });
        c.pSlower = SignFlipGreater(d, s.permutations, s.seed);
        c.pFaster = SignFlipGreater(negated, s.permutations, s.seed);
        return SmallestSignFlipP(d.size(), s.permutations);
    }
    if (bl.size() > 1 || hl.size() > 1) {
        c.test = "runs";
        c.ratio = c.headMedian / c.baseMedian;
        c.pSlower = PermutationGreater(hl, bl, s.permutations, s.seed);
        c.pFaster = PermutationGreater(bl, hl, s.permutations, s.seed);
        return SmallestPermutationP(hl.size(), bl.size(), s.permutations);
    }
    // One run a side: its steps, as if independent.
    c.test = "steps";
    const std::vector<double> bs = Pooled(baseRuns), hs = Pooled(headRuns);
    c.baseMedian = Median(bs), c.headMedian = Median(hs), c.ratio = c.headMedian / c.baseMedian;
    if (bs.size() < s.minSamples || hs.size() < s.minSamples) return 1;
    c.interval = BootstrapRatioOfMedians(bs, hs, s.confidence, s.resamples, s.seed);
    c.pSlower = MannWhitneyGreater(hs, bs).p;
    c.pFaster = MannWhitneyGreater(bs, hs).p;
    return 0;
}

}  // namespace

size_t CompareOutcome::Unjudged() const {
    return size_t(std::count_if(rows.begin(), rows.end(), [](const Comparison& c) { return c.mark == '?'; }));
}

CompareOutcome Compare(const Side& base, const Side& head, const CompareSettings& s) {
    CompareOutcome out;
    out.separate = !s.interleaved;
    out.threshold = ThresholdOf(s, "");
    std::vector<size_t> tested;     // rows with a test, for Holm's correction
    std::vector<double> smallestP;  // the smallest p each tested row's test can give
    for (const auto& [scene, backend, stage] : Keys(base.runs, head.runs)) {
        Comparison c;
        c.scene = scene, c.backend = backend, c.stage = stage, c.metric = "time";
        const std::vector<RunSamples>* b = Find(base.runs, scene, backend, stage);
        const std::vector<RunSamples>* h = Find(head.runs, scene, backend, stage);
        if (b) c.baseCount = Pooled(*b).size();
        if (h) c.headCount = Pooled(*h).size();
        const std::string headFailure = Failure(head, scene, backend);
        // A stage timed in neither build (it ran in warm-up steps only, as a static volume formed once) is no
        // comparison, and no failure of HEAD's.
        if (!c.baseCount && !c.headCount && headFailure.empty()) continue;
        if (!headFailure.empty() || !c.headCount) {
            c.mark = 'x';
            c.note = headFailure.empty() ? "no samples in HEAD" : "HEAD: " + headFailure;
            if (c.baseCount) c.baseMedian = Median(Pooled(*b));
        } else if (!c.baseCount) {
            c.mark = '!';
            c.note = "new: no samples in BASE";
            c.headMedian = Median(Pooled(*h));
        } else if (const double smallest = TestTime(c, *b, *h, s); std::isnan(c.pSlower)) {
            c.mark = '?';
            c.note = "cannot judge: one run a side with fewer than " + std::to_string(s.minSamples) + " samples";
        } else {
            tested.push_back(out.rows.size());
            smallestP.push_back(smallest);
        }
        out.rows.push_back(c);
    }
    std::vector<double> slower, faster;
    for (size_t i : tested) slower.push_back(out.rows[i].pSlower), faster.push_back(out.rows[i].pFaster);
    // A row whose test cannot reach alpha after Holm's correction (its smallest p times the number of
    // tests) cannot be judged, and says so; it still counts in the correction of the others. A row with
    // no test at all is not one of the family.
    const size_t family = tested.size();
    const std::vector<double> slowerHolm = HolmAdjusted(slower), fasterHolm = HolmAdjusted(faster);
    for (size_t n = 0; n < tested.size(); ++n) {
        Comparison& c = out.rows[tested[n]];
        c.threshold = ThresholdOf(s, c.backend);
        if (smallestP[n] * double(family) >= s.alpha) {
            c.mark = '?';
            c.note = c.test == "rounds"
                         ? "cannot judge: " + std::to_string(c.pairs) + " rounds cannot reach Holm-adjusted p < " +
                               General(s.alpha) + " over " + std::to_string(family) + " tests"
                         : "cannot judge: " + std::to_string(c.baseRuns) + " and " + std::to_string(c.headRuns) +
                               " runs cannot reach Holm-adjusted p < " + General(s.alpha) + " over " +
                               std::to_string(family) + " tests";
            continue;
        }
        c.pSlowerHolm = slowerHolm[n];
        c.pFasterHolm = fasterHolm[n];
        const bool slowerSignificant = c.pSlowerHolm < s.alpha, fasterSignificant = c.pFasterHolm < s.alpha;
        // Only the step test has an absolute floor: with runs as the samples, the ratio decides.
        const double difference = c.headMedian - c.baseMedian;
        const double floor = c.test == "steps" ? s.floorMs : 0;
        if (slowerSignificant && c.ratio > c.threshold && difference > floor) {
            c.mark = '+';
            c.regression = true;
            c.note = "regression";
        } else if (fasterSignificant && c.ratio < 1 / c.threshold && -difference > floor) {
            c.mark = '-';
            c.note = "improvement";
        } else if (slowerSignificant || fasterSignificant) {
            c.note =
                std::abs(difference) <= floor ? "significant, under the floor" : "significant, within the threshold";
        } else {
            c.note = "not significant";
        }
    }
    // Instruction counts are exact: a change beyond the threshold is a change, no test needed. A side
    // without any counts (no `count` run) is not compared.
    if (base.instructions.empty() || head.instructions.empty()) {
        out.headFailed =
            std::any_of(out.rows.begin(), out.rows.end(), [](const Comparison& c) { return c.mark == 'x'; });
        return out;
    }
    for (const auto& [scene, backend, stage] : Keys(base.instructions, head.instructions)) {
        Comparison c;
        c.scene = scene, c.backend = backend, c.stage = stage, c.metric = "instructions";
        const double* b = Find(base.instructions, scene, backend, stage);
        const double* h = Find(head.instructions, scene, backend, stage);
        if (b) c.baseCount = 1, c.baseMedian = *b;
        if (h) c.headCount = 1, c.headMedian = *h;
        if (!h) {
            c.mark = 'x';
            c.note = "no count in HEAD";
        } else if (!b) {
            c.mark = '!';
            c.note = "new: no count in BASE";
        } else {
            c.ratio = *b > 0 ? *h / *b : (*h > 0 ? INFINITY : 1.0);
            c.threshold = 1 + s.instructionThreshold;
            if (c.ratio > 1 + s.instructionThreshold) {
                c.mark = '+';
                c.regression = true;
                c.note = "regression";
            } else if (c.ratio < 1 / (1 + s.instructionThreshold)) {
                c.mark = '-';
                c.note = "improvement";
            } else {
                c.note = c.ratio == 1 ? "same count" : "within the threshold";
            }
        }
        out.rows.push_back(c);
    }
    out.headFailed = std::any_of(out.rows.begin(), out.rows.end(), [](const Comparison& c) { return c.mark == 'x'; });
    return out;
}

}  // namespace cb::perf
