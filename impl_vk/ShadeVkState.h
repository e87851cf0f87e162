// Shade's state on vk, and shade_sky's (ShadeVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct ShadeVkState {
    static constexpr Stage kStage = Stage::Shade;
    // Resolution 2 or 4: q and T on the coarse grid, kept between the shares of a sweep.
    BufferSlot coarseQ, coarseT;
    // Below full resolution, coarseQ and coarseT: ceil(n / f) cells per axis.
    uint64_t ScratchBytes(const Scene& scene) const;
};

// The sky light's shade (stage shade_sky): the same sweep toward the sky light, with coarse grids of its own, so
// that a sky shade between two shares of the sun's sweep leaves the sun's as they were.
struct ShadeSkyVkState : ShadeVkState {
    static constexpr Stage kStage = Stage::ShadeSky;
};

}  // namespace cb::vk
