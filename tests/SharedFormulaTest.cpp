// Independent tests of the formulas every backend takes from
// core/ (host-only code, or code with a GLSL twin that the twin test only
// compares with this C++). A backend-vs-CPU comparison cannot see a bug here,
// so every expected value below is hand-worked, a published vector, or a slow
// path written differently (integer-exact references, plain loops).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Rules.h"
#include "core/math/Shading.h"
#include "core/math/Splat.h"
#include "core/pipeline/Backend.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/SplatFrame.h"
#include "tests/LowBias32Inverse.h"

namespace cb {
namespace {

// ---- 1a. lowbias32 and the stream keys -----------------------------------------

// Test that the published inverse undoes LowBias32 (and the reverse) on a
// spread of inputs: any change of a constant or a shift breaks it.
TEST(SharedFormula, LowBias32InvertsWithThePublishedInverse) {
    Pcg32 rng(17);
    for (uint32_t x : {0u, 1u, 2u, 0x7fffffffu, 0x80000000u, 0xffffffffu, 0x9E3779B9u}) {
        EXPECT_EQ(test::LowBias32Inverse(LowBias32(x)), x);
        EXPECT_EQ(LowBias32(test::LowBias32Inverse(x)), x);
    }
    for (int n = 0; n < 200000; ++n) {
        const uint32_t x = rng.NextU32();
        ASSERT_EQ(test::LowBias32Inverse(LowBias32(x)), x) << x;
        ASSERT_EQ(LowBias32(test::LowBias32Inverse(x)), x) << x;
    }
}

// Test StreamKey(seed, step, stream) = LB(seed ^ LB(step*4 + stream + 0x9E3779B9))
// against values worked out with Python's integers (masking to 32 bits); the
// inner argument is shown where it matters.
TEST(SharedFormula, StreamKeysByHand) {
    EXPECT_EQ(LowBias32(0x9E3779B9u), 0x01fce552u);  // the inner hash of step 0, stream 0
    EXPECT_EQ(StreamKey(0, 0, 0), 0xae6f80f1u);       // = LB(0x01fce552)
    EXPECT_EQ(LowBias32(0x01fce552u), 0xae6f80f1u);
    EXPECT_EQ(StreamKey(0, 0, 3), 0x85a43057u);  // inner 0x9e3779bc
    EXPECT_EQ(StreamKey(1, 0, 0), 0xa07c7a97u);  // seed enters outside the inner hash
    EXPECT_EQ(StreamKey(9, 0, 0), 0xd6d63a2au);
    EXPECT_EQ(StreamKey(5, 0xFFFFFFFFu, 1), 0x8102aaeeu);  // inner wraps: 0xfffffffc + 1 + 0x9E3779B9 = 0x9e3779b6
    EXPECT_EQ(StreamKey(0xFFFFFFFFu, 0xFFFFFFFFu, 3), 0xca4d4754u);
    // rand24 is the top 24 bits of LB(voxel ^ key): with the inverse, a chosen draw at a chosen voxel.
    const uint32_t key = StreamKey(123, 7, kStreamHumidity);
    const uint32_t voxel = test::LowBias32Inverse((128000u << 8) | 0x5au) ^ key;
    EXPECT_EQ(Rand24FromKey(key, voxel), 128000u);
    EXPECT_EQ(Rand24(123, 7, kStreamHumidity, voxel), 128000u);
}

// Test the host generator against the published pcg32-demo output
// (pcg32_srandom_r(&rng, 42, 54), O'Neill, pcg-random.org).
TEST(SharedFormula, Pcg32PublishedVector) {
    Pcg32 rng(42, 54);
    for (uint32_t want : {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu})
        EXPECT_EQ(rng.NextU32(), want);
}

// ---- 1b. Q(p) at exact halves ----------------------------------------------------

// Test that Q(p) = round(p 2^24) rounds exact halves up (away from zero; the
// documented choice, docs/pipeline.md), where ties-to-even would differ, and
// that the largest double below a half does not round up (floor(x + 0.5) would).
TEST(SharedFormula, QuantizeProbabilityHalvesRoundUp) {
    EXPECT_EQ(QuantizeProbability(0x1p-25), 1u);                        // 0.5: even would give 0
    EXPECT_EQ(QuantizeProbability(1.5 * 0x1p-24), 2u);                  // 1.5: both give 2
    EXPECT_EQ(QuantizeProbability(5 * 0x1p-25), 3u);                    // 2.5: even would give 2
    EXPECT_EQ(QuantizeProbability(0.5 + 0x1p-25), 8388609u);            // 2^23 + 0.5
    EXPECT_EQ(QuantizeProbability(1.0 - 3 * 0x1p-25), 16777215u);       // 2^24 - 1.5: even would give 2^24 - 2
    EXPECT_EQ(QuantizeProbability(0x1.fffffffffffffp-26), 0u);          // p 2^24 = 0.49999999999999994
    EXPECT_EQ(QuantizeProbability(0x1.0000000000001p-25), 1u);          // just above a half
    for (uint32_t k : {0u, 1u, 2u, 1000u, 8388607u, 16777214u}) {
        const double p = (double(k) + 0.5) * 0x1p-24;  // exact
        EXPECT_EQ(QuantizeProbability(p), k + 1) << k;
        EXPECT_EQ(QuantizeProbability(std::nextafter(p, 0.0)), k) << k;
    }
}

// ---- 1c. The region's weight and quantisation ------------------------------------

// Test the yaw's sign at 45 degrees (90 degrees cannot show it): an ellipsoid
// a = 4, b = c = 1 centred on a voxel centre, turned +45 degrees about z, is long
// along (1, 1). Voxel (+2, +2) lies on its long axis, rho = sqrt(8)/4,
// 255 (1 - 0.70711) = 74.69 -> 75; voxel (+2, -2) is sqrt(8) across the short axis: 0.
// Rotating by -45 degrees instead swaps them.
TEST(SharedFormula, RegionYaw45Sign) {
    const float c = std::sqrt(0.5f);
    const RasterEllipsoid e{{5.5f, 5.5f, 1.5f}, {4, 1, 1}, c, c};
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 7.5f, 7.5f, 1.5f)), 75);
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 3.5f, 3.5f, 1.5f)), 75);
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 7.5f, 3.5f, 1.5f)), 0);
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 3.5f, 7.5f, 1.5f)), 0);
    // (+1, +1): rho = sqrt(2)/4 = 0.35355, 255 * 0.64645 = 164.85 -> 165; (+1, -1): rho = sqrt(2) -> 0.
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 6.5f, 6.5f, 1.5f)), 165);
    EXPECT_EQ(QuantizeRegion(EllipsoidWeight(e, 6.5f, 4.5f, 1.5f)), 0);
}

