// The OpenGL backend's typed options (impl_gl/GLOptions.h) on the command
// line: each name of a table parses to its value, any other value is refused
// with a message that lists the names, and the help lists them from the same
// table.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <string_view>

#include "harness/Command.h"
#include "impl_gl/GLOptions.h"

namespace cb {
namespace {

static_assert(gl::kCaLayoutNames.size() == size_t(gl::CaLayout::Rgba8) + 1);
static_assert(gl::kContextKindNames.size() == size_t(gl::ContextKind::Egl) + 1);
static_assert(ValueNamed(gl::kCaLayoutNames, "rgba8") == gl::CaLayout::Rgba8);
static_assert(gl::ContextKindName(gl::ContextKind::Egl) == "egl");

const OptionSpec& SceneOption(std::string_view name) {
    for (const OptionSpec& option : SceneCommandOptions())
        if (option.name == name) return option;
    ADD_FAILURE() << "no option " << name;
    return SceneCommandOptions().front();
}

TEST(BackendOptions, CaLayoutParsesEachName) {
    const OptionSpec& option = SceneOption("--gl-ca-layout");
    for (const auto& [name, value] : gl::kCaLayoutNames) {
        CommonOptions options;
        EXPECT_EQ(option.apply(options, std::string(name).c_str()), std::nullopt) << name;
        EXPECT_EQ(options.glCaLayout, value) << name;
        EXPECT_EQ(options.Backend().glCaLayout, value) << name;
    }
}

TEST(BackendOptions, ContextParsesEachName) {
    const OptionSpec& option = SceneOption("--gl-context");
    for (const auto& [name, value] : gl::kContextKindNames) {
        CommonOptions options;
        EXPECT_EQ(option.apply(options, std::string(name).c_str()), std::nullopt) << name;
        EXPECT_EQ(options.Backend().glContext, value) << name;
    }
}

TEST(BackendOptions, UnknownOrMissingValueListsTheNames) {
    CommonOptions options;
    EXPECT_EQ(SceneOption("--gl-ca-layout").apply(options, "RGBA8"), "--gl-ca-layout needs packed or rgba8");
    EXPECT_EQ(SceneOption("--gl-ca-layout").apply(options, nullptr), "--gl-ca-layout needs packed or rgba8");
    EXPECT_EQ(SceneOption("--gl-context").apply(options, "glx"), "--gl-context needs osmesa or egl");
    EXPECT_EQ(options.glCaLayout, gl::CaLayout::Packed);  // unchanged by a refused value
}

TEST(BackendOptions, HelpListsTheNamesDefaultFirst) {
    const std::string help = GlOptionsHelp();
    EXPECT_NE(help.find("--gl-context CTX   OpenGL context: osmesa (default) or egl\n"), std::string::npos) << help;
    EXPECT_NE(help.find("--gl-ca-layout L   OpenGL automaton layout: packed (default) or rgba8\n"), std::string::npos)
        << help;
}

}  // namespace
}  // namespace cb
