// render_march on Vulkan (impl_vk/RenderMarchVk.cpp) on small grids, with the
// Khronos validation layer on and no message expected: against closed forms
// (the empty volume, a full volume seen head on) and against the CPU backend,
// an independent host implementation of SPEC 10, over every option (light
// sources, skipping, fixed and adaptive steps, jitter, each phase function,
// powder, the point light, odd grids and images, q_prev != q_cur). On lavapipe
// (a device of type "cpu") the images are bit-identical but for powder (GLSL's
// pow is the driver's, not glibc's powf: a few ulps), and the MarchStats
// counters equal the CPU's exactly on every device where the images are exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/math/March.h"
#include "core/scene/Scene.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb {
namespace {

#if CLOUDBENCH_HAVE_VK

struct VkMarchCase {
    Extent3 grid{16, 16, 16};
    std::vector<float> qPrev, qCur, T;
    MarchParams params;
};

struct VkMarchImage {
    std::vector<float> rgb;
    MarchStats stats;
};

VkMarchImage RenderOn(Backend& backend, const VkMarchCase& c) {
    const Extent3 e = c.grid;
    auto qPrev = test::MakeFilled(backend, BufferFormat::F32, e, c.qPrev);
    auto qCur = test::MakeFilled(backend, BufferFormat::F32, e, c.qCur);
    auto t = test::MakeFilled(backend, BufferFormat::F32, e, c.T);
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, c.params.camera.width, c.params.camera.height});
    VkMarchImage out;
    const MarchInputs in{qPrev.get(), qCur.get(), c.params.light == MarchLightSource::Shade ? t.get() : nullptr};
    Status status = backend.RenderMarch(c.params, in, *image, &out.stats);
    EXPECT_TRUE(status.has_value()) << status.error().message;
    out.rgb = test::Read<float>(backend, *image);
    return out;
}

// The shared test camera, with early termination at epsilon 0.01.
MarchParams VkCameraParams(const Extent3& e, std::array<double, 3> eye, std::array<double, 3> target, uint32_t w,
                           uint32_t h, float sigmaH) {
    MarchParams p = test::CameraParams(e, eye, target, w, h, sigmaH);
    p.setup.epsilon = 0.01f;
    return p;
}

class RenderMarchVk : public ::testing::Test {
  protected:
    void SetUp() override {
        BackendOptions options;
        options.vkValidation = true;
        auto backend = CreateBackend("vk", options);
        if (!backend) GTEST_SKIP() << "no Vulkan device: " << backend.error().message;
        mBackend = std::move(*backend);
        mVk = dynamic_cast<vk::BackendVk*>(mBackend.get());
        mExact = mVk->Device().find("llvmpipe") != std::string::npos;
    }
    void TearDown() override {
        if (mVk) {
            EXPECT_EQ(mVk->ValidationMessages(), 0u);
        }
    }
    std::unique_ptr<Backend> mBackend;
    vk::BackendVk* mVk = nullptr;
    bool mExact = false;  // lavapipe: the CPU's operations bit for bit
};

// Test that an empty volume gives the background exactly, with skipping on
// and off, and that the counters see every ray and no light sample.
TEST_F(RenderMarchVk, EmptyVolumeGivesTheBackgroundExactly) {
    VkMarchCase c;
    c.qPrev.assign(c.grid.Count(), 0.0f);
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    c.params = VkCameraParams(c.grid, {-10, 4, 12}, {8, 8, 8}, 24, 18, 0.05f);
    for (bool skipping : {false, true}) {
        c.params.skipping = skipping;
        const VkMarchImage im = RenderOn(*mBackend, c);
        for (size_t i = 0; i < im.rgb.size(); ++i) ASSERT_EQ(im.rgb[i], c.params.setup.background[i % 3]) << i;
        EXPECT_GT(im.stats.rays, 24u * 18u / 4);  // the box fills much of the view
        EXPECT_EQ(im.stats.lightSamples, 0u);
        if (skipping) {
            // 16^3 in bricks of 8: all eight empty, and no sample is taken.
            EXPECT_EQ(im.stats.bricks, 8u);
            EXPECT_EQ(im.stats.emptyBricks, 8u);
            EXPECT_EQ(im.stats.samples, 0u);
        }
    }
}