// Floats w where float(255 w) is exactly k + 0.5 (a tie of k/255 and (k+1)/255),
// found by a plain search near (k + 0.5)/255; one exists for every k in 0..254.
std::vector<float> SfUnormTiesFor(int k) {
    std::vector<float> out;
    float w = (float(k) + 0.5f) / 255.0f;
    for (int n = 0; n < 16; ++n) w = std::nextafter(w, 0.0f);
    for (int n = 0; n < 33; ++n, w = std::nextafter(w, 1.0f))
        if (255.0f * w == float(k) + 0.5f) out.push_back(w);
    return out;
}

// Test R = floor(255 w + 0.5) at exact halves: they round up, for every k
// (a change to rint, ties to even, fails at every even k).
TEST(SharedFormula, QuantizeRegionHalvesRoundUp) {
    EXPECT_EQ(QuantizeRegion(std::bit_cast<float>(0x3b008081u)), 1);  // 255 w = 0.5
    EXPECT_EQ(QuantizeRegion(std::bit_cast<float>(0x3c20a0a1u)), 3);  // 2.5
    EXPECT_EQ(QuantizeRegion(std::bit_cast<float>(0x3c909091u)), 5);  // 4.5
    for (int k = 0; k <= 254; ++k) {
        const std::vector<float> ties = SfUnormTiesFor(k);
        ASSERT_FALSE(ties.empty()) << "no tie float for k = " << k;
        for (float w : ties) ASSERT_EQ(QuantizeRegion(w), k + 1) << "k " << k << " w " << w;
        // Below the tie R = k, except at k = 0: there 255 w = 0.49999997 (2^-1 - 2^-25), and
        // 0.49999997 + 0.5 = 1 - 2^-25 is halfway between 1 - 2^-24 and 1 in binary32, so
        // the sum rounds (to even) to 1 and R = 1. SPEC 1 evaluates floats in binary32, so
        // this is the formula as written (docs/pipeline.md, "Region rasterisation").
        ASSERT_EQ(QuantizeRegion(std::nextafter(ties.front(), 0.0f)), k == 0 ? 1 : k) << "k " << k;
        ASSERT_EQ(QuantizeRegion(std::nextafter(ties.back(), 1.0f)), k + 1) << "k " << k;
    }
}

// ---- 1d. The principal axis at exact ties ----------------------------------------

