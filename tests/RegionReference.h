// The region volume (SPEC 2) by brute force: every ellipsoid's quantised
// weight at every voxel centre, max-blended. The slow path the CPU's per-row
// span rasteriser is checked against.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/Rules.h"

namespace cb::test {

inline std::vector<uint8_t> BruteForceRegion(const Extent3& e, const std::vector<RasterEllipsoid>& list) {
    std::vector<uint8_t> region(e.Count(), 0);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                uint8_t best = 0;
                for (const RasterEllipsoid& el : list)
                    best = uint8_t(std::max<int>(best, QuantizeRegion(EllipsoidWeight(el, i + 0.5f, j + 0.5f, k + 0.5f))));
                region[VoxelIndex(e, i, j, k)] = best;
            }
    return region;
}

}  // namespace cb::test
