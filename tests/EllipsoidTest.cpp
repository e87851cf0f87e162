// The host-side ellipsoid list (SPEC section 2, Fizimayer's thesis, section 4.3.3.5).
#include <gtest/gtest.h>

#include "core/pipeline/Ellipsoids.h"

namespace cb {
namespace {

EllipsoidSettings Settings() {
    EllipsoidSettings s;
    s.seed = 3;
    s.targetCount = 30;
    s.densityAdaption = 2;
    s.lifetimeMean = 50;
    s.lifetimeVariance = 20;
    s.shrinkSteps = 10;
    s.margin = 8;
    s.wind.vector = {0.5, 0.0};
    return s;
}

// Test that the same seed gives the same list, step after step.
TEST(Ellipsoids, DeterministicForASeed) {
    EllipsoidList a(Settings(), {64, 32, 16}), b(Settings(), {64, 32, 16});
    for (int t = 0; t < 100; ++t) {
        a.Update();
        b.Update();
    }
    ASSERT_EQ(a.Items().size(), b.Items().size());
    for (size_t n = 0; n < a.Items().size(); ++n) {
        EXPECT_EQ(a.Items()[n].center[0], b.Items()[n].center[0]);
        EXPECT_EQ(a.Items()[n].age, b.Items()[n].age);
    }
}

// Test the count rules: it never changes by more than density_adaption in a
// step beyond the deaths, stays near the target, and nothing lives past its
// lifetime or outside the bounds.
TEST(Ellipsoids, CountAgeAndBounds) {
    EllipsoidSettings s = Settings();
    const Extent3 grid{64, 32, 16};
    EllipsoidList list(s, grid);
    EXPECT_EQ(list.Items().size(), s.targetCount);
    for (int t = 0; t < 500; ++t) {
        list.Update();
        const size_t count = list.Items().size();
        EXPECT_LE(count, s.targetCount);
        EXPECT_GE(count + 10, s.targetCount) << "step " << t;  // deaths are refilled at 2 a step
        for (const Ellipsoid& e : list.Items()) {
            ASSERT_LT(e.age, e.lifetime);
            ASSERT_GE(e.center[0], -s.margin);
            ASSERT_LE(e.center[0], grid.nx + s.margin);
        }
    }
}

// Test the linear shrink over the last shrink_steps of life.
TEST(Ellipsoids, ShrinkFactor) {
    Ellipsoid e{};
    e.lifetime = 100;
    e.age = 80;
    EXPECT_EQ(e.ShrinkFactor(10), 1.0);
    e.age = 90;
    EXPECT_EQ(e.ShrinkFactor(10), 1.0);
    e.age = 95;
    EXPECT_EQ(e.ShrinkFactor(10), 0.5);
    e.age = 99;
    EXPECT_DOUBLE_EQ(e.ShrinkFactor(10), 0.1);
    EXPECT_EQ(e.ShrinkFactor(0), 1.0);
}

// Test that a shrink longer than 2^32 - 1 - age still shrinks: age + shrink_steps must not wrap (found by fuzzing).
TEST(Ellipsoids, ShrinkFactorWithLongestShrink) {
    Ellipsoid e{};
    e.lifetime = 10;
    e.age = 5;
    EXPECT_DOUBLE_EQ(e.ShrinkFactor(UINT32_MAX), 5.0 / double(UINT32_MAX));
}

// Test that a lifetime beyond uint32 saturates at 2^32 - 1 steps instead of converting out of range (undefined
// behaviour: SSE code wraps 1e10 to 1410065408, while AVX-512's unsigned conversion happens to saturate, so this
// test can pass on such a machine without the fix; Sanitized.RunHugeLifetime's UBSan catches it on every machine).
TEST(Ellipsoids, HugeLifetimeSaturates) {
    for (double mean : {1e10, 1e20, 1e300}) {
        EllipsoidSettings s = Settings();
        s.lifetimeMean = mean;
        s.lifetimeVariance = 0;
        EllipsoidList list(s, {64, 32, 16});
        list.Update();
        ASSERT_FALSE(list.Items().empty());
        for (const Ellipsoid& e : list.Items()) EXPECT_EQ(e.lifetime, UINT32_MAX) << "lifetime_mean " << mean;
    }
}

// Test that the wind moves the centres: with no jitter, every survivor moves
// by exactly the wind vector.
TEST(Ellipsoids, WindMovesCentres) {
    EllipsoidSettings s = Settings();
    s.jitter = 0;
    s.lifetimeMean = 1000;
    s.lifetimeVariance = 0;
    EllipsoidList list(s, {64, 32, 16});
    std::vector<Ellipsoid> before = list.Items();
    list.Update();
    size_t matched = 0;
    for (const Ellipsoid& after : list.Items())
        for (const Ellipsoid& b : before)
            if (after.yaw == b.yaw) {
                EXPECT_DOUBLE_EQ(after.center[0], b.center[0] + 0.5);
                EXPECT_DOUBLE_EQ(after.center[1], b.center[1]);
                ++matched;
            }
    EXPECT_GE(matched, before.size() - 2);  // all but those that left the bounds
}

// Test the bilinear wind grid: at the centre of a 2x1 grid's cells the wind is
// the cell's vector; halfway between them, the mean.
TEST(Ellipsoids, WindGridIsBilinear) {
    EllipsoidSettings s = Settings();
    s.margin = 0;
    s.wind.gridNx = 2;
    s.wind.gridNy = 1;
    s.wind.grid = {{1.0, 0.0}, {3.0, 2.0}};
    EllipsoidList list(s, {100, 10, 4});
    // Cell centres at x = 25 and x = 75.
    EXPECT_DOUBLE_EQ(list.WindAt(25, 5)[0], 1.0);
    EXPECT_DOUBLE_EQ(list.WindAt(75, 5)[0], 3.0);
    EXPECT_DOUBLE_EQ(list.WindAt(50, 5)[0], 2.0);
    EXPECT_DOUBLE_EQ(list.WindAt(50, 5)[1], 1.0);
    EXPECT_DOUBLE_EQ(list.WindAt(0, 5)[0], 1.0);  // clamped at the edge
}

}  // namespace
}  // namespace cb