// Test PrincipalAxis's ties (z over y over x) in the cases ShadeTest does not
// reach: |z| = |y| > |x|, |z| >= |x| but |z| < |y|, the all-equal vector, and the
// zero vector (z, documented in docs/pipeline.md).
TEST(SharedFormula, PrincipalAxisMoreTies) {
    EXPECT_EQ(PrincipalAxis({0, 1, 1}), 2);
    EXPECT_EQ(PrincipalAxis({0, -1, 1}), 2);
    EXPECT_EQ(PrincipalAxis({0, 1, -1}), 2);
    EXPECT_EQ(PrincipalAxis({0, 1, 0.5f}), 1);    // |z| >= |x| does not make z
    EXPECT_EQ(PrincipalAxis({0.5f, -0.5f, 0.25f}), 1);
    EXPECT_EQ(PrincipalAxis({1, 1, 1}), 2);
    EXPECT_EQ(PrincipalAxis({-1, -1, 0}), 1);
    EXPECT_EQ(PrincipalAxis({-1, 0.5f, 1}), 2);
    EXPECT_EQ(PrincipalAxis({1, 0, 0}), 0);
    EXPECT_EQ(PrincipalAxis({0, 0, 0}), 2);
    EXPECT_EQ(PrincipalAxis({-0.0f, 0, -0.0f}), 2);
}

// ---- 1e. fp16 and unorm8 rounding at every tie ------------------------------------

// The value of half code c (c <= 0x3C00), built from its fields with ldexp.
float SfHalfValue(uint32_t c) {
    const uint32_t exponent = c >> 10, mantissa = c & 0x3ffu;
    return exponent == 0 ? float(std::ldexp(double(mantissa), -24))
                         : float(std::ldexp(1.0 + mantissa / 1024.0, int(exponent) - 15));
}

// Test RoundToHalf at every fp16 tie in [0, 1): the midpoint m of codes c and
// c + 1 (exact in float: 12 significant bits) goes to the even code, the float
// below m to c, the float above to c + 1; the same with signs flipped (compared
// as bits, so -0 stays -0). 15360 ties, 92160 cases, the subnormal halves included.
TEST(SharedFormula, RoundToHalfEveryTie) {
    uint32_t checked = 0;
    for (uint32_t c = 0; c <= 0x3BFFu; ++c) {
        const float lo = SfHalfValue(c), hi = SfHalfValue(c + 1);
        const double mid = (double(lo) + double(hi)) / 2;
        const float m = float(mid);
        ASSERT_EQ(double(m), mid) << "midpoint not exact at code " << c;
        const float even = (c & 1u) ? hi : lo;
        const float below = std::nextafter(m, 0.0f), above = std::nextafter(m, 1.0f);
        for (float sign : {1.0f, -1.0f}) {
            auto bits = [&](float v) { return std::bit_cast<uint32_t>(sign * v); };
            ASSERT_EQ(std::bit_cast<uint32_t>(RoundToHalf(sign * m)), bits(even)) << "tie at code " << c << " sign " << sign;
            ASSERT_EQ(std::bit_cast<uint32_t>(RoundToHalf(sign * below)), bits(lo)) << "below tie at code " << c;
            ASSERT_EQ(std::bit_cast<uint32_t>(RoundToHalf(sign * above)), bits(hi)) << "above tie at code " << c;
            // And through the storage switch, which the shading stages call.
            ASSERT_EQ(std::bit_cast<uint32_t>(RoundToStorage(StorageFormat::Fp16, sign * m)), bits(even)) << c;
            checked += 3;
        }
    }
    EXPECT_EQ(checked, 6u * 0x3C00u);
}

// Test unorm8 rounding (ties to even, SPEC 6) at the floats where float(255 v)
// is exactly k + 0.5, for every k, and their neighbours; hand examples besides.
TEST(SharedFormula, RoundToUnorm8EveryTie) {
    EXPECT_EQ(RoundToUnorm8(std::bit_cast<float>(0x3b008081u)), 0.0f);  // 0.5 -> 0
    EXPECT_EQ(RoundToUnorm8(std::bit_cast<float>(0x3bc0c0c1u)), 2.0f / 255.0f);  // 1.5 -> 2
    EXPECT_EQ(RoundToUnorm8(std::bit_cast<float>(0x3c20a0a1u)), 2.0f / 255.0f);  // 2.5 -> 2
    for (uint32_t bits : {0x3f7e7e7eu, 0x3f7f7f7fu, 0x3f7f7f80u})  // 253.5, 254.5, 254.5
        EXPECT_EQ(RoundToUnorm8(std::bit_cast<float>(bits)), 254.0f / 255.0f) << std::hex << bits;
    for (int k = 0; k <= 254; ++k) {
        const std::vector<float> ties = SfUnormTiesFor(k);
        ASSERT_FALSE(ties.empty()) << "no tie float for k = " << k;
        const int even = (k % 2 == 0) ? k : k + 1;
        for (float v : ties) {
            ASSERT_EQ(RoundToUnorm8(v), float(even) / 255.0f) << "k " << k << " v " << v;
            ASSERT_EQ(RoundToStorage(StorageFormat::Unorm8, v), float(even) / 255.0f) << "k " << k;
        }
        ASSERT_EQ(RoundToUnorm8(std::nextafter(ties.front(), 0.0f)), float(k) / 255.0f) << "k " << k;
        ASSERT_EQ(RoundToUnorm8(std::nextafter(ties.back(), 1.0f)), float(k + 1) / 255.0f) << "k " << k;
    }
}


