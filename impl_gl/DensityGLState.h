// Density's state on gl (DensityGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct DensityGLState {
    static constexpr Stage kStage = Stage::Density;
    TextureSlot coverFlags;   // the R8UI flags of the covered columns
    BufferSlot coverCounter;  // the atomic counter of covered columns (outside a batch)
    // coverFlags: a byte per column.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
