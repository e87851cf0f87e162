#include "reference/MarchReference.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/math/March.h"
#include "reference/ExactDepth.h"
#include "reference/Trilinear.h"

namespace cb::ref {

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
