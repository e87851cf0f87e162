// Stage `density` on the CPU (SPEC 5): column sums, tile and band occupancy,
// and cloud cover. Work is split by rows of tiles, so each task owns its
// outputs and no two tasks write the same byte.
#include <algorithm>
#include <bit>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {

Status BackendCpu::Density(const DensityParams& params, const Buffer& qBuffer, const Buffer& cldBuffer,
                           DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("cpu: density tile and band must be positive");
    const float* q = static_cast<const BufferCpu&>(qBuffer).F32();
    const BitField& cld = static_cast<const BufferCpu&>(cldBuffer).Bits();
    float* D = static_cast<BufferCpu&>(*out.columnSum).F32();
    uint8_t* tiles = static_cast<BufferCpu&>(*out.tiles).U8();
    uint8_t* bands = static_cast<BufferCpu&>(*out.bands).U8();
    const Extent3 e = qBuffer.Extent();
    const uint32_t T = params.tile, B = params.band;
    const uint32_t tilesX = CeilDiv(e.nx, T), tilesY = CeilDiv(e.ny, T), bandCount = CeilDiv(e.nz, B);
    const size_t sliceSize = size_t(e.nx) * e.ny;

    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, tilesY, 1), [&](const tbb::blocked_range<uint32_t>& tileRows) {
            for (uint32_t ty = tileRows.begin(); ty != tileRows.end(); ++ty) {
                uint8_t* tileRow = tiles + size_t(tilesX) * ty;
                std::fill(tileRow, tileRow + tilesX, 0);
                for (uint32_t b = 0; b < bandCount; ++b)
                    std::fill_n(bands + tilesX * (ty + size_t(tilesY) * b), tilesX, 0);
                const uint32_t j1 = std::min(e.ny, (ty + 1) * T);
                for (uint32_t j = ty * T; j < j1; ++j) {
                    float* d = D + size_t(e.nx) * j;
                    std::fill(d, d + e.nx, 0.0f);
                    for (uint32_t k = 0; k < e.nz; ++k) {  // k ascending: the order every backend sums in
                        const float* row = q + sliceSize * k + size_t(e.nx) * j;
                        uint8_t* bandRow = bands + tilesX * (ty + size_t(tilesY) * (k / B));
                        for (uint32_t tx = 0; tx < tilesX; ++tx) {
                            const uint32_t i0 = tx * T, i1 = std::min(e.nx, i0 + T);
                            bool any = false;
                            for (uint32_t i = i0; i < i1; ++i) {
                                d[i] += row[i];
                                any |= row[i] > 0.0f;
                            }
                            bandRow[tx] |= uint8_t(any);
                        }
                    }
                    for (uint32_t tx = 0; tx < tilesX; ++tx) {
                        const uint32_t i0 = tx * T, i1 = std::min(e.nx, i0 + T);
                        for (uint32_t i = i0; i < i1; ++i) tileRow[tx] |= uint8_t(d[i] > 0.0f);
                    }
                }
            }
        });

        out.coveredColumns = tbb::parallel_reduce(
            tbb::blocked_range<uint32_t>(0, e.ny, 8), 0u,
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
    });
    return {};
}

}  // namespace cb::cpu
