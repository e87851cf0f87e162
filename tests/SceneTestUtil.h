// Helpers shared by the scene tests (SceneTest, SceneErrorsTest, SceneOverridesTest):
// parse a scene that must be accepted or refused, and look for lines of its message.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"

namespace cb::test {

inline constexpr const char* kLabel = "test.json";

inline std::vector<std::string> SplitLines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream stream(text);
    for (std::string line; std::getline(stream, line);) lines.push_back(line);
    return lines;
}

// The error message of a scene that must be refused ("" and a failure when it was accepted).
inline std::string ErrorOf(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    Result<Scene> scene = ParseScene(text, kLabel, overrides);
    if (scene) {
        ADD_FAILURE() << "the scene was accepted:\n" << text;
        return "";
    }
    return scene.error().message;
}

// A scene that must be accepted (a default Scene and a failure when it was refused).
inline Scene Parsed(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    Result<Scene> scene = ParseScene(text, kLabel, overrides);
    if (!scene) {
        ADD_FAILURE() << "the scene was refused:\n" << scene.error().message;
        return Scene{};
    }
    return *scene;
}

// True when one line of `message` equals `expected` exactly.
inline ::testing::AssertionResult HasLine(const std::string& message, const std::string& expected) {
    for (const std::string& line : SplitLines(message))
        if (line == expected) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "no line\n  " << expected << "\nin\n" << message;
}

// True when one line of `message` starts with `prefix`.
inline ::testing::AssertionResult HasLineStartingWith(const std::string& message, const std::string& prefix) {
    for (const std::string& line : SplitLines(message))
        if (line.starts_with(prefix)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "no line starting with\n  " << prefix << "\nin\n" << message;
}

inline StageSet Stages(std::initializer_list<Stage> list) {
    StageSet set;
    for (Stage s : list) set.Add(s);
    return set;
}

inline constexpr const char* kMinimal = R"({"grid": {"size": [8, 4, 6]}})";

}  // namespace cb::test
