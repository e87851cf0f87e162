// Stage render_march on each GPU backend (impl_gl/RenderMarchGL.cpp,
// impl_vk/RenderMarchVk.cpp; Vulkan with the Khronos validation layer on and no
// message expected), on small grids: against closed forms (an empty volume, a
// full volume seen head on, the image's top row, the Mie table's lookups) and
// against the CPU backend, an independent host implementation of SPEC 10, over
// every option (light sources, skipping and brick sizes, fixed and adaptive
// steps, jitter, each phase function, powder, the point light, odd grids and
// images, q_prev != q_cur), and at the extremes. Skipped where a backend cannot
// start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/math/March.h"
#include "core/math/Shading.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "core/stages/render_march/RenderMarch.h"
#include "core/stages/shade/Shade.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

struct GpuMarchCase {
    Extent3 grid{16, 16, 16};
    std::vector<float> qPrev, qCur, T;  // T empty: no T buffer (light "march")
    MarchParams params;
};

struct GpuMarchImage {
    std::vector<float> rgb;
    MarchStats stats;
    bool ok = false;
};

GpuMarchImage RenderMarchOn(Backend& backend, const GpuMarchCase& c) {
    const Extent3 e = c.grid;
    auto qPrev = test::MakeFilled(backend, BufferFormat::F32, e, c.qPrev);
    auto qCur = test::MakeFilled(backend, BufferFormat::F32, e, c.qCur);
    std::unique_ptr<Buffer> t;
    if (!c.T.empty()) t = test::MakeFilled(backend, BufferFormat::F32, e, c.T);
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, c.params.camera.width, c.params.camera.height});
    GpuMarchImage out;
    // Garbage in the stats, so that a field the backend forgets to set fails.
    out.stats = {777, 777, 777, 777, 777, 777};
    const MarchInputs in{qPrev.get(), qCur.get(), t.get()};
    Status status = backend.RenderMarch(c.params, in, *image, &out.stats);
    EXPECT_TRUE(status.has_value()) << backend.Name() << ": " << status.error().message;
    out.ok = status.has_value();
    if (out.ok) out.rgb = test::Read<float>(backend, *image);
    return out;
}

// SPEC 10's per-channel tolerance, from the stage's comparison rule.
double GpuMarchTolerance() { return Describe(Stage::RenderMarch).rule(Scene{}).tolerance; }

class RenderMarchGpu : public test::BackendTest {
  protected:
    void SetUp() override {
        test::BackendTest::SetUp();
        if (IsSkipped()) return;
        ASSERT_TRUE(mBackend->Supports(Stage::RenderMarch));
        mSoftware = mBackend->Device().find("llvmpipe") != std::string::npos;
    }
    // llvmpipe (gl) and lavapipe (vk) run on this machine's CPU: measured there, gl's images lie within 1e-5
    // of the CPU's and lavapipe's are the CPU's bit for bit but for powder (GLSL's pow is the driver's, not
    // glibc's powf: a few ulps, within 1e-6); on both every counter equals the CPU's.
    bool mSoftware = false;
};

// The shared test camera, with early termination at epsilon 0.01 and alpha 0.3.
MarchParams GpuCameraParams(const Extent3& e, std::array<double, 3> eye, std::array<double, 3> target, uint32_t w,
                             uint32_t h, float sigmaH = 0.05f) {
    MarchParams p = test::CameraParams(e, eye, target, w, h, sigmaH);
    p.setup.epsilon = 0.01f;
    p.alpha = 0.3f;
    return p;
}

// Two different steps of blobs (so that q_alpha mixes them), zero below 1e-3
// so that whole bricks are empty, and a T that varies from voxel to voxel.
GpuMarchCase GpuBlobCase(const Extent3& e, uint32_t w, uint32_t h) {
    GpuMarchCase c;
    c.grid = e;
    const double x = e.nx, y = e.ny, z = e.nz;
    c.qPrev = test::GaussianBlobField(e, {{0.3 * x, 0.4 * y, 0.35 * z, 2}, {0.7 * x, 0.6 * y, 0.6 * z, 2.5}});
    c.qCur = test::GaussianBlobField(e, {{0.35 * x, 0.4 * y, 0.4 * z, 2.2}, {0.45 * x, 0.75 * y, 0.7 * z, 1.5}});
    c.T.resize(e.Count());
    for (size_t i = 0; i < c.T.size(); ++i) c.T[i] = 0.3f + 0.7f * float((i * 2654435761u) % 1000) / 1000.0f;
    c.params = GpuCameraParams(e, {-0.6 * x, -0.3 * y, 1.9 * z}, {0.5 * x, 0.5 * y, 0.4 * z}, w, h);
    return c;
}

