// Stage-isolated conformance (SPEC's comparison rules): every backend's stage
// is fed exactly the inputs the CPU reference gets, and the outputs are
// compared by the stage's rule. Written once, instantiated for every backend;
// a backend that cannot start here is skipped with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <tuple>

#include "core/Ellipsoids.h"
#include "core/Random.h"
#include "core/Scene.h"
#include "harness/Report.h"
#include "harness/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb {
namespace {

struct SizeCase {
    const char* name;
    Extent3 size;
};
void PrintTo(const SizeCase& c, std::ostream* os) { *os << c.name; }

// A backend under test: its name and the options it is made with.
struct BackendVariant {
    std::string backend;
    BackendOptions options;
    // The name in test names: the backend, then any non-default automaton layout ("gl_rgba8").
    std::string Label() const {
        if (options.glCaLayout == gl::CaLayout::Packed) return backend;
        return backend + "_" + std::string(gl::CaLayoutName(options.glCaLayout));
    }
};
void PrintTo(const BackendVariant& v, std::ostream* os) { *os << v.Label(); }

using Param = std::tuple<BackendVariant, SizeCase>;

class Conformance : public ::testing::TestWithParam<Param> {
  protected:
    void SetUp() override {
        const BackendVariant& variant = std::get<0>(GetParam());
        BackendOptions options = variant.options;
        options.vkValidation = true;  // the tests run with the Khronos layer and expect no message
        mAutomatonOnly = options.glCaLayout != gl::CaLayout::Packed;
        auto backend = CreateBackend(variant.backend, options);
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
    }
    void TearDown() override {
#if CLOUDBENCH_HAVE_VK
        if (auto* vk = dynamic_cast<vk::BackendVk*>(mBackend.get())) {
            EXPECT_EQ(vk->ValidationMessages(), 0u);
        }
#endif
    }
    Extent3 Size() const { return std::get<1>(GetParam()).size; }
    // Why the test of `stage` is skipped on this backend; nullopt when it runs.
    // A variant with another automaton layout differs from its backend in the ca stage only.
    std::optional<std::string> SkipReason(Stage stage) const {
        if (!mBackend->Supports(stage))
            return "not implemented yet: " + mBackend->Name() + " has no " + std::string(StageName(stage)) + " stage";
        if (mAutomatonOnly && stage != Stage::Ca)
            return std::string("the RGBA8 automaton layout changes only the ca stage (tested as gl)");
        return std::nullopt;
    }

    // Location of voxel v as "(i, j, k)".
    static std::string Where(const Extent3& e, size_t v) {
        std::ostringstream s;
        s << "(" << v % e.nx << ", " << (v / e.nx) % e.ny << ", " << v / (size_t(e.nx) * e.ny) << ")";
        return s.str();
    }
    // Bit-exact comparison that reports the first differing voxel and how many differ.
    template <typename T>
    void ExpectExact(const std::vector<T>& reference, const std::vector<T>& got, const Extent3& e, const char* what) {
        ASSERT_EQ(reference.size(), got.size());
        size_t first = reference.size(), count = 0;
        for (size_t v = 0; v < reference.size(); ++v)
            if (std::memcmp(&reference[v], &got[v], sizeof(T)) != 0) {
                if (first == reference.size()) first = v;
                ++count;
            }
        EXPECT_EQ(count, 0u) << what << ": " << count << " of " << reference.size() << " differ; first at "
                             << Where(e, first) << ": cpu " << +reference[first] << ", " << mBackend->Name() << " "
                             << +got[first];
    }

