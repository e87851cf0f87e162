// `cloudbench perf compare` (docs/cli.md, "perf"): compares two result files,
// two records, or interleaved runs of two binaries (each a child `cloudbench
// run`), prints the comparison with its regression verdict and writes --json.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <random>
#include <thread>
#include <tuple>

#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"
#include "core/scene/Stage.h"
#include "harness/commands/PerfCommon.h"
#include "harness/platform/OutputFolder.h"
#include "harness/report/JUnit.h"
#include "harness/report/ReportModel.h"
#include "harness/run/Session.h"

namespace cb::perf_command {
namespace {

// The most rounds --rounds takes (each round is two runs a scene).
constexpr long long kMaxRounds = 1000;

std::string SideSummary(const perf::Side& side) {
    std::string text = side.label;
    const json& p = side.provenance;
    std::string commit = p.is_object() && p.contains("git") ? p["git"].value("commit", "") : "";
    if (commit.size() > 10) commit.resize(10);
    if (!side.date.empty() || !commit.empty()) text += " (" + side.date + (commit.empty() ? "" : ", " + commit) + ")";
    return text;
}

// "median" for 0.5, "25th percentile" otherwise.
std::string RunStatisticName(double quantile) {
    return quantile == 0.5 ? "median" : Num("%g", quantile * 100) + "th percentile";
}

// What a row's test drew on: "8 rounds", "5+5 runs", "100+100 steps".
std::string TestedOn(const perf::Comparison& c) {
    if (c.test == "rounds") return std::to_string(c.pairs) + (c.pairs == 1 ? " round" : " rounds");
    if (c.test == "runs") return std::to_string(c.baseRuns) + "+" + std::to_string(c.headRuns) + " runs";
    if (c.test == "steps") return std::to_string(c.baseCount) + "+" + std::to_string(c.headCount) + " steps";
    return "";
}

json ComparisonJson(const perf::Comparison& c) {
    auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    return {{"scene", c.scene},
            {"backend", c.backend},
            {"stage", c.stage},
            {"metric", c.metric},
            {"test", c.test},
            {"base_runs", c.baseRuns},
            {"head_runs", c.headRuns},
            {"pairs", c.pairs},
            {"base_count", c.baseCount},
            {"head_count", c.headCount},
            {"base_median", number(c.baseMedian)},
            {"head_median", number(c.headMedian)},
            {"ratio", number(c.ratio)},
            {"threshold", number(c.threshold)},
            {"ratio_ci", {number(c.interval.low), number(c.interval.high)}},
            {"p_slower", number(c.pSlower)},
            {"p_faster", number(c.pFaster)},
            {"p_slower_holm", number(c.pSlowerHolm)},
            {"p_faster_holm", number(c.pFasterHolm)},
            {"mark", std::string(1, c.mark)},
            {"regression", c.regression},
            {"note", c.note}};
}

// What an interleave (live or kept) adds to the verdict: the runs that failed, and whether fewer runs
// were recorded than planned (a kept interleave cut short). Either makes a verdict without a regression exit 1.
// The planted slowdown, if any, is shown in the header and the JSON.
struct RunProblems {
    std::vector<perf::FailedRun> failedRuns;
    std::string cutShort;  // why the runs are fewer than planned; "" when they are all there
    std::optional<perf::PlantedSlowdown> plant;
};

// "region x2 in HEAD (...)": how --plant ran the two sides.
std::string PlantSummary(const perf::PlantedSlowdown& plant) {
    return plant.stage + " x" + Num("%g", plant.factor) + " in HEAD, " + plant.stage +
           " x1 in BASE (the control), through CLOUDBENCH_TEST_SLOWDOWN";
}

json FailedRunJson(const perf::FailedRun& run) {
    return {
        {"side", run.side}, {"scene", run.scene}, {"round", run.round}, {"exit", run.exit}, {"compared", run.compared}};
}

// --junit: a test case per comparison (SCENE.BACKEND, the stage; "STAGE instructions" for a count): a regression
// is a failure naming the ratio, its interval, the threshold and the adjusted p, a row that cannot be judged ('?')
// is skipped with the note, a stage that failed or is missing in HEAD ('x') is an error.
std::string CompareJUnit(const perf::CompareOutcome& outcome, const std::string& base, const std::string& head) {
    std::vector<JUnitCase> cases;
    char text[256];
    for (const perf::Comparison& c : outcome.rows) {
        JUnitCase j{c.scene + "." + c.backend, c.stage + (c.metric == "time" ? "" : " " + c.metric)};
        if (c.regression) {
            std::snprintf(text, sizeof text,
                          "%s slower: ratio %.4g (95 %% interval %.4g to %.4g) above the threshold %.4g, Holm p %.3g",
                          c.metric == "time" ? "HEAD is" : "HEAD's count is", c.ratio, c.interval.low, c.interval.high,
                          c.threshold, c.pSlowerHolm);
            j.result = JUnitCase::Result::Failure;
            j.type = "regression";
            j.message = text;
            j.text = c.note;
        } else if (c.mark == '?') {
            j.result = JUnitCase::Result::Skipped;
            j.message = "cannot be judged: " + c.note;
        } else if (c.mark == 'x') {
            j.result = JUnitCase::Result::Error;
            j.type = "head-failed";
            j.message = c.note.empty() ? "failed or missing in HEAD" : c.note;
        }
        cases.push_back(std::move(j));
    }
    return JUnitXml("cloudbench perf compare", "perf compare " + base + " -> " + head, cases);
}

// Prints the comparison, writes the JSON to each of `jsonPaths` (--json, a kept folder's compare.json), returns
// the exit code: 6 for a regression, else 1 when HEAD failed, a run failed or the runs were cut short, else 0.
// Each failed run gets a line on stderr.
int PrintComparison(const perf::Side& base, const perf::Side& head, const perf::CompareSettings& settings,
                    const std::string& mode, const std::vector<std::string>& jsonPaths, const std::string& junitPath,
                    const RunProblems& problems = {}) {
    const perf::CompareOutcome outcome = perf::Compare(base, head, settings);
    report::Report rep("perf compare");
    report::Section section;
    section.title = "";
    report::KeyValues header;
    header.items = {
        {"BASE", SideSummary(base)},
        {"HEAD", SideSummary(head)},
        {"mode", mode},
        {"clock", head.clock == perf::Clock::Cpu ? "cpu (the process's CPU time over each stage's calls)" : "wall"}};
    if (problems.plant) header.items.push_back({"planted", PlantSummary(*problems.plant)});
    if (outcome.separate)
        header.items.push_back(
            {"note", "BASE and HEAD were measured at different times, not interleaved: the wider threshold " +
                         Num("%gx", outcome.threshold) + " applies"});
    std::string own;
    for (const auto& [backend, unused] : settings.backendThreshold)
        own += ", " + backend + " " + Num("%gx", perf::ThresholdOf(settings, backend));
    header.items.push_back({"gate", "+ when slower by more than " + Num("%gx", outcome.threshold) + own +
                                        ", Holm-adjusted p < " + Num("%g", settings.alpha) + " over runs (each run's " +
                                        RunStatisticName(settings.runQuantile) +
                                        " step; interleaved runs paired by round); one run a side: its steps, and " +
                                        Num("%g ms", settings.floorMs) + "; instructions: more than " +
                                        Num("%g %%", settings.instructionThreshold * 100)});
    section.blocks.push_back(header);
    report::Table table({report::Column(""), report::Column("scene"), report::Column("backend"),
                         report::Column("stage"), report::Column("base"), report::Column("head"),
                         report::Column("ratio").AlignRight(), report::Column("95% CI"), report::Column("tested on"),
                         report::Column("p slower (Holm)").AlignRight(), report::Column("note")});
    for (const perf::Comparison& c : outcome.rows) {
        const bool time = c.metric == "time";
        const char* f = time ? "%.3f ms" : "%.0f";
        table.rows.push_back(
            {std::string(1, c.mark), c.scene, c.backend, c.stage + (time ? "" : " (instructions)"),
             Num(f, c.baseMedian), Num(f, c.headMedian), Num("%.3f", c.ratio),
             std::isnan(c.interval.low) ? "" : Num("%.3f", c.interval.low) + "-" + Num("%.3f", c.interval.high),
             TestedOn(c), Num("%.2g", c.pSlowerHolm), c.note});
    }
    section.blocks.push_back(table);
    rep.sections.push_back(section);
    std::printf("%s", report::RenderText(section).c_str());
    int code = kExitOk;
    if (outcome.Regressions()) {
        code = kExitRegression;
        std::printf("regression:");
        for (const perf::Comparison& c : outcome.rows)
            if (c.regression)
                std::printf(" %s/%s/%s%s (x%.2f)", c.scene.c_str(), c.backend.c_str(), c.stage.c_str(),
                            c.metric == "time" ? "" : " instructions", c.ratio);
        std::printf("\n");
    } else if (outcome.headFailed) {
        code = kExitFailed;
        std::printf("no regression, but HEAD failed or lacks a measurement (marked x)\n");
    } else if (const size_t failed = problems.failedRuns.size()) {
        code = kExitFailed;
        std::printf("no regression, but %zu %s failed (named on standard error)\n", failed,
                    failed == 1 ? "run" : "runs");
    } else if (!problems.cutShort.empty()) {
        code = kExitFailed;
        std::printf("no regression in what was measured, but %s\n", problems.cutShort.c_str());
    } else {
        std::printf("no regression\n");
    }
    std::fflush(stdout);
    for (const perf::FailedRun& run : problems.failedRuns)
        std::fprintf(stderr, "perf compare: failed run: %s\n", perf::DescribeFailedRun(run).c_str());
    if (!problems.cutShort.empty()) std::fprintf(stderr, "perf compare: %s\n", problems.cutShort.c_str());
    if (const size_t unjudged = outcome.Unjudged()) {
        std::printf("warning: %zu of %zu time comparisons could not be judged (marked ?):", unjudged,
                    size_t(std::count_if(outcome.rows.begin(), outcome.rows.end(),
                                         [](const perf::Comparison& c) { return c.metric == "time"; })));
        for (const perf::Comparison& c : outcome.rows)
            if (c.mark == '?') std::printf(" %s/%s/%s", c.scene.c_str(), c.backend.c_str(), c.stage.c_str());
        std::printf("; %s\n", perf::UnjudgedAdvice(base, head, settings, outcome).c_str());
    }
    if (!jsonPaths.empty()) {
        json doc = {{"format", "cloudbench-perf-compare/1"},
                    {"base", {{"label", base.label}, {"date", base.date}, {"provenance", base.provenance}}},
                    {"head", {{"label", head.label}, {"date", head.date}, {"provenance", head.provenance}}},
                    {"mode", mode},
                    {"clock", perf::ClockName(head.clock)},
                    {"separate", outcome.separate},
                    {"threshold", outcome.threshold},
                    {"backend_thresholds", json::object()},
                    {"floor_ms", settings.floorMs},
                    {"alpha", settings.alpha},
                    {"instruction_threshold", settings.instructionThreshold},
                    {"comparisons", json::array()},
                    {"run_statistic", RunStatisticName(settings.runQuantile)},
                    {"regressions", outcome.Regressions()},
                    {"unjudged", json::array()},
                    {"failed_runs", json::array()},
                    {"cut_short", problems.cutShort},
                    {"exit_code", code},
                    {"report", report::RenderJson(rep)}};
        for (const perf::Comparison& c : outcome.rows) {
            doc["comparisons"].push_back(ComparisonJson(c));
            if (c.mark == '?') doc["unjudged"].push_back(c.scene + "/" + c.backend + "/" + c.stage);
        }
        for (const auto& [backend, unused] : settings.backendThreshold)
            doc["backend_thresholds"][backend] = perf::ThresholdOf(settings, backend);
        for (const perf::FailedRun& run : problems.failedRuns) doc["failed_runs"].push_back(FailedRunJson(run));
        if (problems.plant) doc["plant"] = {{"stage", problems.plant->stage}, {"factor", problems.plant->factor}};
        for (const std::string& path : jsonPaths)
            if (!WriteJsonFile(path, doc) && code == kExitOk) code = kExitFailed;
    }
    if (!junitPath.empty()) {
        if (Status s = Session::WriteText(junitPath, CompareJUnit(outcome, base.label, head.label)); !s) {
            std::fprintf(stderr, "%s\n", s.error().message.c_str());
            if (code == kExitOk) code = kExitFailed;
        }
    }
    return code;
}

// The order of a round's two runs: a fair coin of its own for every round and scene, so that with no
// change each round's log-ratio has either sign with probability 1/2 whatever the machine does, which
// is what the sign-flip test assumes. A fixed order cannot promise that: ABBA puts one side's runs next
// to each other at every round's end, and a load that lasts two runs then moves two rounds' ratios
// alike (docs/performance.md, "Why the order is drawn").
class PairOrder {
public:
    PairOrder() : coin_(std::random_device{}()) {}
    std::array<int, 2> Next() { return coin_() & 1 ? std::array{1, 0} : std::array{0, 1}; }

private:
    std::mt19937 coin_;
};

// order: the manifest's "order": "random" (drawn a round at a time) or "ABBA" (kept by earlier versions).
std::string InterleavedMode(int rounds, const std::string& order) {
    return "interleaved (" + std::string(order == "random" ? "random order" : order) + "), " +
           std::to_string(rounds) + (rounds == 1 ? " round" : " rounds");
}

// "r03-thesis-low": the round (1-based) and the scene's file stem, kept to a plain name.
std::string KeptRunName(int round, const std::string& scene) {
    std::string stem = std::filesystem::path(scene).stem().string(), name;
    for (char c : stem) name += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "r%02d-", round + 1);
    return prefix + name;
}

// The 1, 5 and 15 minute load averages (/proc/loadavg); empty where there is none.
json LoadAverage() {
    double load[3];
    if (::getloadavg(load, 3) != 3) return json::array();
    return {std::round(load[0] * 100) / 100, std::round(load[1] * 100) / 100, std::round(load[2] * 100) / 100};
}

// On the wall clock, a warning when a run started with more jobs ready to run
// than the machine has cores: the CPU backend's wall times then follow the
// other jobs (a stage gets one core or two), and CPU time does not.
void WarnIfLoaded(double peakLoad, perf::Clock clock) {
    const unsigned cores = std::thread::hardware_concurrency();
    if (clock != perf::Clock::Wall || cores == 0 || peakLoad <= double(cores)) return;
    std::printf(
        "warning: the machine was loaded (1-minute load average up to %.2f on %u cores): wall times "
        "follow the other jobs; on a shared machine compare CPU time (--clock cpu)\n",
        peakLoad, cores);
}

// --keep's folder: created (with its parents) when missing, claimed like any
// output folder, and its base/ and head/ made inside it without following links.
Status ClaimKeptFolder(const std::string& folder) {
    if (auto made = OpenFolderForWriting(folder, true); !made) return std::unexpected(made.error());
    CB_TRY(ClaimOutputFolder(folder, "perf compare"));
    for (const char* side : {"/base", "/head"})
        if (auto made = OpenFolderForWriting(folder + side, true); !made) return std::unexpected(made.error());
    return {};
}

bool SameFile(const std::string& a, const std::string& b) {
    std::error_code ec;
    return std::filesystem::equivalent(a, b, ec);
}

// The rounds at which a sign-flip test over the rounds still reaches alpha,
// after Holm over every time comparison the first round found, for a
// slowdown with two rounds against it: the smallest K with
// (comparisons) x (1 + K + K (K - 1) / 2) x 2^-K < alpha. With at most two
// discordant rounds, each no larger than any two concordant ones together,
// the sign patterns that sum to as much as the observed one flip at most two
// rounds: at most 1 + K + K (K - 1) / 2 of the 2^K. One round against it
// (K + 1 patterns) was not enough margin on a loaded 2-core runner
// (docs/performance.md, "The regression gate").
int RoundsToJudge(const perf::Side& base, const perf::Side& head, double alpha) {
    size_t comparisons = 0;
    for (const auto& [scene, backends] : head.runs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, runs] : stages)
                if (auto s = base.runs.find(scene); s != base.runs.end())
                    if (auto b = s->second.find(backend); b != s->second.end() && b->second.count(stage)) ++comparisons;
    int rounds = 1;
    auto patterns = [](int k) { return 1.0 + k + k * (k - 1) / 2.0; };
    while (double(std::max<size_t>(comparisons, 1)) * patterns(rounds) * std::ldexp(1.0, -rounds) >= alpha) ++rounds;
    return rounds;
}

