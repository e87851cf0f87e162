// Stage `density`'s types (SPEC 5, docs/contract.md): its settings (section `density`), outputs and
// parameters.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <cstdint>

#include "core/math/Grid.h"

namespace cb {

class Buffer;  // core/pipeline/Backend.h

struct DensitySettings {
    uint32_t tile = 32;  // tile edge in columns
    uint32_t band = 4;   // slices per height band
};

// Outputs of the density stage (SPEC 5) for one step. The tile and band
// occupancy are this step's alone; the renderer ORs the two steps it
// interpolates between (docs/pipeline.md).
struct DensityOutputs {
    Buffer* columnSum = nullptr;  // F32, (nx, ny, 1): D
    Buffer* tiles = nullptr;      // U8, (ceil(nx/T), ceil(ny/T), 1): 1 iff D > 0 in the tile
    Buffer* bands = nullptr;      // U8, (ceil(nx/T), ceil(ny/T), ceil(nz/B)): 1 iff q > 0 in tile x band
    uint32_t coveredColumns = 0;  // columns (i, j) with any cld = 1; without cld, with D > 0
};

struct DensityParams {
    uint32_t tile = 32;
    uint32_t band = 4;
    SliceRange slices;  // the rows of tiles to compute
};

}  // namespace cb
