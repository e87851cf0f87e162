// Empty-space skipping for the CPU's layers: one bit per padded cell of the padded volume (PaddedVolumeCpu-inl.h), set
// where the trilinear taps based there (core/math/Layers.h LayersTapsAt: the cell and its neighbours +1 in x, y and
// z) all read q = 0. Most of a wide view's fragments fall in clear sky (90 % on wang-20km); with the bit set
// LayersSampleAt skips their blend, whose q would be 0 exactly, so the pixels are those without it, bit for bit.
// Per-target code (Highway's -inl.h form): included by a file that compiles itself once per SIMD target
// (impl_cpu/CpuIsa.h), after hwy/highway.h, so that each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_LAYERS_OCCUPANCY_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_LAYERS_OCCUPANCY_CPU_INL_H
#undef CB_IMPL_CPU_LAYERS_OCCUPANCY_CPU_INL_H
#else
#define CB_IMPL_CPU_LAYERS_OCCUPANCY_CPU_INL_H
#endif

#include <hwy/highway.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <vector>

#include "core/pipeline/Backend.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

// Sets bit b of `bits` (b = i + px (j + py k), the padded index) iff the eight cells b + {0, 1} x {0, px} x {0, pxy}
// all hold q == 0 (q(cell) reads a cell's q); bases on the last row, column or slab, which no tap starts from, are
// 0. Call inside the backend's task arena.
template <class Cell, class ReadQ>
void FormEmptyTaps(std::vector<uint64_t>& bits, const std::vector<Cell>& volume, const Extent3& e, ReadQ&& q) {
    const size_t px = size_t(e.nx) + 2, py = size_t(e.ny) + 2, pz = size_t(e.nz) + 2, pxy = px * py;
    const size_t cells = px * py * pz, words = (cells + 63) / 64;
    bits.assign(words, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, words, 256), [&](const tbb::blocked_range<size_t>& r) {
        size_t base = 64 * r.begin();
        size_t i = base % px, j = (base / px) % py, k = base / pxy;
        for (size_t w = r.begin(); w < r.end(); ++w) {
            uint64_t word = 0;
            for (uint32_t b = 0; b < 64 && base < cells; ++b, ++base) {
                if (i + 1 < px && j + 1 < py && k + 1 < pz) {
                    const Cell* a = volume.data() + base;
                    const Cell* c = a + pxy;
                    const bool empty = q(a[0]) == 0.0f && q(a[1]) == 0.0f && q(a[px]) == 0.0f && q(a[px + 1]) == 0.0f &&
                                       q(c[0]) == 0.0f && q(c[1]) == 0.0f && q(c[px]) == 0.0f && q(c[px + 1]) == 0.0f;
                    word |= uint64_t(empty) << b;
                }
                if (++i == px) {
                    i = 0;
                    if (++j == py) j = 0, ++k;
                }
            }
            bits[w] = word;
        }
    });
}

// The layers' fetch on the CPU: a padded volume's cells, and FormEmptyTaps's bits for LayersSampleAt's skip.
template <class Cell>
struct LayersPaddedFetch {
    const Cell* volume = nullptr;
    const uint64_t* emptyTaps = nullptr;
    Cell operator()(uint32_t i) const { return volume[i]; }
    bool TapsEmpty(uint32_t base) const { return (emptyTaps[base >> 6] >> (base & 63)) & 1u; }
};

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_LAYERS_OCCUPANCY_CPU_INL_H
