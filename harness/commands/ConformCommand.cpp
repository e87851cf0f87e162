// `cloudbench conform`: stage-isolated conformance of every backend against
// the CPU on a scene (harness/conform/Conform.h); writes conform.json and conform.csv,
// exits 5 on a failure; --baseline and --flake-reruns as deqp-runner's, and
// --matrix / --vary to compare over cases of options (harness/conform/ConformMatrix.h, docs/cli.md).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "core/plan/StageGraph.h"
#include "harness/commands/SweepOutput.h"
#include "harness/conform/Conform.h"
#include "harness/conform/ConformMatrix.h"
#include "harness/conform/ConformTransfer.h"
#include "harness/platform/Isolation.h"
#include "harness/run/RunTransfer.h"
#include "harness/run/Session.h"

namespace cb {
namespace {

constexpr const char* kHelpIntro = R"(usage: cloudbench conform [SCENE] [options]

Runs SCENE on the CPU and, at every step, feeds each other backend's stages
the CPU's inputs of that step (stage-isolated conformance), and compares their
outputs by SPEC's rule for the stage (each stage's descriptor, core/stages/<stage>/):
)";
constexpr const char* kHelpOptions = R"(Prints stage x backend with the result, the rule and the worst error with where
it is, writes DIR/conform.json and DIR/conform.csv, and exits 5 if any check
fails. Stages a backend lacks are listed as skipped.

Options:
  --backend LIST     backends to check (default: all built; cpu is the reference);
                     --backends is the same
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/conform)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --threads N        CPU backend threads (default: all)
  --cpu-isa ISA      CPU kernels' SIMD target: auto (default: the best here), scalar, sse4, avx2, avx512
  --quiet            no progress lines
  --vk-device DEV    Vulkan device: index or part of the name
  --baseline FILE    known failures, "stage,backend,status" a line (a conform.csv
                     will do): a listed failure is expected-fail and does not fail
                     the command; a listed row that passes is unexpected-pass (exit 5)
  --junit FILE       also write the rows as JUnit XML for a CI system: a test
                     case per stage x backend (x case), failures with the worst
                     difference, the tolerance and the rule
  --flake-reruns N   rerun a backend with a failing row up to N times (its whole
                     comparison); a row that then passes is flaky, not a failure
  --matrix           compare over the built-in option set, one option at a time
                     from the scene's own settings: each case is the scene with
                     the overrides it is named by ("shade.storage=fp16", ...;
                     "scene" for none). Every value of smooth.radius, shade.*,
                     phase.function, shadow.form, render.culling/skipping, the
                     sun on each principal axis, ca.wind_shift on/off and gl's
                     other automaton layout (docs/cli.md lists them). Rows,
                     conform.csv and the baseline carry the case; difference
                     images go to DIR/<case>/
  --vary PATH=V1,... cases of a cartesian product, as sweep's (with --matrix:
                     added after the built-in cases)
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
nlohmann::json IsolatedConformance(Session& session, const std::string& name, const SendMessage& send, uint32_t attempt,
                                   const std::string& caseName) {
    MarkPhase("opening backend");
    std::vector<OpenedBackend> cpu = session.OpenBackends({"cpu"}, nullptr, /*report=*/false);
    std::vector<OpenedBackend> other = session.OpenBackends({name}, nullptr, /*report=*/false);
    nlohmann::json backends = nlohmann::json::array();
    for (const BackendProvenance& record : session.BackendRecords()) backends.push_back(transfer::ToJson(record));
    if (!cpu[0].backend) return {{"error", cpu[0].reason}, {"backends", backends}};
    auto rows = RunConformance(
        session.GetScene(), *cpu[0].backend, other,
        [&](uint32_t step, const std::vector<ConformRow>& soFar) {
            nlohmann::json list = nlohmann::json::array();
            for (const ConformRow& row : soFar) list.push_back(transfer::ToJson(row));
            send({{"step", step}, {"rows", list}});
        },
        session.OutDir(), attempt, caseName);
    nlohmann::json list = nlohmann::json::array();
    if (rows)
        for (const ConformRow& row : *rows) list.push_back(transfer::ToJson(row));
    else
        list.push_back(transfer::ToJson(ConformRow{"(all)", name, "failed", "", 0, 0, rows.error().message, "", ""}));
    MarkPhase("closing backends");
    return {{"rows", list}, {"backends", backends}};
}

// conform's own options (docs/cli.md).
struct ConformOptions : OwnOptions {
    std::string baseline;           // --baseline FILE: known failures
    uint32_t flakeReruns = 0;       // --flake-reruns N
    bool matrix = false;            // --matrix: the stages' choice settings (harness/conform/ConformMatrix.h)
    std::vector<std::string> vary;  // --vary PATH=V1,V2,...
    std::string junit;              // --junit FILE: the rows as JUnit XML
};

