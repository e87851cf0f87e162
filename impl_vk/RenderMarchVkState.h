// The ray marcher's state on vk (RenderMarchVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

// Bytes of render_march's padded volume on a grid of extent e: (q_alpha, T) pairs, or q_alpha alone.
uint64_t MarchVolumeBytes(const Extent3& e, bool withT);

struct RenderMarchVkState {
    static constexpr Stage kStage = Stage::RenderMarch;
    BufferSlot frame;     // the constants (core/pipeline/MarchGpu.h), sizeof(MarchGpu)
    BufferSlot volume;    // the padded volume, (q_alpha, T) pairs with light "shade", else q_alpha
    BufferSlot bricks;    // one word per brick, 1 iff empty (only with skipping)
    BufferSlot mieTable;  // kMieCloudTable's values (MiePhaseTable; only with phase Mie)
    BufferSlot stats;     // the MarchStats counters, 64-bit as two words each
    BufferSlot ground;    // with the ground: the GroundGpu block (core/math/Ground.h)
    BufferSlot skyVolume;  // with the sky light: T_sky's padded volume (SkyVolumeVk.h)
    // The constants, the padded volume, a word per brick with skipping, the
    // Mie table with phase Mie, the counters, T_sky's padded volume with the sky light.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::vk
