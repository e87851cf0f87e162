#include "impl_vk/RegionTileLists.h"

#include <algorithm>
#include <cmath>

namespace cb::vk {

bool EllipsoidReachesRegionTile(const RasterEllipsoid& el, const Extent3& grid, uint32_t tx, uint32_t ty, uint32_t k) {
    const float x0 = float(tx * kRegionTile) + 0.5f, x1 = float(std::min(grid.nx, (tx + 1) * kRegionTile) - 1) + 0.5f;
    const float y0 = float(ty * kRegionTile) + 0.5f, y1 = float(std::min(grid.ny, (ty + 1) * kRegionTile) - 1) + 0.5f;
    const float z = float(k) + 0.5f;
    const float reach = std::max(el.semiAxes[0], el.semiAxes[1]) + 2.0f;
    return !(std::fabs(z - el.center[2]) > el.semiAxes[2] + 2.0f || el.center[0] + reach < x0 ||
             el.center[0] - reach > x1 || el.center[1] + reach < y0 || el.center[1] - reach > y1);
}

namespace {

// The indices [first, last] of `count` cells of `size` voxels whose centres may lie within
// [centre - reach, centre + reach], widened by a cell either side (the exact test decides); empty when first > last.
struct CellSpan {
    int64_t first = 0, last = -1;
};
CellSpan CandidateCells(float centre, float reach, uint32_t size, uint32_t count) {
    const double lo = std::floor((double(centre) - double(reach)) / size) - 1;
    const double hi = std::floor((double(centre) + double(reach)) / size) + 1;
    if (!(lo <= hi)) return {};  // NaN
    return {int64_t(std::clamp(lo, 0.0, double(count))), int64_t(std::clamp(hi, -1.0, double(count) - 1))};
}

}  // namespace

RegionTileLists BuildRegionTileLists(std::span<const RasterEllipsoid> ellipsoids, const Extent3& grid, uint32_t k0,
                                     uint32_t k1) {
    RegionTileLists lists;
    lists.tilesX = (grid.nx + kRegionTile - 1) / kRegionTile;
    lists.tilesY = (grid.ny + kRegionTile - 1) / kRegionTile;
    const uint32_t slices = k1 > k0 ? k1 - k0 : 0;
    const size_t tiles = size_t(lists.tilesX) * lists.tilesY * slices;
    // Each ellipsoid visits only the tiles its box can reach, in ascending ellipsoid order; a
    // stable counting sort by tile then keeps every list ascending, as a scan over all pairs would.
    struct Pair {
        uint32_t tile, ellipsoid;
    };
    std::vector<Pair> pairs;
    std::vector<uint32_t> counts(tiles + 1, 0);
    for (uint32_t n = 0; n < ellipsoids.size(); ++n) {
        const RasterEllipsoid& el = ellipsoids[n];
        const float reach = std::max(el.semiAxes[0], el.semiAxes[1]) + 2.0f;
        const CellSpan xs = CandidateCells(el.center[0], reach, kRegionTile, lists.tilesX);
        const CellSpan ys = CandidateCells(el.center[1], reach, kRegionTile, lists.tilesY);
        const CellSpan ks = CandidateCells(el.center[2], el.semiAxes[2] + 2.0f, 1, k1);
        for (int64_t k = std::max<int64_t>(ks.first, k0); k <= ks.last; ++k)
            for (int64_t ty = ys.first; ty <= ys.last; ++ty)
                for (int64_t tx = xs.first; tx <= xs.last; ++tx) {
                    if (!EllipsoidReachesRegionTile(el, grid, uint32_t(tx), uint32_t(ty), uint32_t(k))) continue;
                    const uint32_t tile =
                        uint32_t(tx + int64_t(lists.tilesX) * (ty + int64_t(lists.tilesY) * (k - k0)));
                    pairs.push_back({tile, n});
                    ++counts[tile + 1];
                }
    }
    for (size_t t = 0; t < tiles; ++t) counts[t + 1] += counts[t];
    lists.starts = counts;
    lists.entries.resize(pairs.size());
    for (const Pair& p : pairs) lists.entries[counts[p.tile]++] = p.ellipsoid;
    return lists;
}

}  // namespace cb::vk
