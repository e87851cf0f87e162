// Stage `shade` on the CPU (SPEC 6): inverse shear-warp, one slice after another
// from the sun side. The previous slice's T and q live in padded 2-D buffers
// whose border reads T = 1, q = 0, so every tap is a plain load and the inner
// loop over u vectorises. At resolution f > 1 the same loop runs on the mean of
// each f^3 block and the result is read back trilinearly.
#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/ShadePlan.h"
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
        const float factor = SliceFactor(kAttenuation == AttenuationKind::Beer, depthPerQ, ar, gain, qs);
        out[a] = StoreTransmittance(kStorage, t, factor);
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

// Shades the sweep's slices m in [m0, m1) of the plan's grid (full or coarse):
// Q in, T out, both of plan.cells. With m0 > 0, slice m0 - 1 of T must hold
// what this function wrote there (an earlier share): it is read back as the
// previous slice, exactly the values the whole sweep would carry over.
void ShadeGrid(const ShadePlan& plan, StorageFormat storage, const float* Q, float* T, tbb::task_arena& arena,
               uint32_t m0, uint32_t m1) {
    const ShearWarp& g = plan.geometry;
    const int w = g.w, u = g.u, v = g.v;
    const uint32_t nu = plan.nu, nv = plan.nv, nw = plan.nw;
    const size_t stride[3] = {1, plan.cells[0], size_t(plan.cells[0]) * plan.cells[1]};
    const ShadeKernel kernel{plan.attenuation, storage};
    const int u0 = g.u0, v0 = g.v0;
    const float fu = g.fu, fv = g.fv;

    // Padded previous slice: index (a + 1) + pitch * (b + 1) holds (a, b), with
    // one ring below and two above (taps reach u - 1 .. u + 2).
    const uint32_t pitch = nu + 3;
    std::vector<float> prevT(size_t(pitch) * (nv + 3), 1.0f), prevQ(size_t(pitch) * (nv + 3), 0.0f);
    auto padded = [&](int64_t a, int64_t b) { return size_t(a + 1) + size_t(pitch) * size_t(b + 1); };

    // Slice wIndex of T and Q becomes the previous one.
    auto keep = [&](uint32_t wIndex) {
        const size_t sliceBase = stride[w] * wIndex;
        for (uint32_t b = 0; b < nv; ++b) {
            float* pt = prevT.data() + padded(0, b);
            float* pq = prevQ.data() + padded(0, b);
            const float* t = T + sliceBase + stride[v] * b;
            const float* q = Q + sliceBase + stride[v] * b;
            for (uint32_t a = 0; a < nu; ++a) {
                pt[a] = t[stride[u] * a];
                pq[a] = q[stride[u] * a];
            }
        }
    };
    if (m0 > 0) keep(plan.SliceW(m0 - 1));
    for (uint32_t m = m0; m < std::min(m1, nw); ++m) {
        const uint32_t wIndex = plan.SliceW(m);
        const size_t sliceBase = stride[w] * wIndex;
        if (m == 0) {
            for (uint32_t b = 0; b < nv; ++b)
                for (uint32_t a = 0; a < nu; ++a) T[sliceBase + stride[u] * a + stride[v] * b] = 1.0f;
        } else {
            auto rows = [&](const tbb::blocked_range<uint32_t>& range) {
                for (uint32_t b = range.begin(); b != range.end(); ++b) {
                    const float* t0 = prevT.data() + padded(u0, int64_t(b) + v0);
                    const float* q0 = prevQ.data() + padded(u0, int64_t(b) + v0);
                    float* out = T + sliceBase + stride[v] * b;
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
        if (m + 1 < m1) keep(wIndex);
    }
}

// cell[I] += sum of row[I*f .. I*f + f) (the last block may be short), with
// the block size fixed at compile time for the full blocks so the loop vectorises.
template <int F>
void AddRowBlocksT(const float* __restrict row, uint32_t n, float* __restrict cell) {
    const uint32_t full = n / F;
    for (uint32_t I = 0; I < full; ++I) {
        float sum = 0;
        for (int d = 0; d < F; ++d) sum += row[I * F + d];
        cell[I] += sum;
    }
    float sum = 0;
    for (uint32_t i = full * F; i < n; ++i) sum += row[i];
    if (full * F < n) cell[full] += sum;
}

// out[i] = b[x0[i]] (1 - fx[i]) + b[x1[i]] fx[i] for i < n. Away from the
// edges the taps repeat with period F (fine voxel F*I + p reads cells
// I + o_p and I + o_p + 1 with weight t_p), so the interior runs as F
// unit-stride streams; the edges use the tables. Same arithmetic either way.
template <int F>
void UpsampleRowT(const float* __restrict b, uint32_t cells, const uint32_t* x0, const uint32_t* x1, const float* fx,
                  float* __restrict out, uint32_t n) {
    // Cells I with 1 <= I and I + 1 <= cells - 1 have every phase in the interior.
    const uint32_t firstI = 1, lastI = cells >= 2 ? cells - 2 : 0;
    const uint32_t interiorBegin = F * firstI, interiorEnd = cells >= 3 ? std::min(n, F * (lastI + 1)) : 0;
    for (uint32_t i = 0; i < std::min(n, interiorBegin); ++i) out[i] = Lerp(b[x0[i]], b[x1[i]], fx[i]);
    if (interiorEnd > interiorBegin) {
        for (int p = 0; p < F; ++p) {
            const uint32_t i = interiorBegin + uint32_t(p);
            const int offset = int(x0[i]) - int(firstI);  // o_p: -1 or 0
            const float t = fx[i];
            const float* lo = b + int(firstI) + offset;
            float* o = out + interiorBegin + p;
            const uint32_t count = (interiorEnd - interiorBegin) / F;
            for (uint32_t I = 0; I < count; ++I) o[F * I] = Lerp(lo[I], lo[I + 1], t);
        }
    }
    for (uint32_t i = std::max(interiorEnd, std::min(n, interiorBegin)); i < n; ++i)
        out[i] = Lerp(b[x0[i]], b[x1[i]], fx[i]);
}

void UpsampleRow(const float* b, uint32_t cells, int f, const uint32_t* x0, const uint32_t* x1, const float* fx,
                 float* out, uint32_t n) {
    if (f == 2) UpsampleRowT<2>(b, cells, x0, x1, fx, out, n);
    else UpsampleRowT<4>(b, cells, x0, x1, fx, out, n);
}

void AddRowBlocks(const float* row, uint32_t n, int f, float* cell) {
    if (f == 2) AddRowBlocksT<2>(row, n, cell);
    else AddRowBlocksT<4>(row, n, cell);
}

// The coarse grid of q at resolution f: the mean of each f^3 block (partial
// blocks: of the voxels present). `cq` (plan.cells) must hold zeros.
void DownsampleShadeQ(const ShadePlan& plan, int f, const float* q, const Extent3& e, float* cq,
                      tbb::task_arena& arena) {
    const uint32_t* c = plan.cells;
    const size_t coarseSlice = size_t(c[0]) * c[1];
    auto blockSize = [&](uint32_t cell, uint32_t n) { return std::min<uint32_t>(f, n - cell * f); };
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, c[2]), [&](const tbb::blocked_range<uint32_t>& slices) {
            for (uint32_t K = slices.begin(); K != slices.end(); ++K) {
                float* out = cq + coarseSlice * K;
                // Sum the block's fine rows into coarse rows, x-cells first.
                for (uint32_t k = K * f; k < K * f + blockSize(K, e.nz); ++k)
                    for (uint32_t j = 0; j < e.ny; ++j) {
                        const float* row = q + size_t(e.nx) * (j + size_t(e.ny) * k);
                        float* cell = out + size_t(c[0]) * (j / f);
                        AddRowBlocks(row, e.nx, f, cell);
                    }
                for (uint32_t J = 0; J < c[1]; ++J)
                    for (uint32_t I = 0; I < c[0]; ++I)
                        out[I + size_t(c[0]) * J] /= float(blockSize(I, e.nx) * blockSize(J, e.ny) * blockSize(K, e.nz));
            }
        });
    });
}

}  // namespace

