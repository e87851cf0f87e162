#include "harness/platform/Command.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/base/InstallLayout.h"
#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"

namespace cb {
namespace {

std::map<std::string_view, Command>& Registry() {
    static std::map<std::string_view, Command> registry;
    return registry;
}

// A name from the command line as a message shows it (core/base/ShownText.h): printable ASCII, the rest as \xNN, cut
// short.
std::string Shown(std::string_view name) { return ShownArgument(name); }

// An option whose value is one of `table`'s names, stored in `field` as its
// value; otherwise the usage message lists the names: "--x needs a or b".
template <typename Enum, size_t N>
OptionSpec Choice(std::string_view name, Enum CommonOptions::*field, const std::array<NamedValue<Enum>, N>& table) {
    const std::string message = std::string(name) + " needs " + ChoiceOf(table);
    return {name, "", true, [=, &table](CommonOptions& o, const char* v) -> std::optional<std::string> {
                const std::optional<Enum> value = v ? ValueNamed(table, v) : std::nullopt;
                if (!value) return message;
                o.*field = *value;
                return std::nullopt;
            }};
}

// The table's names as a choice, the first marked as the default: "a (default) or b".
template <typename Enum, size_t N>
std::string DefaultFirst(const std::array<NamedValue<Enum>, N>& table) {
    std::string out;
    for (size_t i = 0; i < N; ++i) {
        if (i > 0) out += i + 1 == N ? " or " : ", ";
        out += table[i].name;
        if (i == 0) out += " (default)";
    }
    return out;
}

// Function-local statics: commands in other files read them during static initialisation.
std::vector<OptionSpec> MakeSceneCommandOptions() {
    return {
        {"--backend", "--backends", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             if (!v) return "--backend needs a list, e.g. --backend cpu";
             return ParseBackendList(v, o.backends);
         }},
        {"--steps", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             if (!v) return "--steps needs a number";
             o.overrides.push_back({"steps", v});
             return std::nullopt;
         }},
        TextOption("--out", &CommonOptions::outDir, "--out needs a folder"),
        {"--set", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             const char* eq = v ? std::strchr(v, '=') : nullptr;
             if (!eq || eq == v) return "--set needs PATH=VALUE, e.g. --set ca.seed=42";
             o.overrides.push_back({std::string(v, eq), std::string(eq + 1)});
             return std::nullopt;
         }},
        {"--threads", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             long long threads = 0;
             if (auto why = ParseWholeNumber("--threads", v, 1, kMaxCpuThreads, threads)) return why;
             o.cpuThreads = int(threads);
             return std::nullopt;
         }},
        // Process-wide, at once: the CPU kernels' dispatch is (impl_cpu/CpuIsa.h).
        {"--cpu-isa", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             const std::optional<cpu::CpuIsa> isa = v ? ValueNamed(cpu::kCpuIsaNames, v) : std::nullopt;
             if (!isa) return "--cpu-isa needs " + ChoiceOf(cpu::kCpuIsaNames);
             if (Status s = cpu::SelectCpuIsa(*isa); !s) return s.error().message;
             o.cpuIsa = *isa;
             return std::nullopt;
         }},
        Choice("--gl-context", &CommonOptions::glContext, gl::kContextKindNames),
        Choice("--gl-ca-layout", &CommonOptions::glCaLayout, gl::kCaLayoutNames),
        TextOption("--vk-device", &CommonOptions::vkDevice, "--vk-device needs an index or a name"),
        FlagOption("--quiet", &CommonOptions::quiet),
    };
}

}  // namespace

std::optional<std::string> ParseWholeNumber(std::string_view name, const char* value, long long low, long long high,
                                            long long& out) {
    const std::string needs =
        std::string(name) + ": needs a whole number in [" + std::to_string(low) + ", " + std::to_string(high) + "]";
    if (!value) return needs;
    const std::string_view text = value;
    long long parsed = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), parsed);
    if (text.empty() || error != std::errc() || end != text.data() + text.size() || parsed < low || parsed > high)
        return needs + ", got '" + Shown(text) + "'";
    out = parsed;
    return std::nullopt;
}

OptionSpec FlagOption(std::string_view name, bool CommonOptions::*field) {
    return {name, "", false, [=](CommonOptions& o, const char*) -> std::optional<std::string> {
                o.*field = true;
                return std::nullopt;
            }};
}

std::optional<std::string> StoreText(std::string_view name, std::string& field, const char* value,
                                     const std::string& missing) {
    if (!value) return missing;
    if (!*value) return std::string(name) + ": must not be empty";
    field = value;
    return std::nullopt;
}

OptionSpec TextOption(std::string_view name, std::string CommonOptions::*field, std::string missing) {
    return {name, "", true, [=](CommonOptions& o, const char* v) { return StoreText(name, o.*field, v, missing); }};
}

std::span<const std::string_view> KnownBackends() {
    // The names registry/Registry.cpp's CreateBackend knows (BackendOptionsTest checks them against it).
    static constexpr std::array<std::string_view, 3> kKnown = {"cpu", "gl", "vk"};
    return kKnown;
}

std::optional<std::string> UnknownBackend(std::string_view option, std::string_view name) {
    const std::span<const std::string_view> known = KnownBackends();
    if (std::ranges::find(known, name) != known.end()) return std::nullopt;
    std::string knownList;
    for (std::string_view k : known) knownList += (knownList.empty() ? "" : ", ") + std::string(k);
    std::string message = std::string(option) + ": unknown backend '" + Shown(name) + "' (known: " + knownList + ")";
    if (const std::string_view best = ClosestName(name, known); !best.empty())
        message += "; did you mean '" + std::string(best) + "'?";
    return message;
}

