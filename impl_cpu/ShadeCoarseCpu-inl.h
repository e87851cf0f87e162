// Shade at resolution f > 1 on the CPU (SPEC 6): the coarse grid of q that
// the sweep runs on, and T read back from the coarse grid trilinearly.
// Per-target code (Highway's -inl.h form), included by impl_cpu/ShadeCpu.cpp
// once per SIMD target after hwy/highway.h; no #pragma once.
#if defined(CB_IMPL_CPU_SHADE_COARSE_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_SHADE_COARSE_CPU_INL_H
#undef CB_IMPL_CPU_SHADE_COARSE_CPU_INL_H
#else
#define CB_IMPL_CPU_SHADE_COARSE_CPU_INL_H
#endif

#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "core/math/Shading.h"
#include "core/pipeline/ShadePlan.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

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
    if (f == 2)
        UpsampleRowT<2>(b, cells, x0, x1, fx, out, n);
    else
        UpsampleRowT<4>(b, cells, x0, x1, fx, out, n);
}

void AddRowBlocks(const float* row, uint32_t n, int f, float* cell) {
    if (f == 2)
        AddRowBlocksT<2>(row, n, cell);
    else
        AddRowBlocksT<4>(row, n, cell);
}

}  // namespace

// The coarse grid of q at resolution f: the mean of each f^3 block (partial
// blocks: of the voxels present). `cq` (plan.cells) must hold zeros.
inline void DownsampleShadeQ(const ShadePlan& plan, int f, const float* q, const Extent3& e, float* cq,
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
                        out[I + size_t(c[0]) * J] /=
                            float(blockSize(I, e.nx) * blockSize(J, e.ny) * blockSize(K, e.nz));
            }
        });
    });
}

// T at full resolution (extent e), trilinear from the coarse T `ct` (plan.cells):
// full voxel i sits at coarse coordinate (i + 0.5) / f - 0.5, clamped to the
// coarse grid's centres.
inline void UpsampleShadeT(const ShadePlan& plan, int f, const float* ct, const Extent3& e, float* T,
                           tbb::task_arena& arena) {
    const uint32_t* c = plan.cells;
    // Per fine row, the four coarse rows around it are blended in y and z first
    // (a coarse row in L1), then each voxel blends two of its cells in x.
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
    arena.execute([&] {
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
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_SHADE_COARSE_CPU_INL_H
