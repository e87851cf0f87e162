// The density map (SPEC section 5): column sums, tile and band occupancy, cover.
#include <gtest/gtest.h>

#include "core/math/Random.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

struct DensityResult {
    std::vector<float> D;
    std::vector<uint8_t> tiles, bands;
    uint32_t covered;
};

// `cld` empty: a scene without an automaton (Density gets no cld).
DensityResult RunDensity(const Extent3& e, const std::vector<float>& q, const std::vector<uint8_t>& cld, uint32_t T,
                         uint32_t B) {
    cpu::BackendCpu backend;
    auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto cb = cld.empty() ? nullptr : test::MakeFilled(backend, BufferFormat::Bits, e, cld);
    auto D = test::MakeBuffer(backend, BufferFormat::F32, {e.nx, e.ny, 1});
    auto tiles = test::MakeBuffer(backend, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), 1});
    auto bands = test::MakeBuffer(backend, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), CeilDiv(e.nz, B)});
    DensityOutputs out{D.get(), tiles.get(), bands.get(), 0};
    EXPECT_TRUE(backend.Density({T, B, {}}, *qb, cb.get(), out).has_value());
    return {test::Read<float>(backend, *D), test::Read<uint8_t>(backend, *tiles), test::Read<uint8_t>(backend, *bands),
            out.coveredColumns};
}

// Test that D is the sum of each column, exactly, on random multiples of 1/64.
TEST(Density, SumsTheColumns) {
    const Extent3 e{37, 21, 9};
    Pcg32 rng(8);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(2) ? float(rng.Below(65)) / 64.0f : 0.0f;
    DensityResult r = RunDensity(e, q, std::vector<uint8_t>(e.Count()), 8, 4);
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            double sum = 0;  // exact: at most 9 terms of 1/64 steps
            for (uint32_t k = 0; k < e.nz; ++k) sum += q[VoxelIndex(e, i, j, k)];
            ASSERT_EQ(r.D[i + e.nx * j], float(sum)) << i << "," << j;
        }
}

// Test tile and band occupancy with edge tiles that are partial: a grid of
// 10x7x6 with tiles of 4 and bands of 4 has 3x2 tiles and 2 bands.
TEST(Density, TileAndBandOccupancyHandWorked) {
    const Extent3 e{10, 7, 6};
    std::vector<float> q(e.Count(), 0.0f);
    q[VoxelIndex(e, 9, 6, 5)] = 0.25f;  // last (partial) tile (2,1), band 1
    q[VoxelIndex(e, 4, 0, 0)] = 1.0f;   // tile (1,0), band 0
    DensityResult r = RunDensity(e, q, std::vector<uint8_t>(e.Count()), 4, 4);
    const std::vector<uint8_t> tiles = {0, 1, 0, 0, 0, 1};
    EXPECT_EQ(r.tiles, tiles);
    const std::vector<uint8_t> bands = {0, 1, 0, 0, 0, 0,   // band 0
                                        0, 0, 0, 0, 0, 1};  // band 1
    EXPECT_EQ(r.bands, bands);
}

// Test cover: the fraction of columns with any cloud, counted from cld.
TEST(Density, CoverCountsColumnsWithCloud) {
    const Extent3 e{70, 3, 5};  // rows longer than one 64-bit word
    std::vector<uint8_t> cld(e.Count());
    cld[VoxelIndex(e, 0, 0, 0)] = 1;
    cld[VoxelIndex(e, 0, 0, 4)] = 1;   // same column: counts once
    cld[VoxelIndex(e, 69, 2, 2)] = 1;  // past the first word
    cld[VoxelIndex(e, 64, 1, 3)] = 1;
    DensityResult r = RunDensity(e, std::vector<float>(e.Count()), cld, 32, 4);
    EXPECT_EQ(r.covered, 3u);
}

// Test cover without an automaton (no cld): the columns whose D is above zero,
// with cloud at the grid's corners and a column that holds only zeros.
TEST(Density, CoverWithoutAutomatonCountsColumnsWithDensity) {
    const Extent3 e{70, 3, 5};
    std::vector<float> q(e.Count(), 0.0f);
    q[VoxelIndex(e, 0, 0, 0)] = 0.5f;
    q[VoxelIndex(e, 0, 0, 4)] = 0.25f;         // same column: counts once
    q[VoxelIndex(e, 69, 2, 4)] = 1.0f / 1024;  // the far corner, a small value
    q[VoxelIndex(e, 64, 1, 3)] = 1.0f;
    DensityResult r = RunDensity(e, q, {}, 32, 4);
    EXPECT_EQ(r.covered, 3u);
    // With cld given, the cover is cld's (here: none), not D's.
    EXPECT_EQ(RunDensity(e, q, std::vector<uint8_t>(e.Count()), 32, 4).covered, 0u);
}

}  // namespace
}  // namespace cb
