// Stage `shadow`'s types (SPEC 7, docs/contract.md): its settings (section `shadow`) and parameters.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <cstdint>

#include "core/math/Shading.h"

namespace cb {

// Stage `shadow` (SPEC 7).
struct ShadowSettings {
    ShadowForm form = ShadowForm::Beer;  // beer: exp(-sigma h D / s_z); thesis: 1 - clamp(kappa D); wang: eq. 19
    double kappa = 0.25;                 // thesis form: shadow per unit of D
    double coverage = 1;                 // wang form: coverage C (Wang, Ji and Zhang, eq. 15, 19)
    double densityFactor = 1;            // wang form: density factor D_w (Wang, Ji and Zhang, eq. 16, 19)
};

// Inputs of the shadow stage (SPEC 7) besides D.
struct ShadowParams {
    Vec3 sun{0, 0, 1};
    ShadowForm form = ShadowForm::Beer;
    float sigma = 0.02f, voxelSize = 50, kappa = 0.25f;
    float coverage = 1, densityFactor = 1;  // wang form (Wang, Ji and Zhang, eq. 19)
    uint32_t nz = 1;                        // grid height in voxels (the volume's mid-height is nz/2)
};

}  // namespace cb
