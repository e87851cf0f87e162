// Stage `noise` (SPEC 10a): the noises, fBm, the forming and the CPU stage
// (core/math/Noise.h, impl_cpu/NoiseCpu.cpp). Expected values come from closed
// forms, hand arithmetic, brute force or an independent loop in the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "core/math/Noise.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

using noise::Period;

const noise::Permutation& Perm() {
    static const noise::Permutation perm = noise::MakePermutation(7);
    return perm;
}

// Uniform numbers in [lo, hi) from the project's generator.
struct Draw {
    Pcg32 rng{12345};
    double operator()(double lo, double hi) { return rng.Uniform(lo, hi); }
};

// Test that the table is a permutation of 0..255, the same for the same seed
// and different for another.
TEST(Noise, PermutationIsASeededShuffle) {
    const noise::Permutation a = noise::MakePermutation(1), b = noise::MakePermutation(1),
                             c = noise::MakePermutation(2);
    std::array<uint8_t, 256> sorted = a;
    std::sort(sorted.begin(), sorted.end());
    for (int n = 0; n < 256; ++n) ASSERT_EQ(sorted[n], n);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    std::array<uint8_t, 256> identity;
    std::iota(identity.begin(), identity.end(), uint8_t(0));
    EXPECT_NE(a, identity);
}

// Test that Perlin and simplex noise vanish at their lattice points: for
// Perlin the integer points, for simplex the points whose skewed coordinates
// are integers, Cartesian (5a-b-c, 5b-a-c, 5c-a-b) / 6.
TEST(Noise, ZeroAtLatticePoints) {
    const Period period{4, 5, 6}, simplexPeriod{6, 9, 3};
    for (int a = -3; a <= 8; ++a)
        for (int b = -3; b <= 8; ++b)
            for (int c = -3; c <= 8; ++c) {
                ASSERT_EQ(noise::Perlin(Perm().data(), float(a), float(b), float(c), period), 0.0f) << a << b << c;
                const double x = (5.0 * a - b - c) / 6, y = (5.0 * b - a - c) / 6, z = (5.0 * c - a - b) / 6;
                ASSERT_NEAR(noise::Simplex(Perm().data(), x, y, z, simplexPeriod), 0.0, 1e-12) << a << b << c;
            }
}

// The noises as functions of a float point, for the periodicity tests.
using NoiseFn = float (*)(float, float, float, Period);
float PerlinF(float x, float y, float z, Period p) { return noise::Perlin(Perm().data(), x, y, z, p); }
float SimplexF(float x, float y, float z, Period p) { return noise::Simplex(Perm().data(), x, y, z, p); }
float WorleyF(float x, float y, float z, Period p) { return noise::Worley(99, x, y, z, p); }

// Largest |n(p) - n(p + period_a e_a)| over points and axes. Dyadic points
// (multiples of 1/64) shift without rounding, so there the noise must repeat exactly.
float PeriodicMismatch(NoiseFn fn, Period period, bool dyadic) {
    Draw draw;
    float worst = 0;
    for (int n = 0; n < 3000; ++n) {
        float p[3] = {float(draw(-12, 12)), float(draw(-12, 12)), float(draw(-12, 12))};
        if (dyadic)
            for (float& c : p) c = std::round(c * 64) / 64;
        const int32_t shift[3] = {period.x, period.y, period.z};
        for (int a = 0; a < 3; ++a) {
            float q[3] = {p[0], p[1], p[2]};
            q[a] += float(shift[a]);
            worst = std::max(worst, std::fabs(fn(p[0], p[1], p[2], period) - fn(q[0], q[1], q[2], period)));
        }
    }
    return worst;
}

