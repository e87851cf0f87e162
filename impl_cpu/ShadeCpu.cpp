// Stage `shade` on the CPU (SPEC 6): inverse shear-warp, one slice after another
// from the sun side. The previous slice's T and q live in padded 2-D buffers
// whose border reads T = 1, q = 0, so every tap is a plain load and the inner
// loop over u vectorises. At resolution f > 1 the same loop runs on the mean of
// each f^3 block and the result is read back trilinearly.
#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {
namespace {

constexpr uint32_t kMaxStackRow = 512;

// The per-voxel work of one slice, with the options fixed at compile time so
// that the loop over a row vectorises (a switch per voxel stops it).
struct ShadeKernel {
    SliceAttenuation attenuation;
    StorageFormat storage;
};

template <AttenuationKind kAttenuation, StorageFormat kStorage>
void ShadeRowT(const SliceAttenuation& att, const float* __restrict t0, const float* __restrict t1,
               const float* __restrict q0, const float* __restrict q1, float fu, float fv, float* __restrict out,
               uint32_t n) {
    const float depthPerQ = att.opticalDepthPerQ, gain = att.scatterGain, ar = att.thesisAr;
    for (uint32_t a = 0; a < n; ++a) {
        const float t = Bilinear(t0[a], t0[a + 1], t1[a], t1[a + 1], fu, fv);
        const float qs = Bilinear(q0[a], q0[a + 1], q1[a], q1[a + 1], fu, fv);
        // SliceAttenuation::Factor with the kind fixed.
        const float tau = depthPerQ * qs;
        float factor = kAttenuation == AttenuationKind::Beer ? ExpNonPositive(-tau) : 1.0f - (1.0f - ar) * qs;
        factor = std::clamp(factor + gain * tau, 0.0f, 1.0f);
        const float value = RoundToStorage(kStorage, t * factor);
        out[a] = value < kTransmittanceFloor ? 0.0f : value;
    }
}

void ShadeRow(const ShadeKernel& k, const float* t0, const float* t1, const float* q0, const float* q1, float fu,
              float fv, float* out, uint32_t n) {
    const SliceAttenuation& a = k.attenuation;
    const bool beer = a.kind == AttenuationKind::Beer;
    switch (k.storage) {
        case StorageFormat::Fp32:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Fp32>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Fp32>(a, t0, t1, q0, q1, fu, fv, out, n);
        case StorageFormat::Fp16:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Fp16>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Fp16>(a, t0, t1, q0, q1, fu, fv, out, n);
        case StorageFormat::Unorm8:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Unorm8>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Unorm8>(a, t0, t1, q0, q1, fu, fv, out, n);
    }
}

// A volume with explicit sizes, for the shading grid (full or coarse).
struct Grid3 {
    uint32_t n[3];
    const float* q;
    float* T;
};

// Shades `grid` with voxels of edge `cellSize` metres.
void ShadeGrid(const ShadeParams& p, float cellSize, const Grid3& grid, tbb::task_arena& arena) {
    const Vec3& s = p.sun;
    const int w = PrincipalAxis(s);
    const int u = w == 0 ? 1 : 0;
    const int v = w == 2 ? 1 : 2;
    const uint32_t nu = grid.n[u], nv = grid.n[v], nw = grid.n[w];
    const size_t stride[3] = {1, grid.n[0], size_t(grid.n[0]) * grid.n[1]};
    const float sw = std::fabs(s[w]);
    const float du = s[u] / sw, dv = s[v] / sw;  // |du|, |dv| <= 1: w is the largest component

    SliceAttenuation attenuation;
    attenuation.kind = p.attenuation;
    attenuation.opticalDepthPerQ = p.sigma * cellSize / sw;
    attenuation.thesisAr = p.thesisAr;
    if (p.scattering) attenuation.scatterGain = p.albedo * PhaseValue(p.phase, 1.0f) * p.solidAngle / (4.0f * std::numbers::pi_v<float>);

    const ShadeKernel kernel{attenuation, p.storage};

    // Taps of output (u, v) in the previous slice: base (u + u0, v + v0) and +1.
    const bool nearest = p.filter == SampleFilter::Nearest;
    const int u0 = nearest ? int(std::floor(du + 0.5f)) : int(std::floor(du));
    const int v0 = nearest ? int(std::floor(dv + 0.5f)) : int(std::floor(dv));
    const float fu = nearest ? 0.0f : du - std::floor(du);
    const float fv = nearest ? 0.0f : dv - std::floor(dv);

    // Padded previous slice: index (a + 1) + pitch * (b + 1) holds (a, b), with
    // one ring below and two above (taps reach u - 1 .. u + 2).
    const uint32_t pitch = nu + 3;
    std::vector<float> prevT(size_t(pitch) * (nv + 3), 1.0f), prevQ(size_t(pitch) * (nv + 3), 0.0f);
    auto padded = [&](int64_t a, int64_t b) { return size_t(a + 1) + size_t(pitch) * size_t(b + 1); };

    const bool sunAbove = s[w] > 0;  // sun toward +w: the first slice is the last index
    for (uint32_t m = 0; m < nw; ++m) {
        const uint32_t wIndex = sunAbove ? nw - 1 - m : m;
        const size_t sliceBase = stride[w] * wIndex;
        if (m == 0) {
            for (uint32_t b = 0; b < nv; ++b)
                for (uint32_t a = 0; a < nu; ++a) grid.T[sliceBase + stride[u] * a + stride[v] * b] = 1.0f;
        } else {
            auto rows = [&](const tbb::blocked_range<uint32_t>& range) {
                for (uint32_t b = range.begin(); b != range.end(); ++b) {
                    const float* t0 = prevT.data() + padded(u0, int64_t(b) + v0);
                    const float* q0 = prevQ.data() + padded(u0, int64_t(b) + v0);
                    float* out = grid.T + sliceBase + stride[v] * b;
                    if (stride[u] == 1) ShadeRow(kernel, t0, t0 + pitch, q0, q0 + pitch, fu, fv, out, nu);
                    else {
                        // u is not x: shade into a contiguous row, then scatter.
                        float row[kMaxStackRow];
                        for (uint32_t a0 = 0; a0 < nu; a0 += kMaxStackRow) {
                            const uint32_t count = std::min(kMaxStackRow, nu - a0);
                            ShadeRow(kernel, t0 + a0, t0 + pitch + a0, q0 + a0, q0 + pitch + a0, fu, fv, row, count);
                            for (uint32_t a = 0; a < count; ++a) out[stride[u] * (a0 + a)] = row[a];
                        }
                    }
                }
            };
            const uint32_t grain = std::max<uint32_t>(1, 16384 / std::max<uint32_t>(nu, 1));
            if (nv > grain) arena.execute([&] { tbb::parallel_for(tbb::blocked_range<uint32_t>(0, nv, grain), rows); });
            else rows(tbb::blocked_range<uint32_t>(0, nv));
        }
        // This slice becomes the previous one.
        for (uint32_t b = 0; b < nv; ++b) {
            float* pt = prevT.data() + padded(0, b);
            float* pq = prevQ.data() + padded(0, b);
            const float* t = grid.T + sliceBase + stride[v] * b;
            const float* q = grid.q + sliceBase + stride[v] * b;
            for (uint32_t a = 0; a < nu; ++a) {
                pt[a] = t[stride[u] * a];
                pq[a] = q[stride[u] * a];
            }
        }
    }
}

}  // namespace

