// Edge cases of the perf statistics (harness/perf/Stats.h) whose values follow
// from the definitions alone; the formulas themselves are checked against
// SciPy in tests/check_perf_stats.py.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "harness/perf/Stats.h"

namespace cb::perf {
namespace {

// Test that the median averages the two middle values of an even count and is NaN for none.
TEST(PerfStats, Median) {
    EXPECT_EQ(Median(std::vector<double>{3, 1, 2}), 2);
    EXPECT_EQ(Median(std::vector<double>{4, 1, 3, 2}), 2.5);
    EXPECT_TRUE(std::isnan(Median(std::vector<double>{})));
}

// Test that U counts the pairs where x wins (ties count 1/2), and that all-equal samples give p = 1.
TEST(PerfStats, MannWhitneyCountsPairs) {
    const std::vector<double> x = {1, 2, 3}, y = {2, 2};
    // x > y: 3 > 2 twice = 2; ties 2 == 2 twice = 1; U = 3.
    EXPECT_DOUBLE_EQ(MannWhitneyGreater(x, y).u, 3);
    const std::vector<double> same(20, 1.0);
    EXPECT_EQ(MannWhitneyGreater(same, same).p, 1);
    EXPECT_EQ(MannWhitneyGreater(std::vector<double>{}, same).p, 1);
}

// Test that Holm multiplies the smallest p by m, keeps the order monotone, and caps at 1.
TEST(PerfStats, HolmSteps) {
    const std::vector<double> adjusted = HolmAdjusted(std::vector<double>{0.01, 0.04, 0.03, 0.5});
    EXPECT_DOUBLE_EQ(adjusted[0], 0.04);  // 4 x 0.01
    EXPECT_DOUBLE_EQ(adjusted[2], 0.09);  // 3 x 0.03
    EXPECT_DOUBLE_EQ(adjusted[1], 0.09);  // 2 x 0.04 = 0.08, raised to the previous 0.09
    EXPECT_DOUBLE_EQ(adjusted[3], 0.5);   // 1 x 0.5
}

// Test that the bootstrap interval is reproducible for a seed and brackets a constant ratio exactly.
TEST(PerfStats, BootstrapIsDeterministic) {
    std::mt19937 rng(1);
    std::normal_distribution<double> noise(1, 0.1);
    std::vector<double> base, head;
    for (int i = 0; i < 50; ++i) base.push_back(noise(rng)), head.push_back(2 * noise(rng));
    const Interval a = BootstrapRatioOfMedians(base, head, 0.95, 500, 7);
    const Interval b = BootstrapRatioOfMedians(base, head, 0.95, 500, 7);
    EXPECT_EQ(a.low, b.low);
    EXPECT_EQ(a.high, b.high);
    EXPECT_LT(a.low, 2.0);
    EXPECT_GT(a.high, 2.0);
    const Interval constant =
        BootstrapRatioOfMedians(std::vector<double>(9, 2.0), std::vector<double>(9, 3.0), 0.9, 100, 1);
    EXPECT_DOUBLE_EQ(constant.low, 1.5);
    EXPECT_DOUBLE_EQ(constant.high, 1.5);
}

// Test the sign-flip test on cases counted by hand: the sums of +-1 +-2 +-3 are 6, 4, 2, 0, 0, -2, -4, -6.
TEST(PerfStats, SignFlipCountsPatterns) {
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>{1, 2, 3}, 0, 0), 1.0 / 8);   // only 6 >= 6
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>{1, -2, 3}, 0, 0), 3.0 / 8);  // 6, 4, 2 >= 2
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>{-1, -2, -3}, 0, 0), 1.0);    // all >= -6
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>{}, 0, 0), 1.0);
    // Zeros flip to themselves: {0, 0, 1} has 8 patterns, 4 with the sum 1.
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>{0, 0, 1}, 0, 0), 4.0 / 8);
    EXPECT_DOUBLE_EQ(SmallestSignFlipP(10, 999), 1.0 / 1024);
    // Above 40 pairs the patterns are drawn: 41 equal positive differences are beaten by none of 999.
    EXPECT_DOUBLE_EQ(SignFlipGreater(std::vector<double>(41, 1.0), 999, 3), 1.0 / 1000);
    EXPECT_DOUBLE_EQ(SmallestSignFlipP(41, 999), 1.0 / 1000);
}

// Test the two-sample test on a case counted by hand: the 6 ways to pick two of {1, 2, 3, 4} as x give
// mean differences 2, 1, 0, 0, -1, -2.
TEST(PerfStats, PermutationCountsSplits) {
    const std::vector<double> x = {3, 4}, y = {1, 2};
    EXPECT_DOUBLE_EQ(PermutationGreater(x, y, 0, 0), 1.0 / 6);
    EXPECT_DOUBLE_EQ(PermutationGreater(y, x, 0, 0), 1.0);
    EXPECT_DOUBLE_EQ(PermutationGreater(std::vector<double>{1, 4}, std::vector<double>{2, 3}, 0, 0), 4.0 / 6);
    EXPECT_DOUBLE_EQ(PermutationGreater(std::vector<double>{}, y, 0, 0), 1.0);
    EXPECT_DOUBLE_EQ(SmallestPermutationP(2, 2, 0), 1.0 / 6);
}

// Test that the quantile interpolates linearly between order statistics (NumPy's default).
TEST(PerfStats, QuantileInterpolates) {
    const std::vector<double> v = {4, 1, 3, 2};  // sorted 1 2 3 4: q at position 3q
    EXPECT_DOUBLE_EQ(Quantile(v, 0), 1);
    EXPECT_DOUBLE_EQ(Quantile(v, 0.25), 1.75);
    EXPECT_DOUBLE_EQ(Quantile(v, 0.5), 2.5);
    EXPECT_DOUBLE_EQ(Quantile(v, 1), 4);
    EXPECT_TRUE(std::isnan(Quantile(std::vector<double>{}, 0.5)));
}

// Test that a series shorter than two minimum segments has no change point, and a clean step is found.
TEST(PerfStats, ChangePointsNeedTwoSegments) {
    ChangePointSettings s;
    s.minSegment = 4;
    EXPECT_TRUE(ChangePoints(std::vector<double>{0, 0, 0, 1, 1, 1, 1}, s).empty());
    std::vector<double> step(12, 0.0);
    for (size_t i = 5; i < step.size(); ++i) step[i] = 1;
    EXPECT_EQ(ChangePoints(step, s), std::vector<size_t>{5});
    s.minChange = 2;  // larger than the step
    EXPECT_TRUE(ChangePoints(step, s).empty());
}

}  // namespace
}  // namespace cb::perf
