// A scene's settings turned into each stage's parameters, in one place for the
// simulation driver, `conform` and the benchmarks.
#pragma once

#include "core/Backend.h"
#include "core/Scene.h"

namespace cb {

CaInitParams MakeCaInitParams(const Scene& scene);
// Without the wind shifts, which the caller keeps alive and sets.
CaStepParams MakeCaStepParams(const Scene& scene, uint32_t step);
DensityParams MakeDensityParams(const Scene& scene);
ShadeParams MakeShadeParams(const Scene& scene);
ShadowParams MakeShadowParams(const Scene& scene);
// Points into scene.noise: the scene must outlive the parameters.
NoiseParams MakeNoiseParams(const Scene& scene, uint32_t step);
// Everything but the order, which the caller makes (MakeSplatOrder) and keeps alive.
SplatParams MakeSplatParams(const Scene& scene, const CameraSettings& camera);
// The ray marcher's parameters for one camera at `step` (the jitter's frame and the lightning's flash window).
MarchParams MakeMarchParams(const Scene& scene, const CameraSettings& camera, uint32_t step);

}  // namespace cb