Status BackendCpu::Shade(const ShadeParams& params, const Buffer& qBuffer, Buffer& TBuffer) {
    const int f = params.resolution;
    if (f != 1 && f != 2 && f != 4) return MakeError("cpu: shade resolution must be 1, 2 or 4");
    const float* q = static_cast<const BufferCpu&>(qBuffer).F32();
    float* T = static_cast<BufferCpu&>(TBuffer).F32();
    const Extent3 e = qBuffer.Extent();
    if (f == 1) {
        ShadeGrid(params, params.voxelSize, {{e.nx, e.ny, e.nz}, q, T}, mArena);
        return {};
    }

    // Coarse grid: the mean of each f^3 block (partial blocks: of the voxels present).
    const uint32_t c[3] = {CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)};
    const size_t coarseCount = size_t(c[0]) * c[1] * c[2];
    mShadeCoarseQ.assign(coarseCount, 0.0f);
    mShadeCoarseT.assign(coarseCount, 1.0f);
    float* cq = mShadeCoarseQ.data();
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, c[2]), [&](const tbb::blocked_range<uint32_t>& slices) {
            for (uint32_t K = slices.begin(); K != slices.end(); ++K)
                for (uint32_t J = 0; J < c[1]; ++J)
                    for (uint32_t I = 0; I < c[0]; ++I) {
                        float sum = 0;
                        uint32_t count = 0;
                        for (uint32_t k = K * f; k < std::min(e.nz, (K + 1) * f); ++k)
                            for (uint32_t j = J * f; j < std::min(e.ny, (J + 1) * f); ++j)
                                for (uint32_t i = I * f; i < std::min(e.nx, (I + 1) * f); ++i, ++count)
                                    sum += q[VoxelIndex(e, i, j, k)];
                        cq[I + size_t(c[0]) * (J + size_t(c[1]) * K)] = sum / float(count);
                    }
        });
    });
    ShadeGrid(params, params.voxelSize * float(f), {{c[0], c[1], c[2]}, cq, mShadeCoarseT.data()}, mArena);

    // Full resolution, trilinear from the coarse grid: full voxel i sits at coarse
    // coordinate (i + 0.5)/f - 0.5, clamped to the coarse grid's centres.
    const float* ct = mShadeCoarseT.data();
    auto axis = [&](uint32_t i, uint32_t n, uint32_t& i0, uint32_t& i1, float& t) {
        const float x = std::clamp((float(i) + 0.5f) / float(f) - 0.5f, 0.0f, float(n - 1));
        i0 = uint32_t(x);
        i1 = std::min(i0 + 1, n - 1);
        t = x - float(i0);
    };
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.nz), [&](const tbb::blocked_range<uint32_t>& slices) {
            for (uint32_t k = slices.begin(); k != slices.end(); ++k) {
                uint32_t k0, k1;
                float tz;
                axis(k, c[2], k0, k1, tz);
                for (uint32_t j = 0; j < e.ny; ++j) {
                    uint32_t j0, j1;
                    float ty;
                    axis(j, c[1], j0, j1, ty);
                    auto at = [&](uint32_t I, uint32_t J, uint32_t K) { return ct[I + size_t(c[0]) * (J + size_t(c[1]) * K)]; };
                    for (uint32_t i = 0; i < e.nx; ++i) {
                        uint32_t i0, i1;
                        float tx;
                        axis(i, c[0], i0, i1, tx);
                        const float lo = Bilinear(at(i0, j0, k0), at(i1, j0, k0), at(i0, j1, k0), at(i1, j1, k0), tx, ty);
                        const float hi = Bilinear(at(i0, j0, k1), at(i1, j0, k1), at(i0, j1, k1), at(i1, j1, k1), tx, ty);
                        T[VoxelIndex(e, i, j, k)] = lo * (1.0f - tz) + hi * tz;
                    }
                }
            }
        });
    });
    return {};
}

