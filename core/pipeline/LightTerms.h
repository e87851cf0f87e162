// The scene's light terms (core/math/Light.h's LightTerms) as every renderer
// carries them (MarchSetup, LayersSetup, SplatParams: their member `light`),
// made once here for each renderer's Make*Params, and the readers of the scene
// sections they come from (`lighting`, `lightning`; docs/scenes.md). A light
// term's settings, reader and making live here; its sum is InScattered.
#pragma once

#include <cstdint>

#include "core/math/Light.h"
#include "core/scene/Scene.h"
#include "core/scene/SectionReader.h"

namespace cb {

// The sun's radiance and direction, the ambient light, the phase function (none
// where eye scattering replaces it), the voxel size h, 1 / nz, the lightning's
// point light at `step` (its flash; position in voxel units, radiance colour *
// intensity, r0^2 in metres^2), the city glow's blobs in voxel units and eye
// scattering's cone.
LightTerms MakeLightTerms(const Scene& scene, uint32_t step);

// The scene sections MakeLightTerms reads besides the sun and the grid: every renderer's image depends on them
// (a sweep that varies one of them measures every renderer's image). The shafts of light (lighting.shafts) also read
// the shadow's form and shade.sigma; they are measured apart from the renderers' images (accuracy's shafts rows).
inline constexpr std::string_view kLightTermFields[] = {"lighting", "lightning", "phase"};

namespace scene_io {
// Each reads its section from the document root into settings that hold the defaults on entry; a wrong field is
// reported into `check` and leaves its default.
void ReadLighting(const Json& root, Validator& check, LightingSettings& lighting);
// The section switches the light on unless it says "enabled": false.
void ReadLightning(const Json& root, Validator& check, LightningSettings& lightning);
}  // namespace scene_io

}  // namespace cb
