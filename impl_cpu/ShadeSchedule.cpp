#include "impl_cpu/ShadeSchedule.h"

#include <algorithm>
#include <cmath>

#include "core/math/Grid.h"
#include "core/pipeline/ShadePlan.h"

namespace cb::cpu {

ShadeSchedule MakeShadeSchedule(const ShadePlan& plan, int threads, uint32_t m0, uint32_t m1) {
    ShadeSchedule s;
    m1 = std::min(m1, plan.nw);
    if (m0 >= m1) return s;
    const uint32_t slices = m1 - m0, nu = plan.nu, nv = plan.nv;
    s.work = double(slices) * nu * nv;
    s.span = s.work;
    s.blockSlices = slices;
    const uint32_t p = uint32_t(std::max(threads, 1));
    if (plan.geometry.w == 0 && nv >= kMinStridedRows) {
        // u = y, v = z: a row's cells lie a grid row apart, and one slice's
        // rows touch a cache line each per cell, too many to stay cached
        // from one slice to the next. Tiles of as many slices as a cache line
        // holds floats use each line whole. Bands of kStridedBandRows rows;
        // the rows cut into chunks (at least kMinChunkCells, whole lines)
        // until each block has two tiles a thread.
        s.axis = 1;
        s.bands = std::max<uint32_t>(1, nv / kStridedBandRows);
        s.towardHigher = plan.geometry.v0 >= 0;
        s.chunkTowardHigher = plan.geometry.u0 >= 0;
        const uint32_t wanted = std::clamp(CeilDiv(2 * p, s.bands), 1u, std::max(1u, nu / kMinChunkCells));
        s.chunkCells = CeilDiv(CeilDiv(nu, wanted), kLineFloats) * kLineFloats;
        s.chunks = CeilDiv(nu, s.chunkCells);
        s.blockSlices = std::min(kLineFloats, slices);
        s.blocks = CeilDiv(slices, s.blockSlices);
        s.span = (double(s.bands - 1 + s.chunks - 1) * s.blockSlices + slices) * double(CeilDiv(nv, s.bands)) *
                 std::min(nu, s.chunkCells);
        return s;
    }
    // Bands along v (whole rows) when each thread gets at least 4 rows, else
    // along u, at least kMinBandCells wide.
    s.axis = nv >= 4 * p ? 1 : 0;
    const uint32_t n = s.axis == 1 ? nv : nu;
    s.bands = s.axis == 1 ? p : std::max<uint32_t>(1, std::min(p, n / kMinBandCells));
    if (s.bands == 1) return s;
    const int o0 = s.axis == 1 ? plan.geometry.v0 : plan.geometry.u0;
    s.towardHigher = o0 >= 0;
    const double bandCells = double(nu) * nv / s.bands;
    // Slices per tile: about kTileCells cells, but the pipeline's fill, (bands
    // - 1) tiles, at most a quarter of the sweep.
    const uint32_t byCells = uint32_t(std::max(1.0, std::ceil(kTileCells / bandCells)));
    const uint32_t byFill = std::max<uint32_t>(1, slices / (4 * (s.bands - 1)));
    s.blockSlices = std::min({byCells, byFill, slices});
    s.blocks = CeilDiv(slices, s.blockSlices);
    // Every longest chain of tiles has bands - 1 tiles of the first block
    // (the pipeline's fill) and one tile of every block; a tile of the widest
    // band holds `widest` cells per slice.
    const double widest = double(CeilDiv(n, s.bands)) * (s.axis == 1 ? nu : nv);
    s.span = (double(s.bands - 1) * s.blockSlices + slices) * widest;
    return s;
}

}  // namespace cb::cpu
