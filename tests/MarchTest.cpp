// The ray marcher (SPEC 10): the shared kernel (core/math/March.h) against closed
// forms, and the CPU backend's render_march on small grids. Expected values
// come from analytic integrals or independent double-precision quadrature,
// never from the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <limits>
#include <vector>

#include "core/math/March.h"
#include "core/math/Random.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

using test::CameraParams;
using test::PlainSetup;

// ---- Helpers ---------------------------------------------------------------------


// A ray along +z through (x, y), clipped to [t0, t1].
MarchRayGeometry RayAlongZ(float x, float y, float t0, float t1) {
    MarchRayGeometry r;
    r.origin = {x, y, 0};
    r.dir = {0, 0, 1};
    r.tMin = t0;
    r.tMax = t1;
    return r;
}

MarchLightSample UnitLight(const Vec3&) { return {1.0f, 1.0f}; }

struct MarchCase {
    Extent3 grid{16, 16, 16};
    std::vector<float> q, T;  // T empty: all 1
    MarchParams params;
};

struct MarchImage {
    std::vector<float> rgb;
    MarchStats stats;
};

MarchImage RenderCpu(const MarchCase& c, int threads = 2) {
    cpu::BackendCpu backend(threads);
    const Extent3 e = c.grid;
    auto q = test::MakeFilled(backend, BufferFormat::F32, e, c.q);
    std::vector<float> T = c.T.empty() ? std::vector<float>(e.Count(), 1.0f) : c.T;
    auto t = test::MakeFilled(backend, BufferFormat::F32, e, T);
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, c.params.camera.width, c.params.camera.height});
    MarchImage out;
    const MarchInputs in{q.get(), q.get(), t.get()};
    Status status = backend.RenderMarch(c.params, in, *image, &out.stats);
    EXPECT_TRUE(status.has_value()) << status.error().message;
    out.rgb = test::Read<float>(backend, *image);
    return out;
}


// A few Gaussian blobs, zero below 1e-3 so that whole bricks are empty.
std::vector<float> BlobField(const Extent3& e) {
    return test::GaussianBlobField(e, {{10, 12, 8, 2}, {22, 20, 14, 2.5}, {14, 24, 18, 1.5}});
}

