// SPEC 12, "Numerical stability at the extremes": the soak (Spec12Soak),
// 10,000 automaton steps per backend with the cover held in a band derived
// from the automaton's rules, and RSS after step 100 and step 10,000. The
// items are in tests/Spec12ExtremesTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/math/Random.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/Spec12Outputs.h"
#include "tests/TestUtil.h"

namespace cb::spec12_test {

// VmRSS of this process in KiB (0 where /proc is missing).
uint64_t ResidentKiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6));
    return 0;
}

// P_x of SPEC 3.2 for region weight R: (R Q + 127) / 255, uint32.
uint32_t RegionProbability(uint32_t R, uint32_t Q) { return (R * Q + 127) / 255; }

constexpr uint32_t kSoakSteps = 10000;

class Spec12Soak : public ::testing::TestWithParam<std::string> {};

// Test 10,000 automaton steps (SPEC 12) on a 32 x 32 x 8 grid with ci-small's
// probabilities and its ellipsoids scaled to the grid, stages region and ca
// (smooth and density tripled gl's time; their cover is tested by the
// items), the cover counted from the downloaded cld every step. The band is
// derived from SPEC 3, pathwise (no statistics, so it cannot flake), for
// every step t:
//
// Upper: step 3 ends with cld2 = cld2 & (R > 0) and there is no wind shift, so
//   cld_t lies inside R_{t-1} > 0 and cover_t <= the columns with any R_{t-1} > 0.
// Lower: strip the automaton of growth. act2 = act1 | [rand24(seed,t,2,v) < P_act]
//   holds the spontaneous activations whatever the state, and
//   cld_{t+1} = (cld_t | act_t) & !ext & (R_t > 0) is monotone in cld_t and
//   act_t, with the extinction draws fixed by (seed, t, v). So a host automaton
//   with only those draws, act'_{t+1} = [rand24(seed,t,2,v) < P_act(R_t)],
//   cld'_{t+1} = (cld'_t | act'_t) & !ext_t & (R_t > 0), from the same act_0
//   and cld_0 = 0, stays inside the real one step after step (induction), and
//   cover_t >= the columns with any cld'_t.
// Memory must stay flat: RSS after step 10,000 at most 32 MiB above step 100
// (a leak of 4 KiB per step would exceed it).
TEST_P(Spec12Soak, TenThousandStepsCoverInBandMemoryFlat) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    auto scene = LoadScene(
        std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
        {{"grid.size", "[32, 32, 8]"},
         {"steps", std::to_string(kSoakSteps)},
         {"warmup_steps", "0"},
         {"stages", R"(["region", "ca"])"},
         {"ellipsoids.size_mean", "[5, 5, 2.5]"},
         {"ellipsoids.size_variance", "[1.5, 1.5, 0.5]"},
         {"ellipsoids.margin", "4"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const Extent3 e = scene->grid.size;
    const uint32_t seed = scene->ca.seed, columns = e.nx * e.ny;
    const uint32_t qExt = QuantizeProbability(scene->ca.pExt), qAct = QuantizeProbability(scene->ca.pAct);
    ASSERT_TRUE(scene->ca.windShift.empty() || !scene->ca.HasWind()) << "the upper bound assumes no advection";
    auto sim = Simulation::Create(*scene, *backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;

    std::vector<uint8_t> act(e.Count()), cld(e.Count(), 0), supportPrev;  // the growth-free automaton
    for (uint32_t v = 0; v < act.size(); ++v)
        act[v] = Rand24(seed, kInitialStateStep, 2, v) < QuantizeProbability(scene->ca.act0);
    auto coveredBy = [&](const std::vector<uint8_t>& field) {
        uint32_t n = 0;
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                bool any = false;
                for (uint32_t k = 0; k < e.nz && !any; ++k) any = field[VoxelIndex(e, i, j, k)] != 0;
                n += any;
            }
        return n;
    };
    uint32_t minCover = columns, maxCover = 0, outside = 0;
    double sumCover = 0, sumLower = 0, sumUpper = 0;
    uint64_t rss100 = 0;
    const auto start = std::chrono::steady_clock::now();
    for (uint32_t t = 0; t < kSoakSteps; ++t) {
        StepRecord record;
        std::vector<uint8_t> R, cldNow;
        const Status status = (*sim)->Step(record, [&](const Simulation& s) -> Status {
            R = test::Read<uint8_t>(*backend, *s.Region());
            cldNow = test::Read<uint8_t>(*backend, *s.Cld());
            return {};
        });
        ASSERT_TRUE(status.has_value()) << "step " << t << ": " << status.error().message;
        const uint32_t cover = coveredBy(cldNow);
        const uint32_t lower = coveredBy(cld), upper = t == 0 ? 0 : coveredBy(supportPrev);
        if (cover < lower || cover > upper) {
            if (outside++ < 5) ADD_FAILURE() << "step " << t << ": cover " << cover << " outside [" << lower << ", " << upper << "]";
        }
        minCover = std::min(minCover, cover), maxCover = std::max(maxCover, cover);
        sumCover += cover, sumLower += lower, sumUpper += upper;
        // Advance the growth-free automaton with R_t, and keep R_t > 0 for the next step's upper bound.
        supportPrev.assign(R.size(), 0);
        for (uint32_t v = 0; v < R.size(); ++v) {
            const bool extinct = Rand24(seed, t, 0, v) < RegionProbability(255 - R[v], qExt);
            const bool nextCld = (cld[v] || act[v]) && !extinct && R[v] > 0;
            act[v] = R[v] > 0 && Rand24(seed, t, 2, v) < RegionProbability(R[v], qAct);
            cld[v] = nextCld;
            supportPrev[v] = R[v] > 0;
        }
        if (t + 1 == 100) rss100 = ResidentKiB();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const uint64_t rssEnd = ResidentKiB();
    EXPECT_EQ(outside, 0u) << "steps with the cover outside its band";
    EXPECT_GT(sumLower, 0.0) << "the lower bound never rose above 0: the band proves nothing";
    EXPECT_LE(rssEnd, rss100 + 32 * 1024) << "RSS grew from " << rss100 << " KiB at step 100 to " << rssEnd << " KiB";
    std::printf("soak %s: %u steps of %ux%ux%u in %.1f s; RSS %llu KiB after step 100, %llu KiB after step %u; "
                "cover min %.4f max %.4f mean %.4f (band means: lower %.4f, upper %.4f)\n",
                GetParam().c_str(), kSoakSteps, e.nx, e.ny, e.nz, seconds, (unsigned long long)rss100,
                (unsigned long long)rssEnd, kSoakSteps, minCover / double(columns), maxCover / double(columns),
                sumCover / kSoakSteps / columns, sumLower / kSoakSteps / columns, sumUpper / kSoakSteps / columns);
}

INSTANTIATE_TEST_SUITE_P(Backends, Spec12Soak, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace cb::spec12_test