Status BackendCpu::Shade(const ShadeParams& params, const Buffer& qBuffer, Buffer& TBuffer) {
    const int f = params.resolution;
    if (f != 1 && f != 2 && f != 4) return MakeError("cpu: shade resolution must be 1, 2 or 4");
    const float* q = static_cast<const BufferCpu&>(qBuffer).F32();
    float* T = static_cast<BufferCpu&>(TBuffer).F32();
    const Extent3 e = qBuffer.Extent();
    const ShadePlan plan = MakeShadePlan(params, e);
    // The share: the sweep's slices m in [m0, m1), of the shaded (at f > 1 the
    // coarse) grid. At f > 1 the share with m = 0 also forms the coarse q, the
    // coarse grids stay in mShadeCoarseQ/T until the last share, and the share
    // ending at nw writes all of T from them.
    const uint32_t m0 = params.slices.Begin(plan.nw), m1 = params.slices.End(plan.nw);
    if (m0 >= m1) return {};
    if (f == 1) {
        ShadeGrid(plan, params.storage, q, T, mArena, m0, m1);
        return {};
    }

    const uint32_t* c = plan.cells;
    const size_t coarseSlice = size_t(c[0]) * c[1];
    if (m0 > 0 && (mShadeCoarseQ.size() != coarseSlice * c[2] || mShadeCoarseT.size() != coarseSlice * c[2]))
        return MakeError("cpu: shade share [" + std::to_string(m0) + ", " + std::to_string(m1) +
                         ") without the share that starts the sweep");
    if (m0 == 0) {
        mShadeCoarseQ.assign(coarseSlice * c[2], 0.0f);
        mShadeCoarseT.assign(coarseSlice * c[2], 1.0f);
        DownsampleShadeQ(plan, f, q, e, mShadeCoarseQ.data(), mArena);
    }
    ShadeGrid(plan, params.storage, mShadeCoarseQ.data(), mShadeCoarseT.data(), mArena, m0, m1);
    if (m1 < plan.nw) return {};

    // Full resolution, trilinear from the coarse grid: full voxel i sits at coarse
    // coordinate (i + 0.5)/f - 0.5, clamped to the coarse grid's centres. Per fine
    // row, the four coarse rows around it are blended in y and z first (a coarse
    // row in L1), then each voxel blends two of its cells in x.
    // Per-axis taps (structure of arrays, so the x loop vectorises as gathers).
    struct Taps {
        std::vector<uint32_t> i0, i1;
        std::vector<float> t;
    };
    auto taps = [&](uint32_t n, uint32_t cells) {
        Taps out{std::vector<uint32_t>(n), std::vector<uint32_t>(n), std::vector<float>(n)};
        for (uint32_t i = 0; i < n; ++i) {
            const UpsampleTaps tap = UpsampleTap(i, f, cells);
            out.i0[i] = tap.i0;
            out.i1[i] = tap.i1;
            out.t[i] = tap.w;
        }
        return out;
    };
    const Taps tx = taps(e.nx, c[0]), ty = taps(e.ny, c[1]), tz = taps(e.nz, c[2]);
    const float* ct = mShadeCoarseT.data();
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.nz), [&](const tbb::blocked_range<uint32_t>& slices) {
            std::vector<float> blended(c[0]);
            for (uint32_t k = slices.begin(); k != slices.end(); ++k)
                for (uint32_t j = 0; j < e.ny; ++j) {
                    const uint32_t y0 = ty.i0[j], y1 = ty.i1[j], z0 = tz.i0[k], z1 = tz.i1[k];
                    const float fy = ty.t[j], fz = tz.t[k];
                    const float* r00 = ct + size_t(c[0]) * (y0 + size_t(c[1]) * z0);
                    const float* r10 = ct + size_t(c[0]) * (y1 + size_t(c[1]) * z0);
                    const float* r01 = ct + size_t(c[0]) * (y0 + size_t(c[1]) * z1);
                    const float* r11 = ct + size_t(c[0]) * (y1 + size_t(c[1]) * z1);
                    float* b = blended.data();
                    for (uint32_t I = 0; I < c[0]; ++I) b[I] = Bilinear(r00[I], r10[I], r01[I], r11[I], fy, fz);
                    float* out = T + size_t(e.nx) * (j + size_t(e.ny) * k);
                    const uint32_t* x0 = tx.i0.data();
                    const uint32_t* x1 = tx.i1.data();
                    const float* fx = tx.t.data();
                    UpsampleRow(b, c[0], f, x0, x1, fx, out, e.nx);
                }
        });
    });
    return {};
}

