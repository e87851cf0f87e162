// The layered renderer's state on gl (RenderLayersGL.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct RenderLayersGLState {
    static constexpr Stage kStage = Stage::RenderLayers;
    TextureSlot volume;     // the padded (q_alpha, T) volume, RG32F layers, wrapped horizontally with tiling
    TextureSlot skyVolume;  // the sky light on: the padded T_sky volume, R32F layers, wrapped likewise
    TextureSlot target;     // the RGBA32F image
    BufferSlot block;       // the LayersGpu uniform block (core/pipeline/LayersGpu.h)
    BufferSlot order;       // the layers in drawing order (LayersDrawOrder)
    BufferSlot volumeCopy;  // the padded volume as a storage buffer of (q_alpha, T) pairs
    BufferSlot skyVolumeCopy;  // the sky light on: the padded T_sky volume as a storage buffer of floats
    BufferSlot phaseTable;  // phase mie: kMieCloudTable's values, uploaded once (mieUploaded)
    BufferSlot counters;    // the shader's LayersStats counters
    BufferSlot imageCopy;   // the pixel buffer the image passes through
    BufferSlot map;         // wang opacity: the modulation map, nx * ny floats
    BufferSlot billboards;  // LOD0's billboards (core/math/Layers.h LayersBillboard), in drawing order
    bool mieUploaded = false;
    // volume and its copy, with the sky light skyVolume and its copy, target and the RGB32F image copy; with phase
    // mie the table; with wang the map; the billboards (at most LayersBillboardBound of them).
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
