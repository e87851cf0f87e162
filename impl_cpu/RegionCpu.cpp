// Stage `region` on the CPU (SPEC 2): each ellipsoid is evaluated only over the
// voxels of each row that its surface can reach, and max-blended into R.
#include <algorithm>
#include <cmath>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {
namespace {

// Where an ellipsoid can be nonzero, in double precision (scheduling only: the
// value written is always Rules.h's float EllipsoidWeight).
struct EllipsoidBounds {
    double zLo, zHi, yLo, yHi;  // voxel-centre coordinates that may lie inside
    // rho^2(u) = A u^2 + B(Y) u + C(Y, Z) with u = px - cx, Y = py - cy, Z = pz - cz
    double a2inv, b2inv, c2inv, cosYaw, sinYaw, quadA;
};

EllipsoidBounds ComputeBounds(const RasterEllipsoid& e) {
    EllipsoidBounds b{};
    double a = e.semiAxes[0], bb = e.semiAxes[1], c = e.semiAxes[2];
    b.cosYaw = e.cosYaw;
    b.sinYaw = e.sinYaw;
    b.a2inv = 1.0 / (a * a);
    b.b2inv = 1.0 / (bb * bb);
    b.c2inv = 1.0 / (c * c);
    b.quadA = b.cosYaw * b.cosYaw * b.a2inv + b.sinYaw * b.sinYaw * b.b2inv;
    double ey = std::sqrt(a * a * b.sinYaw * b.sinYaw + bb * bb * b.cosYaw * b.cosYaw);
    // One voxel of slack on every side covers float rounding at the surface.
    b.zLo = e.center[2] - c - 1;
    b.zHi = e.center[2] + c + 1;
    b.yLo = e.center[1] - ey - 1;
    b.yHi = e.center[1] + ey + 1;
    return b;
}

}  // namespace

Status BackendCpu::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& regionBuffer) {
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
        std::vector<float> wMax(nx);
        float* w = wMax.data();
        for (uint32_t k = range.rows().begin(); k != range.rows().end(); ++k) {
            const double pz = k + 0.5;
            for (uint32_t j = range.cols().begin(); j != range.cols().end(); ++j) {
                const double py = j + 0.5;
                uint8_t* row = region + size_t(e.nx) * (j + size_t(e.ny) * k);
                std::fill(w, w + nx, 0.0f);
                for (size_t n = 0; n < ellipsoids.size(); ++n) {
                    const EllipsoidBounds& b = bounds[n];
                    if (pz < b.zLo || pz > b.zHi || py < b.yLo || py > b.yHi) continue;
                    const RasterEllipsoid& el = ellipsoids[n];
                    const double Y = py - el.center[1], Z = pz - el.center[2];
                    const double quadB = 2.0 * Y * b.cosYaw * b.sinYaw * (b.a2inv - b.b2inv);
                    const double quadC = Y * Y * (b.sinYaw * b.sinYaw * b.a2inv + b.cosYaw * b.cosYaw * b.b2inv) +
                                         Z * Z * b.c2inv - 1.0;
                    const double disc = quadB * quadB - 4.0 * b.quadA * quadC;
                    // disc < 0: rho^2 > 1 on the whole row in exact arithmetic. A voxel
                    // needs rho <= 1 - 1/510 to quantise to R >= 1, far beyond float error.
                    if (disc < 0) continue;
                    const double root = std::sqrt(disc);
                    const double u0 = (-quadB - root) / (2.0 * b.quadA);
                    const double u1 = (-quadB + root) / (2.0 * b.quadA);
                    const double iLo = std::ceil(el.center[0] + u0 - 0.5) - 1;
                    const double iHi = std::floor(el.center[0] + u1 - 0.5) + 1;
                    const int64_t i0 = std::max<int64_t>(0, int64_t(iLo));
                    const int64_t i1 = std::min<int64_t>(int64_t(nx) - 1, int64_t(iHi));
                    const RasterEllipsoid local = el;
                    const float fy = float(py), fz = float(pz);
                    for (int32_t i = int32_t(i0); i <= int32_t(i1); ++i)
                        w[i] = std::max(w[i], EllipsoidWeight(local, float(i) + 0.5f, fy, fz));
                }
                for (uint32_t i = 0; i < nx; ++i) row[i] = uint8_t(QuantizeRegion(w[i]));
            }
        }
    };
    mArena.execute([&] { tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, e.nz, 1, 0, e.ny, 16), rows); });
    return {};
}

}  // namespace cb::cpu
