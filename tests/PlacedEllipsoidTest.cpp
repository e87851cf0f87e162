// Placed ellipsoids (SPEC 17, docs/contract.md): hand-worked keyframes, lifetimes, persistence, shrink and yaw,
// the random list untouched by them, and their region combined with the random one's by the maximum (SPEC 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/pipeline/Ellipsoids.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/RegionReference.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// A list with no random ellipsoids: only the placed ones rasterise.
EllipsoidSettings PeOnlyPlaced(std::vector<PlacedEllipsoid> placed, uint32_t shrinkSteps = 0) {
    EllipsoidSettings s;
    s.targetCount = 0;
    s.densityAdaption = 0;
    s.shrinkSteps = shrinkSteps;
    s.placed = std::move(placed);
    return s;
}

PlacedEllipsoid PePlaced(std::array<double, 3> center, std::array<double, 3> semiAxes, uint32_t start,
                         std::optional<uint32_t> lifetime) {
    PlacedEllipsoid p;
    p.center = center;
    p.semiAxes = semiAxes;
    p.start = start;
    p.lifetime = lifetime;
    return p;
}

std::vector<uint8_t> PeRasterise(const Extent3& e, const std::vector<RasterEllipsoid>& list) {
    cpu::BackendCpu backend;
    auto region = test::MakeBuffer(backend, BufferFormat::U8, e);
    EXPECT_TRUE(backend.Region(list, *region).has_value());
    return test::Read<uint8_t>(backend, *region);
}

// Test the keyframes by hand: (10, 20, 5) at step 2, (18, 12, 9) at step 6, (18, 12, 1) at step 10. Held before the
// first and after the last; step 3 is a quarter of the first segment (12, 18, 6), step 5 three quarters (16, 14, 8),
// step 8 half of the second (18, 12, 5).
TEST(PlacedEllipsoids, KeyframesInterpolateLinearlyAndHold) {
    PlacedEllipsoid p;
    p.keyframes = {{2, {10, 20, 5}}, {6, {18, 12, 9}}, {10, {18, 12, 1}}};
    using C = std::array<double, 3>;
    const std::pair<uint32_t, C> expected[] = {
        {0, {10, 20, 5}}, {2, {10, 20, 5}},  {3, {12, 18, 6}},  {5, {16, 14, 8}},           {6, {18, 12, 9}},
        {8, {18, 12, 5}}, {10, {18, 12, 1}}, {11, {18, 12, 1}}, {4000000000u, {18, 12, 1}},
    };
    for (const auto& [step, centre] : expected) {
        const C got = PlacedCenterAt(p, step);
        for (int axis = 0; axis < 3; ++axis) EXPECT_DOUBLE_EQ(got[axis], centre[axis]) << "step " << step;
    }
    // Without keyframes the centre holds.
    const PlacedEllipsoid still = PePlaced({3, 4, 5}, {1, 1, 1}, 0, std::nullopt);
    EXPECT_EQ(PlacedCenterAt(still, 0), (C{3, 4, 5}));
    EXPECT_EQ(PlacedCenterAt(still, 77), (C{3, 4, 5}));
}

// Test the lifetime and the start: an ellipsoid starting at step 2 with lifetime 3 lives at list steps 2, 3 and 4
// (ages 0, 1, 2) and not at 0, 1 or 5; a persistent one lives at every step.
TEST(PlacedEllipsoids, StartLifetimeAndPersistence) {
    EllipsoidList list(
        PeOnlyPlaced({PePlaced({8, 8, 4}, {3, 3, 2}, 2, 3), PePlaced({20, 8, 4}, {2, 2, 2}, 0, std::nullopt)}),
        {32, 16, 8});
    const size_t expectedCount[] = {1, 1, 2, 2, 2, 1, 1};
    for (uint32_t t = 0; t < 7; ++t) {
        EXPECT_EQ(list.ListStep(), t);
        const std::vector<RasterEllipsoid> raster = list.Raster();
        EXPECT_EQ(raster.size(), expectedCount[t]) << "list step " << t;
        // The persistent one is always there (it is listed after the first when both live).
        EXPECT_EQ(raster.back().center[0], 20.0f) << "list step " << t;
        list.Update();
    }
    const std::optional<Ellipsoid> atThree = PlacedAt(PePlaced({8, 8, 4}, {3, 3, 2}, 2, 3), 3);
    ASSERT_TRUE(atThree.has_value());
    EXPECT_EQ(atThree->age, 1u);
    EXPECT_EQ(atThree->lifetime, 3u);
    EXPECT_FALSE(PlacedAt(PePlaced({8, 8, 4}, {3, 3, 2}, 2, 3), 5).has_value());
}

