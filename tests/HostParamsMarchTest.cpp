// The ray marcher's, the splat renderer's and shade's host-side parameters (SPEC 0, 6, 8, 10; docs/pipeline.md
// "Ray-march renderer", "Lightning", "The real-time loop") against the formulas worked by hand. They are made once
// on the host (MakeMarchParams, MakeSplatParams, MakeShadeParams, MakeCameraFrame) and packed for the GPUs
// (MakeMarchGpu, MakeSplatFrame, MakeShadePlan); every backend receives them alike, so the differential tests
// cannot see a wrong one. Each expected number is derived in its comment. Edges: the first step, alpha at 0 and 1,
// the sun past 90 degrees and below the horizon, the flash window's first and last step, a camera looking straight
// down (the degenerate up), bricks and tiles on and beyond the grid's edge.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "core/math/Camera.h"
#include "core/math/March.h"
#include "core/pipeline/MarchGpu.h"
#include "core/pipeline/ShadePlan.h"
#include "core/pipeline/SplatFrame.h"
#include "core/scene/Scene.h"
#include "core/stages/render_march/RenderMarch.h"
#include "core/stages/render_splat/RenderSplat.h"
#include "core/stages/shade/Shade.h"

namespace cb {
namespace {

// Grid 10 x 8 x 5, h = 20 m, origin (-100, 40, 0). One camera at (0, 120, 50) looking straight down (target
// (0, 120, -50)), fov 90 deg, 31 x 25 pixels, near 10 m, far 2000 m. The sun starts at elevation 20, azimuth 0 and
// sinks 35 degrees a step. sigma 0.03125 1/m. Lightning at (60, 0, 100), on for steps 3 and 4.
Scene HpmScene() {
    Scene sc;
    sc.grid.size = {10, 8, 5};
    sc.grid.voxelSize = 20;
    sc.grid.origin = {-100, 40, 0};
    sc.render.width = 31;
    sc.render.height = 25;
    CameraSettings cam;
    cam.eye = {0, 120, 50};
    cam.target = {0, 120, -50};
    cam.up = {0, 0, 1};
    cam.fovDeg = 90;
    cam.nearPlane = 10;
    cam.farPlane = 2000;
    sc.render.cameras = {cam};
    sc.sun.elevationDeg = 20;
    sc.sun.azimuthDeg = 0;
    sc.sun.elevationSpeedDeg = -35;
    sc.sun.color = {0.5, 1, 0.25};
    sc.sun.intensity = 2;
    sc.lighting.ambient = {0.25, 0.5, 0.75};
    sc.lighting.background = {0.125, 0.375, 0.625};
    // The dual lobe's numbers too, though Cornette-Shanks ignores them: the blocks carry them for any kind.
    sc.phase = {PhaseKind::CornetteShanks, 0.375f, 0.625f, -0.25f, 0.875f};
    sc.shade.sigma = 0.03125;
    sc.march.step = 0.75;
    sc.march.adaptive = true;
    sc.march.kappa = 0.125;
    sc.march.adaptiveStart = 16;
    sc.march.epsilon = 0.0625;
    sc.march.jitter = true;
    sc.march.light = MarchLightSource::March;
    sc.march.lightSteps = 6;
    sc.march.powder = true;
    sc.march.powderC = 3;
    sc.march.skipping = true;
    sc.march.brick = 4;
    sc.ca.seed = 777;
    sc.lightning.enabled = true;
    sc.lightning.position = {60, 0, 100};
    sc.lightning.color = {0.5, 0.25, 1};
    sc.lightning.intensity = 8;
    sc.lightning.radius = 5;
    sc.lightning.flashStart = 3;
    sc.lightning.flashSteps = 2;
    sc.render.ground.on = true;
    sc.render.ground.albedo = {0.25, 0.5, 0.125};
    sc.density.tile = 4;
    sc.density.band = 2;
    sc.splat.qMin = 0.125;
    sc.splat.splatScale = 1.5;
    sc.splat.opacity = 0.625;
    return sc;
}

MarchParams HpmMarch(const Scene& sc, uint32_t step, uint32_t frame = 0, uint32_t frames = 0) {
    return MakeMarchParams(sc, sc.render.cameras[0], step, frame, frames);
}

void HpmNear3(const Vec3& a, const Vec3& b, const char* why) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f) << why << " component " << i;
}

