// TrilinearDepthTracer with Embree 3 user geometry.
//
// Dual cells: dual cell (a,b,c), a in [-1, nx-1] (likewise b, c), spans
// [a+1/2, a+3/2] x [b+1/2, b+3/2] x [c+1/2, c+3/2] between the voxel centres
// (a..a+1, b..b+1, c..c+1), clipped to the box [0,nx]x[0,ny]x[0,nz]; its corner
// values come from a copy of q padded with one voxel of zeros on every side,
// so taps outside the grid read 0 without a test.
//
// Why no piece is missed or counted twice (as in Reference.cpp):
// - One box per maximal run along x of dual cells with a nonzero corner in a
//   dual row (b, c). Runs are disjoint, each a single primitive in a single
//   BVH leaf (medium-quality build: no spatial splits, no repeated calls).
// - The callback never reports a hit, so traversal visits every box the ray
//   touches. Embree traces a float copy of the ray; the boxes are padded by a
//   margin far above that copy's rounding and the scene is
//   RTC_SCENE_FLAG_ROBUST, so every box the exact ray crosses is visited. The
//   callback works on the exact double ray kept in the ray's context.
// - All clipping is in double; every plane p of an axis gives t = (p - o)/d,
//   computed as (p - o) * (1/d), by one expression wherever it appears, so neighbouring pieces meet at the
//   same t. An axis with d = 0 uses half-open intervals [lo, hi), closed at the
//   box's upper face, so a ray in a shared face counts once and a ray in the
//   box's face counts (the box is closed).
#include "reference/Trilinear.h"

