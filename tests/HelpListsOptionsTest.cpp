// Every command's `cloudbench help NAME` names every option the command
// accepts: the scene options every scene command takes (SceneCommandOptions)
// and its own (Command::extraOptions), each by its name and alias. perf parses
// its subcommands' options itself (Command::rawArguments) and is left out; its
// help is checked by the perf tests' option cases.
#include <gtest/gtest.h>

#include <cctype>
#include <string>
#include <vector>

#include "harness/platform/Command.h"

namespace cb {
namespace {

// The name as a whole option in the help: followed by neither a letter, a digit nor '-' (so "--set" is not found
// in "--settings").
bool HelpNames(std::string_view help, std::string_view name) {
    for (size_t at = help.find(name); at != std::string_view::npos; at = help.find(name, at + 1)) {
        const size_t end = at + name.size();
        const bool wordEnds = end == help.size() || !(std::isalnum(static_cast<unsigned char>(help[end])) ||
                                                      help[end] == '-');
        if (wordEnds) return true;
    }
    return false;
}

TEST(HelpListsOptions, EveryCommandNamesEveryOptionItAccepts) {
    const std::vector<const Command*> commands = RegisteredCommands();
    ASSERT_GE(commands.size(), 10u) << "the commands' registrations were not linked";
    for (const Command* command : commands) {
        if (command->rawArguments) continue;
        std::vector<OptionSpec> options = command->extraOptions;
        if (command->takesScene)
            options.insert(options.end(), SceneCommandOptions().begin(), SceneCommandOptions().end());
        for (const OptionSpec& option : options) {
            EXPECT_TRUE(HelpNames(command->help, option.name))
                << "cloudbench help " << command->name << " does not name " << option.name;
            if (!option.alias.empty())
                EXPECT_TRUE(HelpNames(command->help, option.alias))
                    << "cloudbench help " << command->name << " does not name " << option.alias;
        }
    }
}

// The matcher itself: a whole option, not a prefix of a longer one.
TEST(HelpListsOptions, MatchesWholeOptionsOnly) {
    EXPECT_TRUE(HelpNames("  --set PATH=VALUE  override", "--set"));
    EXPECT_FALSE(HelpNames("  --settings FILE", "--set"));
    EXPECT_FALSE(HelpNames("  --set-all", "--set"));
    EXPECT_TRUE(HelpNames("--steps N, --set", "--set"));
    EXPECT_FALSE(HelpNames("no options here", "--quiet"));
}

}  // namespace
}  // namespace cb
