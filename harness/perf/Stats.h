// The statistics of `perf compare` and `perf history` (docs/cli.md, "perf"):
// medians and quantiles, one-sided permutation tests over runs (paired sign
// flips, two samples), a one-sided Mann-Whitney U test, Holm's correction,
// bootstrap intervals, and change points in a series. Each formula is checked
// against SciPy in tests/check_perf_stats.py.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace cb::perf {

// The median, averaging the two middle values of an even count (NumPy's);
// NaN for no values.
double Median(std::span<const double> values);

// The q-quantile by linear interpolation between order statistics (NumPy's
// default); NaN for no values.
double Quantile(std::span<const double> values, double q);

// The two-sample permutation test counts every split when there are at most
// kExactPermutations; the sign-flip test counts every pattern of up to
// kExactSignFlipPairs differences (2^40, met in the middle: two halves of
// 2^20 sums). Beyond, each draws `permutations` random ones (fixed seed).
inline constexpr uint64_t kExactPermutations = 1 << 16;
inline constexpr size_t kExactSignFlipPairs = 40;

// The one-sided paired permutation test that the differences `d` have a
// positive mean: each difference's sign is flipped at random (the two sides of
// a pair are exchangeable under the null). p is the fraction of the 2^n sign
// patterns (the observed one included) whose sum is at least the observed sum:
// scipy.stats.permutation_test((d,), mean, permutation_type="samples",
// alternative="greater", n_resamples=np.inf); above kExactSignFlipPairs,
// random patterns give (1 + as large) / (1 + permutations). p = 1 for no
// differences. The smallest p n differences can give is 2^-n, exactly.
double SignFlipGreater(std::span<const double> d, int permutations, uint64_t seed);

// The one-sided two-sample permutation test that mean(x) > mean(y): the pooled
// values are split at random into groups of the two sizes.
// scipy.stats.permutation_test((x, y), mean(x) - mean(y),
// permutation_type="independent", alternative="greater"), exact over all
// C(n, |x|) splits when there are at most kExactPermutations. p = 1 when either
// side is empty. The smallest p is 1 / C(n, |x|).
double PermutationGreater(std::span<const double> x, std::span<const double> y, int permutations, uint64_t seed);

// The smallest p SignFlipGreater (of `pairs` differences) or
// PermutationGreater (of sizes nx, ny) can give with `permutations` random
// arrangements where they are not exact.
double SmallestSignFlipP(size_t pairs, int permutations);
double SmallestPermutationP(size_t nx, size_t ny, int permutations);

struct UTestResult {
    double u = 0;  // U of `x`: the number of pairs (x_i, y_j) with x_i > y_j, ties counting 1/2
    double z = 0;
    double p = 1;  // one-sided: the probability of a U this large if x and y had one distribution
};

// The one-sided Mann-Whitney U test that `x` is stochastically greater than
// `y`, by the normal approximation with the tie correction and a continuity
// correction of 1/2: scipy.stats.mannwhitneyu(x, y, alternative="greater",
// method="asymptotic"). p = 1 when either side is empty or every value ties.
UTestResult MannWhitneyGreater(std::span<const double> x, std::span<const double> y);

// Holm's step-down adjusted p-values (Holm-Bonferroni), in the input order:
// the family-wise error rate is at most alpha when the hypotheses with an
// adjusted p below alpha are rejected.
std::vector<double> HolmAdjusted(std::span<const double> p);

struct Interval {
    double low = 0, high = 0;
};

// The percentile bootstrap interval of median(head) / median(base): `resamples`
// times, each side is resampled with replacement on its own; the interval is
// the (1 - confidence) / 2 and (1 + confidence) / 2 quantiles of the ratios
// (linear interpolation, NumPy's default). Deterministic for a given seed.
Interval BootstrapRatioOfMedians(std::span<const double> base, std::span<const double> head, double confidence,
                                 int resamples, uint64_t seed);

// The percentile bootstrap interval of exp(mean(d)) for log-ratios `d`:
// `resamples` times, d is resampled with replacement. Deterministic for a seed.
Interval BootstrapExpMean(std::span<const double> d, double confidence, int resamples, uint64_t seed);

// Change points in `series` by binary segmentation: the split that maximises
// sqrt(nL nR / n) |mean(left) - mean(right)| (both sides at least minSegment
// long) is kept when the medians of its sides differ by at least minChange and
// a permutation test (`permutations` shuffles, fixed seed) gives p <= alpha;
// each side is then searched again. Returns the index of the first value after
// each change, ascending. For relative changes pass logs and log(1 + change).
struct ChangePointSettings {
    int minSegment = 4;
    double minChange = 0.1;  // |median(right) - median(left)|, in the series' units
    double alpha = 0.01;
    int permutations = 999;
    uint64_t seed = 12345;
};
std::vector<size_t> ChangePoints(std::span<const double> series, const ChangePointSettings& settings);

// What the search decided for each segment it looked at, in the order it
// looked: the first is the whole series. A segment shorter than 2 minSegment
// has no split (TooShort); otherwise its best split, the difference of its
// sides' medians (right - left) and, when that reaches minChange, the
// permutation p: shuffling stops once p cannot reach alpha, so a p above
// alpha is estimated from the shuffles drawn.
struct SegmentTest {
    enum class Outcome { Change, TooShort, BelowMinChange, NotSignificant };
    size_t begin = 0, end = 0;  // the segment, [begin, end) of the series
    size_t split = 0;           // the first index after its best split; 0 when TooShort
    double change = 0;          // median(right) - median(left), in the series' units
    double p = 1;               // 1 when not tested
    Outcome outcome = Outcome::TooShort;
};
struct ChangePointSearch {
    std::vector<size_t> points;  // as ChangePoints
    std::vector<SegmentTest> tests;
};
ChangePointSearch SearchChangePoints(std::span<const double> series, const ChangePointSettings& settings);

}  // namespace cb::perf