// ---- 1f. The back-to-front order at ties ---------------------------------------

// Test the splat order's ties: a view along (1, 1, 0) gives two equal |forward|
// components, and x stays before y (then z; docs/pipeline.md). Eye index 2.0 in
// n = 5: distances |i + 0.5 - 2| = 1.5, 0.5, 0.5, 1.5, 2.5 -> 4, then 0 and 3 (the
// lower first), then 1 and 2. An eye below the grid (-3.7): farthest index first.
TEST(SharedFormula, SplatOrderTies) {
    CameraSettings cam;
    cam.eye = {2.5, 2.5, 0};
    cam.target = {12.5, 12.5, 0};
    CameraFrame frame = MakeCameraFrame(cam, 8, 8);
    ASSERT_EQ(std::fabs(frame.forward[0]), std::fabs(frame.forward[1]));
    EXPECT_EQ(MakeSplatOrder(frame, {5, 5, 5}, {0, 0, 0}, 1.0).axes, (std::array<int, 3>{0, 1, 2}));
    cam.target = {-7.5, -7.5, 0};  // the same tie, both components negative
    frame = MakeCameraFrame(cam, 8, 8);
    EXPECT_EQ(MakeSplatOrder(frame, {5, 5, 5}, {0, 0, 0}, 1.0).axes, (std::array<int, 3>{0, 1, 2}));
    cam.eye = {0, 2.5, 2.5};  // a tie of y and z: y first
    cam.target = {0, 12.5, 12.5};
    frame = MakeCameraFrame(cam, 8, 8);
    EXPECT_EQ(MakeSplatOrder(frame, {5, 5, 5}, {0, 0, 0}, 1.0).axes, (std::array<int, 3>{1, 2, 0}));

    cam.eye = {2.0, -3.7, 0.25};  // eye indices 2.0, -3.7 and 0.25 with h = 1, origin 0
    cam.target = {2.0, 10, 3};
    frame = MakeCameraFrame(cam, 8, 8);
    const SplatOrder order = MakeSplatOrder(frame, {5, 5, 2}, {0, 0, 0}, 1.0);
    EXPECT_EQ(order.indices[0], (std::vector<uint32_t>{4, 0, 3, 1, 2}));
    EXPECT_EQ(order.indices[1], (std::vector<uint32_t>{4, 3, 2, 1, 0}));
    EXPECT_EQ(order.indices[2], (std::vector<uint32_t>{1, 0}));  // |0.5 - 0.25| < |1.5 - 0.25|
}

// ---- 1g. The frustum bound grown by the splat radius ------------------------------

// A case worked by hand: grid 40 x 40 x 1, h = 1, origin 0, one
// voxel per box; eye (0.5, 20.5, 0.5) looking along +x, fov 90 degrees, 64 x 64
// (f = 32 px), so right = forward x up = (0, -1, 0); splat diameter 4.
struct SfFrustumCase {
    Extent3 grid{40, 40, 1};
    CameraFrame camera;
    SfFrustumCase() {
        CameraSettings cam;
        cam.eye = {0.5, 20.5, 0.5};
        cam.target = {10.5, 20.5, 0.5};
        cam.fovDeg = 90;
        cam.nearPlane = 1;
        camera = MakeCameraFrame(cam, 64, 64);
    }
    std::vector<uint8_t> Visible(float diameter) const {
        return FrustumVisibleBoxes(camera, grid, {0, 0, 0}, 1.0f, 1, 1, diameter);
    }
    bool VisibleAt(const std::vector<uint8_t>& v, uint32_t i, uint32_t j) const { return v[i + grid.nx * j] != 0; }
};