// Test every option of SPEC 10 the GPU backends implement, alone and combined:
// the image within SPEC 10's tolerance of the CPU's everywhere (stricter than
// its 99.9 % of pixels), within what was measured on llvmpipe and lavapipe
// there, and every counter equal where the images are.
TEST_P(RenderMarchGpu, MatchesTheCpuOnEveryOptionOnOddSizes) {
    cpu::BackendCpu cpu(2);
    struct Option {
        std::string name;
        std::function<void(GpuMarchCase&)> edit;
    };
    const auto pointLight = [](GpuMarchCase& c) {
        MarchSetup& s = c.params.setup;
        s.light.pointOn = true;
        s.light.pointPosition = {0.5f * s.size[0], 0.45f * s.size[1], 0.3f * s.size[2]};
        s.light.pointRadiance = {30, 28, 40};
        s.light.pointMinDistance2 = 1;
    };
    // The volume repeated in x and y out to a far plane 120 voxel edges deep; bricks of 4 (the wrapped border
    // leaves no brick of 8 empty on 24 x 20 x 18).
    const auto tiling = [](GpuMarchCase& c) {
        MarchSetup& s = c.params.setup;
        s.tiling = true;
        s.invSize = {1.0f / s.size[0], 1.0f / s.size[1], 1.0f / s.size[2]};
        c.params.camera.farPlane = 120;
        c.params.brick = 4;
    };
    const std::vector<Option> options = {
        {"shade, skipping, HG", [](GpuMarchCase&) {}},
        {"skipping off", [](GpuMarchCase& c) { c.params.skipping = false; }},
        {"brick 1", [](GpuMarchCase& c) { c.params.brick = 1; }},
        {"brick 5", [](GpuMarchCase& c) { c.params.brick = 5; }},
        {"jitter", [](GpuMarchCase& c) { c.params.jitter = true, c.params.seed = 9, c.params.frame = 4; }},
        {"adaptive",
         [](GpuMarchCase& c) {
             c.params.setup.adaptive = true, c.params.setup.kappa = 0.1f, c.params.setup.adaptiveStart = 8;
         }},
        {"adaptive, brick 1",
         [](GpuMarchCase& c) { c.params.setup.adaptive = true, c.params.setup.kappa = 0.05f, c.params.brick = 1; }},
        {"adaptive, jitter, brick 3",
         [](GpuMarchCase& c) {
             c.params.setup.adaptive = true, c.params.setup.kappa = 0.1f, c.params.setup.adaptiveStart = 8;
             c.params.jitter = true, c.params.frame = 2, c.params.brick = 3;
         }},
        {"light march", [](GpuMarchCase& c) { c.params.light = MarchLightSource::March, c.T.clear(); }},
        {"light march, skipping off",
         [](GpuMarchCase& c) { c.params.light = MarchLightSource::March, c.T.clear(), c.params.skipping = false; }},
        {"light march n_l 3, jitter",
         [](GpuMarchCase& c) {
             c.params.light = MarchLightSource::March, c.T.clear(), c.params.lightSteps = 3, c.params.jitter = true;
         }},
        {"powder", [](GpuMarchCase& c) { c.params.setup.powder = true, c.params.setup.powderC = 2.5f; }},
        {"phase none", [](GpuMarchCase& c) { c.params.setup.light.phase.kind = PhaseKind::None; }},
        {"phase cornette-shanks",
         [](GpuMarchCase& c) {
             c.params.setup.light.phase = {PhaseKind::CornetteShanks, 0.7f};
         }},
        {"phase cornette-shanks, back",
         [](GpuMarchCase& c) {
             c.params.setup.light.phase = {PhaseKind::CornetteShanks, -0.3f};
         }},
        {"phase mie", [](GpuMarchCase& c) { c.params.setup.light.phase.kind = PhaseKind::Mie; }},
        {"phase dual-lobe, mostly backward",
         [](GpuMarchCase& c) {
             c.params.setup.light.phase = {PhaseKind::DualLobe, 0.6f, 0.7f, -0.6f, 0.7f};
         }},
        {"point light, dual-lobe",
         [&](GpuMarchCase& c) {
             pointLight(c);
             c.params.setup.light.phase = {PhaseKind::DualLobe, 0.6f, 0.8f, -0.5f, 0.5f};
         }},
        {"point light", pointLight},
        {"point light, mie, light march, powder",
         [&](GpuMarchCase& c) {
             pointLight(c);
             c.params.setup.light.phase.kind = PhaseKind::Mie;
             c.params.light = MarchLightSource::March, c.T.clear();
             c.params.setup.powder = true;
         }},
        {"point light outside, step 0.21, epsilon 0",
         [](GpuMarchCase& c) {
             c.params.setup.light.pointOn = true, c.params.setup.light.pointPosition = {-3, 14, 20};
             c.params.setup.light.pointRadiance = {300, 200, 100}, c.params.setup.light.pointMinDistance2 = 4;
             c.params.setup.step = 0.21f, c.params.setup.epsilon = 0;
         }},
        {"epsilon 0, step 0.37", [](GpuMarchCase& c) { c.params.setup.epsilon = 0, c.params.setup.step = 0.37f; }},
        {"dense (early stop)", [](GpuMarchCase& c) { c.params.setup.sigmaH = 2.0f; }},
        // Tiling: the rays to the far plane through the repeated layer, the wrapped taps and bricks (brick 5:
        // the last brick along x is cut at the seam on 24 and 31 voxels), the light march through the copies.
        {"tiling", tiling},
        {"tiling, brick 5", [&](GpuMarchCase& c) { tiling(c), c.params.brick = 5; }},
        {"tiling, light march",
         [&](GpuMarchCase& c) { tiling(c), c.params.light = MarchLightSource::March, c.T.clear(); }},
        {"tiling, adaptive, jitter, point light",
         [&](GpuMarchCase& c) {
             tiling(c), pointLight(c);
             c.params.setup.adaptive = true, c.params.setup.kappa = 0.1f, c.params.setup.adaptiveStart = 8;
             c.params.jitter = true, c.params.frame = 3;
         }},
    };
    struct Size {
        Extent3 grid;
        uint32_t w, h;
    };
    const bool gl = GetParam() == "gl";
    for (const Size& size : {Size{{31, 29, 13}, 37, 23}, Size{{24, 20, 18}, 32, 24}})
        for (const Option& option : options) {
            GpuMarchCase c = GpuBlobCase(size.grid, size.w, size.h);
            option.edit(c);
            const GpuMarchImage want = RenderMarchOn(cpu, c);
            const GpuMarchImage got = RenderMarchOn(*mBackend, c);
            if (!want.ok || !got.ok) continue;
            const std::string where = option.name + " on " + std::to_string(size.grid.nx) + "x" +
                                      std::to_string(size.grid.ny) + "x" + std::to_string(size.grid.nz);
            ASSERT_EQ(got.rgb.size(), want.rgb.size()) << where;
            double worst = 0;
            size_t worstAt = 0, differ = 0;
            for (size_t i = 0; i < want.rgb.size(); ++i) {
                ASSERT_TRUE(std::isfinite(got.rgb[i])) << where << " at " << i;
                const double d = std::fabs(double(got.rgb[i]) - want.rgb[i]);
                if (d > worst) worst = d, worstAt = i;
                differ += d != 0;
            }
            const std::string at =
                where + ": channel " + std::to_string(worstAt % 3) + " of pixel " + std::to_string(worstAt / 3);
            EXPECT_LE(worst, GpuMarchTolerance()) << at;
            if (mSoftware && gl) {
                EXPECT_LE(worst, 1e-5) << at;
            }
            if (mSoftware && !gl && c.params.setup.powder) {
                EXPECT_LE(worst, 1e-6) << at;
            }
            if (mSoftware && !gl && !c.params.setup.powder) {
                EXPECT_EQ(differ, 0u) << at << ", worst " << worst;
            }
            if (mSoftware || differ == 0) {
                EXPECT_EQ(got.stats.rays, want.stats.rays) << where;
                EXPECT_EQ(got.stats.samples, want.stats.samples) << where;
                EXPECT_EQ(got.stats.lightSamples, want.stats.lightSamples) << where;
                EXPECT_EQ(got.stats.bricksSkipped, want.stats.bricksSkipped) << where;
            }
            EXPECT_EQ(got.stats.bricks, want.stats.bricks) << where;
            EXPECT_EQ(got.stats.emptyBricks, want.stats.emptyBricks) << where;
            // The case must exercise the marcher: clouds in view, and skipping where it is on.
            EXPECT_GT(want.stats.lightSamples, 0u) << where;
            if (c.params.skipping) {
                EXPECT_GT(want.stats.bricksSkipped, 0u) << where;
                EXPECT_GT(got.stats.emptyBricks, 0u) << where;
                EXPECT_LT(got.stats.emptyBricks, got.stats.bricks) << where;
            }
        }
}

