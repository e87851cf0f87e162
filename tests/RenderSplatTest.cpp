// The splat renderer (SPEC 8) and the shared camera and order (core/math/Camera.h).
#include <gtest/gtest.h>

#include <cmath>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "harness/report/Report.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

struct RenderCase {
    Extent3 grid;
    std::vector<float> qPrev, qCur, T;
    CameraSettings camera;
    uint32_t width = 64, height = 48;
    SplatParams params;
};

struct Rendered {
    std::vector<float> rgb;
    SplatStats stats;
};

// Renders on the CPU; the occupancy maps are computed by the density stage.
Rendered Render(RenderCase c, bool culling, bool skipping, int threads = 0) {
    cpu::BackendCpu backend(threads);
    const Extent3 e = c.grid;
    auto qp = test::MakeFilled(backend, BufferFormat::F32, e, c.qPrev);
    auto qc = test::MakeFilled(backend, BufferFormat::F32, e, c.qCur);
    auto T = test::MakeFilled(backend, BufferFormat::F32, e, c.T);
    const uint32_t tile = c.params.tile, band = c.params.band;
    const Extent3 tiles{CeilDiv(e.nx, tile), CeilDiv(e.ny, tile), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, band)};
    std::unique_ptr<Buffer> occupancy[2][2];
    auto cld = test::MakeBuffer(backend, BufferFormat::Bits, e);
    for (int step = 0; step < 2; ++step) {
        auto D = test::MakeBuffer(backend, BufferFormat::F32, {e.nx, e.ny, 1});
        occupancy[step][0] = test::MakeBuffer(backend, BufferFormat::U8, tiles);
        occupancy[step][1] = test::MakeBuffer(backend, BufferFormat::U8, bands);
        DensityOutputs out{D.get(), occupancy[step][0].get(), occupancy[step][1].get(), 0};
        EXPECT_TRUE(backend.Density({tile, band, {}}, step == 0 ? *qp : *qc, cld.get(), out).has_value());
    }
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, c.width, c.height});
    SplatParams p = c.params;
    p.camera = MakeCameraFrame(c.camera, c.width, c.height);
    const SplatOrder order = MakeSplatOrder(p.camera, e, {double(p.origin[0]), double(p.origin[1]), double(p.origin[2])},
                                            p.voxelSize);
    p.order = &order;
    p.culling = culling;
    p.skipping = skipping;
    SplatInputs in{qp.get(), qc.get(), T.get(), occupancy[0][0].get(), occupancy[1][0].get(), occupancy[0][1].get(),
                   occupancy[1][1].get()};
    Rendered r;
    Status s = backend.RenderSplat(p, in, *image, &r.stats);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    r.rgb = test::Read<float>(backend, *image);
    return r;
}

// Test one splat against a footprint worked out by hand. One voxel of size 2
// centred at (1,1,1); the camera at (1,1,11) looks down -z at it, 10 units
// away, fov 90 degrees on a 40 x 40 image: f_px = 40/(2 tan 45) = 20, the
// centre projects to (20, 20), and d = 3 gives s = 3*20/10 = 6 pixels. Pixels
// x with 17 <= x + 0.5 < 23 are covered: x = 17..22 (likewise y). At pixel
// (19, 20): a = (19.5 - 20)/6 + 0.5 = 5/12, b = 7/12, rho^2 = 2*(1/6)^2 = 1/18,
// kappa = (17/18)^2, alpha = q*kappa*opacity with q = 0.8, opacity 0.5.
TEST(RenderSplat, SingleSplatHandWorked) {
    RenderCase c;
    c.grid = {1, 1, 1};
    c.qPrev = {0.8f};
    c.qCur = {0.8f};
    c.T = {0.5f};
    c.camera.eye = {1, 1, 11};
    c.camera.target = {1, 1, 0};
    c.camera.up = {0, 1, 0};
    c.camera.fovDeg = 90;
    c.width = c.height = 40;
    SplatParams& p = c.params;
    p.voxelSize = 2;
    p.origin = {0, 0, 0};
    p.splatDiameter = 3;
    p.opacity = 0.5f;
    p.qMin = 0.3f;
    p.sun = {0, 0, 1};
    p.light.sunRadiance = {2, 2, 2};
    p.light.phase = {PhaseKind::None, 0};
    p.light.ambient = {0.1f, 0.1f, 0.1f};
    p.background = {0, 0, 1};
    p.tile = 4;
    p.band = 4;
    const Rendered r = Render(c, true, true);
    EXPECT_EQ(r.stats.splats, 1u);
    const float color = 2 * 0.5f * 1 + 0.1f;  // sun * T * phase + ambient
    for (uint32_t y = 0; y < 40; ++y)
        for (uint32_t x = 0; x < 40; ++x) {
            const float* px = &r.rgb[3 * (x + 40 * y)];
            const bool covered = x >= 17 && x <= 22 && y >= 17 && y <= 22;
            if (!covered) {
                ASSERT_EQ(px[0], 0.0f) << x << "," << y;
                ASSERT_EQ(px[2], 1.0f) << x << "," << y;
            }
        }
    const float kappa = (17.0f / 18.0f) * (17.0f / 18.0f);
    const float alpha = 0.8f * kappa * 0.5f;
    const float* px = &r.rgb[3 * (19 + 40 * 20)];
    EXPECT_NEAR(px[0], alpha * color, 1e-6);
    EXPECT_NEAR(px[2], alpha * color + (1 - alpha) * 1.0f, 1e-6);
    // A corner pixel of the footprint: rho^2 = 2 (5/6)^2 > 1, kappa = 0: background.
    EXPECT_EQ(r.rgb[3 * (17 + 40 * 17) + 2], 1.0f);
}