// Test the shrink: lifetime 4 and shrink_steps 2 keep the full size at ages 0 to 2 (age + 2 <= 4) and halve it at
// age 3 ((4 - 3) / 2); a persistent ellipsoid never shrinks, even at list step 1000 with shrink_steps 2000.
TEST(PlacedEllipsoids, ShrinkOverTheLastStepsUnlessPersistent) {
    EllipsoidList mortal(PeOnlyPlaced({PePlaced({8, 8, 4}, {6, 4, 2}, 0, 4)}, 2), {16, 16, 8});
    const float expectedA[] = {6, 6, 6, 3};
    for (uint32_t t = 0; t < 4; ++t) {
        const std::vector<RasterEllipsoid> raster = mortal.Raster();
        ASSERT_EQ(raster.size(), 1u) << "list step " << t;
        EXPECT_EQ(raster[0].semiAxes[0], expectedA[t]) << "list step " << t;
        EXPECT_EQ(raster[0].semiAxes[2], expectedA[t] / 3) << "list step " << t;
        mortal.Update();
    }
    EXPECT_TRUE(mortal.Raster().empty());

    EllipsoidList persistent(PeOnlyPlaced({PePlaced({8, 8, 4}, {6, 4, 2}, 0, std::nullopt)}, 2000), {16, 16, 8});
    for (int t = 0; t < 1000; ++t) persistent.Update();
    const std::vector<RasterEllipsoid> raster = persistent.Raster();
    ASSERT_EQ(raster.size(), 1u);
    EXPECT_EQ(raster[0].semiAxes[0], 6.0f);
}

// Test the yaw on the CPU's region: a = 8, b = c = 2 centred on voxel (10, 10, 2) turned by 90 degrees is long in
// world y. Six voxels along y: d = Rz(-90)(0, 6, 0) = (6, 0, 0), rho = 6/8, R = floor(255 * 0.25 + 0.5) = 64; six
// along x: rho = 6/2 = 3, R = 0. Unturned, the two swap. The raster carries cos and sin of the yaw in radians.
TEST(PlacedEllipsoids, YawTurnsTheirAxesInTheRegion) {
    const Extent3 e{21, 21, 5};
    PlacedEllipsoid p = PePlaced({10.5, 10.5, 2.5}, {8, 2, 2}, 0, std::nullopt);
    for (double yaw : {90.0, -270.0}) {
        p.yawDeg = yaw;
        const std::vector<RasterEllipsoid> raster = EllipsoidList(PeOnlyPlaced({p}), e).Raster();
        ASSERT_EQ(raster.size(), 1u);
        EXPECT_NEAR(raster[0].cosYaw, 0.0f, 1e-7f);
        EXPECT_FLOAT_EQ(raster[0].sinYaw, 1.0f);
        const std::vector<uint8_t> r = PeRasterise(e, raster);
        EXPECT_EQ(r[VoxelIndex(e, 10, 16, 2)], 64) << "yaw " << yaw;
        EXPECT_EQ(r[VoxelIndex(e, 16, 10, 2)], 0) << "yaw " << yaw;
    }
    p.yawDeg = 0;
    const std::vector<uint8_t> r = PeRasterise(e, EllipsoidList(PeOnlyPlaced({p}), e).Raster());
    EXPECT_EQ(r[VoxelIndex(e, 16, 10, 2)], 64);
    EXPECT_EQ(r[VoxelIndex(e, 10, 16, 2)], 0);
}