// Test the radius growth by hand. Voxel (16, 3, 0) is at depth 16 and 17 to the
// right: px = 32 + 17 * 32/16 = 66, size 4 * 32/16 = 8, so its splat covers
// x = 62..63 of the image. The widened right plane n = (-33, -32, 0)/45.967 puts
// it 16/45.967 = 0.348 outside, which is less than the radius 2: it must stay
// visible (a bound without the radius culls it). Voxel (16, 0, 0) is
// 112/45.967 = 2.44 > 2 outside (its splat starts at x = 68): culled. The left
// edge mirrors it. Voxels at depth <= near (x index 0 and 1) are culled.
TEST(SharedFormula, FrustumBoundGrowsBySplatRadius) {
    const SfFrustumCase c;
    EXPECT_NEAR(c.camera.focalPx, 32.0f, 1e-4f);
    EXPECT_NEAR(c.camera.right[1], -1.0f, 1e-6f);
    const std::vector<uint8_t> v = c.Visible(4.0f);
    EXPECT_TRUE(c.VisibleAt(v, 16, 3));   // 0.348 outside, radius 2
    EXPECT_TRUE(c.VisibleAt(v, 16, 1));   // 80/45.967 = 1.74 outside
    EXPECT_FALSE(c.VisibleAt(v, 16, 0));  // 2.44 outside
    EXPECT_TRUE(c.VisibleAt(v, 16, 37));  // mirrored (y 37.5 = 20.5 + 17): 0.348 outside the left plane
    EXPECT_TRUE(c.VisibleAt(v, 16, 39));  // 1.74
    EXPECT_FALSE(c.VisibleAt(v, 10, 39)); // rel (10, 19): (-330 + 608)/45.967 = 6.05
    EXPECT_FALSE(c.VisibleAt(v, 10, 0));  // rel (10, -20): (-330 + 640)/45.967 = 6.74
    EXPECT_TRUE(c.VisibleAt(v, 16, 20));  // on the axis
    EXPECT_FALSE(c.VisibleAt(v, 0, 20));  // depth 0
    EXPECT_FALSE(c.VisibleAt(v, 1, 20));  // depth 1 = near: culled, as MakeSplat drops it
    EXPECT_TRUE(c.VisibleAt(v, 2, 20));
    // A smaller splat (diameter 0.5, radius 0.25) no longer reaches from 0.348 outside.
    EXPECT_FALSE(c.VisibleAt(c.Visible(0.5f), 16, 3));

    // The splat itself, from the shared MakeSplat: covers x = 62..63, y = 28..35.
    SplatParams p;
    SplatOrder order = MakeSplatOrder(c.camera, c.grid, {0, 0, 0}, 1.0);
    p.camera = c.camera;
    p.order = &order;
    p.splatDiameter = 4;
    p.voxelSize = 1;
    p.qMin = 0;
    const SplatFrame frame = MakeSplatFrame(p, c.grid, FlattenSplatOrder(order), 64, 64);
    Splat s;
    ASSERT_TRUE(MakeSplat(frame, 16, 3, 0, 1.0f, 1.0f, 1.0f, s));
    EXPECT_NEAR(s.px, 66.0f, 1e-4f);
    EXPECT_NEAR(s.size, 8.0f, 1e-4f);
    EXPECT_EQ(s.x0, 62);
    EXPECT_EQ(s.x1, 63);
    EXPECT_EQ(s.y0, 28);
    EXPECT_EQ(s.y1, 35);
}

