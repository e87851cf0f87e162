// `cloudbench count`: exact mode (docs/performance.md). Counts the
// instructions of every stage call under callgrind at one thread and writes
// them, summed over the steps after warm-up and step by step, as
// cloudbench-count/1 JSON. The command runs itself again under valgrind; in
// that child role (RUNNING_ON_VALGRIND) it only steps the scene, and the stage
// brackets of harness/run/StageCall.cpp write one dump per call.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/base/CallgrindRequests.h"
#include "harness/perf/CallgrindCount.h"
#include "harness/run/Session.h"
#include "harness/run/Simulation.h"

namespace cb {
namespace {

constexpr const char* kHelp = R"(usage: cloudbench count [SCENE] [options]

Exact mode: counts the instructions of every stage call of SCENE (default:
thesis-medium) under valgrind's callgrind, on the CPU backend at one thread,
and writes FILE (default: out/<scene name>/count.json, format cloudbench-count/1):
each stage's count summed over the steps after warm-up, and each step's count.
The same binary and scene give the same counts on every run, so a change of
2 % is a change of the code, not noise. The run costs about 15 to 20 times a
plain run's CPU time. Needs valgrind and a build without -march=native:
  cmake --preset exact && cmake --build --preset exact
  build/exact/cloudbench count ci-small

Options:
  --backend cpu      the backend counted (only cpu: see docs/performance.md);
                     --backends is the same
  --steps N          number of steps, warm-up included (same as --set steps=N)
  --out FILE         the JSON file written
  --set PATH=VALUE   override a scene field by its dotted path
  --threads 1        the only thread count: at 2 threads counts vary from run
                     to run (up to 0.57 %, docs/performance.md "Stable")
  --cpu-isa ISA      the CPU kernels' SIMD target counted (default: the best
                     valgrind's CPU reports): scalar, sse4, avx2 or avx512
  --quiet            no progress lines
  --gl-context, --gl-ca-layout, --vk-device
                     accepted as by every scene command, and unused: only
                     the CPU backend is counted

Exit codes: 0 counted, 1 the counting run failed or FILE could not be written,
2 bad command line, 3 bad scene, 4 this binary cannot count (built with
-march=native or without valgrind's headers, or valgrind is not installed).
)";

// The backends whose counts are the same from run to run (docs/performance.md, "Exact mode").
constexpr std::string_view kCountedBackends[] = {"cpu"};

std::string FileFolder(const std::string& path) {
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    return folder.empty() ? "." : folder.string();
}

// The child role, under valgrind: steps the scene on the one backend and
// writes {"device": ...} to --out for the parent.
int CountChild(const CommonOptions& options) {
    auto session = Session::Open(options, "");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    const std::vector<std::string> names = (*session)->RequestedBackends({"cpu"});
    std::vector<OpenedBackend> opened = (*session)->OpenBackends(names, &scene);
    if (opened.size() != 1 || !opened[0].backend) return kExitNoBackend;
    Backend& backend = *opened[0].backend;
    auto sim = Simulation::Create(scene, backend);
    if (!sim) {
        std::fprintf(stderr, "%s\n", sim.error().message.c_str());
        return kExitFailed;
    }
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        if (Status status = (*sim)->Step(record); !status) {
            std::fprintf(stderr, "step %u: %s\n", t, status.error().message.c_str());
            return kExitFailed;
        }
    }
    if (Status s = Session::WriteText(options.outDir, nlohmann::json{{"device", backend.Device()}}.dump() + "\n"); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    return kExitOk;
}

int Count(const CommonOptions& options) {
    if (RunningOnValgrind()) return CountChild(options);
    if (options.cpuThreads > 1) {
        std::fprintf(stderr, "cloudbench: count: --threads must be 1 (at 2 threads the counts vary from run to run, up to 0.57 %% in docs/performance.md)\n");
        return kExitUsage;
    }
    auto session = Session::Open(options, "");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    const std::vector<std::string> backends = (*session)->RequestedBackends({"cpu"});
    for (const std::string& name : backends)
        if (std::ranges::find(kCountedBackends, name) == std::end(kCountedBackends)) {
            std::fprintf(stderr,
                         "cloudbench: count: backend %s is not counted: only cpu gives the same counts on every run "
                         "(docs/performance.md, \"Exact mode\")\n",
                         name.c_str());
            return kExitUsage;
        }
    if (scene.steps <= scene.warmupSteps) {
        std::fprintf(stderr, "cloudbench: count: nothing to count: %s runs %u steps, all of them warm-up (%u)\n",
                     scene.name.c_str(), scene.steps, scene.warmupSteps);
        return kExitUsage;
    }
    const std::string flags = (*session)->Provenance()["build"]["flags"].get<std::string>();
    if (auto why = WhyCannotCount(flags)) {
        std::fprintf(stderr, "cloudbench: count: %s\n", why->c_str());
        return kExitNoBackend;
    }
    auto self = SelfExecutable();
    if (!self) {
        std::fprintf(stderr, "cloudbench: count: %s\n", self.error().message.c_str());
        return kExitFailed;
    }
    const std::string outFile = options.outDir.empty() ? "out/" + scene.name + "/count.json" : options.outDir;
    if (Status made = MakeFolder(FileFolder(outFile)); !made) {
        std::fprintf(stderr, "%s\n", made.error().message.c_str());
        return kExitFailed;
    }
    std::printf("scene %s: %ux%ux%u voxels, %u steps (%u warm-up), counted under callgrind at 1 thread\n",
                scene.name.c_str(), scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps,
                scene.warmupSteps);

    nlohmann::json instructions, perStep, wall;
    std::string valgrindVersion;
    for (const std::string& name : backends) {
        CountRequest request{.scenePath = (*session)->ScenePath(), .overrides = options.overrides, .backend = name, .extraArgs = {}};
        // The child counts the target this command was given (valgrind's CPU decides an automatic one).
        if (options.cpuIsa != cpu::CpuIsa::Auto)
            request.extraArgs = {"--cpu-isa", std::string(cpu::CpuIsaName(options.cpuIsa))};
        auto run = CountUnderCallgrind(*self, request);
        if (!run) {
            std::fprintf(stderr, "cloudbench: count: backend %s: %s\n", name.c_str(), run.error().message.c_str());
            return kExitFailed;
        }
        (*session)->AddBackendRecord({name, "available", run->device, ""});
        valgrindVersion = run->valgrindVersion;
        wall[name] = run->wallSeconds;
        std::printf("%s (%s): %.1f s under callgrind\n  %-14s %16s %14s %14s\n", name.c_str(), run->device.c_str(),
                    run->wallSeconds, "stage", "instructions", "min per step", "max per step");
        for (const auto& [stage, steps] : run->counts[name]) {
            uint64_t total = 0, low = UINT64_MAX, high = 0;
            bool counted = false;
            for (const auto& [step, count] : steps) {
                perStep[scene.name][name][stage][std::to_string(step)] = count;
                if (step < scene.warmupSteps) continue;
                counted = true;
                total += count;
                low = std::min(low, count);
                high = std::max(high, count);
            }
            if (!counted) continue;  // it ran in the warm-up only
            instructions[scene.name][name][stage] = total;
            std::printf("  %-14s %16llu %14llu %14llu\n", stage.c_str(), (unsigned long long)total,
                        (unsigned long long)low, (unsigned long long)high);
        }
    }
    nlohmann::json doc = {
        {"format", "cloudbench-count/1"},
        {"tool",
         {{"valgrind", valgrindVersion}, {"options", CallgrindOptions("<dump>", "<log>")}, {"threads", 1}}},
        {"scene", scene.name},
        {"steps", scene.steps},
        {"warmup_steps", scene.warmupSteps},
        {"counted_steps", {scene.warmupSteps, scene.steps - 1}},
        {"instructions", instructions},
        {"per_step", perStep},
        {"wall_s", wall},
    };
    if (Status s = (*session)->WriteJson(outFile, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("counts: %s\n", outFile.c_str());
    return kExitOk;
}

const CommandRegistration kRegistration({
    .name = "count",
    .summary = "Count each stage's instructions under callgrind (exact mode), write count.json",
    .help = kHelp,
    .helpOrder = 6,
    .keepsWarmup = true,
    .run = RunWith(Count),
});

}  // namespace
}  // namespace cb