bool AllFinite(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

// ---- Closed forms through the kernel --------------------------------------------

// A homogeneous slab with constant light: the discrete sum telescopes to
// (sun P + ambient)(1 - e^{-sigma q L}) + e^{-sigma q L} background for any
// step, jitter and schedule, including the last partial segment.
TEST(March, HomogeneousSlabMatchesAnalyticInScattering) {
    const float q0 = 0.7f, sigmaH = 0.08f, depth = 13.3f;
    for (bool adaptive : {false, true})
        for (float xi : {0.5f, 0.137f, 0.93f}) {
            MarchSetup s = PlainSetup({20, 20, 20}, sigmaH);
            s.step = 0.37f;
            s.adaptive = adaptive;
            s.kappa = 0.3f;
            s.adaptiveStart = 4;
            const MarchRayGeometry ray = RayAlongZ(10, 10, 2.0f, 2.0f + depth);
            auto q = [&](const Vec3&) { return q0; };
            const MarchRayResult r = MarchRay(s, ray, xi, nullptr, q, UnitLight);
            const double T = std::exp(-double(sigmaH) * q0 * depth);
            for (int c = 0; c < 3; ++c) {
                const double expected =
                    (double(s.light.sunRadiance[c]) + s.light.ambient[c]) * (1 - T) + T * double(s.background[c]);
                EXPECT_NEAR(r.color[c], expected, 1e-5 * expected) << "adaptive " << adaptive << " xi " << xi;
            }
            EXPECT_NEAR(r.transmittance, T, 1e-5 * T);
        }
}

// The reference for a smooth field along a z ray: q(z) = a + b sin(z / w), light
// S(z) = exp(-c z); L = int S sigma q e^{-sigma Q(z)} dz with Q the analytic
// antiderivative, by composite Simpson in double (20000 intervals).
struct SmoothRay {
    double a = 0.5, b = 0.4, w = 3, c = 0.07, sigma = 0.1, length = 24;
    double Q(double z) const { return a * z - b * w * (std::cos(z / w) - 1); }
    double q(double z) const { return a + b * std::sin(z / w); }
    double S(double z) const { return std::exp(-c * z); }
    double Reference() const {
        const int n = 20000;
        const double hz = length / n;
        double sum = 0;
        for (int i = 0; i <= n; ++i) {
            const double z = i * hz;
            const double f = S(z) * sigma * q(z) * std::exp(-sigma * Q(z));
            sum += f * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
        }
        return sum * hz / 3;
    }
    // The kernel's in-scattered light (red channel, sun radiance 1, no ambient or background).
    float March(float step, float xi) const {
        MarchSetup s = PlainSetup({32, 32, 32}, float(sigma));
        s.step = step;
        s.light.sunRadiance = {1, 1, 1};
        s.light.ambient = {0, 0, 0};
        s.background = {0, 0, 0};
        auto density = [&](const Vec3& p) { return float(q(p[2])); };
        auto light = [&](const Vec3& p) { return MarchLightSample{float(S(p[2])), 1.0f}; };
        return MarchRay(s, RayAlongZ(8, 8, 0, float(length)), xi, nullptr, density, light).color[0];
    }
};

// Midpoint samples (xi = 0.5) with exact segment transmittance: the error is
// O(Delta^2) for smooth q and light. Observed order from Delta = 2, 1, 0.5.
TEST(March, HalvingTheStepConvergesAtSecondOrder) {
    const SmoothRay ray;
    const double ref = ray.Reference();
    const double e1 = std::fabs(ray.March(2.0f, 0.5f) - ref);
    const double e2 = std::fabs(ray.March(1.0f, 0.5f) - ref);
    const double e3 = std::fabs(ray.March(0.5f, 0.5f) - ref);
    const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e3);
    EXPECT_GT(e3, 1e-6) << "the error must stay above float noise for the order to mean anything";
    EXPECT_GE(order1, 1.7) << e1 << " " << e2;
    EXPECT_GE(order2, 1.7) << e2 << " " << e3;
    EXPECT_LT(std::fabs(ray.March(0.05f, 0.5f) - ref), 2e-4 * ref);
}

