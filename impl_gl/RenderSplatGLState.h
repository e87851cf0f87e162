// The splat renderer's state on gl (RenderSplatGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

// Pixels the splat pass's viewport reaches past the image on each side (more than the largest half splat
// plus the 2-pixel margin), so a splat centred outside the image still draws its part inside.
inline constexpr int kSplatGuardPixels = 130;

struct RenderSplatGLState {
    static constexpr Stage kStage = Stage::RenderSplat;
    TextureSlot target;    // the RGBA32F image
    BufferSlot order;      // the flattened shared order
    BufferSlot frame;      // the shared frame block (core/math/Splat.h)
    BufferSlot counters;   // the shader's counters (splats drawn), outside a batch
    BufferSlot imageCopy;  // the pixel buffer the image passes through
    BufferSlot ground;     // with the ground: the GroundGpu block (core/math/Ground.h)
    BufferSlot phaseTable;  // phase mie: kMieCloudTable's values, uploaded once (mieUploaded)
    bool mieUploaded = false;
    // target; with phase mie the table.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
