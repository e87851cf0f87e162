// Shade's state on cpu (ShadeCpu.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"

namespace cb::cpu {

struct ShadeCpuState {
    static constexpr Stage kStage = Stage::Shade;
    // At resolution f > 1: q and T on the coarse grid, kept between the shares of a sweep.
    std::vector<float> coarseQ, coarseT;
    // coarseQ and coarseT below full resolution (ceil(n / f) cells per axis,
    // ShadePlan); the sweep reads the previous slice in place, and its rows and
    // tile counts are per call.
    uint64_t ScratchBytes(const Scene& scene) const;
};

// The sky light's shade (stage shade_sky): the same sweep toward the sky light, with coarse grids of its own.
struct ShadeSkyCpuState : ShadeCpuState {
    static constexpr Stage kStage = Stage::ShadeSky;
};

}  // namespace cb::cpu
