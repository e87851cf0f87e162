// The exact haze reference (reference/HazeReference.h): the cloudless slab against the closed form of the
// single-scattering integral, a sun at or below the horizon, a homogeneous cloud layer (tiled) that makes the sun's
// and the view's transmittance constants worked out by hand, and the composite rule converging (against a finer step
// and against a brute-force midpoint sum over the whole segment that takes no closed-form shortcut). Expected values
// come from closed forms derived here, never from the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "core/math/March.h"
#include "core/math/Random.h"
#include "reference/HazeReference.h"
#include "reference/Trilinear.h"

namespace cb {
namespace {

constexpr double kHazeDeg = std::numbers::pi / 180;

// Grid origin and voxel size of every case: world = origin + h * (voxel units), so the units are exercised.
constexpr std::array<float, 3> kHazeOrigin{10, -4, 3};
constexpr float kHazeH = 2;

// Params for a camera at `eye` looking at `target` (both in voxel units).
ref::HazeReferenceParams HazeParams(std::array<double, 3> eye, std::array<double, 3> target, double farMetres,
                                    uint32_t w, uint32_t h, double fovDeg = 40) {
    CameraSettings cam;
    for (int a = 0; a < 3; ++a) {
        cam.eye[a] = kHazeOrigin[a] + kHazeH * eye[a];
        cam.target[a] = kHazeOrigin[a] + kHazeH * target[a];
    }
    cam.up = {0, 0, 1};
    cam.fovDeg = fovDeg;
    cam.nearPlane = 0.01;
    cam.farPlane = farMetres;
    ref::HazeReferenceParams p;
    p.camera = MakeCameraFrame(cam, w, h);
    p.origin = kHazeOrigin;
    p.voxelSize = kHazeH;
    p.sun = SunDirection(30 * kHazeDeg, 20 * kHazeDeg);
    p.sunRadiance = {3.0f, 2.4f, 1.8f};
    p.extinction = 0.01;  // sigma = 0.02 per voxel edge: e^-1 over 50 voxels
    p.g = 0.7;
    p.threads = 2;
    return p;
}

ref::HazeReferenceResult HazeRun(const ref::HazeReferenceParams& p, const Extent3& e, const std::vector<float>& q) {
    auto r = ref::RenderHazeReference(p, e, q);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    return r ? std::move(*r) : ref::HazeReferenceResult{};
}
std::vector<float> HazeRender(const ref::HazeReferenceParams& p, const Extent3& e, const std::vector<float>& q) {
    return HazeRun(p, e, q).image;
}

// One pixel's ray in voxel units and its haze segment [t0, t1]: the view range [near, far] / (h cosForward) cut to
// 0 <= z <= nz/2 (empty: t0 >= t1).
struct HazeRay {
    std::array<double, 3> o, d;
    double t0, t1;
};
HazeRay HazeSegment(const ref::HazeReferenceParams& p, const Extent3& e, uint32_t x, uint32_t y) {
    const PixelDirection pd = PixelRayDirection(p.camera, x, y);
    HazeRay r;
    for (int a = 0; a < 3; ++a) {
        r.o[a] = (double(p.camera.eye[a]) - p.origin[a]) / p.voxelSize;
        r.d[a] = pd.dir[a];
    }
    r.t0 = p.camera.nearPlane / (p.voxelSize * double(pd.cosForward));
    r.t1 = p.camera.farPlane / (p.voxelSize * double(pd.cosForward));
    const double top = e.nz / 2.0;
    if (r.d[2] == 0) {
        if (r.o[2] < 0 || r.o[2] > top) r.t1 = r.t0;
    } else {
        // Where the ray crosses the ground and the top; it is in the slab between them.
        const double tGround = -r.o[2] / r.d[2], tTop = (top - r.o[2]) / r.d[2];
        r.t0 = std::max(r.t0, std::min(tGround, tTop));
        r.t1 = std::min(r.t1, std::max(tGround, tTop));
    }
    return r;
}

// Henyey-Greenstein's P^ = (1 - g^2) / (1 + g^2 - 2 g cos)^1.5 between the ray and the sun.
double HazePhase(const ref::HazeReferenceParams& p, const std::array<double, 3>& d) {
    const double n = std::sqrt(double(p.sun[0]) * p.sun[0] + double(p.sun[1]) * p.sun[1] + double(p.sun[2]) * p.sun[2]);
    const double c = (d[0] * p.sun[0] + d[1] * p.sun[1] + d[2] * p.sun[2]) / n;
    return (1 - p.g * p.g) / std::pow(1 + p.g * p.g - 2 * p.g * c, 1.5);
}

// sunRadiance-free value of a pixel without clouds: P^(d.s) (e^{-sigma t0} - e^{-sigma t1}) (the integral of
// sigma e^{-sigma t} with V = Tview = 1), 0 for an empty segment.
double HazeClosedForm(const ref::HazeReferenceParams& p, const HazeRay& r) {
    if (!(r.t0 < r.t1)) return 0;
    const double sigma = p.extinction * p.voxelSize;
    return HazePhase(p, r.d) * (std::exp(-sigma * r.t0) - std::exp(-sigma * r.t1));
}

// Every pixel is factor * sunRadiance * HazeClosedForm, to `rel` relative (float rounding of the image and of
// the ray's direction); returns how many pixels see haze.
int ExpectHazeClosedForm(const ref::HazeReferenceParams& p, const Extent3& e, const std::vector<float>& image,
                         double factor, double rel, const char* name) {
    const uint32_t W = p.camera.width, H = p.camera.height;
    EXPECT_EQ(image.size(), 3u * W * H);
    if (image.size() != 3u * W * H) return 0;
    int lit = 0;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const double v = factor * HazeClosedForm(p, HazeSegment(p, e, x, y));
            lit += v > 0;
            for (int c = 0; c < 3; ++c) {
                const double expected = p.sunRadiance[c] * v;
                EXPECT_NEAR(image[c + 3 * (x + W * y)], expected, rel * expected + 1e-30)
                    << name << " pixel " << x << "," << y << " channel " << c;
            }
        }
    return lit;
}

TEST(HazeReference, NoCloudsIsTheClosedForm) {
    const Extent3 e{16, 16, 16};  // the haze: 0 <= z <= 8
    const std::vector<float> q(e.Count(), 0.0f);
    struct Case {
        const char* name;
        std::array<double, 3> eye, target;
        double far;
    } cases[] = {
        // Inside the haze looking level: the middle rows end at the far plane (100 m = 50 voxels / cosForward),
        // the top rows leave through z = 8, the bottom rows reach the ground.
        {"inside, level", {4, 6, 4}, {20, 10, 4}, 100},
        // Above the slab looking down 45 degrees: enters at z = 8, ends on the ground z = 0.
        {"above, down", {-3, 5, 14}, {7, 5, 4}, 1e4},
        // On z = 1 looking 30 degrees up: starts at the eye, leaves at z = 8.
        {"below, up", {2, 3, 1}, {2 + 10 * std::cos(30 * kHazeDeg), 3, 1 + 10 * std::sin(30 * kHazeDeg)}, 1e4},
    };
    for (const Case& k : cases) {
        ref::HazeReferenceParams p = HazeParams(k.eye, k.target, k.far, 24, 16);
        p.cloudSigma = 0.3;  // no clouds to attenuate
        EXPECT_GT(ExpectHazeClosedForm(p, e, HazeRender(p, e, q), 1.0, 1e-5, k.name), 100) << k.name;
    }
    // The same with clouds of zero extinction, tiled: V = Tview = 1 again.
    std::vector<float> cloudy(e.Count(), 0.0f);
    for (size_t v = cloudy.size() / 3; v < cloudy.size(); v += 7) cloudy[v] = 0.9f;
    ref::HazeReferenceParams p = HazeParams({4, 6, 4}, {20, 10, 4}, 100, 24, 16);
    p.tiling = true;
    p.cloudSigma = 0;
    ExpectHazeClosedForm(p, e, HazeRender(p, e, cloudy), 1.0, 1e-5, "zero cloud extinction");
}

TEST(HazeReference, SunAtOrBelowTheHorizonGivesZero) {
    const Extent3 e{8, 8, 8};
    std::vector<float> q(e.Count(), 0.0f);
    for (size_t v = 0; v < q.size(); v += 3) q[v] = 0.5f;
    for (double elevation : {-5.0, 0.0}) {
        for (bool tiling : {false, true}) {
            ref::HazeReferenceParams p = HazeParams({-2, 4, 2}, {8, 4, 2}, 1e3, 12, 8);
            p.sun = SunDirection(elevation * kHazeDeg, 0.3);
            p.cloudSigma = 0.5;
            p.tiling = tiling;
            const std::vector<float> image = HazeRender(p, e, q);
            ASSERT_EQ(image.size(), 3u * 12 * 8);
            for (float v : image) EXPECT_EQ(v, 0.0f) << "elevation " << elevation << " tiling " << tiling;
        }
    }
}

// q = c in layers k >= nz/2 + 1 (centres z >= nz/2 + 3/2), 0 below, tiled: the field depends on z alone, 0 for
// z <= nz/2 + 1/2 (so in the whole haze), rising linearly to c at nz/2 + 3/2, c up to the top layer's centre
// nz - 1/2, then falling toward 0 at nz + 1/2 (the tap above reads 0), reaching c/2 at the top face nz. Its column
// over [0, nz]: c/2 (ramp) + c (nz/2 - 2) (plateau) + (c + c/2)/2 * 1/2 = 3c/8 (half ramp) = c (nz/2 - 9/8).
// Every haze point lies below the layer, so V = exp(-sc column / s_z) everywhere.
constexpr uint32_t kLayerNz = 16;
constexpr double kLayerC = 0.5;
constexpr double kLayerColumn = kLayerC * (kLayerNz / 2.0 - 9.0 / 8.0);  // 6.875 c

std::vector<float> HazeCloudLayer(const Extent3& e) {
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t k = e.nz / 2 + 1; k < e.nz; ++k)
        for (size_t v = 0; v < size_t(e.nx) * e.ny; ++v) q[v + size_t(e.nx) * e.ny * k] = float(kLayerC);
    return q;
}

