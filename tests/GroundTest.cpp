// The ground plane in the frame (docs/pipeline.md, "The ground
// in the frame"): core/math/Ground.h's formulas against values worked out by hand,
// both renderers on every backend against closed forms (an empty volume over a
// ground of known G), the flat background where no ray meets the ground, and
// the backends against the CPU by SPEC 8's and SPEC 10's image rules.
#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include "core/math/Ground.h"
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

// ---- core/math/Ground.h alone ------------------------------------------------------

// Test that a ray meets z = 0 where the line does, and only pointing down within [tNear, tFar].
TEST(GroundFormula, HitPoint) {
    float x = -1, y = -1;
    // From (2, 3, 4) along (0.6, 0, -0.8): t = 4 / 0.8 = 5, x = 2 + 3 = 5, y = 3.
    ASSERT_TRUE(GroundHit({2, 3, 4}, {0.6f, 0, -0.8f}, 0.1f, 100, x, y));
    EXPECT_FLOAT_EQ(x, 5.0f);
    EXPECT_FLOAT_EQ(y, 3.0f);
    EXPECT_FALSE(GroundHit({2, 3, 4}, {0.6f, 0, -0.8f}, 0.1f, 4.9f, x, y));  // beyond far
    EXPECT_FALSE(GroundHit({2, 3, 4}, {0.6f, 0, -0.8f}, 5.1f, 100, x, y));   // before near
    EXPECT_FALSE(GroundHit({2, 3, 4}, {1, 0, 0}, 0.1f, 100, x, y));          // level
    EXPECT_FALSE(GroundHit({2, 3, 4}, {0, 0.6f, 0.8f}, 0.1f, 100, x, y));    // up
    EXPECT_FALSE(GroundHit({2, 3, -1}, {0, 0, -1}, 0.1f, 100, x, y));        // eye below the ground
}

// Test G between cell centres, clamped at the edge cells, and 1 outside the footprint.
// Cells of a 3 x 2 grid: row j = 0: 0.2 0.4 0.8; row j = 1: 1.0 0.0 0.6 (centres at i + 0.5, j + 0.5).
TEST(GroundFormula, ShadowBilinearClampedOutsideOne) {
    const float g[6] = {0.2f, 0.4f, 0.8f, 1.0f, 0.0f, 0.6f};
    auto at = [&](float x, float y) {
        return GroundShadowAt(x, y, 3, 2, [&](uint32_t i, uint32_t j) { return g[i + 3 * j]; });
    };
    EXPECT_FLOAT_EQ(at(0.5f, 0.5f), 0.2f);             // a centre
    EXPECT_FLOAT_EQ(at(1.0f, 0.5f), 0.3f);             // halfway between 0.2 and 0.4
    EXPECT_FLOAT_EQ(at(1.0f, 1.0f), 0.4f);             // the mean of 0.2, 0.4, 1.0, 0.0
    EXPECT_FLOAT_EQ(at(2.75f, 0.5f), 0.8f);            // past the last centre: clamped to cell 2
    EXPECT_FLOAT_EQ(at(0.1f, 1.9f), 1.0f);             // corner cell (0, 1), clamped both ways
    EXPECT_FLOAT_EQ(at(3.0f, 2.0f), 0.6f);             // the footprint's far corner is inside
    // Taps (1.5, 0.75): rows 0.4..0.8 -> 0.6 and 0.0..0.6 -> 0.3, then 0.6 * 0.25 + 0.3 * 0.75.
    EXPECT_FLOAT_EQ(at(2.0f, 1.25f), 0.375f);
    EXPECT_EQ(at(-0.01f, 1.0f), 1.0f);                 // outside the footprint: no cloud
    EXPECT_EQ(at(1.0f, 2.01f), 1.0f);
    EXPECT_EQ(at(3.5f, 0.5f), 1.0f);
}

// Test the colour: albedo (sun s_z G + ambient), and no sun term with the sun below the horizon.
TEST(GroundFormula, Channel) {
    EXPECT_FLOAT_EQ(GroundChannel(0.5f, 2.0f, 0.5f, 0.25f, 0.5f), 0.5f * (2.0f * 0.5f * 0.5f + 0.25f));
    EXPECT_FLOAT_EQ(GroundChannel(0.5f, 2.0f, -0.3f, 0.25f, 0.5f), 0.125f);
}

// ---- Both renderers on every backend ------------------------------------------