// Jittered frames (xi from rand24, stream 3, one frame per step) average to the
// unjittered result: |mean - U| <= 4 s / sqrt(N) + 2 |U - R|, with s the
// frames' standard deviation and R the converged reference.
TEST(March, JitteredFramesAverageToTheUnjitteredResult) {
    const SmoothRay ray;
    const float step = 1.0f;
    const double ref = ray.Reference();
    const double unjittered = ray.March(step, 0.5f);
    const int frames = 256;
    double sum = 0, sum2 = 0;
    for (int f = 0; f < frames; ++f) {
        const float xi = MarchJitter(7, uint32_t(f), 1234);
        ASSERT_GE(xi, 0.0f);
        ASSERT_LT(xi, 1.0f);
        const double v = ray.March(step, xi);
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / frames, sd = std::sqrt(std::max(0.0, sum2 / frames - mean * mean));
    EXPECT_GT(sd, 0.0) << "the frames must differ";
    EXPECT_LE(std::fabs(mean - unjittered), 4 * sd / std::sqrt(double(frames)) + 2 * std::fabs(unjittered - ref));
    EXPECT_LT(std::fabs(mean - ref), 1e-2 * ref);
}

TEST(March, ToneMapIsMonotoneAndMapsZeroToZero) {
    EXPECT_EQ(ReinhardToneMap(0.0f, 1.0f), 0.0f);
    EXPECT_EQ(ReinhardToneMap(0.0f, 7.5f), 0.0f);
    EXPECT_FLOAT_EQ(ReinhardToneMap(1.0f, 1.0f), 0.5f);
    EXPECT_FLOAT_EQ(ReinhardToneMap(1.0f, 3.0f), 0.75f);  // x = 3: 3 / 4
    float previous = 0;
    for (int i = 1; i < 4000; ++i) {
        const float c = std::pow(10.0f, -4.0f + i * 0.002f);
        const float v = ReinhardToneMap(c, 2.0f);
        EXPECT_GE(v, previous) << c;
        EXPECT_LT(v, 1.0f + 1e-7f);
        previous = v;
    }
    EXPECT_EQ(ReinhardToneMap(std::numeric_limits<float>::infinity(), 1.0f), 1.0f);
}

// A thin homogeneous piece of ray [z0 - w, z0 + w] lit only by the point light at
// distance d beside it: L = radiance / max(d^2, r0^2) (1 - e^{-2 sigma q w}),
// to within the spread of D over the piece (w^2 / d^2).
TEST(March, PointLightFallsOffAsInverseSquareWithTheR0Guard) {
    const float w = 0.05f, z0 = 20, q0 = 1, sigmaH = 0.5f, r0 = 4;
    MarchSetup s = PlainSetup({64, 64, 64}, sigmaH);
    s.step = 0.01f;
    s.light.sunRadiance = {0, 0, 0};
    s.light.ambient = {0, 0, 0};
    s.background = {0, 0, 0};
    s.light.pointOn = true;
    s.light.pointRadiance = {1000, 500, 250};
    s.light.pointMinDistance2 = r0 * r0;
    const double slab = 1 - std::exp(-2.0 * sigmaH * q0 * w);
    auto q = [&](const Vec3&) { return q0; };
    for (float d : {0.5f, 2.0f, 4.0f, 8.0f, 16.0f, 30.0f}) {
        s.light.pointPosition = {10 + d, 10, z0};
        const MarchRayResult r = MarchRay(s, RayAlongZ(10, 10, z0 - w, z0 + w), 0.5f, nullptr, q, UnitLight);
        const double falloff = 1.0 / std::max(double(d) * d, double(r0) * r0);
        for (int c = 0; c < 3; ++c) {
            const double expected = s.light.pointRadiance[c] * falloff * slab;
            EXPECT_NEAR(r.color[c], expected, 2e-3 * expected) << "d = " << d;
        }
    }
    // Metres: the falloff uses D h; with h = 10 and the light 8 voxels away, D = 80 m.
    s.voxelSize = s.light.voxelSize = 10;
    s.light.pointPosition = {18, 10, z0};
    const MarchRayResult r = MarchRay(s, RayAlongZ(10, 10, z0 - w, z0 + w), 0.5f, nullptr, q, UnitLight);
    EXPECT_NEAR(r.color[0], 1000.0 / (80.0 * 80.0) * slab, 2e-3 * 1000.0 / 6400.0 * slab);
}

// The point light's phase angle: light straight ahead of the eye (seen through the
// sample) gives P(1), light behind the eye P(-1).
TEST(March, PointLightPhaseUsesTheAngleBetweenViewAndLight) {
    MarchSetup s = PlainSetup({64, 64, 64}, 0.5f);
    s.light.sunRadiance = {0, 0, 0};
    s.light.ambient = {0, 0, 0};
    s.background = {0, 0, 0};
    s.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
    s.light.pointOn = true;
    s.light.pointRadiance = {1, 1, 1};
    s.light.pointMinDistance2 = 1e-6f;
    auto q = [&](const Vec3&) { return 1.0f; };
    s.light.pointPosition = {10, 10, 40};  // ahead
    const float ahead = MarchRay(s, RayAlongZ(10, 10, 19.99f, 20.01f), 0.5f, nullptr, q, UnitLight).color[0];
    s.light.pointPosition = {10, 10, 0};  // behind
    const float behind = MarchRay(s, RayAlongZ(10, 10, 19.99f, 20.01f), 0.5f, nullptr, q, UnitLight).color[0];
    // Same distance (20), so the ratio is the phase ratio P(1) / P(-1) = ((1 + g) / (1 - g))^3 for HG.
    const double g = 0.6, ratio = std::pow((1 + g) / (1 - g), 3);
    EXPECT_NEAR(ahead / behind, ratio, 1e-3 * ratio);
}

// The point light's transmittance: a march through a homogeneous medium ends at
// the light when it is inside the box, at the box exit otherwise.
TEST(March, PointLightMarchStopsAtTheLightOrTheBox) {
    MarchSetup s = PlainSetup({10, 10, 10}, 0.2f);
    auto q = [](const Vec3&) { return 0.5f; };
    s.light.pointPosition = {5, 5, 8};
    EXPECT_NEAR(PointLightMarch(s, {5, 5, 2}, 4, q), std::exp(-0.2 * 0.5 * 6), 1e-6);
    s.light.pointPosition = {5, 5, 100};
    EXPECT_NEAR(PointLightMarch(s, {5, 5, 2}, 4, q), std::exp(-0.2 * 0.5 * 8), 1e-6);
}

// The light march toward the sun converges to a direct fine integral of the same
// trilinear field (TrilinearSample, composite Simpson in double) as n_l grows.
TEST(March, LightMarchConvergesToTheTrilinearIntegral) {
    const Extent3 e{32, 32, 32};
    const std::vector<float> field = BlobField(e);
    MarchSetup s = PlainSetup({32, 32, 32}, 0.3f);
    s.sun = SunDirection(0.6, 0.9);
    auto q = [&](const Vec3& p) { return TrilinearSample(field.data(), e, 0.0f, p); };
    const Vec3 p{9.3f, 11.7f, 6.2f};
    // Exit distance along s, then Simpson over the piecewise-trilinear integrand.
    double exit = 1e30;
    for (int a = 0; a < 3; ++a)
        if (std::fabs(s.sun[a]) > 0) exit = std::min(exit, ((s.sun[a] > 0 ? 32.0 : 0.0) - p[a]) / s.sun[a]);
    const int n = 200000;
    double depth = 0;
    for (int i = 0; i <= n; ++i) {
        const double t = exit * i / n;
        const Vec3 x{float(p[0] + s.sun[0] * t), float(p[1] + s.sun[1] * t), float(p[2] + s.sun[2] * t)};
        depth += TrilinearSample(field.data(), e, 0.0f, x) * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
    }
    depth *= exit / n / 3;
    const double exact = std::exp(-0.3 * depth);
    ASSERT_LT(exact, 0.9) << "the path must cross cloud";
    double previous = 1;
    for (uint32_t nl : {4u, 16u, 64u, 256u}) {
        const double err = std::fabs(SunLightMarch(s, p, nl, q) - exact);
        EXPECT_LT(err, std::max(previous, 1e-6)) << nl;
        previous = err;
    }
    EXPECT_LT(previous, 1e-4);
}

TEST(March, TrilinearSampleReadsVoxelCentresAndZeroOutside) {
    const Extent3 e{2, 1, 1};
    const std::vector<float> v{1.0f, 3.0f};
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 0.0f, {0.5f, 0.5f, 0.5f}), 1.0f);
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 0.0f, {1.5f, 0.5f, 0.5f}), 3.0f);
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 0.0f, {1.0f, 0.5f, 0.5f}), 2.0f);
    // At the x = 0 face: half of voxel 0 and half of the outside tap.
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 0.0f, {0.0f, 0.5f, 0.5f}), 0.5f);
    // At the z = 1 face (one slice): half the inside value.
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 0.0f, {0.5f, 0.5f, 1.0f}), 0.5f);
    EXPECT_FLOAT_EQ(TrilinearSample(v.data(), e, 1.0f, {-5.0f, 0.5f, 0.5f}), 1.0f);
}

