// A scene's settings turned into the parameters of the lighting stages, in
// one place for the simulation driver, `conform` and the benchmarks.
#pragma once

#include "core/Backend.h"
#include "core/Scene.h"

namespace cb {

ShadeParams MakeShadeParams(const Scene& scene);
ShadowParams MakeShadowParams(const Scene& scene);
// Everything but the order, which the caller makes (MakeSplatOrder) and keeps alive.
SplatParams MakeSplatParams(const Scene& scene, const CameraSettings& camera);

}  // namespace cb