    cpu::BackendCpu mCpu;
    std::unique_ptr<Backend> mBackend;
    bool mAutomatonOnly = false;
};

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

// Test the noise stage: |dq| <= 1e-5 against the CPU (SPEC 10a, core/StageDescriptors.cpp), steps 0 and 5.
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
            EXPECT_LE(worstError, 1e-5f) << "at " << Where(e, worst) << ": cpu " << a[worst] << ", " << mBackend->Name()
                                         << " " << b[worst];
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
    auto gotQ = test::MakeFilled(*mBackend, BufferFormat::F32, e, qData);
    auto gotBits = test::MakeFilled(*mBackend, BufferFormat::Bits, e, cld);
    const DensityParams params{8, 4, {}};
    const Extent3 tiles{CeilDiv(e.nx, 8), CeilDiv(e.ny, 8), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, 4)};
    std::unique_ptr<Buffer> out[2][3];
    Backend* backends[2] = {&mCpu, mBackend.get()};
    DensityOutputs results[2];
    for (int n = 0; n < 2; ++n) {
        out[n][0] = test::MakeBuffer(*backends[n], BufferFormat::F32, {e.nx, e.ny, 1});
        out[n][1] = test::MakeBuffer(*backends[n], BufferFormat::U8, tiles);
        out[n][2] = test::MakeBuffer(*backends[n], BufferFormat::U8, bands);
        results[n] = {out[n][0].get(), out[n][1].get(), out[n][2].get(), 0};
    }
    ASSERT_TRUE(mCpu.Density(params, *q, refBits.get(), results[0]));
    Status s = mBackend->Density(params, *gotQ, gotBits.get(), results[1]);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    ExpectExact(test::Read<float>(mCpu, *out[0][0]), test::Read<float>(*mBackend, *out[1][0]), {e.nx, e.ny, 1}, "D");
    ExpectExact(test::Read<uint8_t>(mCpu, *out[0][1]), test::Read<uint8_t>(*mBackend, *out[1][1]), tiles, "tiles");
    ExpectExact(test::Read<uint8_t>(mCpu, *out[0][2]), test::Read<uint8_t>(*mBackend, *out[1][2]), bands, "bands");
    EXPECT_EQ(results[0].coveredColumns, results[1].coveredColumns);
    // Without an automaton (no cld) the cover counts columns with D > 0.
    DensityOutputs withoutCld[2];
    for (int n = 0; n < 2; ++n) withoutCld[n] = {out[n][0].get(), out[n][1].get(), out[n][2].get(), 0};
    ASSERT_TRUE(mCpu.Density(params, *q, nullptr, withoutCld[0]));
    s = mBackend->Density(params, *gotQ, nullptr, withoutCld[1]);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    EXPECT_EQ(withoutCld[0].coveredColumns, withoutCld[1].coveredColumns);
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
    auto refQ = test::MakeFilled(mCpu, BufferFormat::F32, e, qData);
    auto refBits = test::MakeFilled(mCpu, BufferFormat::Bits, e, cld);
    auto gotQ = test::MakeFilled(*mBackend, BufferFormat::F32, e, qData);
    auto gotBits = test::MakeFilled(*mBackend, BufferFormat::Bits, e, cld);
    for (const uint32_t band : {1u, 3u}) {
        SCOPED_TRACE("band " + std::to_string(band));
        const DensityParams params{32, band, {}};
        const Extent3 tiles{CeilDiv(e.nx, 32), CeilDiv(e.ny, 32), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, band)};
        std::unique_ptr<Buffer> out[2][3];
        Backend* backends[2] = {&mCpu, mBackend.get()};
        DensityOutputs results[2];
        for (int n = 0; n < 2; ++n) {
            out[n][0] = test::MakeBuffer(*backends[n], BufferFormat::F32, {e.nx, e.ny, 1});
            out[n][1] = test::MakeBuffer(*backends[n], BufferFormat::U8, tiles);
            out[n][2] = test::MakeBuffer(*backends[n], BufferFormat::U8, bands);
            results[n] = {out[n][0].get(), out[n][1].get(), out[n][2].get(), 0};
        }
        ASSERT_TRUE(mCpu.Density(params, *refQ, refBits.get(), results[0]));
        Status s = mBackend->Density(params, *gotQ, gotBits.get(), results[1]);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        const std::vector<uint8_t> refBands = test::Read<uint8_t>(mCpu, *out[0][2]);
        if (band == 1) {  // the data holds both empty and occupied boxes
            EXPECT_NE(std::count(refBands.begin(), refBands.end(), 0), 0);
            EXPECT_NE(std::count(refBands.begin(), refBands.end(), 1), 0);
        }
        ExpectExact(test::Read<float>(mCpu, *out[0][0]), test::Read<float>(*mBackend, *out[1][0]), {e.nx, e.ny, 1},
                    "D");
        ExpectExact(test::Read<uint8_t>(mCpu, *out[0][1]), test::Read<uint8_t>(*mBackend, *out[1][1]), tiles, "tiles");
        ExpectExact(refBands, test::Read<uint8_t>(*mBackend, *out[1][2]), bands, "bands");
        EXPECT_EQ(results[0].coveredColumns, results[1].coveredColumns);
        ASSERT_TRUE(mCpu.Density(params, *refQ, nullptr, results[0]));
        s = mBackend->Density(params, *gotQ, nullptr, results[1]);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        EXPECT_EQ(results[0].coveredColumns, results[1].coveredColumns) << "without cld";
    }
}

