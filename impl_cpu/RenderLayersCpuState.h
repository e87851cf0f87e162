// The layered renderer's state on cpu (RenderLayersCpu.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"

namespace cb::cpu {

struct RenderLayersCpuState {
    static constexpr Stage kStage = Stage::RenderLayers;
    std::vector<std::array<float, 2>> volume;  // the padded (q_alpha, T) volume, wrapped horizontally with tiling
    // The padded volume.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
