// The noise former's state on cpu (NoiseCpu.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/math/Noise.h"
#include "core/scene/Scene.h"

namespace cb::cpu {

struct NoiseCpuState {
    static constexpr Stage kStage = Stage::Noise;
    // What does not change per step (permutations, the detail volume), made on
    // the first call and again only when the settings or grid change.
    std::unique_ptr<noise::NoiseForm> form;
    std::vector<float> map;  // the weather map of one call (coverage only)
    // The detail volume (size^3 floats) and the weather map (nx * ny floats).
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
