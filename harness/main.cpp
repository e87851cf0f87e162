// cloudbench: cross-backend validation and benchmark harness for the cloud
// pipeline of docs/contract.md. The registry loop: finds the command named by argv[1]
// (harness/commands/), parses its options, prints help, runs it. docs/cli.md
// describes the commands.
#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"
#include "harness/platform/Command.h"
#include "harness/platform/Isolation.h"
#include "harness/platform/Provenance.h"
#include "harness/report/images/ImageModule.h"

namespace {

constexpr const char* kExitCodesHelp = R"(
Exit codes: 0 success, 1 a stage failed or an output could not be written,
2 bad command line, 3 bad scene file or --set value, 4 no requested backend
available, 5 a conformance check failed, 6 perf compare found a regression.
)";

std::string MainHelp() {
    std::string out = "usage: cloudbench <command> [options]\n\nCommands:\n";
    for (const cb::Command* command : cb::RegisteredCommands()) {
        char line[256];
        std::snprintf(line, sizeof line, "  %-8s %s\n", std::string(command->name).c_str(),
                      std::string(command->summary).c_str());
        out += line;
    }
    return out + "  help   Show help for a command: cloudbench help run\n" +
           "  --version  the version, commit and build, and where the scenes and the image module are read from\n" +
           kExitCodesHelp;
}

int Usage(const std::string& message, std::string_view help) {
    std::fprintf(stderr, "cloudbench: %s\n\n%.*s", cb::ShownMessage(message).c_str(), int(help.size()), help.data());
    return cb::kExitUsage;
}

const cb::OptionSpec* FindOption(const cb::Command& command, std::string_view arg) {
    auto matches = [&](const cb::OptionSpec& o) { return arg == o.name || (!o.alias.empty() && arg == o.alias); };
    if (command.takesScene)
        for (const cb::OptionSpec& o : cb::SceneCommandOptions())
            if (matches(o)) return &o;
    for (const cb::OptionSpec& o : command.extraOptions)
        if (matches(o)) return &o;
    return nullptr;
}

// "; did you mean '--backend'?" for an option close to one of the command's, else "".
std::string OptionSuggestion(const cb::Command& command, std::string_view arg) {
    std::vector<std::string_view> names;
    if (command.takesScene)
        for (const cb::OptionSpec& o : cb::SceneCommandOptions()) names.push_back(o.name);
    for (const cb::OptionSpec& o : command.extraOptions) names.push_back(o.name);
    const std::string_view best = cb::ClosestName(arg, names);
    return best.empty() ? "" : "; did you mean '" + std::string(best) + "'?";
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs(MainHelp().c_str(), stderr);
        return cb::kExitUsage;
    }
    const std::string_view name = argv[1];
    if (name == "--version") {
        std::fputs(cb::VersionText(cb::images::kModuleFileName).c_str(), stdout);
        return cb::kExitOk;
    }
    if (name == "--help" || name == "-h") {
        std::fputs(MainHelp().c_str(), stdout);
        return cb::kExitOk;
    }
    if (name == "help") {
        const cb::Command* topic = cb::FindCommand(argc > 2 ? argv[2] : "");
        std::fputs(topic ? std::string(topic->help).c_str() : MainHelp().c_str(), stdout);
        return cb::kExitOk;
    }
    const cb::Command* command = cb::FindCommand(name);
    if (!command) return Usage("unknown command '" + cb::ShownArgument(name) + "'", MainHelp());

    cb::CommonOptions options;
    const std::unique_ptr<cb::OwnOptions> own = command->makeOptions();
    options.commandLine.assign(argv, argv + argc);
    if (!command->keepsWarmup) options.overrides.push_back({"warmup_steps", "0"});
    bool sceneGiven = false;
    for (int n = 2; n < argc; ++n) {
        const std::string_view arg = argv[n];
        if (arg == "--help" || arg == "-h") {
            std::fputs(std::string(command->help).c_str(), stdout);
            return cb::kExitOk;
        }
        if (command->rawArguments) {
            options.arguments.emplace_back(arg);
        } else if (const cb::OptionSpec* option = FindOption(*command, arg)) {
            const char* value = option->takesValue ? (n + 1 < argc ? argv[++n] : nullptr) : nullptr;
            auto message = option->apply ? option->apply(options, value) : option->applyOwn(*own, value);
            if (message) return Usage(*message, command->help);
        } else if (arg.starts_with("-")) {
            return Usage("unknown option '" + cb::ShownArgument(arg) + "'" + OptionSuggestion(*command, arg),
                         command->help);
        } else if (command->takesArguments) {
            options.arguments.emplace_back(arg);
        } else if (!command->takesScene) {
            return Usage("unexpected argument '" + cb::ShownArgument(arg) + "'", command->help);
        } else if (!sceneGiven) {
            options.scene = std::string(arg);
            sceneGiven = true;
        } else {
            return Usage("unexpected argument '" + cb::ShownArgument(arg) + "' (one scene at a time)", command->help);
        }
    }
    // An allocation that fails anywhere outside an isolated backend's process
    // (which reports its own) ends the command with a message, not an abort.
    try {
        return command->run(options, *own);
    } catch (const std::bad_alloc& e) {
        const std::string phase = cb::CurrentPhase();
        std::fflush(stdout);
        std::fprintf(stderr, "cloudbench: out of memory%s%s: %s\n", phase.empty() ? "" : " in ", phase.c_str(),
                     e.what());
        return cb::kExitFailed;
    }
}