RenderCase RandomCloud(uint32_t seed) {
    RenderCase c;
    c.grid = {40, 36, 12};
    const size_t n = c.grid.Count();
    Pcg32 rng(seed);
    c.qPrev.resize(n);
    c.qCur.resize(n);
    c.T.resize(n);
    for (size_t v = 0; v < n; ++v) {
        // Blobs: most voxels empty, so skipping has something to skip.
        const bool cloudy = (v / 97) % 5 == 0;
        c.qPrev[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        c.qCur[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        c.T[v] = float(rng.Below(256)) / 255.0f;
    }
    SplatParams& p = c.params;
    p.voxelSize = 50;
    p.origin = {0, 0, 0};
    p.splatDiameter = 75;
    p.sun = SunDirection(0.6, 0.4);
    p.light.sunRadiance = {1.5f, 1.4f, 1.3f};
    p.light.ambient = {0.2f, 0.25f, 0.3f};
    p.background = {0.4f, 0.5f, 0.8f};
    p.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
    p.tile = 8;
    p.band = 4;
    p.alpha = 0.3f;
    return c;
}

std::vector<CameraSettings> TestCameras() {
    std::vector<CameraSettings> cams;
    auto add = [&](std::array<double, 3> eye, std::array<double, 3> target, std::array<double, 3> up, double fov) {
        CameraSettings c;
        c.eye = eye;
        c.target = target;
        c.up = up;
        c.fovDeg = fov;
        c.nearPlane = 1;
        cams.push_back(c);
    };
    add({-800, -600, 300}, {1000, 900, 300}, {0, 0, 1}, 60);   // outside, sees all
    add({1000, 900, -500}, {1000, 900, 300}, {0, 0, 1}, 50);   // straight up from below: degenerate up
    add({1000, 900, 2000}, {1000, 900, 0}, {0, 0, 1}, 70);     // straight down from above
    add({700, 500, 300}, {1500, 700, 320}, {0, 0, 1}, 40);     // inside the volume, sees part
    add({1000, 900, 300}, {1000, 1900, 300}, {0, 0, 1}, 30);   // inside, on a voxel boundary, narrow view
    add({-3000, 900, 300}, {-4000, 900, 300}, {0, 0, 1}, 60);  // looking away: nothing visible
    return cams;
}

// Test that culling and empty-space skipping change no pixel, from cameras
// outside, inside, above, below and looking away, and that they do cut work.
TEST(RenderSplat, CullingAndSkippingChangeNothing) {
    RenderCase c = RandomCloud(1);
    uint64_t visitedAll = 0, visitedCulled = 0;
    for (const CameraSettings& camera : TestCameras()) {
        c.camera = camera;
        const Rendered plain = Render(c, false, false);
        for (bool culling : {false, true})
            for (bool skipping : {false, true}) {
                const Rendered r = Render(c, culling, skipping);
                ASSERT_EQ(r.rgb, plain.rgb) << "culling " << culling << " skipping " << skipping << " eye "
                                            << camera.eye[0] << "," << camera.eye[1] << "," << camera.eye[2];
                if (culling && skipping) visitedCulled += r.stats.voxelsVisited;
            }
        visitedAll += plain.stats.voxelsVisited;
        for (float v : plain.rgb) ASSERT_TRUE(std::isfinite(v));
    }
    EXPECT_LT(visitedCulled, visitedAll / 2);
}

// Test that the image is identical for 1 and 2 threads.
TEST(RenderSplat, SameImageForOneAndTwoThreads) {
    RenderCase c = RandomCloud(2);
    c.width = 160;
    c.height = 120;
    for (const CameraSettings& camera : TestCameras()) {
        c.camera = camera;
        EXPECT_EQ(Render(c, true, true, 1).rgb, Render(c, true, true, 2).rgb);
    }
}

// Test the shared order: axes by decreasing |view component|, indices by
// decreasing distance from the eye's index, ties to the lower index.
TEST(SplatOrder, HandWorked) {
    CameraSettings cam;
    cam.eye = {2.5, 0, 0};       // eye index along x: 2.5 with h = 1
    cam.target = {2.5, 10, 3};   // view mostly +y, then +z, then 0 in x
    const CameraFrame frame = MakeCameraFrame(cam, 10, 10);
    const SplatOrder order = MakeSplatOrder(frame, {5, 3, 2}, {0, 0, 0}, 1.0);
    EXPECT_EQ(order.axes, (std::array<int, 3>{1, 2, 0}));
    // x: |i + 0.5 - 2.5| = 2, 1, 0, 1, 2 -> 0 and 4 first (lower index first), then 1 and 3, then 2.
    EXPECT_EQ(order.indices[0], (std::vector<uint32_t>{0, 4, 1, 3, 2}));
    // y: eye at 0: farthest first.
    EXPECT_EQ(order.indices[1], (std::vector<uint32_t>{2, 1, 0}));
}

// Test the camera frame with a degenerate up vector: finite, orthonormal.
TEST(Camera, DegenerateUpFallsBack) {
    CameraSettings cam;
    cam.eye = {0, 0, 0};
    cam.target = {0, 0, 5};
    cam.up = {0, 0, 1};
    const CameraFrame f = MakeCameraFrame(cam, 8, 8);
    auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    EXPECT_NEAR(dot(f.right, f.right), 1, 1e-6);
    EXPECT_NEAR(dot(f.upVector, f.upVector), 1, 1e-6);
    EXPECT_NEAR(dot(f.right, f.forward), 0, 1e-6);
    EXPECT_NEAR(dot(f.upVector, f.forward), 0, 1e-6);
    const Projected p = Project(f, {0, 0, 5});
    EXPECT_FLOAT_EQ(p.px, 4);
    EXPECT_FLOAT_EQ(p.py, 4);
    EXPECT_FLOAT_EQ(p.depth, 5);
}

}  // namespace
}  // namespace cb

