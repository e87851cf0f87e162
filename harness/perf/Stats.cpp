#include "harness/perf/Stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace cb::perf {
namespace {

// NumPy's default quantile of sorted values: linear interpolation between order statistics.
double SortedQuantile(std::vector<double>& sorted, double q) {
    const double position = q * double(sorted.size() - 1);
    const size_t below = size_t(std::floor(position));
    const size_t above = std::min(below + 1, sorted.size() - 1);
    return sorted[below] + (position - double(below)) * (sorted[above] - sorted[below]);
}

// The median of `values`, reordering them.
double MedianInPlace(std::vector<double>& values) {
    const size_t n = values.size();
    if (n == 0) return std::numeric_limits<double>::quiet_NaN();
    const auto middle = values.begin() + std::ptrdiff_t(n / 2);
    std::nth_element(values.begin(), middle, values.end());
    if (n % 2 == 1) return *middle;
    return (*middle + *std::max_element(values.begin(), middle)) / 2;
}

// The best split of `x` (each side at least minSegment long) and its statistic
// sqrt(nL nR / n) |mean(left) - mean(right)|; {0, -1} when there is none.
std::pair<size_t, double> BestSplit(std::span<const double> x, int minSegment) {
    const size_t n = x.size();
    const double total = std::accumulate(x.begin(), x.end(), 0.0);
    std::pair<size_t, double> best{0, -1};
    double left = 0;
    for (size_t k = 1; k < n; ++k) {
        left += x[k - 1];
        if (k < size_t(minSegment) || n - k < size_t(minSegment)) continue;
        const double nl = double(k), nr = double(n - k);
        const double statistic = std::sqrt(nl * nr / double(n)) * std::abs(left / nl - (total - left) / nr);
        if (statistic > best.second) best = {k, statistic};
    }
    return best;
}

// Floating-point sums of one arrangement in another order can differ in the
// last bits: a permuted statistic within this relative distance of the
// observed one counts as at least as large (SciPy's permutation_test does the same).
constexpr double kPermutationTolerance = 1e-14;

// p from `asLarge` of `total` arrangements, exact or random (SciPy's adjustment of 1 for random ones).
double PermutationP(uint64_t asLarge, uint64_t total, bool exact) {
    return exact ? double(asLarge) / double(total) : double(asLarge + 1) / double(total + 1);
}

// C(n, k), saturating at UINT64_MAX.
uint64_t Binomial(size_t n, size_t k) {
    k = std::min(k, n - k);
    long double c = 1;
    for (size_t i = 1; i <= k; ++i) c = c * (long double)(n - k + i) / (long double)i;
    return c >= (long double)UINT64_MAX ? UINT64_MAX : uint64_t(std::llround(c));
}

void Segment(std::span<const double> series, size_t offset, const ChangePointSettings& s, std::mt19937_64& rng,
             ChangePointSearch& search) {
    SegmentTest test;
    test.begin = offset, test.end = offset + series.size();
    const auto [split, statistic] = BestSplit(series, s.minSegment);
    if (statistic < 0) {
        search.tests.push_back(test);
        return;
    }
    const std::span<const double> left = series.first(split), right = series.subspan(split);
    test.split = offset + split;
    test.change = Median(right) - Median(left);
    test.outcome = SegmentTest::Outcome::BelowMinChange;
    if (std::abs(test.change) < s.minChange) {
        search.tests.push_back(test);
        return;
    }
    std::vector<double> shuffled(series.begin(), series.end());
    // p = (1 + asLarge) / (1 + permutations) exceeds alpha once asLarge reaches this: no need to go on.
    const double hopeless = s.alpha * double(1 + s.permutations) - 1;
    int asLarge = 0, drawn = 0;
    while (drawn < s.permutations && double(asLarge) <= hopeless) {
        std::shuffle(shuffled.begin(), shuffled.end(), rng);
        if (BestSplit(shuffled, s.minSegment).second >= statistic) ++asLarge;
        ++drawn;
    }
    test.p = double(1 + asLarge) / double(1 + drawn);
    test.outcome = test.p <= s.alpha && drawn == s.permutations ? SegmentTest::Outcome::Change
                                                                  : SegmentTest::Outcome::NotSignificant;
    search.tests.push_back(test);
    if (test.outcome != SegmentTest::Outcome::Change) return;
    Segment(left, offset, s, rng, search);
    search.points.push_back(offset + split);
    Segment(right, offset + split, s, rng, search);
}

}  // namespace

double Median(std::span<const double> values) {
    std::vector<double> copy(values.begin(), values.end());
    return MedianInPlace(copy);
}

