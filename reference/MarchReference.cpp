#include "reference/MarchReference.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "core/math/March.h"
#include "reference/Trilinear.h"

namespace cb::ref {
namespace {

// The exact integral of q_alpha (voxel edges) along o + t u, t in [0, tEnd] (tEnd may be +infinity: to the
// volume's edge). Without tiling the tracer covers the box. With tiling it covers one period grown by a wrapped
// column on each side (voxel (i, j, k) at (i + 1, j + 1, k)), where the trilinear field over [1, n + 1] in x and y
// is the periodic field over [0, n]: the ray is clipped to the slab 0 <= z <= nz, cut where it crosses a
// period's side, and each piece integrated in its own period. The walk stops once the depth reaches `stopDepth`
// (where exp(-sigma h depth) rounds to 0 in float), or after kMaxTilePieces pieces: a light within about 0.001
// degrees of the horizon, whose path through the slab crosses that many periods, is integrated that far.
class ExactDepth {
  public:
    static constexpr int kMaxTilePieces = 1 << 16;

    ExactDepth(const TrilinearDepthTracer& tracer, const Extent3& grid, bool tiling, double stopDepth)
        : mTracer(tracer),
          mTiling(tiling),
          mN{double(grid.nx), double(grid.ny), double(grid.nz)},
          mStopDepth(stopDepth) {}

    double Along(const Point3d& o, const Point3d& u, double tEnd) const {
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

  private:
    const TrilinearDepthTracer& mTracer;
    bool mTiling;
    double mN[3];
    double mStopDepth;
};

// The field the tracer holds: q itself, or with tiling one period grown by a wrapped column on each side in x and y.
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

}  // namespace

Result<MarchReferenceResult> RenderMarchReference(const MarchParams& params, const Extent3& grid,
                                                  std::span<const float> qPrev, std::span<const float> qCur,
                                                  const MarchReferenceOptions& options) {
    if (qPrev.size() != grid.Count() || qCur.size() != grid.Count())
        return MakeError("reference render: q does not have the grid's size");
    if (!(options.stepVoxels > 0.0f) || !std::isfinite(options.stepVoxels))
        return MakeError("reference render: the step must be positive");
    const auto start = std::chrono::steady_clock::now();
    // q_alpha, the field both the main march and the exact light read.
    std::vector<float> q(grid.Count());
    for (size_t v = 0; v < q.size(); ++v) q[v] = Lerp(qPrev[v], qCur[v], params.alpha);
    MarchSetup s = params.setup;
    s.step = options.stepVoxels;
    s.adaptive = false;
    s.epsilon = 0.0f;
    const auto [tracedExtent, traced] = TracedField(grid, q, s.tiling);
    auto tracer = TrilinearDepthTracer::Create(tracedExtent, traced, options.threads);
    if (!tracer) return std::unexpected(tracer.error());
    const TrilinearDepthTracer& exact = **tracer;
    const double sigmaH = s.sigmaH;
    // exp(-x) rounds to 0 in float for x > 104 (the smallest subnormal is e^-103.3).
    const ExactDepth depth(exact, grid, s.tiling,
                           sigmaH > 0 ? 110.0 / sigmaH : std::numeric_limits<double>::infinity());
    const Point3d sun{s.sun[0], s.sun[1], s.sun[2]};
    const Point3d sky{s.light.skyDirection[0], s.light.skyDirection[1], s.light.skyDirection[2]};
    const Point3d light{s.light.pointPosition[0], s.light.pointPosition[1], s.light.pointPosition[2]};
    const CameraFrame& cam = params.camera;
    const uint32_t W = cam.width, H = cam.height;

    MarchReferenceResult r;
    r.buildSeconds = exact.BuildSeconds();
    r.primitives = exact.Primitives();
    r.image.assign(3 * size_t(W) * H, 0.0f);
    std::atomic<uint64_t> lightRays{0}, samples{0};
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<uint32_t>(0, H, 4, 0, W, 4), [&](const tbb::blocked_range2d<uint32_t>& b) {
                uint64_t nLight = 0, nSamples = 0;
                auto density = [&](const Vec3& p) { return TrilinearSample(q.data(), grid, 0.0f, p, s.tiling); };
                auto exactLight = [&](const Vec3& p) {
                    const Point3d at{p[0], p[1], p[2]};
                    MarchLightSample l;
                    l.sun = float(std::exp(-sigmaH * depth.Along(at, sun, std::numeric_limits<double>::infinity())));
                    ++nLight;
                    if (s.light.skyOn) {
                        l.sky =
                            float(std::exp(-sigmaH * depth.Along(at, sky, std::numeric_limits<double>::infinity())));
                        ++nLight;
                    }
                    if (s.light.pointOn) {
                        const Point3d v{light[0] - at[0], light[1] - at[1], light[2] - at[2]};
                        const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                        if (length > 0)
                            l.point = float(std::exp(
                                -sigmaH * depth.Along(at, {v[0] / length, v[1] / length, v[2] / length}, length)));
                        ++nLight;
                    }
                    return l;
                };
                for (uint32_t y = b.rows().begin(); y < b.rows().end(); ++y)
                    for (uint32_t x = b.cols().begin(); x < b.cols().end(); ++x) {
                        const MarchRayGeometry ray =
                            MakePixelRay(cam, params.origin, s.voxelSize, s.size, x, y, s.tiling);
                        const MarchRayResult m = MarchRay(s, ray, 0.5f, nullptr, density, exactLight);
                        float* out = r.image.data() + 3 * (size_t(x) + size_t(W) * y);
                        out[0] = m.color[0];
                        out[1] = m.color[1];
                        out[2] = m.color[2];
                        nSamples += m.samples;
                    }
                lightRays += nLight;
                samples += nSamples;
            });
    });
    r.light.rays = lightRays;
    r.samples = samples;
    r.light.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace cb::ref
