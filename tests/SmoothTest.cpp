// Smoothing (SPEC section 4) against hand-worked kernels and a direct 3-D sum.
#include <gtest/gtest.h>

#include "core/math/Random.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

std::vector<float> SmoothOnCpu(cpu::BackendCpu& backend, const Extent3& e, const std::vector<uint8_t>& cld, int radius) {
    auto bits = test::MakeFilled(backend, BufferFormat::Bits, e, cld);
    auto q = test::MakeBuffer(backend, BufferFormat::F32, e);
    Status s = backend.Smooth(radius, *bits, *q);
    EXPECT_TRUE(s.has_value());
    return test::Read<float>(backend, *q);
}

// Test that a single cloud voxel smooths into the binomial kernel itself:
// r = 1 gives (1,2,1)^3/64, so 8/64 at the centre, 4/64 on faces, 2/64 on
// edges, 1/64 at corners and 0 beyond.
TEST(Smooth, SingleVoxelGivesKernelRadius1) {
    const Extent3 e{7, 7, 7};
    std::vector<uint8_t> cld(e.Count());
    cld[VoxelIndex(e, 3, 3, 3)] = 1;
    cpu::BackendCpu backend;
    std::vector<float> q = SmoothOnCpu(backend, e, cld, 1);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                int di = std::abs(int(i) - 3), dj = std::abs(int(j) - 3), dk = std::abs(int(k) - 3);
                float expected = 0;
                if (di <= 1 && dj <= 1 && dk <= 1) expected = float((2 >> di) * (2 >> dj) * (2 >> dk)) / 64.0f;
                ASSERT_EQ(q[VoxelIndex(e, i, j, k)], expected) << i << "," << j << "," << k;
            }
}

// Test r = 2 at hand-worked points: centre 6*6*6/4096, (1,0,0) 4*6*6/4096,
// (2,2,2) 1/4096, (3,0,0) 0.
TEST(Smooth, SingleVoxelGivesKernelRadius2) {
    const Extent3 e{9, 9, 9};
    std::vector<uint8_t> cld(e.Count());
    cld[VoxelIndex(e, 4, 4, 4)] = 1;
    cpu::BackendCpu backend;
    std::vector<float> q = SmoothOnCpu(backend, e, cld, 2);
    EXPECT_EQ(q[VoxelIndex(e, 4, 4, 4)], 216.0f / 4096.0f);
    EXPECT_EQ(q[VoxelIndex(e, 5, 4, 4)], 144.0f / 4096.0f);
    EXPECT_EQ(q[VoxelIndex(e, 6, 6, 6)], 1.0f / 4096.0f);
    EXPECT_EQ(q[VoxelIndex(e, 2, 6, 4)], 1.0f * 1 * 6 / 4096.0f);
    EXPECT_EQ(q[VoxelIndex(e, 7, 4, 4)], 0.0f);
    float sum = 0;
    for (float v : q) sum += v;
    EXPECT_EQ(sum, 1.0f);  // the whole kernel fits in the grid
}

// Test that outside the grid counts as 0: a full grid at r = 1 has 1 inside,
// 48/64 on a face, 36/64 on an edge and 27/64 at a corner.
TEST(Smooth, BoundaryCountsAsEmpty) {
    const Extent3 e{5, 4, 3};
    std::vector<uint8_t> cld(e.Count(), 1);
    cpu::BackendCpu backend;
    std::vector<float> q = SmoothOnCpu(backend, e, cld, 1);
    EXPECT_EQ(q[VoxelIndex(e, 2, 1, 1)], 1.0f);
    EXPECT_EQ(q[VoxelIndex(e, 0, 1, 1)], 48.0f / 64.0f);
    EXPECT_EQ(q[VoxelIndex(e, 0, 0, 1)], 36.0f / 64.0f);
    EXPECT_EQ(q[VoxelIndex(e, 4, 3, 2)], 27.0f / 64.0f);
}

// Test r = 0 is the identity, and r = 1 and 2 equal a direct triple sum over
// the neighbourhood (the slow path) bit for bit on a random odd-sized field.
TEST(Smooth, EqualsDirectSumOnRandomField) {
    const Extent3 e{67, 13, 11};
    Pcg32 rng(4);
    std::vector<uint8_t> cld(e.Count());
    for (uint8_t& c : cld) c = rng.Below(3) == 0;
    cpu::BackendCpu backend;
    std::vector<float> q0 = SmoothOnCpu(backend, e, cld, 0);
    for (size_t v = 0; v < cld.size(); ++v) ASSERT_EQ(q0[v], float(cld[v]));
    for (int r : {1, 2}) {
        const int w1[3] = {1, 2, 1}, w2[5] = {1, 4, 6, 4, 1};
        const int* w = r == 1 ? w1 : w2;
        const float W = r == 1 ? 64.0f : 4096.0f;
        std::vector<float> q = SmoothOnCpu(backend, e, cld, r);
        for (int k = 0; k < int(e.nz); ++k)
            for (int j = 0; j < int(e.ny); ++j)
                for (int i = 0; i < int(e.nx); ++i) {
                    int sum = 0;
                    for (int dk = -r; dk <= r; ++dk)
                        for (int dj = -r; dj <= r; ++dj)
                            for (int di = -r; di <= r; ++di) {
                                int x = i + di, y = j + dj, z = k + dk;
                                if (x < 0 || y < 0 || z < 0 || x >= int(e.nx) || y >= int(e.ny) || z >= int(e.nz)) continue;
                                sum += w[di + r] * w[dj + r] * w[dk + r] * cld[VoxelIndex(e, x, y, z)];
                            }
                    ASSERT_EQ(q[VoxelIndex(e, i, j, k)], float(sum) / W) << "r=" << r << " at " << i << "," << j << "," << k;
                }
    }
}

}  // namespace
}  // namespace cb