// --json's path, if given, and `more` (a kept folder's compare.json).
std::vector<std::string> JsonPaths(const std::string& jsonPath, const std::string& more = "") {
    std::vector<std::string> paths;
    for (const std::string& path : {jsonPath, more})
        if (!path.empty()) paths.push_back(path);
    return paths;
}

// --plant STAGE:FACTOR: a stage of core/scene/Stage.h and a factor in [1, 1000] as CLOUDBENCH_TEST_SLOWDOWN
// takes it (harness/run/StageCall.cpp). Sets the environment each side runs with: HEAD's STAGE:FACTOR as given,
// BASE's STAGE:1 padded with leading zeros to the same length (the switch reads "001" as 1), so that the two
// environments differ in the factor's digits alone. The usage message on a bad value.
std::optional<std::string> ParsePlant(const ParsedArgs& a, std::optional<perf::PlantedSlowdown>& plant,
                                      std::vector<std::string> (&env)[2]) {
    if (!a.values.count("--plant")) return std::nullopt;
    if (a.values.at("--plant").size() > 1) return "--plant: given more than once; one stage is planted at a time";
    const std::string text = a.Value("--plant");
    const size_t colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0)
        return "--plant: needs STAGE:FACTOR (e.g. region:2), got '" + ShownArgument(text) + "'";
    const std::string stage = text.substr(0, colon), factorText = text.substr(colon + 1);
    if (!ParseStage(stage)) {
        std::vector<std::string_view> known;
        for (Stage s : kAllStages) known.push_back(StageName(s));
        std::string list;
        for (std::string_view name : known) list += (list.empty() ? "" : ", ") + std::string(name);
        const std::string_view best = ClosestName(stage, known);
        return "--plant: unknown stage '" + ShownArgument(stage) + "' (known: " + list + ")" +
               (best.empty() ? "" : "; did you mean '" + std::string(best) + "'?");
    }
    char* end = nullptr;
    const double factor = factorText.empty() ? NAN : std::strtod(factorText.c_str(), &end);
    if (factorText.empty() || !std::isdigit(static_cast<unsigned char>(factorText[0])) || *end != '\0' ||
        !(factor >= 1 && factor <= 1000))
        return "--plant: the factor of '" + ShownArgument(text) + "' must be a number in [1, 1000], got '" +
               ShownArgument(factorText) + "'";
    plant = perf::PlantedSlowdown{stage, factor};
    const std::string variable = "CLOUDBENCH_TEST_SLOWDOWN=" + stage + ":";
    env[0] = {variable + std::string(factorText.size() - 1, '0') + "1"};
    env[1] = {variable + factorText};
    return std::nullopt;
}

