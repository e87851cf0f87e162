// The renderers of the GPU pass extents test (GpuExtents.h): render_splat,
// render_march and render_layers, each on a GPU backend and on the CPU from the
// same inputs, compared as ConformanceRenderTest.cpp (SPEC 8's image rule),
// RenderMarchGpuTest.cpp (SPEC 10's tolerance everywhere) and
// RenderLayersTest.cpp (1e-4 everywhere) compare them, with every counter equal.
// q is dense (0.35 to 0.85 everywhere, so every voxel is a splat and no brick is
// empty) and the cameras look at the grid's +x side, where the padded volume's
// last columns (i = nx, nx + 1) are sampled: a column the volume pass leaves
// unwritten holds the previous, larger call's values there, not (0, 1).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Shading.h"
#include "core/plan/StageGraph.h"
#include "harness/report/Report.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/GpuExtents.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb::extents {
namespace {

// The three volumes every renderer reads: q_prev, q_cur in [0.35, 0.85] and T in [0.3, 1], all different.
struct ExtVolumes {
    std::vector<float> qPrev, qCur, T;
};
ExtVolumes ExtDenseVolumes(const Extent3& e) {
    ExtVolumes v;
    v.qPrev.resize(e.Count()), v.qCur.resize(e.Count()), v.T.resize(e.Count());
    for (size_t i = 0; i < v.qPrev.size(); ++i) {
        v.qPrev[i] = 0.35f + float(LowBias32(uint32_t(i)) % 501u) / 1000.0f;
        v.qCur[i] = 0.35f + float(LowBias32(uint32_t(i) + 7777u) % 501u) / 1000.0f;
        v.T[i] = 0.3f + float(LowBias32(uint32_t(i) * 3u + 1u) % 701u) / 1000.0f;
    }
    return v;
}

// The renderers' inputs on one backend.
struct ExtInputs {
    std::unique_ptr<Buffer> qPrev, qCur, T, image;
    ExtInputs(Backend& b, const Extent3& e, const ExtVolumes& v, uint32_t w, uint32_t h)
        : qPrev(test::MakeFilled(b, BufferFormat::F32, e, v.qPrev)),
          qCur(test::MakeFilled(b, BufferFormat::F32, e, v.qCur)),
          T(test::MakeFilled(b, BufferFormat::F32, e, v.T)),
          image(test::MakeBuffer(b, BufferFormat::F32, {3, w, h})) {}
};

double ExtWorst(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return 1e30;
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const double d = std::fabs(double(a[i]) - double(b[i]));
        if (!(d <= worst)) worst = d;
    }
    return worst;
}

// A camera far enough off the grid that all of it is in view, looking at its centre from the +x side and above.
CameraFrame ExtWholeGridCamera(const Extent3& e, uint32_t w, uint32_t h) {
    const double d = 3.0 * (e.nx + e.ny + e.nz);
    CameraSettings cam;
    cam.target = {0.5 * e.nx, 0.5 * e.ny, 0.5 * e.nz};
    cam.eye = {0.5 * e.nx + d, 0.5 * e.ny - 0.4 * d, 0.5 * e.nz + 0.6 * d};
    cam.fovDeg = 50, cam.nearPlane = 0.01, cam.farPlane = 1e5;
    return MakeCameraFrame(cam, w, h);
}

// render_splat: every voxel a splat (the grid in view, q_alpha > q_min everywhere); option: vk's ranks per chunk,
// +1000 for skipping from density's occupancy at tile 2, band 1.
void ExtSplat(Backend& cpu, Backend& gpu, const ExtentCase& c) {
    const Extent3 e = c.grid;
    const ExtVolumes v = ExtDenseVolumes(e);
    const bool skipping = c.option >= 1000;
#if CLOUDBENCH_HAVE_VK
    auto* vk = dynamic_cast<vk::BackendVk*>(&gpu);
    if (vk) vk->SetSplatChunkRanks(c.option % 1000);
#endif
    SplatParams p;
    p.camera = ExtWholeGridCamera(e, c.width, c.height);
    const SplatOrder order = MakeSplatOrder(p.camera, e, {0, 0, 0}, 1.0);
    p.order = &order;
    p.voxelSize = 1, p.splatDiameter = 1.5f;
    p.sun = SunDirection(0.5, 0.8);
    p.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
    p.light.sunRadiance = {1.5f, 1.4f, 1.3f}, p.light.ambient = {0.2f, 0.25f, 0.3f}, p.background = {0.4f, 0.5f, 0.8f};
    p.alpha = 0.4f;
    p.skipping = skipping, p.tile = 2, p.band = 1;
    Backend* backends[2] = {&cpu, &gpu};
    std::vector<float> rgb[2];
    SplatStats stats[2];
    for (int n = 0; n < 2; ++n) {
        Backend& b = *backends[n];
        ExtInputs in(b, e, v, c.width, c.height);
        const Extent3 tiles{CeilDiv(e.nx, 2u), CeilDiv(e.ny, 2u), 1}, bands{tiles.nx, tiles.ny, e.nz};
        std::unique_ptr<Buffer> occupancy[2][2];
        SplatInputs si{in.qPrev.get(), in.qCur.get(), in.T.get()};
        if (skipping) {
            for (int step = 0; step < 2; ++step) {
                auto D = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
                occupancy[step][0] = test::MakeBuffer(b, BufferFormat::U8, tiles);
                occupancy[step][1] = test::MakeBuffer(b, BufferFormat::U8, bands);
                DensityOutputs out{D.get(), occupancy[step][0].get(), occupancy[step][1].get(), 0};
                ASSERT_TRUE(b.Density({2, 1, {}}, step == 0 ? *in.qPrev : *in.qCur, nullptr, out).has_value());
            }
            si.tilesPrev = occupancy[0][0].get(), si.tilesCur = occupancy[1][0].get();
            si.bandsPrev = occupancy[0][1].get(), si.bandsCur = occupancy[1][1].get();
        }
        const Status s = b.RenderSplat(p, si, *in.image, &stats[n]);
        ASSERT_TRUE(s.has_value()) << b.Name() << ": " << s.error().message;
        rgb[n] = test::Read<float>(b, *in.image);
    }
#if CLOUDBENCH_HAVE_VK
    if (vk) vk->SetSplatChunkRanks(0);
#endif
    EXPECT_EQ(stats[0].splats, e.Count()) << "every voxel is a splat: the splat count is the extent the case sets";
    EXPECT_EQ(stats[1].splats, stats[0].splats);
    EXPECT_EQ(stats[1].voxelsVisited, stats[0].voxelsVisited);
    EXPECT_EQ(stats[1].fragments, stats[0].fragments);
    const ImageComparison cmp = CompareImages(rgb[0], rgb[1], c.width, c.height).value();
    EXPECT_TRUE(cmp.Passes()) << "max error " << cmp.maxError << " at (" << cmp.worstX << ", " << cmp.worstY << "), "
                              << cmp.pixelsOverTolerance << " of " << cmp.pixels << " pixels over the tolerance";
}

