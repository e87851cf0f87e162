// Metamorphic invariants of the renderers (docs/testing.md,
// "Metamorphic invariants: culling, skipping, origin"): culling and empty-space
// skipping on or off give the same image bit for bit, on scenes built to
// stress them (splats at the frustum's edges, cloud that appears and dissolves
// between the two interpolated steps, cameras inside the volume and on its
// faces and tile edges). Every backend, both renderers. Moving the origin:
// MetamorphicRenderOriginTest.cpp.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Splat.h"
#include "core/pipeline/SplatFrame.h"
#include "tests/MetamorphicRender.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// ---- The frustum's edges, worked by hand -------------------
//
// Grid 40 x 40 x 1, h = 1, origin 0, tile = band = 1. The eye (0.5, 20.5, 0.5)
// looks along +x (target (10.5, 20.5, 0.5)), fov 90 on 64 x 64: f = 32. With
// up = +z: right = forward x up = (0, -1, 0). Splat diameter d = 4 (radius 2),
// near plane 1. Voxel (16, 3, 0) has its centre at (16.5, 3.5, 0.5): depth 16,
// x_cam = 17, so px = 32 + 17 * 32/16 = 66 (2 px right of the image), py = 32,
// size 4 * 32/16 = 8: it covers 62 <= x + 0.5 < 70, pixels x = 62..63 on the
// image, y = 28..35. The right side plane widened by a pixel has the normal
// 32 right - 33 forward = (-33, -32, 0) / 45.967; n.(16, -17, 0) = 16/45.967
// = 0.348: outside the plane, yet within the radius 2, so the box stays.
// Voxel (16, 0, 0): x_cam = 20, px = 72, covers 68..75 (off the image); its
// distance (-528 + 640)/45.967 = 2.437 > 2, so the box is culled.
// Mirrors: (16, 37, 0) has x_cam = -17 (left edge, pixels 0..1); with up = +y
// (right = +z, image up = +y) (16, 3, 0) sits at y_cam = -17: bottom edge
// (rows 62..63), (16, 37, 0) at the top (rows 0..1).

struct EdgeCase {
    const char* name;
    uint32_t i, j;
    std::array<double, 3> up;
    bool visible;        // the box stays (and the splat covers pixels)
    int x0, x1, y0, y1;  // the covered pixels, worked by hand (visible only)
    float size = 8;      // the splat's edge in pixels
};

const EdgeCase kEdgeCases[] = {
    {"right", 16, 3, {0, 0, 1}, true, 62, 63, 28, 35},
    {"left", 16, 37, {0, 0, 1}, true, 0, 1, 28, 35},
    {"bottom", 16, 3, {0, 1, 0}, true, 28, 35, 62, 63},
    {"top", 16, 37, {0, 1, 0}, true, 28, 35, 0, 1},
    {"beyond the radius, right", 16, 0, {0, 0, 1}, false, 0, 0, 0, 0},
    {"beyond the radius, bottom", 16, 0, {0, 1, 0}, false, 0, 0, 0, 0},
    // Depth 0 and 1 (the near plane is 1): not beyond the near plane.
    {"behind the near plane", 0, 20, {0, 0, 1}, false, 0, 0, 0, 0},
    {"on the near plane", 1, 20, {0, 0, 1}, false, 0, 0, 0, 0},
    // Depth 2, one voxel beyond the near plane, straight ahead: size 4 * 32/2 =
    // 64, centred at (32, 32): the whole image. A near test grown by the radius
    // (depth <= near + 2) would cull it.
    {"just beyond the near plane", 2, 20, {0, 0, 1}, true, 0, 63, 0, 63, 64},
};

MetaScene EdgeScene(const EdgeCase& c) {
    MetaScene s;
    s.grid = {40, 40, 1};
    s.tile = s.band = 1;
    s.splatDiameter = 4;
    s.qPrev.assign(s.grid.Count(), 0.0f);
    s.qPrev[VoxelIndex(s.grid, c.i, c.j, 0)] = 1.0f;
    s.qCur = s.qPrev;
    s.T.assign(s.grid.Count(), 1.0f);
    return s;
}

CameraSettings EdgeCamera(const EdgeCase& c) { return MetaCamera({0.5, 20.5, 0.5}, {10.5, 20.5, 0.5}, 90, c.up, 1); }

