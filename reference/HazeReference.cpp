#include "reference/HazeReference.h"

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
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The early stop: the rest of the integral is below this share of the sum so far (far below float's rounding) ...
constexpr double kRelativeStop = 1e-10;
// ... or, times the largest sunRadiance P^, below this (rounds to 0 in float, whose least subnormal is 1.4e-45).
constexpr double kAbsoluteStop = 1e-46;

// Clips [t0, t1] to lo <= o + t d <= hi along one axis. False if empty.
bool ClipAxis(double o, double d, double lo, double hi, double& t0, double& t1) {
    if (d == 0.0) return lo <= o && o <= hi && t0 < t1;
    double ta = (lo - o) / d, tb = (hi - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    return t0 < t1;
}

// int_t0^t1 sigma exp(-sigma t) dt = exp(-sigma t0) - exp(-sigma t1), without cancellation for small sigma (t1 - t0).
double ExpWeight(double sigma, double t0, double t1) { return -std::exp(-sigma * t0) * std::expm1(-sigma * (t1 - t0)); }

// The xy bounds of the field's support (dual cells with a nonzero corner, clipped to the box) and its top; false if
// q is all zero.
struct Support {
    double lo[2], hi[2], zTop;
};
bool FieldSupport(const Extent3& grid, std::span<const float> q, Support& s) {
    int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {-1, -1, -1};
    for (uint32_t k = 0; k < grid.nz; ++k)
        for (uint32_t j = 0; j < grid.ny; ++j)
            for (uint32_t i = 0; i < grid.nx; ++i)
                if (q[i + size_t(grid.nx) * (j + size_t(grid.ny) * k)] != 0.0f) {
                    const int64_t v[3] = {i, j, k};
                    for (int a = 0; a < 3; ++a) {
                        lo[a] = std::min(lo[a], v[a]);
                        hi[a] = std::max(hi[a], v[a]);
                    }
                }
    if (hi[0] < 0) return false;
    const double n[3] = {double(grid.nx), double(grid.ny), double(grid.nz)};
    for (int a = 0; a < 2; ++a) {
        s.lo[a] = std::max(0.0, double(lo[a]) - 0.5);
        s.hi[a] = std::min(n[a], double(hi[a]) + 1.5);
    }
    s.zTop = std::min(n[2], double(hi[2]) + 1.5);
    return true;
}

// One pixel's haze integral int_a^b sigma V Tview exp(-sigma t) dt (without sunRadiance P^).
struct HazeIntegrator {
    const ExactDepth* depth = nullptr;  // null: no clouds (V = Tview = 1)
    bool tiling = false;
    double sigma = 0, sigmaCloud = 0, step = 0.25;
    Point3d sun{0, 0, 1};
    double rectLo[2] = {0, 0}, rectHi[2] = {0, 0};  // R, without tiling
    double absoluteStop = 0;                        // kAbsoluteStop / (max sunRadiance P^)

    double operator()(const Point3d& o, const Point3d& d, double a, double b, uint64_t& nodes) const {
        if (!depth) return ExpWeight(sigma, a, b);
        // [c1, c2]: the composite rule's part; closed before and after it.
        double c1 = a, c2 = b;
        bool inside = true;
        if (!tiling)
            for (int ax = 0; ax < 2 && inside; ++ax) inside = ClipAxis(o[ax], d[ax], rectLo[ax], rectHi[ax], c1, c2);
        double viewDepth = depth->Between(o, d, 0.0, a);
        if (!inside) return std::exp(-sigmaCloud * viewDepth) * ExpWeight(sigma, a, b);
        double sum = std::exp(-sigmaCloud * viewDepth) * ExpWeight(sigma, a, c1);
        viewDepth += depth->Between(o, d, a, c1);
        const double span = c2 - c1;
        const uint64_t n = uint64_t(std::clamp(std::ceil(span / step), 1.0, 0x1p62));
        const double dt = span / double(n);
        double tPrev = c1, viewPrev = std::exp(-sigmaCloud * viewDepth);
        for (uint64_t i = 0; i < n; ++i) {
            const double t0 = c1 + double(i) * dt, t1 = i + 1 == n ? c2 : c1 + double(i + 1) * dt;
            // The most the rest (from t0 on, the closed tail included) can add.
            const double rest = viewPrev * std::exp(-sigma * t0);
            if (rest <= kRelativeStop * sum || rest < absoluteStop) return sum;
            const double tm = 0.5 * (t0 + t1);
            viewDepth += depth->Between(o, d, tPrev, tm);
            tPrev = tm;
            viewPrev = std::exp(-sigmaCloud * viewDepth);
            const Point3d p{o[0] + tm * d[0], o[1] + tm * d[1], o[2] + tm * d[2]};
            const double v = std::exp(-sigmaCloud * depth->Along(p, sun, kInf));
            sum += v * viewPrev * ExpWeight(sigma, t0, t1);
            ++nodes;
        }
        viewDepth += depth->Between(o, d, tPrev, c2);
        return sum + std::exp(-sigmaCloud * viewDepth) * ExpWeight(sigma, c2, b);
    }
};

}  // namespace

Result<HazeReferenceResult> RenderHazeReference(const HazeReferenceParams& params, const Extent3& grid,
                                                std::span<const float> qAlpha) {
    if (qAlpha.size() != grid.Count()) return MakeError("haze reference: q does not have the grid's size");
    if (grid.Count() == 0) return MakeError("haze reference: the grid is empty");
    if (!(params.stepVoxels > 0) || !std::isfinite(params.stepVoxels))
        return MakeError("haze reference: the step must be positive");
    if (!(params.voxelSize > 0) || !std::isfinite(params.voxelSize))
        return MakeError("haze reference: the voxel size must be positive");
    if (!(params.extinction >= 0) || !std::isfinite(params.extinction) || !(params.cloudSigma >= 0) ||
        !std::isfinite(params.cloudSigma))
        return MakeError("haze reference: the extinctions must be finite and not negative");
    if (!(std::fabs(params.g) < 1)) return MakeError("haze reference: g must lie in (-1, 1)");
    const CameraFrame& cam = params.camera;
    if (cam.width == 0 || cam.height == 0) return MakeError("haze reference: the image is empty");
    if (!std::isfinite(cam.nearPlane) || !std::isfinite(cam.farPlane))
        return MakeError("haze reference: the near and far planes must be finite");
    Point3d sun{params.sun[0], params.sun[1], params.sun[2]};
    const double sunLength = std::sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
    if (!(sunLength > 0) || !std::isfinite(sunLength)) return MakeError("haze reference: the sun has no direction");
    for (double& c : sun) c /= sunLength;
    for (float c : params.sunRadiance)
        if (!std::isfinite(c)) return MakeError("haze reference: the sun's radiance must be finite");

    const auto start = std::chrono::steady_clock::now();
    const uint32_t W = cam.width, H = cam.height;
    HazeReferenceResult r;
    r.image.assign(3 * size_t(W) * H, 0.0f);
    if (!(sun[2] > 0)) {  // at or below the horizon
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return r;
    }
    const double h = params.voxelSize;
    HazeIntegrator haze;
    haze.tiling = params.tiling;
    haze.sigma = params.extinction * h;
    haze.sigmaCloud = params.cloudSigma * h;
    haze.step = params.stepVoxels;
    haze.sun = sun;
    double maxRadiance = 0;
    for (float c : params.sunRadiance) maxRadiance = std::max(maxRadiance, std::fabs(double(c)));
    const double gg = params.g;
    const double maxPhase = (1 + std::fabs(gg)) / ((1 - std::fabs(gg)) * (1 - std::fabs(gg)));
    haze.absoluteStop = kAbsoluteStop / std::max(maxRadiance * maxPhase, 1e-300);

    // The tracer, only where the clouds can attenuate anything.
    Support support{};
    std::unique_ptr<TrilinearDepthTracer> tracer;
    std::unique_ptr<ExactDepth> depth;
    if (haze.sigmaCloud > 0 && FieldSupport(grid, qAlpha, support)) {
        const auto [tracedExtent, traced] =
            TracedField(grid, std::vector<float>(qAlpha.begin(), qAlpha.end()), params.tiling);
        auto built = TrilinearDepthTracer::Create(tracedExtent, traced, params.threads);
        if (!built) return std::unexpected(built.error());
        tracer = std::move(*built);
        // exp(-x) rounds to 0 in float for x > 104 (as in MarchReference).
        depth = std::make_unique<ExactDepth>(*tracer, grid, params.tiling, 110.0 / haze.sigmaCloud);
        haze.depth = depth.get();
        // R: the support's footprint swept back along the sun over the support's height.
        for (int a = 0; a < 2; ++a) {
            const double shift = -sun[a] / sun[2] * support.zTop;
            const double margin = 1e-9 * (1.0 + std::fabs(support.hi[a]) + std::fabs(shift));
            haze.rectLo[a] = support.lo[a] + std::min(0.0, shift) - margin;
            haze.rectHi[a] = support.hi[a] + std::max(0.0, shift) + margin;
        }
    }

    const Point3d eye{(double(cam.eye[0]) - params.origin[0]) / h, (double(cam.eye[1]) - params.origin[1]) / h,
                      (double(cam.eye[2]) - params.origin[2]) / h};
    const double zTop = 0.5 * double(grid.nz);
    std::atomic<uint64_t> samples{0};
    tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, H, 4, 0, W, 4),
                          [&](const tbb::blocked_range2d<uint32_t>& blk) {
                              uint64_t nodes = 0;
                              for (uint32_t y = blk.rows().begin(); y < blk.rows().end(); ++y)
                                  for (uint32_t x = blk.cols().begin(); x < blk.cols().end(); ++x) {
                                      const PixelDirection pd = PixelRayDirection(cam, x, y);
                                      const Point3d d{pd.dir[0], pd.dir[1], pd.dir[2]};
                                      const double perDepth = 1.0 / (h * double(pd.cosForward));
                                      double a = double(cam.nearPlane) * perDepth, b = double(cam.farPlane) * perDepth;
                                      if (!ClipAxis(eye[2], d[2], 0.0, zTop, a, b)) continue;
                                      const double cosTheta = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
                                      const double denom = 1 + gg * gg - 2 * gg * cosTheta;
                                      const double phase = (1 - gg * gg) / (denom * std::sqrt(denom));
                                      const double value = phase * haze(eye, d, a, b, nodes);
                                      float* out = r.image.data() + 3 * (size_t(x) + size_t(W) * y);
                                      for (int c = 0; c < 3; ++c) out[c] = float(double(params.sunRadiance[c]) * value);
                                  }
                              samples += nodes;
                          });
    });
    r.samples = samples;
    r.lightRays = samples;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace cb::ref
