// OpticalDepthTracer with Embree 3 user geometry.
//
// Why no voxel is missed or counted twice:
// - Geometry: one box per maximal run of voxels with q > 0 along x in a row
//   (j, k). Runs are disjoint and each is one primitive, referenced by one BVH
//   leaf: user geometry is never split, and the scene is built at medium
//   quality (Embree documents that only the high-quality build may call a
//   callback more than once for the same primitive).
// - Traversal: the callback never reports a hit, so tfar stays infinite and
//   Embree visits every primitive whose box the ray touches; the scene is
//   RTC_SCENE_FLAG_ROBUST, so box tests are conservative.
// - Arithmetic: the callback clips the ray to the run box and to each voxel of
//   the run in double, every boundary plane b giving t = (b - o_a) / d_a by the
//   same expression wherever it appears, so the pieces of neighbouring voxels
//   and runs meet exactly and their lengths add up. An axis with d_a = 0 uses
//   half-open intervals [lo, hi), so a ray along a shared face counts in one
//   voxel only.
#include "reference/Reference.h"

#include "reference/EmbreeRuns.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

namespace cb::ref {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A maximal run of occupied voxels [i0, i1) x {j} x {k}.
struct Run {
    uint32_t i0, i1, j, k;
};

struct Geometry {
    Extent3 extent;
    std::vector<float> q;
    std::vector<Run> runs;
};

// Per-ray state. `base` must come first: Embree hands the callback &base.
struct RayContext {
    RTCIntersectContext base;
    double start = 0;  // count only t > start
    double sum = 0;    // sum of q l
};

// Clips [t0, t1] to the slab lo <= o + t d < hi of one axis; false if empty.
inline bool ClipSlab(double o, double d, double lo, double hi, double& t0, double& t1) {
    if (d == 0.0) return lo <= o && o < hi;
    double ta = (lo - o) / d, tb = (hi - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    return t0 < t1;
}

void RunBounds(const RTCBoundsFunctionArguments* args) {
    const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
    const Run& r = g.runs[args->primID];
    RTCBounds* b = args->bounds_o;
    b->lower_x = float(r.i0);
    b->lower_y = float(r.j);
    b->lower_z = float(r.k);
    b->upper_x = float(r.i1);
    b->upper_y = float(r.j + 1);
    b->upper_z = float(r.k + 1);
}

void RunIntersect(const RTCIntersectFunctionNArguments* args) {
    // rtcIntersect1 only: one ray.
    if (args->N != 1 || !args->valid[0]) return;
    const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
    RayContext& ctx = *reinterpret_cast<RayContext*>(args->context);
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, 1);
    const double o[3] = {RTCRayN_org_x(ray, 1, 0), RTCRayN_org_y(ray, 1, 0), RTCRayN_org_z(ray, 1, 0)};
    const double d[3] = {RTCRayN_dir_x(ray, 1, 0), RTCRayN_dir_y(ray, 1, 0), RTCRayN_dir_z(ray, 1, 0)};
    const Run& r = g.runs[args->primID];
    double t0 = ctx.start, t1 = kInf;
    if (!ClipSlab(o[1], d[1], r.j, r.j + 1.0, t0, t1) || !ClipSlab(o[2], d[2], r.k, r.k + 1.0, t0, t1) ||
        !ClipSlab(o[0], d[0], r.i0, double(r.i1), t0, t1))
        return;
    const float* q = g.q.data() + (size_t(g.extent.nx) * (r.j + size_t(g.extent.ny) * r.k));
    if (d[0] == 0.0) {
        ctx.sum += double(q[uint32_t(std::floor(o[0]))]) * (t1 - t0);
        return;
    }
    // The voxels of the run between x(t0) and x(t1); neighbours at the ends
    // contribute max(0, ...) = 0 if rounding put them in the range.
    const double xa = o[0] + t0 * d[0], xb = o[0] + t1 * d[0];
    const double lo = std::floor(std::min(xa, xb)), hi = std::floor(std::max(xa, xb));
    const uint32_t first = uint32_t(std::clamp(lo, double(r.i0), double(r.i1 - 1)));
    const uint32_t last = uint32_t(std::clamp(hi, double(r.i0), double(r.i1 - 1)));
    double sum = 0;
    for (uint32_t i = first; i <= last; ++i) {
        double ta = (double(i) - o[0]) / d[0], tb = (double(i + 1) - o[0]) / d[0];
        if (ta > tb) std::swap(ta, tb);
        const double length = std::min(tb, t1) - std::max(ta, t0);
        if (length > 0) sum += double(q[i]) * length;
    }
    ctx.sum += sum;
}

// Never called (the tracer only intersects), but user geometry needs one.
void RunOccluded(const RTCOccludedFunctionNArguments*) {}

}  // namespace

const char* RayStartName(RayStart start) { return start == RayStart::VoxelExit ? "voxel-exit" : "voxel-centre"; }