TEST(March, RayBoxClipHandlesZeroComponentsAndAnInsideEye) {
    float t0 = 0, t1 = 1e30f;
    ClipRayToBox({0.5f, 0.5f, -2}, {0, 0, 1}, {1, 1, 1}, t0, t1);
    EXPECT_FLOAT_EQ(t0, 2.0f);
    EXPECT_FLOAT_EQ(t1, 3.0f);
    t0 = 0, t1 = 1e30f;
    ClipRayToBox({1.5f, 0.5f, -2}, {0, 0, 1}, {1, 1, 1}, t0, t1);  // outside the x slab, parallel to it
    EXPECT_FALSE(t0 < t1);
    t0 = 0, t1 = 1e30f;
    ClipRayToBox({0.5f, 0.5f, 0.5f}, {0, -0.0f, -1}, {1, 1, 1}, t0, t1);  // inside, -0 component
    EXPECT_FLOAT_EQ(t0, 0.0f);
    EXPECT_FLOAT_EQ(t1, 0.5f);
}

// Pixel rays invert SPEC 8's projection: the ray through a pixel's centre projects back onto it.
TEST(March, PixelRaysProjectBackOntoTheirPixel) {
    CameraSettings cam;
    cam.eye = {3, -4, 5};
    cam.target = {10, 2, 1};
    cam.fovDeg = 40;
    const CameraFrame f = MakeCameraFrame(cam, 40, 30);
    for (uint32_t y : {0u, 7u, 29u})
        for (uint32_t x : {0u, 13u, 39u}) {
            const PixelDirection d = PixelRayDirection(f, x, y);
            const Projected p = Project(f, MarchAlong(f.eye, d.dir, 10.0f));
            EXPECT_NEAR(p.px, x + 0.5f, 1e-3f);
            EXPECT_NEAR(p.py, y + 0.5f, 1e-3f);
            EXPECT_NEAR(p.depth, 10.0f * d.cosForward, 1e-4f);
        }
}

