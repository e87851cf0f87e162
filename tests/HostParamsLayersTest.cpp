// The layered renderer's host-side parameters (SPEC 15, docs/pipeline.md "Layered renderer", docs/scenes.md
// `layers`) against the formulas worked by hand. MakeLayersParams computes them once on the host and every backend
// receives them alike, so a wrong value here is invisible to the differential tests (conform, GPU vs CPU): each
// expected number below is derived in its comment from the paper's or SPEC's formula, not read from the code.
// Edges: the first step and frame, alpha at 0 and 1, the sun past 90 degrees from its start and below the horizon,
// negative and large wind, drifts and points on and beyond a tile's edge; and the GPU block (MakeLayersGpu) carries
// the same numbers in the rows its comments name.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/math/Layers.h"
#include "core/math/Shading.h"
#include "core/pipeline/LayersGpu.h"
#include "core/scene/Scene.h"
#include "core/stages/render_layers/RenderLayers.h"

namespace cb {
namespace {

// Grid 8 x 6 x 4, h = 50 m, origin (100, -200, 300); one camera at (300, -50, 400) looking along +y, fov 90 deg,
// 33 x 21 pixels, near 25 m, far 1000 m. Wind (100, -50) m per step = (2, -1) voxel edges per step. The sun starts
// at elevation 0, azimuth 0 (s0 = (1, 0, 0)), colour (1, 0.5, 0.25) times 4. sigma 0.125 1/m.
Scene HplScene() {
    Scene sc;
    sc.grid.size = {8, 6, 4};
    sc.grid.voxelSize = 50;
    sc.grid.origin = {100, -200, 300};
    sc.render.width = 33;
    sc.render.height = 21;
    sc.render.alpha = 0.5;
    CameraSettings cam;
    cam.eye = {300, -50, 400};
    cam.target = {300, 950, 400};
    cam.up = {0, 0, 1};
    cam.fovDeg = 90;
    cam.nearPlane = 25;
    cam.farPlane = 1000;
    sc.render.cameras = {cam};
    sc.layers.wind = {100, -50};
    sc.sun.elevationDeg = 0;
    sc.sun.azimuthDeg = 0;
    sc.sun.color = {1, 0.5, 0.25};
    sc.sun.intensity = 4;
    sc.shade.sigma = 0.125;
    sc.lighting.ambient = {0.25, 0.5, 0.75};
    sc.lighting.background = {0.125, 0.375, 0.625};
    sc.phase = {PhaseKind::HenyeyGreenstein, 0.25f};
    return sc;
}

LayersParams HplParams(const Scene& sc, uint32_t step, uint32_t frame = 0, uint32_t frames = 0) {
    return MakeLayersParams(sc, sc.render.cameras[0], step, frame, frames);
}

struct HplDriftCase {
    uint32_t step;
    double alpha;            // render.alpha (one frame per step)
    std::array<float, 2> drift;  // expected, voxel edges
    const char* why;
};

// Test the wind's drift against Wang, Ji and Zhang's eq. 18 at the frame's time t = step - 1 + alpha
// (docs/scenes.md layers.wind): drift = wind t / h, without tiling not reduced. wind / h = (2, -1) per step.
TEST(HostParamsLayers, DriftIsEq18AtTheFramesTimeStepMinusOnePlusAlpha) {
    const HplDriftCase cases[] = {
        {0, 0.0, {-2.0f, 1.0f}, "step 0, alpha 0: t = -1 -> (-2, 1)"},
        {0, 1.0, {0.0f, 0.0f}, "step 0, alpha 1: t = 0 -> (0, 0)"},
        {1, 0.0, {0.0f, 0.0f}, "step 1, alpha 0: t = 0 -> (0, 0), the first step's start does not drift"},
        {1, 0.5, {1.0f, -0.5f}, "step 1, alpha 0.5: t = 0.5 -> (1, -0.5)"},
        {1, 1.0, {2.0f, -1.0f}, "step 1, alpha 1: t = 1 -> (2, -1)"},
        {7, 0.25, {12.5f, -6.25f}, "step 7, alpha 0.25: t = 6.25 -> (12.5, -6.25), past the grid, not reduced"},
    };
    for (const HplDriftCase& c : cases) {
        Scene sc = HplScene();
        sc.render.alpha = c.alpha;
        const LayersParams p = HplParams(sc, c.step);
        EXPECT_EQ(p.alpha, float(c.alpha)) << c.why;
        EXPECT_EQ(p.setup.drift[0], c.drift[0]) << c.why;
        EXPECT_EQ(p.setup.drift[1], c.drift[1]) << c.why;
    }
    // Frames between steps (render.frames_per_step 4): frame f draws alpha (f + 1) / 4.
    Scene sc = HplScene();
    sc.render.framesPerStep = 4;
    // step 2, frame 0: alpha 1/4, t = 1.25 -> (2.5, -1.25).
    EXPECT_EQ(HplParams(sc, 2, 0, 4).setup.drift, (std::array<float, 2>{2.5f, -1.25f}));
    // step 2, frame 3: alpha 1, t = 2 -> (4, -2); equal to step 3's alpha 0 (t = 2 too).
    EXPECT_EQ(HplParams(sc, 2, 3, 4).setup.drift, (std::array<float, 2>{4.0f, -2.0f}));
    // step 1, frame 0: alpha 1/4, t = 0.25 -> (0.5, -0.25).
    EXPECT_EQ(HplParams(sc, 1, 0, 4).setup.drift, (std::array<float, 2>{0.5f, -0.25f}));
    // No wind: (0, 0) at every time, also before the first step (t = -1 at step 0, alpha 0).
    sc.layers.wind = {0, 0};
    sc.render.framesPerStep = 1;
    sc.render.alpha = 0;
    EXPECT_EQ(HplParams(sc, 0).setup.drift, (std::array<float, 2>{0.0f, 0.0f}));
}

// Test negative and large wind (layers.wind in [-1e6, 1e6] m per step): the drift is formed in double and rounded
// to float once, and with tiling reduced modulo the period in double, so a large time keeps its fraction.
TEST(HostParamsLayers, DriftOfNegativeAndLargeWind) {
    Scene sc = HplScene();
    // (-150, -400) m per step, h 50: (-3, -8) per step; step 3, alpha 0.5: t = 2.5 -> (-7.5, -20).
    sc.layers.wind = {-150, -400};
    EXPECT_EQ(HplParams(sc, 3).setup.drift, (std::array<float, 2>{-7.5f, -20.0f}));
    // The largest wind, h = 64 m: 1e6 / 64 = 15625 per step; step 1000, alpha 0.5: t = 999.5,
    // 15625 * 999.5 = 15617187.5, a tie between floats 15617187 and 15617188 (spacing 1 above 2^23): to even.
    sc.grid.voxelSize = 64;
    sc.layers.wind = {1e6, -1e6};
    EXPECT_EQ(HplParams(sc, 1000).setup.drift, (std::array<float, 2>{15617188.0f, -15617188.0f}));
    // Tiled: 15617187.5 - 8 floor(15617187.5 / 8) = 15617187.5 - 8 * 1952148 = 3.5;
    // -15617187.5 - 6 floor(-15617187.5 / 6) = -15617187.5 + 6 * 2602865 = 2.5 (a float drift would lose the .5).
    sc.grid.tiling = true;
    EXPECT_EQ(HplParams(sc, 1000).setup.drift, (std::array<float, 2>{3.5f, 2.5f}));
}

// Test the tiled drift on and beyond the tile's edge: d - n floor(d / n) with (nx, ny) = (8, 6), in [0, n).
TEST(HostParamsLayers, TiledDriftOnAndBeyondTheTileEdge) {
    const HplDriftCase cases[] = {
        {5, 1.0, {2.0f, 1.0f}, "t = 5: raw (10, -5) -> (10 - 8, -5 + 6) = (2, 1)"},
        {4, 1.0, {0.0f, 2.0f}, "t = 4: raw (8, -4) -> x on the edge 8 -> 0 (not 8); y -4 + 6 = 2"},
        {7, 0.0, {4.0f, 0.0f}, "t = 6: raw (12, -6) -> (4, 0): y on the edge -6 -> 0"},
        {5, 0.25, {0.5f, 1.75f}, "t = 4.25: raw (8.5, -4.25) -> (0.5, 1.75), just beyond the edge"},
        {0, 0.0, {6.0f, 1.0f}, "t = -1: raw (-2, 1) -> (6, 1)"},
        {1, 0.0, {0.0f, 0.0f}, "t = 0: raw (0, 0) -> (0, 0)"},
        {1, 1.0, {2.0f, 5.0f}, "t = 1: raw (2, -1) -> (2, 5)"},
        {13, 0.5, {1.0f, 5.5f}, "t = 12.5: raw (25, -12.5) -> (25 - 24, -12.5 + 18) = (1, 5.5)"},
    };
    for (const HplDriftCase& c : cases) {
        Scene sc = HplScene();
        sc.grid.tiling = true;
        sc.render.alpha = c.alpha;
        const LayersSetup s = HplParams(sc, c.step).setup;
        EXPECT_EQ(s.drift[0], c.drift[0]) << c.why;
        EXPECT_EQ(s.drift[1], c.drift[1]) << c.why;
        EXPECT_TRUE(s.drift[0] >= 0.0f && s.drift[0] < 8.0f && s.drift[1] >= 0.0f && s.drift[1] < 6.0f) << c.why;
    }
}

// Test the relighting factor (SPEC 15, docs/pipeline.md "Relighting"): n . s = T (s0 . s), lightScale =
// max(0, s0 . s), s0 the first step's sun. The sun turns 45 degrees of azimuth per step at elevation 0, so
// s(t) = (cos 45t, sin 45t, 0) and s0 . s(t) = cos(45 t degrees).
TEST(HostParamsLayers, LightScaleIsTheClampedCosineToTheFirstStepsSun) {
    Scene sc = HplScene();
    sc.sun.azimuthSpeedDeg = 45;
    sc.layers.relight = LayersRelight::Vector;
    EXPECT_EQ(HplParams(sc, 0).setup.lightScale, 1.0f);                  // cos 0 = 1: the first step
    EXPECT_NEAR(HplParams(sc, 1).setup.lightScale, 0.70710678f, 1e-6f);  // cos 45
    const float at90 = HplParams(sc, 2).setup.lightScale;                // cos 90 = 0 (to rounding)
    EXPECT_GE(at90, 0.0f);
    EXPECT_NEAR(at90, 0.0f, 1e-7f);
    EXPECT_EQ(HplParams(sc, 3).setup.lightScale, 0.0f);  // cos 135 = -0.707: past 90 degrees, clamped to 0
    EXPECT_EQ(HplParams(sc, 4).setup.lightScale, 0.0f);  // cos 180 = -1 -> 0
    EXPECT_EQ(HplParams(sc, 5).setup.lightScale, 0.0f);  // cos 225 = -0.707 -> 0
    EXPECT_NEAR(HplParams(sc, 7).setup.lightScale, 0.70710678f, 1e-6f);  // cos 315 = 0.707: back in front
    // Every frame of a step has the step's factor: the sun is not interpolated between steps.
    sc.render.framesPerStep = 4;
    EXPECT_EQ(HplParams(sc, 3, 0, 4).setup.lightScale, 0.0f);
    EXPECT_NEAR(HplParams(sc, 1, 0, 4).setup.lightScale, 0.70710678f, 1e-6f);

    // Below the horizon: elevation 30 - 40 t at azimuth 0, so the angle between s0 and s(t) is 40 t degrees:
    // cos 40 = 0.76604444 (s at -10 deg), cos 80 = 0.17364818 (-50 deg), cos 120 = -0.5 (-90 deg) -> 0.
    Scene low = HplScene();
    low.sun.elevationDeg = 30;
    low.sun.elevationSpeedDeg = -40;
    low.layers.relight = LayersRelight::Vector;
    EXPECT_NEAR(HplParams(low, 1).setup.lightScale, 0.76604444f, 1e-6f);
    EXPECT_NEAR(HplParams(low, 2).setup.lightScale, 0.17364818f, 1e-6f);
    EXPECT_EQ(HplParams(low, 3).setup.lightScale, 0.0f);

    // Without relighting shade's T is the step's own: the factor is 1 whatever the sun, past 90 degrees and below.
    sc.layers.relight = LayersRelight::Shade;
    low.layers.relight = LayersRelight::Shade;
    for (uint32_t step : {0u, 3u, 4u}) EXPECT_EQ(HplParams(sc, step).setup.lightScale, 1.0f) << step;
    EXPECT_EQ(HplParams(low, 3).setup.lightScale, 1.0f);
}

// Test the frame's sun (SPEC 0: s = (cos el cos az, cos el sin az, sin el)) at the step, past 90 degrees of azimuth
// and below the horizon, the same for every frame of the step and with or without relighting (shade's T is then
// s0's, but the phase angle is the frame's sun).
TEST(HostParamsLayers, SunIsTheStepsDirectionPastNinetyAndBelowTheHorizon) {
    Scene sc = HplScene();
    sc.sun.azimuthSpeedDeg = 45;
    auto near3 = [](const Vec3& a, const Vec3& b, const char* why) {
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f) << why << " component " << i;
    };
    near3(HplParams(sc, 0).setup.sun, {1.0f, 0.0f, 0.0f}, "step 0: el 0, az 0");
    near3(HplParams(sc, 3).setup.sun, {-0.70710678f, 0.70710678f, 0.0f}, "step 3: az 135");
    sc.render.framesPerStep = 4;
    near3(HplParams(sc, 3, 0, 4).setup.sun, {-0.70710678f, 0.70710678f, 0.0f}, "step 3 frame 0: still az 135");
    sc.layers.relight = LayersRelight::Vector;
    near3(HplParams(sc, 4).setup.sun, {-1.0f, 0.0f, 0.0f}, "step 4 relit: az 180, the frame's sun");
    Scene low = HplScene();
    low.sun.elevationDeg = 30;
    low.sun.elevationSpeedDeg = -40;
    // el -10: (cos 10, 0, -sin 10); el -50: (cos 50, 0, -sin 50).
    near3(HplParams(low, 1).setup.sun, {0.98480775f, 0.0f, -0.17364818f}, "step 1: el -10");
    near3(HplParams(low, 2).setup.sun, {0.64278761f, 0.0f, -0.76604444f}, "step 2: el -50");
}

// Test alpha (docs/pipeline.md "Frames between steps"): one frame draws render.alpha, at its edges 0 and 1; F > 1
// frames draw (f + 1) / F, never 0; time-slicing with one frame draws (0 + 1) / 1 = 1.
TEST(HostParamsLayers, AlphaIsTheFramesFraction) {
    Scene sc = HplScene();
    sc.render.alpha = 0;
    EXPECT_EQ(HplParams(sc, 1).alpha, 0.0f);
    sc.render.alpha = 1;
    EXPECT_EQ(HplParams(sc, 1).alpha, 1.0f);
    sc.render.alpha = 0.3;
    EXPECT_EQ(HplParams(sc, 1).alpha, 0.3f);
    sc.render.alpha = 0.5;
    sc.render.framesPerStep = 4;
    EXPECT_EQ(HplParams(sc, 1, 0).alpha, 0.25f);  // frames 0 means render.frames_per_step
    EXPECT_EQ(HplParams(sc, 1, 0, 4).alpha, 0.25f);
    EXPECT_EQ(HplParams(sc, 1, 1, 4).alpha, 0.5f);
    EXPECT_EQ(HplParams(sc, 1, 3, 4).alpha, 1.0f);
    EXPECT_EQ(HplParams(sc, 1, 0, 3).alpha, float(1.0 / 3.0));  // rounded to float once
    Scene sliced = HplScene();
    sliced.render.slicesPerFrame = 2;
    EXPECT_EQ(HplParams(sliced, 1, 0, 1).alpha, 1.0f);
    EXPECT_EQ(HplParams(sliced, 1, 1, 2).alpha, 1.0f);
    EXPECT_EQ(HplParams(sliced, 1, 0, 2).alpha, 0.5f);
}

// Test the geometry handed to the kernel (core/math/Layers.h, voxel units): eye (eye - origin) / h, the grid and
// its reciprocals, spacing nz / N, extent^2 in voxel edges^2 (default the far plane), l_max (default nz), sigma h.
TEST(HostParamsLayers, GeometryFromTheGridAndTheCamera) {
    Scene sc = HplScene();
    LayersParams p = HplParams(sc, 0);
    const LayersSetup& s = p.setup;
    // ((300 - 100) / 50, (-50 + 200) / 50, (400 - 300) / 50) = (4, 3, 2).
    EXPECT_EQ(s.eye, (Vec3{4.0f, 3.0f, 2.0f}));
    EXPECT_EQ(p.origin, (std::array<float, 3>{100.0f, -200.0f, 300.0f}));
    EXPECT_EQ(s.size, (Vec3{8.0f, 6.0f, 4.0f}));
    EXPECT_EQ(s.invSize, (Vec3{0.125f, 1.0f / 6.0f, 0.25f}));
    EXPECT_EQ(s.voxelSize, 50.0f);
    EXPECT_EQ(s.count, 4u);           // default N = nz
    EXPECT_EQ(s.spacing, 1.0f);       // nz / N = 4 / 4
    EXPECT_EQ(s.outer2, 400.0f);      // extent = far 1000 m = 20 voxel edges, squared
    // Default fade 0.5: inner radius 10, 1 / (400 - 100) = 1 / 300.
    EXPECT_FLOAT_EQ(s.fadeInv2, 1.0f / 300.0f);
    EXPECT_EQ(s.maxLength, 4.0f);     // l_max default nz
    EXPECT_EQ(s.sigmaH, 6.25f);       // 0.125 * 50
    EXPECT_FALSE(s.tiling);
    EXPECT_EQ(s.light.sunRadiance, (Vec3{4.0f, 2.0f, 1.0f}));  // (1, 0.5, 0.25) * 4
    EXPECT_EQ(s.light.ambient, (Vec3{0.25f, 0.5f, 0.75f}));
    EXPECT_EQ(s.background, (Vec3{0.125f, 0.375f, 0.625f}));
    EXPECT_EQ(s.light.phase.kind, PhaseKind::HenyeyGreenstein);
    EXPECT_EQ(s.light.phase.g, 0.25f);
    EXPECT_FALSE(s.wang);
    EXPECT_EQ(s.lightScale, 1.0f);
    // Layer heights z_i = (i + 0.5) nz / N: with N = 4, 0.5 and 3.5.
    EXPECT_EQ(LayerHeight(s, 0), 0.5f);
    EXPECT_EQ(LayerHeight(s, 3), 3.5f);

    // The camera frame: forward (0, 1, 0), right = forward x up = (1, 0, 0), up (0, 0, 1); f = H / (2 tan 45) = 10.5.
    EXPECT_EQ(p.camera.forward, (Vec3{0.0f, 1.0f, 0.0f}));
    EXPECT_EQ(p.camera.right, (Vec3{1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(p.camera.upVector, (Vec3{0.0f, 0.0f, 1.0f}));
    EXPECT_NEAR(p.camera.focalPx, 10.5f, 1e-5f);
    EXPECT_EQ(p.camera.width, 33u);
    EXPECT_EQ(p.camera.height, 21u);
    EXPECT_EQ(p.camera.nearPlane, 25.0f);
    EXPECT_EQ(p.camera.farPlane, 1000.0f);
    // The centre pixel's ray is the view axis: near 25 m / 50 = 0.5, far 1000 / 50 = 20 voxel edges.
    const LayersRay ray = MakeLayersRay(p.camera, s.voxelSize, 16, 10);
    EXPECT_EQ(ray.dir, (Vec3{0.0f, 1.0f, 0.0f}));
    EXPECT_EQ(ray.tNear, 0.5f);
    EXPECT_EQ(ray.tFar, 20.0f);

    // Three layers: spacing 4 / 3, heights 2/3 and 10/3; an extent of 250 m is 5 voxel edges, 25 squared; l_max 2.5.
    sc.layers.count = 3;
    sc.layers.extent = 250;
    sc.layers.maxLength = 2.5;
    p = HplParams(sc, 0);
    EXPECT_EQ(p.setup.count, 3u);
    EXPECT_EQ(p.setup.spacing, float(4.0 / 3.0));
    EXPECT_NEAR(LayerHeight(p.setup, 0), 0.6666667f, 1e-6f);
    EXPECT_NEAR(LayerHeight(p.setup, 2), 3.3333333f, 1e-6f);
    EXPECT_EQ(p.setup.outer2, 25.0f);
    EXPECT_EQ(p.setup.maxLength, 2.5f);
    // Fade 0.2: inner radius 4, 1 / (25 - 16) = 1 / 9; fade 0 is no falloff.
    sc.layers.fade = 0.2;
    EXPECT_FLOAT_EQ(HplParams(sc, 0).setup.fadeInv2, 1.0f / 9.0f);
    sc.layers.fade = 0;
    EXPECT_EQ(HplParams(sc, 0).setup.fadeInv2, 0.0f);
    // Eight layers (two per voxel): spacing 0.5, and l_max's default is still nz = 4 (not N). The largest extent,
    // 1e30 m: (1e30 / 50)^2 = 4e56 is capped at 1e36.
    sc.layers.count = 8;
    sc.layers.extent = 1e30;
    sc.layers.maxLength = 0;
    p = HplParams(sc, 0);
    EXPECT_EQ(p.setup.spacing, 0.5f);
    EXPECT_EQ(p.setup.maxLength, 4.0f);
    EXPECT_EQ(LayerHeight(p.setup, 7), 3.75f);  // (7 + 0.5) * 0.5
    EXPECT_EQ(p.setup.outer2, 1e36f);
    EXPECT_TRUE(std::isfinite(p.setup.outer2 * 1.0f));
    // The wang opacity's settings pass through: C and D_w.
    sc.layers.wang.enabled = true;
    sc.layers.wang.coverage = 0.75;
    sc.layers.wang.density = 3;
    sc.grid.tiling = true;
    p = HplParams(sc, 0);
    EXPECT_TRUE(p.setup.wang);
    EXPECT_TRUE(p.setup.tiling);
    EXPECT_EQ(p.setup.coverage, 0.75f);
    EXPECT_EQ(p.setup.density, 3.0f);
}

// Test the tiling's wrap of a point (docs/pipeline.md "Tiling": x - n floor(x (1/n))) on and beyond the tile's
// edge, and the padded border's source voxel (PaddedSourceVoxel: the opposite edge with wrap, outside without).
TEST(HostParamsLayers, WrapOnAndBeyondTheTileEdge) {
    const float inv8 = 0.125f, inv6 = 1.0f / 6.0f;
    EXPECT_EQ(TileWrap(0.0f, 8.0f, inv8), 0.0f);
    EXPECT_EQ(TileWrap(8.0f, 8.0f, inv8), 0.0f);   // on the edge: the next tile's start
    EXPECT_EQ(TileWrap(8.5f, 8.0f, inv8), 0.5f);   // beyond it
    EXPECT_EQ(TileWrap(-0.5f, 8.0f, inv8), 7.5f);  // before the start: the previous tile's end
    EXPECT_EQ(TileWrap(-8.0f, 8.0f, inv8), 0.0f);
    EXPECT_EQ(TileWrap(16.0f, 8.0f, inv8), 0.0f);
    EXPECT_EQ(TileWrap(23.25f, 8.0f, inv8), 7.25f);  // 23.25 - 16
    EXPECT_EQ(TileWrap(7.75f, 8.0f, inv8), 7.75f);
    EXPECT_EQ(TileWrap(-1e-7f, 8.0f, inv8), 8.0f);  // -1e-7 + 8 rounds to 8: the closed end of [0, n]
    EXPECT_EQ(TileWrap(6.0f, 6.0f, inv6), 0.0f);    // 6 * float(1/6) rounds to 1: floor 1
    EXPECT_EQ(TileWrap(12.0f, 6.0f, inv6), 0.0f);
    EXPECT_EQ(TileWrap(-6.0f, 6.0f, inv6), 0.0f);
    EXPECT_EQ(TileWrap(6.5f, 6.0f, inv6), 0.5f);
    EXPECT_EQ(TileWrap(-0.5f, 6.0f, inv6), 5.5f);
    // Padded index i stands for voxel i - 1 inside; the border 0 and n + 1 is voxel n - 1 and 0 with wrap.
    EXPECT_EQ(PaddedSourceVoxel(0, 8, true), 7);
    EXPECT_EQ(PaddedSourceVoxel(9, 8, true), 0);
    EXPECT_EQ(PaddedSourceVoxel(0, 8, false), -1);
    EXPECT_EQ(PaddedSourceVoxel(9, 8, false), -1);
    EXPECT_EQ(PaddedSourceVoxel(1, 8, true), 0);
    EXPECT_EQ(PaddedSourceVoxel(8, 8, false), 7);
}

// Test the GPU block (core/pipeline/LayersGpu.h): each member holds the host's value,
// with every field distinct, so a swapped or dropped lane fails. Tiled, wang, relit at step 1 (sun at az 45).
TEST(HostParamsLayers, GpuBlockCarriesTheHostValues) {
    Scene sc = HplScene();
    sc.grid.tiling = true;
    sc.sun.azimuthSpeedDeg = 45;
    sc.layers.relight = LayersRelight::Vector;
    sc.layers.wang.enabled = true;
    sc.layers.wang.coverage = 0.75;
    sc.layers.wang.density = 3;
    sc.layers.maxLength = 2.5;
    const LayersParams p = HplParams(sc, 1);
    const LayersGpu g = MakeLayersGpu(p);
    const float c45 = p.setup.sun[0];
    EXPECT_NEAR(c45, 0.70710678f, 1e-6f);
    using F3 = std::array<float, 3>;
    EXPECT_EQ(g.eye, (F3{4.0f, 3.0f, 2.0f}));
    EXPECT_NEAR(g.focalPx, 10.5f, 1e-5f);
    EXPECT_EQ(g.forward, (F3{0.0f, 1.0f, 0.0f}));
    EXPECT_EQ(g.nearPlane, 25.0f);  // m
    EXPECT_EQ(g.right, (F3{1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(g.farPlane, 1000.0f);  // m
    EXPECT_EQ(g.up, (F3{0.0f, 0.0f, 1.0f}));
    EXPECT_EQ(g.voxelSize, 50.0f);
    EXPECT_EQ(g.size, (F3{8.0f, 6.0f, 4.0f}));
    EXPECT_EQ(g.sigmaH, 6.25f);
    EXPECT_EQ(g.invSize, (F3{0.125f, 1.0f / 6.0f, 0.25f}));
    EXPECT_EQ(g.spacing, 1.0f);
    EXPECT_NEAR(g.sun[0], 0.70710678f, 1e-6f);
    EXPECT_NEAR(g.sun[1], 0.70710678f, 1e-6f);
    EXPECT_NEAR(g.sun[2], 0.0f, 1e-7f);
    EXPECT_EQ(g.light.phaseG, 0.25f);
    EXPECT_EQ(g.light.sunRadiance, (F3{4.0f, 2.0f, 1.0f}));
    EXPECT_EQ(g.outer2, 400.0f);  // extent^2
    EXPECT_EQ(g.light.mieIndexPerRadian, kMieCloudTable.indexPerRadian);
    EXPECT_EQ(g.light.ambient[2], 0.75f);
    EXPECT_EQ(g.light.pointOn, 0u);
    EXPECT_EQ(g.background, (F3{0.125f, 0.375f, 0.625f}));
    EXPECT_EQ(g.maxLength, 2.5f);  // l_max
    EXPECT_EQ(g.width, 33u);
    EXPECT_EQ(g.height, 21u);
    EXPECT_EQ(g.count, 4u);
    EXPECT_EQ(g.flags, uint32_t(kLayersGpuTiling | kLayersGpuWang));
    EXPECT_EQ(g.light.phaseKind, uint32_t(PhaseKind::HenyeyGreenstein));
    EXPECT_EQ(g.light.mieCount, kMieCloudTable.count);
    // Padded strides: px = 8 + 2 = 10, px py = 10 * (6 + 2) = 80.
    EXPECT_EQ(g.strideY, 10u);
    EXPECT_EQ(g.strideZ, 80u);
    // Step 1, alpha 0.5: t = 0.5, raw drift (1, -0.5), tiled (1, 5.5); then C, D_w.
    EXPECT_EQ(g.drift, (std::array<float, 2>{1.0f, 5.5f}));
    EXPECT_EQ(g.coverage, 0.75f);
    EXPECT_EQ(g.density, 3.0f);
    EXPECT_NEAR(g.lightScale, 0.70710678f, 1e-6f);  // cos 45
    EXPECT_EQ(g.lightScale, p.setup.lightScale);
    EXPECT_EQ(g.fadeInv2, p.setup.fadeInv2);  // the falloff, 1 / 300 (default fade 0.5 of 20 voxel edges)
    EXPECT_FLOAT_EQ(g.fadeInv2, 1.0f / 300.0f);
    // Step 3 (135 degrees from s0): the block carries the clamped 0.
    EXPECT_EQ(MakeLayersGpu(HplParams(sc, 3)).lightScale, 0.0f);
    // Without tiling or wang no flag bit.
    sc.grid.tiling = false;
    sc.layers.wang.enabled = false;
    EXPECT_EQ(MakeLayersGpu(HplParams(sc, 1)).flags, 0u);
}

// Test the OpenGL draw order (SPEC 15: decreasing |z_i - z_eye|, ties by lower index) on four layers at
// 0.5, 1.5, 2.5, 3.5.
TEST(HostParamsLayers, DrawOrderIsDecreasingDistanceFromTheEye) {
    LayersSetup s;
    s.count = 4;
    s.spacing = 1;
    s.eye = {0, 0, 2.0f};  // distances 1.5, 0.5, 0.5, 1.5: 0 and 3 tie, 1 and 2 tie
    EXPECT_EQ(LayersDrawOrder(s), (std::vector<uint32_t>{0, 3, 1, 2}));
    s.eye[2] = 1.25f;  // 0.75, 0.25, 1.25, 2.25
    EXPECT_EQ(LayersDrawOrder(s), (std::vector<uint32_t>{3, 2, 0, 1}));
    s.eye[2] = -1.0f;  // below: 1.5, 2.5, 3.5, 4.5
    EXPECT_EQ(LayersDrawOrder(s), (std::vector<uint32_t>{3, 2, 1, 0}));
    s.eye[2] = 9.0f;   // above: 8.5, 7.5, 6.5, 5.5
    EXPECT_EQ(LayersDrawOrder(s), (std::vector<uint32_t>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace cb
