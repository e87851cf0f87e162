// The `cloudbench` subcommands. Each returns the process exit code
// (docs/cli.md): 0 success, 1 a stage failed or an output could not be written,
// 2 bad command line, 3 bad scene, 4 none of the requested backends available,
// 5 a conformance check failed.
#pragma once

#include <string>
#include <vector>

#include "core/Backend.h"
#include "core/Scene.h"

namespace cb {

enum ExitCode : int {
    kExitOk = 0,
    kExitFailed = 1,
    kExitUsage = 2,
    kExitBadScene = 3,
    kExitNoBackend = 4,
    kExitNonConformant = 5,
};

struct CommonOptions {
    std::string scene;                    // name in scenes/ or a path; "" = default scene
    std::vector<std::string> backends;    // empty = every built backend (run) / cpu (dump)
    std::vector<SceneOverride> overrides; // --set, and --steps as "steps"
    std::string outDir;                   // "" = out/<scene name>[/dump]
    int cpuThreads = 0;
    std::string vkDevice;                 // --vk-device INDEX|NAME
    std::string glContext;                // --gl-context osmesa|egl
    std::string glCaLayout;               // --gl-ca-layout packed|rgba8
    bool quiet = false;
    // Accuracy (docs/accuracy.md): dump --reference; sweep --vary PATH=V1,V2;
    // timed calls per measurement; accuracy --switches; sweep --metric.
    bool reference = false;
    std::vector<std::string> vary;
    int repeats = 5;
    bool switches = false;
    std::string metric = "max";

    BackendOptions Backend() const {
        BackendOptions b;
        b.cpuThreads = cpuThreads;
        b.vkDevice = vkDevice;
        b.glContext = glContext;
        b.glCaLayout = glCaLayout;
        return b;
    }
};

// Creates `dir` and its parents; the error names the folder and the reason.
Status MakeOutDir(const std::string& dir);

int RunCommand(const CommonOptions& options);
int DumpCommand(const CommonOptions& options);
// Lists the Vulkan devices (and says which other backends this build has).
int DevicesCommand();
int ConformCommand(const CommonOptions& options);
// Every shade and shadow option's error against the exact reference, per backend.
int AccuracyCommand(const CommonOptions& options);
// The cartesian product of --vary values: time and error per point, Pareto front.
int SweepCommand(const CommonOptions& options);

class Simulation;
// dump --reference: writes T_ref.npy (with shade) and shadow_ref.npy (with
// shadow) of the simulation's current step into `dir`.
Status WriteReferenceDump(const Simulation& simulation, const std::string& dir, int threads);

// scenes/<name>.json for a bare name, the argument itself for a path.
std::string ResolveScenePath(const std::string& nameOrPath);
inline constexpr const char* kDefaultScene = "thesis-medium";

}  // namespace cb