// Test the host's boxes and splat footprint against the hand-worked numbers.
TEST(MetamorphicRender, FrustumEdgeBoxesHandWorked) {
    for (const EdgeCase& c : kEdgeCases) {
        const MetaScene s = EdgeScene(c);
        SplatParams p = MetaSplatParams(s, MakeCameraFrame(EdgeCamera(c), 64, 64));
        ASSERT_EQ(p.camera.focalPx, 32.0f);
        const std::vector<uint8_t> boxes =
            FrustumVisibleBoxes(p.camera, s.grid, s.origin, s.h, s.tile, s.band, s.splatDiameter);
        ASSERT_EQ(boxes.size(), s.grid.Count());
        EXPECT_EQ(boxes[VoxelIndex(s.grid, c.i, c.j, 0)], c.visible ? 1 : 0) << c.name;
        // SplatBoxVisibility with culling: the frustum's boxes, less the empty bands when skipping.
        const std::vector<uint8_t> none(boxes.size(), 0), all(boxes.size(), 1);
        EXPECT_EQ(SplatBoxVisibility(p, s.grid, all, all), boxes) << c.name;
        EXPECT_EQ(SplatBoxVisibility(p, s.grid, none, none), none) << c.name;
        p.skipping = false;
        EXPECT_EQ(SplatBoxVisibility(p, s.grid, {}, {}), boxes) << c.name;
        p.culling = false;
        EXPECT_EQ(SplatBoxVisibility(p, s.grid, {}, {}), all) << c.name;
        if (!c.visible) continue;
        const SplatOrder order = MakeSplatOrder(p.camera, s.grid, {0, 0, 0}, 1.0);
        p.order = &order;
        const SplatFrame F = MakeSplatFrame(p, s.grid, FlattenSplatOrder(order), 64, 64);
        Splat splat;
        ASSERT_TRUE(MakeSplat(F, c.i, c.j, 0, 1.0f, 1.0f, 1.0f, splat)) << c.name;
        EXPECT_EQ(splat.size, c.size) << c.name;
        EXPECT_EQ(splat.x0, c.x0) << c.name;
        EXPECT_EQ(splat.x1, c.x1) << c.name;
        EXPECT_EQ(splat.y0, c.y0) << c.name;
        EXPECT_EQ(splat.y1, c.y1) << c.name;
    }
}

// Test that the splats at the frustum's edges are drawn (the pixels worked by
// hand differ from the background) and the image is the same with culling and
// skipping on or off; splats beyond the radius and behind the near plane are
// not drawn at all.
TEST_P(MetamorphicRenderBackend, FrustumEdgeSplatsSurviveCulling) {
    for (const EdgeCase& c : kEdgeCases) {
        const MetaScene s = EdgeScene(c);
        const std::vector<float> rgb = ExpectSplatUnchanged(s, EdgeCamera(c), 64, 64, c.name);
        ASSERT_EQ(rgb.size(), size_t(3) * 64 * 64);
        if (c.visible) {
            // kappa > 0 on 10 pixels of the footprint: on the right edge, x = 62
            // and 63 are at 2a - 1 = -7/8 and -5/8, rows 28..35 at 2b - 1 = -7/8
            // .. 7/8 in steps of 1/4; (7/8)^2 + y^2 < 1 for |y| <= 3/8 (4 rows),
            // (5/8)^2 + y^2 < 1 for |y| <= 5/8 (6 rows). The other edges mirror it.
            size_t inside = 0;
            for (int y = c.y0; y <= c.y1; ++y)
                for (int x = c.x0; x <= c.x1; ++x) {
                    const size_t n = 3 * (x + 64 * size_t(y));
                    inside += rgb[n] != kMetaBackground[0] || rgb[n + 1] != kMetaBackground[1] ||
                              rgb[n + 2] != kMetaBackground[2];
                }
            if (c.size == 8) {
                EXPECT_EQ(inside, 10u) << c.name;
                EXPECT_EQ(MetaNonBackground(rgb), 10u) << c.name;
            } else {  // the centre pixels at least (kappa near 1 there)
                EXPECT_GT(inside, 32u * 32u) << c.name;
            }
        } else {
            EXPECT_EQ(MetaNonBackground(rgb), 0u) << c.name;
        }
    }
}

// ---- Cloud that appears and dissolves between the two steps -----------------------
//
// 16 x 16 x 8, tile 4, band 2, alpha 1/2, q_min 0.3. q_prev = 1 only in box
// A (tile (0, 0), band 0), q_cur = 1 only in box B (tile (2, 2), band 2): at
// alpha 1/2 every one of those voxels has q_alpha = 1/2 > q_min, so all four
// splats are drawn; skipping that read one step's bands alone would lose two.
MetaScene AppearDissolveScene() {
    MetaScene s;
    s.qPrev.assign(s.grid.Count(), 0.0f);
    s.qCur = s.qPrev;
    s.qPrev[VoxelIndex(s.grid, 1, 1, 0)] = 1.0f;
    s.qPrev[VoxelIndex(s.grid, 2, 2, 1)] = 1.0f;
    s.qCur[VoxelIndex(s.grid, 9, 9, 4)] = 1.0f;
    s.qCur[VoxelIndex(s.grid, 10, 10, 5)] = 1.0f;
    s.T.assign(s.grid.Count(), 0.8f);
    return s;
}

