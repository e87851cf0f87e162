// The layered renderer's state on vk (RenderLayersVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct RenderLayersVkState {
    static constexpr Stage kStage = Stage::RenderLayers;
    BufferSlot frame;     // the constants (core/pipeline/LayersGpu.h), sizeof(LayersGpu)
    BufferSlot volume;    // the padded (q_alpha, T) volume, wrapped horizontally with tiling
    BufferSlot mieTable;  // kMieCloudTable's values (MiePhaseTable; only with phase Mie)
    BufferSlot stats;     // the LayersStats counters, 64-bit as two words each
    BufferSlot map;       // wang opacity: the modulation map, nx * ny floats (uploaded when it changes)
    BufferSlot billboards;  // LOD0's billboards (core/math/Layers.h LayersBillboard), in drawing order
    BufferSlot skyVolume;   // with the sky light: T_sky's padded volume, wrapped alike (SkyVolumeVk.h)
    // The constants, the padded volume, the Mie table with phase Mie, the counters, the map with wang, the
    // billboards (at most LayersBillboardBound of them), T_sky's padded volume with the sky light.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::vk