// ---- The CPU backend ----------------------------------------------------------

TEST(MarchCpu, EmptyVolumeGivesTheBackgroundExactly) {
    MarchCase c;
    c.q.assign(c.grid.Count(), 0.0f);
    c.params = CameraParams(c.grid, {-10, 4, 12}, {8, 8, 8}, 24, 18);
    for (bool skipping : {false, true}) {
        c.params.skipping = skipping;
        const MarchImage im = RenderCpu(c);
        for (size_t i = 0; i < im.rgb.size(); ++i) ASSERT_EQ(im.rgb[i], c.params.setup.background[i % 3]) << i;
    }
}

// Looking straight down (degenerate up) through the centre of a full volume of q = 1
// with T = 1: between voxel centres q = 1, in the half voxel at each face it ramps
// linearly from 1/2 to 1 (taps outside read 0), so the optical depth is
// sigma h (nz - 1/4); at step 1/2 the segments end on the kinks and the midpoint
// rule is exact. C = (sun + ambient)(1 - T) + T background.
TEST(MarchCpu, FullVolumeSeenHeadOnMatchesTheTrilinearOpticalDepth) {
    MarchCase c;
    c.grid = {8, 8, 12};
    c.q.assign(c.grid.Count(), 1.0f);
    c.params = CameraParams(c.grid, {4, 4, 40}, {4, 4, 0}, 1, 1, 0.07f);
    c.params.setup.light.phase.kind = PhaseKind::None;
    c.params.setup.epsilon = 0;
    c.params.setup.step = 0.5f;
    const MarchImage im = RenderCpu(c);
    const double T = std::exp(-0.07 * (12 - 0.25));
    for (int ch = 0; ch < 3; ++ch) {
        const MarchSetup& s = c.params.setup;
        const double expected =
            (double(s.light.sunRadiance[ch]) + s.light.ambient[ch]) * (1 - T) + T * s.background[ch];
        EXPECT_NEAR(im.rgb[ch], expected, 1e-5 * expected);
    }
    EXPECT_EQ(im.stats.rays, 1u);
    EXPECT_EQ(im.stats.samples, 24u);
}

