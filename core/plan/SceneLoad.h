// Loading a scene file: parsed, overridden, every section read and checked,
// then checked across sections and against memory (core/plan/SceneLoad.cpp).
#pragma once

#include <string>
#include <vector>

#include "core/base/Error.h"
#include "core/scene/Scene.h"

namespace cb {

// Reads, overrides and validates a scene. Errors read "file: field: reason",
// one per line, every problem found (not just the first).
Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides = {});

// Same, from JSON text (for tests); `label` stands in for the file name.
Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides = {});

}  // namespace cb
