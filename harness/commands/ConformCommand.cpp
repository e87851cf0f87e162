// `cloudbench conform`: stage-isolated conformance of every backend against
// the CPU on a scene (harness/Conform.h); writes conform.json and conform.csv,
// exits 5 on a failure; --baseline and --flake-reruns as deqp-runner's (docs/cli.md).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "core/StageDescriptors.h"
#include "harness/Conform.h"
#include "harness/Isolation.h"
#include "harness/Session.h"
#include "harness/Transfer.h"

namespace cb {
namespace {

constexpr const char* kHelpIntro = R"(usage: cloudbench conform [SCENE] [options]

Runs SCENE on the CPU and, at every step, feeds each other backend's stages
the CPU's inputs of that step (stage-isolated conformance), and compares their
outputs by SPEC's rule for the stage (core/StageDescriptors.cpp):
)";
constexpr const char* kHelpOptions = R"(Prints stage x backend with the result, the rule and the worst error with where
it is, writes DIR/conform.json and DIR/conform.csv, and exits 5 if any check
fails. Stages a backend lacks are listed as skipped.

Options:
  --backend LIST     backends to check (default: all built; cpu is the reference)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/conform)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --vk-device DEV    Vulkan device: index or part of the name
  --baseline FILE    known failures, "stage,backend,status" a line (a conform.csv
                     will do): a listed failure is expected-fail and does not fail
                     the command; a listed row that passes is unexpected-pass (exit 5)
  --flake-reruns N   rerun a backend with a failing row up to N times (its whole
                     comparison); a row that then passes is flaky, not a failure
)";

// One line per stage: its rule in a default scene, and what changes it.
std::string RulesHelp() {
    std::string text;
    const Scene defaults;
    for (Stage stage : kAllStages) {
        const StageDescriptor& d = Describe(stage);
        std::string line = "  " + std::string(StageName(stage));
        line.resize(16, ' ');
        line += d.rule(defaults).Text(d.symbol);
        if (!d.ruleNote.empty()) line += " (" + std::string(d.ruleNote) + ")";
        text += line + "\n";
        if (stage == Stage::Density) {
            line = "  " + std::string(kCoverRowStage);
            line.resize(16, ' ');
            text += line + "bit-exact (density's count of covered columns)\n";
        }
    }
    return text + "\n";
}

const std::string kHelp = kHelpIntro + RulesHelp() + kHelpOptions + GlOptionsHelp() + IsolationOptionsHelp();

// One backend's conformance against the CPU, in its own process when isolated:
// both are opened there. Returns {"rows": [...], "backends": [provenance...]},
// or {"error": ...} when the CPU reference cannot be opened.
// After each step it sends {"step": t, "rows": [...]}, the rows so far, so that a
// backend whose process dies later keeps the comparisons it finished.
nlohmann::json IsolatedConformance(Session& session, const std::string& name, const SendMessage& send,
                                   uint32_t attempt) {
    MarkPhase("opening backend");
    std::vector<OpenedBackend> cpu = session.OpenBackends({"cpu"}, nullptr, /*report=*/false);
    std::vector<OpenedBackend> other = session.OpenBackends({name}, nullptr, /*report=*/false);
    nlohmann::json backends = nlohmann::json::array();
    for (const BackendProvenance& record : session.BackendRecords()) backends.push_back(transfer::ToJson(record));
    if (!cpu[0].backend) return {{"error", cpu[0].reason}, {"backends", backends}};
    auto rows = RunConformance(session.GetScene(), *cpu[0].backend, other,
                               [&](uint32_t step, const std::vector<ConformRow>& soFar) {
                                   nlohmann::json list = nlohmann::json::array();
                                   for (const ConformRow& row : soFar) list.push_back(transfer::ToJson(row));
                                   send({{"step", step}, {"rows", list}});
                               },
                               session.OutDir(), attempt);
    nlohmann::json list = nlohmann::json::array();
    if (rows)
        for (const ConformRow& row : *rows) list.push_back(transfer::ToJson(row));
    else
        list.push_back(transfer::ToJson(ConformRow{"(all)", name, "failed", "", 0, 0, rows.error().message, ""}));
    MarkPhase("closing backends");
    return {{"rows", list}, {"backends", backends}};
}