// Test conservativeness over random cameras, grids and diameters (a slow path:
// every voxel's own splat): no culled box holds a voxel whose splat covers a pixel.
TEST(SharedFormula, FrustumCullsNoSplatThatCoversAPixel) {
    Pcg32 rng(1717);
    const Extent3 grid{24, 20, 9};
    uint32_t culledBoxes = 0, coveringVoxels = 0;
    for (int n = 0; n < 60; ++n) {
        CameraSettings cam;
        cam.eye = {rng.Uniform(-20, 44), rng.Uniform(-20, 40), rng.Uniform(-5, 20)};
        cam.target = {rng.Uniform(0, 24), rng.Uniform(0, 20), rng.Uniform(0, 9)};
        cam.fovDeg = rng.Uniform(20, 100);
        cam.nearPlane = rng.Uniform(0.1, 3);
        const uint32_t width = 16 + rng.Below(80), height = 16 + rng.Below(80);
        SplatParams p;
        p.camera = MakeCameraFrame(cam, width, height);
        SplatOrder order = MakeSplatOrder(p.camera, grid, {0, 0, 0}, 1.0);
        p.order = &order;
        p.splatDiameter = float(rng.Uniform(0.5, 6));
        p.voxelSize = 1;
        p.qMin = 0;
        p.tile = 1 + rng.Below(6);
        p.band = 1 + rng.Below(4);
        const std::vector<uint8_t> visible =
            FrustumVisibleBoxes(p.camera, grid, {0, 0, 0}, 1.0f, p.tile, p.band, p.splatDiameter);
        const SplatFrame frame = MakeSplatFrame(p, grid, FlattenSplatOrder(order), width, height);
        const uint32_t tilesX = (grid.nx + p.tile - 1) / p.tile, tilesY = (grid.ny + p.tile - 1) / p.tile;
        for (uint32_t k = 0; k < grid.nz; ++k)
            for (uint32_t j = 0; j < grid.ny; ++j)
                for (uint32_t i = 0; i < grid.nx; ++i) {
                    const size_t box = i / p.tile + tilesX * (j / p.tile + size_t(tilesY) * (k / p.band));
                    Splat s;
                    const bool covers = MakeSplat(frame, i, j, k, 1.0f, 1.0f, 1.0f, s) && s.x0 <= s.x1 && s.y0 <= s.y1;
                    coveringVoxels += covers;
                    if (covers) {
                        ASSERT_TRUE(visible[box]) << "camera " << n << " voxel " << i << "," << j << "," << k;
                    }
                }
        for (uint8_t b : visible) culledBoxes += b == 0;
    }
    EXPECT_GT(culledBoxes, 1000u);  // the cameras do cull
    EXPECT_GT(coveringVoxels, 10000u);
}

// ---- 1h. The ground-shadow lookup height -----------------------------------------

// Test where the ground shadow reads D: nz/2 voxels up along s, so the offset is
// (s_x, s_y) nz / (2 s_z). nz = 7 at 45 degrees along +x: 3.5 (an odd height; a
// lookup with nz/2 in integers gives 3); 45 degrees along -y with nz = 8: -4 in y;
// a 60-degree elevation along +x with nz = 10: 5 cot 60 = 2.88675.
TEST(SharedFormula, ShadowLookupHeight) {
    const float r = std::sqrt(0.5f);
    ShadowLookup l = MakeShadowLookup({r, 0, r}, 10, 4, 7, 0.01f, 50);
    ASSERT_FALSE(l.noSun);
    EXPECT_NEAR(float(l.baseX) + l.fx, 3.5f, 1e-5f);
    EXPECT_EQ(l.baseX, 3);
    EXPECT_NEAR(l.fx, 0.5f, 1e-5f);
    EXPECT_EQ(l.baseY, 0);
    EXPECT_EQ(l.fy, 0.0f);
    EXPECT_NEAR(l.opticalDepthPerD, 0.01f * 50 / r, 1e-5f);
    l = MakeShadowLookup({0, -r, r}, 4, 10, 8, 0.01f, 50);
    EXPECT_NEAR(float(l.baseY) + l.fy, -4.0f, 1e-5f);
    EXPECT_NEAR(float(l.baseX) + l.fx, 0.0f, 1e-6f);
    const float c60 = 0.5f, s60 = std::sqrt(0.75f);
    l = MakeShadowLookup({c60, 0, s60}, 10, 4, 10, 0.01f, 50);
    EXPECT_NEAR(float(l.baseX) + l.fx, 5.0f * 0.5f / std::sqrt(0.75f), 1e-5f);
    EXPECT_EQ(l.baseX, 2);
    l = MakeShadowLookup({-c60, 0, s60}, 10, 4, 10, 0.01f, 50);
    EXPECT_NEAR(float(l.baseX) + l.fx, -2.886751f, 1e-5f);
    EXPECT_EQ(l.baseX, -3);
    EXPECT_TRUE(MakeShadowLookup({1, 0, 0}, 10, 4, 8, 0.01f, 50).noSun);
}

// ---- 1i. Wind-grid orientation ------------------------------------------------------

// Test the wind grid's layout (x fastest, docs/scenes.md) on a 3 x 2 grid with
// distinct vectors, by hand: grid 30 x 20, margin 0, so the cell centres are at
// x = 5, 15, 25 and y = 5, 15. Row y = 5 holds (1,0) (2,0) (3,0), row y = 15 holds
// (0,1) (0,2) (.5,-3). A transposed lookup reads (0,2) at (25, 5).
EllipsoidSettings SfWindSettings() {
    EllipsoidSettings s;
    s.seed = 5;
    s.targetCount = 12;
    s.margin = 0;
    s.jitter = 0;
    s.lifetimeMean = 100;
    s.lifetimeVariance = 0;
    s.wind.gridNx = 3;
    s.wind.gridNy = 2;
    s.wind.grid = {{1, 0}, {2, 0}, {3, 0}, {0, 1}, {0, 2}, {0.5, -3}};
    return s;
}

