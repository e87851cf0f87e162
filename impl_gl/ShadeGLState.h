// Shade's state on gl, and shade_sky's (ShadeGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct ShadeGLState {
    static constexpr Stage kStage = Stage::Shade;
    TextureSlot coarseQ;     // resolution > 1: the down-sampled q
    TextureSlot volume;      // the w-major volume of slices
    TextureSlot ping, pong;  // the slice loop's previous and current slice
    // R32F: coarseQ below full resolution and volume on the shaded grid; ping
    // and pong counted for the two longest axes.
    uint64_t ScratchBytes(const Scene& scene) const;
};

// The sky light's shade (stage shade_sky): the same sweep toward the sky light, with textures of its own, so that
// a sky shade between two shares of the sun's sweep leaves the sun's slices as they were.
struct ShadeSkyGLState : ShadeGLState {
    static constexpr Stage kStage = Stage::ShadeSky;
};

}  // namespace cb::gl
