#include "reference/ExactDepth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/math/March.h"

namespace cb::ref {

double ExactDepth::Along(const Point3d& o, const Point3d& u, double tEnd) const {
    if (!mTiling) return mTracer.Integrate(o, u, 0.0, tEnd);
    if (u[2] > 0) tEnd = std::min(tEnd, (mN[2] - o[2]) / u[2]);
    if (u[2] < 0) tEnd = std::min(tEnd, (0.0 - o[2]) / u[2]);
    if (!(tEnd > 0)) return 0.0;
    // The period (kx, ky) the ray starts in, and where it leaves each.
    double k[2] = {std::floor(o[0] / mN[0]), std::floor(o[1] / mN[1])};
    double depth = 0, t = 0;
    for (int piece = 0; piece < kMaxTilePieces && t < tEnd && depth < mStopDepth; ++piece) {
        double side[2];
        for (int a = 0; a < 2; ++a)
            side[a] = u[a] > 0   ? ((k[a] + 1) * mN[a] - o[a]) / u[a]
                      : u[a] < 0 ? (k[a] * mN[a] - o[a]) / u[a]
                                 : std::numeric_limits<double>::infinity();
        const double tNext = std::min({side[0], side[1], tEnd});
        const Point3d local{o[0] - k[0] * mN[0] + 1.0, o[1] - k[1] * mN[1] + 1.0, o[2]};
        if (tNext > t) depth += mTracer.Integrate(local, u, t, tNext);
        for (int a = 0; a < 2; ++a)
            if (side[a] == tNext) k[a] += u[a] > 0 ? 1 : -1;
        t = std::max(t, tNext);
    }
    return depth;
}

double ExactDepth::Between(const Point3d& o, const Point3d& u, double t0, double t1) const {
    if (!(t0 < t1)) return 0.0;
    if (!mTiling) return mTracer.Integrate(o, u, t0, t1);
    return Along({o[0] + t0 * u[0], o[1] + t0 * u[1], o[2] + t0 * u[2]}, u, t1 - t0);
}

std::pair<Extent3, std::vector<float>> TracedField(const Extent3& grid, std::vector<float> q, bool tiling) {
    if (!tiling) return {grid, std::move(q)};
    const Extent3 grown{grid.nx + 2, grid.ny + 2, grid.nz};
    std::vector<float> out(grown.Count());
    for (uint32_t k = 0; k < grid.nz; ++k)
        for (uint32_t j = 0; j < grown.ny; ++j)
            for (uint32_t i = 0; i < grown.nx; ++i) {
                const size_t si = size_t(PaddedSourceVoxel(i, grid.nx, true));
                const size_t sj = size_t(PaddedSourceVoxel(j, grid.ny, true));
                out[i + size_t(grown.nx) * (j + size_t(grown.ny) * k)] = q[si + size_t(grid.nx) * (sj + grid.ny * k)];
            }
    return {grown, std::move(out)};
}

}  // namespace cb::ref
