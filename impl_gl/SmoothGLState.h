// Smooth's state on gl (SmoothGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct SmoothGLState {
    static constexpr Stage kStage = Stage::Smooth;
    TextureSlot sumX;   // the R16UI sums along x
    TextureSlot sumXY;  // the R16UI sums along x and y
    // The slices [begin, end) whose xy sums sumXY holds, of which cld at which
    // radius, valid while the façade's count of bit-field writes is bitsWrites.
    struct Sums {
        GLuint cld = 0;
        int radius = -1;
        Extent3 extent;
        uint64_t bitsWrites = ~uint64_t(0);
        uint32_t begin = 0, end = 0;
    };
    Sums held;
    // The two R16UI sum volumes.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