// Test a full volume of q = 1 (T = 1, phase none) seen straight down through
// its centre: the trilinear optical depth is sigma h (nz - 1/4) (q ramps from
// 1/2 to 1 in the half voxel at each face), and at step 1/2 the midpoint rule
// is exact, so C = (sun + ambient)(1 - T) + T background; 2 nz samples on 1 ray.
TEST_P(RenderMarchGpu, FullVolumeSeenHeadOnMatchesTheTrilinearOpticalDepth) {
    GpuMarchCase c;
    c.grid = {8, 8, 12};
    c.qPrev.assign(c.grid.Count(), 1.0f);
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    c.params = GpuCameraParams(c.grid, {4, 4, 40}, {4, 4, 0}, 1, 1, 0.07f);
    c.params.setup.light.phase.kind = PhaseKind::None;
    c.params.setup.epsilon = 0;
    const GpuMarchImage im = RenderMarchOn(*mBackend, c);
    ASSERT_TRUE(im.ok);
    const double T = std::exp(-0.07 * (12 - 0.25));
    const MarchSetup& s = c.params.setup;
    for (int ch = 0; ch < 3; ++ch) {
        const double expected =
            (double(s.light.sunRadiance[ch]) + s.light.ambient[ch]) * (1 - T) + T * s.background[ch];
        EXPECT_NEAR(im.rgb[ch], expected, 1e-5 * expected) << ch;
    }
    EXPECT_EQ(im.stats.rays, 1u);
    EXPECT_EQ(im.stats.samples, 24u);
    EXPECT_EQ(im.stats.lightSamples, 24u);
    EXPECT_EQ(im.stats.bricksSkipped, 0u);  // no brick is empty
    EXPECT_EQ(im.stats.bricks, 2u);         // ceil(8/8) ceil(8/8) ceil(12/8)
    EXPECT_EQ(im.stats.emptyBricks, 0u);
}