TEST_P(MetamorphicRenderBackend, AppearAndDissolveSurviveSkipping) {
    const MetaScene s = AppearDissolveScene();
    const uint32_t W = 64, H = 48;
    for (const CameraSettings& cam : {MetaCamera({-6, -6, 14}, {8, 8, 3}), MetaCamera({20, 3, 4}, {0, 12, 4})}) {
        const std::vector<float> rgb = ExpectSplatUnchanged(s, cam, W, H, "appear/dissolve");
        for (bool culling : {false, true})
            for (bool skipping : {false, true})
                EXPECT_EQ(MetaRenderSplat(*mBackend, s, cam, W, H, culling, skipping).splat.splats, 4u)
                    << culling << skipping;
        // Each step's pair alone is on the image: both show.
        MetaScene prevOnly = s, curOnly = s;
        prevOnly.qCur.assign(s.grid.Count(), 0.0f);
        curOnly.qPrev.assign(s.grid.Count(), 0.0f);
        EXPECT_GT(MetaNonBackground(MetaRenderSplat(*mBackend, prevOnly, cam, W, H, false, false).rgb), 0u);
        EXPECT_GT(MetaNonBackground(MetaRenderSplat(*mBackend, curOnly, cam, W, H, false, false).rgb), 0u);
        EXPECT_GT(MetaNonBackground(rgb), 0u);
    }
}

// The march forms q_alpha and builds its bricks from it: with blobs of q_prev
// and of q_cur apart (each brick of q_alpha > 0 holds one step only), skipping
// on and off give the same image for bricks of 1, 4 and 8.
TEST_P(MetamorphicRenderBackend, MarchAppearAndDissolveSurviveSkipping) {
    if (!HasMarch()) GTEST_SKIP() << mBackend->Name() << " has no render_march";
    MetaScene s;
    s.grid = {24, 16, 8};
    s.qPrev = test::GaussianBlobField(s.grid, {{4, 4, 2, 1.2}});
    s.qCur = test::GaussianBlobField(s.grid, {{19, 12, 5, 1.2}});
    s.T.assign(s.grid.Count(), 0.7f);
    const CameraSettings cam = MetaCamera({-8, -6, 12}, {12, 8, 4});
    const uint32_t W = 48, H = 32;
    ExpectMarchUnchanged(s, cam, W, H, "march appear/dissolve");
    // Both blobs are seen: each alone changes the image.
    MetaScene prevOnly = s, curOnly = s;
    prevOnly.qCur.assign(s.grid.Count(), 0.0f);
    curOnly.qPrev.assign(s.grid.Count(), 0.0f);
    const std::vector<float> both = MetaRenderMarch(*mBackend, s, cam, W, H, true, 4);
    EXPECT_FALSE(MetaRenderMarch(*mBackend, prevOnly, cam, W, H, true, 4) == both);
    EXPECT_FALSE(MetaRenderMarch(*mBackend, curOnly, cam, W, H, true, 4) == both);
    EXPECT_GT(MetaNonBackground(both), 0u);
}

// ---- Cameras inside the volume and on its faces and tile edges --------------------
//
// Blobs that move between the steps; T varies. Eyes: inside, exactly on the
// x = 0 face, on the top face, on a tile and band edge (x = 4, y = 8, z = 2),
// on a corner; each looking several ways.
TEST_P(MetamorphicRenderBackend, CamerasInsideAndOnFacesChangeNothing) {
    MetaScene s;
    s.qPrev = test::GaussianBlobField(s.grid, {{4, 4, 2, 1.5}, {12, 5, 5, 1.5}});
    s.qCur = test::GaussianBlobField(s.grid, {{5, 11, 3, 1.5}, {11, 12, 6, 1.5}});
    s.T.resize(s.grid.Count());
    for (size_t n = 0; n < s.T.size(); ++n) s.T[n] = 0.3f + 0.7f * float((n * 2654435761u) % 1000) / 1000.0f;
    struct Eye {
        const char* name;
        std::array<double, 3> eye, target;
    };
    const Eye eyes[] = {
        {"inside", {8, 8, 4}, {0, 0, 2}},
        {"inside, looking up", {8, 8, 2}, {11, 12, 8}},
        {"inside, other way", {8, 8, 4}, {16, 14, 6}},
        {"on x = 0", {0, 6, 3}, {16, 10, 4}},
        {"on x = 0, along it", {0, 6, 3}, {0, 16, 3}},
        {"on the top", {7, 9, 8}, {3, 3, 0}},
        {"on the top, across", {7, 9, 8}, {12, 5, 4}},
        {"on a tile edge", {4, 8, 2}, {14, 2, 6}},
        {"on a tile edge, back", {4, 8, 2}, {2, 16, 3}},
        {"on a corner", {0, 0, 0}, {16, 16, 8}},
    };
    const uint32_t W = 48, H = 40;
    for (const Eye& e : eyes) {
        const CameraSettings cam = MetaCamera(e.eye, e.target, 75);
        const std::vector<float> rgb = ExpectSplatUnchanged(s, cam, W, H, e.name);
        EXPECT_GT(MetaNonBackground(rgb), 0u) << e.name;
        ExpectMarchUnchanged(s, cam, W, H, e.name);
    }
}

