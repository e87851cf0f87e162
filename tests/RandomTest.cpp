// The hash random numbers of SPEC section 1 and the integer probability rules.
#include <gtest/gtest.h>

#include <set>

#include "core/math/Random.h"
#include "core/math/Rules.h"

namespace cb {
namespace {

// Test lowbias32 and rand24 against values worked out independently with
// Python's integers, masking to 32 bits after each multiply and add:
//   def lb(x): x ^= x>>16; x = x*0x7feb352d & M; x ^= x>>15; x = x*0x846ca68b & M; x ^= x>>16
//   key(s,t,c) = lb(s ^ lb((t*4 + c + 0x9E3779B9) & M)); rand24 = lb(v ^ key) >> 8
TEST(Random, MatchesIndependentPythonValues) {
    EXPECT_EQ(LowBias32(0u), 0u);
    EXPECT_EQ(LowBias32(1u), 0x688990c0u);
    EXPECT_EQ(LowBias32(2u), 0xd1132181u);
    EXPECT_EQ(LowBias32(0xdeadbeefu), 0xe628c683u);
    EXPECT_EQ(LowBias32(0xffffffffu), 0x6768824au);
    EXPECT_EQ(Rand24(1, 0, kStreamExtinction, 0), 13007976u);
    EXPECT_EQ(Rand24(1, 0, kStreamHumidity, 12345), 16669248u);
    EXPECT_EQ(Rand24(42, 7, kStreamActivation, 999999), 11197575u);
    // The initial-state step 0xFFFFFFFF wraps step*4 in uint32.
    EXPECT_EQ(Rand24(7, kInitialStateStep, kStreamHumidity, 3), 598340u);
}

// Test that rand24 stays in [0, 2^24) and that streams and steps differ.
TEST(Random, RangeAndIndependentStreams) {
    std::set<uint32_t> keys;
    for (uint32_t step = 0; step < 4; ++step)
        for (uint32_t stream = 0; stream < 4; ++stream) keys.insert(StreamKey(5, step, stream));
    EXPECT_EQ(keys.size(), 16u);
    for (uint32_t v = 0; v < 100000; ++v) ASSERT_LT(Rand24(3, 1, 2, v), 1u << 24);
}

// Test Q(p) = round(p * 2^24) at the ends and in between, and that p = 0 never
// fires and p = 1 always fires.
TEST(Random, QuantizedProbabilityEnds) {
    EXPECT_EQ(QuantizeProbability(0.0), 0u);
    EXPECT_EQ(QuantizeProbability(1.0), 1u << 24);
    EXPECT_EQ(QuantizeProbability(0.5), 1u << 23);
    EXPECT_EQ(QuantizeProbability(0.1), 1677722u);  // 1677721.6 rounds up
    for (uint32_t r : {0u, 1u, (1u << 24) - 1}) {
        EXPECT_FALSE(r < QuantizeProbability(0.0));
        EXPECT_TRUE(r < QuantizeProbability(1.0));
    }
}

// Test the region scaling P = (R*Q + 127)/255 at hand-worked points: R = 255
// keeps Q, R = 0 gives 0, and Q(1) at R = 255 stays 2^24 (always fires).
TEST(Random, RegionProbabilityHandWorked) {
    EXPECT_EQ(RegionProbability(255, 1u << 24), 1u << 24);
    EXPECT_EQ(RegionProbability(0, 1u << 24), 0u);              // 127/255 = 0
    EXPECT_EQ(RegionProbability(128, 1000), 502u);              // (128000 + 127)/255 = 502.45
    EXPECT_EQ(RegionProbability(1, 1677722), 6579u);            // 1677849/255 = 6579.8
}

// Test that the division-free comparison used by the vector kernels equals
// rand24 < P for every R and Q near the thresholds and at the ends.
TEST(Random, DivisionFreeComparisonEqualsDivision) {
    const uint32_t qs[] = {0, 1, 2, 254, 255, 256, 16777, 1677722, (1u << 24) - 1, 1u << 24};
    for (uint32_t q : qs)
        for (uint32_t region = 0; region < 256; ++region) {
            const uint32_t p = RegionProbability(region, q);
            for (int64_t d = -2; d <= 2; ++d) {
                int64_t r = int64_t(p) + d;
                if (r < 0 || r >= (1 << 24)) continue;
                ASSERT_EQ(RegionEventFires(uint32_t(r), region, q), uint32_t(r) < p)
                    << "R=" << region << " Q=" << q << " rand=" << r;
            }
            ASSERT_EQ(RegionEventFires(0, region, q), 0 < p);
            ASSERT_EQ(RegionEventFires((1u << 24) - 1, region, q), (1u << 24) - 1 < p);
        }
}

// Test that the host generator is deterministic and spreads over [0, 1).
TEST(Random, Pcg32DeterministicAndUniform) {
    Pcg32 a(99), b(99), c(100);
    bool differs = false;
    double sum = 0;
    for (int n = 0; n < 10000; ++n) {
        double x = a.NextDouble();
        ASSERT_EQ(x, b.NextDouble());
        differs |= x != c.NextDouble();
        ASSERT_GE(x, 0.0);
        ASSERT_LT(x, 1.0);
        sum += x;
    }
    EXPECT_TRUE(differs);
    EXPECT_NEAR(sum / 10000, 0.5, 0.02);
    for (int n = 0; n < 1000; ++n) ASSERT_LT(a.Below(7), 7u);
}

}  // namespace
}  // namespace cb
