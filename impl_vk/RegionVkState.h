// Region's state on vk (RegionVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct RegionVkState {
    static constexpr Stage kStage = Stage::Region;
    BufferSlot ellipsoids;   // the ellipsoids, 32 bytes each
    BufferSlot tileStarts;   // first tileEntries index per 16x16 tile of a slice, and one past the end
    BufferSlot tileEntries;  // ellipsoid indices, tile by tile
    // The lists depend on the ellipsoids, not on the scene's sizes: not counted.
    uint64_t ScratchBytes(const Scene&) const { return 0; }
};

}  // namespace cb::vk
