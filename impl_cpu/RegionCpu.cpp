// Stage `region` on the CPU (SPEC 2): each ellipsoid is evaluated only over the
// voxels of each row that its surface can reach, and max-blended into R.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/RegionCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "impl_cpu/BackendCpu.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

// Where an ellipsoid can be nonzero, in double precision (scheduling only: the
// value written is always Rules.h's float EllipsoidWeight). Along a row,
// rho^2(u) = A u^2 + kB*Y u + kC*Y^2 + Z^2/c^2 with u = px - cx, Y = py - cy,
// Z = pz - cz; the row's span is where that is below 1.
struct EllipsoidBounds {
    double zLo, zHi, yLo, yHi;  // voxel-centre coordinates that may lie inside
    double kB, kC, c2inv, inv2A, disc4A;  // inv2A = 1/(2A), disc4A = 4A
};

EllipsoidBounds ComputeBounds(const RasterEllipsoid& e) {
    EllipsoidBounds b{};
    const double a = e.semiAxes[0], bb = e.semiAxes[1], c = e.semiAxes[2];
    const double cs = e.cosYaw, sn = e.sinYaw;
    const double a2inv = 1.0 / (a * a), b2inv = 1.0 / (bb * bb);
    const double quadA = cs * cs * a2inv + sn * sn * b2inv;
    b.kB = 2.0 * cs * sn * (a2inv - b2inv);
    b.kC = sn * sn * a2inv + cs * cs * b2inv;
    b.c2inv = 1.0 / (c * c);
    b.inv2A = 1.0 / (2.0 * quadA);
    b.disc4A = 4.0 * quadA;
    const double ey = std::sqrt(a * a * sn * sn + bb * bb * cs * cs);
    // One voxel of slack on every side covers float rounding at the surface.
    b.zLo = e.center[2] - c - 1;
    b.zHi = e.center[2] + c + 1;
    b.yLo = e.center[1] - ey - 1;
    b.yHi = e.center[1] + ey + 1;
    return b;
}

}  // namespace

Status Region(tbb::task_arena& arena, std::span<const RasterEllipsoid> ellipsoids, Buffer& regionBuffer,
              SliceRange slices) {
    uint8_t* region = static_cast<BufferCpu&>(regionBuffer).U8();
    const Extent3 e = regionBuffer.Extent();
    std::vector<EllipsoidBounds> bounds(ellipsoids.size());
    for (size_t n = 0; n < ellipsoids.size(); ++n) bounds[n] = ComputeBounds(ellipsoids[n]);

    auto rows = [&](const tbb::blocked_range2d<uint32_t>& range) {
        // The largest w of the row so far, blended in float (16 lanes a vector)
        // and quantised once per row: quantising is monotone, so this equals
        // max-blending the quantised values.
        // Locals, not captures: stores through uint8_t* may alias anything the
        // lambda reaches by reference, which would stop the loops vectorising.
        const uint32_t nx = e.nx;
        const uint32_t count = uint32_t(ellipsoids.size());
        struct SliceEntry {
            uint32_t index;
            double zTerm;  // Z^2/c^2 - 1
        };
        std::vector<SliceEntry> slice;
        slice.reserve(count);
        std::vector<float> wMax(nx);
        float* w = wMax.data();
        for (uint32_t k = range.rows().begin(); k != range.rows().end(); ++k) {
            const double pz = k + 0.5;
            // The ellipsoids that reach this slice, and their z term.
            slice.clear();
            for (uint32_t n = 0; n < count; ++n) {
                const EllipsoidBounds& b = bounds[n];
                if (pz < b.zLo || pz > b.zHi) continue;
                const double Z = pz - ellipsoids[n].center[2];
                slice.push_back({n, Z * Z * b.c2inv - 1.0});
            }
            for (uint32_t j = range.cols().begin(); j != range.cols().end(); ++j) {
                const double py = j + 0.5;
                uint8_t* row = region + size_t(nx) * (j + size_t(e.ny) * k);
                std::fill(w, w + nx, 0.0f);
                for (const SliceEntry& entry : slice) {
                    const EllipsoidBounds& b = bounds[entry.index];
                    if (py < b.yLo || py > b.yHi) continue;
                    const RasterEllipsoid& el = ellipsoids[entry.index];
                    const double Y = py - el.center[1];
                    const double quadB = b.kB * Y;
                    const double quadC = b.kC * Y * Y + entry.zTerm;
                    const double disc = quadB * quadB - b.disc4A * quadC;
                    // disc < 0: rho^2 > 1 on the whole row in exact arithmetic. A voxel
                    // needs rho <= 1 - 1/510 to quantise to R >= 1, far beyond float error.
                    if (disc < 0) continue;
                    const double root = std::sqrt(disc);
                    const double u0 = (-quadB - root) * b.inv2A;
                    const double u1 = (-quadB + root) * b.inv2A;
                    // The span is clamped to [0, nx - 1] in double, and only then narrowed:
                    // a huge ellipsoid's bounds exceed every integer type.
                    const double iLo = std::max(0.0, std::ceil(el.center[0] + u0 - 0.5) - 1);
                    const double iHi = std::min(double(nx) - 1, std::floor(el.center[0] + u1 - 0.5) + 1);
                    if (!(iLo <= iHi)) continue;  // off the row, or NaN
                    const uint32_t i0 = uint32_t(iLo), i1 = uint32_t(iHi);
                    const RasterEllipsoid local = el;
                    const float fy = float(py), fz = float(pz);
                    for (uint32_t i = i0; i <= i1; ++i)
                        w[i] = std::max(w[i], EllipsoidWeight(local, float(i) + 0.5f, fy, fz));
                }
                for (uint32_t i = 0; i < nx; ++i) row[i] = uint8_t(QuantizeRegion(w[i]));
            }
        }
    };
    // The share: slices k in [k0, k1); every voxel's value depends on its own
    // position alone, so a share is the whole call's loop over fewer slices.
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) return {};
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range2d<uint32_t>(k0, k1, 1, 0, e.ny, 16), rows); });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(Region);

Status BackendCpu::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& regionBuffer, SliceRange slices) {
    return HWY_DYNAMIC_DISPATCH(Region)(mArena, ellipsoids, regionBuffer, slices);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