int Conform(const CommonOptions& options) {
    // The baseline is read before anything else runs: a bad one exits 3 with "file: line N: reason".
    std::optional<ConformBaseline> baseline;
    if (!options.baseline.empty()) {
        auto loaded = LoadConformBaseline(options.baseline);
        if (!loaded) {
            std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
            return kExitBadScene;
        }
        baseline = std::move(*loaded);
    }
    auto session = Session::Open(options, "conform");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::printf("conformance of scene %s (%ux%ux%u, %u steps) against the cpu backend\n", scene.name.c_str(),
                scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps);
    // The CPU is the reference; the others are opened as asked, less the CPU,
    // each in a process of its own with a CPU reference of its own.
    std::vector<std::string> names;
    for (const std::string& name : (*session)->RequestedBackends(BuiltBackends()))
        if (name != "cpu") names.push_back(name);
    std::vector<ConformRow> rows;
    if (names.empty()) {
        // Nothing to compare; the CPU is still opened (in a child) for the provenance.
        IsolatedOutcome outcome = RunIsolated("backend cpu", IsolationFrom(options), [&](const SendMessage&) {
            (*session)->OpenBackends({"cpu"}, nullptr, /*report=*/false);
            return transfer::ToJson((*session)->BackendRecords().back());
        });
        if (outcome.result) (*session)->AddBackendRecord(transfer::ProvenanceFromJson(*outcome.result));
    }
    // One backend's rows, from its own process; `crashed` when the process died.
    auto runBackend = [&](const std::string& name, uint32_t attempt, bool& crashed) -> std::optional<
                          std::vector<ConformRow>> {
        std::vector<ConformRow> got;
        IsolatedOutcome outcome = RunIsolated("backend " + name, IsolationFrom(options),
                                              [&](const SendMessage& send) {
                                                  return IsolatedConformance(**session, name, send, attempt);
                                              });
        if (!outcome.result) {
            const ChildFailure& failure = *outcome.failure;
            std::fprintf(stderr, "backend %s %s\n", name.c_str(), failure.Describe().c_str());
            if (attempt == 0)
                (*session)->AddBackendRecord(
                    {name, failure.stage == "opening backend" ? "unavailable" : "available", "", failure.Describe()});
            // The comparisons of the steps it finished are kept, each row's worst over those steps.
            std::string kept;
            if (!outcome.messages.empty()) {
                const nlohmann::json& last = outcome.messages.back();
                for (const nlohmann::json& row : last["rows"]) got.push_back(transfer::ConformRowFromJson(row));
                kept = "; rows above cover steps 0-" + std::to_string(last["step"].get<uint32_t>());
            }
            got.push_back({"(all)", name, failure.status, "", 0, 0, failure.Describe() + kept, ""});
            crashed = true;
            return got;
        }
        const nlohmann::json& r = *outcome.result;
        if (attempt == 0)
            for (const nlohmann::json& record : r["backends"])
                (*session)->AddBackendRecord(transfer::ProvenanceFromJson(record));
        if (r.contains("error")) {
            std::fprintf(stderr, "conform: %s\n", r["error"].get<std::string>().c_str());
            return std::nullopt;
        }
        for (const nlohmann::json& row : r["rows"]) got.push_back(transfer::ConformRowFromJson(row));
        return got;
    };
    for (const std::string& name : names) {
        bool crashed = false;
        auto got = runBackend(name, 0, crashed);
        if (!got) return kExitFailed;
        // --flake-reruns: the backend's whole comparison again (a single stage cannot be rerun alone: its
        // inputs are the CPU's of that step), until no row fails. A crash that then passes is flaky too.
        for (uint32_t attempt = 1; attempt <= options.flakeReruns && std::ranges::any_of(*got, IsConformFailure);
             ++attempt) {
            std::printf("backend %s: rerun %u of %u for its failing rows\n", name.c_str(), attempt,
                        options.flakeReruns);
            bool crashedAgain = false;
            auto again = runBackend(name, attempt, crashedAgain);
            if (!again) return kExitFailed;
            // A first run that crashed: its rows of the steps it finished are merged, the rerun's other rows
            // added, and the crash row "(all)" is flaky.
            auto all = std::ranges::find_if(*got, [](const ConformRow& r) { return r.stage == "(all)"; });
            if (all != got->end() && !crashedAgain) {
                ConformRow flaky = *all;
                flaky.status = "flaky";
                flaky.detail = "passed on rerun " + std::to_string(attempt) + "; the first run: " + all->status +
                               ", " + all->detail;
                got->erase(all);
                MergeRerun(*got, *again, attempt);
                for (const ConformRow& r : *again)
                    if (std::ranges::none_of(*got, [&](const ConformRow& g) { return g.stage == r.stage; }))
                        got->push_back(r);
                got->push_back(flaky);
                continue;
            }
            MergeRerun(*got, *again, attempt);
        }
        rows.insert(rows.end(), got->begin(), got->end());
    }
    if (baseline) ApplyBaseline(rows, *baseline);
    report::Report report("Conformance of " + scene.name);
    report.sections.push_back({"", {ConformTable(rows)}});
    std::printf("%s", report::RenderText(report.sections[0]).c_str());
    nlohmann::json doc = ConformJson(scene, rows);
    // The automaton layout is gl's command-line option, not the scene's.
    if (doc["coverage"].contains("ca"))
        for (const nlohmann::json& backend : doc["coverage"]["ca"]["compared_on"])
            if (backend == "gl") doc["coverage"]["ca"]["options"]["gl_ca_layout"] = gl::CaLayoutName(options.glCaLayout);
    doc["flake_reruns"] = options.flakeReruns;
    doc["baseline"] = options.baseline;
    doc["report"] = report::RenderJson(report);
    const std::string path = (*session)->OutDir() + "/conform.json";
    if (Status s = (*session)->WriteJson(path, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    const std::string csvPath = (*session)->OutDir() + "/conform.csv";
    if (Status s = Session::WriteText(csvPath, ConformCsv(rows)); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s, %s\n", path.c_str(), csvPath.c_str());
    return ConformExitCode(rows);
}

const CommandRegistration kRegistration({
    .name = "conform",
    .summary = "Check every backend's stages against the CPU on a scene",
    .help = kHelp,
    .helpOrder = 2,
    .extraOptions = WithIsolationOptions({
        TextOption("--baseline", &CommonOptions::baseline, "--baseline needs a file of known failures"),
        {"--flake-reruns", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             char* end = nullptr;
             const unsigned long n = v && *v ? std::strtoul(v, &end, 10) : 0;
             if (!v || !*v || *end || v[0] == '-' || n > 100) return "--flake-reruns needs a count from 0 to 100";
             o.flakeReruns = uint32_t(n);
             return std::nullopt;
         }},
    }),
    .run = Conform,
});

}  // namespace
}  // namespace cb
