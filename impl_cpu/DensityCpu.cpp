// Stage `density` on the CPU (SPEC 5): column sums, tile and band occupancy,
// and cloud cover. Work is split by rows of tiles, so each task owns its
// outputs and no two tasks write the same byte.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/DensityCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>

#include "impl_cpu/BackendCpu.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

// Writes flags[tx] = 1 iff some value > 0 in tile column tx of `rows` rows of
// length nx (tiles of T columns). `columnMax` is scratch of nx floats. The rows
// are folded into one by a max across i first, which vectorises.
void TileFlags(const float* values, uint32_t nx, uint32_t rows, uint32_t T, std::vector<float>& columnMax,
               uint8_t* flags) {
    columnMax.assign(values, values + nx);
    for (uint32_t r = 1; r < rows; ++r) {
        const float* row = values + size_t(nx) * r;
        for (uint32_t i = 0; i < nx; ++i) columnMax[i] = std::max(columnMax[i], row[i]);
    }
    for (uint32_t tx = 0, i0 = 0; i0 < nx; ++tx, i0 += T) {
        const uint32_t i1 = std::min(nx, i0 + T);
        float m = 0.0f;
        for (uint32_t i = i0; i < i1; ++i) m = std::max(m, columnMax[i]);
        flags[tx] = uint8_t(m > 0.0f);
    }
}

// Columns (i, j), j in [j0, j1), with any cld = 1: the OR of a column's
// slices, counted a word at a time.
uint32_t CoveredColumns(const BitField& cld, const Extent3& e, uint32_t j0, uint32_t j1) {
    return tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(j0, j1, 8), 0u,
        [&](const tbb::blocked_range<uint32_t>& rows, uint32_t count) {
            std::vector<uint64_t> columns(cld.WordsPerRow());
            for (uint32_t j = rows.begin(); j != rows.end(); ++j) {
                std::fill(columns.begin(), columns.end(), 0);
                for (uint32_t k = 0; k < e.nz; ++k) {
                    const uint64_t* row = cld.Row(j, k);
                    for (uint32_t w = 0; w < cld.WordsPerRow(); ++w) columns[w] |= row[w];
                }
                for (uint64_t word : columns) count += uint32_t(std::popcount(word));
            }
            return count;
        },
        [](uint32_t a, uint32_t b) { return a + b; });
}

// Columns with D > 0 (the cover of a scene without an automaton).
uint32_t ColumnsAboveZero(const float* D, size_t columns) {
    return uint32_t(std::count_if(D, D + columns, [](float d) { return d > 0.0f; }));
}

}  // namespace

Status Density(tbb::task_arena& arena, const DensityParams& params, const Buffer& qBuffer, const Buffer* cldBuffer,
               DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("cpu: density tile and band must be positive");
    const float* q = static_cast<const BufferCpu&>(qBuffer).F32();
    float* D = static_cast<BufferCpu&>(*out.columnSum).F32();
    uint8_t* tiles = static_cast<BufferCpu&>(*out.tiles).U8();
    uint8_t* bands = static_cast<BufferCpu&>(*out.bands).U8();
    const Extent3 e = qBuffer.Extent();
    const uint32_t T = params.tile, B = params.band;
    const uint32_t tilesX = CeilDiv(e.nx, T), tilesY = CeilDiv(e.ny, T), bandCount = CeilDiv(e.nz, B);
    const size_t sliceSize = size_t(e.nx) * e.ny;
    // The share: rows of tiles [ty0, ty1), i.e. the columns of rows j in [jBegin, jEnd).
    const uint32_t ty0 = params.slices.Begin(tilesY), ty1 = params.slices.End(tilesY);
    out.coveredColumns = 0;
    if (ty0 >= ty1) return {};
    const uint32_t jBegin = ty0 * T, jEnd = std::min(e.ny, ty1 * T);

    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<uint32_t>(ty0, ty1, 1), [&](const tbb::blocked_range<uint32_t>& tileRows) {
                // The columns of one row of tiles are contiguous in D and in each
                // slice of q, so every inner loop runs over T*nx consecutive floats.
                std::vector<float> bandMax;  // per column: the largest q within the current band
                std::vector<float> columnMax;
                for (uint32_t ty = tileRows.begin(); ty != tileRows.end(); ++ty) {
                    const uint32_t j0 = ty * T, j1 = std::min(e.ny, j0 + T);
                    const size_t count = size_t(j1 - j0) * e.nx;
                    float* d = D + size_t(e.nx) * j0;
                    std::fill(d, d + count, 0.0f);
                    bandMax.resize(count);
                    for (uint32_t b = 0; b < bandCount; ++b) {
                        std::fill(bandMax.begin(), bandMax.end(), 0.0f);
                        const uint32_t kEnd = std::min(e.nz, (b + 1) * B);
                        // k ascending, the order every backend sums in; four slices per
                        // pass so that d and bandMax are loaded and stored once per four.
                        uint32_t k = b * B;
                        for (; k + 4 <= kEnd; k += 4) {
                            const float* s0 = q + sliceSize * k + size_t(e.nx) * j0;
                            const float *s1 = s0 + sliceSize, *s2 = s1 + sliceSize, *s3 = s2 + sliceSize;
                            float* m = bandMax.data();
                            for (size_t n = 0; n < count; ++n) {
                                d[n] = (((d[n] + s0[n]) + s1[n]) + s2[n]) + s3[n];
                                m[n] = std::max(std::max(m[n], s0[n]), std::max(s1[n], std::max(s2[n], s3[n])));
                            }
                        }
                        for (; k < kEnd; ++k) {
                            const float* slice = q + sliceSize * k + size_t(e.nx) * j0;
                            for (size_t n = 0; n < count; ++n) {
                                d[n] += slice[n];
                                bandMax[n] = std::max(bandMax[n], slice[n]);
                            }
                        }
                        uint8_t* bandRow = bands + tilesX * (ty + size_t(tilesY) * b);
                        TileFlags(bandMax.data(), e.nx, j1 - j0, T, columnMax, bandRow);
                    }
                    uint8_t* tileRow = tiles + size_t(tilesX) * ty;
                    TileFlags(d, e.nx, j1 - j0, T, columnMax, tileRow);
                }
            });

        out.coveredColumns = cldBuffer
                                 ? CoveredColumns(static_cast<const BufferCpu&>(*cldBuffer).Bits(), e, jBegin, jEnd)
                                 : ColumnsAboveZero(D + size_t(e.nx) * jBegin, size_t(e.nx) * (jEnd - jBegin));
    });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(Density);

Status BackendCpu::Density(const DensityParams& params, const Buffer& qBuffer, const Buffer* cldBuffer,
                           DensityOutputs& out) {
    return HWY_DYNAMIC_DISPATCH(Density)(mArena, params, qBuffer, cldBuffer, out);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