enum class Renderer { Splat, March };
void PrintTo(Renderer r, std::ostream* os) { *os << (r == Renderer::Splat ? "render_splat" : "render_march"); }
using GroundParam = std::tuple<std::string, Renderer>;

// The test grid: 16 x 12 x 4 voxels of 1 m at the origin; the ground is z = 0.
constexpr Extent3 kGroundGrid{16, 12, 4};
const Vec3 kAlbedo{0.5f, 0.4f, 0.3f}, kSun{1.2f, 1.1f, 1.0f}, kAmbient{0.2f, 0.25f, 0.3f}, kFlat{0.1f, 0.2f, 0.9f};

CameraSettings GroundCamera(std::array<double, 3> eye, std::array<double, 3> target, double fov = 90,
                            std::array<double, 3> up = {0, 1, 0}) {
    CameraSettings c;
    c.eye = eye;
    c.target = target;
    c.up = up;
    c.fovDeg = fov;
    c.nearPlane = 0.05;
    c.farPlane = 1000;
    return c;
}

class GroundRender : public ::testing::TestWithParam<GroundParam> {
  protected:
    void SetUp() override {
        BackendOptions options;
        options.vkValidation = true;  // the Khronos layer must stay silent
        auto backend = CreateBackend(std::get<0>(GetParam()), options);
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
        const Stage stage = Which() == Renderer::Splat ? Stage::RenderSplat : Stage::RenderMarch;
        if (!mBackend->Supports(stage)) GTEST_SKIP() << mBackend->Name() << " has no " << StageName(stage);
    }
    void TearDown() override {
#if CLOUDBENCH_HAVE_VK
        if (auto* vk = dynamic_cast<vk::BackendVk*>(mBackend.get())) {
            EXPECT_EQ(vk->ValidationMessages(), 0u);
        }
#endif
    }
    Renderer Which() const { return std::get<1>(GetParam()); }

    // Renders q (both steps), T and G (nullptr: no ground) from `camera` on backend b, W x H.
    std::vector<float> Render(Backend& b, const CameraSettings& camera, uint32_t W, uint32_t H,
                              const std::vector<float>& q, const std::vector<float>& T, const std::vector<float>* G,
                              const Vec3& sunDir) {
        const Extent3 e = kGroundGrid;
        auto qb = test::MakeFilled(b, BufferFormat::F32, e, q);
        auto tb = test::MakeFilled(b, BufferFormat::F32, e, T);
        std::unique_ptr<Buffer> gb;
        if (G) gb = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, *G);
        auto image = test::MakeBuffer(b, BufferFormat::F32, {3, W, H});
        GroundParams ground{G != nullptr, kAlbedo};
        Status s;
        if (Which() == Renderer::Splat) {
            SplatParams p;
            p.camera = MakeCameraFrame(camera, W, H);
            const SplatOrder order = MakeSplatOrder(p.camera, e, {0, 0, 0}, 1.0);
            p.order = &order;
            p.sun = sunDir;
            p.light.sunRadiance = kSun;
            p.light.ambient = kAmbient;
            p.background = kFlat;
            p.light.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
            p.splatDiameter = 1.5f;
            p.voxelSize = 1;
            p.skipping = false;  // no occupancy maps here
            p.ground = ground;
            SplatInputs in{qb.get(), qb.get(), tb.get()};
            in.G = gb.get();
            SplatStats stats;
            s = b.RenderSplat(p, in, *image, &stats);
        } else {
            MarchParams p;
            p.camera = MakeCameraFrame(camera, W, H);
            p.setup.size = {float(e.nx), float(e.ny), float(e.nz)};
            p.setup.voxelSize = p.setup.light.voxelSize = 1;
            p.setup.sigmaH = 0.5f;
            p.setup.sun = sunDir;
            p.setup.light.sunRadiance = kSun;
            p.setup.light.ambient = kAmbient;
            p.setup.background = kFlat;
            p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
            p.ground = ground;
            MarchInputs in{qb.get(), qb.get(), tb.get()};
            in.G = gb.get();
            MarchStats stats;
            s = b.RenderMarch(p, in, *image, &stats);
        }
        EXPECT_TRUE(s.has_value()) << b.Name() << ": " << (s ? "" : s.error().message);
        return s ? test::Read<float>(b, *image) : std::vector<float>{};
    }

    std::unique_ptr<Backend> mBackend;
};

