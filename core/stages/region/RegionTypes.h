// Stage `region`'s types (SPEC 2, docs/contract.md): the ellipsoids' settings (section `ellipsoids`).
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cb {

// Horizontal wind that moves the ellipsoids, in voxels per step: one vector, or
// a grid of vectors spread over the region bounds and looked up bilinearly.
struct EllipsoidWind {
    std::array<double, 2> vector{0, 0};
    uint32_t gridNx = 0, gridNy = 0;          // 0: use `vector`
    std::vector<std::array<double, 2>> grid;  // gridNx*gridNy, x fastest
};

// A placed ellipsoid's centre at one list step (SPEC 17, docs/contract.md).
struct PlacedKeyframe {
    uint32_t step = 0;
    std::array<double, 3> center{0, 0, 0};  // voxel units
};

// An ellipsoid an artist placed by hand (SPEC 17): it enters the region volume as a random one does, but
// the wind and the jitter do not move it, no bound removes it and target_count does not count it.
// At list step t it lives when t >= start and, unless persistent, t - start < lifetime; its age is t - start
// and it shrinks over the last shrink_steps of its life like a random one.
struct PlacedEllipsoid {
    std::string name;                         // for messages and docs only
    std::array<double, 3> center{0, 0, 0};    // voxel units; with keyframes, the first keyframe's
    std::array<double, 3> semiAxes{1, 1, 1};  // voxels, each > 0
    double yawDeg = 0;                        // about z
    uint32_t start = 0;                       // the list step it appears at
    std::optional<uint32_t> lifetime;         // steps; none: persistent
    std::vector<PlacedKeyframe> keyframes;    // strictly increasing steps; empty: the centre holds
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
    std::vector<PlacedEllipsoid> placed;  // hand-placed, beside the random list (SPEC 17)
};

}  // namespace cb
