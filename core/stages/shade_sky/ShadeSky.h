// Stage `shade_sky` (SPEC 16, docs/contract.md): the sky light's transmittance T_sky by shade's inverse shear-warp
// toward the sky light (lighting.sky), with shade's settings (section `shade`); it runs iff the scene has a sky
// light, and with the sky fixed it runs again only when q changes.
// Its home: its parameters from a scene, its descriptor and its call adapter. It has no section of its own.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/stages/shade/ShadeTypes.h"

namespace cb {

// Shade's parameters (MakeShadeParams) lighting toward the sky light.
ShadeParams MakeShadeSkyParams(const Scene& scene);

const StageDescriptor& DescribeShadeSky();
Status CallShadeSky(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                    StageCallRecord& record);

}  // namespace cb