double Quantile(std::span<const double> values, double q) {
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::vector<double> sorted(values.begin(), values.end());
    std::sort(sorted.begin(), sorted.end());
    return SortedQuantile(sorted, q);
}

// Every sum of +-v[i] over the 2^n sign patterns, ascending. The first pattern built is all plus, summed in
// order, so the observed pattern's sum is met exactly.
std::vector<double> SortedSignedSums(std::span<const double> v) {
    std::vector<double> sums(size_t(1) << v.size());
    size_t filled = 1;
    for (double x : v) {
        for (size_t i = 0; i < filled; ++i) {
            sums[filled + i] = sums[i] - x;
            sums[i] += x;
        }
        filled *= 2;
    }
    std::sort(sums.begin(), sums.end());
    return sums;
}

double SignFlipGreater(std::span<const double> d, int permutations, uint64_t seed) {
    const size_t n = d.size();
    if (n == 0) return 1;
    if (n <= kExactSignFlipPairs) {
        // Meet in the middle: the 2^n pattern sums are every a + b, a from the first half's 2^(n/2) sums and b
        // from the second's. The observed sum is formed the same way, so its own pattern always counts.
        const std::span<const double> front = d.first(n / 2), back = d.subspan(n / 2);
        const double observed = std::accumulate(front.begin(), front.end(), 0.0) +
                                std::accumulate(back.begin(), back.end(), 0.0);
        const double atLeast = observed - std::abs(observed) * kPermutationTolerance;
        const std::vector<double> a = SortedSignedSums(front), b = SortedSignedSums(back);
        // a + b grows with each of them, so the b that reach atLeast are a suffix that only lengthens as a grows.
        uint64_t asLarge = 0;
        size_t first = b.size();
        for (double x : a) {
            while (first > 0 && x + b[first - 1] >= atLeast) --first;
            asLarge += b.size() - first;
        }
        return PermutationP(asLarge, uint64_t(1) << n, true);
    }
    const double observed = std::accumulate(d.begin(), d.end(), 0.0);
    const double atLeast = observed - std::abs(observed) * kPermutationTolerance;
    uint64_t asLarge = 0;
    std::mt19937_64 rng(seed);
    for (int r = 0; r < permutations; ++r) {
        double sum = 0;
        for (size_t i = 0; i < n; ++i) sum += (rng() & 1) ? -d[i] : d[i];
        asLarge += sum >= atLeast;
    }
    return PermutationP(asLarge, uint64_t(permutations), false);
}

double PermutationGreater(std::span<const double> x, std::span<const double> y, int permutations, uint64_t seed) {
    if (x.empty() || y.empty()) return 1;
    std::vector<double> pooled(x.begin(), x.end());
    pooled.insert(pooled.end(), y.begin(), y.end());
    const size_t n = pooled.size(), nx = x.size();
    const double total = std::accumulate(pooled.begin(), pooled.end(), 0.0);
    auto statistic = [&](double sumX) { return sumX / double(nx) - (total - sumX) / double(n - nx); };
    const double observed = statistic(std::accumulate(x.begin(), x.end(), 0.0));
    const double atLeast = observed - std::abs(observed) * kPermutationTolerance;
    uint64_t asLarge = 0;
    if (const uint64_t splits = Binomial(n, nx); splits <= kExactPermutations) {
        // Every choice of nx of the n values as x, in lexicographic order of their indices.
        std::vector<size_t> chosen(nx);
        std::iota(chosen.begin(), chosen.end(), 0);
        for (uint64_t count = 0; count < splits; ++count) {
            double sumX = 0;
            for (size_t i : chosen) sumX += pooled[i];
            asLarge += statistic(sumX) >= atLeast;
            size_t i = nx;
            while (i > 0 && chosen[i - 1] == n - nx + i - 1) --i;
            if (i == 0) break;
            ++chosen[i - 1];
            for (size_t j = i; j < nx; ++j) chosen[j] = chosen[j - 1] + 1;
        }
        return PermutationP(asLarge, splits, true);
    }
    std::mt19937_64 rng(seed);
    for (int r = 0; r < permutations; ++r) {
        std::shuffle(pooled.begin(), pooled.end(), rng);
        asLarge += statistic(std::accumulate(pooled.begin(), pooled.begin() + std::ptrdiff_t(nx), 0.0)) >= atLeast;
    }
    return PermutationP(asLarge, uint64_t(permutations), false);
}

double SmallestSignFlipP(size_t pairs, int permutations) {
    if (pairs == 0) return 1;
    if (pairs <= kExactSignFlipPairs) return std::ldexp(1.0, -int(pairs));
    return 1 / double(permutations + 1);
}