// render_march, light "shade", early termination at 0.01; option: the brick (0: skipping off). The eye looks at
// the +x face, whose first samples read the padded volume's columns nx and nx + 1.
void ExtMarch(Backend& cpu, Backend& gpu, const ExtentCase& c) {
    const Extent3 e = c.grid;
    const ExtVolumes v = ExtDenseVolumes(e);
    MarchParams p = test::CameraParams(e, {e.nx + 3.0 + e.nz, 0.3 * e.ny, e.nz + 1.5},
                                       {e.nx - 1.0, 0.5 * e.ny, 0.3 * e.nz}, c.width, c.height);
    p.setup.epsilon = 0.01f;
    p.alpha = 0.3f;
    p.skipping = c.option != 0;
    p.brick = std::max(1u, c.option);
    Backend* backends[2] = {&cpu, &gpu};
    std::vector<float> rgb[2];
    MarchStats stats[2];
    for (int n = 0; n < 2; ++n) {
        ExtInputs in(*backends[n], e, v, c.width, c.height);
        const Status s = backends[n]->RenderMarch(p, {in.qPrev.get(), in.qCur.get(), in.T.get()}, *in.image, &stats[n]);
        ASSERT_TRUE(s.has_value()) << backends[n]->Name() << ": " << s.error().message;
        rgb[n] = test::Read<float>(*backends[n], *in.image);
    }
    EXPECT_LE(ExtWorst(rgb[0], rgb[1]), cb::Describe(Stage::RenderMarch).rule(Scene{}).tolerance) << "image";
    EXPECT_GT(stats[0].rays, 0u);
    EXPECT_EQ(stats[1].rays, stats[0].rays);
    EXPECT_EQ(stats[1].samples, stats[0].samples);
    EXPECT_EQ(stats[1].bricks, stats[0].bricks);
    EXPECT_EQ(stats[1].emptyBricks, stats[0].emptyBricks);
}

// render_layers, one layer per voxel of height; option 1: tiling; 2: tiling and LOD0's billboards (r0 = 4, p_s = 1,
// around the eye). The eye is above the +x edge, looking down at it.
void ExtLayers(Backend& cpu, Backend& gpu, const ExtentCase& c) {
    const Extent3 e = c.grid;
    const ExtVolumes v = ExtDenseVolumes(e);
    const MarchParams m = test::CameraParams(e, {e.nx - 1.5, 0.4 * e.ny, e.nz + 4.0 + e.ny},
                                             {e.nx - 0.5, 0.5 * e.ny, 0.0}, c.width, c.height);
    LayersParams p = test::LayersFromCamera(m, e, e.nz, c.option >= 1);
    if (c.option == 2) SetLayersLod0(p.setup, 4.0, 1.0);
    Backend* backends[2] = {&cpu, &gpu};
    std::vector<float> rgb[2];
    LayersStats stats[2];
    for (int n = 0; n < 2; ++n) {
        ExtInputs in(*backends[n], e, v, c.width, c.height);
        const Status s2 =
            backends[n]->RenderLayers(p, {in.qPrev.get(), in.qCur.get(), in.T.get()}, *in.image, &stats[n]);
        ASSERT_TRUE(s2.has_value()) << backends[n]->Name() << ": " << s2.error().message;
        rgb[n] = test::Read<float>(*backends[n], *in.image);
    }
    EXPECT_LT(ExtWorst(rgb[0], rgb[1]), 1e-4) << "image";  // RenderLayersGpu.MatchesTheCpu's bound
    EXPECT_GT(stats[0].drawn, 0u);
    EXPECT_EQ(stats[1].fragments, stats[0].fragments);
    EXPECT_EQ(stats[1].drawn, stats[0].drawn);
}

}  // namespace

void RunRenderExtentCase(Stage stage, Backend& gpu, const ExtentCase& c) {
    cpu::BackendCpu cpu(2);
    switch (stage) {
        case Stage::RenderSplat: return ExtSplat(cpu, gpu, c);
        case Stage::RenderMarch: return ExtMarch(cpu, gpu, c);
        case Stage::RenderLayers: return ExtLayers(cpu, gpu, c);
        default: ADD_FAILURE() << "no extent runner for " << StageName(stage);
    }
}

}  // namespace cb::extents