TEST(SharedFormula, WindGridOrientation) {
    const EllipsoidList list(SfWindSettings(), {30, 20, 4});
    auto at = [&](double x, double y) { return list.WindAt(x, y); };
    EXPECT_EQ(at(5, 5), (std::array<double, 2>{1, 0}));
    EXPECT_EQ(at(15, 5), (std::array<double, 2>{2, 0}));
    EXPECT_EQ(at(25, 5), (std::array<double, 2>{3, 0}));
    EXPECT_EQ(at(5, 15), (std::array<double, 2>{0, 1}));
    EXPECT_EQ(at(15, 15), (std::array<double, 2>{0, 2}));
    EXPECT_EQ(at(25, 15), (std::array<double, 2>{0.5, -3}));
    // (20, 10): halfway in both: ((2,0) + (3,0) + (0,2) + (.5,-3)) / 4 = (1.375, -0.25).
    EXPECT_DOUBLE_EQ(at(20, 10)[0], 1.375);
    EXPECT_DOUBLE_EQ(at(20, 10)[1], -0.25);
    // (10, 5): halfway between the first two of row 0; (25, 12.5): 3/4 of the way up the last column.
    EXPECT_DOUBLE_EQ(at(10, 5)[0], 1.5);
    EXPECT_DOUBLE_EQ(at(25, 12.5)[0], 3 * 0.25 + 0.5 * 0.75);
    EXPECT_DOUBLE_EQ(at(25, 12.5)[1], -3 * 0.75);
    EXPECT_EQ(at(-5, 100), (std::array<double, 2>{0, 1}));  // clamped to the corner cell
    EXPECT_EQ(at(100, -100), (std::array<double, 2>{3, 0}));
}

// Test that one update with no jitter moves every surviving centre by exactly
// the grid's wind at its old centre (hand-interpolated here, not WindAt).
TEST(SharedFormula, WindGridMovesCentres) {
    const EllipsoidSettings s = SfWindSettings();
    EllipsoidList list(s, {30, 20, 4});
    auto wind = [&](double x, double y) {  // the bilinear grid, written out
        const double gx = std::clamp(x / 30 * 3 - 0.5, 0.0, 2.0), gy = std::clamp(y / 20 * 2 - 0.5, 0.0, 1.0);
        const int ix = std::min(int(gx), 1), iy = 0;
        const double fx = gx - ix, fy = gy - iy;
        std::array<double, 2> out{};
        for (int c = 0; c < 2; ++c) {
            const double row0 = s.wind.grid[ix][c] + fx * (s.wind.grid[ix + 1][c] - s.wind.grid[ix][c]);
            const double row1 = s.wind.grid[3 + ix][c] + fx * (s.wind.grid[3 + ix + 1][c] - s.wind.grid[3 + ix][c]);
            out[c] = row0 + fy * (row1 - row0);
        }
        return out;
    };
    const std::vector<Ellipsoid> before = list.Items();
    list.Update();
    size_t matched = 0;
    for (const Ellipsoid& after : list.Items())
        for (const Ellipsoid& b : before)
            if (after.yaw == b.yaw) {
                const std::array<double, 2> w = wind(b.center[0], b.center[1]);
                EXPECT_NEAR(after.center[0], b.center[0] + w[0], 1e-12);
                EXPECT_NEAR(after.center[1], b.center[1] + w[1], 1e-12);
                ++matched;
            }
    EXPECT_GE(matched, 3u);
}

// ---- 1j. The ellipsoid list update -------------------------------------------------

