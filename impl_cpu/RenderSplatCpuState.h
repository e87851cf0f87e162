// The splat renderer's state on cpu (RenderSplatCpu.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math/Splat.h"
#include "core/scene/Scene.h"

namespace cb::cpu {

struct RenderSplatCpuState {
    static constexpr Stage kStage = Stage::RenderSplat;
    std::vector<std::vector<Splat>> slices;  // each outer slice's splats, kept so steady-state frames do not allocate
    // The splat lists depend on the clouds: not counted.
    uint64_t ScratchBytes(const Scene&) const { return 0; }
};

}  // namespace cb::cpu