Status BackendCpu::Shadow(const ShadowParams& params, const Buffer& columnSumBuffer, Buffer& GBuffer) {
    const float* D = static_cast<const BufferCpu&>(columnSumBuffer).F32();
    float* G = static_cast<BufferCpu&>(GBuffer).F32();
    const Extent3 e = columnSumBuffer.Extent();
    const ShadowLookup l = MakeShadowLookup(params.sun, e.nx, e.ny, params.nz, params.sigma, params.voxelSize);
    if (l.noSun) {  // no sun above the horizon: no shadow (docs/pipeline.md)
        std::fill(G, G + size_t(e.nx) * e.ny, 1.0f);
        return {};
    }
    const bool beer = params.form == ShadowForm::Beer, wang = params.form == ShadowForm::Wang;
    auto tap = [&](int64_t i, int64_t j) -> float {
        return (i < 0 || j < 0 || i >= e.nx || j >= e.ny) ? 0.0f : D[size_t(i) + size_t(e.nx) * size_t(j)];
    };
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny, 8), [&](const tbb::blocked_range<uint32_t>& rows) {
            for (uint32_t j = rows.begin(); j != rows.end(); ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    const int64_t x = int64_t(i) + l.baseX, y = int64_t(j) + l.baseY;
                    const float d = Bilinear(tap(x, y), tap(x + 1, y), tap(x, y + 1), tap(x + 1, y + 1), l.fx, l.fy);
                    G[i + size_t(e.nx) * j] =
                        wang ? WangShadow(l.opticalDepthPerD, params.coverage, params.densityFactor, d)
                             : GroundShadow(beer, l.opticalDepthPerD, params.kappa, d);
                }
        });
    });
    return {};
}

}  // namespace cb::cpu
