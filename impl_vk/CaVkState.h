// The automaton's state on vk (CaVk.cpp).
#pragma once

#include <array>
#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct CaVkState {
    static constexpr Stage kStage = Stage::Ca;
    // With wind: the rules' hum, act and cld before advection.
    std::array<BufferSlot, 3> rules;
    BufferSlot windShifts;  // with wind: (shiftX, shiftY) per slice
    // With wind, the three rule outputs as bit fields.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::vk