// The CPU's padded sampler and light functors against the kernel run here with
// the canonical TrilinearSample: the same image to float rounding.
TEST(MarchCpu, MatchesTheKernelWithCanonicalSamplers) {
    MarchCase c;
    c.grid = {32, 32, 24};
    c.q = BlobField(c.grid);
    c.T.resize(c.grid.Count());
    for (size_t i = 0; i < c.T.size(); ++i) c.T[i] = 0.3f + 0.7f * float((i * 2654435761u) % 1000) / 1000.0f;
    c.params = CameraParams(c.grid, {-20, -10, 30}, {16, 16, 10}, 32, 24);
    c.params.skipping = false;
    for (MarchLightSource source : {MarchLightSource::Shade, MarchLightSource::March}) {
        c.params.light = source;
        c.params.lightSteps = 6;
        c.params.setup.light.pointOn = true;
        c.params.setup.light.pointPosition = {12, 20, 14};
        c.params.setup.light.pointRadiance = {30, 30, 40};
        c.params.setup.light.pointMinDistance2 = 1;
        const MarchImage im = RenderCpu(c);
        auto q = [&](const Vec3& p) { return TrilinearSample(c.q.data(), c.grid, 0.0f, p); };
        auto light = [&](const Vec3& p) {
            MarchLightSample l;
            l.sun = source == MarchLightSource::Shade ? TrilinearSample(c.T.data(), c.grid, 1.0f, p)
                                                      : SunLightMarch(c.params.setup, p, 6, q);
            l.point = PointLightMarch(c.params.setup, p, 6, q);
            return l;
        };
        double worst = 0;
        for (uint32_t y = 0; y < 24; ++y)
            for (uint32_t x = 0; x < 32; ++x) {
                const MarchRayGeometry ray =
                    MakePixelRay(c.params.camera, c.params.origin, 1.0f, c.params.setup.size, x, y);
                const MarchRayResult r = MarchRay(c.params.setup, ray, 0.5f, nullptr, q, light);
                for (int ch = 0; ch < 3; ++ch)
                    worst = std::max(worst, double(std::fabs(r.color[ch] - im.rgb[3 * (x + 32 * y) + ch])));
            }
        EXPECT_LT(worst, 1e-5) << int(source);
    }
}

// Skipping empty bricks changes no sample: the same image, for fixed and
// adaptive steps, with and without jitter, for several brick sizes.
TEST(MarchCpu, SkippingOnAndOffGiveTheSameImage) {
    MarchCase c;
    c.grid = {32, 32, 24};
    c.q = BlobField(c.grid);
    c.params = CameraParams(c.grid, {-20, -10, 30}, {16, 16, 10}, 40, 30);
    for (bool adaptive : {false, true})
        for (bool jitter : {false, true})
            for (uint32_t brick : {1u, 4u, 8u}) {
                c.params.setup.adaptive = adaptive;
                c.params.setup.kappa = 0.05f;
                c.params.setup.adaptiveStart = 20;
                c.params.jitter = jitter;
                c.params.frame = 3;
                c.params.brick = brick;
                c.params.skipping = false;
                const MarchImage off = RenderCpu(c);
                c.params.skipping = true;
                const MarchImage on = RenderCpu(c);
                double worst = 0;
                for (size_t i = 0; i < on.rgb.size(); ++i)
                    worst = std::max(worst, double(std::fabs(on.rgb[i] - off.rgb[i])));
                EXPECT_LE(worst, 1e-6) << adaptive << jitter << brick;
                EXPECT_GT(on.stats.bricksSkipped, 0u);
                EXPECT_GT(on.stats.emptyBricks, 0u);
                EXPECT_LT(on.stats.samples, off.stats.samples);
                EXPECT_EQ(on.stats.lightSamples, off.stats.lightSamples);
            }
}

