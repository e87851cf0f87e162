// Stage-isolated conformance of the ray marcher (SPEC 10): every backend gets
// the CPU's inputs (q of two steps, alpha, shade's T) and renders from cameras
// outside, inside, toward the sun and at the volume's edge, over a matrix of
// options: jitter, skipping, the fixed and adaptive step, both light sources,
// every phase function (Mie too), powder, the point light, early termination.
// Images compare by SPEC 10's rule (max |d| <= 1e-4 per linear channel on
// 99.9 % of pixels); a failure writes the difference image and names the worst
// pixel and the PSNR. The Vulkan backend runs with the Khronos validation
// layer and must print nothing.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "core/math/Random.h"
#include "harness/report/Report.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb {
namespace {

struct MarchGrid {
    const char* name;
    Extent3 size;
};
void PrintTo(const MarchGrid& g, std::ostream* os) { *os << g.name; }

using MarchConformanceParam = std::tuple<std::string, MarchGrid>;

// One option set of the matrix: a name and its edit of the base parameters.
struct MarchVariant {
    const char* name;
    std::function<void(MarchParams&)> edit;
};

// Each option on and off at least once, and the options that interact
// (skipping with jitter and the adaptive step, the light march with powder and
// the point light) together.
std::vector<MarchVariant> MarchVariants(const Extent3& e) {
    auto point = [e](MarchParams& p) {
        p.setup.light.pointOn = true;
        p.setup.light.pointPosition = {0.6f * float(e.nx), 0.4f * float(e.ny), 0.5f * float(e.nz)};
        p.setup.light.pointRadiance = {40.0f, 42.0f, 50.0f};
        p.setup.light.pointMinDistance2 = 4.0f;  // r0 = 2 m (h = 1 m): the cap bites next to the light
    };
    return {
        {"baseline: shade light, skipping, HG", [](MarchParams&) {}},
        {"skipping off", [](MarchParams& p) { p.skipping = false; }},
        {"jitter", [](MarchParams& p) { p.jitter = true; }},
        {"jitter, skipping off", [](MarchParams& p) { p.jitter = true, p.skipping = false; }},
        {"adaptive step",
         [](MarchParams& p) { p.setup.adaptive = true, p.setup.kappa = 0.05f, p.setup.adaptiveStart = 8; }},
        {"adaptive, jitter, skipping off",
         [](MarchParams& p) {
             p.setup.adaptive = true, p.setup.kappa = 0.08f, p.setup.adaptiveStart = 4;
             p.jitter = true, p.skipping = false;
         }},
        {"brick 4, step 1", [](MarchParams& p) { p.brick = 4, p.setup.step = 1.0f; }},
        {"light march n_l 5", [](MarchParams& p) { p.light = MarchLightSource::March, p.lightSteps = 5; }},
        {"light march, powder c 2",
         [](MarchParams& p) { p.light = MarchLightSource::March, p.lightSteps = 4, p.setup.powder = true; }},
        {"shade light, powder c 3.5", [](MarchParams& p) { p.setup.powder = true, p.setup.powderC = 3.5f; }},
        {"phase none", [](MarchParams& p) { p.setup.light.phase.kind = PhaseKind::None; }},
        {"phase Cornette-Shanks g 0.75",
         [](MarchParams& p) {
             p.setup.light.phase = {PhaseKind::CornetteShanks, 0.75f};
         }},
        {"phase Mie", [](MarchParams& p) { p.setup.light.phase.kind = PhaseKind::Mie; }},
        {"phase dual-lobe 0.85 / -0.4, blend 0.3",
         [](MarchParams& p) {
             p.setup.light.phase = {PhaseKind::DualLobe, 0.6f, 0.85f, -0.4f, 0.3f};
         }},
        {"point light, shade light", point},
        {"point light, light march, Mie, jitter, adaptive",
         [point](MarchParams& p) {
             point(p);
             p.light = MarchLightSource::March, p.lightSteps = 3;
             p.setup.light.phase.kind = PhaseKind::Mie;
             p.jitter = true;
             p.setup.adaptive = true, p.setup.kappa = 0.05f, p.setup.adaptiveStart = 6;
         }},
        {"epsilon 0, dense", [](MarchParams& p) { p.setup.epsilon = 0, p.setup.sigmaH = 0.6f; }},
        // The ground plane lit through G (core/math/Ground.h) as the background, per pixel.
        {"ground",
         [](MarchParams& p) {
             p.ground = {true, {0.35f, 0.3f, 0.25f}};
         }},
        {"ground, light march, jitter",
         [](MarchParams& p) {
             p.ground = {true, {0.6f, 0.5f, 0.4f}};
             p.light = MarchLightSource::March, p.lightSteps = 4, p.jitter = true;
         }},
    };
}

class MarchConformance : public ::testing::TestWithParam<MarchConformanceParam> {
  protected:
    void SetUp() override {
        BackendOptions options;
        options.vkValidation = true;  // the Khronos layer must stay silent
        options.cpuThreads = 1;       // the CPU against itself: one thread against two
        auto backend = CreateBackend(std::get<0>(GetParam()), options);
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
        if (!mBackend->Supports(Stage::RenderMarch)) GTEST_SKIP() << mBackend->Name() << " has no render_march";
    }
    void TearDown() override {
#if CLOUDBENCH_HAVE_VK
        if (auto* vk = dynamic_cast<vk::BackendVk*>(mBackend.get())) {
            EXPECT_EQ(vk->ValidationMessages(), 0u);
        }
#endif
    }
    cpu::BackendCpu mCpu{2};
    std::unique_ptr<Backend> mBackend;
};

// Cameras (eye, target) in voxel units (h = 1 m) for a grid e.
std::vector<std::pair<const char*, CameraSettings>> MarchCameras(const Extent3& e, const Vec3& sun) {
    const double cx = e.nx / 2.0, cy = e.ny / 2.0, cz = e.nz / 2.0;
    auto camera = [](std::array<double, 3> eye, std::array<double, 3> target) {
        CameraSettings c;
        c.eye = eye;
        c.target = target;
        c.fovDeg = 55;
        c.nearPlane = 0.05;
        c.farPlane = 1e4;
        return c;
    };
    // Toward the sun, the sun 25 degrees above the view axis: forward scattering, Mie's steep lobe.
    const double d = 3.0 * (e.nx + e.ny + e.nz);
    const std::array<double, 3> behind{cx - sun[0] * d, cy - sun[1] * d, cz + 0.2 * e.nz};
    return {
        {"above", camera({-0.6 * e.nx, -0.5 * e.ny, 3.0 * e.nz + 10}, {cx, cy, cz})},
        {"inside", camera({0.3 * e.nx, 0.45 * e.ny, 0.55 * e.nz}, {e.nx * 1.0, cy, cz * 0.8})},
        {"toward the sun", camera(behind, {cx + sun[0] * 10, cy + sun[1] * 10, cz + 0.2 * e.nz})},
        {"edge, grazing", camera({0.0, 0.5 * e.ny, 1.0 * e.nz}, {e.nx * 1.0, 0.52 * e.ny, 0.9 * e.nz})},
    };
}

// q of two steps (a cloud that moves and changes between them), T, and a ground shadow G.
struct MarchFields {
    std::vector<float> qPrev, qCur, T, G;
};
MarchFields MakeMarchFields(const Extent3& e) {
    MarchFields f;
    const double sx = e.nx, sy = e.ny, sz = e.nz;
    f.qPrev = test::GaussianBlobField(
        e, {{0.3 * sx, 0.35 * sy, 0.5 * sz, 0.12 * sx + 0.5}, {0.7 * sx, 0.6 * sy, 0.4 * sz, 0.1 * sx + 0.5}});
    f.qCur = test::GaussianBlobField(
        e, {{0.36 * sx, 0.4 * sy, 0.55 * sz, 0.1 * sx + 0.5}, {0.62 * sx, 0.7 * sy, 0.45 * sz, 0.12 * sx + 0.5}});
    Pcg32 rng(41);
    f.T.resize(e.Count());
    for (float& t : f.T) t = float(rng.Below(4097)) / 4096.0f;
    f.G.resize(size_t(e.nx) * e.ny);
    for (float& g : f.G) g = float(rng.Below(4097)) / 4096.0f;
    return f;
}

struct MarchRendering {
    std::vector<float> rgb;
    MarchStats stats;
};

MarchRendering RenderMarchOn(Backend& b, const Extent3& e, const MarchFields& f, const MarchParams& p) {
    auto qp = test::MakeFilled(b, BufferFormat::F32, e, f.qPrev);
    auto qc = test::MakeFilled(b, BufferFormat::F32, e, f.qCur);
    auto t = test::MakeFilled(b, BufferFormat::F32, e, f.T);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    auto g = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, f.G);
    MarchInputs in{qp.get(), qc.get(), p.light == MarchLightSource::Shade ? t.get() : nullptr};
    in.G = p.ground.on ? g.get() : nullptr;
    MarchRendering r;
    Status s = b.RenderMarch(p, in, *image, &r.stats);
    EXPECT_TRUE(s.has_value()) << b.Name() << ": " << s.error().message;
    if (s) r.rgb = test::Read<float>(b, *image);
    return r;
}