#include "reference/EmbreeRuns.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace cb::ref {
namespace {

constexpr double kTriInf = std::numeric_limits<double>::infinity();

// Dual cells [a0, a1) x {b} x {c} along x, indices from -1.
struct TriRun {
    int32_t a0, a1, b, c;
};

struct TriGeometry {
    Extent3 extent;
    uint32_t px = 0, py = 0;    // padded sizes nx + 2, ny + 2
    std::vector<float> padded;  // q(i,j,k) at (i+1) + px ((j+1) + py (k+1)); zero border
    std::vector<TriRun> runs;
    float margin = 0;  // box padding for the float ray Embree traces
};

// One ray's state: the exact ray, its range and its accumulator.
struct TriLane {
    double o[3], d[3];
    double inv[3];  // 1 / d (unused where d = 0)
    double t0, t1;  // integrate over [t0, t1], already inside the box
    double sum;
};

// Up to 16 rays (a packet); a ray's `id` is its lane. `base` must come first:
// Embree hands the callback &base.
constexpr int kTriPacket = 16;
struct TriRayContext {
    RTCIntersectContext base;
    TriLane lane[kTriPacket];
};

// Clips [t0, t1] to lo <= o + t d <= hi along one axis (inv = 1 / d). With
// d = 0 the slab is [lo, hi), or [lo, hi] when closedHi. False if empty.
inline bool TriClip(double o, double d, double inv, double lo, double hi, bool closedHi, double& t0, double& t1) {
    if (d == 0.0) return lo <= o && (o < hi || (closedHi && o == hi));
    double ta = (lo - o) * inv, tb = (hi - o) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    return t0 < t1;
}

// The run's box along each axis: dual cells [a0, a1) span [a0+1/2, a1+1/2]
// clipped to [0, n].
inline double TriLo(int32_t a) { return std::max(0.0, a + 0.5); }
inline double TriHi(int32_t aEnd, uint32_t n) { return std::min(double(n), aEnd + 0.5); }

void TriBounds(const RTCBoundsFunctionArguments* args) {
    const TriGeometry& g = *static_cast<const TriGeometry*>(args->geometryUserPtr);
    const TriRun& r = g.runs[args->primID];
    const float m = g.margin;
    RTCBounds* b = args->bounds_o;
    b->lower_x = float(TriLo(r.a0)) - m;
    b->lower_y = float(TriLo(r.b)) - m;
    b->lower_z = float(TriLo(r.c)) - m;
    b->upper_x = float(TriHi(r.a1, g.extent.nx)) + m;
    b->upper_y = float(TriHi(r.b + 1, g.extent.ny)) + m;
    b->upper_z = float(TriHi(r.c + 1, g.extent.nz)) + m;
}

// The integral of the trilinear field of one dual cell over [ta, tb]:
// 2-point Gauss-Legendre, exact for the cubic. c: the 8 corners, index
// dx + 2 dy + 4 dz; (ox, oy, oz): the ray origin in the cell's own coordinates.
inline double TriCellIntegral(const double c[8], double ox, double oy, double oz, const double d[3], double ta,
                              double tb) {
    constexpr double kNode = 0.57735026918962576451;  // 1 / sqrt(3)
    const double half = 0.5 * (tb - ta), mid = 0.5 * (ta + tb);
    double sum = 0;
    for (double t : {mid - half * kNode, mid + half * kNode}) {
        const double fx = ox + t * d[0], fy = oy + t * d[1], fz = oz + t * d[2];
        const double x00 = c[0] + fx * (c[1] - c[0]), x10 = c[2] + fx * (c[3] - c[2]);
        const double x01 = c[4] + fx * (c[5] - c[4]), x11 = c[6] + fx * (c[7] - c[6]);
        const double y0 = x00 + fy * (x10 - x00), y1 = x01 + fy * (x11 - x01);
        sum += y0 + fz * (y1 - y0);
    }
    return half * sum;
}

// Adds run r's part of one ray to the ray's accumulator.
void TriAccumulate(const TriGeometry& g, const TriRun& r, TriLane& lane) {
    const double* o = lane.o;
    const double* d = lane.d;
    const double* inv = lane.inv;
    const Extent3& e = g.extent;
    double t0 = lane.t0, t1 = lane.t1;
    if (!TriClip(o[1], d[1], inv[1], TriLo(r.b), TriHi(r.b + 1, e.ny), r.b + 1 == int32_t(e.ny), t0, t1) ||
        !TriClip(o[2], d[2], inv[2], TriLo(r.c), TriHi(r.c + 1, e.nz), r.c + 1 == int32_t(e.nz), t0, t1) ||
        !TriClip(o[0], d[0], inv[0], TriLo(r.a0), TriHi(r.a1, e.nx), r.a1 == int32_t(e.nx), t0, t1))
        return;
    // The dual cells of the run between x(t0) and x(t1); cells at the ends that
    // rounding put in the range get an empty piece.
    int32_t first, last;
    if (d[0] == 0.0) {
        first = last = std::clamp(int32_t(std::floor(o[0] - 0.5)), r.a0, r.a1 - 1);
    } else {
        const double xa = o[0] + t0 * d[0], xb = o[0] + t1 * d[0];
        first = std::clamp(int32_t(std::floor(std::min(xa, xb) - 0.5)), r.a0, r.a1 - 1);
        last = std::clamp(int32_t(std::floor(std::max(xa, xb) - 0.5)), r.a0, r.a1 - 1);
    }
    const size_t px = g.px, pxy = size_t(g.px) * g.py;
    const float* row = g.padded.data() + px * size_t(r.b + 1) + pxy * size_t(r.c + 1);
    const double oy = o[1] - (r.b + 0.5), oz = o[2] - (r.c + 0.5);
    double sum = 0;
    for (int32_t a = first; a <= last; ++a) {
        double ta = t0, tb = t1;
        if (d[0] != 0.0) {
            double pa = (std::max(0.0, a + 0.5) - o[0]) * inv[0];
            double pb = (std::min(double(e.nx), a + 1.5) - o[0]) * inv[0];
            if (pa > pb) std::swap(pa, pb);
            ta = std::max(ta, pa);
            tb = std::min(tb, pb);
            if (!(ta < tb)) continue;
        }
        const float* p = row + size_t(a + 1);
        const double c[8] = {p[0], p[1], p[px], p[px + 1], p[pxy], p[pxy + 1], p[pxy + px], p[pxy + px + 1]};
        sum += TriCellIntegral(c, o[0] - (a + 0.5), oy, oz, d, ta, tb);
    }
    lane.sum += sum;
}

// Single rays and packets alike: each valid ray's id names its lane.
void TriIntersect(const RTCIntersectFunctionNArguments* args) {
    const TriGeometry& g = *static_cast<const TriGeometry*>(args->geometryUserPtr);
    TriRayContext& ctx = *reinterpret_cast<TriRayContext*>(args->context);
    const TriRun& r = g.runs[args->primID];
    RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i]) TriAccumulate(g, r, ctx.lane[RTCRayN_id(rays, args->N, i)]);
}

