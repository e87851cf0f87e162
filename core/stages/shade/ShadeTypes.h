// Stage `shade`'s types (SPEC 6, docs/contract.md): its settings (section `shade`) and parameters.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/base/Error.h"
#include "core/math/Grid.h"
#include "core/math/Shading.h"

namespace cb {

// The shaded grid's coarsening f (SPEC 6: shade.resolution), the one list the
// scene reader and every backend check against.
inline constexpr int64_t kShadeResolutions[] = {1, 2, 4};
inline constexpr const char* kShadeResolutionsText = "1, 2 or 4";
inline bool IsShadeResolution(int64_t f) {
    for (const int64_t allowed : kShadeResolutions)
        if (f == allowed) return true;
    return false;
}
struct ShadeSettings {
    AttenuationKind attenuation = AttenuationKind::Beer;
    double sigma = 0.02;    // extinction coefficient at q = 1, 1/m (beer, and tau for scattering)
    double thesisAr = 0.9;  // a_r of the thesis's linear form
    SampleFilter filter = SampleFilter::Bilinear;
    int resolution = 1;  // one of kShadeResolutions
    StorageFormat storage = StorageFormat::Fp32;
    bool scattering = false;   // multiple forward scattering (Wang, Ji and Zhang, eq. 5-7)
    double albedo = 0.9;       // alpha_s
    double solidAngle = 0.05;  // gamma, steradians
};

// What a shade stage answers for a resolution outside kShadeResolutions: "BACKEND: shade resolution must be ...".
inline Status CheckShadeResolution(std::string_view backend, int64_t f) {
    if (IsShadeResolution(f)) return {};
    return MakeError(std::string(backend) + ": shade resolution must be " + kShadeResolutionsText);
}

// Inputs of the shade stage (SPEC 6) besides q.
struct ShadeParams {
    Vec3 sun{0, 0, 1};  // unit vector toward the sun
    AttenuationKind attenuation = AttenuationKind::Beer;
    float sigma = 0.02f;   // 1/m at q = 1
    float voxelSize = 50;  // h, metres
    float thesisAr = 0.9f;
    SampleFilter filter = SampleFilter::Bilinear;
    int resolution = 1;  // one of kShadeResolutions
    StorageFormat storage = StorageFormat::Fp32;
    bool scattering = false;
    float albedo = 0.9f, solidAngle = 0.05f;
    PhaseParams phase;
    SliceRange slices;  // the sweep's slices m to compute
};

}  // namespace cb