// Test the spawn and update order against an independent Python port of
// docs/pipeline.md: grid 16 x 8 x 4, seed 7, target 2,
// adaption 1, size (4,4,2) +- (1,1,.5), life 3 +- 0, margin 2, height (.25,.5),
// wind (1,0), jitter .1. Draws: x, y, z, three semi-axes, yaw, life, then age
// (Below(lifetime)) at the start; after moving (x then y jitter per item) and
// ageing, item 1 dies and one is born with age 0.
TEST(SharedFormula, EllipsoidListMatchesIndependentPort) {
    EllipsoidSettings s;
    s.seed = 7;
    s.targetCount = 2;
    s.densityAdaption = 1;
    s.sizeMean = {4, 4, 2};
    s.sizeVariance = {1, 1, 0.5};
    s.lifetimeMean = 3;
    s.lifetimeVariance = 0;
    s.margin = 2;
    s.heightRange = {0.25, 0.5};
    s.wind.vector = {1, 0};
    s.jitter = 0.1;
    EllipsoidList list(s, {16, 8, 4});
    ASSERT_EQ(list.Items().size(), 2u);
    const Ellipsoid& a = list.Items()[0];
    EXPECT_DOUBLE_EQ(a.center[0], 14.46875206662613);
    EXPECT_DOUBLE_EQ(a.center[1], 6.1102068724617915);
    EXPECT_DOUBLE_EQ(a.center[2], 1.818213292065742);
    EXPECT_EQ(a.lifetime, 3u);
    EXPECT_EQ(a.age, 0u);
    const Ellipsoid& b = list.Items()[1];
    EXPECT_DOUBLE_EQ(b.center[0], 6.055207750028517);
    EXPECT_DOUBLE_EQ(b.center[1], 5.3890322320628865);
    EXPECT_EQ(b.age, 2u);
    list.Update();
    ASSERT_EQ(list.Items().size(), 2u);
    const Ellipsoid& moved = list.Items()[0];
    EXPECT_DOUBLE_EQ(moved.center[0], 15.566760098866782);
    EXPECT_DOUBLE_EQ(moved.center[1], 6.025397378582523);
    EXPECT_EQ(moved.age, 1u);
    const Ellipsoid& born = list.Items()[1];
    EXPECT_DOUBLE_EQ(born.center[0], -0.9889784869735179);
    EXPECT_DOUBLE_EQ(born.center[1], 9.697616667912097);
    EXPECT_DOUBLE_EQ(born.center[2], 1.2246692739836107);
    EXPECT_DOUBLE_EQ(born.yaw, 6.096030358387616);
    EXPECT_EQ(born.age, 0u);
}


// Test eight updates against the same independent port (extended): deaths by age
// and by leaving the bounds, the adaption limit (step 5: two die, one is born),
// lifetimes 4 +- 1.5 rounded, wind (1.5, -0.25), jitter 0.3. Grid 16 x 8 x 4, seed 11,
// target 3, adaption 1. The list never exceeds its target (births stop there), so
// the random-removal branch of Update is unreachable with fixed settings.
TEST(SharedFormula, EllipsoidListEightStepsMatchIndependentPort) {
    EllipsoidSettings s;
    s.seed = 11;
    s.targetCount = 3;
    s.densityAdaption = 1;
    s.sizeMean = {4, 4, 2};
    s.sizeVariance = {1, 1, 0.5};
    s.lifetimeMean = 4;
    s.lifetimeVariance = 1.5;
    s.margin = 2;
    s.heightRange = {0.25, 0.5};
    s.wind.vector = {1.5, -0.25};
    s.jitter = 0.3;
    EllipsoidList list(s, {16, 8, 4});
    const size_t sizes[8] = {3, 3, 3, 3, 2, 3, 3, 3};
    for (int step = 0; step < 8; ++step) {
        list.Update();
        ASSERT_EQ(list.Items().size(), sizes[step]) << "after update " << step + 1;
    }
    struct Want {
        double c[3], a[3], yaw;
        uint32_t lifetime, age;
    };
    const Want want[3] = {
        {{16.187713976803423, 2.922479746306546, 1.5737939093375688},
         {3.9551018893237666, 3.041143230778137, 2.1140194433291652}, 3.163178085419022, 5, 4},
        {{6.8857179595580815, 3.3323839830016366, 1.5075957481709525},
         {4.091237242737663, 3.178188343552854, 2.4919092225744564}, 1.7318439345947823, 5, 3},
        {{11.23366752200793, 4.973939751060113, 1.3974873608361391},
         {3.9283606596839293, 3.418020187303883, 2.0144997152103103}, 0.8151843802905121, 3, 2},
    };
    for (int n = 0; n < 3; ++n) {
        const Ellipsoid& e = list.Items()[n];
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_DOUBLE_EQ(e.center[axis], want[n].c[axis]) << "item " << n << " axis " << axis;
            EXPECT_DOUBLE_EQ(e.semiAxes[axis], want[n].a[axis]) << "item " << n << " axis " << axis;
        }
        EXPECT_DOUBLE_EQ(e.yaw, want[n].yaw) << n;
        EXPECT_EQ(e.lifetime, want[n].lifetime) << n;
        EXPECT_EQ(e.age, want[n].age) << n;
    }
}

}  // namespace
}  // namespace cb