// Sets up one ray: the exact ray clipped to the box in `lane`, and the float
// copy Embree traces from the box entry over the clipped length plus the
// margin. False if the ray misses the box.
bool TriSetup(const TriGeometry& g, const Point3d& origin, const Point3d& dir, double tMin, double tMax, TriLane& lane,
              float org[3], float dirF[3], float& tfar) {
    if (!(tMin < tMax)) return false;
    double t0 = tMin, t1 = tMax;
    const uint32_t n[3] = {g.extent.nx, g.extent.ny, g.extent.nz};
    for (int a = 0; a < 3; ++a) {
        lane.o[a] = origin[a];
        lane.d[a] = dir[a];
        lane.inv[a] = dir[a] != 0.0 ? 1.0 / dir[a] : 0.0;
        if (!TriClip(origin[a], dir[a], lane.inv[a], 0.0, double(n[a]), true, t0, t1)) return false;
    }
    lane.t0 = t0;
    lane.t1 = t1;
    lane.sum = 0;
    for (int a = 0; a < 3; ++a) {
        org[a] = float(origin[a] + t0 * dir[a]);
        dirF[a] = float(dir[a]);
    }
    tfar = float((t1 - t0) * (1.0 + 1e-6) + 4.0 * g.margin);
    return true;
}

void TriOccluded(const RTCOccludedFunctionNArguments*) {}

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

struct TrilinearDepthTracer::Impl {
    TriGeometry geometry;
    EmbreeRunScene embree;
    bool packets = true;

    explicit Impl(int threads) : embree(threads) {}

    // Rays [begin, end) (at most 16) as one packet; ray(i, lane, org, dir,
    // tfar) sets ray i up (TriSetup). Writes each ray's depth to out[i].
    template <class Ray>
    void Packet(size_t begin, size_t end, Ray ray, double* out) const {
        TriRayContext ctx;
        rtcInitIntersectContext(&ctx.base);
        alignas(64) RTCRayHit16 rh;
        alignas(64) int valid[kTriPacket];
        bool any = false;
        for (int l = 0; l < kTriPacket; ++l) {
            const size_t i = begin + size_t(l);
            float org[3] = {0, 0, 0}, dir[3] = {0, 0, 1}, tfar = 0;
            const bool live = i < end && ray(i, ctx.lane[l], org, dir, tfar);
            valid[l] = live ? -1 : 0;
            if (!live) ctx.lane[l].sum = 0;
            any = any || live;
            rh.ray.org_x[l] = org[0];
            rh.ray.org_y[l] = org[1];
            rh.ray.org_z[l] = org[2];
            rh.ray.dir_x[l] = dir[0];
            rh.ray.dir_y[l] = dir[1];
            rh.ray.dir_z[l] = dir[2];
            rh.ray.tnear[l] = 0.0f;
            rh.ray.tfar[l] = tfar;
            rh.ray.time[l] = 0.0f;
            rh.ray.mask[l] = ~0u;
            rh.ray.id[l] = unsigned(l);
            rh.ray.flags[l] = 0;
            rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
        }
        if (any) rtcIntersect16(valid, embree.Scene(), &ctx.base, &rh);
        // A lane with no ray (a point on the light: depth 0) reads 0, whatever a callback made of its unset lane.
        for (size_t i = begin; i < end; ++i) out[i] = valid[i - begin] ? ctx.lane[i - begin].sum : 0.0;
    }