EllipsoidSettings PeMixed(bool withPlaced) {
    EllipsoidSettings s;
    s.seed = 11;
    s.targetCount = 12;
    s.densityAdaption = 2;
    s.sizeMean = {6, 6, 3};
    s.sizeVariance = {2, 2, 1};
    s.lifetimeMean = 8;
    s.lifetimeVariance = 4;
    s.shrinkSteps = 3;
    s.margin = 4;
    s.wind.vector = {0.3, -0.1};
    s.jitter = 0.2;
    if (withPlaced) {
        PlacedEllipsoid drifting = PePlaced({}, {9, 4, 3}, 1, 20);
        drifting.keyframes = {{0, {6, 10, 5}}, {12, {30, 14, 6}}};
        drifting.yawDeg = 35;
        PlacedEllipsoid tower = PePlaced({24, 24, 6}, {5, 5, 6}, 0, std::nullopt);
        s.placed = {drifting, tower};
    }
    return s;
}

// Test that placed ellipsoids leave the random list alone (they draw nothing from its generator and count nothing
// against target_count): step after step, the random items are those of the same list without them, and the raster
// is the random ones followed by the placed ones alive at that step.
TEST(PlacedEllipsoids, RandomListUnchangedByThem) {
    const Extent3 e{40, 32, 12};
    EllipsoidList plain(PeMixed(false), e), mixed(PeMixed(true), e);
    for (uint32_t t = 0; t < 30; ++t) {
        ASSERT_EQ(mixed.Items().size(), plain.Items().size()) << "step " << t;
        for (size_t n = 0; n < plain.Items().size(); ++n) {
            EXPECT_EQ(mixed.Items()[n].center[0], plain.Items()[n].center[0]);
            EXPECT_EQ(mixed.Items()[n].age, plain.Items()[n].age);
        }
        const std::vector<RasterEllipsoid> a = plain.Raster(), b = mixed.Raster();
        const size_t placedAlive = (t >= 1 && t < 21 ? 1 : 0) + 1;
        ASSERT_EQ(b.size(), a.size() + placedAlive) << "step " << t;
        for (size_t n = 0; n < a.size(); ++n) EXPECT_EQ(b[n].center[0], a[n].center[0]);
        EXPECT_EQ(b.back().center[0], 24.0f);
        plain.Update();
        mixed.Update();
    }
}

// Test SPEC 2's combination on the CPU's region: the region of random and placed ellipsoids together is, voxel by
// voxel, the larger of the random ones' region and the placed ones' region, and equals the brute-force region of
// every ellipsoid (tests/RegionReference.h), at steps where the drifting placed ellipsoid overlaps random ones.
TEST(PlacedEllipsoids, RegionIsTheMaximumOverRandomAndPlaced) {
    const Extent3 e{40, 32, 12};
    EllipsoidList plain(PeMixed(false), e), mixed(PeMixed(true), e);
    EllipsoidSettings placedOnly = PeMixed(true);
    placedOnly.targetCount = 0;
    EllipsoidList onlyPlaced(placedOnly, e);
    size_t overlaps = 0;
    for (uint32_t t = 0; t < 16; ++t) {
        const std::vector<uint8_t> random = PeRasterise(e, plain.Raster()),
                                   placed = PeRasterise(e, onlyPlaced.Raster());
        const std::vector<uint8_t> both = PeRasterise(e, mixed.Raster());
        ASSERT_EQ(both, test::BruteForceRegion(e, mixed.Raster())) << "step " << t;
        for (size_t v = 0; v < both.size(); ++v) {
            ASSERT_EQ(both[v], std::max(random[v], placed[v])) << "step " << t << ", voxel " << v;
            overlaps += random[v] > 0 && placed[v] > 0;
        }
        plain.Update();
        mixed.Update();
        onlyPlaced.Update();
    }
    EXPECT_GT(overlaps, 0u) << "the test needs placed and random ellipsoids that overlap";
}

}  // namespace
}  // namespace cb
