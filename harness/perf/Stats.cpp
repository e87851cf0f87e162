#include "harness/perf/Stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace cb::perf {
namespace {

// NumPy's default quantile: linear interpolation between order statistics.
double Quantile(std::vector<double>& sorted, double q) {
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

void Segment(std::span<const double> series, size_t offset, const ChangePointSettings& s, std::mt19937_64& rng,
             std::vector<size_t>& found) {
    const auto [split, statistic] = BestSplit(series, s.minSegment);
    if (statistic < 0) return;
    const std::span<const double> left = series.first(split), right = series.subspan(split);
    if (std::abs(Median(right) - Median(left)) < s.minChange) return;
    std::vector<double> shuffled(series.begin(), series.end());
    int asLarge = 0;
    for (int n = 0; n < s.permutations; ++n) {
        std::shuffle(shuffled.begin(), shuffled.end(), rng);
        if (BestSplit(shuffled, s.minSegment).second >= statistic) ++asLarge;
    }
    const double p = double(1 + asLarge) / double(1 + s.permutations);
    if (p > s.alpha) return;
    Segment(left, offset, s, rng, found);
    found.push_back(offset + split);
    Segment(right, offset + split, s, rng, found);
}

}  // namespace

double Median(std::span<const double> values) {
    std::vector<double> copy(values.begin(), values.end());
    return MedianInPlace(copy);
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
    return {Quantile(ratios, (1 - confidence) / 2), Quantile(ratios, (1 + confidence) / 2)};
}

std::vector<size_t> ChangePoints(std::span<const double> series, const ChangePointSettings& settings) {
    std::vector<size_t> found;
    std::mt19937_64 rng(settings.seed);
    Segment(series, 0, settings, rng, found);
    return found;
}

}  // namespace cb::perf