TEST(HazeReference, CloudLayerShadowIsAConstantFactor) {
    const Extent3 e{8, 8, kLayerNz};
    const std::vector<float> q = HazeCloudLayer(e);
    struct Case {
        const char* name;
        std::array<double, 3> eye, target;
        double far;
    } cases[] = {
        {"level", {3, 2, 3}, {20, 9, 3}, 120},
        {"up", {3, 2, 3}, {8, 7, 8}, 1e4},
        {"down", {1, 5, 6}, {9, 3, 1}, 1e4},
    };
    for (double elevation : {50.0, 25.0}) {
        for (const Case& k : cases) {
            ref::HazeReferenceParams p = HazeParams(k.eye, k.target, k.far, 12, 8);
            p.sun = SunDirection(elevation * kHazeDeg, 200 * kHazeDeg);
            p.tiling = true;
            p.cloudSigma = 0.2;  // sc = 0.4 per voxel edge at q = 1
            const double sc = p.cloudSigma * p.voxelSize;
            const double V = std::exp(-sc * kLayerColumn / std::sin(elevation * kHazeDeg));
            EXPECT_GT(ExpectHazeClosedForm(p, e, HazeRender(p, e, q), V, 1e-5, k.name), 40) << k.name;
        }
    }
}

TEST(HazeReference, LookingDownThroughTheLayer) {
    const Extent3 e{8, 8, kLayerNz};
    const std::vector<float> q = HazeCloudLayer(e);
    // From z = 20 looking 60 degrees down: every view ray crosses the whole layer (z from 16 down to 8.5), a
    // vertical column stretched by 1 / |d_z|, before it reaches the haze: Tview = exp(-sc column / |d_z|), and
    // V as above.
    ref::HazeReferenceParams p =
        HazeParams({2, 3, 20}, {2 + std::cos(60 * kHazeDeg), 3, 20 - std::sin(60 * kHazeDeg)}, 1e4, 12, 8);
    p.sun = SunDirection(40 * kHazeDeg, 0.5);
    p.tiling = true;
    p.cloudSigma = 0.2;
    const double sc = p.cloudSigma * p.voxelSize;
    const double V = std::exp(-sc * kLayerColumn / std::sin(40 * kHazeDeg));
    const std::vector<float> image = HazeRender(p, e, q);
    ASSERT_EQ(image.size(), 3u * 12 * 8);
    for (uint32_t y = 0; y < 8; ++y)
        for (uint32_t x = 0; x < 12; ++x) {
            const HazeRay r = HazeSegment(p, e, x, y);
            ASSERT_LT(r.d[2], 0);
            const double T = std::exp(-sc * kLayerColumn / -r.d[2]);
            const double v = V * T * HazeClosedForm(p, r);
            ASSERT_GT(v, 0);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(image[c + 3 * (x + 12 * y)], p.sunRadiance[c] * v, 1e-5 * p.sunRadiance[c] * v)
                    << x << "," << y;
        }
}

