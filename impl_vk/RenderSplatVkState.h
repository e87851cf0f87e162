// The splat renderer's state on vk (RenderSplatVk.cpp).
#pragma once

#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct RenderSplatVkState {
    static constexpr Stage kStage = Stage::RenderSplat;
    BufferSlot frame;             // grid, camera and light (the shaders' Frame)
    BufferSlot rankParts;         // per position of each axis order, its coordinate and index shares
    BufferSlot boxes;             // visibility of each tile x band box, one byte each
    BufferSlot candidates;        // a bit per rank, 1 where it makes a splat
    BufferSlot chunkSplats;       // splats per chunk of ranks
    BufferSlot chunkPairs;        // (screen tile, splat) pairs per chunk of ranks
    BufferSlot chunkOffsets;      // chunkSplats scanned, and the total
    BufferSlot chunkPairOffsets;  // chunkPairs scanned, and the total
    BufferSlot totals;       // the splats, the pairs, and 64 slots of voxels visited and fragments, read by the host
    BufferSlot splats;       // the splats in the shared order, 48 bytes each
    BufferSlot splatTiles;   // screen tiles per splat
    BufferSlot pairOffsets;  // splatTiles scanned, and the total
    BufferSlot keys[2];      // the pairs' screen tiles (radix sort ping, pong)
    BufferSlot values[2];    // the pairs' splat indices (radix sort ping, pong)
    BufferSlot sortCounts;   // pairs per radix digit x sort block
    BufferSlot sortOffsets;  // sortCounts scanned, and the total
    BufferSlot tileBases;    // the first sorted pair of each screen tile, and the pairs
    BufferSlot scanSums;     // the block sums of its scans (scan.comp)
    BufferSlot ground;       // with the ground: the GroundGpu block (core/math/Ground.h)
    BufferSlot mieTable;     // with phase Mie: kMieCloudTable's values (MiePhaseTable)
    // The Mie table with phase Mie; the lists depend on the clouds: not counted.
    uint64_t ScratchBytes(const Scene& scene) const {
        return scene.phase.kind == PhaseKind::Mie ? uint64_t(kMieCloudTable.count) * 4 : 0;
    }
};

}  // namespace cb::vk
