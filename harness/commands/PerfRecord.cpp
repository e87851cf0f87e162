// `cloudbench perf record` (docs/cli.md, "perf"): runs a suite of scenes, each
// as `cloudbench run` in a child process, counts their CPU instructions where
// this build can, and appends one record to a history.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/base/ShownText.h"
#include "harness/commands/PerfCommon.h"
#include "harness/perf/CallgrindCount.h"
#include "harness/perf/History.h"
#include "harness/perf/Spawn.h"
#include "harness/report/InputFormats.h"

namespace cb::perf_command {
namespace {

struct SuiteEntry {
    std::string scene;
    std::vector<std::string> set;  // PATH=VALUE overrides
};

// The default suite: the thesis scenes as `run` runs them.
std::vector<SuiteEntry> DefaultSuite() { return {{"thesis-low", {}}, {"thesis-medium", {}}, {"thesis-high", {}}}; }

// {"scenes": [{"scene": NAME_OR_PATH, "set": ["PATH=VALUE", ...]}, ...]} (harness/report/InputFormats.h).
Result<std::vector<SuiteEntry>> LoadSuite(const std::string& path) {
    static constexpr input::Format kSuite[] = {input::Format::Suite};
    auto read = input::ReadCloudbenchFile(path, kSuite);
    if (!read) return std::unexpected(read.error());
    std::vector<SuiteEntry> suite;
    const json& scenes = read->doc["scenes"];
    for (size_t i = 0; i < scenes.size(); ++i) {
        const std::string where = path + ": /scenes/" + std::to_string(i);
        SuiteEntry entry{scenes[i]["scene"].get<std::string>(), {}};
        if (entry.scene.empty()) return MakeError(where + "/scene: must be a scene name or path, not \"\"");
        const json set = scenes[i].value("set", json::array());
        for (size_t k = 0; k < set.size(); ++k) {
            const std::string s = set[k].get<std::string>();
            if (s.find('=') == std::string::npos || s.front() == '=')
                return MakeError(where + "/set/" + std::to_string(k) + ": must be \"PATH=VALUE\", not " + QuoteShown(s));
            entry.set.push_back(s);
        }
        suite.push_back(std::move(entry));
    }
    return suite;
}

// The instruction counts of a `cloudbench count` output or an instruction file, added to `side`.
Status AddInstructionsFile(perf::Side& side, const std::string& path) {
    static constexpr input::Format kCounts[] = {input::Format::Count, input::Format::Instructions};
    auto read = input::ReadCloudbenchFile(path, kCounts);
    if (!read) return std::unexpected(read.error());
    return perf::AddInstructions(side, read->doc);
}

// Adds the CPU times of the results.json at `path` to `cpu`; false (with a
// warning) when it cannot, and the record then keeps wall times alone.
bool AddCpuTimes(perf::Side& cpu, const std::string& path) {
    static constexpr input::Format kResults[] = {input::Format::Results};
    auto results = input::ReadCloudbenchFile(path, kResults);
    Status added = results ? perf::AddResults(cpu, results->doc) : Status(std::unexpected(results.error()));
    if (!added) std::fprintf(stderr, "perf record: warning: no CPU times recorded: %s\n", added.error().message.c_str());
    return bool(added);
}

}  // namespace

int Record(const std::vector<std::string>& args, const CommonOptions& options) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--suite", "--history", "--repeat", "--backend", "--instructions"}, {"--quiet"}, a))
        return Usage(*m);
    if (!a.positional.empty()) return Usage("perf record: unexpected argument '" + a.positional[0] + "'");
    long long repeat = 1;
    if (auto m = WholeNumberOption(a, "--repeat", 1, 1000, repeat)) return Usage(*m);
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
    perf::Side side, cpu;  // the same runs on the wall clock and on the CPU clock
    side.label = "record";
    cpu.clock = perf::Clock::Cpu;
    bool everyCpu = true;  // every run's results.json held its stages' CPU times
    if (a.Has("--instructions")) {
        const std::string path = a.Value("--instructions");
        side.label = path;
        if (Status s = AddInstructionsFile(side, path); !s) {
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
                std::fprintf(stderr, "perf record: %s, run %d of %d\n", entry.scene.c_str(), r + 1, int(repeat));
            bool compared = false;
            if (auto code = RunInto(self, entry.scene, runArgs, out, temporary.path + "/runs.log", side, failed, -1,
                                    nullptr, &compared))
                return *code;
            if (compared && everyCpu) everyCpu = AddCpuTimes(cpu, out + "/results.json");
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
            Status added = rc && *rc == kExitOk ? AddInstructionsFile(side, out) : Status();
            if (!rc || *rc != kExitOk || !added) {
                std::fprintf(stderr, "perf record: counting %s failed (exit %d)%s\n", suite[i].scene.c_str(),
                             rc ? *rc : -1, added ? "" : (": " + added.error().message).c_str());
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
    if (!everyCpu) cpu.runs.clear();  // a record's CPU times are all its runs' or none
    const json sections = perf::RecordSections(side, cpu);
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

}  // namespace cb::perf_command