namespace cb {
namespace {

// Test SPEC 8's image rule as CompareImages applies it: one pixel 8/255 off
// fails, a channel 2.5/255 off on 0.05 % of pixels passes and on 0.2 % fails.
TEST(ImageRule, ThresholdsAndCounts) {
    const uint32_t W = 100, H = 100;
    const std::vector<float> a(3 * W * H, 0.5f);
    std::vector<float> b = a;
    EXPECT_TRUE(CompareImages(a, b, W, H).value().Passes());
    b[3 * (10 + W * 20) + 1] += 9.0f / 255.0f;
    ImageComparison c = CompareImages(a, b, W, H).value();
    EXPECT_FALSE(c.Passes());
    EXPECT_EQ(c.worstX, 10);
    EXPECT_EQ(c.worstY, 20);
    b = a;
    for (uint32_t n = 0; n < 5; ++n) b[3 * n] += 2.5f / 255.0f;  // 5 of 10000 pixels
    c = CompareImages(a, b, W, H).value();
    EXPECT_EQ(c.pixelsOverTolerance, 5u);
    EXPECT_TRUE(c.Passes());
    for (uint32_t n = 5; n < 20; ++n) b[3 * n] += 2.5f / 255.0f;  // 20 of 10000
    EXPECT_FALSE(CompareImages(a, b, W, H).value().Passes());
}

}  // namespace
}  // namespace cb