// G of a step at a known x: 1 on cells i < 8, 0.25 on cells i >= 8.
std::vector<float> StepShadow() {
    std::vector<float> g(size_t(kGroundGrid.nx) * kGroundGrid.ny);
    for (uint32_t j = 0; j < kGroundGrid.ny; ++j)
        for (uint32_t i = 0; i < kGroundGrid.nx; ++i) g[i + kGroundGrid.nx * j] = i < 8 ? 1.0f : 0.25f;
    return g;
}

std::vector<float> Zeros() { return std::vector<float>(kGroundGrid.Count(), 0.0f); }
std::vector<float> Ones() { return std::vector<float>(kGroundGrid.Count(), 1.0f); }

// GPU backends may round the ray's divisions and square root differently (a few ulps).
float Tolerance(const Backend& b) { return b.Name() == "cpu" ? 0.0f : 1e-6f; }

// Test an empty volume seen from straight above, the sun overhead, G = 1: every
// pixel is ground lit by the whole sun, albedo (sun + ambient).
TEST_P(GroundRender, EmptyVolumeFullSun) {
    const uint32_t W = 32, H = 24;
    const std::vector<float> G(size_t(kGroundGrid.nx) * kGroundGrid.ny, 1.0f);
    const auto rgb = Render(*mBackend, GroundCamera({8, 6, 12}, {8, 6, 0}), W, H, Zeros(), Ones(), &G, {0, 0, 1});
    ASSERT_EQ(rgb.size(), size_t(3) * W * H);
    const float tol = Tolerance(*mBackend);
    for (uint32_t n = 0; n < W * H; ++n)
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(rgb[3 * n + c], kAlbedo[c] * (kSun[c] + kAmbient[c]), tol)
                << "pixel (" << n % W << ", " << n / W << ") channel " << c;
}

// Test the step of G on the pixels worked out by hand. The camera looks straight
// down from (8.25, 6, 12), fov 90 on 32 x 24: f_px = 12, right = +x, up = +y,
// so pixel (x, y) sees the ground at (x - 7.25, 17.5 - y). Inside the footprint
// [0, 16] x [0, 12] (x = 8..23, y = 6..17) G is bilinear between the centres
// (i + 0.5): at pixel x the tap coordinate is x - 7.75, so x = 8..14 read
// cells i <= 7 only (G = 1), x = 15 reads 3/4 of cell 7 and 1/4 of cell 8 (G =
// 0.8125), x = 16..22 cells >= 8 (0.25), x = 23 (15.25) is clamped to cell 15
// (0.25). Outside the footprint G = 1.
TEST_P(GroundRender, ShadowStepOnExpectedPixels) {
    const uint32_t W = 32, H = 24;
    const std::vector<float> G = StepShadow();
    const auto rgb = Render(*mBackend, GroundCamera({8.25, 6, 12}, {8.25, 6, 0}), W, H, Zeros(), Ones(), &G, {0, 0, 1});
    ASSERT_EQ(rgb.size(), size_t(3) * W * H);
    const float tol = 1e-5f;  // the ray lands on a tap coordinate up to a few ulps off
    int shadowed = 0;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const bool inside = x >= 8 && x <= 23 && y >= 6 && y <= 17;
            const float g = !inside ? 1.0f : x <= 14 ? 1.0f : x == 15 ? 0.8125f : 0.25f;
            shadowed += g < 1.0f;
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(rgb[3 * (x + W * y) + c], kAlbedo[c] * (kSun[c] * g + kAmbient[c]), tol)
                    << "pixel (" << x << ", " << y << ") channel " << c << ", G " << g;
        }
    EXPECT_EQ(shadowed, 9 * 12);
}

// Test that a slanted sun scales the sun's term by s_z, and that no ray meets
// the ground beyond the far plane: there the flat background stays.
TEST_P(GroundRender, SlantedSunAndFarPlane) {
    const uint32_t W = 8, H = 6;
    const std::vector<float> G(size_t(kGroundGrid.nx) * kGroundGrid.ny, 1.0f);
    const Vec3 sun{0.6f, 0.0f, 0.8f};
    const auto lit = Render(*mBackend, GroundCamera({8, 6, 12}, {8, 6, 0}), W, H, Zeros(), Ones(), &G, sun);
    ASSERT_EQ(lit.size(), size_t(3) * W * H);
    for (uint32_t n = 0; n < W * H; ++n)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(lit[3 * n + c], kAlbedo[c] * (kSun[c] * 0.8f + kAmbient[c]), 1e-6f);
    CameraSettings shortSight = GroundCamera({8, 6, 12}, {8, 6, 0});
    shortSight.farPlane = 11;  // the ground lies at depth 12 and more
    const auto far = Render(*mBackend, shortSight, W, H, Zeros(), Ones(), &G, sun);
    ASSERT_EQ(far.size(), size_t(3) * W * H);
    for (uint32_t n = 0; n < W * H; ++n)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(far[3 * n + c], kFlat[c]) << "pixel " << n;
}

