// The CPU renderers' padded volumes (the march's and the layers'): (nx + 2) x (ny + 2) x (nz + 2) cells with voxel
// (i, j, k) at (i + 1, j + 1, k + 1), so that a trilinear sample needs no bounds checks. A border cell holds
// `border` (outside the grid), or with tiling, in x and y, the opposite edge's voxel (PaddedSourceVoxel,
// core/math/March.h). Call inside the backend's task arena.
// Per-target code (Highway's -inl.h form): included by a file that compiles itself once per SIMD target
// (impl_cpu/CpuIsa.h), after hwy/highway.h, so that each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_PADDED_VOLUME_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_PADDED_VOLUME_CPU_INL_H
#undef CB_IMPL_CPU_PADDED_VOLUME_CPU_INL_H
#else
#define CB_IMPL_CPU_PADDED_VOLUME_CPU_INL_H
#endif

#include <hwy/highway.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

#include "core/math/March.h"
#include "core/pipeline/Backend.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

// Forms the volume, each cell written once: cell(v) is voxel v's (v = i + nx (j + ny k)).
template <class Cell, class MakeCell>
void FormPaddedVolume(std::vector<Cell>& volume, const Extent3& e, bool tiling, const Cell& border, MakeCell&& cell) {
    const size_t px = size_t(e.nx) + 2, py = size_t(e.ny) + 2, pz = size_t(e.nz) + 2;
    volume.resize(px * py * pz);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pz), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t pk = r.begin(); pk < r.end(); ++pk)
            for (size_t pj = 0; pj < py; ++pj) {
                Cell* dst = volume.data() + px * (pj + py * pk);
                const int64_t k = PaddedSourceVoxel(uint32_t(pk), e.nz, false);
                const int64_t j = PaddedSourceVoxel(uint32_t(pj), e.ny, tiling);
                if (k < 0 || j < 0) {
                    std::fill(dst, dst + px, border);
                    continue;
                }
                const size_t src = size_t(e.nx) * (size_t(j) + size_t(e.ny) * size_t(k));
                for (size_t i = 0; i < e.nx; ++i) dst[i + 1] = cell(src + i);
                if (tiling) {
                    dst[0] = dst[e.nx];
                    dst[e.nx + 1] = dst[1];
                } else {
                    dst[0] = dst[e.nx + 1] = border;
                }
            }
    });
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_PADDED_VOLUME_CPU_INL_H
