// The `cloudbench` commands: what one command declares (name, help, options,
// run function) and the registry that main() walks. Each command lives in its
// own file under harness/commands/ and registers itself with a
// CommandRegistration; docs/cli.md and CONTRIBUTING.md describe them.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "registry/Registry.h"

namespace cb {

// The process exit codes (docs/cli.md).
enum ExitCode : int {
    kExitOk = 0,
    kExitFailed = 1,  // a stage failed, or an output could not be written
    kExitUsage = 2,   // bad command line
    kExitBadScene = 3,
    kExitNoBackend = 4,  // none of the requested backends is available
    kExitNonConformant = 5,
    kExitRegression = 6,  // perf compare: a confirmed performance regression
};

// What the command line sets; every command reads the fields its options fill.
struct CommonOptions {
    std::optional<std::string> scene;      // name in scenes/ or a path; none = kDefaultScene; "" is refused
    std::vector<std::string> backends;     // empty = the command's default
    std::vector<SceneOverride> overrides;  // --set, and --steps as "steps"
    std::string outDir;                    // "" = the command's default under out/<scene name>
    int cpuThreads = 0;
    std::string vkDevice;                                 // --vk-device INDEX|NAME
    gl::ContextKind glContext = gl::ContextKind::OSMesa;  // --gl-context, gl::kContextKindNames
    gl::CaLayout glCaLayout = gl::CaLayout::Packed;       // --gl-ca-layout, gl::kCaLayoutNames
    bool quiet = false;
    // Crash isolation (harness/platform/Isolation.h): --no-isolation, --backend-timeout SECONDS (0 = none).
    bool noIsolation = false;
    double backendTimeout = 3600;
    // conform: --baseline FILE (known failures) and --flake-reruns N (docs/cli.md).
    std::string baseline;
    uint32_t flakeReruns = 0;
    // conform --matrix: compare over the built-in option set (harness/conform/ConformMatrix.h).
    bool matrix = false;
    // Accuracy (docs/accuracy.md): dump --reference; sweep --vary PATH=V1,V2;
    // timed calls per measurement; accuracy --switches; sweep --metric.
    bool reference = false;
    std::vector<std::string> vary;
    int repeats = 5;
    bool switches = false;
    // accuracy and sweep: the step of the exact reference render, voxel edges (--reference-step).
    double referenceStep = 0.125;
    std::string metric = "max";
    // sweep --shard I/N: share I (1-based) of N; shardCount 0 = not sharded.
    int shardIndex = 0;
    int shardCount = 0;
    // The positional arguments of a command that takes them rather than a scene
    // (Command::takesArguments: report's files), or, for a command with
    // Command::rawArguments (perf), every argument after its name, unparsed.
    std::vector<std::string> arguments;
    // report: --history FILE and -o FILE (docs/cli.md).
    std::string history;
    std::string outFile;
    // run --timing: "synchronized", "pipelined" or "both" (docs/performance.md, "Two ways to time a step").
    std::string timing = "synchronized";
    // run --save-state DIR, --save-state-every N (0 = only at the end), --resume DIR (harness/run/SimulationState.h).
    std::string saveState, resumeState;
    uint32_t saveStateEvery = 0;
    // argv as given, for the provenance of the outputs.
    std::vector<std::string> commandLine;

    BackendOptions Backend() const;
};

// One command-line option. `apply` stores the value (nullptr for a flag) and
// returns a usage message when the value is missing or wrong.
struct OptionSpec {
    std::string_view name;
    std::string_view alias;  // "" = none
    bool takesValue = false;
    std::function<std::optional<std::string>(CommonOptions&, const char* value)> apply;
};

// A flag that sets `field`.
OptionSpec FlagOption(std::string_view name, bool CommonOptions::*field);
// An option whose value is stored in `field` (appended, for a list); `missing`
// is the usage message when the value is missing. TextOption refuses an empty
// value: "--x: must not be empty".
OptionSpec TextOption(std::string_view name, std::string CommonOptions::*field, std::string missing);
OptionSpec ListOption(std::string_view name, std::vector<std::string> CommonOptions::*field, std::string missing);

// Every backend name the registry knows, built in this build or not, sorted: cpu, gl, vk.
std::span<const std::string_view> KnownBackends();

// "OPTION: unknown backend 'x' (known: cpu, gl, vk); did you mean 'cpu'?" when `name` is not in KnownBackends(),
// else nullopt: the one message for a backend named in an option (--backend, perf compare --threshold).
std::optional<std::string> UnknownBackend(std::string_view option, std::string_view name);
// Appends the names of one --backend LIST to `backends`. Returns the usage
// message, and appends nothing, for an empty list or item, a name given twice
// (in `list` or already in `backends`), or a name not in KnownBackends().
std::optional<std::string> ParseBackendList(std::string_view list, std::vector<std::string>& backends);

// The options every scene command accepts: --backend, --steps, --out, --set,
// --threads, --gl-context, --gl-ca-layout, --vk-device, --quiet.
std::span<const OptionSpec> SceneCommandOptions();
// The help lines of --gl-context and --gl-ca-layout, their values listed from
// the options' name tables, the default first.
std::string GlOptionsHelp();
// --repeat N, shared by accuracy and sweep.
OptionSpec RepeatOption();
// --reference-step X: the exact reference render's step in voxel edges, (0, 1] (accuracy, sweep).
OptionSpec ReferenceStepOption();

struct Command {
    std::string_view name;
    std::string_view summary;  // one line in `cloudbench --help`
    std::string_view help;     // `cloudbench help NAME`
    int helpOrder = 0;         // position in `cloudbench --help`
    // Whether the command takes a scene and the scene options; devices does not.
    bool takesScene = true;
    // Whether the scene's warm-up steps are kept (run times them; the others set them to 0).
    bool keepsWarmup = false;
    // Whether it takes any number of arguments (files) into CommonOptions::arguments; only without a scene.
    bool takesArguments = false;
    // Whether the command parses its own arguments (perf's subcommands): main
    // passes them in CommonOptions::arguments and handles only --help.
    bool rawArguments = false;
    std::vector<OptionSpec> extraOptions = {};  // besides SceneCommandOptions()
    std::function<int(const CommonOptions&)> run;
};

// Adds a command to the registry at static initialisation.
struct CommandRegistration {
    explicit CommandRegistration(Command command);
};

// The registered commands in help order.
std::vector<const Command*> RegisteredCommands();
const Command* FindCommand(std::string_view name);

// scenes/<name>.json for a bare name, the argument itself for a path.
std::string ResolveScenePath(const std::string& nameOrPath);
inline constexpr const char* kDefaultScene = "thesis-medium";

}  // namespace cb
