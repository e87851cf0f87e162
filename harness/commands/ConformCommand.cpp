// `cloudbench conform`: stage-isolated conformance of every backend against
// the CPU on a scene (harness/Conform.h); writes conform.json, exits 5 on a failure.
#include <cstdio>

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
it is, writes DIR/conform.json, and exits 5 if any check fails. Stages a
backend lacks are listed as skipped.

Options:
  --backend LIST     backends to check (default: all built; cpu is the reference)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/conform)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --vk-device DEV    Vulkan device: index or part of the name
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
    }
    return text + "\n";
}

const std::string kHelp = kHelpIntro + RulesHelp() + kHelpOptions + GlOptionsHelp() + IsolationOptionsHelp();

// One backend's conformance against the CPU, in its own process when isolated:
// both are opened there. Returns {"rows": [...], "backends": [provenance...]},
// or {"error": ...} when the CPU reference cannot be opened.
// After each step it sends {"step": t, "rows": [...]}, the rows so far, so that a
// backend whose process dies later keeps the comparisons it finished.
nlohmann::json IsolatedConformance(Session& session, const std::string& name, const SendMessage& send) {
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
                               session.OutDir());
    nlohmann::json list = nlohmann::json::array();
    if (rows)
        for (const ConformRow& row : *rows) list.push_back(transfer::ToJson(row));
    else
        list.push_back(transfer::ToJson(ConformRow{"(all)", name, "failed", "", 0, 0, rows.error().message, ""}));
    MarkPhase("closing backends");
    return {{"rows", list}, {"backends", backends}};
}

int Conform(const CommonOptions& options) {
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
    bool anyCrashed = false;
    if (names.empty()) {
        // Nothing to compare; the CPU is still opened (in a child) for the provenance.
        IsolatedOutcome outcome = RunIsolated("backend cpu", IsolationFrom(options), [&](const SendMessage&) {
            (*session)->OpenBackends({"cpu"}, nullptr, /*report=*/false);
            return transfer::ToJson((*session)->BackendRecords().back());
        });
        if (outcome.result) (*session)->AddBackendRecord(transfer::ProvenanceFromJson(*outcome.result));
    }
    for (const std::string& name : names) {
        IsolatedOutcome outcome = RunIsolated("backend " + name, IsolationFrom(options),
                                              [&](const SendMessage& send) {
                                                  return IsolatedConformance(**session, name, send);
                                              });
        if (!outcome.result) {
            const ChildFailure& failure = *outcome.failure;
            std::fprintf(stderr, "backend %s %s\n", name.c_str(), failure.Describe().c_str());
            (*session)->AddBackendRecord(
                {name, failure.stage == "opening backend" ? "unavailable" : "available", "", failure.Describe()});
            // The comparisons of the steps it finished are kept, each row's worst over those steps.
            std::string kept;
            if (!outcome.messages.empty()) {
                const nlohmann::json& last = outcome.messages.back();
                for (const nlohmann::json& row : last["rows"]) rows.push_back(transfer::ConformRowFromJson(row));
                kept = "; rows above cover steps 0-" + std::to_string(last["step"].get<uint32_t>());
            }
            rows.push_back({"(all)", name, failure.status, "", 0, 0, failure.Describe() + kept, ""});
            anyCrashed = true;
            continue;
        }
        const nlohmann::json& r = *outcome.result;
        for (const nlohmann::json& record : r["backends"])
            (*session)->AddBackendRecord(transfer::ProvenanceFromJson(record));
        if (r.contains("error")) {
            std::fprintf(stderr, "conform: %s\n", r["error"].get<std::string>().c_str());
            return kExitFailed;
        }
        for (const nlohmann::json& row : r["rows"]) rows.push_back(transfer::ConformRowFromJson(row));
    }
    report::Report report("Conformance of " + scene.name);
    report.sections.push_back({"", {ConformTable(rows)}});
    std::printf("%s", report::RenderText(report.sections[0]).c_str());
    nlohmann::json doc = ConformJson(scene, rows);
    doc["report"] = report::RenderJson(report);
    const std::string path = (*session)->OutDir() + "/conform.json";
    if (Status s = (*session)->WriteJson(path, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s\n", path.c_str());
    bool failed = false, compared = false, broken = anyCrashed;
    for (const ConformRow& r : rows) {
        failed |= r.status == "fail";
        broken |= r.status == "failed";
        compared |= r.status != "skipped";
    }
    // A backend that crashed or could not run its stages is a failure (1), before a check that failed (5).
    if (broken) return kExitFailed;
    if (failed) return kExitNonConformant;
    return compared ? kExitOk : kExitNoBackend;
}

const CommandRegistration kRegistration({
    .name = "conform",
    .summary = "Check every backend's stages against the CPU on a scene",
    .help = kHelp,
    .helpOrder = 2,
    .extraOptions = IsolationOptions(),
    .run = Conform,
});

}  // namespace
}  // namespace cb
