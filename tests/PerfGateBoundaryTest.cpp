// The regression gate's decision rules at their boundaries (perf::Compare,
// harness/perf/Compare.h; the rules in docs/cli.md "perf compare" and
// docs/performance.md "The regression gate"): whether a row can be judged at
// all (its smallest reachable p times the Holm family against alpha), Holm's
// step-down, the sign-flip test's exact mode to 40 pairs and its draws at 41, the
// ratio thresholds and the floor. Every expected p-value is a hand count of
// sign patterns or splits (written out beside it); the boundaries that meet a
// computed ratio take the ratio the gate computed as the threshold itself, so
// that "exactly at" is exact, and check it against the hand value only to a
// tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "harness/perf/Compare.h"
#include "harness/perf/Stats.h"

namespace cb::perf {
namespace {

// C(n, k) as a double, for the hand counts below.
double GateChoose(int n, int k) {
    double c = 1;
    for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
    return c;
}

// The number of the 2^n sign patterns of n differences of +-1 with at most k negative: those whose sum is at
// least n - 2k.
double GateAtMostNegative(int n, int k) {
    double count = 0;
    for (int j = 0; j <= k; ++j) count += GateChoose(n, j);
    return count;
}

// An interleaved side pair: stage -> the head / base log-ratio of each round (base 1 ms, head exp(d) ms), one
// step a run, so each run's median is its one value.
struct GateRounds {
    Side base, head;
    void Add(const std::string& stage, const std::vector<double>& d, double baseMs = 1.0,
             const std::string& backend = "cpu") {
        for (size_t r = 0; r < d.size(); ++r) {
            base.runs["s"][backend][stage].push_back({int(r), {baseMs}});
            head.runs["s"][backend][stage].push_back({int(r), {baseMs * std::exp(d[r])}});
        }
    }
};

CompareSettings GateInterleaved(double alpha = 0.01) {
    CompareSettings s;
    s.interleaved = true;
    s.alpha = alpha;
    return s;
}

const Comparison& GateRow(const CompareOutcome& out, const std::string& stage, const std::string& backend = "cpu") {
    for (const Comparison& c : out.rows)
        if (c.stage == stage && c.backend == backend && c.metric == "time") return c;
    static const Comparison missing;
    ADD_FAILURE() << "no row " << backend << "/" << stage;
    return missing;
}

std::vector<double> GateSame(size_t n, double v) { return std::vector<double>(n, v); }

// Test the sign-flip test at the edge of its exact mode (kExactSignFlipPairs = 40): up to 40 pairs every pattern
// is counted, so p is a hand count over 2^n; at 41 the patterns are drawn, p = (1 + as large) / (1 + draws).
TEST(PerfGateBoundary, SignFlipExactTo40SampledAt41) {
    // All positive: only the observed pattern sums as high.
    for (int n : {16, 17, 25, 39, 40}) {
        EXPECT_EQ(SignFlipGreater(GateSame(size_t(n), 0.1), 999, 5), std::ldexp(1.0, -n)) << n << " pairs";
        EXPECT_EQ(SmallestSignFlipP(size_t(n), 999), std::ldexp(1.0, -n)) << n << " pairs";
    }
    EXPECT_EQ(SmallestSignFlipP(41, 999), 1.0 / 1000);
    // n differences of +-1, four of them -1: the observed sum n - 8 is reached by the patterns with at most four
    // negative, sum over j <= 4 of C(n, j): 3214 of 2^17 (the gate's 17 rounds), 15276 of 2^25, 92171 of 2^39,
    // 102091 of 2^40.
    const std::pair<int, double> counted[] = {{17, 3214}, {25, 15276}, {39, 92171}, {40, 102091}};
    for (auto [n, count] : counted) {
        std::vector<double> d(size_t(n), 1.0);
        for (int i = 0; i < 4; ++i) d[size_t(3 * i + 1)] = -1.0;
        EXPECT_EQ(GateAtMostNegative(n, 4), count) << n << " pairs";
        EXPECT_EQ(SignFlipGreater(d, 999, 5), count / std::ldexp(1.0, n)) << n << " pairs";
    }
    // Unequal magnitudes, where the two halves' sums must meet: {3, -1, 2, 5, -4} sums to 5, and a pattern sums
    // to 5 - 2 x (the values it flips), so it reaches 5 when those sum to at most 0: {}, {-1}, {-4}, {-1, -4},
    // {3, -4}, {2, -4}, {3, -1, -4}, {2, -1, -4}, {3, 2, -1, -4}, {5, -1, -4}: 10 of 32.
    EXPECT_EQ(SignFlipGreater(std::vector<double>{3, -1, 2, 5, -4}, 999, 5), 10.0 / 32);
}

// Test the met-in-the-middle count against every pattern summed in turn, the way it was counted before, on
// random differences of 1 to 20 pairs (log-ratios of a few percent, as the gate sees).
TEST(PerfGateBoundary, SignFlipHalvesCountAsEveryPattern) {
    std::mt19937 random(7);
    std::normal_distribution<double> logRatio(0.02, 0.1);
    for (int trial = 0; trial < 60; ++trial) {
        const size_t n = 1 + size_t(trial) % 20;
        std::vector<double> d(n);
        for (double& x : d) x = logRatio(random);
        const double observed = std::accumulate(d.begin(), d.end(), 0.0);
        uint64_t reach = 0;
        for (uint64_t signs = 0; signs < (uint64_t(1) << n); ++signs) {
            double sum = 0;
            for (size_t i = 0; i < n; ++i) sum += (signs >> i & 1) ? -d[i] : d[i];
            reach += sum >= observed - std::abs(observed) * 1e-14;
        }
        EXPECT_EQ(SignFlipGreater(d, 999, 5), double(reach) / std::ldexp(1.0, int(n))) << n << " pairs";
    }
}

// Test the promise of the rounds rule at the gate's default, 17 rounds for one 7-stage scene: a slowdown with two
// rounds against it is caught. Its p is 154 / 2^17 = 0.00117 (the patterns with at most two rounds negative,
// 1 + 17 + 136), and Holm's 7 x 0.00117 = 0.0082 < 0.01. Drawn from 9999 patterns, p was (1 + X) / 10000 with X
// binomial (9999, 0.00117), above 0.01 / 7 (X >= 14) with probability 0.29: the promise held only when counted.
TEST(PerfGateBoundary, TwoRoundsAgainstCaughtAtSeventeen) {
    GateRounds g;
    std::vector<double> d = GateSame(17, std::log(1.25));
    d[4] = d[11] = -std::log(1.25);
    g.Add("region", d);
    for (const char* quiet : {"ca", "density", "smooth", "shade", "shadow", "render_splat"})
        g.Add(quiet, GateSame(17, 0.0));
    const CompareOutcome out = Compare(g.base, g.head, GateInterleaved(0.01));
    const Comparison& c = GateRow(out, "region");
    EXPECT_EQ(c.pSlower, 154.0 / 131072.0);
    EXPECT_DOUBLE_EQ(c.pSlowerHolm, 7 * 154.0 / 131072.0);
    EXPECT_EQ(c.mark, '+') << c.note;
}

// Test the draws above the exact mode.
TEST(PerfGateBoundary, SignFlipSampledAt41) {
    // 41 pairs: drawn. Seventeen -1 of 41 reach the observed sum in sum over j <= 17 of C(41, j) of the 2^41
    // patterns, p = 0.1744; 9999 draws estimate it (standard error 0.0038) on the grid of 1/10000.
    std::vector<double> d41(41, 1.0);
    for (int i = 0; i < 17; ++i) d41[size_t(2 * i + 1)] = -1.0;
    const double p41 = SignFlipGreater(d41, 9999, 5);
    EXPECT_NEAR(p41, GateAtMostNegative(41, 17) / std::ldexp(1.0, 41), 5 * 0.0038);
    EXPECT_NEAR(p41 * 10000, std::round(p41 * 10000), 1e-6);
    // All positive at 41: no draw of 999 matches (each would with chance 2^-41), so p = 1 / 1000, not 2^-41.
    EXPECT_EQ(SignFlipGreater(GateSame(41, 0.1), 999, 5), 1.0 / 1000);
}

// Test the judgeable rule on the rounds test: a row is judged only when 2^-K x m < alpha (m the rows with a
// test); exactly at alpha it is '?', named as unjudged, and one ulp of alpha above it is judged. Between alpha / m
// and alpha, the raw smallest p would reach alpha but Holm's factor makes it unreachable: '?', not '~'.
TEST(PerfGateBoundary, RoundsJudgeableOnlyBelowAlphaOverHolmsFactor) {
    GateRounds g;
    g.Add("region", GateSame(7, std::log(1.5)));
    g.Add("ca", GateSame(7, std::log(1.5)));
    // 2^-7 = 0.0078 < 0.01 alone, but 2 x 2^-7 = 0.015625 >= 0.01.
    CompareOutcome out = Compare(g.base, g.head, GateInterleaved(0.01));
    for (const char* stage : {"region", "ca"}) {
        const Comparison& c = GateRow(out, stage);
        EXPECT_EQ(c.mark, '?') << stage << ": " << c.note;
        EXPECT_FALSE(c.regression);
        EXPECT_EQ(c.note, "cannot judge: 7 rounds cannot reach Holm-adjusted p < 0.01 over 2 tests");
        EXPECT_TRUE(std::isnan(c.pSlowerHolm));
    }
    EXPECT_EQ(out.Unjudged(), 2u);
    EXPECT_EQ(out.Regressions(), 0u);
    // Exactly at the boundary: 2 x 2^-7 = alpha is not below it.
    out = Compare(g.base, g.head, GateInterleaved(0.015625));
    EXPECT_EQ(GateRow(out, "region").mark, '?');
    EXPECT_EQ(out.Unjudged(), 2u);
    // Just above: judged, and every round slower gives p = 2^-7, Holm 2 x 2^-7 < alpha: a regression.
    out = Compare(g.base, g.head, GateInterleaved(std::nextafter(0.015625, 1.0)));
    for (const char* stage : {"region", "ca"}) {
        const Comparison& c = GateRow(out, stage);
        EXPECT_EQ(c.mark, '+') << stage << ": " << c.note;
        EXPECT_EQ(c.pSlower, std::ldexp(1.0, -7));
        EXPECT_EQ(c.pSlowerHolm, 0.015625);
        EXPECT_EQ(c.pFaster, 1.0);
        EXPECT_NEAR(c.ratio, 1.5, 1e-12);
    }
    EXPECT_EQ(out.Unjudged(), 0u);
    // One round more: 2 x 2^-8 < 0.01, judged at the default alpha.
    GateRounds eight;
    eight.Add("region", GateSame(8, std::log(1.5)));
    eight.Add("ca", GateSame(8, std::log(1.5)));
    out = Compare(eight.base, eight.head, GateInterleaved(0.01));
    EXPECT_EQ(GateRow(out, "region").mark, '+');
    EXPECT_EQ(GateRow(out, "ca").mark, '+');
}

// Test the judgeable rule at 40 rounds, the last exact count: 2^-40 x m against alpha. At 41 the draws' smallest
// p is 1 / (1 + 9999), so an alpha below it leaves the row '?' however the rounds agree.
TEST(PerfGateBoundary, FortyRoundsJudgedExactlyFortyOneDrawn) {
    GateRounds g;
    g.Add("region", GateSame(40, std::log(1.25)));
    const double smallest = std::ldexp(1.0, -40);
    CompareOutcome out = Compare(g.base, g.head, GateInterleaved(smallest));
    EXPECT_EQ(GateRow(out, "region").mark, '?');
    out = Compare(g.base, g.head, GateInterleaved(std::nextafter(smallest, 1.0)));
    const Comparison& c = GateRow(out, "region");
    EXPECT_EQ(c.mark, '+') << c.note;
    EXPECT_EQ(c.pSlower, smallest);
    EXPECT_EQ(c.pSlowerHolm, smallest);
    GateRounds drawn;
    drawn.Add("region", GateSame(41, std::log(1.25)));
    EXPECT_EQ(GateRow(Compare(drawn.base, drawn.head, GateInterleaved(1e-4)), "region").mark, '?');
    const Comparison& d = GateRow(Compare(drawn.base, drawn.head, GateInterleaved(std::nextafter(1e-4, 1.0))), "region");
    EXPECT_EQ(d.mark, '+') << d.note;
    EXPECT_EQ(d.pSlower, 1e-4);
}

// Test the judgeable rule on the runs test (sides not interleaved, several runs): its smallest p is 1 / C(n, |x|);
// 4 + 4 runs give 1 / 70, judged alone at alpha 0.02 but not with a second row (2 / 70 >= 0.02).
TEST(PerfGateBoundary, RunsJudgeableOnlyBelowAlphaOverHolmsFactor) {
    auto sides = [](int stages) {
        std::array<Side, 2> s;
        const char* names[] = {"region", "ca"};
        for (int st = 0; st < stages; ++st)
            for (int r = 0; r < 4; ++r) {
                s[0].runs["s"]["cpu"][names[st]].push_back({-1, {1.0 + 0.01 * r}});
                s[1].runs["s"]["cpu"][names[st]].push_back({-1, {3.0 + 0.01 * r}});
            }
        return s;
    };
    CompareSettings s;
    s.alpha = 0.02;
    auto one = sides(1);
    CompareOutcome out = Compare(one[0], one[1], s);
    const Comparison& alone = GateRow(out, "region");
    EXPECT_EQ(alone.test, "runs");
    EXPECT_EQ(alone.pSlower, 1.0 / 70);  // only the observed split puts the four largest in HEAD
    EXPECT_EQ(alone.mark, '+') << alone.note;
    auto two = sides(2);
    out = Compare(two[0], two[1], s);
    EXPECT_EQ(GateRow(out, "region").mark, '?');
    EXPECT_EQ(GateRow(out, "ca").mark, '?');
    EXPECT_EQ(GateRow(out, "ca").note, "cannot judge: 4 and 4 runs cannot reach Holm-adjusted p < 0.02 over 2 tests");
    // 3 + 3 runs: 1 / C(6, 3) = 0.05; exactly at alpha '?', just above judged.
    std::array<Side, 2> three;
    for (int r = 0; r < 3; ++r) {
        three[0].runs["s"]["cpu"]["region"].push_back({-1, {1.0 + 0.01 * r}});
        three[1].runs["s"]["cpu"]["region"].push_back({-1, {3.0 + 0.01 * r}});
    }
    s.alpha = 0.05;
    EXPECT_EQ(GateRow(Compare(three[0], three[1], s), "region").mark, '?');
    s.alpha = std::nextafter(0.05, 1.0);
    EXPECT_EQ(GateRow(Compare(three[0], three[1], s), "region").mark, '+');
}

// Steps a side, each value once; the median of 1.0 + 0.025 i for i in [0, n) with n even sits between two steps.
std::vector<RunSamples> GateSteps(size_t n, double offset) {
    RunSamples run;
    for (size_t i = 0; i < n; ++i) run.ms.push_back(offset + 0.75 + 0.5 * double(i) / double(n - 1));
    return {run};
}

// Test the steps test's boundary (one run a side): fewer than minSamples steps on a side cannot be tested ('?',
// and not one of Holm's family); minSamples can.
TEST(PerfGateBoundary, StepsNeedMinSamples) {
    CompareSettings s;
    s.separateThreshold = 1.2, s.threshold = 1.2;
    Side base, head;
    base.runs["s"]["cpu"]["region"] = GateSteps(20, 0);
    head.runs["s"]["cpu"]["region"] = GateSteps(19, 1.0);
    base.runs["s"]["cpu"]["ca"] = GateSteps(20, 0);
    head.runs["s"]["cpu"]["ca"] = GateSteps(20, 1.0);
    const CompareOutcome out = Compare(base, head, s);
    const Comparison& few = GateRow(out, "region");
    EXPECT_EQ(few.mark, '?');
    EXPECT_EQ(few.test, "steps");
    EXPECT_EQ(few.note, "cannot judge: one run a side with fewer than 20 samples");
    const Comparison& enough = GateRow(out, "ca");
    EXPECT_EQ(enough.mark, '+') << enough.note;
    // The '?' row is not in the family: ca's Holm p is its raw p (a family of one).
    EXPECT_EQ(enough.pSlowerHolm, enough.pSlower);
}

// Test Holm's step-down as the gate uses it: the p-values sorted, the k-th smallest times (m - k), never below an
// earlier one, capped at 1; significance on the adjusted p, not the raw one.
TEST(PerfGateBoundary, HolmStepDownOrder) {
    // Sorted 0.001 (x4 = 0.004), 0.002 (x3 = 0.006), 0.0035 (x2 = 0.007), 0.5 (x1); given out of order.
    std::vector<double> adjusted = HolmAdjusted(std::vector<double>{0.5, 0.0035, 0.001, 0.002});
    EXPECT_DOUBLE_EQ(adjusted[2], 0.004);
    EXPECT_DOUBLE_EQ(adjusted[3], 0.006);
    EXPECT_DOUBLE_EQ(adjusted[1], 0.007);
    EXPECT_DOUBLE_EQ(adjusted[0], 0.5);
    // Monotone: 0.01 x 3 = 0.03, then 0.011 x 2 = 0.022 is raised to 0.03; the cap: 0.6 x 1 -> 0.6, 0.4 x 3 -> 1.
    adjusted = HolmAdjusted(std::vector<double>{0.011, 0.01, 0.6});
    EXPECT_DOUBLE_EQ(adjusted[1], 0.03);
    EXPECT_DOUBLE_EQ(adjusted[0], 0.03);
    EXPECT_DOUBLE_EQ(adjusted[2], 0.6);
    adjusted = HolmAdjusted(std::vector<double>{0.4, 0.45, 0.9});
    EXPECT_EQ(adjusted, (std::vector<double>{1, 1, 1}));
    // Ties keep their order and both get the larger factor's running maximum.
    adjusted = HolmAdjusted(std::vector<double>{0.002, 0.002});
    EXPECT_DOUBLE_EQ(adjusted[0], 0.004);
    EXPECT_DOUBLE_EQ(adjusted[1], 0.004);

    // In the gate, three rows of 9 rounds (smallest p 2^-9, 3 x 2^-9 < 0.01: all judgeable).
    // region: every round slower, p = 1 / 512, Holm 3 / 512.
    // ca: seven rounds of +1 and two of -0.25 and -0.5: the observed sum 6.25 is reached by flipping either
    // negative, both, or none (flipping a +1 loses 2, more than the negatives can give back): p = 4 / 512 =
    // 0.0078 < 0.01 raw, but Holm's second factor makes it 2 x 4 / 512 = 0.0156: within no regression.
    // smooth: alternating signs, not significant, p far above.
    GateRounds g;
    g.Add("region", GateSame(9, 1.0));
    g.Add("ca", {1, 1, 1, 1, -0.25, 1, 1, 1, -0.5});
    g.Add("smooth", {1, -1, 1, -1, 1, -1, 1, -1, 0.5});
    const CompareOutcome out = Compare(g.base, g.head, GateInterleaved(0.01));
    const Comparison &region = GateRow(out, "region"), &ca = GateRow(out, "ca"), &smooth = GateRow(out, "smooth");
    EXPECT_EQ(region.pSlower, 1.0 / 512);
    EXPECT_EQ(ca.pSlower, 4.0 / 512);
    EXPECT_DOUBLE_EQ(region.pSlowerHolm, 3.0 / 512);
    EXPECT_DOUBLE_EQ(ca.pSlowerHolm, 8.0 / 512);
    EXPECT_GE(smooth.pSlowerHolm, ca.pSlowerHolm);
    EXPECT_EQ(region.mark, '+');
    EXPECT_EQ(ca.mark, '~') << ca.note;
    EXPECT_EQ(ca.note, "not significant");
    EXPECT_EQ(smooth.mark, '~');
    EXPECT_NEAR(ca.ratio, std::exp(6.25 / 9), 1e-12);
}

// Test the threshold: a significant slowdown whose ratio is exactly the threshold is within it ('~'), one whose
// ratio is above it by an ulp of the threshold is a regression; the same for an improvement at 1 / threshold.
TEST(PerfGateBoundary, RatioExactlyAtTheThreshold) {
    GateRounds g;
    g.Add("region", GateSame(10, std::log(1.1)));
    g.Add("ca", GateSame(10, -std::log(1.1)));
    CompareSettings s = GateInterleaved(0.01);
    const double slower = GateRow(Compare(g.base, g.head, s), "region").ratio;
    const double faster = GateRow(Compare(g.base, g.head, s), "ca").ratio;
    ASSERT_NEAR(slower, 1.1, 1e-12);
    ASSERT_NEAR(faster, 1 / 1.1, 1e-12);
    s.threshold = slower;  // ratio == threshold: not above it
    CompareOutcome out = Compare(g.base, g.head, s);
    EXPECT_EQ(GateRow(out, "region").mark, '~');
    EXPECT_EQ(GateRow(out, "region").note, "significant, within the threshold");
    EXPECT_EQ(GateRow(out, "region").threshold, slower);
    s.threshold = std::nextafter(slower, 0.0);  // ratio just above
    out = Compare(g.base, g.head, s);
    EXPECT_EQ(GateRow(out, "region").mark, '+');
    EXPECT_TRUE(GateRow(out, "region").regression);
    // An improvement needs ratio < 1 / threshold: the threshold whose reciprocal is the ratio exactly leaves it
    // within, one ulp lower makes it an improvement.
    double atFaster = NAN;
    for (double t = std::nextafter(std::nextafter(1 / faster, 0.0), 0.0), k = 0; k < 5; ++k, t = std::nextafter(t, 2.0))
        if (1 / t == faster) atFaster = t;
    if (1 / atFaster == faster) {
        s.threshold = atFaster;
        EXPECT_EQ(GateRow(Compare(g.base, g.head, s), "ca").mark, '~');
        double below = std::nextafter(atFaster, 0.0);
        while (!(faster < 1 / below)) below = std::nextafter(below, 0.0);
        s.threshold = below;
        EXPECT_EQ(GateRow(Compare(g.base, g.head, s), "ca").mark, '-');
    }
    s.threshold = 1.05;
    out = Compare(g.base, g.head, s);
    EXPECT_EQ(GateRow(out, "ca").mark, '-');
    EXPECT_EQ(GateRow(out, "ca").note, "improvement");
    EXPECT_FALSE(GateRow(out, "ca").regression);
    s.threshold = 1.2;
    out = Compare(g.base, g.head, s);
    EXPECT_EQ(GateRow(out, "ca").mark, '~');
    EXPECT_EQ(GateRow(out, "region").mark, '~');
}

// Test the per-backend thresholds and the separate threshold: interleaved, each backend has its own (gl and vk 3x
// by default, --threshold BACKEND=R); not interleaved, the larger of its own and --separate-threshold.
TEST(PerfGateBoundary, BackendAndSeparateThresholds) {
    CompareSettings s;
    s.interleaved = true;
    EXPECT_EQ(ThresholdOf(s, "cpu"), 1.1);
    EXPECT_EQ(ThresholdOf(s, "gl"), 3.0);
    EXPECT_EQ(ThresholdOf(s, "vk"), 3.0);
    s.interleaved = false;
    EXPECT_EQ(ThresholdOf(s, "cpu"), 2.0);
    EXPECT_EQ(ThresholdOf(s, "gl"), 3.0);
    s.separateThreshold = 1.05;
    EXPECT_EQ(ThresholdOf(s, "cpu"), 1.1);
    s.separateThreshold = 3.5;
    EXPECT_EQ(ThresholdOf(s, "gl"), 3.5);

    // 2.5x on cpu and gl, interleaved: a regression on cpu only; --threshold gl=2.4 makes it one on gl.
    GateRounds g;
    g.Add("region", GateSame(10, std::log(2.5)), 1.0, "cpu");
    g.Add("region", GateSame(10, std::log(2.5)), 1.0, "gl");
    CompareSettings t = GateInterleaved(0.01);
    CompareOutcome out = Compare(g.base, g.head, t);
    EXPECT_EQ(GateRow(out, "region", "cpu").mark, '+');
    EXPECT_EQ(GateRow(out, "region", "gl").mark, '~');
    EXPECT_EQ(GateRow(out, "region", "gl").threshold, 3.0);
    t.backendThreshold["gl"] = 2.4;
    out = Compare(g.base, g.head, t);
    EXPECT_EQ(GateRow(out, "region", "gl").mark, '+');
    // The ratio itself as gl's threshold: within it.
    t.backendThreshold["gl"] = GateRow(out, "region", "gl").ratio;
    EXPECT_EQ(GateRow(Compare(g.base, g.head, t), "region", "gl").mark, '~');

    // Not interleaved, 4 + 4 runs 1.5x apart, p = 1 / 70: within the separate 2x, a regression at 1.4.
    Side base, head;
    for (int r = 0; r < 4; ++r) {
        base.runs["s"]["cpu"]["region"].push_back({-1, {1.0 + 0.01 * r}});
        head.runs["s"]["cpu"]["region"].push_back({-1, {1.5 * (1.0 + 0.01 * r)}});
    }
    CompareSettings separate;
    separate.alpha = 0.02;
    EXPECT_EQ(GateRow(Compare(base, head, separate), "region").mark, '~');
    EXPECT_EQ(GateRow(Compare(base, head, separate), "region").threshold, 2.0);
    separate.separateThreshold = 1.4;
    EXPECT_EQ(GateRow(Compare(base, head, separate), "region").mark, '+');
    separate.separateThreshold = 1.0;  // the default 1.1 is then the larger
    EXPECT_EQ(GateRow(Compare(base, head, separate), "region").threshold, 1.1);
}

// Test the floor (one run a side only): medians that differ by exactly --floor are under it ('~'), by an ulp more a
// regression; the runs and rounds tests have no floor.
TEST(PerfGateBoundary, FloorOnTheStepsTestOnly) {
    Side base, head;
    base.runs["s"]["cpu"]["region"] = GateSteps(20, 0);    // median 1.0
    head.runs["s"]["cpu"]["region"] = GateSteps(20, 0.5);  // median 1.5
    CompareSettings s;
    s.threshold = 1.2, s.separateThreshold = 1.2;
    const Comparison first = GateRow(Compare(base, head, s), "region");
    ASSERT_EQ(first.test, "steps");
    ASSERT_LT(first.pSlower, 1e-6);
    const double difference = first.headMedian - first.baseMedian;
    ASSERT_NEAR(difference, 0.5, 1e-12);
    s.floorMs = difference;
    Comparison c = GateRow(Compare(base, head, s), "region");
    EXPECT_EQ(c.mark, '~');
    EXPECT_EQ(c.note, "significant, under the floor");
    s.floorMs = std::nextafter(difference, 0.0);
    c = GateRow(Compare(base, head, s), "region");
    EXPECT_EQ(c.mark, '+');
    // The other way: an improvement by exactly the floor is not one.
    s.floorMs = difference;
    EXPECT_EQ(GateRow(Compare(head, base, s), "region").mark, '~');
    s.floorMs = std::nextafter(difference, 0.0);
    EXPECT_EQ(GateRow(Compare(head, base, s), "region").mark, '-');

    // Rounds of 0.001 ms against 0.002 ms: far under the default 0.05 ms floor, still a regression.
    GateRounds g;
    g.Add("region", GateSame(10, std::log(2.0)), 0.001);
    const Comparison& tiny = GateRow(Compare(g.base, g.head, GateInterleaved(0.01)), "region");
    EXPECT_EQ(tiny.mark, '+') << tiny.note;
}

// Test that a stage with no sample in either build (one that ran in warm-up steps only) has no row and is no failure
// of HEAD's, while one that lost its samples in HEAD alone is.
TEST(PerfGateBoundary, AStageTimedInNeitherBuildIsNoRow) {
    GateRounds g;
    g.Add("region", GateSame(10, 0.0));
    g.base.runs["s"]["cpu"]["noise"].push_back({0, {}});
    g.head.runs["s"]["cpu"]["noise"].push_back({0, {}});
    CompareOutcome out = Compare(g.base, g.head, GateInterleaved(0.01));
    EXPECT_EQ(std::count_if(out.rows.begin(), out.rows.end(), [](const Comparison& c) { return c.stage == "noise"; }),
              0);
    EXPECT_FALSE(out.headFailed);
    g.base.runs["s"]["cpu"]["noise"][0].ms = {1.0};
    out = Compare(g.base, g.head, GateInterleaved(0.01));
    EXPECT_EQ(GateRow(out, "noise").mark, 'x');
    EXPECT_TRUE(out.headFailed);
}

// Test the marks a time row can have and what the outcome counts: + (regression), - (improvement), ~, ? (unjudged,
// counted apart), x (HEAD failed or lacks the stage: headFailed) and ! (new in HEAD).
TEST(PerfGateBoundary, EveryMark) {
    GateRounds g;
    g.Add("region", GateSame(10, std::log(2.0)));
    g.Add("ca", GateSame(10, -std::log(2.0)));
    g.Add("smooth", {0.1, -0.1, 0.1, -0.1, 0.1, -0.1, 0.1, -0.1, 0.1, -0.1});
    g.base.runs["s"]["cpu"]["density"].push_back({0, {1.0}});  // only in BASE: x
    g.head.runs["s"]["cpu"]["shade"].push_back({0, {1.0}});    // only in HEAD: !
    CompareOutcome out = Compare(g.base, g.head, GateInterleaved(0.01));
    EXPECT_EQ(GateRow(out, "region").mark, '+');
    EXPECT_EQ(GateRow(out, "ca").mark, '-');
    EXPECT_EQ(GateRow(out, "smooth").mark, '~');
    EXPECT_EQ(GateRow(out, "density").mark, 'x');
    EXPECT_EQ(GateRow(out, "density").note, "no samples in HEAD");
    EXPECT_EQ(GateRow(out, "shade").mark, '!');
    EXPECT_EQ(out.Regressions(), 1u);
    EXPECT_TRUE(out.headFailed);
    EXPECT_EQ(out.Unjudged(), 0u);
    // HEAD's backend failed: every stage of it x, with the reason.
    g.head.failures["s"]["cpu"] = "crashed";
    out = Compare(g.base, g.head, GateInterleaved(0.01));
    EXPECT_EQ(GateRow(out, "region").mark, 'x');
    EXPECT_EQ(GateRow(out, "region").note, "HEAD: crashed");
    EXPECT_EQ(out.Regressions(), 0u);
    // With 3 tested rows (+, -, ~ above), 10 rounds: 3 x 2^-10 < 0.01. At alpha = 3 x 2^-10 all three are '?'.
    g.head.failures.clear();
    out = Compare(g.base, g.head, GateInterleaved(3 * std::ldexp(1.0, -10)));
    EXPECT_EQ(out.Unjudged(), 3u);
    EXPECT_EQ(out.Regressions(), 0u);
}

}  // namespace
}  // namespace cb::perf
