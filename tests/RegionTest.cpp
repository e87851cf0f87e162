// Region rasterisation (SPEC section 2): hand-worked values, and the CPU's
// per-row span rasteriser against a brute-force loop over every voxel.
#include <gtest/gtest.h>

#include <cmath>

#include "core/math/Random.h"
#include "core/pipeline/Ellipsoids.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/RegionReference.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

std::vector<uint8_t> Rasterise(const Extent3& e, const std::vector<RasterEllipsoid>& list, int threads = 0) {
    cpu::BackendCpu backend(threads);
    auto region = test::MakeBuffer(backend, BufferFormat::U8, e);
    EXPECT_TRUE(backend.Region(list, *region).has_value());
    return test::Read<uint8_t>(backend, *region);
}

// Test a sphere of radius 4 centred on voxel (5,5,5)'s centre: R = 255 at the
// centre; one voxel away rho = 1/4, 255*0.75 = 191.25 -> 191; two away
// rho = 1/2 -> floor(127.5 + 0.5) = 128; four away rho = 1 -> 0.
TEST(Region, SphereHandWorked) {
    const Extent3 e{11, 11, 11};
    RasterEllipsoid s{{5.5f, 5.5f, 5.5f}, {4, 4, 4}, 1, 0};
    std::vector<uint8_t> r = Rasterise(e, {s});
    EXPECT_EQ(r[VoxelIndex(e, 5, 5, 5)], 255);
    EXPECT_EQ(r[VoxelIndex(e, 6, 5, 5)], 191);
    EXPECT_EQ(r[VoxelIndex(e, 5, 3, 5)], 128);
    EXPECT_EQ(r[VoxelIndex(e, 5, 5, 9)], 0);
    EXPECT_EQ(r[VoxelIndex(e, 0, 0, 0)], 0);
}

// Test the yaw: an ellipsoid long in its own x, turned by 90 degrees, is long
// in world y. a = 4, b = 1: three voxels along y keep rho = 3/4 -> 64.
TEST(Region, YawTurnsTheAxes) {
    const Extent3 e{11, 11, 3};
    RasterEllipsoid s{{5.5f, 5.5f, 1.5f}, {4, 1, 1}, 0, 1};
    std::vector<uint8_t> r = Rasterise(e, {s});
    EXPECT_EQ(r[VoxelIndex(e, 5, 8, 1)], 64);  // floor(63.75 + 0.5)
    EXPECT_EQ(r[VoxelIndex(e, 8, 5, 1)], 0);   // rho = 3 across the short axis
}

// Test max blending: where two ellipsoids overlap the larger value wins.
TEST(Region, OverlapTakesTheMaximum) {
    const Extent3 e{12, 5, 5};
    RasterEllipsoid a{{3.5f, 2.5f, 2.5f}, {4, 4, 4}, 1, 0};
    RasterEllipsoid b{{6.5f, 2.5f, 2.5f}, {4, 4, 4}, 1, 0};
    std::vector<uint8_t> r = Rasterise(e, {a, b});
    EXPECT_EQ(r[VoxelIndex(e, 5, 2, 2)], 191);  // 1 from b (191) beats 2 from a (128)
    EXPECT_EQ(r[VoxelIndex(e, 3, 2, 2)], 255);
    EXPECT_EQ(r[VoxelIndex(e, 6, 2, 2)], 255);
}

// Test the span rasteriser against brute force over every voxel and every
// ellipsoid (the slow path it replaces): identical bytes, on random rotated
// ellipsoids that cross the grid's faces, for 1 and 2 threads.
TEST(Region, EqualsBruteForceOnRandomEllipsoids) {
    const Extent3 e{75, 41, 13};
    Pcg32 rng(21);
    std::vector<RasterEllipsoid> list;
    for (int n = 0; n < 60; ++n) {
        float yaw = float(rng.Uniform(0, 6.283185307179586));
        list.push_back({{float(rng.Uniform(-10, 85)), float(rng.Uniform(-10, 51)), float(rng.Uniform(-3, 16))},
                        {float(rng.Uniform(0.3, 20)), float(rng.Uniform(0.3, 12)), float(rng.Uniform(0.3, 6))},
                        std::cos(yaw), std::sin(yaw)});
    }
    const std::vector<uint8_t> expected = test::BruteForceRegion(e, list);
    for (int threads : {1, 2}) {
        std::vector<uint8_t> got = Rasterise(e, list, threads);
        size_t nonzero = 0;
        for (size_t v = 0; v < got.size(); ++v) {
            ASSERT_EQ(got[v], expected[v]) << "voxel " << v << " threads " << threads;
            nonzero += got[v] != 0;
        }
        EXPECT_GT(nonzero, e.Count() / 10);  // the case is not trivially empty
    }
}

}  // namespace
}  // namespace cb
