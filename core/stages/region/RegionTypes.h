// Stage `region`'s types (SPEC 2, docs/contract.md): the ellipsoids' settings (section `ellipsoids`).
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace cb {

// Horizontal wind that moves the ellipsoids, in voxels per step: one vector, or
// a grid of vectors spread over the region bounds and looked up bilinearly.
struct EllipsoidWind {
    std::array<double, 2> vector{0, 0};
    uint32_t gridNx = 0, gridNy = 0;          // 0: use `vector`
    std::vector<std::array<double, 2>> grid;  // gridNx*gridNy, x fastest
};

struct EllipsoidSettings {
    uint64_t seed = 1;
    uint32_t targetCount = 40;
    uint32_t densityAdaption = 2;                 // most added or removed per step
    std::array<double, 3> sizeMean{16, 16, 8};    // semi-axes in voxels
    std::array<double, 3> sizeVariance{4, 4, 2};  // uniform +- around the mean
    double lifetimeMean = 400;                    // steps
    double lifetimeVariance = 100;
    uint32_t shrinkSteps = 40;
    double margin = 16;                            // voxels added around the grid (region bounds)
    std::array<double, 2> heightRange{0.25, 0.5};  // centre height, fraction of nz
    EllipsoidWind wind;
    double jitter = 0.05;  // uniform +- per axis per step, voxels
};

}  // namespace cb
