// The memory a scene needs on the CPU backend, and the memory the machine has.
// The estimate saturates at UINT64_MAX instead of overflowing.
#include "core/SceneMemory.h"

#include <unistd.h>

#include <algorithm>
#include <limits>

#include "core/Scene.h"

namespace cb {
namespace {

uint64_t SatAdd(uint64_t a, uint64_t b) {
    uint64_t r;
    return __builtin_add_overflow(a, b, &r) ? std::numeric_limits<uint64_t>::max() : r;
}

uint64_t SatMul(uint64_t a, uint64_t b) {
    uint64_t r;
    return __builtin_mul_overflow(a, b, &r) ? std::numeric_limits<uint64_t>::max() : r;
}

uint64_t CeilDiv64(uint64_t a, uint64_t b) { return b == 0 ? a : a / b + (a % b != 0 ? 1 : 0); }

}  // namespace

namespace scene_io {

std::optional<uint64_t> PhysicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return std::nullopt;
    return SatMul(uint64_t(pages), uint64_t(pageSize));
}

}  // namespace scene_io

uint64_t EstimateSceneBytes(const Scene& scene) {
    const Extent3& e = scene.grid.size;
    const uint64_t voxels = SatMul(SatMul(e.nx, e.ny), e.nz);
    // One bit field: rows of 64-voxel words.
    const uint64_t bitField = SatMul(SatMul(SatMul(CeilDiv64(e.nx, 64), e.ny), e.nz), 8);

    uint64_t bytes = SatMul(voxels, 4);  // canonical dump staging buffer, float32 per voxel
    if (scene.stages.Has(Stage::Region)) bytes = SatAdd(bytes, SatAdd(voxels, 64));
    if (scene.stages.Has(Stage::Ca)) {
        // hum/act/cld for two steps, plus three advection scratch fields with wind.
        bytes = SatAdd(bytes, SatMul(bitField, scene.ca.HasWind() ? 9 : 6));
    }
    if (scene.stages.Has(Stage::Smooth)) {
        // q for the previous and current step, plus each thread's ring of up to
        // five 16-bit slices (counted for 64 threads: an upper bound).
        const uint64_t slice = uint64_t(scene.grid.size.nx) * scene.grid.size.ny;
        bytes = SatAdd(bytes, SatAdd(SatMul(voxels, 8), SatMul(slice, 64 * 5 * 2)));
    }
    if (scene.stages.Has(Stage::Density)) {
        const uint64_t columns = SatMul(e.nx, e.ny);
        const uint64_t tile = std::max<uint32_t>(scene.density.tile, 1);
        const uint64_t band = std::max<uint32_t>(scene.density.band, 1);
        const uint64_t tiles = SatMul(CeilDiv64(e.nx, tile), CeilDiv64(e.ny, tile));
        bytes = SatAdd(bytes, SatMul(columns, 8));  // D for two steps, float32
        bytes = SatAdd(bytes, SatMul(SatMul(tiles, SatAdd(CeilDiv64(e.nz, band), 1)), 2));
    }
    if (scene.stages.Has(Stage::Shade)) {
        // T, float32 per voxel; below full resolution also the coarse q and T grids.
        bytes = SatAdd(bytes, SatMul(voxels, 4));
        const uint64_t f = uint64_t(std::max(scene.shade.resolution, 1));
        if (f > 1) {
            const uint64_t coarse = SatMul(SatMul(CeilDiv64(e.nx, f), CeilDiv64(e.ny, f)), CeilDiv64(e.nz, f));
            bytes = SatAdd(bytes, SatMul(coarse, 2 * 4));
        }
    }
    if (scene.stages.Has(Stage::Shadow)) bytes = SatAdd(bytes, SatMul(SatMul(e.nx, e.ny), 4));  // G, float32
    if (scene.stages.Has(Stage::RenderSplat)) {
        // One more q volume (the previous step, for the alpha interpolation) and the RGB float32 image.
        bytes = SatAdd(bytes, SatMul(voxels, 4));
        bytes = SatAdd(bytes, SatMul(SatMul(scene.render.width, scene.render.height), 3 * 4));
    }
    // Other stages do not have an estimate yet and count 0.
    return bytes;
}

}  // namespace cb