std::optional<std::string> ParseBackendList(std::string_view list, std::vector<std::string>& backends) {
    const std::span<const std::string_view> known = KnownBackends();
    std::string knownList;
    for (std::string_view name : known) knownList += (knownList.empty() ? "" : ", ") + std::string(name);
    if (list.empty()) return "--backend: empty list (known: " + knownList + ")";
    std::vector<std::string> names;
    for (size_t start = 0; start <= list.size();) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string_view name = list.substr(start, comma - start);
        start = comma + 1;
        if (name.empty()) return "--backend: empty backend name in '" + Shown(list) + "'";
        if (auto why = UnknownBackend("--backend", name)) return *why;
        if (std::ranges::find(names, name) != names.end() || std::ranges::find(backends, name) != backends.end())
            return "--backend: " + std::string(name) + " named twice";
        names.emplace_back(name);
    }
    backends.insert(backends.end(), names.begin(), names.end());
    return std::nullopt;
}

BackendOptions CommonOptions::Backend() const {
    BackendOptions b;
    b.cpuThreads = cpuThreads;
    b.vkDevice = vkDevice;
    b.glContext = glContext;
    b.glCaLayout = glCaLayout;
    return b;
}

std::span<const OptionSpec> SceneCommandOptions() {
    static const std::vector<OptionSpec> options = MakeSceneCommandOptions();
    return options;
}

std::string GlOptionsHelp() {
    return "  --gl-context CTX   OpenGL context: " + DefaultFirst(gl::kContextKindNames) +
           "\n  --gl-ca-layout L   OpenGL automaton layout: " + DefaultFirst(gl::kCaLayoutNames) + "\n";
}

OptionSpec RepeatOption() {
    return OwnOption<MeasurementOptions>("--repeat", true,
                                         [](MeasurementOptions& o, const char* v) -> std::optional<std::string> {
                                             long long repeats = 0;
                                             if (auto why = ParseWholeNumber("--repeat", v, 1, 10000, repeats))
                                                 return why;
                                             o.repeats = int(repeats);
                                             return std::nullopt;
                                         });
}

OptionSpec ReferenceStepOption() {
    return OwnOption<MeasurementOptions>(
        "--reference-step", true, [](MeasurementOptions& o, const char* v) -> std::optional<std::string> {
            char* end = nullptr;
            const double step = v ? std::strtod(v, &end) : 0;
            const std::string needs = "--reference-step: needs a number of voxel edges in [1/1024, 1]";
            if (!v) return needs;
            if (end == v || *end != '\0' || !(step >= 1.0 / 1024 && step <= 1))
                return needs + ", got '" + Shown(v) + "'";
            o.referenceStep = step;
            return std::nullopt;
        });
}

CommandRegistration::CommandRegistration(Command command) {
    const std::string_view name = command.name;
    Registry().emplace(name, std::move(command));
}

std::vector<const Command*> RegisteredCommands() {
    std::vector<const Command*> out;
    for (const auto& [name, command] : Registry()) out.push_back(&command);
    std::ranges::stable_sort(out, {}, &Command::helpOrder);
    return out;
}

const Command* FindCommand(std::string_view name) {
    auto it = Registry().find(name);
    return it == Registry().end() ? nullptr : &it->second;
}

Result<std::vector<std::string>> SceneNamesIn(const std::string& folder) {
    std::error_code error;
    std::filesystem::directory_iterator it(folder, error);
    if (error) return MakeError(folder + ": cannot list the folder: " + error.message());
    std::vector<std::string> names;
    for (; it != std::filesystem::directory_iterator(); it.increment(error)) {
        const std::string file = it->path().filename().string();
        if (file.size() > 5 && file.ends_with(".json")) names.push_back(file.substr(0, file.size() - 5));
    }
    if (error) return MakeError(folder + ": cannot list the folder: " + error.message());
    std::ranges::sort(names);
    return names;
}

Result<std::string> ResolveScenePath(const std::string& nameOrPath) {
    const std::string& name = nameOrPath.empty() ? std::string(kDefaultScene) : nameOrPath;
    if (name.find('/') != std::string::npos || name.ends_with(".json")) return name;
    const std::string folder = SceneFolder();
    const std::string path = (std::filesystem::path(folder) / (name + ".json")).string();
    // Only a file that is not there makes the name unknown; any other failure is the loader's to name.
    std::error_code error;
    if (std::filesystem::symlink_status(path, error).type() != std::filesystem::file_type::not_found) return path;
    // The folder, the path and the listed names are shown through ShownMessage; the argument is cut as usual.
    std::string message = "SCENE: no scene named '" + Shown(name) + "' (no file " + path + ")";
    Result<std::vector<std::string>> names = SceneNamesIn(folder);
    if (!names) return MakeError(ShownMessage(message + "; " + names.error().message));
    if (names->empty()) return MakeError(ShownMessage(message + "; " + folder + " holds no scene (*.json)"));
    std::string list;
    for (const std::string& known : *names) list += (list.empty() ? "" : ", ") + known;
    message += "; the scenes there: " + list;
    if (const std::string_view best = ClosestName(name, *names); !best.empty())
        message += "; did you mean '" + std::string(best) + "'?";
    return MakeError(ShownMessage(message));
}

}  // namespace cb