// Test an empty volume, with skipping on and off: every pixel is the background
// exactly and nothing is lit; the rays that miss the box (the image's corners)
// are not counted. With skipping every brick is empty, every ray that meets
// the box skips at least one and no sample is taken; without, there are no bricks.
TEST_P(RenderMarchGpu, EmptyVolumeGivesTheBackgroundAndOnlyEmptyBricks) {
    GpuMarchCase c;
    c.grid = {20, 12, 9};
    c.qPrev.assign(c.grid.Count(), 0.0f);
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    c.params = GpuCameraParams(c.grid, {-10, 4, 12}, {8, 8, 8}, 24, 18);
    c.params.brick = 4;
    for (bool skipping : {false, true}) {
        SCOPED_TRACE(skipping ? "skipping" : "no skipping");
        c.params.skipping = skipping;
        const GpuMarchImage im = RenderMarchOn(*mBackend, c);
        ASSERT_TRUE(im.ok);
        for (size_t i = 0; i < im.rgb.size(); ++i) ASSERT_EQ(im.rgb[i], c.params.setup.background[i % 3]) << i;
        EXPECT_EQ(im.stats.lightSamples, 0u);
        EXPECT_GT(im.stats.rays, 24u * 18u / 4);  // the box fills much of the view
        EXPECT_LE(im.stats.rays, 24u * 18u);
        if (skipping) {
            EXPECT_EQ(im.stats.bricks, 5u * 3u * 3u);
            EXPECT_EQ(im.stats.emptyBricks, im.stats.bricks);
            EXPECT_GE(im.stats.bricksSkipped, im.stats.rays);
            EXPECT_EQ(im.stats.samples, 0u);
        } else {
            EXPECT_EQ(im.stats.bricks, 0u);
            EXPECT_EQ(im.stats.emptyBricks, 0u);
        }
    }
}