// Test a full volume of q = 1 (T = 1) seen straight down through its centre: the
// optical depth is sigma h (nz - 1/4) (the half voxel at each face ramps from
// 1/2 to 1), exact for the midpoint rule at step 1/2, so
// C = (sun + ambient)(1 - T) + T background, P = 1; 24 samples on the one ray.
TEST_F(RenderMarchVk, FullVolumeSeenHeadOnMatchesTheTrilinearOpticalDepth) {
    VkMarchCase c;
    c.grid = {8, 8, 12};
    c.qPrev.assign(c.grid.Count(), 1.0f);
    c.qCur = c.qPrev;
    c.T.assign(c.grid.Count(), 1.0f);
    c.params = VkCameraParams(c.grid, {4, 4, 40}, {4, 4, 0}, 1, 1, 0.07f);
    c.params.setup.phase.kind = PhaseKind::None;
    c.params.setup.epsilon = 0;
    const VkMarchImage im = RenderOn(*mBackend, c);
    const double T = std::exp(-0.07 * (12 - 0.25));
    for (int ch = 0; ch < 3; ++ch) {
        const MarchSetup& s = c.params.setup;
        const double expected = (double(s.sunRadiance[ch]) + s.ambient[ch]) * (1 - T) + T * s.background[ch];
        EXPECT_NEAR(im.rgb[ch], expected, 1e-5 * expected);
    }
    EXPECT_EQ(im.stats.rays, 1u);
    EXPECT_EQ(im.stats.samples, 24u);
    EXPECT_EQ(im.stats.lightSamples, 24u);
}

// Test that the image and the counters equal the CPU backend's over the options.
TEST_F(RenderMarchVk, MatchesTheCpuOverEveryOption) {
    cpu::BackendCpu cpu(2);
    VkMarchCase c;
    c.grid = {29, 31, 13};  // odd sizes: partial bricks and workgroups
    c.qCur = test::GaussianBlobField(c.grid, {{8, 10, 5, 2}, {20, 21, 7, 2.5}, {12, 24, 9, 1.5}});
    c.qPrev = test::GaussianBlobField(c.grid, {{9, 10, 5, 2}, {19, 22, 6, 2.5}});
    c.T.resize(c.grid.Count());
    for (size_t i = 0; i < c.T.size(); ++i) c.T[i] = 0.3f + 0.7f * float((i * 2654435761u) % 1000) / 1000.0f;
    struct Variant {
        const char* name;
        void (*apply)(MarchParams&);
    };
    const Variant variants[] = {
        {"default", [](MarchParams&) {}},
        {"no skipping", [](MarchParams& p) { p.skipping = false; }},
        {"light march", [](MarchParams& p) { p.light = MarchLightSource::March, p.lightSteps = 5; }},
        {"light march, no skipping",
         [](MarchParams& p) { p.light = MarchLightSource::March, p.skipping = false; }},
        {"jitter", [](MarchParams& p) { p.jitter = true, p.seed = 7, p.frame = 3; }},
        {"adaptive, jitter, brick 3",
         [](MarchParams& p) {
             p.setup.adaptive = true, p.setup.kappa = 0.2f, p.setup.adaptiveStart = 10;
             p.jitter = true, p.brick = 3;
         }},
        {"adaptive, brick 1", [](MarchParams& p) { p.setup.adaptive = true, p.setup.kappa = 0.05f, p.brick = 1; }},
        {"phase none", [](MarchParams& p) { p.setup.phase.kind = PhaseKind::None; }},
        {"cornette-shanks", [](MarchParams& p) { p.setup.phase = {PhaseKind::CornetteShanks, -0.3f}; }},
        {"mie", [](MarchParams& p) { p.setup.phase.kind = PhaseKind::Mie; }},
        {"powder", [](MarchParams& p) { p.setup.powder = true, p.setup.powderC = 2.5f; }},
        {"point light, mie, light march",
         [](MarchParams& p) {
             p.setup.point = {true, {12, 20, 9}, {30, 30, 40}, 1};
             p.setup.phase.kind = PhaseKind::Mie;
             p.light = MarchLightSource::March;
         }},
        {"point light, small step, epsilon 0",
         [](MarchParams& p) {
             p.setup.point = {true, {-3, 14, 20}, {300, 200, 100}, 4};
             p.setup.step = 0.21f, p.setup.epsilon = 0;
         }},
    };
    for (const Variant& v : variants) {
        SCOPED_TRACE(v.name);
        c.params = VkCameraParams(c.grid, {-20, -10, 30}, {15, 15, 6}, 37, 27, 0.3f);
        c.params.alpha = 0.3f;
        v.apply(c.params);
        const VkMarchImage want = RenderOn(cpu, c);
        const VkMarchImage got = RenderOn(*mBackend, c);
        ASSERT_EQ(got.rgb.size(), want.rgb.size());
        double worst = 0;
        size_t differ = 0;
        for (size_t i = 0; i < want.rgb.size(); ++i) {
            worst = std::max(worst, double(std::fabs(got.rgb[i] - want.rgb[i])));
            differ += got.rgb[i] != want.rgb[i];
        }
        // SPEC 10's rule everywhere (max over every pixel, stricter than 99.9 %); on lavapipe bit for
        // bit but for powder's pow.
        EXPECT_LE(worst, 1e-4);
        if (mExact) {
            if (c.params.setup.powder) EXPECT_LE(worst, 1e-6);
            else EXPECT_EQ(differ, 0u) << "worst " << worst;
        }
        EXPECT_GT(want.stats.lightSamples, 100u);  // the view sees the clouds
        if (mExact || differ == 0) {
            EXPECT_EQ(got.stats.rays, want.stats.rays);
            EXPECT_EQ(got.stats.samples, want.stats.samples);
            EXPECT_EQ(got.stats.lightSamples, want.stats.lightSamples);
            EXPECT_EQ(got.stats.bricksSkipped, want.stats.bricksSkipped);
        }
        EXPECT_EQ(got.stats.bricks, want.stats.bricks);
        EXPECT_EQ(got.stats.emptyBricks, want.stats.emptyBricks);
        if (c.params.skipping) {
            EXPECT_GT(got.stats.emptyBricks, 0u);
            EXPECT_LT(got.stats.emptyBricks, got.stats.bricks);
        }
    }
}

