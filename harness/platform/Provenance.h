// The "provenance" block of every JSON output (docs/results.md): what built
// the binary, the machine, the backends, the scene and the command line, so a
// result can be traced to what produced it.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/scene/Scene.h"

namespace cb {

// One backend a command asked for, as it was opened.
struct BackendProvenance {
    std::string name;
    std::string status;  // "available", "unavailable" or "unsupported"
    std::string device;  // Backend::Device(); "" when it did not open
    std::string reason;  // why it is not available; "" otherwise
};

struct SceneProvenance {
    std::string path;
    const Scene* scene = nullptr;
    std::span<const SceneOverride> overrides;
};

// `cloudbench --version`: the version, the commit (and whether the tree was
// dirty), the build type and compiler, and where this executable reads its
// scenes and its image module (`imageModuleFileName`) from (core/base/InstallLayout.h).
std::string VersionText(std::string_view imageModuleFileName);

// Keys: git {commit, dirty}, build {version, type, flags, compiler}, machine {cpu,
// threads, os}, date (UTC, ISO 8601), backends [...], scene {path, name,
// overrides, resolved}, command_line [...].
nlohmann::json MakeProvenance(std::span<const std::string> commandLine, const SceneProvenance& scene,
                              std::span<const BackendProvenance> backends);

// The scene file at `path` with `overrides` applied by their dotted paths,
// as the loader applies them before validation; null when it cannot be read.
nlohmann::json SceneWithOverrides(const std::string& path, std::span<const SceneOverride> overrides);

}  // namespace cb