// Largest |a - b| and where it is.
template <typename T>
std::pair<double, size_t> WorstDifference(const std::vector<T>& a, const std::vector<T>& b) {
    double worst = 0;
    size_t at = 0;
    for (size_t v = 0; v < a.size(); ++v) {
        const double d = std::fabs(double(a[v]) - double(b[v]));
        if (!(d <= worst)) worst = d, at = v;  // NaN counts as worst
    }
    return {worst, at};
}

// Test shading for every option and several suns: max |dT| <= 1e-5 for fp32,
// one stored code for fp16 and unorm8 (SPEC 6; issue 16: a float difference can
// exceed 1/255 by an ulp where the codes differ by one).
TEST_P(Conformance, Shade) {
    if (auto why = SkipReason(Stage::Shade)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(21);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    auto refQ = test::MakeFilled(mCpu, BufferFormat::F32, e, q);
    auto gotQ = test::MakeFilled(*mBackend, BufferFormat::F32, e, q);
    auto refT = test::MakeBuffer(mCpu, BufferFormat::F32, e);
    auto gotT = test::MakeBuffer(*mBackend, BufferFormat::F32, e);
    const Vec3 suns[] = {
        {0, 0, 1}, SunDirection(0.44, 1.05), SunDirection(0.7853981633974483, 0.3), SunDirection(0.2, 3.5)};
    for (const Vec3& sun : suns)
        for (AttenuationKind att : {AttenuationKind::Beer, AttenuationKind::Thesis})
            for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
                for (int f : {1, 2, 4})
                    for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8})
                        for (bool scattering : {false, true}) {
                            ShadeParams p;
                            p.sun = sun;
                            p.attenuation = att;
                            p.filter = filter;
                            p.resolution = f;
                            p.storage = storage;
                            p.scattering = scattering;
                            p.sigma = 0.01f;
                            ASSERT_TRUE(mCpu.Shade(p, *refQ, *refT));
                            Status s = mBackend->Shade(p, *gotQ, *gotT);
                            ASSERT_TRUE(s.has_value()) << s.error().message;
                            const auto a = test::Read<float>(mCpu, *refT), b = test::Read<float>(*mBackend, *gotT);
                            // fp32 within 1e-5; fp16 and unorm8 within one stored code, compared as integers.
                            auto [worst, at] = WorstDifference(a, b);
                            double tolerance = 1e-5;
                            if (storage != StorageFormat::Fp32) {
                                std::vector<double> ca(a.size()), cb(b.size());
                                for (size_t v = 0; v < a.size(); ++v)
                                    ca[v] = StorageCode(storage, a[v]), cb[v] = StorageCode(storage, b[v]);
                                std::tie(worst, at) = WorstDifference(ca, cb);
                                tolerance = 1;
                            }
                            ASSERT_LE(worst, tolerance)
                                << "sun (" << sun[0] << ", " << sun[1] << ", " << sun[2] << ") att " << int(att)
                                << " filter " << int(filter) << " f " << f << " storage " << int(storage)
                                << " scattering " << scattering << ": worst at " << Where(e, at) << ": cpu " << a[at]
                                << ", " << mBackend->Name() << " " << b[at];
                        }
}

