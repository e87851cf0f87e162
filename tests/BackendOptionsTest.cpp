// The OpenGL backend's typed options (impl_gl/GLOptions.h) on the command
// line: each name of a table parses to its value, any other value is refused
// with a message that lists the names, and the help lists them from the same
// table. --backend LIST is parsed strictly: an empty list or item, a name
// given twice or an unknown name is refused with a message; --out refuses "".
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/platform/Command.h"
#include "impl_gl/GLOptions.h"
#include "registry/Registry.h"

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

TEST(BackendOptions, BackendListParsesKnownNamesInOrder) {
    CommonOptions options;
    EXPECT_EQ(SceneOption("--backend").apply(options, "vk,cpu"), std::nullopt);
    EXPECT_EQ(SceneOption("--backend").apply(options, "gl"), std::nullopt);  // repeated options add up
    EXPECT_EQ(options.backends, (std::vector<std::string>{"vk", "cpu", "gl"}));
}

TEST(BackendOptions, BackendListRefusesEmptyNames) {
    std::vector<std::string> backends;
    EXPECT_EQ(ParseBackendList("", backends), "--backend: empty list (known: cpu, gl, vk)");
    EXPECT_EQ(ParseBackendList(",", backends), "--backend: empty backend name in ','");
    EXPECT_EQ(ParseBackendList("cpu,", backends), "--backend: empty backend name in 'cpu,'");
    EXPECT_EQ(ParseBackendList(",cpu", backends), "--backend: empty backend name in ',cpu'");
    EXPECT_EQ(ParseBackendList("cpu,,vk", backends), "--backend: empty backend name in 'cpu,,vk'");
    EXPECT_TRUE(backends.empty());  // a refused list adds nothing
    CommonOptions options;
    EXPECT_EQ(SceneOption("--backend").apply(options, nullptr), "--backend needs a list, e.g. --backend cpu");
}

TEST(BackendOptions, BackendListRefusesDuplicates) {
    std::vector<std::string> backends;
    EXPECT_EQ(ParseBackendList("cpu,cpu", backends), "--backend: cpu named twice");
    EXPECT_TRUE(backends.empty());
    EXPECT_EQ(ParseBackendList("cpu,vk", backends), std::nullopt);
    EXPECT_EQ(ParseBackendList("gl,vk", backends), "--backend: vk named twice");  // across --backend options
    EXPECT_EQ(backends, (std::vector<std::string>{"cpu", "vk"}));
}

TEST(BackendOptions, BackendListRefusesUnknownNamesWithASuggestion) {
    std::vector<std::string> backends;
    EXPECT_EQ(ParseBackendList("cpuu", backends),
              "--backend: unknown backend 'cpuu' (known: cpu, gl, vk); did you mean 'cpu'?");
    EXPECT_EQ(ParseBackendList("cpu,CPU", backends),
              "--backend: unknown backend 'CPU' (known: cpu, gl, vk); did you mean 'cpu'?");
    EXPECT_EQ(ParseBackendList("vulkan", backends), "--backend: unknown backend 'vulkan' (known: cpu, gl, vk)");
    EXPECT_EQ(ParseBackendList("x", backends), "--backend: unknown backend 'x' (known: cpu, gl, vk)");
    EXPECT_TRUE(backends.empty());
}

// Test the rule docs/cli.md gives for names from the command line: control and non-ASCII bytes as \xNN (no raw
// ESC reaches the terminal, and a look-alike "çpu" shows its odd bytes), cut to 40 bytes.
TEST(BackendOptions, BackendListShowsNamesSafely) {
    std::vector<std::string> backends;
    EXPECT_EQ(ParseBackendList("c\x1b[2Jpu", backends), "--backend: unknown backend 'c\\x1b[2Jpu' (known: cpu, gl, vk)");
    EXPECT_EQ(ParseBackendList("\xc3\xa7pu", backends),
              "--backend: unknown backend '\\xc3\\xa7pu' (known: cpu, gl, vk); did you mean 'cpu'?");  // 2 byte edits
    const std::string huge(1'000'000, 'a');
    const std::optional<std::string> message = ParseBackendList(huge, backends);
    ASSERT_TRUE(message);
    EXPECT_EQ(*message, "--backend: unknown backend '" + std::string(40, 'a') + "...' (known: cpu, gl, vk)");
}

// KnownBackends() is the registry's list: every built backend is in it, and
// CreateBackend's message for an unknown name lists the same names.
TEST(BackendOptions, KnownBackendsAreTheRegistrys) {
    std::string known;
    for (std::string_view name : KnownBackends()) known += (known.empty() ? "" : ", ") + std::string(name);
    for (const std::string& built : BuiltBackends())
        EXPECT_NE(std::ranges::find(KnownBackends(), built), KnownBackends().end()) << built;
    auto unknown = CreateBackend("no-such-backend");
    ASSERT_FALSE(unknown);
    EXPECT_NE(unknown.error().message.find("(known: " + known + ")"), std::string::npos) << unknown.error().message;
}

TEST(BackendOptions, OutRefusesAnEmptyFolder) {
    CommonOptions options;
    EXPECT_EQ(SceneOption("--out").apply(options, ""), "--out: must not be empty");
    EXPECT_EQ(SceneOption("--out").apply(options, nullptr), "--out needs a folder");
    EXPECT_EQ(SceneOption("--out").apply(options, "out/x"), std::nullopt);
    EXPECT_EQ(options.outDir, "out/x");
}

}  // namespace
}  // namespace cb