double VoxelExitDistance(const Vec3& dir) {
    const double m = std::max({std::fabs(double(dir[0])), std::fabs(double(dir[1])), std::fabs(double(dir[2]))});
    return 0.5 / m;
}

struct OpticalDepthTracer::Impl {
    Geometry geometry;
    EmbreeRunScene embree;

    explicit Impl(int threads) : embree(threads) {}
};

OpticalDepthTracer::OpticalDepthTracer(const Extent3& extent) : mExtent(extent) {}
OpticalDepthTracer::~OpticalDepthTracer() = default;

size_t OpticalDepthTracer::Primitives() const { return mImpl->geometry.runs.size(); }

Result<std::unique_ptr<OpticalDepthTracer>> OpticalDepthTracer::Create(const Extent3& extent, std::span<const float> q,
                                                                       int threads) {
    if (q.size() != extent.Count())
        return MakeError("reference: q has " + std::to_string(q.size()) + " values, the grid " +
                         std::to_string(extent.Count()));
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<OpticalDepthTracer> tracer(new OpticalDepthTracer(extent));
    tracer->mImpl = std::make_unique<Impl>(threads);
    Impl& impl = *tracer->mImpl;
    Geometry& g = impl.geometry;
    g.extent = extent;
    g.q.assign(q.begin(), q.end());
    for (uint32_t k = 0; k < extent.nz; ++k)
        for (uint32_t j = 0; j < extent.ny; ++j) {
            const float* row = g.q.data() + size_t(extent.nx) * (j + size_t(extent.ny) * k);
            for (uint32_t i = 0; i < extent.nx;) {
                if (!(row[i] > 0.0f)) {
                    ++i;
                    continue;
                }
                uint32_t end = i + 1;
                while (end < extent.nx && row[end] > 0.0f) ++end;
                g.runs.push_back({i, end, j, k});
                i = end;
            }
        }

    CB_TRY(impl.embree.Build(unsigned(g.runs.size()), &g, {RunBounds, RunIntersect, RunOccluded}));
    tracer->mBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return tracer;
}

double OpticalDepthTracer::Integrate(const std::array<double, 3>& origin, const Vec3& dir, double tStart) const {
    RayContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.start = tStart;
    alignas(16) RTCRayHit rh{};
    rh.ray.org_x = float(origin[0]);
    rh.ray.org_y = float(origin[1]);
    rh.ray.org_z = float(origin[2]);
    rh.ray.dir_x = dir[0];
    rh.ray.dir_y = dir[1];
    rh.ray.dir_z = dir[2];
    // Embree's own range is the whole ray; the callback clips to t > tStart exactly.
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->embree.Scene(), &ctx.base, &rh);
    return ctx.sum;
}

std::vector<float> OpticalDepthTracer::Transmittance(const ReferenceParams& p, TraceStats* stats) const {
    const Extent3 e = mExtent;
    std::vector<float> T(e.Count(), 1.0f);
    const double tStart = p.start == RayStart::VoxelExit ? VoxelExitDistance(p.sun) : 0.0;
    const double depthPerSum = p.sigma * p.voxelSize;
    if (mImpl->geometry.runs.empty()) return T;  // nothing to trace: T = 1
    const auto start = std::chrono::steady_clock::now();
    {
        const uint32_t rows = e.ny * e.nz;
        mImpl->embree.Arena().execute([&] {
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rows, 4), [&](const tbb::blocked_range<uint32_t>& r) {
                for (uint32_t row = r.begin(); row != r.end(); ++row) {
                    const uint32_t j = row % e.ny, k = row / e.ny;
                    float* out = T.data() + size_t(e.nx) * row;
                    for (uint32_t i = 0; i < e.nx; ++i) {
                        const double tau = Integrate({i + 0.5, j + 0.5, k + 0.5}, p.sun, tStart);
                        out[i] = float(std::exp(-depthPerSum * tau));
                    }
                }
            });
        });
    }
    if (stats) {
        stats->rays += e.Count();
        stats->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    return T;
}

std::vector<float> OpticalDepthTracer::GroundShadow(const ReferenceParams& p, TraceStats* stats) const {
    const Extent3 e = mExtent;
    std::vector<float> G(size_t(e.nx) * e.ny, 1.0f);
    if (p.sun[2] <= 0.0f || mImpl->geometry.runs.empty()) return G;
    const double depthPerSum = p.sigma * p.voxelSize;
    const auto start = std::chrono::steady_clock::now();
    mImpl->embree.Arena().execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny, 4), [&](const tbb::blocked_range<uint32_t>& r) {
            for (uint32_t j = r.begin(); j != r.end(); ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    const double tau = Integrate({i + 0.5, j + 0.5, 0.0}, p.sun, 0.0);
                    G[i + size_t(e.nx) * j] = float(std::exp(-depthPerSum * tau));
                }
        });
    });
    if (stats) {
        stats->rays += G.size();
        stats->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    return G;
}

}  // namespace cb::ref