// Test that the image's row 0 is the top: looking down -z with up +y at a
// dense slab that fills only the volume's +y half, the top rows see the slab,
// lit by sun + ambient (blue 0.8 + 0.3, phase none, T = 1) over the
// background's blue 0.9, and the bottom rows the background exactly.
TEST_P(RenderMarchGpu, RowZeroIsTheTopOfTheImage) {
    GpuMarchCase c;
    c.grid = {16, 16, 4};
    c.qPrev.assign(c.grid.Count(), 0.0f);
    for (uint32_t k = 0; k < c.grid.nz; ++k)
        for (uint32_t j = c.grid.ny / 2; j < c.grid.ny; ++j)
            for (uint32_t i = 0; i < c.grid.nx; ++i) c.qPrev[VoxelIndex(c.grid, i, j, k)] = 1.0f;
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    CameraSettings cam;
    cam.eye = {8, 8, 30};
    cam.target = {8, 8, 0};
    cam.up = {0, 1, 0};
    cam.fovDeg = 40;
    cam.nearPlane = 0.01;
    cam.farPlane = 1e5;
    c.params = GpuCameraParams(c.grid, cam.eye, cam.target, 16, 12, 1.0f);
    c.params.camera = MakeCameraFrame(cam, 16, 12);
    c.params.setup.light.phase.kind = PhaseKind::None;
    const GpuMarchImage im = RenderMarchOn(*mBackend, c);
    ASSERT_TRUE(im.ok);
    const float bg = c.params.setup.background[2];
    const float top = im.rgb[3 * (8 + 16 * 1) + 2], bottom = im.rgb[3 * (8 + 16 * 10) + 2];
    EXPECT_EQ(bottom, bg);      // row 10 of 12 looks at the empty -y half
    EXPECT_GT(top, bg + 0.1f);  // row 1 looks into the slab: about 1.1
}

// Test that the Mie table read in the shader gives the CPU's lookup. The eye
// inside a full, very dense volume (sigma h 1000: the first segment's
// transmittance underflows to 0), light T = 1, no ambient or background, sun
// radiance 1: each pixel is exactly the phase at cos theta = sun . dir,
// looking toward the sun (the forward peak), across and away from it, so that
// the lookups span the table. Each value must also lie between the two table
// entries around its angle.
TEST_P(RenderMarchGpu, MieLookupsEqualTheCpus) {
    GpuMarchCase c;
    c.grid = {16, 16, 16};
    c.qPrev.assign(c.grid.Count(), 1.0f);
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    const Vec3 sun = SunDirection(0.5, 1.0);
    const std::array<double, 3> eye{8, 8, 8};
    uint64_t checked = 0;
    for (double sign : {1.0, -1.0, 0.0}) {
        std::array<double, 3> target{eye[0] + sign * sun[0], eye[1] + sign * sun[1], eye[2] + sign * sun[2]};
        if (sign == 0.0) target = {eye[0] - sun[1], eye[1] + sun[0], eye[2]};  // across: perpendicular in xy
        c.params = GpuCameraParams(c.grid, eye, target, 48, 36, 1000.0f);
        CameraSettings cam;
        cam.eye = eye;
        cam.target = target;
        cam.fovDeg = 100;
        cam.nearPlane = 0.01;
        cam.farPlane = 1e5;
        c.params.camera = MakeCameraFrame(cam, 48, 36);
        MarchSetup& s = c.params.setup;
        s.sun = sun;
        s.light.sunRadiance = {1, 1, 1};
        s.light.ambient = {0, 0, 0};
        s.background = {0, 0, 0};
        s.light.phase.kind = PhaseKind::Mie;
        const GpuMarchImage im = RenderMarchOn(*mBackend, c);
        ASSERT_TRUE(im.ok);
        const PhaseTable& table = kMieCloudTable;
        for (uint32_t y = 0; y < 36; ++y)
            for (uint32_t x = 0; x < 48; ++x) {
                const MarchRayGeometry ray = MakePixelRay(c.params.camera, c.params.origin, 1.0f, s.size, x, y);
                const float cosTheta = MarchDot(sun, ray.dir);
                const float want = SamplePhaseTable(table, cosTheta);
                const float got = im.rgb[3 * (x + 48 * y)];
                ASSERT_NEAR(got, want, 1e-6 * want) << "pixel " << x << ", " << y << ", cos " << cosTheta;
                const double theta = std::acos(std::clamp(double(cosTheta), -1.0, 1.0)) * table.indexPerRadian;
                const uint32_t i = std::min(uint32_t(theta), table.count - 2);
                ASSERT_GE(got, std::min(table.values[i], table.values[i + 1]) * (1 - 1e-6f));
                ASSERT_LE(got, std::max(table.values[i], table.values[i + 1]) * (1 + 1e-6f));
                EXPECT_EQ(im.rgb[3 * (x + 48 * y) + 1], got);
                ++checked;
            }
    }
    EXPECT_EQ(checked, 3u * 48u * 36u);
}

