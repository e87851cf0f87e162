// Stage `noise`'s types (SPEC 10a, docs/contract.md): its parameters (the settings, section `noise`, are
// core/math/NoiseSettings.h, which the noise formulas read).
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <cstdint>

#include "core/math/Grid.h"
#include "core/math/NoiseSettings.h"

namespace cb {

// Inputs of the noise producer of q (SPEC 10a): the scene's noise settings,
// the grid q has, and the step, whose index is the time coordinate (the
// noise drifts by settings->drift voxels per step).
struct NoiseParams {
    uint32_t step = 0;
    const NoiseSettings* settings = nullptr;  // not owned; must outlive the call
    Extent3 grid;                             // must equal q's extent
};

}  // namespace cb
