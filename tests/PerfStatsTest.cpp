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