// Test no NaN or Inf and the CPU's image at the extremes: the eye inside the
// volume looking straight up, down and along x (degenerate up), sigma 0, 1e6
// and 0.05, empty, full and blob volumes, both light sources, powder and a
// point light at the eye, with skipping (bricks of 4) on.
TEST_P(RenderMarchGpu, NoNanOrInfAtTheExtremesAndTheCpusImage) {
    cpu::BackendCpu cpu(2);
    const Extent3 e{12, 10, 9};
    const std::vector<std::vector<float>> fields = {std::vector<float>(e.Count(), 0.0f),
                                                    std::vector<float>(e.Count(), 1.0f),
                                                    test::GaussianBlobField(e, {{4, 4, 3, 1.5}, {9, 7, 6, 1.5}})};
    const std::array<double, 3> inside{6, 5, 4.5};
    const std::vector<std::array<double, 3>> targets = {{6, 5, 100}, {6, 5, -100}, {50, 5, 4.5}};
    const float tolerance = float(GpuMarchTolerance());
    for (const auto& field : fields)
        for (const auto& target : targets)
            for (float sigma : {0.0f, 1e6f, 0.05f})
                for (MarchLightSource source : {MarchLightSource::Shade, MarchLightSource::March}) {
                    GpuMarchCase c;
                    c.grid = e;
                    c.qPrev = c.qCur = field;
                    c.T.assign(e.Count(), 0.5f);
                    c.params = GpuCameraParams(e, inside, target, 9, 7, MarchOpticalDepthPerVoxel(sigma, 1.0f));
                    c.params.light = source;
                    c.params.brick = 4;
                    c.params.setup.powder = true;
                    c.params.setup.light.pointOn = true, c.params.setup.light.pointPosition = {6, 5, 4.5f};
                    c.params.setup.light.pointRadiance = {1e3f, 1e3f, 1e3f};
                    c.params.setup.light.pointMinDistance2 = 0.25f;
                    const GpuMarchImage got = RenderMarchOn(*mBackend, c);
                    const GpuMarchImage want = RenderMarchOn(cpu, c);
                    ASSERT_TRUE(got.ok && want.ok);
                    for (size_t i = 0; i < got.rgb.size(); ++i) {
                        ASSERT_TRUE(std::isfinite(got.rgb[i])) << "sigma " << sigma << " pixel value " << i;
                        ASSERT_GE(got.rgb[i], 0.0f);
                        // SPEC 10's tolerance, relative where the point light makes values large.
                        ASSERT_LE(std::fabs(got.rgb[i] - want.rgb[i]),
                                  tolerance * std::max(1.0f, std::fabs(want.rgb[i])))
                            << "sigma " << sigma << " value " << i;
                    }
                    if (sigma == 0.0f) {
                        for (size_t i = 0; i < got.rgb.size(); ++i)
                            ASSERT_EQ(got.rgb[i], c.params.setup.background[i % 3]);
                    }
                    EXPECT_EQ(got.stats.samples, want.stats.samples);
                }
}

