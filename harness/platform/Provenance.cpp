#include "harness/platform/Provenance.h"

#include <sys/utsname.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <thread>

#include "cloudbench_build_info.h"
#include "core/base/InstallLayout.h"
#include "core/base/PathPolicy.h"
#include "core/base/SystemFile.h"

namespace cb {
namespace {

using nlohmann::json;

std::string CpuModel() {
    std::istringstream cpuinfo(ReadSystemFile("/proc/cpuinfo"));
    for (std::string line; std::getline(cpuinfo, line);) {
        if (!line.starts_with("model name")) continue;
        const size_t colon = line.find(':');
        if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
    }
    return "unknown";
}

std::string OperatingSystem() {
    utsname u{};
    if (uname(&u) != 0) return "unknown";
    return std::string(u.sysname) + " " + u.release + " " + u.version + " " + u.machine;
}

std::string UtcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text;
}

// The value as the loader reads it: JSON text, or a bare word as a string.
json OverrideValue(const std::string& text) {
    json value = json::parse(text, nullptr, /*allow_exceptions=*/false);
    return value.is_discarded() ? json(text) : value;
}

// Sets the field at the override's dotted path (a number indexes an array).
void ApplyOverride(json& root, const SceneOverride& o) {
    json* node = &root;
    for (size_t start = 0; start <= o.path.size();) {
        const size_t dot = std::min(o.path.find('.', start), o.path.size());
        const std::string key = o.path.substr(start, dot - start);
        if (node->is_array() && !key.empty() && key.find_first_not_of("0123456789") == std::string::npos)
            node = &node->at(std::stoul(key));
        else
            node = &(*node)[key];
        start = dot + 1;
    }
    *node = OverrideValue(o.value);
}

}  // namespace

json SceneWithOverrides(const std::string& path, std::span<const SceneOverride> overrides) {
    // Read again as LoadScene read it (core/base/PathPolicy.h): the file may have changed since, even into a FIFO.
    Result<std::string> text = ReadInputFile(path, kSceneInput);
    if (!text) return nullptr;
    json root = json::parse(*text, nullptr, /*allow_exceptions=*/false);
    if (root.is_discarded()) return nullptr;
    try {
        for (const SceneOverride& o : overrides) ApplyOverride(root, o);
    } catch (const std::exception&) {
        return nullptr;  // LoadScene reports what is wrong with the override
    }
    return root;
}

std::string VersionText(std::string_view imageModuleFileName) {
    const std::string dirty = CLOUDBENCH_GIT_DIRTY;
    std::string module = "not found (looked for";
    std::error_code error;
    for (const std::string& path : ModuleCandidates(imageModuleFileName)) {
        if (std::filesystem::exists(path, error)) {
            module = path;
            break;
        }
        module += " " + path;
    }
    if (module.starts_with("not found")) module += ")";
    return std::string("cloudbench ") + CLOUDBENCH_VERSION + "\ncommit " + CLOUDBENCH_GIT_COMMIT +
           (dirty == "true" ? " (with uncommitted changes)" : dirty == "unknown" ? " (not a git checkout)" : "") +
           "\nbuild " + CLOUDBENCH_BUILD_TYPE + ", " + CLOUDBENCH_COMPILER + "\nscenes " + SceneFolder() +
           "\nimage module " + module + "\n";
}

json MakeProvenance(std::span<const std::string> commandLine, const SceneProvenance& scene,
                    std::span<const BackendProvenance> backends) {
    const std::string dirty = CLOUDBENCH_GIT_DIRTY;
    json doc = {
        {"git",
         {{"commit", CLOUDBENCH_GIT_COMMIT}, {"dirty", dirty == "unknown" ? json(dirty) : json(dirty == "true")}}},
        {"build",
         {{"version", CLOUDBENCH_VERSION},
          {"type", CLOUDBENCH_BUILD_TYPE},
          {"flags", CLOUDBENCH_CXX_FLAGS},
          {"compiler", CLOUDBENCH_COMPILER}}},
        {"machine", {{"cpu", CpuModel()}, {"threads", std::thread::hardware_concurrency()}, {"os", OperatingSystem()}}},
        {"date", UtcNow()},
        {"backends", json::array()},
        {"command_line", commandLine},
    };
    for (const BackendProvenance& b : backends) {
        json entry = {{"name", b.name}, {"status", b.status}, {"device", b.device}};
        if (!b.reason.empty()) entry["reason"] = b.reason;
        doc["backends"].push_back(entry);
    }
    json overrides = json::array();
    for (const SceneOverride& o : scene.overrides) overrides.push_back({{"path", o.path}, {"value", o.value}});
    doc["scene"] = {{"path", scene.path},
                    {"name", scene.scene ? scene.scene->name : ""},
                    {"overrides", overrides},
                    {"resolved", SceneWithOverrides(scene.path, scene.overrides)}};
    return doc;
}

}  // namespace cb
