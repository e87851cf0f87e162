// Density's state on vk (DensityVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct DensityVkState {
    static constexpr Stage kStage = Stage::Density;
    BufferSlot coverCounter;  // covered columns, one uint
    uint64_t ScratchBytes(const Scene&) const { return 0; }
};

}  // namespace cb::vk