double SmallestPermutationP(size_t nx, size_t ny, int permutations) {
    if (nx == 0 || ny == 0) return 1;
    const uint64_t splits = Binomial(nx + ny, nx);
    return splits <= kExactPermutations ? 1 / double(splits) : 1 / double(permutations + 1);
}

Interval BootstrapExpMean(std::span<const double> d, double confidence, int resamples, uint64_t seed) {
    if (d.empty() || resamples < 1) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {nan, nan};
    }
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<size_t> pick(0, d.size() - 1);
    std::vector<double> means;
    means.reserve(size_t(resamples));
    for (int r = 0; r < resamples; ++r) {
        double sum = 0;
        for (size_t i = 0; i < d.size(); ++i) sum += d[pick(rng)];
        means.push_back(std::exp(sum / double(d.size())));
    }
    std::sort(means.begin(), means.end());
    return {SortedQuantile(means, (1 - confidence) / 2), SortedQuantile(means, (1 + confidence) / 2)};
}

UTestResult MannWhitneyGreater(std::span<const double> x, std::span<const double> y) {
    const size_t n1 = x.size(), n2 = y.size(), n = n1 + n2;
    if (n1 == 0 || n2 == 0) return {};
    // Midranks of the pooled values; t^3 - t summed over each group of ties.
    std::vector<std::pair<double, bool>> pooled;  // value, from x
    pooled.reserve(n);
    for (double v : x) pooled.emplace_back(v, true);
    for (double v : y) pooled.emplace_back(v, false);
    std::sort(pooled.begin(), pooled.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    double rankSumX = 0, tieTerm = 0;
    for (size_t start = 0; start < n;) {
        size_t end = start;
        while (end < n && pooled[end].first == pooled[start].first) ++end;
        const double midrank = double(start + 1 + end) / 2;  // ranks start+1 .. end
        for (size_t i = start; i < end; ++i)
            if (pooled[i].second) rankSumX += midrank;
        const double t = double(end - start);
        tieTerm += t * t * t - t;
        start = end;
    }
    UTestResult r;
    r.u = rankSumX - double(n1) * double(n1 + 1) / 2;
    const double mu = double(n1) * double(n2) / 2;
    const double variance = double(n1) * double(n2) / 12 * (double(n + 1) - tieTerm / (double(n) * double(n - 1)));
    if (!(variance > 0)) return {r.u, 0, 1};
    r.z = (r.u - mu - 0.5) / std::sqrt(variance);
    r.p = std::clamp(0.5 * std::erfc(r.z / std::sqrt(2.0)), 0.0, 1.0);
    return r;
}

std::vector<double> HolmAdjusted(std::span<const double> p) {
    const size_t m = p.size();
    std::vector<size_t> order(m);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p[a] < p[b]; });
    std::vector<double> adjusted(m);
    double running = 0;  // the adjusted p-values never decrease along the order
    for (size_t rank = 0; rank < m; ++rank) {
        running = std::max(running, std::min(1.0, double(m - rank) * p[order[rank]]));
        adjusted[order[rank]] = running;
    }
    return adjusted;
}

Interval BootstrapRatioOfMedians(std::span<const double> base, std::span<const double> head, double confidence,
                                 int resamples, uint64_t seed) {
    if (base.empty() || head.empty() || resamples < 1) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {nan, nan};
    }
    std::mt19937_64 rng(seed);
    std::vector<double> ratios, b(base.size()), h(head.size());
    ratios.reserve(size_t(resamples));
    std::uniform_int_distribution<size_t> pickBase(0, base.size() - 1), pickHead(0, head.size() - 1);
    for (int r = 0; r < resamples; ++r) {
        for (double& v : b) v = base[pickBase(rng)];
        for (double& v : h) v = head[pickHead(rng)];
        ratios.push_back(MedianInPlace(h) / MedianInPlace(b));
    }
    std::sort(ratios.begin(), ratios.end());
    return {SortedQuantile(ratios, (1 - confidence) / 2), SortedQuantile(ratios, (1 + confidence) / 2)};
}

ChangePointSearch SearchChangePoints(std::span<const double> series, const ChangePointSettings& settings) {
    ChangePointSearch search;
    std::mt19937_64 rng(settings.seed);
    Segment(series, 0, settings, rng, search);
    return search;
}

std::vector<size_t> ChangePoints(std::span<const double> series, const ChangePointSettings& settings) {
    return SearchChangePoints(series, settings).points;
}

}  // namespace cb::perf