// A random small cloud (untiled) straddling the haze's top; its support is x, y in [4.5, 11.5], z up to 11.5.
std::vector<float> HazeRandomCloud(const Extent3& e) {
    std::vector<float> q(e.Count(), 0.0f);
    Pcg32 rng(20240611);
    for (uint32_t k = 5; k < 11; ++k)
        for (uint32_t j = 5; j < 11; ++j)
            for (uint32_t i = 5; i < 11; ++i) q[VoxelIndex(e, i, j, k)] = float(rng.Uniform(0, 1));
    return q;
}

// The integral by brute force, with the exact transmittances (the tracer the test builds itself) and a plain
// midpoint sum of step 1/64 over the WHOLE segment: sum sigma e^{-sigma t} V(t) Tview(t) dt at midpoints.
std::vector<double> HazeBruteForce(const ref::HazeReferenceParams& p, const Extent3& e, const std::vector<float>& q) {
    auto tracer = ref::TrilinearDepthTracer::Create(e, q, 2);
    EXPECT_TRUE(tracer.has_value());
    if (!tracer) return {};
    const ref::TrilinearDepthTracer& exact = **tracer;
    const uint32_t W = p.camera.width, H = p.camera.height;
    const double sigma = p.extinction * p.voxelSize, sc = p.cloudSigma * p.voxelSize, inf = HUGE_VAL;
    const ref::Point3d s{p.sun[0], p.sun[1], p.sun[2]};
    std::vector<double> out(size_t(W) * H, 0.0);
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const HazeRay r = HazeSegment(p, e, x, y);
            if (!(r.t0 < r.t1)) continue;
            const int n = int(std::ceil((r.t1 - r.t0) * 64));
            const double dt = (r.t1 - r.t0) / n;
            double viewDepth = exact.Integrate(r.o, r.d, 0, r.t0), tPrev = r.t0, sum = 0;
            for (int i = 0; i < n; ++i) {
                const double t = r.t0 + (i + 0.5) * dt;
                viewDepth += exact.Integrate(r.o, r.d, tPrev, t);
                tPrev = t;
                const ref::Point3d at{r.o[0] + t * r.d[0], r.o[1] + t * r.d[1], r.o[2] + t * r.d[2]};
                const double V = std::exp(-sc * exact.Integrate(at, s, 0, inf));
                sum += sigma * std::exp(-sigma * t) * V * std::exp(-sc * viewDepth) * dt;
            }
            out[x + size_t(W) * y] = HazePhase(p, r.d) * sum;
        }
    return out;
}

