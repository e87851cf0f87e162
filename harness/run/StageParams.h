// A scene's settings turned into each stage's parameters, in one place for the
// simulation driver, `conform` and the benchmarks.
#pragma once

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"

namespace cb {

CaInitParams MakeCaInitParams(const Scene& scene);
// Without the wind shifts, which the caller keeps alive and sets.
CaStepParams MakeCaStepParams(const Scene& scene, uint32_t step);
DensityParams MakeDensityParams(const Scene& scene);
// The sun is the scene's at `step` (SunSettings::DirectionAt; step 0 is the fixed sun's).
ShadeParams MakeShadeParams(const Scene& scene, uint32_t step = 0);
ShadowParams MakeShadowParams(const Scene& scene, uint32_t step = 0);
// Points into scene.noise: the scene must outlive the parameters.
NoiseParams MakeNoiseParams(const Scene& scene, uint32_t step);
// Everything but the order, which the caller makes (MakeSplatOrder) and keeps alive; the sun at `step`, alpha of
// frame `frame` of a step of `frames` frames (RenderSettings::FrameAlpha; 0: render.frames_per_step).
SplatParams MakeSplatParams(const Scene& scene, const CameraSettings& camera, uint32_t step = 0, uint32_t frame = 0,
                            uint32_t frames = 0);
// The scene's ground (render.ground) as both renderers take it.
GroundParams MakeGroundParams(const Scene& scene);
// The ray marcher's parameters for one camera at `step` (the jitter's frame, the lightning's flash window and the
// sun), frame `frame` of a step of `frames` frames (its alpha).
MarchParams MakeMarchParams(const Scene& scene, const CameraSettings& camera, uint32_t step, uint32_t frame = 0,
                            uint32_t frames = 0);

}  // namespace cb
