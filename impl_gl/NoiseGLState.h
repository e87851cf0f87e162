// The noise former's state on gl (NoiseGL.cpp).
#pragma once

#include <cstdint>
#include <memory>

#include "core/math/Noise.h"
#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct NoiseGLState {
    static constexpr Stage kStage = Stage::Noise;
    // The scene whose data block (core/math/NoiseGpu.h) is in `data`, kept while it stays.
    std::unique_ptr<noise::NoiseForm> form;
    BufferSlot data;
    // The data block.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