// `perf compare FOLDER`: the verdict again from a kept interleave's runs, with the exit code the live
// command ended with for the same runs.
int CompareKept(const std::string& folder, perf::CompareSettings settings, perf::Clock clock,
                const std::string& jsonPath, const std::string& junitPath) {
    auto kept = perf::LoadInterleave(folder, clock);
    if (!kept) {
        std::fprintf(stderr, "%s\n", kept.error().message.c_str());
        return kExitBadScene;
    }
    RunProblems problems;
    problems.failedRuns = kept->failedRuns;
    problems.plant = kept->plant;
    if (kept->recordedRuns < kept->plannedRuns)
        problems.cutShort = "the interleave was cut short: " + std::to_string(kept->recordedRuns) + " of " +
                            std::to_string(kept->plannedRuns) + " runs recorded in " + folder + "/" +
                            perf::kInterleaveFile;
    settings.interleaved = true;
    const int code = PrintComparison(kept->sides[0], kept->sides[1], settings,
                                     InterleavedMode(kept->rounds, kept->order) + ", kept in " + folder,
                                     JsonPaths(jsonPath), junitPath, problems);
    WarnIfLoaded(kept->peakLoad, clock);
    return code;
}

}  // namespace

int ComparePerf(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(
            args,
            {"--threshold", "--separate-threshold", "--floor", "--alpha", "--instruction-threshold", "--json",
             "--junit", "--rounds", "--backend", "--steps", "--set", "--keep", "--run-quantile", "--clock", "--plant"},
            {"--interleave", "--quiet"}, a))
        return Usage(*m);
    perf::CompareSettings settings;
    // --threshold R sets the default; --threshold BACKEND=R that backend's own.
    if (a.values.count("--threshold")) {
        std::vector<std::string> defaults;
        for (const std::string& value : a.values.at("--threshold")) {
            const size_t equals = value.find('=');
            ParsedArgs one;
            one.values["--threshold"] = {equals == std::string::npos ? value : value.substr(equals + 1)};
            double threshold = 0;
            if (auto m = NumberOption(one, "--threshold", 1.0, 1e6, threshold)) return Usage(*m);
            if (equals == std::string::npos)
                settings.threshold = threshold;
            else if (equals == 0)
                return Usage("--threshold: empty backend name in '" + ShownArgument(value) + "'");
            else if (auto why = UnknownBackend("--threshold", value.substr(0, equals)))
                return Usage(*why);
            else
                settings.backendThreshold[value.substr(0, equals)] = threshold;
        }
    }
    for (auto [name, low, high, field] :
         {std::tuple{"--separate-threshold", 1.0, 1e6, &settings.separateThreshold},
          std::tuple{"--floor", 0.0, 1e9, &settings.floorMs}, std::tuple{"--alpha", 1e-12, 1.0, &settings.alpha},
          std::tuple{"--instruction-threshold", 0.0, 1e6, &settings.instructionThreshold},
          std::tuple{"--run-quantile", 0.0, 1.0, &settings.runQuantile}})
        if (auto m = NumberOption(a, name, low, high, *field)) return Usage(*m);
    perf::Clock clock = perf::Clock::Wall;
    if (a.Has("--clock")) {
        const std::string name = a.Value("--clock");
        if (name != "wall" && name != "cpu")
            return Usage("--clock: needs wall or cpu, got '" + ShownArgument(name) + "'");
        clock = name == "cpu" ? perf::Clock::Cpu : perf::Clock::Wall;
    }
    const std::string jsonPath = a.Value("--json");
    const std::string junitPath = a.Value("--junit");
    if (!a.Has("--interleave")) {
        for (const char* o : {"--rounds", "--backend", "--steps", "--set", "--keep", "--plant"})
            if (a.Has(o)) return Usage(std::string(o) + " is for perf compare --interleave");
        if (a.positional.size() == 1 && std::filesystem::is_directory(a.positional[0]))
            return CompareKept(a.positional[0], settings, clock, jsonPath, junitPath);
        if (a.positional.size() != 2)
            return Usage("perf compare needs BASE and HEAD, or the FOLDER of a kept interleave");
        perf::Side sides[2];
        for (int n = 0; n < 2; ++n) {
            if (a.positional[n].empty()) return Usage(std::string(n ? "HEAD" : "BASE") + ": must not be empty");
            auto side = perf::LoadSide(a.positional[n], clock);
            if (!side) {
                std::fprintf(stderr, "%s\n", side.error().message.c_str());
                return kExitBadScene;
            }
            sides[n] = std::move(*side);
        }
        if (SameFile(a.positional[0], a.positional[1]))
            std::fprintf(stderr,
                         "perf compare: warning: BASE and HEAD are the same file (%s): nothing is compared "
                         "but the file with itself\n",
                         ShownArgument(a.positional[0]).c_str());
        settings.interleaved = false;
        return PrintComparison(sides[0], sides[1], settings, "separate files", JsonPaths(jsonPath), junitPath);
    }
    if (a.positional.size() < 3) return Usage("perf compare --interleave needs BASE_BINARY HEAD_BINARY SCENE...");
    // Without --rounds, the rounds follow from the first: as many as every time comparison needs to be judged.
    long long rounds = 0;
    if (auto m = WholeNumberOption(a, "--rounds", 1, kMaxRounds, rounds)) return Usage(*m);
    const bool autoRounds = rounds == 0;
    std::optional<perf::PlantedSlowdown> plant;
    std::vector<std::string> plantEnv[2];  // what --plant sets in each side's environment: BASE, HEAD
    if (auto m = ParsePlant(a, plant, plantEnv)) return Usage(*m);
    if (autoRounds) rounds = 1;
    std::vector<std::string> extra;
    if (a.Has("--backend")) extra.insert(extra.end(), {"--backend", a.Value("--backend")});
    if (a.Has("--steps")) extra.insert(extra.end(), {"--steps", a.Value("--steps")});
    if (a.values.count("--set"))
        for (const std::string& s : a.values.at("--set")) extra.insert(extra.end(), {"--set", s});
    const std::string binaries[2] = {a.positional[0], a.positional[1]};
    for (const std::string& b : binaries)
        if (::access(b.c_str(), X_OK) != 0) return Usage("'" + ShownArgument(b) + "' is not an executable file");
    if (binaries[0] == binaries[1] && !plant && !a.Has("--quiet"))
        std::fprintf(stderr, "perf compare: BASE_BINARY and HEAD_BINARY are the same file: a null comparison\n");
    const std::vector<std::string> scenes(a.positional.begin() + 2, a.positional.end());
    // The runs' outputs go to --keep's folder, or to a temporary one removed at the end.
    TemporaryFolder temporary(!a.Has("--keep"));
    const std::string folder = a.Has("--keep") ? a.Value("--keep") : temporary.path;
    if (folder.empty()) {
        std::fprintf(stderr, "perf compare: cannot create a temporary folder\n");
        return kExitFailed;
    }
    if (a.Has("--keep"))
        if (Status claimed = ClaimKeptFolder(folder); !claimed) {
            std::fprintf(stderr, "%s\n", claimed.error().message.c_str());
            return kExitFailed;
        }
    json manifest = {{"format", perf::kInterleaveFormat},
                     {"base", binaries[0]},
                     {"head", binaries[1]},
                     {"scenes", scenes},
                     {"rounds", int(rounds)},
                     {"order", "random"},
                     {"run_options", extra},
                     {"runs", json::array()}};
    if (plant) manifest["plant"] = {{"stage", plant->stage}, {"factor", plant->factor}};
    perf::Side sides[2];
    sides[0].label = binaries[0] + " (BASE)";
    sides[1].label = binaries[1] + " (HEAD)";
    for (perf::Side& side : sides) side.clock = clock;
    double peakLoad = 0;
    RunProblems problems;
    problems.plant = plant;
    std::optional<int> stop;  // the exit code to end with at once
    PairOrder order;
    auto runRound = [&](int round) {
        for (size_t s = 0; s < scenes.size() && !stop; ++s)
            for (int n : order.Next()) {
                if (!a.Has("--quiet"))
                    std::fprintf(stderr, "perf compare: round %d of %s, %s, %s\n", round + 1,
                                 autoRounds && round == 0 ? "(counting)" : std::to_string(int(rounds)).c_str(),
                                 scenes[s].c_str(), n ? "HEAD" : "BASE");
                const std::string side = n ? "head" : "base";
                const std::string name = side + "/" + KeptRunName(round, scenes[s]);
                json run = {
                    {"side", side}, {"scene", scenes[s]}, {"round", round}, {"folder", name}, {"load", LoadAverage()}};
                if (!run["load"].empty()) peakLoad = std::max(peakLoad, run["load"][0].get<double>());
                const auto start = std::chrono::steady_clock::now();
                int exitCode = -1;
                bool runFailed = false, compared = false;
                if (auto code = RunInto(binaries[n], scenes[s], extra, folder + "/" + name, folder + "/runs.log",
                                        sides[n], runFailed, round, &exitCode, &compared, plantEnv[n])) {
                    stop = *code;
                    return;
                }
                if (runFailed) problems.failedRuns.push_back({side, scenes[s], round, exitCode, compared});
                run["exit"] = exitCode;
                run["seconds"] =
                    std::round(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * 1000) /
                    1000;
                manifest["runs"].push_back(run);
                // Rewritten after each run, so that a comparison cut short keeps what it measured.
                if (a.Has("--keep") && !WriteJsonFile(folder + "/" + perf::kInterleaveFile, manifest)) {
                    stop = kExitFailed;
                    return;
                }
            }
    };
    for (int round = 0; round < int(rounds) && !stop; ++round) runRound(round);
    if (autoRounds && !stop) {
        rounds = RoundsToJudge(sides[0], sides[1], settings.alpha);
        manifest["rounds"] = int(rounds);
        if (!a.Has("--quiet"))
            std::fprintf(stderr, "perf compare: %d rounds, enough for each comparison to be judged\n", int(rounds));
        for (int round = 1; round < int(rounds) && !stop; ++round) runRound(round);
    }
    if (stop) return *stop;
    settings.interleaved = true;
    const int code = PrintComparison(sides[0], sides[1], settings, InterleavedMode(int(rounds), "random"),
                                     JsonPaths(jsonPath, a.Has("--keep") ? folder + "/" + perf::kKeptVerdictFile : ""),
                                     junitPath, problems);
    WarnIfLoaded(peakLoad, clock);
    return code;
}

}  // namespace cb::perf_command
