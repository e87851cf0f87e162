// The `cloudbench` commands: what one command declares (name, help, options,
// run function) and the registry that main() walks. Each command lives in its
// own file under harness/commands/ and registers itself with a
// CommandRegistration; docs/cli.md and CONTRIBUTING.md describe them.
#pragma once

#include <concepts>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
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

// What every command shares on the command line: the scene and its
// overrides, the backends (which, their options, and how they run: crash
// isolation) and the output. A command's own options are its OwnOptions.
struct CommonOptions {
    std::optional<std::string> scene;      // name in scenes/ or a path; none = kDefaultScene; "" is refused
    std::vector<std::string> backends;     // empty = the command's default
    std::vector<SceneOverride> overrides;  // --set, and --steps as "steps"
    std::string outDir;                    // "" = the command's default under out/<scene name>
    int cpuThreads = 0;
    cpu::CpuIsa cpuIsa = cpu::CpuIsa::Auto;               // --cpu-isa, already applied when parsed
    std::string vkDevice;                                 // --vk-device INDEX|NAME
    gl::ContextKind glContext = gl::ContextKind::OSMesa;  // --gl-context, gl::kContextKindNames
    gl::CaLayout glCaLayout = gl::CaLayout::Packed;       // --gl-ca-layout, gl::kCaLayoutNames
    bool quiet = false;
    // Crash isolation (harness/platform/Isolation.h): --no-isolation, --backend-timeout SECONDS (0 = none).
    bool noIsolation = false;
    double backendTimeout = 3600;
    // The positional arguments of a command that takes them rather than a scene
    // (Command::takesArguments: report's files), or, for a command with
    // Command::rawArguments (perf), every argument after its name, unparsed.
    std::vector<std::string> arguments;
    // argv as given, for the provenance of the outputs.
    std::vector<std::string> commandLine;

    BackendOptions Backend() const;
};

// A command's own options: a struct deriving from this (RunOptions in
// RunCommand.cpp, ConformOptions, ...), made fresh for each command line
// (Command::makeOptions) and filled by the command's own OptionSpecs.
struct OwnOptions {
    virtual ~OwnOptions() = default;
};

// The own options of the commands that measure against the exact reference
// (accuracy, sweep): timed calls per measurement (--repeat) and the step of
// the exact reference render in voxel edges (--reference-step).
struct MeasurementOptions : OwnOptions {
    int repeats = 5;
    double referenceStep = 0.125;
};

// One command-line option. Its apply function stores the value (nullptr for a
// flag) and returns a usage message when the value is missing or wrong: a
// shared option's `apply` into CommonOptions, a command's own option's
// `applyOwn` into the command's OwnOptions. One of the two is set.
struct OptionSpec {
    using Apply = std::function<std::optional<std::string>(CommonOptions&, const char* value)>;
    using ApplyOwn = std::function<std::optional<std::string>(OwnOptions&, const char* value)>;
    std::string_view name;
    std::string_view alias;  // "" = none
    bool takesValue = false;
    Apply apply;
    ApplyOwn applyOwn = {};
};

// A command's own option of options type `Own`: `apply` gets them as Own.
template <typename Own>
requires std::derived_from<Own, OwnOptions> OptionSpec OwnOption(
    std::string_view name, bool takesValue, std::function<std::optional<std::string>(Own&, const char* value)> apply) {
    return {name, "", takesValue, {}, [apply](OwnOptions& own, const char* value) {
                return apply(dynamic_cast<Own&>(own), value);
            }};
}

// A flag that sets `field`.
OptionSpec FlagOption(std::string_view name, bool CommonOptions::*field);
// An option whose value is stored in `field` (appended, for a list); `missing`
// is the usage message when the value is missing. TextOption refuses an empty
// value: "--x: must not be empty".
OptionSpec TextOption(std::string_view name, std::string CommonOptions::*field, std::string missing);
// What TextOption does with a value: `missing` for none, a refusal for "", else stores it.
std::optional<std::string> StoreText(std::string_view name, std::string& field, const char* value,
                                     const std::string& missing);