// No NaN or Inf: the camera inside the volume looking straight up and down
// (degenerate up), sigma 0 and 1e6, empty and full volumes, both light sources.
TEST(MarchCpu, NoNanOrInfAtTheExtremes) {
    const Extent3 e{12, 10, 9};
    const std::vector<std::vector<float>> fields = {std::vector<float>(e.Count(), 0.0f),
                                                    std::vector<float>(e.Count(), 1.0f), BlobField(e)};
    const std::array<double, 3> inside{6, 5, 4.5};
    const std::vector<std::array<double, 3>> targets = {{6, 5, 100}, {6, 5, -100}, {50, 5, 4.5}};
    for (const auto& field : fields)
        for (const auto& target : targets)
            for (float sigma : {0.0f, 1e6f, 0.05f})
                for (MarchLightSource source : {MarchLightSource::Shade, MarchLightSource::March}) {
                    MarchCase c;
                    c.grid = e;
                    c.q = field;
                    c.params = CameraParams(e, inside, target, 9, 7, sigma);
                    c.params.setup.sigmaH = MarchOpticalDepthPerVoxel(sigma, 1.0f);
                    c.params.light = source;
                    c.params.setup.powder = true;
                    c.params.setup.light.pointOn = true;
                    c.params.setup.light.pointPosition = {6, 5, 4.5f};  // at the eye, inside the cloud
                    c.params.setup.light.pointRadiance = {1e3f, 1e3f, 1e3f};
                    c.params.setup.light.pointMinDistance2 = 0.25f;
                    const MarchImage im = RenderCpu(c, 1);
                    ASSERT_TRUE(AllFinite(im.rgb)) << "sigma " << sigma;
                    for (float v : im.rgb) ASSERT_GE(v, 0.0f);
                    if (sigma == 0.0f) {
                        for (size_t i = 0; i < im.rgb.size(); ++i)
                            ASSERT_EQ(im.rgb[i], c.params.setup.background[i % 3]);
                    }
                }
}

// ---- Benchmark (run by hand: --gtest_also_run_disabled_tests --gtest_filter='*MarchBench*') ----
// reports/march/march.md: a 128^3 cumulus-like field of Gaussian puffs (flat
// bottoms), T from the CPU shade stage, 1280x720, 7 frames per setting; prints
// wall and process CPU ms per frame (median, min, max) and samples per second.
namespace bench {

double CpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

std::vector<float> CumulusField(const Extent3& e) {
    std::vector<float> q(e.Count(), 0.0f);
    Pcg32 rng(11);
    for (int b = 0; b < 60; ++b) {
        const double cx = rng.NextDouble() * e.nx, cy = rng.NextDouble() * e.ny;
        const double cz = (0.3 + 0.25 * rng.NextDouble()) * e.nz, r = 5 + 9 * rng.NextDouble();
        const double base = 0.28 * e.nz;
        for (uint32_t k = uint32_t(std::max(base, cz - 3 * r)); k < std::min<double>(e.nz, cz + 3 * r); ++k)
            for (uint32_t j = uint32_t(std::max(0.0, cy - 3 * r)); j < std::min<double>(e.ny, cy + 3 * r); ++j)
                for (uint32_t i = uint32_t(std::max(0.0, cx - 3 * r)); i < std::min<double>(e.nx, cx + 3 * r); ++i) {
                    const double dx = i + 0.5 - cx, dy = j + 0.5 - cy, dz = (k + 0.5 - cz) * 1.3;
                    const double v = 1.6 * std::exp(-(dx * dx + dy * dy + dz * dz) / (2 * r * r)) - 0.35;
                    float& out = q[VoxelIndex(e, i, j, k)];
                    out = std::max(out, float(std::clamp(v, 0.0, 1.0)));
                }
    }
    return q;
}

}  // namespace bench