// Test the whole matrix: every variant from every camera, compared by SPEC 10's rule.
TEST_P(MarchConformance, OptionMatrix) {
    const Extent3 e = std::get<1>(GetParam()).size;
    const MarchFields fields = MakeMarchFields(e);
    const Vec3 sun = SunDirection(0.5, 0.9);
    const uint32_t W = 37, H = 23;  // odd, and not a multiple of any tile
    const CompareRule rule = Describe(Stage::RenderMarch).rule(Scene{});
    for (const auto& [cameraName, camera] : MarchCameras(e, sun)) {
        uint64_t lightSamples = 0;
        for (const MarchVariant& v : MarchVariants(e)) {
            SCOPED_TRACE(std::string(cameraName) + " | " + v.name);
            MarchParams p;
            p.camera = MakeCameraFrame(camera, W, H);
            p.setup.size = {float(e.nx), float(e.ny), float(e.nz)};
            p.setup.voxelSize = p.setup.light.voxelSize = 1;
            p.setup.step = 0.5f;
            p.setup.sigmaH = 0.25f;
            p.setup.epsilon = 0.01f;
            p.setup.sun = sun;
            p.setup.light.sunRadiance = {1.5f, 1.4f, 1.25f};
            p.setup.light.ambient = {0.2f, 0.24f, 0.3f};
            p.setup.background = {0.4f, 0.55f, 0.85f};
            p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
            p.origin = {0, 0, 0};
            p.alpha = 0.4f;
            p.seed = 7;
            p.frame = 3;
            v.edit(p);
            const MarchRendering ref = RenderMarchOn(mCpu, e, fields, p);
            const MarchRendering got = RenderMarchOn(*mBackend, e, fields, p);
            ASSERT_EQ(got.rgb.size(), ref.rgb.size());
            lightSamples += ref.stats.lightSamples;
            // Counts: the rays and the skip structure are integer work, equal everywhere; the samples may
            // differ where a float rounds a sample across the end of a ray or T_view across epsilon.
            EXPECT_EQ(got.stats.rays, ref.stats.rays);
            EXPECT_EQ(got.stats.bricks, ref.stats.bricks);
            EXPECT_EQ(got.stats.emptyBricks, ref.stats.emptyBricks);
            EXPECT_NEAR(double(got.stats.samples), double(ref.stats.samples), 2 + 1e-3 * double(ref.stats.samples));
            EXPECT_NEAR(double(got.stats.lightSamples), double(ref.stats.lightSamples),
                        2 + 1e-3 * double(ref.stats.lightSamples));
            const ImageComparison cmp = CompareImages(ref.rgb, got.rgb, W, H, rule).value();
            if (!cmp.Passes()) {
                const std::string path = ::testing::TempDir() + "/march_diff_" + mBackend->Name() + ".exr";
                (void)WriteDifferenceImage(path, ref.rgb, got.rgb, W, H);
                const size_t at = 3 * (size_t(cmp.worstX) + size_t(W) * size_t(cmp.worstY));
                ADD_FAILURE() << "max error " << cmp.maxError << " at (" << cmp.worstX << ", " << cmp.worstY
                              << "): cpu " << ref.rgb[at] << " " << ref.rgb[at + 1] << " " << ref.rgb[at + 2] << ", "
                              << mBackend->Name() << " " << got.rgb[at] << " " << got.rgb[at + 1] << " "
                              << got.rgb[at + 2] << "; " << cmp.pixelsOverTolerance << " of " << cmp.pixels
                              << " pixels over " << rule.tolerance << ", PSNR " << cmp.psnr
                              << "; difference image: " << path;
            }
        }
        // Every camera sees cloud, or the comparison would prove little.
        if (e.nx > 1) {
            EXPECT_GT(lightSamples, 0u) << cameraName << " sees no cloud";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(RenderMarch, MarchConformance,
                         ::testing::Combine(::testing::ValuesIn(cb::test::TestBackends()),
                                            ::testing::Values(MarchGrid{"Small32x32x16", {32, 32, 16}},
                                                              MarchGrid{"Odd31x29x13", {31, 29, 13}},
                                                              MarchGrid{"Thin1x1x9", {1, 1, 9}})),
                         [](const ::testing::TestParamInfo<MarchConformanceParam>& info) {
                             return std::string(std::get<1>(info.param).name) + "_" + std::get<0>(info.param);
                         });

}  // namespace
}  // namespace cb