// Clouds: two Gaussian blobs in the 16 x 12 x 4 grid, and a T that varies.
std::vector<float> CloudQ() {
    return test::GaussianBlobField(kGroundGrid, {{5, 5, 2, 2.0}, {11, 7, 2.5, 1.8}});
}
std::vector<float> CloudT() {
    std::vector<float> t(kGroundGrid.Count());
    Pcg32 rng(5);
    for (float& v : t) v = float(rng.Below(4097)) / 4096.0f;
    return t;
}

// Test that a pixel whose ray misses the ground keeps the flat background, so a
// view of the clouds from below looking up is byte for byte the image without ground.
TEST_P(GroundRender, LookingUpUnchanged) {
    const uint32_t W = 37, H = 23;
    const CameraSettings up = GroundCamera({7, 5, 1}, {8.5, 6.5, 40}, 70, {1, 0, 0});
    const std::vector<float> G = StepShadow(), q = CloudQ(), T = CloudT();
    const Vec3 sun = SunDirection(0.6, 0.8);
    const auto with = Render(*mBackend, up, W, H, q, T, &G, sun);
    const auto without = Render(*mBackend, up, W, H, q, T, nullptr, sun);
    ASSERT_EQ(with.size(), size_t(3) * W * H);
    ASSERT_EQ(with, without);
    // The clouds are in view (the image is not the flat background alone).
    size_t cloudy = 0;
    for (uint32_t n = 0; n < W * H; ++n) cloudy += with[3 * n + 2] != kFlat[2];
    EXPECT_GT(cloudy, 20u);
}

// Test the backend against the CPU with ground on, clouds, a slanted sun and a
// G with structure, from an oblique camera that sees sky, ground and clouds,
// by the renderer's image rule.
TEST_P(GroundRender, MatchesCpu) {
    const uint32_t W = 67, H = 45;
    std::vector<float> G(size_t(kGroundGrid.nx) * kGroundGrid.ny);
    for (uint32_t j = 0; j < kGroundGrid.ny; ++j)
        for (uint32_t i = 0; i < kGroundGrid.nx; ++i)
            G[i + kGroundGrid.nx * j] = 0.2f + 0.8f * float((i * 7 + j * 3) % 11) / 10.0f;
    const CameraSettings oblique = GroundCamera({-10, -8, 9}, {9, 7, 1}, 60, {0, 0, 1});
    const std::vector<float> q = CloudQ(), T = CloudT();
    const Vec3 sun = SunDirection(0.7, 0.5);
    cpu::BackendCpu cpu(2);
    const auto ref = Render(cpu, oblique, W, H, q, T, &G, sun);
    const auto got = Render(*mBackend, oblique, W, H, q, T, &G, sun);
    ASSERT_EQ(got.size(), ref.size());
    const Stage stage = Which() == Renderer::Splat ? Stage::RenderSplat : Stage::RenderMarch;
    const CompareRule rule = Describe(stage).rule(Scene{});
    const ImageComparison cmp = CompareImages(ref, got, W, H, rule).value();
    EXPECT_TRUE(cmp.Passes()) << "max error " << cmp.maxError << " at (" << cmp.worstX << ", " << cmp.worstY << "), "
                              << cmp.pixelsOverTolerance << " of " << cmp.pixels << " pixels over tolerance";
    // The frame holds ground in shadow, lit ground and sky.
    size_t sky = 0, ground = 0;
    for (uint32_t n = 0; n < W * H; ++n) {
        sky += ref[3 * n] == kFlat[0] && ref[3 * n + 2] == kFlat[2];
        ground += ref[3 * n] != kFlat[0];
    }
    EXPECT_GT(sky, 0u);
    EXPECT_GT(ground, size_t(W) * H / 4);
}

INSTANTIATE_TEST_SUITE_P(Ground, GroundRender,
                         ::testing::Combine(::testing::ValuesIn(cb::test::TestBackends()),
                                            ::testing::Values(Renderer::Splat, Renderer::March)),
                         [](const ::testing::TestParamInfo<GroundParam>& info) {
                             return std::string(std::get<1>(info.param) == Renderer::Splat ? "Splat" : "March") + "_" +
                                    std::get<0>(info.param);
                         });

}  // namespace
}  // namespace cb
