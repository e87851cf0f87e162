// Scene loading: JSON text -> overrides -> validation -> Scene. Every check
// reports into one list of "label: field: reason" lines, so a user sees all
// problems of a file at once. The format is documented in docs/scenes.md; the
// document is built by core/JsonDom, checked by core/SceneValidator and read
// section by section by core/SceneReaders.
#include "core/Scene.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <optional>

#include "core/InputFile.h"
#include "core/JsonDom.h"
#include "core/SceneReaders.h"
#include "core/SceneValidator.h"

namespace cb {
namespace {

using scene_io::Describe;
using scene_io::Json;
using scene_io::JsonDom;
using scene_io::Validator;

Result<Scene> ParseSceneChecked(const std::string& text, const std::string& label,
                                const std::vector<SceneOverride>& overrides) {
    Validator check(label);
    JsonDom dom = scene_io::ParseJsonDom(text);
    if (dom.failure) {
        check.FailWhole(scene_io::DescribeParseFailure(text, *dom.failure));
        return MakeError(check.Message());
    }
    Json& root = dom.root;
    for (const std::string& duplicate : dom.duplicates) check.Fail(duplicate, "duplicate field");
    if (!root.is_object()) {
        check.FailWhole("expected a JSON object at the top level, got " + Describe(root));
        return MakeError(check.Message());
    }
    for (const SceneOverride& item : overrides) scene_io::ApplyOverride(root, item, check);

    Scene scene;
    scene_io::ReadScene(root, label, check, scene);
    if (check.ErrorCount() > 0) return MakeError(check.Message());

    // One pair means "the same shift for every slice"; expanded only now that nz is known to be sane.
    if (scene.ca.windShift.size() == 1 && scene.grid.size.nz > 1)
        scene.ca.windShift.assign(scene.grid.size.nz, scene.ca.windShift[0]);
    return scene;
}

}  // namespace

double SunSettings::ElevationAt(uint32_t step) const {
    if (path.empty()) return elevationDeg + elevationSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().elevationDeg;
    if (step >= path.back().step) return path.back().elevationDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.elevationDeg + (hi.elevationDeg - lo.elevationDeg) * w;
}

double SunSettings::AzimuthAt(uint32_t step) const {
    if (path.empty()) return azimuthDeg + azimuthSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().azimuthDeg;
    if (step >= path.back().step) return path.back().azimuthDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.azimuthDeg + (hi.azimuthDeg - lo.azimuthDeg) * w;
}

Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides) {
    try {
        return ParseSceneChecked(text, label, overrides);
    } catch (const std::exception& e) {
        return MakeError(label + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(label + ": internal error while reading the scene");
    }
}

Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides) {
    try {
        Result<std::string> text = ReadInputFile(path, kSceneInput);
        if (!text) return MakeError(text.error().message);
        Result<Scene> scene = ParseScene(*text, path, overrides);
        if (scene) scene->path = path;
        return scene;
    } catch (const std::exception& e) {
        return MakeError(path + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(path + ": internal error while reading the scene");
    }
}

}  // namespace cb