// Test the ground shadow in every form, several suns: max |dG| <= 1e-5 (SPEC 7).
TEST_P(Conformance, Shadow) {
    if (auto why = SkipReason(Stage::Shadow)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(23);
    std::vector<float> D(size_t(e.nx) * e.ny);
    for (float& v : D) v = float(rng.Below(200)) / 64.0f;
    const Extent3 map{e.nx, e.ny, 1};
    auto refD = test::MakeFilled(mCpu, BufferFormat::F32, map, D);
    auto gotD = test::MakeFilled(*mBackend, BufferFormat::F32, map, D);
    auto refG = test::MakeBuffer(mCpu, BufferFormat::F32, map);
    auto gotG = test::MakeBuffer(*mBackend, BufferFormat::F32, map);
    for (const Vec3& sun : {Vec3{0, 0, 1}, SunDirection(0.5, 0.7), SunDirection(0.05, 2.0), SunDirection(-0.1, 0.0)})
        for (ShadowForm form : {ShadowForm::Beer, ShadowForm::Thesis, ShadowForm::Wang}) {
            ShadowParams p;
            p.sun = sun;
            p.form = form;
            p.coverage = 0.7f;  // wang: both of its terms active (C = D_w = 1 would be beer)
            p.densityFactor = 0.8f;
            p.nz = e.nz;
            ASSERT_TRUE(mCpu.Shadow(p, *refD, *refG));
            Status s = mBackend->Shadow(p, *gotD, *gotG);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            const auto a = test::Read<float>(mCpu, *refG), b = test::Read<float>(*mBackend, *gotG);
            const auto [worst, at] = WorstDifference(a, b);
            EXPECT_LE(worst, 1e-5) << "form " << int(form) << ": worst at " << Where(map, at) << ": cpu " << a[at]
                                   << ", " << mBackend->Name() << " " << b[at];
        }
}

// Test the splat renderer from four cameras (outside, inside, straight down,
// partly out of view) with culling and skipping on, the last two cameras over
// the ground lit through a G (core/Ground.h): per channel |d| <= 2/255
// on 99.9 % of pixels and <= 8/255 everywhere (SPEC 8). A failure writes the
// difference image and names the worst pixel.
TEST_P(Conformance, RenderSplat) {
    if (auto why = SkipReason(Stage::RenderSplat)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(29);
    std::vector<float> qPrev(e.Count()), qCur(e.Count()), T(e.Count());
    for (size_t v = 0; v < qPrev.size(); ++v) {
        const bool cloudy = (v / 61) % 4 == 0;
        qPrev[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        qCur[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        T[v] = float(rng.Below(256)) / 255.0f;
    }
    std::vector<float> G(size_t(e.nx) * e.ny);
    for (float& g : G) g = float(rng.Below(257)) / 256.0f;
    const float h = 50;
    const double cx = e.nx * h / 2, cy = e.ny * h / 2, cz = e.nz * h / 2;
    std::vector<CameraSettings> cameras(4);
    cameras[0].eye = {-cx, -cy, cz * 3};
    cameras[0].target = {cx, cy, cz};
    cameras[1].eye = {cx * 0.7, cy * 0.9, cz};
    cameras[1].target = {cx * 2, cy * 1.5, cz};
    cameras[2].eye = {cx, cy, cz * 8};
    cameras[2].target = {cx, cy, 0};
    cameras[3].eye = {-cx * 2, cy, cz};
    cameras[3].target = {cx * 4, cy * 3, cz};
    const uint32_t W = 96, H = 72;
    Backend* backends[2] = {&mCpu, mBackend.get()};
    const DensityParams density{8, 4, {}};
    for (size_t c = 0; c < cameras.size(); ++c) {
        std::vector<float> images[2];
        SplatStats stats[2];
        for (int n = 0; n < 2; ++n) {
            Backend& b = *backends[n];
            auto qp = test::MakeFilled(b, BufferFormat::F32, e, qPrev);
            auto qc = test::MakeFilled(b, BufferFormat::F32, e, qCur);
            auto t = test::MakeFilled(b, BufferFormat::F32, e, T);
            auto g = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, G);
            auto cld = test::MakeBuffer(b, BufferFormat::Bits, e);
            const Extent3 tiles{CeilDiv(e.nx, 8), CeilDiv(e.ny, 8), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, 4)};
            std::unique_ptr<Buffer> occupancy[2][2];
            for (int step = 0; step < 2; ++step) {
                auto D = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
                occupancy[step][0] = test::MakeBuffer(b, BufferFormat::U8, tiles);
                occupancy[step][1] = test::MakeBuffer(b, BufferFormat::U8, bands);
                DensityOutputs out{D.get(), occupancy[step][0].get(), occupancy[step][1].get(), 0};
                ASSERT_TRUE(b.Density(density, step == 0 ? *qp : *qc, cld.get(), out).has_value());
            }
            SplatParams p;
            p.camera = MakeCameraFrame(cameras[c], W, H);
            const SplatOrder order = MakeSplatOrder(p.camera, e, {0, 0, 0}, h);
            p.order = &order;
            p.voxelSize = h;
            p.splatDiameter = 1.5f * h;
            p.sun = SunDirection(0.5, 0.8);
            p.sunRadiance = {1.5f, 1.4f, 1.3f};
            p.ambient = {0.2f, 0.25f, 0.3f};
            p.background = {0.4f, 0.5f, 0.8f};
            p.tile = 8;
            p.band = 4;
            p.alpha = 0.4f;
            if (c >= 2) p.ground = {true, {0.4f, 0.35f, 0.3f}};
            auto image = test::MakeBuffer(b, BufferFormat::F32, {3, W, H});
            SplatInputs in{qp.get(),
                           qc.get(),
                           t.get(),
                           occupancy[0][0].get(),
                           occupancy[1][0].get(),
                           occupancy[0][1].get(),
                           occupancy[1][1].get()};
            in.G = p.ground.on ? g.get() : nullptr;
            Status s = b.RenderSplat(p, in, *image, &stats[n]);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            images[n] = test::Read<float>(b, *image);
        }
        // The same voxels make splats everywhere; Vulkan does not count the
        // visited voxels or the fragments (docs/pipeline.md), the others must
        // agree on both (GL: runs of visible boxes, and a fragment query).
        EXPECT_GT(stats[0].splats, 0u) << "camera " << c << " sees no splat: the test would prove nothing";
        EXPECT_EQ(stats[1].splats, stats[0].splats) << "camera " << c;
        if (mBackend->Name() != "vk") {
            EXPECT_EQ(stats[1].voxelsVisited, stats[0].voxelsVisited) << "camera " << c;
            EXPECT_EQ(stats[1].fragments, stats[0].fragments) << "camera " << c;
        }
        const ImageComparison cmp = CompareImages(images[0], images[1], W, H);
        if (!cmp.Passes()) {
            const std::string path =
                ::testing::TempDir() + "/render_diff_" + mBackend->Name() + "_" + std::to_string(c) + ".exr";
            (void)WriteDifferenceImage(path, images[0], images[1], W, H);
            ADD_FAILURE() << "camera " << c << ": max error " << cmp.maxError << " at (" << cmp.worstX << ", "
                          << cmp.worstY << "), " << cmp.pixelsOverTolerance << " of " << cmp.pixels
                          << " pixels over 2/255, PSNR " << cmp.psnr << "; difference image: " << path;
        }
    }
}

// Every backend implements the thesis's splat pipeline; a lost stage would
// otherwise only turn its conformance tests into skips.
TEST_P(Conformance, ImplementsTheSplatPipeline) {
    if (std::get<1>(GetParam()).size.nx != 64) GTEST_SKIP() << "runs once per backend";
    for (Stage stage :
         {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade, Stage::Shadow, Stage::RenderSplat})
        EXPECT_TRUE(mBackend->Supports(stage)) << mBackend->Name() << " lacks " << StageName(stage);
    // The noise producer and the ray marcher are on every backend too.
    EXPECT_TRUE(mBackend->Supports(Stage::Noise)) << mBackend->Name() << " lacks noise";
    EXPECT_TRUE(mBackend->Supports(Stage::RenderMarch)) << mBackend->Name() << " lacks render_march";
}

// Test end to end: the simulation stages of ci-small for 15 steps, each backend
// on its own state. Where the region volumes are identical the automaton
// states must be identical too, step after step; where a region differs (SPEC
// allows |dR| <= 1), the states may drift and only the cover is compared, within
// 2 percentage points. (This is also the test of the RGBA8 automaton's
// chained steps, where each step starts from the state the last one left.)
TEST_P(Conformance, EndToEndSimulation) {
    for (Stage stage : {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density})
        if (!mBackend->Supports(stage))
            GTEST_SKIP() << "not implemented yet: " << mBackend->Name() << " has no " << StageName(stage) << " stage";
    if (std::get<1>(GetParam()).size.nx != 64) GTEST_SKIP() << "runs once per backend, on ci-small";
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                           {{"stages", R"(["region", "ca", "smooth", "density"])"},
                            {"steps", "15"},
                            {"warmup_steps", "0"},
                            {"ca.wind_shift", "[[1, -1]]"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    auto ref = Simulation::Create(*scene, mCpu);
    auto got = Simulation::Create(*scene, *mBackend);
    ASSERT_TRUE(ref.has_value() && got.has_value());
    bool regionsIdentical = true;
    const Extent3 e = scene->grid.size;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord a, b;
        ASSERT_TRUE((*ref)->Step(a).has_value());
        Status s = (*got)->Step(b);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        // After Step, Region() holds R_t and Cld() the state t+1.
        regionsIdentical = regionsIdentical && test::Read<uint8_t>(mCpu, *(*ref)->Region()) ==
                                                   test::Read<uint8_t>(*mBackend, *(*got)->Region());
        if (regionsIdentical) {
            SCOPED_TRACE("step " + std::to_string(t));
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Cld()), test::Read<uint8_t>(*mBackend, *(*got)->Cld()), e,
                        "cld");
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Hum()), test::Read<uint8_t>(*mBackend, *(*got)->Hum()), e,
                        "hum");
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Act()), test::Read<uint8_t>(*mBackend, *(*got)->Act()), e,
                        "act");
        }
        const double columns = double(e.nx) * e.ny;
        EXPECT_NEAR(*a.coveredColumns / columns, *b.coveredColumns / columns, regionsIdentical ? 0.0 : 0.02)
            << "step " << t;
    }
}

std::vector<BackendVariant> AllBackends() {
    BackendOptions rgba8;
    rgba8.glCaLayout = gl::CaLayout::Rgba8;
    return {{"cpu", {}}, {"vk", {}}, {"gl", {}}, {"gl", rgba8}};
}

INSTANTIATE_TEST_SUITE_P(Stages, Conformance,
                         ::testing::Combine(::testing::ValuesIn(AllBackends()),
                                            ::testing::Values(SizeCase{"Small64x64x16", {64, 64, 16}},
                                                              SizeCase{"Odd70x33x17", {70, 33, 17}},
                                                              SizeCase{"Thin1x1x9", {1, 1, 9}})),
                         [](const ::testing::TestParamInfo<Param>& info) {
                             return std::string(std::get<1>(info.param).name) + "_" + std::get<0>(info.param).Label();
                         });

}  // namespace
}  // namespace cb