TEST(MarchBench, DISABLED_Cumulus128At720p) {
    const Extent3 e{128, 128, 128};
    const std::vector<float> field = bench::CumulusField(e);
    cpu::BackendCpu backend(2);
    auto q = test::MakeFilled(backend, BufferFormat::F32, e, field);
    auto T = test::MakeBuffer(backend, BufferFormat::F32, e);
    ShadeParams sp;
    sp.sun = SunDirection(0.7, 0.5);
    sp.sigma = 0.02f;
    sp.voxelSize = 50;
    ASSERT_TRUE(backend.Shade(sp, *q, *T).has_value());
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, 1280, 720});
    CameraSettings cam;
    cam.eye = {-1500, -1500, 2500};
    cam.target = {3200, 3200, 2800};
    cam.fovDeg = 60;
    cam.nearPlane = 1;
    cam.farPlane = 50000;
    auto base = [&] {
        MarchParams p;
        p.camera = MakeCameraFrame(cam, 1280, 720);
        p.setup.size = {128, 128, 128};
        p.setup.voxelSize = p.setup.light.voxelSize = 50;
        p.setup.step = 0.5f;
        p.setup.sigmaH = MarchOpticalDepthPerVoxel(0.02f, 50);
        p.setup.epsilon = 0.01f;
        p.setup.sun = sp.sun;
        p.setup.light.sunRadiance = {1.6f, 1.44f, 1.2f};
        p.setup.light.ambient = {0.22f, 0.26f, 0.34f};
        p.setup.background = {0.42f, 0.58f, 0.85f};
        p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
        p.alpha = 0.5f;
        return p;
    };
    struct Row {
        const char* name;
        std::function<void(MarchParams&)> edit;
    };
    const std::vector<Row> rows = {
        {"shade, skip, HG (baseline)", [](MarchParams&) {}},
        {"skipping off", [](MarchParams& p) { p.skipping = false; }},
        {"adaptive (kappa 0.02, t_a 64)",
         [](MarchParams& p) { p.setup.adaptive = true, p.setup.kappa = 0.02f, p.setup.adaptiveStart = 64; }},
        {"light march n_l 6", [](MarchParams& p) { p.light = MarchLightSource::March, p.lightSteps = 6; }},
        {"phase none", [](MarchParams& p) { p.setup.light.phase.kind = PhaseKind::None; }},
        {"jitter", [](MarchParams& p) { p.jitter = true; }},
        {"step 1.0", [](MarchParams& p) { p.setup.step = 1.0f; }},
        {"brick 4", [](MarchParams& p) { p.brick = 4; }},
        {"brick 16", [](MarchParams& p) { p.brick = 16; }},
        {"epsilon 0 (no early stop)", [](MarchParams& p) { p.setup.epsilon = 0; }},
    };
    const char* only = std::getenv("MARCH_BENCH_ROWS");  // e.g. "1": the first row only
    const size_t count = only ? std::min(rows.size(), size_t(std::atoi(only))) : rows.size();
    for (size_t r = 0; r < count; ++r) {
        const Row& row = rows[r];
        MarchParams p = base();
        row.edit(p);
        std::vector<double> wall, cpu;
        MarchStats stats;
        for (int f = 0; f < 7; ++f) {
            p.frame = uint32_t(f);
            const double c0 = bench::CpuMs();
            const auto t0 = std::chrono::steady_clock::now();
            const MarchInputs in{q.get(), q.get(), T.get()};
            ASSERT_TRUE(backend.RenderMarch(p, in, *image, &stats).has_value());
            wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            cpu.push_back(bench::CpuMs() - c0);
        }
        std::sort(wall.begin(), wall.end());
        std::sort(cpu.begin(), cpu.end());
        std::printf(
            "%-32s wall %8.1f [%7.1f %7.1f] ms  cpu %8.1f [%7.1f %7.1f] ms  rays %8llu  samples %10llu  light %9llu  "
            "skipped %9llu  empty bricks %llu/%llu  Msamples/cpu-s %.1f\n",
            row.name, wall[3], wall[0], wall[6], cpu[3], cpu[0], cpu[6], (unsigned long long)stats.rays,
            (unsigned long long)stats.samples, (unsigned long long)stats.lightSamples,
            (unsigned long long)stats.bricksSkipped, (unsigned long long)stats.emptyBricks,
            (unsigned long long)stats.bricks, stats.samples / (cpu[3] * 1e3));
    }
}

}  // namespace
}  // namespace cb
