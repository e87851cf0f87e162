// The scene's light terms (core/math/Light.h's LightTerms) as every renderer
// carries them (MarchSetup, LayersSetup, SplatParams: their member `light`),
// made once here for each renderer's Make*Params.
#pragma once

#include <cstdint>

#include "core/math/Light.h"
#include "core/scene/Scene.h"

namespace cb {

// The sun's radiance, the ambient light, the phase function, the voxel size h
// and the lightning's point light at `step` (its flash; position in voxel
// units, radiance colour * intensity, r0^2 in metres^2).
LightTerms MakeLightTerms(const Scene& scene, uint32_t step);

}  // namespace cb