// ---- The property: no culled box holds a voxel with a splat on the image ----------

// 200 seeded random cameras (inside, near and around a 20 x 16 x 10 grid, h
// 1/2, 1 or 2, random field of view, image size, splat diameter and near
// plane): for each box FrustumVisibleBoxes culls, MakeSplat of each of its
// voxels (q = 1) gives no splat or an empty footprint.
TEST(MetamorphicRender, CulledBoxesHoldNoVisibleSplat) {
    const Extent3 e{20, 16, 10};
    Pcg32 rng(1717);
    uint64_t culledVoxels = 0, nearMisses = 0, drawnVoxels = 0;
    for (int camera = 0; camera < 200; ++camera) {
        MetaScene s;
        s.grid = e;
        s.h = std::array<float, 3>{0.5f, 1.0f, 2.0f}[rng.Below(3)];
        s.origin = {float(rng.Uniform(-20, 20)), float(rng.Uniform(-20, 20)), float(rng.Uniform(-5, 5))};
        s.tile = 1 + rng.Below(6);
        s.band = 1 + rng.Below(4);
        s.splatDiameter = float(rng.Uniform(0.2, 6)) * s.h;
        auto point = [&](double margin) {
            std::array<double, 3> p;
            const uint32_t n[3] = {e.nx, e.ny, e.nz};
            for (int a = 0; a < 3; ++a) p[a] = s.origin[a] + s.h * rng.Uniform(-margin, n[a] + margin);
            return p;
        };
        CameraSettings cam = MetaCamera(point(12), point(0), rng.Uniform(15, 120), {0, 0, 1}, rng.Uniform(0.05, 4));
        if (rng.Below(5) == 0) cam.up = {rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)};
        const uint32_t W = 8 + rng.Below(90), H = 8 + rng.Below(70);
        SplatParams p = MetaSplatParams(s, MakeCameraFrame(cam, W, H));
        const SplatOrder order = MakeSplatOrder(p.camera, e, {s.origin[0], s.origin[1], s.origin[2]}, s.h);
        p.order = &order;
        const SplatFrame F = MakeSplatFrame(p, e, FlattenSplatOrder(order), W, H);
        const std::vector<uint8_t> boxes =
            FrustumVisibleBoxes(p.camera, e, s.origin, s.h, s.tile, s.band, s.splatDiameter);
        const uint32_t tilesX = CeilDiv(e.nx, s.tile), tilesY = CeilDiv(e.ny, s.tile);
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    Splat splat;
                    const bool drawn =
                        MakeSplat(F, i, j, k, 1.0f, 1.0f, 1.0f, splat) && splat.x0 <= splat.x1 && splat.y0 <= splat.y1;
                    const bool visible =
                        boxes[i / s.tile + size_t(tilesX) * (j / s.tile + size_t(tilesY) * (k / s.band))];
                    drawnVoxels += drawn;
                    if (visible) continue;
                    ++culledVoxels;
                    ASSERT_FALSE(drawn) << "camera " << camera << ": voxel (" << i << ", " << j << ", " << k
                                        << ") in a culled box covers pixels " << splat.x0 << ".." << splat.x1 << " x "
                                        << splat.y0 << ".." << splat.y1;
                    // A splat whose centre is off the image but in reach of it.
                    nearMisses += MakeSplat(F, i, j, k, 1.0f, 1.0f, 1.0f, splat) &&
                                  (splat.px > -0.5f * splat.size - 2 && splat.px < W + 0.5f * splat.size + 2) &&
                                  (splat.py > -0.5f * splat.size - 2 && splat.py < H + 0.5f * splat.size + 2);
                }
    }
    // The cameras exercise both sides: many culled voxels, many drawn, and culled
    // ones within two pixels of touching the image.
    EXPECT_GT(culledVoxels, 100000u);
    EXPECT_GT(drawnVoxels, 100000u);
    EXPECT_GT(nearMisses, 100u);
}

INSTANTIATE_TEST_SUITE_P(Backends, MetamorphicRenderBackend, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace cb