TEST(HazeReference, CompositeRuleConverges) {
    const Extent3 e{16, 16, 16};
    const std::vector<float> q = HazeRandomCloud(e);
    struct Case {
        const char* name;
        std::array<double, 3> eye, target;
    } cases[] = {
        // In the haze looking level across the cloud: the segment runs from x = -6 to the far plane far past the
        // swept support, so closed pieces lie on both sides of the composite part.
        {"across", {-6, 7, 4}, {10, 9, 5}},
        // Above the cloud looking down through it at the haze (Tview < 1 on entering the haze).
        {"through", {2, 3, 18}, {9, 9, 4}},
    };
    for (const Case& k : cases) {
        ref::HazeReferenceParams p = HazeParams(k.eye, k.target, 110, 12, 8, 50);
        p.sun = SunDirection(35 * kHazeDeg, 160 * kHazeDeg);  // toward -x: the cloud's shadow falls toward +x
        p.cloudSigma = 0.4;                                   // sc = 0.8 per voxel edge at q = 1
        const ref::HazeReferenceResult coarseRun = HazeRun(p, e, q);
        const std::vector<float>& coarse = coarseRun.image;
        p.stepVoxels = 0.0625;
        const std::vector<float> fine = HazeRender(p, e, q);
        const std::vector<double> brute = HazeBruteForce(p, e, q);
        ASSERT_EQ(coarse.size(), 3 * brute.size());
        ASSERT_EQ(fine.size(), 3 * brute.size());
        // Errors against the image's largest value (a channel-0 pixel).
        double scale = 0, fineErr = 0, bruteErr = 0, fineBruteErr = 0;
        for (size_t v = 0; v < brute.size(); ++v) scale = std::max(scale, brute[v] * p.sunRadiance[0]);
        for (size_t v = 0; v < brute.size(); ++v)
            for (int c = 0; c < 3; ++c) {
                const double b = brute[v] * p.sunRadiance[c];
                fineErr = std::max(fineErr, std::fabs(double(coarse[3 * v + c]) - fine[3 * v + c]));
                bruteErr = std::max(bruteErr, std::fabs(coarse[3 * v + c] - b));
                fineBruteErr = std::max(fineBruteErr, std::fabs(fine[3 * v + c] - b));
            }
        // The closed pieces must have taken a good part of the segments (measured: the composite rule's nodes are
        // 21% ("across") and 47% ("through") of those of step 1/4 over every whole segment).
        uint64_t whole = 0;
        for (uint32_t y = 0; y < p.camera.height; ++y)
            for (uint32_t x = 0; x < p.camera.width; ++x) {
                const HazeRay r = HazeSegment(p, e, x, y);
                if (r.t0 < r.t1) whole += uint64_t(std::ceil((r.t1 - r.t0) / 0.25));
            }
        std::printf("%s: scale %.4g, |1/4 - 1/16| %.2g, |1/4 - brute| %.2g, |1/16 - brute| %.2g, nodes %llu of %llu\n",
                    k.name, scale, fineErr / scale, bruteErr / scale, fineBruteErr / scale,
                    (unsigned long long)coarseRun.samples, (unsigned long long)whole);
        EXPECT_GT(scale, 0.05) << k.name;
        EXPECT_LT(coarseRun.samples, whole * 3 / 4) << k.name;
        // Measured (GCC 13, x86-64): |1/4 - 1/16| 2.2e-5 and 4.2e-5 of the scale, |1/4 - brute| 2.4e-5 and 4.4e-5,
        // |1/16 - brute| 1.7e-6 and 2.7e-6 ("across", "through"): second order (16x from 1/4 to 1/16). The
        // bounds are about 4x the larger, and the error must fall by 6x at least from step 1/4 to 1/16.
        EXPECT_LT(fineErr, 2e-4 * scale) << k.name;
        EXPECT_LT(bruteErr, 2e-4 * scale) << k.name;
        EXPECT_LT(fineBruteErr, 1.2e-5 * scale) << k.name;
        EXPECT_GT(bruteErr, 6 * fineBruteErr) << k.name;
    }
}

TEST(HazeReference, RejectsBadInput) {
    const Extent3 e{4, 4, 4};
    const std::vector<float> q(e.Count(), 0.0f);
    ref::HazeReferenceParams p = HazeParams({0, 0, 1}, {4, 4, 1}, 100, 4, 4);
    EXPECT_FALSE(ref::RenderHazeReference(p, e, std::vector<float>(5, 0.0f)).has_value());
    p.stepVoxels = 0;
    EXPECT_FALSE(ref::RenderHazeReference(p, e, q).has_value());
    p.stepVoxels = 0.25;
    p.g = 1;
    EXPECT_FALSE(ref::RenderHazeReference(p, e, q).has_value());
    p.g = 0.5;
    p.sun = {0, 0, 0};
    EXPECT_FALSE(ref::RenderHazeReference(p, e, q).has_value());
}

}  // namespace
}  // namespace cb
