// The automaton's state on cpu (CaCpu.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"
#include "impl_cpu/BitField.h"

namespace cb::cpu {

struct CaCpuState {
    static constexpr Stage kStage = Stage::Ca;
    // With wind: the three fields the rules write and advection then moves into the output.
    std::vector<BitField> advect;
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