// Test no NaN or Inf and the CPU's image at the extremes: the eye inside the
// volume looking straight up, down and along x (degenerate up), sigma 0, 1e6
// and 0.05, empty, full and blob volumes, both light sources, powder and a
// point light at the eye, with skipping (bricks of 4) on.
TEST_F(RenderMarchVk, NoNanOrInfAtTheExtremesAndTheCpusImage) {
    cpu::BackendCpu cpu(2);
    const Extent3 e{12, 10, 9};
    const std::vector<std::vector<float>> fields = {
        std::vector<float>(e.Count(), 0.0f), std::vector<float>(e.Count(), 1.0f),
        test::GaussianBlobField(e, {{4, 4, 3, 1.5}, {9, 7, 6, 1.5}})};
    const std::array<double, 3> inside{6, 5, 4.5};
    const std::vector<std::array<double, 3>> targets = {{6, 5, 100}, {6, 5, -100}, {50, 5, 4.5}};
    for (const auto& field : fields)
        for (const auto& target : targets)
            for (float sigma : {0.0f, 1e6f, 0.05f})
                for (MarchLightSource source : {MarchLightSource::Shade, MarchLightSource::March}) {
                    VkMarchCase c;
                    c.grid = e;
                    c.qPrev = c.qCur = field;
                    c.T.assign(e.Count(), 0.5f);
                    c.params = VkCameraParams(e, inside, target, 9, 7, MarchOpticalDepthPerVoxel(sigma, 1.0f));
                    c.params.light = source;
                    c.params.brick = 4;
                    c.params.setup.powder = true;
                    c.params.setup.point = {true, {6, 5, 4.5f}, {1e3f, 1e3f, 1e3f}, 0.25f};
                    const VkMarchImage got = RenderOn(*mBackend, c);
                    const VkMarchImage want = RenderOn(cpu, c);
                    for (size_t i = 0; i < got.rgb.size(); ++i) {
                        ASSERT_TRUE(std::isfinite(got.rgb[i])) << "sigma " << sigma << " pixel value " << i;
                        ASSERT_GE(got.rgb[i], 0.0f);
                        // SPEC 10's 1e-4, relative where the point light makes values large.
                        ASSERT_LE(std::fabs(got.rgb[i] - want.rgb[i]), 1e-4f * std::max(1.0f, std::fabs(want.rgb[i])))
                            << "sigma " << sigma << " value " << i;
                    }
                    if (sigma == 0.0f) {
                        for (size_t i = 0; i < got.rgb.size(); ++i)
                            ASSERT_EQ(got.rgb[i], c.params.setup.background[i % 3]);
                    }
                    EXPECT_EQ(got.stats.samples, want.stats.samples);
                }
}

// Test the memory plan's render_march scratch by hand, on a 10 x 12 x 14 grid
// (12 x 14 x 16 = 2688 padded voxels, 3 x 3 x 4 = 36 bricks of 4): the 256-byte
// constants and 40 bytes of counters; (q, T) pairs with light "shade", q alone
// with "march"; a word per brick only with skipping; the table only with Mie.
TEST_F(RenderMarchVk, ScratchBytesByHand) {
    Scene scene;
    scene.stages = StageSet{Stage::RenderMarch};
    scene.grid.size = {10, 12, 14};
    scene.march.brick = 4;
    scene.march.skipping = true;
    scene.march.light = MarchLightSource::Shade;
    scene.phase.kind = PhaseKind::HenyeyGreenstein;
    EXPECT_EQ(mBackend->ScratchBytes(scene), 256u + 40u + 2688u * 8 + 36u * 4);
    scene.march.light = MarchLightSource::March;
    EXPECT_EQ(mBackend->ScratchBytes(scene), 256u + 40u + 2688u * 4 + 36u * 4);
    scene.march.skipping = false;
    EXPECT_EQ(mBackend->ScratchBytes(scene), 256u + 40u + 2688u * 4);
    scene.phase.kind = PhaseKind::Mie;
    EXPECT_EQ(mBackend->ScratchBytes(scene), 256u + 40u + 2688u * 4 + 1801u * 4);
    scene.stages = StageSet{Stage::Shade};
    scene.shade.resolution = 1;
    EXPECT_EQ(mBackend->ScratchBytes(scene), 0u);  // no march, no march scratch
}

#endif  // CLOUDBENCH_HAVE_VK

}  // namespace
}  // namespace cb
