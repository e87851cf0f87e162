// Shafts of light (SPEC 18) in a renderer's frame: the scene's shafts as one frame's block (core/math/Shafts.h
// ShaftsFrame) for every backend's AddShafts. docs/pipeline.md, "Shafts of light".
#pragma once

#include <cstdint>
#include <string_view>

#include "core/math/Camera.h"
#include "core/math/Shafts.h"
#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"

namespace cb {

// The shafts of `camera`'s frame at `step` (the sun's direction at the step; the shadow form, sigma and the grid of
// the scene). Only meaningful with sc.lighting.shafts.on.
ShaftsFrame MakeSceneShaftsFrame(const Scene& sc, const CameraFrame& camera, uint32_t step);

// What every backend's AddShafts checks first: D is (nx, ny, 1) of the frame's grid and the image (3, width,
// height); the error names `backend`.
Status CheckShaftsBuffers(const ShaftsFrame& frame, const Buffer& columnSum, const Buffer& image,
                          std::string_view backend);

}  // namespace cb