// The same for a command's own options.
template <typename Own>
requires std::derived_from<Own, OwnOptions> OptionSpec FlagOption(std::string_view name, bool Own::*field) {
    return OwnOption<Own>(name, false, [field](Own& o, const char*) -> std::optional<std::string> {
        o.*field = true;
        return std::nullopt;
    });
}
template <typename Own>
requires std::derived_from<Own, OwnOptions> OptionSpec TextOption(std::string_view name, std::string Own::*field,
                                                                  std::string missing) {
    return OwnOption<Own>(name, true, [=](Own& o, const char* v) { return StoreText(name, o.*field, v, missing); });
}
template <typename Own>
requires std::derived_from<Own, OwnOptions> OptionSpec ListOption(std::string_view name,
                                                                  std::vector<std::string> Own::*field,
                                                                  std::string missing) {
    return OwnOption<Own>(name, true, [=](Own& o, const char* v) -> std::optional<std::string> {
        if (!v) return missing;
        (o.*field).push_back(v);
        return std::nullopt;
    });
}

// Every backend name the registry knows, built in this build or not, sorted: cpu, gl, vk.
std::span<const std::string_view> KnownBackends();

// "OPTION: unknown backend 'x' (known: cpu, gl, vk); did you mean 'cpu'?" when `name` is not in KnownBackends(),
// else nullopt: the one message for a backend named in an option (--backend, perf compare --threshold).
std::optional<std::string> UnknownBackend(std::string_view option, std::string_view name);
// Appends the names of one --backend LIST to `backends`. Returns the usage
// message, and appends nothing, for an empty list or item, a name given twice
// (in `list` or already in `backends`), or a name not in KnownBackends().
std::optional<std::string> ParseBackendList(std::string_view list, std::vector<std::string>& backends);

// The most threads --threads takes: a fixed cap, so that a command line means the same on every machine
// (above the machine's hardware threads TBB adds no threads; docs/cli.md).
inline constexpr long long kMaxCpuThreads = 1024;

// A whole number in [low, high] from an option's value (decimal digits, no sign or space), stored in `out`;
// otherwise the usage message "NAME: needs a whole number in [LOW, HIGH], got 'TEXT'" (without ", got" when
// the value is missing).
std::optional<std::string> ParseWholeNumber(std::string_view name, const char* value, long long low, long long high,
                                            long long& out);

// The options every scene command accepts: --backend, --steps, --out, --set,
// --threads, --gl-context, --gl-ca-layout, --vk-device, --quiet.
std::span<const OptionSpec> SceneCommandOptions();
// The help lines of --gl-context and --gl-ca-layout, their values listed from
// the options' name tables, the default first.
std::string GlOptionsHelp();
// --repeat N and --reference-step X (the exact reference render's step in
// voxel edges, [1/1024, 1]) into MeasurementOptions (accuracy, sweep).
OptionSpec RepeatOption();
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
    // Makes the command's own options, which its extraOptions fill and `run`
    // reads (MakeOwnOptions<T>); by default, none.
    std::function<std::unique_ptr<OwnOptions>()> makeOptions = [] { return std::make_unique<OwnOptions>(); };
    std::function<int(const CommonOptions&, const OwnOptions&)> run;
};

template <typename Own>
std::unique_ptr<OwnOptions> MakeOwnOptions() {
    return std::make_unique<Own>();
}
// Command::run from a run function of the command's own options type.
template <typename Own>
requires std::derived_from<Own, OwnOptions> std::function<int(const CommonOptions&, const OwnOptions&)> RunWith(
    int (*run)(const CommonOptions&, const Own&)) {
    return [run](const CommonOptions& common, const OwnOptions& own) {
        return run(common, dynamic_cast<const Own&>(own));
    };
}
// Command::run from a command without options of its own.
inline std::function<int(const CommonOptions&, const OwnOptions&)> RunWith(int (*run)(const CommonOptions&)) {
    return [run](const CommonOptions& common, const OwnOptions&) { return run(common); };
}

// Adds a command to the registry at static initialisation.
struct CommandRegistration {
    explicit CommandRegistration(Command command);
};

// The registered commands in help order.
std::vector<const Command*> RegisteredCommands();
const Command* FindCommand(std::string_view name);

// The scene file a SCENE argument names: the argument itself for a path (it has a '/' or ends in ".json"), else
// <folder>/<name>.json, the folder being $CLOUDBENCH_SCENES or the shipped scenes/. A bare name with no such file
// is an error that lists the folder's scenes and suggests the nearest: "SCENE: no scene named 'wang20km' (no
// file scenes/wang20km.json); the scenes there: ci-small, ...; did you mean 'wang-20km'?". A path is not checked
// here: the loader's message names it.
Result<std::string> ResolveScenePath(const std::string& nameOrPath);
// The names of the scenes in `folder` (its *.json files without the suffix), sorted; an error when it cannot be
// listed.
Result<std::vector<std::string>> SceneNamesIn(const std::string& folder);
inline constexpr const char* kDefaultScene = "thesis-medium";

}  // namespace cb
