// One reader per section of a scene file (docs/scenes.md). Each reads its
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

// Which sections read cleanly enough for the checks across sections (core/pipeline/SceneLoad.cpp) to use them.
struct SectionsRead {
    bool gridSize = false;  // grid.size is present and valid
    bool steps = true;      // steps is absent (the default) or valid
    bool stageList = true;  // the stage list has no unknown, duplicate or malformed entry
    bool cameras = true;    // render.cameras is absent or valid
};

// Every section of the scene after parsing and overrides, each checked on its own. The checks across
// sections and against memory follow in core/pipeline/SceneLoad.cpp.
SectionsRead ReadSceneSections(const Json& root, const std::string& label, Validator& check, Scene& scene);

// Simulation sections (core/scene/SceneReaders.cpp).

// Returns true when grid.size is present and valid.
bool ReadGrid(const Json& root, Validator& check, GridSettings& grid);
// The default stage list when absent. False when an entry is unknown, duplicate or not a string.
bool ReadStages(const Json& root, Validator& check, StageSet& stages);
// `nz` is the grid's when known; the wind shift stays as written (one pair or nz pairs).
void ReadCa(const Json& root, Validator& check, std::optional<uint32_t> nz, CaSettings& ca);
void ReadEllipsoids(const Json& root, Validator& check, EllipsoidSettings& ellipsoids);
void ReadSmooth(const Json& root, Validator& check, SmoothSettings& smooth);
void ReadDensity(const Json& root, Validator& check, DensitySettings& density);

// Lighting and rendering sections (core/scene/SceneRenderReaders.cpp).

void ReadSun(const Json& root, Validator& check, SunSettings& sun);
// True when the sun may take azimuth `degrees` (at most 1e9 in magnitude); otherwise fails `field` with the bound
// and the value, `where` appended (e.g. " at the last step (29)").
bool CheckAzimuth(double degrees, const std::string& field, std::string_view where, Validator& check);
void ReadLighting(const Json& root, Validator& check, LightingSettings& lighting);
void ReadPhase(const Json& root, Validator& check, PhaseParams& phase);
void ReadShade(const Json& root, Validator& check, ShadeSettings& shade);
void ReadShadow(const Json& root, Validator& check, ShadowSettings& shadow);
// Returns false when render.cameras was given but is wrong (so "needs a camera" is not piled on).
bool ReadRender(const Json& root, Validator& check, RenderSettings& render);
void ReadSplat(const Json& root, Validator& check, SplatSettings& splat);

// The ray marcher's sections (core/scene/SceneMarchReader.cpp). `stages` is the scene's list: the
// default light source "shade" needs the shade stage when render_march runs.
void ReadMarch(const Json& root, Validator& check, const StageSet& stages, MarchSettings& march);
void ReadLightning(const Json& root, Validator& check, LightningSettings& lightning);
// The noise section (core/scene/SceneNoiseReader.cpp).
void ReadNoise(const Json& root, Validator& check, NoiseSettings& noise);

}  // namespace cb::scene_io
