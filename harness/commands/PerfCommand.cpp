// `cloudbench perf`: performance tracking (docs/cli.md, "perf"). `record`
// appends one record of a fixed suite to a history, `compare` compares two
// result files, two records or interleaved runs of two binaries with a
// regression verdict, `history` finds step changes over a history, `export`
// writes Google Benchmark's JSON. Every measurement is a `cloudbench run` in a
// child process, so the numbers are those `run` reports.
#include <unistd.h>

#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include "harness/Command.h"
#include "harness/ReportModel.h"
#include "harness/perf/CallgrindCount.h"
#include "harness/perf/Compare.h"
#include "harness/perf/History.h"
#include "harness/perf/Spawn.h"
#include "harness/perf/Stats.h"

namespace cb {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kHelp = R"(usage: cloudbench perf record [--suite FILE] [--history FILE] [--repeat N]
                              [--backend LIST] [--instructions FILE]
       cloudbench perf compare BASE HEAD [compare options]
       cloudbench perf compare --interleave BASE_BINARY HEAD_BINARY SCENE...
                              [--rounds K] [--backend LIST] [--steps N] [--set PATH=VALUE]...
                              [compare options]
       cloudbench perf history FILE [--metric time|instructions] [--min-change F]
                              [--min-segment N] [--json FILE]
       cloudbench perf export --gbench OUT SOURCE

record   runs the suite (default: thesis-low, thesis-medium, thesis-high, each as
         `cloudbench run` with its own steps, on every built backend; --suite
         FILE: docs/cli.md) and appends one record to the history (default:
         $CLOUDBENCH_HISTORY, else $XDG_DATA_HOME/cloudbench/history.jsonl, else
         ~/.local/share/cloudbench/history.jsonl). --repeat N runs each scene N
         times and pools the samples. It also counts each scene's CPU
         instructions (`cloudbench count`) when this build can (no
         -march=native: the exact preset; valgrind installed), else the
         record's "instructions_not_counted" says why; --instructions FILE
         merges a `cloudbench count` output instead.
compare  compares per-step stage times (median ratio with a 95 % bootstrap
         interval, one-sided Mann-Whitney U tests with Holm's correction) and
         instruction counts. BASE and HEAD: a results.json, a count output, a
         history (its last record), FILE@ID or FILE@-N (N-th record from the
         end). --interleave runs BASE_BINARY and HEAD_BINARY alternately
         (A B A B ..., K rounds, default 5) and pools each side's samples.
         Marks: + slower, - faster, ~ not significant or within the threshold,
         x failed or missing in HEAD, ! new.
  --threshold [BACKEND=]R  a time regression needs a median ratio above R
                  (default 1.5; gl and vk 3, software drivers here)
  --separate-threshold R  used instead when BASE and HEAD were not run
                  interleaved (default 2.0)
  --floor MS      and the medians to differ by more than MS (default 0.05)
  --alpha A       and a Holm-adjusted p below A (default 0.01)
  --instruction-threshold F  an instruction count regresses above 1 + F
                  (default 0.02)
  --json FILE     also write every comparison as JSON
history  marks step changes in each stage's median over the records (binary
         segmentation, permutation test) and what changed in the provenance.
export   writes SOURCE (as for compare) as Google Benchmark JSON for compare.py.

Exit codes: 0 no regression (an inconclusive result passes), 1 a run failed
or an output could not be written, 2 bad command line, 3 a bad input file,
6 a confirmed regression.
)";

int Usage(const std::string& message) {
    std::fprintf(stderr, "cloudbench: %s\n\n%s", message.c_str(), kHelp);
    return kExitUsage;
}

// Options of one subcommand: those taking a value, repeatable, and flags.
struct ParsedArgs {
    std::vector<std::string> positional;
    std::map<std::string, std::vector<std::string>> values;
    std::set<std::string> flags;