    // A batch: depth(i) for every point, in parallel; with packets on,
    // packet(begin, end, out) does 16 at a time.
    template <class Depth, class PacketFn>
    std::vector<double> Batch(size_t n, Depth depth, PacketFn packet, TraceStats* stats) {
        std::vector<double> out(n, 0.0);
        const auto start = std::chrono::steady_clock::now();
        if (!geometry.runs.empty())
            embree.Arena().execute([&] {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
                    if (packets) {
                        for (size_t i = r.begin(); i < r.end(); i += kTriPacket)
                            packet(i, std::min(r.end(), i + kTriPacket), out.data());
                    } else {
                        for (size_t i = r.begin(); i != r.end(); ++i) out[i] = depth(i);
                    }
                });
            });
        if (stats) {
            stats->rays += n;
            stats->seconds += Seconds(start);
        }
        return out;
    }
};

TrilinearDepthTracer::TrilinearDepthTracer(const Extent3& extent) : mExtent(extent) {}
TrilinearDepthTracer::~TrilinearDepthTracer() = default;

size_t TrilinearDepthTracer::Primitives() const { return mImpl->geometry.runs.size(); }

void TrilinearDepthTracer::UsePackets(bool on) { mImpl->packets = on; }

Result<std::unique_ptr<TrilinearDepthTracer>> TrilinearDepthTracer::Create(const Extent3& extent,
                                                                           std::span<const float> q, int threads) {
    if (q.size() != extent.Count())
        return MakeError("reference: q has " + std::to_string(q.size()) + " values, the grid " +
                         std::to_string(extent.Count()));
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<TrilinearDepthTracer> tracer(new TrilinearDepthTracer(extent));
    tracer->mImpl = std::make_unique<Impl>(threads);
    Impl& impl = *tracer->mImpl;
    TriGeometry& g = impl.geometry;
    g.extent = extent;
    g.px = extent.nx + 2;
    g.py = extent.ny + 2;
    const size_t px = g.px, pxy = size_t(g.px) * g.py;
    g.padded.assign(pxy * (extent.nz + 2), 0.0f);
    for (uint32_t k = 0; k < extent.nz; ++k)
        for (uint32_t j = 0; j < extent.ny; ++j)
            std::copy_n(q.data() + size_t(extent.nx) * (j + size_t(extent.ny) * k), extent.nx,
                        g.padded.data() + 1 + px * (j + 1) + pxy * (k + 1));
    // The margin: far above the rounding of a float ray (origin and direction
    // of a few ulps over coordinates and lengths up to ~2n), far below a cell.
    const uint32_t nMax = std::max({extent.nx, extent.ny, extent.nz});
    g.margin = float(1e-4 * (1.0 + nMax));

    // Runs: a dual cell a is occupied if padded column a+1 or a+2 (the four
    // voxel rows b..b+1, c..c+1) holds a nonzero value.
    std::vector<uint8_t> column(px);
    for (int32_t c = -1; c < int32_t(extent.nz); ++c)
        for (int32_t b = -1; b < int32_t(extent.ny); ++b) {
            const float* rows[4];
            for (int n = 0; n < 4; ++n)
                rows[n] = g.padded.data() + px * size_t(b + 1 + (n & 1)) + pxy * size_t(c + 1 + (n >> 1));
            for (size_t p = 0; p < px; ++p)
                column[p] = rows[0][p] != 0.0f || rows[1][p] != 0.0f || rows[2][p] != 0.0f || rows[3][p] != 0.0f;
            for (int32_t a = -1; a < int32_t(extent.nx);) {
                if (!(column[a + 1] || column[a + 2])) {
                    ++a;
                    continue;
                }
                int32_t end = a + 1;
                while (end < int32_t(extent.nx) && (column[end + 1] || column[end + 2])) ++end;
                g.runs.push_back({a, end, b, c});
                a = end;
            }
        }

    CB_TRY(impl.embree.Build(unsigned(g.runs.size()), &g, {TriBounds, TriIntersect, TriOccluded}));
    tracer->mBuildSeconds = Seconds(start);
    return tracer;
}

