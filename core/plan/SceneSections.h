// Every section of a scene file read, each by its owner: the shared sections
// by core/scene/SceneReaders.h, a stage's by its module (core/stages/<stage>/).
// Internal to core (see core/base/JsonDom.h).
#pragma once

#include <string>

#include "core/scene/Scene.h"
#include "core/scene/SceneValidator.h"

namespace cb::scene_io {

// Which sections read cleanly enough for the checks across sections (core/plan/SceneLoad.cpp) to use them.
struct SectionsRead {
    bool gridSize = false;  // grid.size is present and valid
    bool steps = true;      // steps is absent (the default) or valid
    bool stageList = true;  // the stage list has no unknown, duplicate or malformed entry
    bool cameras = true;    // render.cameras is absent or valid
};

// Every section of the scene after parsing and overrides, each checked on its own. The checks across
// sections and against memory follow in core/plan/SceneLoad.cpp.
SectionsRead ReadSceneSections(const Json& root, const std::string& label, Validator& check, Scene& scene);

}  // namespace cb::scene_io