    std::string Value(const std::string& name, const std::string& fallback = "") const {
        auto it = values.find(name);
        return it == values.end() ? fallback : it->second.back();
    }
    bool Has(const std::string& name) const { return values.count(name) || flags.count(name); }
};

std::optional<std::string> Parse(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
                                 const std::set<std::string>& flagOptions, ParsedArgs& out) {
    for (size_t n = 1; n < args.size(); ++n) {
        const std::string& arg = args[n];
        if (valueOptions.count(arg)) {
            if (n + 1 >= args.size()) return arg + " needs a value";
            if (args[n + 1].empty()) return arg + ": must not be empty";
            out.values[arg].push_back(args[++n]);
        } else if (flagOptions.count(arg)) {
            out.flags.insert(arg);
        } else if (arg.size() > 1 && arg[0] == '-' && !std::isdigit(static_cast<unsigned char>(arg[1]))) {
            return "unknown option '" + arg + "' for perf " + args[0];
        } else {
            out.positional.push_back(arg);
        }
    }
    return std::nullopt;
}

std::string Num(const char* format, double v) {
    if (std::isnan(v)) return "";
    char text[64];
    std::snprintf(text, sizeof text, format, v);
    return text;
}

// A number option in [low, high]; the usage message when it is not one.
std::optional<std::string> NumberOption(const ParsedArgs& a, const std::string& name, double low, double high,
                                        double& value) {
    if (!a.values.count(name)) return std::nullopt;
    const std::string text = a.Value(name);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !(v >= low && v <= high))
        return name + ": needs a number in [" + Num("%g", low) + ", " + Num("%g", high) + "], got '" + text + "'";
    value = v;
    return std::nullopt;
}

// Writes `doc` to `path` whole: a temporary file in the same folder, renamed.
bool WriteJsonFile(const std::string& path, const json& doc) {
    const std::string temporary = path + ".partial";
    {
        std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
        file << doc.dump(1) << "\n";
        file.flush();
        if (!file) {
            std::fprintf(stderr, "%s: cannot write\n", path.c_str());
            std::remove(temporary.c_str());
            return false;
        }
    }
    std::error_code ec;
    fs::rename(temporary, path, ec);
    if (ec) std::fprintf(stderr, "%s: cannot write: %s\n", path.c_str(), ec.message().c_str());
    return !ec;
}

// A temporary folder for runs' outputs, removed when this goes out of scope.
struct TemporaryFolder {
    TemporaryFolder() {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base && *base ? base : "/tmp") + "/cloudbench-perf-XXXXXX";
        if (char* made = ::mkdtemp(pattern.data())) path = made;
    }
    ~TemporaryFolder() {
        std::error_code ec;
        if (!path.empty()) fs::remove_all(path, ec);
    }
    std::string path;
};

