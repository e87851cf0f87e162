// The published names of the scene's choices (core/scene/SceneNames.h): every enum
// value has exactly one name, the names read back to their values, the scene
// loader accepts each of them, and they are exactly those docs/scenes.md lists.
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "core/scene/SceneNames.h"

namespace cb {
namespace {

static_assert(kPhaseKindNames.size() == size_t(PhaseKind::DualLobe) + 1);
static_assert(kAttenuationKindNames.size() == size_t(AttenuationKind::Thesis) + 1);
static_assert(kShadowFormNames.size() == size_t(ShadowForm::Wang) + 1);
static_assert(kSampleFilterNames.size() == size_t(SampleFilter::Nearest) + 1);
static_assert(kStorageFormatNames.size() == size_t(StorageFormat::Unorm8) + 1);
static_assert(ValueNamed(kStorageFormatNames, "fp16") == StorageFormat::Fp16);
static_assert(PhaseKindName(PhaseKind::HenyeyGreenstein) == "henyey-greenstein");

// Every value 0..N-1 of the enum is named once, and each name reads back to its value.
template <typename Enum, size_t N>
void ExpectRoundTrip(const std::array<NamedValue<Enum>, N>& table) {
    std::set<std::string_view> names;
    for (size_t i = 0; i < N; ++i) {
        const Enum value = static_cast<Enum>(i);
        const std::string_view name = NameOf(table, value);
        EXPECT_NE(name, "?") << "value " << i << " has no name";
        EXPECT_EQ(ValueNamed(table, name), value) << name;
        EXPECT_TRUE(names.insert(name).second) << "name " << name << " is used twice";
    }
    EXPECT_EQ(ValueNamed(table, "no-such-name"), std::nullopt);
    const std::array<std::string_view, N> listed = NamesOf(table);
    for (size_t i = 0; i < N; ++i) EXPECT_EQ(listed[i], table[i].name);
}

TEST(SceneNames, EveryValueRoundTripsThroughItsName) {
    ExpectRoundTrip(kPhaseKindNames);
    ExpectRoundTrip(kAttenuationKindNames);
    ExpectRoundTrip(kSampleFilterNames);
    ExpectRoundTrip(kStorageFormatNames);
    for (const auto& [name, value] : kPhaseKindNames) EXPECT_EQ(PhaseKindName(value), name);
    for (const auto& [name, value] : kAttenuationKindNames) EXPECT_EQ(AttenuationKindName(value), name);
    for (const auto& [name, value] : kSampleFilterNames) EXPECT_EQ(SampleFilterName(value), name);
    for (const auto& [name, value] : kStorageFormatNames) EXPECT_EQ(StorageFormatName(value), name);
}

// The scene with one choice set, e.g. {"shade": {"storage": "fp16"}}.
Scene SceneWith(const std::string& section, const std::string& field, std::string_view name) {
    const std::string text =
        R"({"grid": {"size": [8, 4, 6]}, ")" + section + R"(": {")" + field + R"(": ")" + std::string(name) + R"("}})";
    Result<Scene> scene = ParseScene(text, "names.json");
    if (!scene) ADD_FAILURE() << scene.error().message;
    return scene.value_or(Scene{});
}

TEST(SceneNames, TheLoaderAcceptsEveryName) {
    for (const auto& [name, value] : kPhaseKindNames) EXPECT_EQ(SceneWith("phase", "function", name).phase.kind, value);
    for (const auto& [name, value] : kAttenuationKindNames)
        EXPECT_EQ(SceneWith("shade", "attenuation", name).shade.attenuation, value);
    for (const auto& [name, value] : kShadowFormNames) EXPECT_EQ(SceneWith("shadow", "form", name).shadow.form, value);
    for (const auto& [name, value] : kSampleFilterNames)
        EXPECT_EQ(SceneWith("shade", "filter", name).shade.filter, value);
    for (const auto& [name, value] : kStorageFormatNames)
        EXPECT_EQ(SceneWith("shade", "storage", name).shade.storage, value);
}

// The quoted names in the Allowed column of the row of `field` under "## section" in docs/scenes.md.
std::vector<std::string> DocumentedNames(const std::string& section, const std::string& field) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/../docs/scenes.md");
    EXPECT_TRUE(file) << "cannot read docs/scenes.md";
    bool inSection = false;
    for (std::string line; std::getline(file, line);) {
        if (line.starts_with("## ")) inSection = line == "## " + section;
        if (!inSection || !line.starts_with("| `" + field + "` |")) continue;
        // | Field | Type | Units | Default | Allowed |: the Allowed column starts at the fifth bar.
        size_t allowed = 0;
        for (int bar = 1; bar < 5 && allowed != std::string::npos; ++bar) allowed = line.find('|', allowed + 1);
        if (allowed == std::string::npos) {
            ADD_FAILURE() << "the docs row of " << section << "." << field << " has no Allowed column";
            return {};
        }
        std::vector<std::string> names;
        const std::regex quoted(R"re(`"([^"`]+)"`)re");
        const std::string rest = line.substr(allowed);
        for (std::sregex_iterator it(rest.begin(), rest.end(), quoted), end; it != end; ++it) names.push_back((*it)[1]);
        return names;
    }
    ADD_FAILURE() << "docs/scenes.md has no row for " << section << "." << field;
    return {};
}

template <typename Enum, size_t N>
std::vector<std::string> TableNames(const std::array<NamedValue<Enum>, N>& table) {
    std::vector<std::string> names;
    for (const auto& entry : table) names.emplace_back(entry.name);
    return names;
}

TEST(SceneNames, AreThoseTheDocsList) {
    EXPECT_EQ(DocumentedNames("phase", "function"), TableNames(kPhaseKindNames));
    EXPECT_EQ(DocumentedNames("shade", "attenuation"), TableNames(kAttenuationKindNames));
    EXPECT_EQ(DocumentedNames("shade", "filter"), TableNames(kSampleFilterNames));
    EXPECT_EQ(DocumentedNames("shade", "storage"), TableNames(kStorageFormatNames));
    EXPECT_EQ(DocumentedNames("shadow", "form"), TableNames(kShadowFormNames));
}

}  // namespace
}  // namespace cb