double TrilinearDepthTracer::Integrate(const Point3d& origin, const Point3d& dir, double tMin, double tMax) const {
    const TriGeometry& g = mImpl->geometry;
    if (g.runs.empty()) return 0.0;
    TriRayContext ctx;
    rtcInitIntersectContext(&ctx.base);
    alignas(16) RTCRayHit rh{};
    float org[3], dirF[3], tfar;
    if (!TriSetup(g, origin, dir, tMin, tMax, ctx.lane[0], org, dirF, tfar)) return 0.0;
    rh.ray.org_x = org[0];
    rh.ray.org_y = org[1];
    rh.ray.org_z = org[2];
    rh.ray.dir_x = dirF[0];
    rh.ray.dir_y = dirF[1];
    rh.ray.dir_z = dirF[2];
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tfar;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->embree.Scene(), &ctx.base, &rh);
    return ctx.lane[0].sum;
}

double TrilinearDepthTracer::IntegrateSegment(const Point3d& a, const Point3d& b) const {
    const Point3d v = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(length > 0)) return 0.0;
    return Integrate(a, {v[0] / length, v[1] / length, v[2] / length}, 0.0, length);
}

std::vector<double> TrilinearDepthTracer::DepthsToward(std::span<const Point3d> points, const Point3d& dir,
                                                       TraceStats* stats) const {
    const double length = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(length > 0)) return std::vector<double>(points.size(), 0.0);
    const Point3d u = {dir[0] / length, dir[1] / length, dir[2] / length};
    const TriGeometry& g = mImpl->geometry;
    return mImpl->Batch(
        points.size(), [&](size_t i) { return Integrate(points[i], u, 0.0, kTriInf); },
        [&](size_t begin, size_t end, double* out) {
            mImpl->Packet(
                begin, end,
                [&](size_t i, TriLane& lane, float* org, float* dirF, float& tfar) {
                    return TriSetup(g, points[i], u, 0.0, kTriInf, lane, org, dirF, tfar);
                },
                out);
        },
        stats);
}

std::vector<double> TrilinearDepthTracer::DepthsToPoint(std::span<const Point3d> points, const Point3d& target,
                                                        TraceStats* stats) const {
    const TriGeometry& g = mImpl->geometry;
    return mImpl->Batch(
        points.size(), [&](size_t i) { return IntegrateSegment(points[i], target); },
        [&](size_t begin, size_t end, double* out) {
            mImpl->Packet(
                begin, end,
                [&](size_t i, TriLane& lane, float* org, float* dirF, float& tfar) {
                    const Point3d& a = points[i];
                    const Point3d v = {target[0] - a[0], target[1] - a[1], target[2] - a[2]};
                    const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                    if (!(length > 0)) return false;
                    const Point3d u = {v[0] / length, v[1] / length, v[2] / length};
                    return TriSetup(g, a, u, 0.0, length, lane, org, dirF, tfar);
                },
                out);
        },
        stats);
}

namespace {
std::vector<float> TriTransmittance(const std::vector<double>& depths, double sigmaH) {
    std::vector<float> T(depths.size());
    for (size_t i = 0; i < depths.size(); ++i) T[i] = float(std::exp(-sigmaH * depths[i]));
    return T;
}
}  // namespace

std::vector<float> TrilinearDepthTracer::TransmittanceToward(std::span<const Point3d> points, const Point3d& dir,
                                                             double sigmaH, TraceStats* stats) const {
    return TriTransmittance(DepthsToward(points, dir, stats), sigmaH);
}

std::vector<float> TrilinearDepthTracer::TransmittanceToPoint(std::span<const Point3d> points, const Point3d& target,
                                                              double sigmaH, TraceStats* stats) const {
    return TriTransmittance(DepthsToPoint(points, target, stats), sigmaH);
}

}  // namespace cb::ref