// One `cloudbench run` of `scene` by `binary` into `out`, its results added to
// `side`. Returns the exit code the perf command should end with at once (a
// bad scene or command line), or nullopt to go on; `failed` is set when the
// run failed.
std::optional<int> RunInto(const std::string& binary, const std::string& scene, const std::vector<std::string>& extra,
                           const std::string& out, const std::string& log, perf::Side& side, bool& failed) {
    std::vector<std::string> argv = {binary, "run", scene, "--out", out, "--quiet"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto rc = perf::RunChild(argv, log);
    if (!rc) {
        std::fprintf(stderr, "%s\n", rc.error().message.c_str());
        return kExitFailed;
    }
    if (*rc == kExitUsage || *rc == kExitBadScene) {
        std::fprintf(stderr, "perf: %s run %s exited %d (see its message above)\n", binary.c_str(), scene.c_str(), *rc);
        return *rc;
    }
    std::ifstream file(out + "/results.json");
    const json results = json::parse(file, nullptr, /*allow_exceptions=*/false);
    if (results.is_discarded()) {
        std::fprintf(stderr, "perf: %s run %s exited %d and wrote no results.json\n", binary.c_str(), scene.c_str(),
                     *rc);
        failed = true;
        return std::nullopt;
    }
    if (*rc != kExitOk) {
        std::fprintf(stderr, "perf: %s run %s exited %d\n", binary.c_str(), scene.c_str(), *rc);
        failed = true;
    }
    if (Status s = perf::AddResults(side, results); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    return std::nullopt;
}

// ---------------------------------------------------------------- record

struct SuiteEntry {
    std::string scene;
    std::vector<std::string> set;  // PATH=VALUE overrides
};

// The default suite: the thesis scenes as `run` runs them.
std::vector<SuiteEntry> DefaultSuite() { return {{"thesis-low", {}}, {"thesis-medium", {}}, {"thesis-high", {}}}; }

// {"scenes": [{"scene": NAME_OR_PATH, "set": ["PATH=VALUE", ...]}, ...]}
Result<std::vector<SuiteEntry>> LoadSuite(const std::string& path) {
    std::ifstream file(path);
    if (!file) return MakeError(path + ": cannot read");
    const json doc = json::parse(file, nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_object()) return MakeError(path + ": not a JSON object");
    if (!doc.contains("scenes") || !doc["scenes"].is_array() || doc["scenes"].empty())
        return MakeError(path + ": scenes: must be a non-empty array");
    std::vector<SuiteEntry> suite;
    for (size_t i = 0; i < doc["scenes"].size(); ++i) {
        const json& e = doc["scenes"][i];
        const std::string where = path + ": scenes[" + std::to_string(i) + "]";
        if (!e.is_object() || !e.contains("scene") || !e["scene"].is_string() || e["scene"].get<std::string>().empty())
            return MakeError(where + ".scene: must be a scene name or path");
        SuiteEntry entry{e["scene"].get<std::string>(), {}};
        if (e.contains("set")) {
            if (!e["set"].is_array()) return MakeError(where + ".set: must be an array of \"PATH=VALUE\"");
            for (const json& s : e["set"]) {
                if (!s.is_string() || s.get<std::string>().find('=') == std::string::npos)
                    return MakeError(where + ".set: must be an array of \"PATH=VALUE\"");
                entry.set.push_back(s.get<std::string>());
            }
        }
        suite.push_back(entry);
    }
    return suite;
}

int Record(const std::vector<std::string>& args, const CommonOptions& options) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--suite", "--history", "--repeat", "--backend", "--instructions"}, {"--quiet"}, a))
        return Usage(*m);
    if (!a.positional.empty()) return Usage("perf record: unexpected argument '" + a.positional[0] + "'");
    double repeat = 1;
    if (auto m = NumberOption(a, "--repeat", 1, 1000, repeat)) return Usage(*m);
    if (repeat != std::floor(repeat)) return Usage("--repeat: needs a whole number");
    std::vector<SuiteEntry> suite = DefaultSuite();
    if (a.Has("--suite")) {
        auto loaded = LoadSuite(a.Value("--suite"));
        if (!loaded) {
            std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
            return kExitBadScene;
        }
        suite = *loaded;
    }
    const std::string historyPath = a.Value("--history", perf::DefaultHistoryPath());
    perf::Side side;
    side.label = "record";
    if (a.Has("--instructions")) {
        const std::string path = a.Value("--instructions");
        std::ifstream file(path);
        const json doc = json::parse(file, nullptr, /*allow_exceptions=*/false);
        side.label = path;
        Status s = doc.is_object() ? perf::AddInstructions(side, doc) : Status(MakeError(path + ": not a JSON object"));
        if (!s) {
            std::fprintf(stderr, "%s\n", s.error().message.c_str());
            return kExitBadScene;
        }
    }
    std::vector<std::string> extra;
    if (a.Has("--backend")) extra = {"--backend", a.Value("--backend")};
    TemporaryFolder temporary;
    if (temporary.path.empty()) {
        std::fprintf(stderr, "perf record: cannot create a temporary folder\n");
        return kExitFailed;
    }
    const auto start = std::chrono::steady_clock::now();
    bool failed = false;
    json suiteJson = json::array();
    const std::string self = perf::SelfPath();
    for (const SuiteEntry& entry : suite) {
        std::vector<std::string> runArgs = extra;
        for (const std::string& s : entry.set) runArgs.insert(runArgs.end(), {"--set", s});
        suiteJson.push_back({{"scene", entry.scene}, {"set", entry.set}});
        for (int r = 0; r < int(repeat); ++r) {
            const std::string out = temporary.path + "/" + std::to_string(suiteJson.size()) + "-" + std::to_string(r);
            const auto runStart = std::chrono::steady_clock::now();
            if (!a.Has("--quiet"))
                std::fprintf(stderr, "perf record: %s (%d of %d)\n", entry.scene.c_str(), r + 1, int(repeat));
            if (auto code = RunInto(self, entry.scene, runArgs, out, temporary.path + "/runs.log", side, failed))
                return *code;
            if (!a.Has("--quiet"))
                std::fprintf(stderr, "perf record: %s took %.1f s\n", entry.scene.c_str(),
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count());
        }
    }
    // Exact mode: each suite scene's CPU instruction counts, when this build can count them
    // (no -march=native, valgrind present); otherwise the record says why not.
    std::string notCounted;
    if (a.Has("--instructions")) {
        notCounted = "";  // given by the caller
    } else if (auto why = WhyCannotCount(side.provenance.value("build", json::object()).value("flags", ""))) {
        notCounted = *why;
    } else {
        for (size_t i = 0; i < suite.size(); ++i) {
            const std::string out = temporary.path + "/count-" + std::to_string(i) + ".json";
            std::vector<std::string> argv = {self, "count", suite[i].scene, "--out", out, "--quiet"};
            for (const std::string& set : suite[i].set) argv.insert(argv.end(), {"--set", set});
            if (!a.Has("--quiet")) std::fprintf(stderr, "perf record: counting %s\n", suite[i].scene.c_str());
            auto rc = perf::RunChild(argv, temporary.path + "/runs.log");
            std::ifstream file(out);
            const json counts = json::parse(file, nullptr, /*allow_exceptions=*/false);
            if (!rc || *rc != kExitOk || !counts.is_object() || !perf::AddInstructions(side, counts)) {
                std::fprintf(stderr, "perf record: counting %s failed (exit %d)\n", suite[i].scene.c_str(),
                             rc ? *rc : -1);
                notCounted += (notCounted.empty() ? "" : "; ") + suite[i].scene + ": count failed";
                failed = true;
            }
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    json provenance = side.provenance;
    if (provenance.is_object()) {
        provenance.erase("scene");  // one per scene; the suite says which
        provenance["command_line"] = options.commandLine;
    }
    const json sections = perf::RecordSections(side);
    json record = {{"format", perf::kRecordFormat},
                   {"id", perf::NewRecordId()},
                   {"time", side.date},
                   {"provenance", provenance},
                   {"suite", suiteJson},
                   {"repeat", int(repeat)},
                   {"seconds", std::round(seconds * 10) / 10},
                   {"results", sections["results"]},
                   {"failures", sections["failures"]},
                   {"instructions", sections["instructions"]}};
    if (!notCounted.empty()) record["instructions_not_counted"] = notCounted;
    if (Status s = perf::AppendRecord(historyPath, record); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("perf record: appended %s to %s (%zu scenes, %.1f s)\n", record["id"].get<std::string>().c_str(),
                historyPath.c_str(), suite.size(), seconds);
    return failed ? kExitFailed : kExitOk;
}

// ---------------------------------------------------------------- compare

std::string SideSummary(const perf::Side& side) {
    std::string text = side.label;
    const json& p = side.provenance;
    std::string commit = p.is_object() && p.contains("git") ? p["git"].value("commit", "") : "";
    if (commit.size() > 10) commit.resize(10);
    if (!side.date.empty() || !commit.empty()) text += " (" + side.date + (commit.empty() ? "" : ", " + commit) + ")";
    return text;
}

json ComparisonJson(const perf::Comparison& c) {
    auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    return {{"scene", c.scene},
            {"backend", c.backend},
            {"stage", c.stage},
            {"metric", c.metric},
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

// Prints the comparison, writes --json, returns the exit code.
int PrintComparison(const perf::Side& base, const perf::Side& head, const perf::CompareSettings& settings,
                    const std::string& mode, const std::string& jsonPath) {
    const perf::CompareOutcome outcome = perf::Compare(base, head, settings);
    report::Report rep("perf compare");
    report::Section section;
    section.title = "";
    report::KeyValues header;
    header.items = {{"BASE", SideSummary(base)}, {"HEAD", SideSummary(head)}, {"mode", mode}};
    if (outcome.separate)
        header.items.push_back(
            {"note", "BASE and HEAD were measured at different times, not interleaved: the wider threshold " +
                         Num("%gx", outcome.threshold) + " applies"});
    std::string own;
    for (const auto& [backend, unused] : settings.backendThreshold)
        own += ", " + backend + " " + Num("%gx", perf::ThresholdOf(settings, backend));
    header.items.push_back({"gate", "+ when slower by more than " + Num("%gx", outcome.threshold) + own + " and " +
                                        Num("%g ms", settings.floorMs) + ", Holm-adjusted p < " +
                                        Num("%g", settings.alpha) + "; instructions: more than " +
                                        Num("%g %%", settings.instructionThreshold * 100)});
    section.blocks.push_back(header);
    report::Table table({report::Column(""), report::Column("scene"), report::Column("backend"),
                         report::Column("stage"), report::Column("base"), report::Column("head"),
                         report::Column("ratio").AlignRight(), report::Column("95% CI"),
                         report::Column("p slower (Holm)").AlignRight(), report::Column("note")});
    for (const perf::Comparison& c : outcome.rows) {
        const bool time = c.metric == "time";
        const char* f = time ? "%.3f ms" : "%.0f";
        table.rows.push_back(
            {std::string(1, c.mark), c.scene, c.backend, c.stage + (time ? "" : " (instructions)"),
             Num(f, c.baseMedian), Num(f, c.headMedian), Num("%.3f", c.ratio),
             std::isnan(c.interval.low) ? "" : Num("%.3f", c.interval.low) + "-" + Num("%.3f", c.interval.high),
             Num("%.2g", c.pSlowerHolm), c.note});
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
    } else {
        std::printf("no regression\n");
    }
    if (!jsonPath.empty()) {
        json doc = {{"format", "cloudbench-perf-compare/1"},
                    {"base", {{"label", base.label}, {"date", base.date}, {"provenance", base.provenance}}},
                    {"head", {{"label", head.label}, {"date", head.date}, {"provenance", head.provenance}}},
                    {"mode", mode},
                    {"separate", outcome.separate},
                    {"threshold", outcome.threshold},
                    {"backend_thresholds", json::object()},
                    {"floor_ms", settings.floorMs},
                    {"alpha", settings.alpha},
                    {"instruction_threshold", settings.instructionThreshold},
                    {"comparisons", json::array()},
                    {"regressions", outcome.Regressions()},
                    {"exit_code", code},
                    {"report", report::RenderJson(rep)}};
        for (const perf::Comparison& c : outcome.rows) doc["comparisons"].push_back(ComparisonJson(c));
        for (const auto& [backend, unused] : settings.backendThreshold)
            doc["backend_thresholds"][backend] = perf::ThresholdOf(settings, backend);
        if (!WriteJsonFile(jsonPath, doc) && code == kExitOk) code = kExitFailed;
    }
    return code;
}

int ComparePerf(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args,
                       {"--threshold", "--separate-threshold", "--floor", "--alpha", "--instruction-threshold",
                        "--json", "--rounds", "--backend", "--steps", "--set"},
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
                return Usage("--threshold: empty backend name in '" + value + "'");
            else
                settings.backendThreshold[value.substr(0, equals)] = threshold;
        }
    }
    for (auto [name, low, high, field] :
         {std::tuple{"--separate-threshold", 1.0, 1e6, &settings.separateThreshold},
          std::tuple{"--floor", 0.0, 1e9, &settings.floorMs}, std::tuple{"--alpha", 1e-12, 1.0, &settings.alpha},
          std::tuple{"--instruction-threshold", 0.0, 1e6, &settings.instructionThreshold}})
        if (auto m = NumberOption(a, name, low, high, *field)) return Usage(*m);
    const std::string jsonPath = a.Value("--json");
    if (!a.Has("--interleave")) {
        for (const char* o : {"--rounds", "--backend", "--steps", "--set"})
            if (a.Has(o)) return Usage(std::string(o) + " is for perf compare --interleave");
        if (a.positional.size() != 2) return Usage("perf compare needs BASE and HEAD");
        perf::Side sides[2];
        for (int n = 0; n < 2; ++n) {
            if (a.positional[n].empty()) return Usage(std::string(n ? "HEAD" : "BASE") + ": must not be empty");
            auto side = perf::LoadSide(a.positional[n]);
            if (!side) {
                std::fprintf(stderr, "%s\n", side.error().message.c_str());
                return kExitBadScene;
            }
            sides[n] = std::move(*side);
        }
        settings.interleaved = false;
        return PrintComparison(sides[0], sides[1], settings, "separate files", jsonPath);
    }
    if (a.positional.size() < 3) return Usage("perf compare --interleave needs BASE_BINARY HEAD_BINARY SCENE...");
    double rounds = 5;
    if (auto m = NumberOption(a, "--rounds", 1, 1000, rounds)) return Usage(*m);
    std::vector<std::string> extra;
    if (a.Has("--backend")) extra.insert(extra.end(), {"--backend", a.Value("--backend")});
    if (a.Has("--steps")) extra.insert(extra.end(), {"--steps", a.Value("--steps")});
    if (a.values.count("--set"))
        for (const std::string& s : a.values.at("--set")) extra.insert(extra.end(), {"--set", s});
    const std::string binaries[2] = {a.positional[0], a.positional[1]};
    for (const std::string& b : binaries)
        if (::access(b.c_str(), X_OK) != 0) return Usage("'" + b + "' is not an executable file");
    const std::vector<std::string> scenes(a.positional.begin() + 2, a.positional.end());
    TemporaryFolder temporary;
    if (temporary.path.empty()) {
        std::fprintf(stderr, "perf compare: cannot create a temporary folder\n");
        return kExitFailed;
    }
    perf::Side sides[2];
    sides[0].label = binaries[0] + " (BASE)";
    sides[1].label = binaries[1] + " (HEAD)";
    bool failed = false;
    for (int round = 0; round < int(rounds); ++round)
        for (size_t s = 0; s < scenes.size(); ++s)
            for (int n = 0; n < 2; ++n) {
                if (!a.Has("--quiet"))
                    std::fprintf(stderr, "perf compare: round %d of %d, %s, %s\n", round + 1, int(rounds),
                                 scenes[s].c_str(), n ? "HEAD" : "BASE");
                const std::string out =
                    temporary.path + "/" + std::to_string(round) + "-" + std::to_string(s) + (n ? "-head" : "-base");
                if (auto code =
                        RunInto(binaries[n], scenes[s], extra, out, temporary.path + "/runs.log", sides[n], failed))
                    return *code;
            }
    settings.interleaved = true;
    const int code = PrintComparison(sides[0], sides[1], settings,
                                     "interleaved, " + std::to_string(int(rounds)) + " rounds", jsonPath);
    return code == kExitOk && failed ? kExitFailed : code;
}

// ---------------------------------------------------------------- history

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

int History(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--metric", "--min-change", "--min-segment", "--json"}, {}, a)) return Usage(*m);
    if (a.positional.size() != 1 || a.positional[0].empty()) return Usage("perf history needs one history FILE");
    const std::string metric = a.Value("--metric", "time");
    if (metric != "time" && metric != "instructions") return Usage("--metric needs time or instructions");
    perf::ChangePointSettings settings;
    double minChange = 0.1, minSegment = settings.minSegment;
    if (auto m = NumberOption(a, "--min-change", 0, 100, minChange)) return Usage(*m);
    if (auto m = NumberOption(a, "--min-segment", 1, 1e6, minSegment)) return Usage(*m);
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

// ---------------------------------------------------------------- export

// Google Benchmark's JSON (what --benchmark_format=json writes): one
// "iteration" entry per step sample, named scene/backend/stage, so that
// compare.py can run its U test over the samples. cpu_time repeats the wall
// time: cloudbench measures no CPU time.
json GbenchJson(const perf::Side& side) {
    const json& p = side.provenance;
    const json machine = p.is_object() ? p.value("machine", json::object()) : json::object();
    json doc = {{"context",
                 {{"date", side.date},
                  {"host_name", machine.value("cpu", "")},
                  {"executable", "cloudbench " + side.label},
                  {"num_cpus", machine.value("threads", 0)},
                  {"mhz_per_cpu", 0},
                  {"cpu_scaling_enabled", false},
                  {"caches", json::array()},
                  {"library_build_type", "release"}}},
                {"benchmarks", json::array()}};
    for (const auto& [scene, backends] : side.samplesMs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, samples] : stages) {
                const std::string name = scene + "/" + backend + "/" + stage;
                for (size_t i = 0; i < samples.size(); ++i)
                    doc["benchmarks"].push_back({{"name", name},
                                                 {"family_index", 0},
                                                 {"per_family_instance_index", 0},
                                                 {"run_name", name},
                                                 {"run_type", "iteration"},
                                                 {"repetitions", samples.size()},
                                                 {"repetition_index", i},
                                                 {"threads", 1},
                                                 {"iterations", 1},
                                                 {"real_time", samples[i]},
                                                 {"cpu_time", samples[i]},
                                                 {"time_unit", "ms"}});
            }
    return doc;
}

int Export(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--gbench"}, {}, a)) return Usage(*m);
    if (!a.Has("--gbench")) return Usage("perf export needs --gbench OUT");
    if (a.positional.size() != 1 || a.positional[0].empty()) return Usage("perf export needs one SOURCE");
    auto side = perf::LoadSide(a.positional[0]);
    if (!side) {
        std::fprintf(stderr, "%s\n", side.error().message.c_str());
        return kExitBadScene;
    }
    return WriteJsonFile(a.Value("--gbench"), GbenchJson(*side)) ? kExitOk : kExitFailed;
}

int Perf(const CommonOptions& options) {
    const std::vector<std::string>& args = options.arguments;
    if (args.empty()) return Usage("perf needs a subcommand: record, compare, history or export");
    const std::string& sub = args[0];
    if (sub == "record") return Record(args, options);
    if (sub == "compare") return ComparePerf(args);
    if (sub == "history") return History(args);
    if (sub == "export") return Export(args);
    return Usage("perf: unknown subcommand '" + sub + "' (record, compare, history, export)");
}

const CommandRegistration kRegistration({
    .name = "perf",
    .summary = "Performance history and regression gate: record, compare, history, export",
    .help = kHelp,
    .helpOrder = 6,
    .takesScene = false,
    .rawArguments = true,
    .run = Perf,
});

}  // namespace
}  // namespace cb
