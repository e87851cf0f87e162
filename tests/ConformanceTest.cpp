// Stage-isolated conformance (SPEC's comparison rules): every backend's stage
// is fed exactly the inputs the CPU reference gets, and the outputs are
// compared by the stage's rule. Written once, instantiated for every backend;
// a backend that cannot start here is skipped with the reason.
// The simulation stages here; ConformanceRenderTest.cpp has shade, shadow, the
// splat renderer and the whole pipeline, and shares this instantiation.
#include <gtest/gtest.h>

#include "core/plan/StageGraph.h"
#include "tests/BackendTestUtil.h"
#include "tests/ConformanceFixture.h"

namespace cb::conformance {
namespace {

// Test region: |dR| <= 1 everywhere and at most 0.5 % of voxels differ (SPEC 2).
TEST_P(Conformance, Region) {
    if (auto why = SkipReason(Stage::Region)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    const std::vector<RasterEllipsoid> list = test::RandomEllipsoids(e, 3);
    auto ref = test::MakeBuffer(mCpu, BufferFormat::U8, e);
    auto got = test::MakeBuffer(*mBackend, BufferFormat::U8, e);
    ASSERT_TRUE(mCpu.Region(list, *ref));
    Status s = mBackend->Region(list, *got);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    const auto a = test::Read<uint8_t>(mCpu, *ref), b = test::Read<uint8_t>(*mBackend, *got);
    size_t differ = 0, worst = 0;
    int worstDelta = 0;
    for (size_t v = 0; v < a.size(); ++v) {
        const int d = std::abs(int(a[v]) - int(b[v]));
        differ += d != 0;
        if (d > worstDelta) worstDelta = d, worst = v;
    }
    EXPECT_LE(worstDelta, 1) << "worst at " << Where(e, worst) << ": cpu " << +a[worst] << ", " << mBackend->Name()
                             << " " << +b[worst];
    EXPECT_LE(double(differ), 0.005 * double(a.size())) << differ << " voxels differ";
}

// Test the automaton: the initial state, then steps each fed the CPU's state
// and region, with and without wind, bit for bit (SPEC 3).
TEST_P(Conformance, CaSteps) {
    if (auto why = SkipReason(Stage::Ca)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    const uint32_t seed = 11;
    CaInitParams init{seed, QuantizeProbability(0.4), QuantizeProbability(0.02)};
    std::unique_ptr<Buffer> ref[3], got[3], refOut[3], gotOut[3];
    for (int f = 0; f < 3; ++f) {
        ref[f] = test::MakeBuffer(mCpu, BufferFormat::Bits, e);
        refOut[f] = test::MakeBuffer(mCpu, BufferFormat::Bits, e);
        got[f] = test::MakeBuffer(*mBackend, BufferFormat::Bits, e);
        gotOut[f] = test::MakeBuffer(*mBackend, BufferFormat::Bits, e);
    }
    ASSERT_TRUE(mCpu.CaInitialize(init, {ref[0].get(), ref[1].get(), ref[2].get()}));
    Status s = mBackend->CaInitialize(init, {got[0].get(), got[1].get(), got[2].get()});
    ASSERT_TRUE(s.has_value()) << s.error().message;
    const char* names[3] = {"hum", "act", "cld"};
    for (int f = 0; f < 3; ++f)
        ExpectExact(test::Read<uint8_t>(mCpu, *ref[f]), test::Read<uint8_t>(*mBackend, *got[f]), e, names[f]);

    std::vector<RasterEllipsoid> list = test::RandomEllipsoids(e, 5);
    auto region = test::MakeBuffer(mCpu, BufferFormat::U8, e);
    std::vector<int32_t> sx(e.nz), sy(e.nz);
    for (uint32_t k = 0; k < e.nz; ++k) sx[k] = int32_t(k % 5) - 2, sy[k] = k % 3 == 0 ? 1 : -int32_t(k % 2);
    for (uint32_t t = 0; t < 8; ++t) {
        const bool wind = t % 2 == 1;
        ASSERT_TRUE(mCpu.Region(list, *region));
        const std::vector<uint8_t> r = test::Read<uint8_t>(mCpu, *region);
        auto gotRegion = test::MakeFilled(*mBackend, BufferFormat::U8, e, r);
        // The backend starts from the CPU's state (stage isolation).
        for (int f = 0; f < 3; ++f) {
            const std::vector<uint8_t> state = test::Read<uint8_t>(mCpu, *ref[f]);
            ASSERT_TRUE(mBackend->Upload(*got[f], std::as_bytes(std::span(state))));
        }
        CaStepParams p{seed, t, QuantizeProbability(0.2), QuantizeProbability(0.1), QuantizeProbability(0.05), {},
                       {},   {}};
        if (wind) p.shiftX = sx, p.shiftY = sy;
        ASSERT_TRUE(mCpu.CaStep(p, {ref[0].get(), ref[1].get(), ref[2].get()}, *region,
                                {refOut[0].get(), refOut[1].get(), refOut[2].get()}));
        s = mBackend->CaStep(p, {got[0].get(), got[1].get(), got[2].get()}, *gotRegion,
                             {gotOut[0].get(), gotOut[1].get(), gotOut[2].get()});
        ASSERT_TRUE(s.has_value()) << s.error().message;
        for (int f = 0; f < 3; ++f) {
            SCOPED_TRACE("step " + std::to_string(t) + (wind ? " with wind" : ""));
            ExpectExact(test::Read<uint8_t>(mCpu, *refOut[f]), test::Read<uint8_t>(*mBackend, *gotOut[f]), e, names[f]);
            std::swap(ref[f], refOut[f]);
        }
        for (RasterEllipsoid& el : list) el.center[0] += 0.7f;
    }
}

// Test smoothing with r = 0, 1, 2 on a random field, bit for bit (SPEC 4).
TEST_P(Conformance, Smooth) {
    if (auto why = SkipReason(Stage::Smooth)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(7);
    std::vector<uint8_t> cld(e.Count());
    for (uint8_t& c : cld) c = rng.Below(3) == 0;
    auto refBits = test::MakeFilled(mCpu, BufferFormat::Bits, e, cld);
    auto gotBits = test::MakeFilled(*mBackend, BufferFormat::Bits, e, cld);
    for (int radius : {0, 1, 2}) {
        auto ref = test::MakeBuffer(mCpu, BufferFormat::F32, e);
        auto got = test::MakeBuffer(*mBackend, BufferFormat::F32, e);
        ASSERT_TRUE(mCpu.Smooth(radius, *refBits, *ref));
        Status s = mBackend->Smooth(radius, *gotBits, *got);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        SCOPED_TRACE("radius " + std::to_string(radius));
        ExpectExact(test::Read<float>(mCpu, *ref), test::Read<float>(*mBackend, *got), e, "q");
    }
}

// The settings the noise test runs: each basis, with detail, towers, coverage
// and drift on and off (SPEC 10a).
std::vector<std::pair<std::string, NoiseSettings>> NoiseVariants(const Extent3& e) {
    std::vector<std::pair<std::string, NoiseSettings>> v;
    NoiseSettings plain;  // Perlin, frequency (4, 4, 2), 5 octaves, threshold, nothing else
    v.emplace_back("perlin plain", plain);
    NoiseSettings perlin = plain;
    perlin.seed = 11;
    perlin.towers = {{{e.nx * 0.5, e.ny * 0.5, e.nz * 0.25}, {3, 3, 5}, 0.4}, {{0.5, e.ny - 1.0, 1}, {2, 4, 3}, 0.3}};
    perlin.detail.enabled = true;
    perlin.detail.size = 8, perlin.detail.frequency = 2, perlin.detail.fbm.octaves = 2;
    perlin.drift = {0.5, 0.25, -0.3};
    v.emplace_back("perlin towers detail drift", perlin);
    NoiseSettings simplex = plain;
    simplex.seed = 5;
    simplex.frequency = {3, 3, 3};
    simplex.fbm = {NoiseBasis::Simplex, 4, 0.5, 2, true};
    simplex.coverage.enabled = true;
    simplex.drift = {-1.25, 0.75, 0.5};
    v.emplace_back("simplex turbulence coverage drift", simplex);
    NoiseSettings worley = plain;
    worley.seed = 9;
    worley.fbm = {NoiseBasis::Worley, 3, 0.5, 2, false};
    worley.towers = {{{e.nx * 0.25, e.ny * 0.75, 2}, {4, 4, 4}, 0.5}};
    worley.detail.enabled = true;
    worley.detail.fbm = {NoiseBasis::Perlin, 2, 0.5, 2, false};
    worley.coverage.enabled = true, worley.coverage.coverage = 0.8, worley.coverage.density = 2;
    v.emplace_back("worley towers detail coverage", worley);
    NoiseSettings all = perlin;
    all.fbm.lacunarity = 3, all.fbm.gain = 0.6, all.fbm.octaves = 3;
    all.coverage.enabled = true, all.coverage.frequency = {3, 1};
    all.detail.strength = 0.5;
    v.emplace_back("perlin lacunarity 3 everything", all);
    return v;
}

// Test the noise stage: |dq| <= 1e-5 against the CPU (SPEC 10a, core/stages/noise/Noise.cpp), steps 0 and 5.
TEST_P(Conformance, Noise) {
    if (auto why = SkipReason(Stage::Noise)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    for (const auto& [name, settings] : NoiseVariants(e)) {
        for (uint32_t step : {0u, 5u}) {
            SCOPED_TRACE(name + ", step " + std::to_string(step));
            const NoiseParams params{step, &settings, e};
            auto ref = test::MakeBuffer(mCpu, BufferFormat::F32, e);
            auto got = test::MakeBuffer(*mBackend, BufferFormat::F32, e);
            ASSERT_TRUE(mCpu.Noise(params, *ref));
            Status s = mBackend->Noise(params, *got);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            const std::vector<float> a = test::Read<float>(mCpu, *ref), b = test::Read<float>(*mBackend, *got);
            size_t worst = 0;
            float worstError = 0, sum = 0;
            for (size_t n = 0; n < a.size(); ++n) {
                sum += a[n];
                const float d = std::fabs(a[n] - b[n]);
                if (!(d <= worstError)) worstError = d, worst = n;
            }
            EXPECT_LE(worstError, Describe(Stage::Noise).rule(Scene{}).tolerance)
                << "at " << Where(e, worst) << ": cpu " << a[worst] << ", " << mBackend->Name() << " " << b[worst];
            if (e.nx > 1) {
                EXPECT_GT(sum, 0.0f) << "the variant forms no cloud: a weak test";
            }
        }
    }
}

// Test the density stage: D, tiles, bands and cover, bit for bit (SPEC 5).
TEST_P(Conformance, Density) {
    if (auto why = SkipReason(Stage::Density)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(13);
    std::vector<uint8_t> cld(e.Count());
    for (uint8_t& c : cld) c = rng.Below(9) == 0;
    auto refBits = test::MakeFilled(mCpu, BufferFormat::Bits, e, cld);
    auto q = test::MakeBuffer(mCpu, BufferFormat::F32, e);
    ASSERT_TRUE(mCpu.Smooth(1, *refBits, *q));
    const std::vector<float> qData = test::Read<float>(mCpu, *q);
    const DensityParams params{8, 4, {}};
    ExpectDensityMatches(params, e, qData, &cld);
    ExpectDensityMatches(params, e, qData, nullptr);  // without an automaton the cover counts columns with D > 0
}

// Tiles of 32 x 32 columns (more columns than a Vulkan workgroup has
// invocations; partial tiles at the odd sizes) and 70 slices in bands of 1
// (70 bands: more than one 32-band word of flags) and of 3 (a partial last
// band). q mixes dense slices (every 5th: many terms per column, so the sum's
// order shows in its rounding) with sparse ones (most tile x band boxes empty).
TEST_P(Conformance, DensityLargeTilesAndManyBands) {
    if (auto why = SkipReason(Stage::Density)) GTEST_SKIP() << *why;
    const Extent3 e{Size().nx, Size().ny, 70};
    Pcg32 rng(29);
    std::vector<float> qData(e.Count(), 0.0f);
    std::vector<uint8_t> cld(e.Count());
    for (size_t v = 0; v < qData.size(); ++v) {
        const size_t k = v / (size_t(e.nx) * e.ny);
        if (rng.Below(k % 5 == 0 ? 2 : 2000) == 0) qData[v] = float(rng.NextU32() >> 8) * 0x1p-24f;
        cld[v] = rng.Below(50) == 0;
    }
    for (const uint32_t band : {1u, 3u}) {
        SCOPED_TRACE("band " + std::to_string(band));
        const DensityParams params{32, band, {}};
        const std::vector<uint8_t> refBands = ExpectDensityMatches(params, e, qData, &cld);
        if (band == 1) {  // the data holds both empty and occupied boxes
            EXPECT_NE(std::count(refBands.begin(), refBands.end(), 0), 0);
            EXPECT_NE(std::count(refBands.begin(), refBands.end(), 1), 0);
        }
        ExpectDensityMatches(params, e, qData, nullptr);
    }
}

std::vector<BackendVariant> AllBackends() {
    std::vector<BackendVariant> variants;
    for (const std::string& name : test::TestBackendsAndCaLayouts()) {
        const test::TestBackendSetup setup = test::SetupOf(name);
        variants.push_back({setup.backend, setup.options});
    }
    return variants;
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Stages, Conformance,
                         ::testing::Combine(::testing::ValuesIn(AllBackends()),
                                            ::testing::Values(SizeCase{"Small64x64x16", {64, 64, 16}},
                                                              SizeCase{"Odd70x33x17", {70, 33, 17}},
                                                              SizeCase{"Thin1x1x9", {1, 1, 9}})),
                         [](const ::testing::TestParamInfo<Param>& info) {
                             return std::string(std::get<1>(info.param).name) + "_" + std::get<0>(info.param).Label();
                         });

}  // namespace cb::conformance