Status BackendCpu::Shadow(const ShadowParams& params, const Buffer& columnSumBuffer, Buffer& GBuffer) {
    const float* D = static_cast<const BufferCpu&>(columnSumBuffer).F32();
    float* G = static_cast<BufferCpu&>(GBuffer).F32();
    const Extent3 e = columnSumBuffer.Extent();
    const Vec3& s = params.sun;
    if (s[2] <= 0.0f) {  // no sun above the horizon: no shadow (docs/pipeline.md)
        std::fill(G, G + size_t(e.nx) * e.ny, 1.0f);
        return {};
    }
    // From ground cell (i, j) along s to mid-height (nz/2 voxels up), D is read
    // at (i + ox, j + oy) in voxel-centre coordinates.
    const float climb = 0.5f * float(params.nz) / s[2];
    const float ox = s[0] * climb, oy = s[1] * climb;
    const float opticalDepthPerD = params.sigma * params.voxelSize / s[2];
    auto tap = [&](int64_t i, int64_t j) -> float {
        return (i < 0 || j < 0 || i >= e.nx || j >= e.ny) ? 0.0f : D[size_t(i) + size_t(e.nx) * size_t(j)];
    };
    // Offsets beyond the grid put every tap outside; clamp them so the integer
    // conversion below stays defined.
    const float limit = float(e.nx + e.ny) + 2.0f;
    const float cx = std::clamp(ox, -limit, limit), cy = std::clamp(oy, -limit, limit);
    const float floorX = std::floor(cx), floorY = std::floor(cy);
    const int64_t bx = int64_t(floorX), by = int64_t(floorY);
    const float fx = cx - floorX, fy = cy - floorY;
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny, 8), [&](const tbb::blocked_range<uint32_t>& rows) {
            for (uint32_t j = rows.begin(); j != rows.end(); ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    const int64_t x = int64_t(i) + bx, y = int64_t(j) + by;
                    const float d = Bilinear(tap(x, y), tap(x + 1, y), tap(x, y + 1), tap(x + 1, y + 1), fx, fy);
                    G[i + size_t(e.nx) * j] = params.form == AttenuationKind::Beer
                                                  ? ExpNonPositive(-opticalDepthPerD * d)
                                                  : 1.0f - std::clamp(params.kappa * d, 0.0f, 1.0f);
                }
        });
    });
    return {};
}

}  // namespace cb::cpu