// Test the camera frame of a view straight down (docs/pipeline.md: a degenerate up is replaced by +y): forward
// (0, 0, -1), right = forward x (0, 1, 0) = (1, 0, 0), up = right x forward = (0, 1, 0); f = H / (2 tan(fov / 2)):
// 25 / (2 tan 45) = 12.5, and fov 60 over 240 rows: 240 / (2 tan 30) = 207.84610.
TEST(HostParamsMarch, CameraFrameByHand) {
    const Scene sc = HpmScene();
    const CameraFrame f = MakeCameraFrame(sc.render.cameras[0], 31, 25);
    EXPECT_EQ(f.forward, (Vec3{0.0f, 0.0f, -1.0f}));
    EXPECT_EQ(f.right, (Vec3{1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(f.upVector, (Vec3{0.0f, 1.0f, 0.0f}));
    EXPECT_NEAR(f.focalPx, 12.5f, 1e-5f);
    EXPECT_EQ(f.eye, (Vec3{0.0f, 120.0f, 50.0f}));
    EXPECT_EQ(f.nearPlane, 10.0f);
    EXPECT_EQ(f.farPlane, 2000.0f);
    CameraSettings side;
    side.eye = {0, 0, 0};
    side.target = {0, -10, 0};  // looking along -y: right = (0, -1, 0) x (0, 0, 1) = (-1, 0, 0), up (0, 0, 1)
    side.fovDeg = 60;
    const CameraFrame g = MakeCameraFrame(side, 320, 240);
    EXPECT_EQ(g.forward, (Vec3{0.0f, -1.0f, 0.0f}));
    EXPECT_EQ(g.right, (Vec3{-1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(g.upVector, (Vec3{0.0f, 0.0f, 1.0f}));
    EXPECT_NEAR(g.focalPx, 207.84610f, 1e-3f);
    // Depth along forward: a point 7 m in front and 3 m to the side is at depth 7.
    EXPECT_NEAR(g.Depth({3.0f, -7.0f, 0.0f}), 7.0f, 1e-6f);
}

// Test the march's constants (SPEC 10, voxel units): the eye's ray, sigma h, the step schedule, the sun of the
// step (past the horizon it is handed on as is), and the pass-through values.
TEST(HostParamsMarch, SetupFromTheScene) {
    const Scene sc = HpmScene();
    const MarchParams p = HpmMarch(sc, 0);
    const MarchSetup& s = p.setup;
    EXPECT_EQ(s.size, (Vec3{10.0f, 8.0f, 5.0f}));
    EXPECT_EQ(s.voxelSize, 20.0f);
    EXPECT_EQ(p.origin, (std::array<float, 3>{-100.0f, 40.0f, 0.0f}));
    EXPECT_EQ(s.step, 0.75f);
    EXPECT_TRUE(s.adaptive);
    EXPECT_EQ(s.kappa, 0.125f);
    EXPECT_EQ(s.adaptiveStart, 16.0f);
    EXPECT_EQ(s.sigmaH, 0.625f);  // 0.03125 * 20
    EXPECT_EQ(s.epsilon, 0.0625f);
    EXPECT_EQ(s.light.sunRadiance, (Vec3{1.0f, 2.0f, 0.5f}));  // (0.5, 1, 0.25) * 2
    EXPECT_EQ(s.light.ambient, (Vec3{0.25f, 0.5f, 0.75f}));
    EXPECT_EQ(s.background, (Vec3{0.125f, 0.375f, 0.625f}));
    EXPECT_EQ(s.light.phase.kind, PhaseKind::CornetteShanks);
    EXPECT_EQ(s.light.phase.g, 0.375f);
    EXPECT_EQ(s.light.phase.gForward, 0.625f);
    EXPECT_EQ(s.light.phase.gBackward, -0.25f);
    EXPECT_EQ(s.light.phase.blend, 0.875f);
    EXPECT_TRUE(s.powder);
    EXPECT_EQ(s.powderC, 3.0f);
    EXPECT_EQ(p.light, MarchLightSource::March);
    EXPECT_EQ(p.lightSteps, 6u);
    EXPECT_TRUE(p.jitter);
    EXPECT_EQ(p.seed, 777u);
    EXPECT_TRUE(p.skipping);
    EXPECT_EQ(p.brick, 4u);
    EXPECT_TRUE(p.ground.on);
    EXPECT_EQ(p.ground.albedo, (Vec3{0.25f, 0.5f, 0.125f}));
    // The adaptive step: Delta(t) = 0.75 + 0.125 max(0, t - 16): 0.75 up to t = 16, 0.75 + 0.125 * 8 = 1.75 at 24.
    EXPECT_EQ(MarchStepAt(s, 16.0f), 0.75f);
    EXPECT_EQ(MarchStepAt(s, 24.0f), 1.75f);

    // The sun: s = (cos el cos az, cos el sin az, sin el) at el 20 - 35 t.
    HpmNear3(s.sun, {0.93969262f, 0.0f, 0.34202014f}, "step 0: el 20");
    HpmNear3(HpmMarch(sc, 1).setup.sun, {0.96592583f, 0.0f, -0.25881905f}, "step 1: el -15, below the horizon");
    HpmNear3(HpmMarch(sc, 2).setup.sun, {0.64278761f, 0.0f, -0.76604444f}, "step 2: el -50");
    // Frames between steps share the step's sun.
    HpmNear3(HpmMarch(sc, 2, 0, 4).setup.sun, {0.64278761f, 0.0f, -0.76604444f}, "step 2 frame 0 of 4");
    // Past 90 degrees of azimuth: az 30 + 100 t at el 0; step 1 is az 130: (cos 130, sin 130, 0).
    Scene turning = HpmScene();
    turning.sun.elevationDeg = 0;
    turning.sun.elevationSpeedDeg = 0;
    turning.sun.azimuthDeg = 30;
    turning.sun.azimuthSpeedDeg = 100;
    HpmNear3(HpmMarch(turning, 1).setup.sun, {-0.64278761f, 0.76604444f, 0.0f}, "step 1: az 130");
    // A sun path: keyframes (step 2: el 10, az 0) and (step 6: el 50, az 200); step 4 is half way: el 30, az 100;
    // before the first keyframe (step 0) it holds the first: el 10, az 0.
    Scene path = HpmScene();
    path.sun.elevationSpeedDeg = 0;
    path.sun.path = {{2, 10, 0}, {6, 50, 200}};
    HpmNear3(HpmMarch(path, 4).setup.sun, {-0.15038373f, 0.85286853f, 0.5f}, "path step 4: el 30, az 100");
    HpmNear3(HpmMarch(path, 0).setup.sun, {0.98480775f, 0.0f, 0.17364818f}, "path step 0: held at el 10");
    HpmNear3(HpmMarch(path, 9).setup.sun, {-0.60402277f, -0.21984631f, 0.76604444f}, "path step 9: el 50, az 200");
}

// Test alpha (q_alpha = (1 - alpha) q_prev + alpha q_cur) and the jitter's frame key (the step, docs/pipeline.md:
// the frames of one step share their jitter pattern).
TEST(HostParamsMarch, AlphaAndTheJittersFrameKey) {
    Scene sc = HpmScene();
    sc.render.alpha = 0;
    EXPECT_EQ(HpmMarch(sc, 0).alpha, 0.0f);
    EXPECT_EQ(HpmMarch(sc, 0).frame, 0u);  // the first step
    sc.render.alpha = 1;
    EXPECT_EQ(HpmMarch(sc, 5).alpha, 1.0f);
    EXPECT_EQ(HpmMarch(sc, 5).frame, 5u);
    sc.render.framesPerStep = 4;
    EXPECT_EQ(HpmMarch(sc, 5, 0, 4).alpha, 0.25f);  // (0 + 1) / 4
    EXPECT_EQ(HpmMarch(sc, 5, 3, 4).alpha, 1.0f);   // (3 + 1) / 4
    EXPECT_EQ(HpmMarch(sc, 5, 3, 4).frame, 5u);     // the step, not the frame
    // The jitter of pixel 0 at step 5 is rand24(777, 5, 3, 0) / 2^24, in [0, 1).
    const float xi = MarchJitter(777, 5, 0);
    EXPECT_EQ(xi, float(Rand24(777, 5, kStreamOther, 0)) / 16777216.0f);
    EXPECT_TRUE(xi >= 0.0f && xi < 1.0f);
}

// Test the point light (Wang, Ji and Zhang, eq. 21; docs/pipeline.md "Lightning"): its position in voxel units
// (x - origin) / h, radiance colour * intensity, r0^2, and the flash window [start, start + steps) at its edges.
TEST(HostParamsMarch, PointLightAndItsFlashWindow) {
    Scene sc = HpmScene();
    const LightTerms l = HpmMarch(sc, 3).setup.light;
    // ((60 + 100) / 20, (0 - 40) / 20, (100 - 0) / 20) = (8, -2, 5).
    EXPECT_EQ(l.pointPosition, (Vec3{8.0f, -2.0f, 5.0f}));
    EXPECT_EQ(l.pointRadiance, (Vec3{4.0f, 2.0f, 8.0f}));  // (0.5, 0.25, 1) * 8
    EXPECT_EQ(l.pointMinDistance2, 25.0f);                 // 5 m squared, metres^2
    EXPECT_FALSE(HpmMarch(sc, 2).setup.light.pointOn);     // before the window
    EXPECT_TRUE(HpmMarch(sc, 3).setup.light.pointOn);      // its first step
    EXPECT_TRUE(HpmMarch(sc, 4).setup.light.pointOn);      // its last step: 3 + 2 - 1
    EXPECT_FALSE(HpmMarch(sc, 5).setup.light.pointOn);     // 3 + 2: past it
    // A flash at step 0 of one step: on at the first step only.
    sc.lightning.flashStart = 0;
    sc.lightning.flashSteps = 1;
    EXPECT_TRUE(HpmMarch(sc, 0).setup.light.pointOn);
    EXPECT_FALSE(HpmMarch(sc, 1).setup.light.pointOn);
    // The window's end past 2^32 - 1 does not wrap: start 4294967295, 2 steps: on at 4294967295.
    sc.lightning.flashStart = 4294967295u;
    sc.lightning.flashSteps = 2;
    EXPECT_TRUE(HpmMarch(sc, 4294967295u).setup.light.pointOn);
    EXPECT_FALSE(HpmMarch(sc, 0).setup.light.pointOn);
    sc.lightning.enabled = false;
    sc.lightning.flashStart = 3;
    EXPECT_FALSE(HpmMarch(sc, 3).setup.light.pointOn);
}

// Test the centre pixel's ray (docs/pipeline.md "Rays"): dir = forward, depth = t h, so near 10 m is t = 0.5 and the
// eye at voxel z 2.5 looking down leaves the box's floor at t = 2.5 (far 2000 m = t 100 is clipped by the box).
TEST(HostParamsMarch, CentrePixelRayClippedToNearAndBox) {
    const MarchParams p = HpmMarch(HpmScene(), 0);
    const MarchRayGeometry r = MakePixelRay(p.camera, p.origin, p.setup.voxelSize, p.setup.size, 15, 12);
    // ((0 + 100) / 20, (120 - 40) / 20, 50 / 20) = (5, 4, 2.5).
    EXPECT_EQ(r.origin, (Vec3{5.0f, 4.0f, 2.5f}));
    EXPECT_EQ(r.dir, (Vec3{0.0f, 0.0f, -1.0f}));
    EXPECT_EQ(r.tMin, 0.5f);
    EXPECT_EQ(r.tMax, 2.5f);
}

// Test the march's GPU block (core/pipeline/MarchGpu.h): each member holds the host's value.
TEST(HostParamsMarch, GpuBlockCarriesTheHostValues) {
    const Scene sc = HpmScene();
    const Extent3 e = sc.grid.size;
    const MarchParams p = HpmMarch(sc, 3);
    const MarchGpu g = MakeMarchGpu(p, e);
    using F3 = std::array<float, 3>;
    EXPECT_EQ(g.eye, (F3{5.0f, 4.0f, 2.5f}));
    EXPECT_NEAR(g.focalPx, 12.5f, 1e-5f);
    EXPECT_EQ(g.forward, (F3{0.0f, 0.0f, -1.0f}));
    EXPECT_EQ(g.nearPlane, 10.0f);
    EXPECT_EQ(g.right, (F3{1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(g.farPlane, 2000.0f);
    EXPECT_EQ(g.up, (F3{0.0f, 1.0f, 0.0f}));
    EXPECT_EQ(g.voxelSize, 20.0f);
    EXPECT_EQ(g.size, (F3{10.0f, 8.0f, 5.0f}));
    EXPECT_EQ(g.sigmaH, 0.625f);
    EXPECT_EQ(g.baseStep, 0.75f);
    EXPECT_EQ(g.kappa, 0.125f);
    EXPECT_EQ(g.adaptiveStart, 16.0f);
    EXPECT_EQ(g.epsilon, 0.0625f);
    // Step 3: el 20 - 105 = -85: (cos 85, 0, -sin 85) = (0.08715574, 0, -0.99619470).
    EXPECT_NEAR(g.sun[0], 0.08715574f, 1e-6f);
    EXPECT_EQ(g.sun[1], 0.0f);
    EXPECT_NEAR(g.sun[2], -0.99619470f, 1e-6f);
    EXPECT_EQ(g.light.phaseG, 0.375f);
    EXPECT_EQ(g.light.phaseKind, uint32_t(PhaseKind::CornetteShanks));
    EXPECT_EQ(g.light.phaseGForward, 0.625f);
    EXPECT_EQ(g.light.phaseGBackward, -0.25f);
    EXPECT_EQ(g.light.phaseBlend, 0.875f);
    EXPECT_EQ(g.light.sunRadiance, (F3{1.0f, 2.0f, 0.5f}));
    EXPECT_EQ(g.powderC, 3.0f);
    EXPECT_EQ(g.light.ambient, (F3{0.25f, 0.5f, 0.75f}));
    EXPECT_EQ(g.light.mieIndexPerRadian, kMieCloudTable.indexPerRadian);
    EXPECT_EQ(g.light.mieCount, kMieCloudTable.count);
    EXPECT_EQ(g.light.voxelSize, 20.0f);
    EXPECT_EQ(g.background, (F3{0.125f, 0.375f, 0.625f}));
    EXPECT_EQ(g.light.pointPosition, (F3{8.0f, -2.0f, 5.0f}));
    EXPECT_EQ(g.light.pointMinDistance2, 25.0f);  // r0^2
    EXPECT_EQ(g.light.pointRadiance, (F3{4.0f, 2.0f, 8.0f}));
    EXPECT_EQ(g.light.pointOn, 1u);
    EXPECT_EQ(g.width, 31u);
    EXPECT_EQ(g.height, 25u);
    EXPECT_EQ(g.seed, 777u);
    EXPECT_EQ(g.frame, 3u);  // the step
    const uint32_t all = kMarchGpuAdaptive | kMarchGpuJitter | kMarchGpuPowder | kMarchGpuSkipping |
                         kMarchGpuLightMarch | kMarchGpuGround;
    EXPECT_EQ(g.flags, all);
    EXPECT_EQ(g.lightSteps, 6u);
    EXPECT_EQ(g.brick, 4u);
    // px = 10 + 2 = 12, px (8 + 2) = 120.
    EXPECT_EQ(g.strideY, 12u);
    EXPECT_EQ(g.strideZ, 120u);
    // Bricks of 4: ceil(10 / 4) = 3 (a partial brick beyond x 8), ceil(8 / 4) = 2 (on the edge), ceil(5 / 4) = 2.
    EXPECT_EQ(g.bricks, (std::array<uint32_t, 3>{3, 2, 2}));
    // Step 5: the flash is over, the point light alone goes off.
    EXPECT_EQ(MakeMarchGpu(HpmMarch(sc, 5), e).flags, all);
    EXPECT_EQ(MakeMarchGpu(HpmMarch(sc, 5), e).light.pointOn, 0u);
    // Brick 0 counts as 1: one brick per voxel.
    MarchParams q = p;
    q.brick = 0;
    EXPECT_EQ(MakeMarchGpu(q, e).bricks, (std::array<uint32_t, 3>{10, 8, 5}));
    EXPECT_EQ(MakeMarchGpu(q, e).brick, 1u);
    EXPECT_EQ(MarchBrickCounts({9, 8, 1}, 8), (std::array<uint32_t, 3>{2, 1, 1}));  // 9 = one past the edge
}

// Test the splat renderer's parameters and its GPU frame (SPEC 8; core/math/Splat.h's SplatFrame): the splat
// diameter splat_scale h, alpha, the tiles ceil(n / tile), and the world (not voxel) eye.
TEST(HostParamsMarch, SplatFrameCarriesTheHostValues) {
    Scene sc = HpmScene();
    sc.render.alpha = 1;
    const SplatParams p = MakeSplatParams(sc, sc.render.cameras[0], 2);
    EXPECT_EQ(p.splatDiameter, 30.0f);  // 1.5 * 20
    EXPECT_EQ(p.alpha, 1.0f);
    EXPECT_EQ(p.qMin, 0.125f);
    EXPECT_EQ(p.opacity, 0.625f);
    EXPECT_EQ(p.tile, 4u);
    EXPECT_EQ(p.band, 2u);
    HpmNear3(p.sun, {0.64278761f, 0.0f, -0.76604444f}, "splat sun at step 2: el -50");
    const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
    SplatParams withOrder = p;
    withOrder.order = &order;
    const SplatFrame f = MakeSplatFrame(withOrder, sc.grid.size, FlattenSplatOrder(order), 31, 25);
    EXPECT_EQ(f.grid[0], 10u);
    EXPECT_EQ(f.grid[1], 8u);
    EXPECT_EQ(f.grid[2], 5u);
    // Looking down: |forward| largest on z, then x before y at the tie: axes (2, 0, 1); 400 voxels.
    EXPECT_EQ(f.axes[0], 2u);
    EXPECT_EQ(f.axes[1], 0u);
    EXPECT_EQ(f.axes[2], 1u);
    EXPECT_EQ(f.voxelCount, 400u);
    EXPECT_EQ(f.orderBase[0], 0u);
    EXPECT_EQ(f.orderBase[1], 5u);   // after z's 5
    EXPECT_EQ(f.orderBase[2], 15u);  // after x's 10
    // Tiles of 4: ceil(10 / 4) = 3 across (a partial tile), ceil(8 / 4) = 2 down (on the edge).
    EXPECT_EQ(f.boxTile, 4u);
    EXPECT_EQ(f.boxBand, 2u);
    EXPECT_EQ(f.boxTilesX, 3u);
    EXPECT_EQ(f.boxTilesY, 2u);
    EXPECT_EQ(f.width, 31u);
    EXPECT_EQ(f.height, 25u);
    EXPECT_EQ(f.eye[0], 0.0f);
    EXPECT_EQ(f.eye[1], 120.0f);
    EXPECT_EQ(f.eye[2], 50.0f);
    EXPECT_EQ(f.nearPlane, 10.0f);
    EXPECT_EQ(f.forward[2], -1.0f);
    EXPECT_NEAR(f.focalPx, 12.5f, 1e-5f);
    EXPECT_EQ(f.right[0], 1.0f);
    EXPECT_EQ(f.light.mieIndexPerRadian, kMieCloudTable.indexPerRadian);
    EXPECT_EQ(f.up[1], 1.0f);
    EXPECT_EQ(f.light.mieCount, kMieCloudTable.count);
    EXPECT_NEAR(f.sun[2], -0.76604444f, 1e-6f);
    EXPECT_EQ(f.light.phaseG, 0.375f);
    EXPECT_EQ(f.light.sunRadiance, (std::array<float, 3>{1.0f, 2.0f, 0.5f}));
    EXPECT_EQ(f.light.phaseKind, uint32_t(PhaseKind::CornetteShanks));
    EXPECT_EQ(f.light.phaseGForward, 0.625f);
    EXPECT_EQ(f.light.phaseBlend, 0.875f);
    EXPECT_EQ(f.light.pointOn, 0u);
    EXPECT_EQ(f.qMin, 0.125f);
    EXPECT_EQ(f.opacity, 0.625f);
    EXPECT_EQ(f.origin[0], -100.0f);
    EXPECT_EQ(f.origin[1], 40.0f);
    EXPECT_EQ(f.origin[2], 0.0f);
    EXPECT_EQ(f.voxelSize, 20.0f);  // h
    EXPECT_EQ(f.splatDiameter, 30.0f);
    EXPECT_EQ(f.alpha, 1.0f);
}

// Test shade's sun and plan (SPEC 6): the step's sun, or with relighting the first step's at every step; the shaded
// grid ceil(n / f); the principal axis and the slice order for a sun below the horizon (visited from the bottom).
TEST(HostParamsMarch, ShadeSunAndPlanBelowTheHorizon) {
    Scene sc = HpmScene();
    HpmNear3(MakeShadeParams(sc, 2).sun, {0.64278761f, 0.0f, -0.76604444f}, "shade at step 2: el -50");
    sc.needs.shadeOnce = true;  // as the plan decides when a renderer relights (layers.relight "vector")
    HpmNear3(MakeShadeParams(sc, 2).sun, {0.93969262f, 0.0f, 0.34202014f}, "relit: s0 (el 20) at step 2");
    sc.needs.shadeOnce = false;
    ShadeParams sp = MakeShadeParams(sc, 2);
    sp.resolution = 2;
    // el -50: |s_z| = 0.766 >= |s_x| = 0.643: w = z, below: slices from k = 0 up. Cells ceil((10, 8, 5) / 2).
    const ShadePlan below = MakeShadePlan(sp, sc.grid.size);
    EXPECT_EQ(below.cells[0], 5u);
    EXPECT_EQ(below.cells[1], 4u);
    EXPECT_EQ(below.cells[2], 3u);
    EXPECT_EQ(below.geometry.w, 2);
    EXPECT_FALSE(below.geometry.sunAbove);
    EXPECT_EQ(below.nw, 3u);
    EXPECT_EQ(below.SliceW(0), 0u);
    EXPECT_EQ(below.SliceW(2), 2u);
    // Step 0, el 20: |s_x| = 0.940 largest: w = x (u = y, v = z), above: slices from i = nw - 1 = 4 down.
    sp = MakeShadeParams(sc, 0);
    sp.resolution = 2;
    const ShadePlan above = MakeShadePlan(sp, sc.grid.size);
    EXPECT_EQ(above.geometry.w, 0);
    EXPECT_EQ(above.geometry.u, 1);
    EXPECT_EQ(above.geometry.v, 2);
    EXPECT_TRUE(above.geometry.sunAbove);
    EXPECT_EQ(above.nu, 4u);
    EXPECT_EQ(above.nv, 3u);
    EXPECT_EQ(above.nw, 5u);
    EXPECT_EQ(above.SliceW(0), 4u);
    EXPECT_NEAR(above.geometry.absSw, 0.93969262f, 1e-6f);
}

}  // namespace
}  // namespace cb
