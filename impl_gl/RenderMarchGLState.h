// The ray marcher's state on gl (RenderMarchGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct RenderMarchGLState {
    static constexpr Stage kStage = Stage::RenderMarch;
    TextureSlot volume;     // the padded (q_alpha, T) volume, RG32F layers
    TextureSlot skyVolume;  // the sky light on: the padded T_sky volume, R32F layers
    TextureSlot bricks;     // skipping: the R32UI empty flags of the bricks
    TextureSlot target;     // the RGBA32F image
    BufferSlot block;       // the MarchGpu uniform block (core/pipeline/MarchGpu.h)
    BufferSlot volumeCopy;  // the padded volume as a storage buffer of (q_alpha, T) pairs
    BufferSlot skyVolumeCopy;  // the sky light on: the padded T_sky volume as a storage buffer of floats
    BufferSlot bricksCopy;  // skipping: the brick flags as a storage buffer
    BufferSlot phaseTable;  // phase mie: kMieCloudTable's values, uploaded once (mieUploaded)
    BufferSlot counters;    // the shader's MarchStats counters
    BufferSlot imageCopy;   // the pixel buffer the image passes through
    BufferSlot ground;      // with the ground: the GroundGpu block (core/math/Ground.h)
    bool mieUploaded = false;
    // volume and its copy; with the sky light skyVolume and its copy; with
    // skipping bricks and its copy; target and the RGB32F image copy; with
    // phase mie the table.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
