// The ray marcher's state on cpu (RenderMarchCpu.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"

namespace cb::cpu {

// One voxel of the ray marcher's formed volume: q_alpha and T side by side,
// so a trilinear sample of both touches one set of cache lines.
struct MarchQT {
    float q, t;
};

struct RenderMarchCpuState {
    static constexpr Stage kStage = Stage::RenderMarch;
    std::vector<MarchQT> volume;  // the padded (q_alpha, T) volume
    std::vector<float> skyVolume;  // the padded T_sky volume (the sky light on), border 1
    std::vector<uint8_t> bricks;   // skipping: 1 per empty brick, then 3 bytes of 0 (the lanes' 32-bit reads)
    // Reprojecting (core/math/Reprojection.h): per block its traced colour and view depth (4 floats) and the bounds of
    // its neighbourhood's traced colours (6), and the previous frame.
    std::vector<float> traced, bounds, history;
    // The padded volume (and T_sky's with the sky light), one byte per brick, and what reprojecting holds.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
