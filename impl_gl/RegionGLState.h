// Region's state on gl (RegionGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct RegionGLState {
    static constexpr Stage kStage = Stage::Region;
    TextureSlot unorm;      // the R8 UNORM layers the ellipsoids MAX-blend into
    BufferSlot ellipsoids;  // the ellipsoids, read by the vertex shader
    // unorm: a byte per voxel.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
