// `cloudbench conform`: stage-isolated conformance of every backend against
// the CPU on a scene (harness/Conform.h); writes conform.json, exits 5 on a failure.
#include <cstdio>

#include "core/StageDescriptors.h"
#include "harness/Conform.h"
#include "harness/Session.h"

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

const std::string kHelp = kHelpIntro + RulesHelp() + kHelpOptions + GlOptionsHelp();

int Conform(const CommonOptions& options) {
    auto session = Session::Open(options, "conform");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::printf("conformance of scene %s (%ux%ux%u, %u steps) against the cpu backend\n", scene.name.c_str(),
                scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps);
    // The CPU is the reference; the others are opened as asked, less the CPU.
    std::vector<std::string> names;
    for (const std::string& name : (*session)->RequestedBackends(BuiltBackends()))
        if (name != "cpu") names.push_back(name);
    std::vector<OpenedBackend> cpu = (*session)->OpenBackends({"cpu"}, nullptr, /*report=*/false);
    std::vector<OpenedBackend> others = (*session)->OpenBackends(names, nullptr, /*report=*/false);
    if (!cpu[0].backend) {
        std::fprintf(stderr, "conform: %s\n", cpu[0].reason.c_str());
        return kExitFailed;
    }
    auto rows = RunConformance(scene, *cpu[0].backend, others);
    if (!rows) {
        std::fprintf(stderr, "conform: %s\n", rows.error().message.c_str());
        return kExitFailed;
    }
    report::Report report("Conformance of " + scene.name);
    report.sections.push_back({"", {ConformTable(*rows)}});
    std::printf("%s", report::RenderText(report.sections[0]).c_str());
    nlohmann::json doc = ConformJson(scene, *rows);
    doc["report"] = report::RenderJson(report);
    const std::string path = (*session)->OutDir() + "/conform.json";
    if (Status s = (*session)->WriteJson(path, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s\n", path.c_str());
    bool failed = false, compared = false;
    for (const ConformRow& r : *rows) {
        failed |= r.status == "fail";
        compared |= r.status != "skipped";
    }
    if (failed) return kExitNonConformant;
    return compared ? kExitOk : kExitNoBackend;
}

const CommandRegistration kRegistration({
    .name = "conform",
    .summary = "Check every backend's stages against the CPU on a scene",
    .help = kHelp,
    .helpOrder = 2,
    .run = Conform,
});

}  // namespace
}  // namespace cb