// Test the memory plan's scratch for render_march alone, by hand, in each
// backend's own layout.
//  gl, on a 10 x 6 x 4 grid: the padded volume (12 x 8 x 6 pairs of floats)
//  and its storage-buffer copy; with skipping at brick 4, 3 x 2 x 1 R32UI
//  flags and their copy; the RGBA32F target and the RGB32F image copy; with
//  phase mie the 1801-float table.
//  vk, on a 10 x 12 x 14 grid (12 x 14 x 16 = 2688 padded voxels, 3 x 3 x 4 =
//  36 bricks of 4): the constants (MarchGpu) and 40 bytes of counters; (q, T)
//  pairs with light "shade", q alone with "march"; a word per brick only with
//  skipping; the table only with Mie; T_sky's padded volume only with the sky
//  light; and shade's and shade_sky's coarse grids at resolution 2.
TEST_P(RenderMarchGpu, ScratchBytesByHand) {
    Scene scene;
    scene.stages = StageSet{Stage::RenderMarch};
    scene.phase.kind = PhaseKind::HenyeyGreenstein;
    if (GetParam() == "gl") {
        scene.grid.size = {10, 6, 4};
        scene.render.width = 16, scene.render.height = 12;
        scene.march.skipping = false;
        const uint64_t volume = 2 * (12 * 8 * 6) * 8, image = 16 * 12 * (16 + 12);
        EXPECT_EQ(mBackend->ScratchBytes(scene), volume + image);
        scene.march.skipping = true;
        scene.march.brick = 4;
        EXPECT_EQ(mBackend->ScratchBytes(scene), volume + 2 * (3 * 2 * 1) * 4 + image);
        scene.phase.kind = PhaseKind::Mie;
        EXPECT_EQ(mBackend->ScratchBytes(scene), volume + 2 * (3 * 2 * 1) * 4 + image + 1801 * 4);
        // The sky light: T_sky's padded volume, R32F layers and their copy.
        scene.lighting.sky.on = true;
        EXPECT_EQ(mBackend->ScratchBytes(scene),
                  volume + 2 * (12 * 8 * 6) * 4 + 2 * (3 * 2 * 1) * 4 + image + 1801 * 4);
    } else if (GetParam() == "vk") {
        scene.grid.size = {10, 12, 14};
        scene.march.brick = 4;
        scene.march.skipping = true;
        scene.march.light = MarchLightSource::Shade;
        // MarchGpu: its own twelve 16-byte rows and LightGpu's seventeen (thirteen and four glow blobs).
        const uint64_t block = 12u * 16u + 17u * 16u;
        EXPECT_EQ(mBackend->ScratchBytes(scene), block + 40u + 2688u * 8 + 36u * 4);
        scene.march.light = MarchLightSource::March;
        EXPECT_EQ(mBackend->ScratchBytes(scene), block + 40u + 2688u * 4 + 36u * 4);
        scene.march.skipping = false;
        EXPECT_EQ(mBackend->ScratchBytes(scene), block + 40u + 2688u * 4);
        scene.phase.kind = PhaseKind::Mie;
        EXPECT_EQ(mBackend->ScratchBytes(scene), block + 40u + 2688u * 4 + 1801u * 4);
        scene.lighting.sky.on = true;  // T_sky's padded volume, a float per padded voxel
        EXPECT_EQ(mBackend->ScratchBytes(scene), block + 40u + 2688u * 4 + 1801u * 4 + 2688u * 4);
        scene.lighting.sky.on = false;
        scene.stages = StageSet{Stage::Shade};
        scene.shade.resolution = 1;
        EXPECT_EQ(mBackend->ScratchBytes(scene), 0u);  // no march, no march scratch
        // At resolution 2 shade's coarse q and T, 5 x 6 x 7 floats each, and shade_sky's own.
        scene.shade.resolution = 2;
        EXPECT_EQ(mBackend->ScratchBytes(scene), 2u * 210u * 4u);
        scene.stages = StageSet{Stage::Shade, Stage::ShadeSky};
        EXPECT_EQ(mBackend->ScratchBytes(scene), 2u * 2u * 210u * 4u);
    } else {
        GTEST_SKIP() << "no scratch worked out by hand for " << GetParam();
    }
    scene.stages = StageSet{};
    EXPECT_EQ(mBackend->ScratchBytes(scene), 0u);
}

INSTANTIATE_TEST_SUITE_P(Gpu, RenderMarchGpu, ::testing::ValuesIn(test::GpuTestBackends()),
                         [](const auto& info) { return info.param; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(RenderMarchGpu);

}  // namespace
}  // namespace cb
