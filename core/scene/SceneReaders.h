// The readers of the sections every stage shares (grid, stages, sun, phase,
// render; docs/scenes.md); each stage's module reads its own, and the light
// terms' sections are read beside MakeLightTerms (core/pipeline/LightTerms.h). Each reads its
// section from the document root into its settings, which hold the defaults on
// entry; a field that is wrong is reported into `check` and leaves its default.
// Internal to core (see core/base/JsonDom.h).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "core/scene/Scene.h"
#include "core/scene/SceneValidator.h"

namespace cb::scene_io {

inline constexpr int64_t kU32Max = std::numeric_limits<uint32_t>::max();

// Grid and stages (core/scene/SceneReaders.cpp).

// Returns true when grid.size is present and valid.
bool ReadGrid(const Json& root, Validator& check, GridSettings& grid);
// The default stage list when absent. False when an entry is unknown, duplicate or not a string.
bool ReadStages(const Json& root, Validator& check, StageSet& stages);

// Sun, phase and render (core/scene/SceneRenderReaders.cpp).

void ReadSun(const Json& root, Validator& check, SunSettings& sun);
// True when the sun may take azimuth `degrees` (at most 1e9 in magnitude); otherwise fails `field` with the bound
// and the value, `where` appended (e.g. " at the last step (29)").
bool CheckAzimuth(double degrees, const std::string& field, std::string_view where, Validator& check);
void ReadPhase(const Json& root, Validator& check, PhaseParams& phase);
// Returns false when render.cameras was given but is wrong (so "needs a camera" is not piled on).
bool ReadRender(const Json& root, Validator& check, RenderSettings& render);

}  // namespace cb::scene_io