// Test that each noise repeats with its period along each axis: exactly at
// dyadic points, within float rounding of the coordinates elsewhere.
TEST(Noise, SeamlessAcrossThePeriod) {
    EXPECT_EQ(PeriodicMismatch(PerlinF, {4, 5, 7}, true), 0.0f);
    EXPECT_LE(PeriodicMismatch(PerlinF, {4, 5, 7}, false), 2e-5f);
    // Simplex skews by 1/3, which no shift keeps exact, and at dyadic points
    // the rank ties fall either way (Gustavson's radius 0.6 makes the noise
    // jump there): random points only, and the same in double to 1e-9.
    EXPECT_LE(PeriodicMismatch(SimplexF, {3, 6, 9}, false), 2e-5f);
    Draw draw;
    for (int n = 0; n < 2000; ++n) {
        const double x = draw(-9, 9), y = draw(-9, 9), z = draw(-9, 9);
        const double v = noise::Simplex(Perm().data(), x, y, z, Period{3, 6, 9});
        ASSERT_NEAR(noise::Simplex(Perm().data(), x + 3, y, z, Period{3, 6, 9}), v, 1e-9);
        ASSERT_NEAR(noise::Simplex(Perm().data(), x, y + 6, z, Period{3, 6, 9}), v, 1e-9);
        ASSERT_NEAR(noise::Simplex(Perm().data(), x, y, z - 9, Period{3, 6, 9}), v, 1e-9);
    }
    EXPECT_EQ(PeriodicMismatch(WorleyF, {3, 4, 5}, true), 0.0f);
    EXPECT_LE(PeriodicMismatch(WorleyF, {3, 4, 5}, false), 2e-5f);
}

// Test the simplex tiling claim's limit: on periods that are not multiples of
// 3 the lattice does not map onto itself, and the noise does not repeat
// (docs/pipeline.md, "Noise") -- the check above can fail.
TEST(Noise, SimplexNeedsPeriodsOfThree) { EXPECT_GT(PeriodicMismatch(SimplexF, {4, 4, 4}, false), 1e-2f); }