int Conform(const CommonOptions& options, const ConformOptions& own) {
    // The baseline is read before anything else runs: a bad one exits 3 with "file: line N: reason".
    std::optional<ConformBaseline> baseline;
    if (!own.baseline.empty()) {
        auto loaded = LoadConformBaseline(own.baseline);
        if (!loaded) {
            std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
            return kExitBadScene;
        }
        baseline = std::move(*loaded);
    }
    std::vector<SweepAxis> axes;
    if (!own.vary.empty()) {
        auto parsed = ParseVaryAxes(own.vary);
        if (!parsed) {
            std::fprintf(stderr, "conform: %s\n", parsed.error().c_str());
            return kExitUsage;
        }
        axes = std::move(*parsed);
    }
    auto session = Session::Open(options, "conform");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    // The CPU is the reference; the others are opened as asked, less the CPU,
    // each in a process of its own with a CPU reference of its own.
    std::vector<std::string> names;
    for (const std::string& name : (*session)->RequestedBackends(BuiltBackends()))
        if (name != "cpu") names.push_back(name);
    // The cases: the scene alone, or --matrix's and --vary's, each validated before anything runs.
    const bool byCase = own.matrix || !axes.empty();
    std::vector<ConformCase> cases;
    if (own.matrix)
        cases = ConformMatrixCases(scene, options.glCaLayout, std::ranges::find(names, "gl") != names.end());
    for (ConformCase& c : ConformVaryCases(axes))
        if (std::ranges::none_of(cases, [&](const ConformCase& k) { return k.name == c.name; }))
            cases.push_back(std::move(c));
    if (!byCase) cases.push_back({"", {}, std::nullopt, {}});
    std::vector<Scene> caseScenes;
    for (const ConformCase& c : cases) {
        auto variant = (*session)->LoadVariant(c.overrides);
        if (!variant) {
            std::fprintf(stderr, "conform: case %s:\n%s\n", c.name.c_str(), variant.error().message.c_str());
            return kExitBadScene;
        }
        caseScenes.push_back(std::move(*variant));
    }
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::printf("conformance of scene %s (%ux%ux%u, %u %s) against the cpu backend\n", scene.name.c_str(),
                scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps,
                scene.steps == 1 ? "step" : "steps");
    if (byCase) std::printf("%zu cases\n", cases.size());
    std::vector<ConformRow> rows;
    if (names.empty()) {
        // Nothing to compare; the CPU is still opened (in a child) for the provenance.
        IsolatedOutcome outcome = RunIsolated("backend cpu", IsolationFrom(options), [&](const SendMessage&) {
            (*session)->OpenBackends({"cpu"}, nullptr, /*report=*/false);
            return transfer::ToJson((*session)->BackendRecords().back());
        });
        if (outcome.result) (*session)->AddBackendRecord(transfer::ProvenanceFromJson(*outcome.result));
    }
    // One backend's rows in one case, from its own process; `crashed` when the process died.
    auto runBackend = [&](Session& caseSession, const std::string& caseName, const std::string& name, uint32_t attempt,
                          bool& crashed) -> std::optional<std::vector<ConformRow>> {
        std::vector<ConformRow> got;
        IsolatedOutcome outcome = RunIsolated("backend " + name, IsolationFrom(options), [&](const SendMessage& send) {
            return IsolatedConformance(caseSession, name, send, attempt, caseName);
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
            got.push_back({"(all)", name, failure.status, "", 0, 0, failure.Describe() + kept, "", ""});
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
    for (size_t k = 0; k < cases.size(); ++k) {
        const ConformCase& c = cases[k];
        // A case runs in a session of its own: the scene with the case's overrides, gl's layout, and its
        // difference images in DIR/<case>/.
        CommonOptions caseOptions = options;
        caseOptions.overrides.insert(caseOptions.overrides.end(), c.overrides.begin(), c.overrides.end());
        if (c.glCaLayout) caseOptions.glCaLayout = *c.glCaLayout;
        std::unique_ptr<Session> ownSession;
        Session* caseSession = session->get();
        if (byCase) {
            caseOptions.outDir = (*session)->OutDir() + "/" + ConformCaseFolder(c.name);
            auto opened = Session::Open(caseOptions, "conform");
            if (!opened) return opened.error();
            ownSession = std::move(*opened);
            caseSession = ownSession.get();
            if (Status made = MakeFolder(caseSession->OutDir()); !made) {
                std::fprintf(stderr, "%s\n", made.error().message.c_str());
                return kExitFailed;
            }
            if (!options.quiet) {
                std::printf("case %zu/%zu: %s\n", k + 1, cases.size(), c.name.c_str());
                std::fflush(stdout);
            }
        }
        for (const std::string& name : names) {
            if (!c.onlyBackends.empty() && std::ranges::find(c.onlyBackends, name) == c.onlyBackends.end()) continue;
            bool crashed = false;
            auto got = runBackend(*caseSession, c.name, name, 0, crashed);
            if (!got) return kExitFailed;
            // --flake-reruns: the backend's whole comparison in this case again (a single stage cannot be rerun
            // alone: its inputs are the CPU's of that step), until no row fails. A crash that then passes is
            // flaky too.
            for (uint32_t attempt = 1; attempt <= own.flakeReruns && std::ranges::any_of(*got, IsConformFailure);
                 ++attempt) {
                std::printf("backend %s%s: rerun %u of %u for its failing rows\n", name.c_str(),
                            byCase ? (" in case " + c.name).c_str() : "", attempt, own.flakeReruns);
                bool crashedAgain = false;
                auto again = runBackend(*caseSession, c.name, name, attempt, crashedAgain);
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
            for (ConformRow& r : *got) r.caseName = c.name;
            rows.insert(rows.end(), got->begin(), got->end());
        }
    }
    if (baseline) ApplyBaseline(rows, *baseline);
    report::Report report("Conformance of " + scene.name);
    report.sections.push_back({"", {ConformTable(rows)}});
    std::printf("%s", report::RenderText(report.sections[0]).c_str());
    nlohmann::json doc = ConformJson(scene, rows);
    if (byCase) {
        // Each case's overrides, and the coverage over all of them: every value each option was compared under.
        std::vector<ConformCaseScene> scenes;
        nlohmann::json list = nlohmann::json::array();
        for (size_t k = 0; k < cases.size(); ++k) {
            const gl::CaLayout layout = cases[k].glCaLayout.value_or(options.glCaLayout);
            scenes.push_back({cases[k].name, &caseScenes[k], std::string(gl::CaLayoutName(layout))});
            nlohmann::json overrides = nlohmann::json::object();
            for (const SceneOverride& o : cases[k].overrides) overrides[o.path] = o.value;
            nlohmann::json entry = {{"name", cases[k].name}, {"overrides", overrides}};
            if (cases[k].glCaLayout) entry["gl_ca_layout"] = gl::CaLayoutName(*cases[k].glCaLayout);
            if (!cases[k].onlyBackends.empty()) entry["backends"] = cases[k].onlyBackends;
            list.push_back(entry);
        }
        doc["cases"] = list;
        doc["coverage"] = ConformMatrixCoverage(scenes, rows);
        size_t failing = 0;
        for (const ConformCase& c : cases)
            failing += std::ranges::any_of(rows, [&](const ConformRow& r) {
                return r.caseName == c.name && (IsConformFailure(r) || r.status == "unexpected-pass");
            });
        std::printf("%zu of %zu cases with a failing row\n", failing, cases.size());
    } else if (doc["coverage"].contains("ca")) {
        // The automaton layout is gl's command-line option, not the scene's.
        for (const nlohmann::json& backend : doc["coverage"]["ca"]["compared_on"])
            if (backend == "gl")
                doc["coverage"]["ca"]["options"]["gl_ca_layout"] = gl::CaLayoutName(options.glCaLayout);
    }
    doc["flake_reruns"] = own.flakeReruns;
    doc["baseline"] = own.baseline;
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
    if (!own.junit.empty()) {
        if (Status s = Session::WriteText(own.junit, ConformJUnit(rows, scene.name)); !s) {
            std::fprintf(stderr, "%s\n", s.error().message.c_str());
            return kExitFailed;
        }
    }
    std::printf("results: %s, %s%s\n", path.c_str(), csvPath.c_str(),
                own.junit.empty() ? "" : (", " + own.junit).c_str());
    std::printf("conform: %s\n", ConformSummary(rows).c_str());
    return ConformExitCode(rows);
}

const CommandRegistration kRegistration({
    .name = "conform",
    .summary = "Check every backend's stages against the CPU on a scene",
    .help = kHelp,
    .helpOrder = 2,
    .extraOptions = WithIsolationOptions({
        TextOption("--baseline", &ConformOptions::baseline, "--baseline needs a file of known failures"),
        TextOption("--junit", &ConformOptions::junit, "--junit needs a file to write"),
        FlagOption("--matrix", &ConformOptions::matrix),
        ListOption("--vary", &ConformOptions::vary, "--vary needs PATH=V1,V2,..., e.g. --vary smooth.radius=0,2"),
        OwnOption<ConformOptions>("--flake-reruns", true,
                                  [](ConformOptions& o, const char* v) -> std::optional<std::string> {
                                      long long n = 0;
                                      if (auto why = ParseWholeNumber("--flake-reruns", v, 0, 100, n)) return why;
                                      o.flakeReruns = uint32_t(n);
                                      return std::nullopt;
                                  }),
    }),
    .makeOptions = MakeOwnOptions<ConformOptions>,
    .run = RunWith(Conform),
});

}  // namespace
}  // namespace cb