// One-sided m-th derivative of Perlin (double) along axis `a` at p, from the
// right (+1) or the left (-1), by forward or backward differences of step h.
double OneSided(const double p[3], int a, int side, int m, double h) {
    static const int kBinomial[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    double sum = 0;
    for (int n = 0; n <= m; ++n) {
        double q[3] = {p[0], p[1], p[2]};
        q[a] += side * n * h;
        const double sign = ((m - n) % 2 == 0) ? 1 : -1;
        sum += sign * kBinomial[m][n] * noise::Perlin(Perm().data(), q[0], q[1], q[2], Period{5, 5, 5});
    }
    return sum / std::pow(side * h, m);
}

// Test that Perlin noise is C2 across cell faces, as the quintic fade
// promises: the one-sided first and second derivatives agree at faces. The
// third derivative does jump there (fade'''(0) = 60), and the same probe sees
// it, so the probe can tell a C2 function from a C3 one. (Measured: largest
// second-derivative jump 0.0017 with the quintic fade; with the cubic fade
// 3t^2 - 2t^3 put in its place, 16.5, which fails the bound 0.02.)
TEST(Noise, PerlinIsC2AcrossCellFaces) {
    Draw draw;
    double largestThirdJump = 0;
    for (int n = 0; n < 200; ++n) {
        const int a = n % 3;
        double p[3] = {draw(0, 5), draw(0, 5), draw(0, 5)};
        p[a] = double(n % 5);  // on a face
        for (int m = 1; m <= 2; ++m) {
            const double h = 1e-5;  // truncation O(h f^(m+1)), rounding O(1e-16 / h^m)
            const double jump = OneSided(p, a, +1, m, h) - OneSided(p, a, -1, m, h);
            ASSERT_LT(std::fabs(jump), m == 1 ? 1e-3 : 2e-2) << "derivative " << m << " along " << a;
        }
        largestThirdJump =
            std::max(largestThirdJump, std::fabs(OneSided(p, a, +1, 3, 1e-3) - OneSided(p, a, -1, 3, 1e-3)));
    }
    EXPECT_GT(largestThirdJump, 1.0);
}

// Test the ranges. Perlin: |n| <= 2 is provable (a convex blend of g.d, |g.d|
// <= 2); its measured envelope is 0.997 (5e6 random points), asserted as
// (0.8, 1.1]. Simplex: Gustavson's factor 32 is meant to keep it inside
// [-1, 1]; measured 0.978, asserted as (0.6, 1.0]. Worley lies in [0, 1] and
// reaches 1 at a feature point.
TEST(Noise, ValuesStayInTheirRanges) {
    Draw draw;
    float perlin = 0, simplex = 0, worleyLo = 1, worleyHi = 0;
    for (int n = 0; n < 200000; ++n) {
        const float x = float(draw(0, 12)), y = float(draw(0, 12)), z = float(draw(0, 12));
        perlin = std::max(perlin, std::fabs(PerlinF(x, y, z, {12, 12, 12})));
        simplex = std::max(simplex, std::fabs(SimplexF(x, y, z, {12, 12, 12})));
        const float w = WorleyF(x, y, z, {12, 12, 12});
        worleyLo = std::min(worleyLo, w), worleyHi = std::max(worleyHi, w);
    }
    EXPECT_GT(perlin, 0.8f);
    EXPECT_LE(perlin, 1.1f);
    EXPECT_GT(simplex, 0.6f);
    EXPECT_LE(simplex, 1.0f);
    EXPECT_GE(worleyLo, 0.0f);
    EXPECT_LE(worleyHi, 1.0f);
    const std::array<float, 3> f = noise::WorleyFeature(99, 2, 3, 4);
    EXPECT_NEAR(WorleyF(2 + f[0], 3 + f[1], 4 + f[2], {12, 12, 12}), 1.0f, 1e-6f);
}

// Test Worley against a brute force over every feature point of the period
// and its 27 periodic images, in double. The feature points are placed here
// from lowbias32 directly, as SPEC 10a and docs/pipeline.md define them.
TEST(Noise, WorleyEqualsBruteForce) {
    const int P[3] = {3, 4, 5};
    const uint32_t seed = 5;
    std::vector<std::array<double, 3>> points;
    for (int cz = 0; cz < P[2]; ++cz)
        for (int cy = 0; cy < P[1]; ++cy)
            for (int cx = 0; cx < P[0]; ++cx) {
                const uint32_t key =
                    LowBias32(uint32_t(cx) + LowBias32(uint32_t(cy) + LowBias32(uint32_t(cz) + LowBias32(seed))));
                points.push_back({cx + (LowBias32(key) >> 8) / 16777216.0, cy + (LowBias32(key + 1) >> 8) / 16777216.0,
                                  cz + (LowBias32(key + 2) >> 8) / 16777216.0});
            }
    Draw draw;
    for (int n = 0; n < 1000; ++n) {
        const double x = draw(-4, 9), y = draw(-4, 9), z = draw(-4, 9);
        double best = 1e30;
        for (const auto& f : points)
            for (int ix = -4; ix <= 4; ++ix)
                for (int iy = -4; iy <= 4; ++iy)
                    for (int iz = -4; iz <= 4; ++iz) {
                        const double dx = f[0] + ix * P[0] - x, dy = f[1] + iy * P[1] - y, dz = f[2] + iz * P[2] - z;
                        best = std::min(best, dx * dx + dy * dy + dz * dz);
                    }
        const double expected = std::clamp(1 - std::sqrt(best) / std::sqrt(3.0), 0.0, 1.0);
        ASSERT_NEAR(noise::Worley(seed, float(x), float(y), float(z), {P[0], P[1], P[2]}), expected, 1e-5)
            << x << " " << y << " " << z;
    }
}

// Test that fBm is the sum of its octaves, each evaluated on its own here with
// the period and coordinates scaled by lacunarity^o, and turbulence the sum of
// their magnitudes, for every basis.
TEST(Noise, FbmIsTheSumOfItsOctaves) {
    Draw draw;
    for (NoiseBasis basis : {NoiseBasis::Perlin, NoiseBasis::Simplex, NoiseBasis::Worley})
        for (bool turbulence : {false, true}) {
            const FbmSettings fbm{basis, 4, 0.6, 3, turbulence};
            const noise::Lattice lattice{basis, Perm().data(), 11};
            const Period period{3, 6, 3};
            for (int n = 0; n < 200; ++n) {
                const float x = float(draw(0, 3)), y = float(draw(0, 6)), z = float(draw(0, 3));
                double sum = 0, amplitude = 1;
                int m = 1;
                for (int o = 0; o < 4; ++o, amplitude *= 0.6, m *= 3) {
                    const float octave = noise::Basis(lattice, x * float(m), y * float(m), z * float(m),
                                                      {period.x * m, period.y * m, period.z * m});
                    sum += amplitude * (turbulence ? std::fabs(octave) : octave);
                }
                ASSERT_NEAR(noise::Fbm(lattice, fbm, x, y, z, period), sum, 1e-5);
            }
            EXPECT_NEAR(noise::FbmNorm(fbm), 1 + 0.6 + 0.36 + 0.216, 1e-6);
        }
}

// Test Olajos's height distribution against hand values:
// HD(0) = 0; HD(0.1) = (1 - e^-5) e^-0.4 = 0.993262 * 0.670320; HD(0.5) ~ e^-2; HD(1) ~ e^-4.
TEST(Noise, HeightDistributionHandValues) {
    EXPECT_EQ(noise::HeightDistribution(0.0f, 50, 4), 0.0f);
    EXPECT_NEAR(noise::HeightDistribution(0.1f, 50, 4), 0.6658035f, 1e-6f);
    EXPECT_NEAR(noise::HeightDistribution(0.5f, 50, 4), 0.1353353f, 1e-6f);
    EXPECT_NEAR(noise::HeightDistribution(1.0f, 50, 4), 0.0183156f, 1e-6f);
    EXPECT_NEAR(noise::HeightDistribution(0.2f, 10, 2), (1 - std::exp(-2.0f)) * std::exp(-0.4f), 1e-6f);
}

// Test the threshold, coverage and erosion maps at their defining points.
TEST(Noise, ThresholdCoverageAndErosion) {
    EXPECT_EQ(noise::Threshold(0.35f, 0.35f), 0.0f);
    EXPECT_EQ(noise::Threshold(1.0f, 0.35f), 1.0f);
    EXPECT_EQ(noise::Threshold(0.1f, 0.35f), 0.0f);
    EXPECT_EQ(noise::Threshold(1.7f, 0.35f), 1.0f);
    EXPECT_NEAR(noise::Threshold(0.675f, 0.35f), 0.5f, 1e-6f);
    EXPECT_NEAR(CoverageModulate(0.8f, 0.3f, 0.6f, 2.0f), 2 * (0.8f - 0.7f), 1e-6f);  // eq. 16
    EXPECT_EQ(CoverageModulate(0.6f, 0.3f, 0.6f, 2.0f), 0.0f);
    EXPECT_NEAR(CoverageModulate(0.55f, 0.0f, 1.0f, 1.0f), 0.55f, 1e-7f);  // eq. 14 with m = 0
    EXPECT_EQ(noise::Erode(0.4f, 0.0f, 0.3f), 0.4f);
    EXPECT_NEAR(noise::Erode(1.0f, 0.7f, 0.5f), 1.0f, 1e-7f);
    EXPECT_NEAR(noise::Erode(0.35f, 0.7f, 0.5f), 0.0f, 1e-7f);
}

// Test the towers against a direct evaluation of the Gaussian in double at
// the nearest periodic image in x and y, including a tower near the grid's edge.
TEST(Noise, TowersAreGaussianBumps) {
    NoiseSettings s;
    s.towers = {{{10, 12, 5}, {2, 3, 4}, 0.7}, {{1, 30, 3}, {2.5, 2, 3}, 0.4}};
    const Extent3 grid{32, 32, 16};
    const noise::NoiseForm form(s, grid);
    for (uint32_t k = 0; k < grid.nz; k += 3)
        for (uint32_t j = 0; j < grid.ny; ++j)
            for (uint32_t i = 0; i < grid.nx; ++i) {
                double expected = 0;
                for (const NoiseTower& t : s.towers) {
                    double best = 1e30;
                    for (int ox = -1; ox <= 1; ++ox)
                        for (int oy = -1; oy <= 1; ++oy) {
                            const double dx = (i + 0.5 - t.center[0] - ox * 32.0) / t.sigma[0];
                            const double dy = (j + 0.5 - t.center[1] - oy * 32.0) / t.sigma[1];
                            best = std::min(best, dx * dx + dy * dy);
                        }
                    const double dz = (k + 0.5 - t.center[2]) / t.sigma[2];
                    expected += t.amplitude * std::exp(-0.5 * (best + dz * dz));
                }
                ASSERT_NEAR(form.Towers(i, j, k), expected, 1e-6) << i << "," << j << "," << k;
            }
}

// A noise with every feature on: Perlin fBm, a tower, detail, coverage, drift.
NoiseSettings Busy(NoiseBasis basis = NoiseBasis::Perlin) {
    NoiseSettings s;
    s.seed = 4;
    s.fbm.basis = basis;
    s.frequency = basis == NoiseBasis::Simplex ? std::array<uint32_t, 3>{3, 6, 3} : std::array<uint32_t, 3>{4, 2, 2};
    s.fbm.octaves = 3;
    s.towers = {{{5, 6, 4}, {3, 3, 5}, 0.5}};
    s.detail.enabled = true;
    s.detail.size = 8;
    s.detail.frequency = 2;
    s.coverage.enabled = true;
    s.coverage.coverage = 0.7;
    s.coverage.density = 2;
    s.coverage.frequency = {2, 1};
    s.drift = {0.75, -0.5, 0.25};
    return s;
}

// Test that the volume is seamless at its own edges in x and y: q one voxel
// past the last (i = nx, j = ny) equals q at the first, for every basis with
// the detail volume (whose size divides the grid) and the coverage map on.
TEST(Noise, VolumeTilesAcrossItsEdges) {
    const Extent3 grid{16, 24, 8};
    for (NoiseBasis basis : {NoiseBasis::Perlin, NoiseBasis::Simplex, NoiseBasis::Worley}) {
        const noise::NoiseForm form(Busy(basis), grid);
        for (uint32_t step : {0u, 3u}) {
            const noise::StepOffsets o = form.Offsets(step);
            float worst = 0, interior = 0;
            for (uint32_t k = 0; k < grid.nz; ++k) {
                for (uint32_t j = 0; j < grid.ny; ++j) {
                    worst = std::max(worst, std::fabs(form.Q(o, grid.nx, j, k) - form.Q(o, 0, j, k)));
                    interior = std::max(interior, std::fabs(form.Q(o, 1, j, k) - form.Q(o, 0, j, k)));
                }
                for (uint32_t i = 0; i < grid.nx; ++i)
                    worst = std::max(worst, std::fabs(form.Q(o, i, grid.ny, k) - form.Q(o, i, 0, k)));
            }
            EXPECT_LE(worst, 2e-5f) << "basis " << int(basis) << " step " << step;
            EXPECT_GT(interior, 1e-3f) << "the volume is not constant";
        }
    }
}

// Test the time coordinate: with a drift of whole voxels per step (and no
// towers, which stay put), q at step t is q at step 0 moved by drift * t, wrapped.
TEST(Noise, DriftMovesTheClouds) {
    NoiseSettings s = Busy();
    s.towers.clear();
    s.drift = {2, -1, 0};
    const Extent3 grid{16, 16, 8};
    const noise::NoiseForm form(s, grid);
    const noise::StepOffsets o0 = form.Offsets(0), o3 = form.Offsets(3);
    for (uint32_t k = 0; k < grid.nz; ++k)
        for (uint32_t j = 0; j < grid.ny; ++j)
            for (uint32_t i = 0; i < grid.nx; ++i) {
                const uint32_t si = (i + 16 - 6) % 16, sj = (j + 3) % 16;
                ASSERT_NEAR(form.Q(o3, i, j, k), form.Q(o0, si, sj, k), 2e-5f) << i << "," << j << "," << k;
            }
}

// Test the CPU stage: every voxel equals NoiseForm::Q (the same operations),
// at several steps, with every feature on; the same seed gives the same q,
// another seed another q.
TEST(Noise, CpuStageEqualsTheFormula) {
    cpu::BackendCpu backend(2);
    const Extent3 grid{16, 8, 8};
    NoiseSettings turbulent = Busy();  // the stage forms Perlin fBm row by row: turbulence and lacunarity 3 too
    turbulent.fbm.turbulence = true;
    turbulent.fbm.lacunarity = 3;
    for (const NoiseSettings& s :
         {Busy(NoiseBasis::Perlin), Busy(NoiseBasis::Simplex), Busy(NoiseBasis::Worley), turbulent}) {
        const noise::NoiseForm form(s, grid);
        auto q = test::MakeBuffer(backend, BufferFormat::F32, grid);
        for (uint32_t step : {0u, 1u, 5u}) {
            ASSERT_TRUE(backend.Noise({step, &s, grid}, *q).has_value());
            const std::vector<float> values = test::Read<float>(backend, *q);
            const noise::StepOffsets o = form.Offsets(step);
            for (uint32_t k = 0; k < grid.nz; ++k)
                for (uint32_t j = 0; j < grid.ny; ++j)
                    for (uint32_t i = 0; i < grid.nx; ++i)
                        ASSERT_EQ(values[VoxelIndex(grid, i, j, k)], form.Q(o, i, j, k))
                            << i << "," << j << "," << k << " basis " << int(s.fbm.basis);
        }
    }
    NoiseSettings a = Busy(), b = Busy();
    b.seed = 5;
    auto qa = test::MakeBuffer(backend, BufferFormat::F32, grid);
    auto qb = test::MakeBuffer(backend, BufferFormat::F32, grid);
    ASSERT_TRUE(backend.Noise({0, &a, grid}, *qa).has_value());
    ASSERT_TRUE(backend.Noise({0, &b, grid}, *qb).has_value());
    const std::vector<float> va = test::Read<float>(backend, *qa);
    EXPECT_NE(va, test::Read<float>(backend, *qb));
    ASSERT_TRUE(backend.Noise({0, &a, grid}, *qb).has_value());
    EXPECT_EQ(va, test::Read<float>(backend, *qb));
}

// Counts the noise calls of the CPU backend.
class CountingCpu : public cpu::BackendCpu {
  public:
    Status Noise(const NoiseParams& params, Buffer& q) override {
        ++calls;
        return cpu::BackendCpu::Noise(params, q);
    }
    int calls = 0;
};

// Test end to end: the test noise scene (32x32x16) through density, shade,
// shadow and render_splat on the CPU gives q in [0, 1] with clouds in it, and
// a finite image; drifting noise is made every step, static noise once (SPEC 14).
TEST(Noise, SceneRunsEndToEnd) {
    const std::string path = std::string(CLOUDBENCH_SCENES_DIR) + "/../tests/scenes/noise-small.json";
    for (bool animated : {true, false}) {
        std::vector<SceneOverride> overrides;
        if (!animated) overrides.push_back({"noise.drift", "[0, 0, 0]"});
        auto scene = LoadScene(path, overrides);
        ASSERT_TRUE(scene.has_value()) << scene.error().message;
        CountingCpu backend;
        auto sim = Simulation::Create(*scene, backend);
        ASSERT_TRUE(sim.has_value()) << sim.error().message;
        for (uint32_t t = 0; t < scene->steps; ++t) {
            StepRecord r;
            Status s = (*sim)->Step(r);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            EXPECT_EQ(r.stageMs[size_t(Stage::Noise)].has_value(), animated || t == 0) << "step " << t;
            const std::vector<float> q = test::Read<float>(backend, *(*sim)->Q());
            size_t cloudy = 0;
            for (float v : q) {
                ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << v;
                cloudy += v > 0;
            }
            EXPECT_GT(cloudy, q.size() / 100);
            EXPECT_LT(cloudy, q.size() / 2);
        }
        EXPECT_EQ(backend.calls, animated ? int(scene->steps) : 1);
        for (float v : test::Read<float>(backend, *(*sim)->Image(0))) ASSERT_TRUE(std::isfinite(v));
    }
}

// Test the scene section: defaults, a full section, and errors with their fields.
TEST(Noise, SceneSection) {
    auto parse = [](const std::string& noise) {
        return ParseScene(R"({"grid": {"size": [16, 16, 8]}, "stages": ["noise"], "noise": )" + noise + "}",
                          "test.json");
    };
    auto defaults = parse("{}");
    ASSERT_TRUE(defaults.has_value()) << defaults.error().message;
    EXPECT_EQ(defaults->noise, NoiseSettings{});
    EXPECT_FALSE(defaults->noise.Animated());

    auto full = parse(R"({"seed": 9, "basis": "simplex", "frequency": [3, 6, 3], "octaves": 3, "gain": 0.4,
        "lacunarity": 3, "turbulence": true, "height_a": 20, "height_b": 2, "threshold": 0.2,
        "towers": [{"center": [1, 2, 3], "sigma": [4, 5, 6], "amplitude": 0.3}],
        "detail": {"size": 16, "basis": "perlin", "frequency": 4, "octaves": 2, "strength": 0.5},
        "coverage": {"coverage": 0.7, "density": 2, "frequency": [3, 2], "octaves": 2, "gain": 0.6},
        "drift": [1, 0.5, 0]})");
    ASSERT_TRUE(full.has_value()) << full.error().message;
    const NoiseSettings& n = full->noise;
    EXPECT_EQ(n.seed, 9u);
    EXPECT_EQ(n.fbm.basis, NoiseBasis::Simplex);
    EXPECT_EQ(n.fbm.lacunarity, 3u);
    EXPECT_TRUE(n.fbm.turbulence);
    ASSERT_EQ(n.towers.size(), 1u);
    EXPECT_EQ(n.towers[0].sigma[2], 6.0);
    EXPECT_TRUE(n.detail.enabled);
    EXPECT_EQ(n.detail.fbm.basis, NoiseBasis::Perlin);
    EXPECT_EQ(n.detail.size, 16u);
    EXPECT_TRUE(n.coverage.enabled);
    EXPECT_EQ(n.coverage.frequency[0], 3u);
    EXPECT_TRUE(n.Animated());

    auto error = [&](const std::string& noise) {
        auto s = parse(noise);
        return s.has_value() ? std::string("(accepted)") : s.error().message;
    };
    EXPECT_EQ(error(R"({"basis": "simplex"})"),
              "test.json: noise.frequency[0]: must be a multiple of 3 with the simplex basis (its lattice tiles only "
              "on such periods), got 4");
    EXPECT_EQ(error(R"({"threshold": 1})"), "test.json: noise.threshold: must be in [0, 0.99], got 1");
    EXPECT_EQ(error(R"({"frequency": [512, 4, 4], "octaves": 5})"),
              "test.json: noise.frequency[0]: times lacunarity^(octaves - 1) must be at most 4096 lattice cells, got "
              "512 x 16");
    EXPECT_NE(error(R"({"octave": 3})").find("noise.octave"), std::string::npos);
    EXPECT_NE(error(R"({"towers": [{"sigma": [1, 1, 1]}]})").find("noise.towers[0].center: required field is missing"),
              std::string::npos);
}

}  // namespace
}  // namespace cb
