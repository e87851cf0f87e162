// Tiling in the ray marcher and its exact reference render (SPEC 15: density
// and light repeat in x and y with the grid's period). The clip to the slab by
// hand; the CPU march and the reference against the same renders of the untiled
// volume made of explicit copies of the period (which cannot share a wrapping
// bug); skipping that moves no sample across the seams; and homogeneous layers
// seen from many periods away, and under a low sun whose light crosses many
// periods, against their closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/March.h"
#include "impl_cpu/BackendCpu.h"
#include "reference/MarchReference.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test the clip by hand: with tiling only the slab 0 <= z <= nz bounds a ray; without it the box.
TEST(MarchTiling, ClipRayToVolumeBoundsTheSlabAlone) {
    const Vec3 size{10, 10, 10};
    // From far outside the box in x, climbing through the slab: 1/0.5 = 2 exactly, so t in [(0+2) 2, (10+2) 2].
    float t0 = 0, t1 = 1e30f;
    ClipRayToVolume({-100, 5, -2}, {0.75f, 0, 0.5f}, size, true, t0, t1);
    EXPECT_EQ(t0, 4.0f);
    EXPECT_EQ(t1, 24.0f);
    t0 = 0, t1 = 1e30f;
    ClipRayToVolume({-100, 5, -2}, {0.75f, 0, 0.5f}, size, false, t0, t1);
    EXPECT_FALSE(t0 < t1);  // the box lies 133 voxels along, past the slab's top at 24
    // Horizontal inside the slab: nothing bounds it but the interval it came with.
    t0 = 0.5f, t1 = 1e30f;
    ClipRayToVolume({-100, 5, 5}, {1, 0, 0}, size, true, t0, t1);
    EXPECT_EQ(t0, 0.5f);
    EXPECT_EQ(t1, 1e30f);
    // Horizontal below the slab: empty either way.
    t0 = 0, t1 = 1e30f;
    ClipRayToVolume({-100, 5, -1}, {1, 0, 0}, size, true, t0, t1);
    EXPECT_FALSE(t0 < t1);
}

// One period and the untiled volume of copies x copies of it, the copies' grid
// placed so that the period's copy at index (copies / 2, copies / 2) sits where the period does.
struct TiledCopies {
    Extent3 period, big;
    std::vector<float> q, T, qBig, TBig;
    std::array<float, 3> bigOrigin;
};

TiledCopies MakeTiledCopies(const Extent3& e, uint32_t copies) {
    TiledCopies c;
    c.period = e;
    c.big = {e.nx * copies, e.ny * copies, e.nz};
    // A blob across the x = 0 seam and one across the y = 0 seam, so that the wrapped taps matter.
    c.q = test::GaussianBlobField(e, {{0.5, 0.5 * e.ny, 0.4 * e.nz, 1.2}, {0.6 * e.nx, 0.2, 0.6 * e.nz, 1.8},
                                      {0.4 * e.nx, 0.6 * e.ny, 0.5 * e.nz, 1.5}});
    c.T.resize(e.Count());
    for (size_t i = 0; i < c.T.size(); ++i) c.T[i] = 0.3f + 0.7f * float((i * 2654435761u) % 1000) / 1000.0f;
    c.qBig.resize(c.big.Count());
    c.TBig.resize(c.big.Count());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < c.big.ny; ++j)
            for (uint32_t i = 0; i < c.big.nx; ++i) {
                const size_t from = VoxelIndex(e, i % e.nx, j % e.ny, k), to = VoxelIndex(c.big, i, j, k);
                c.qBig[to] = c.q[from];
                c.TBig[to] = c.T[from];
            }
    const uint32_t half = copies / 2;
    c.bigOrigin = {-float(half * e.nx), -float(half * e.ny), 0.0f};
    return c;
}

struct TilingImage {
    std::vector<float> rgb;
    MarchStats stats;
};

TilingImage RenderTilingCpu(const MarchParams& p, const Extent3& e, const std::vector<float>& q, const std::vector<float>& T) {
    cpu::BackendCpu cpu(2);
    auto qb = test::MakeFilled(cpu, BufferFormat::F32, e, q);
    auto tb = test::MakeFilled(cpu, BufferFormat::F32, e, T);
    auto image = test::MakeBuffer(cpu, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    TilingImage out;
    const Status s = cpu.RenderMarch(p, {qb.get(), qb.get(), tb.get()}, *image, &out.stats);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    if (s) out.rgb = test::Read<float>(cpu, *image);
    return out;
}

// The tiled march of one period, and the untiled march of the copies with the same camera, sun and far plane:
// the far plane keeps every ray, and the sun's light march from it, inside the copies.
struct TilingPair {
    MarchParams tiled, copies;
};
TilingPair MakeTilingPair(const TiledCopies& c, MarchLightSource light) {
    // The eye above the layer, looking down across the seams; the far plane 20 voxel edges of depth, so a ray
    // reaches at most 24 voxels across, and the sun (40 degrees up) adds at most 10 more on its way out.
    TilingPair p;
    p.tiled = test::CameraParams(c.period, {6, 5, 14}, {14, 11, 0}, 24, 18);
    p.tiled.camera.farPlane = 20;
    p.tiled.light = light;
    p.tiled.lightSteps = 6;
    p.tiled.skipping = false;
    p.tiled.setup.tiling = true;
    const Vec3 size = p.tiled.setup.size;
    p.tiled.setup.invSize = {1.0f / size[0], 1.0f / size[1], 1.0f / size[2]};
    p.copies = p.tiled;
    p.copies.setup.tiling = false;
    p.copies.setup.size = {float(c.big.nx), float(c.big.ny), float(c.big.nz)};
    p.copies.origin = c.bigOrigin;
    return p;
}

double TilingWorstDifference(const std::vector<float>& a, const std::vector<float>& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::fabs(double(a[i]) - b[i]));
    return worst;
}

// Test the tiled CPU march against the untiled march of explicit copies, with
// shade's T and with the light march: within SPEC 10's 1e-4 (the two place the
// same samples, from eyes 36 and 30 voxels apart in their grids' units, so
// they differ by rounding alone) and with the same samples taken.
TEST(MarchTiling, CpuMarchEqualsTheUntiledMarchOfCopies) {
    const TiledCopies c = MakeTiledCopies({12, 10, 8}, 7);
    for (MarchLightSource light : {MarchLightSource::Shade, MarchLightSource::March}) {
        const TilingPair p = MakeTilingPair(c, light);
        const TilingImage tiled = RenderTilingCpu(p.tiled, c.period, c.q, c.T);
        const TilingImage copies = RenderTilingCpu(p.copies, c.big, c.qBig, c.TBig);
        const char* name = light == MarchLightSource::Shade ? "shade" : "light march";
        ASSERT_EQ(tiled.rgb.size(), copies.rgb.size()) << name;
        EXPECT_LE(TilingWorstDifference(tiled.rgb, copies.rgb), 1e-4) << name;
        EXPECT_EQ(tiled.stats.samples, copies.stats.samples) << name;
        EXPECT_EQ(tiled.stats.rays, copies.stats.rays) << name;
        // The case must cross the seams and see clouds in more than one period.
        EXPECT_GT(tiled.stats.lightSamples, 0u) << name;
        // Without tiling the period alone is a small box most rays miss: the images must differ.
        MarchParams untiled = p.tiled;
        untiled.setup.tiling = false;
        EXPECT_GT(TilingWorstDifference(RenderTilingCpu(untiled, c.period, c.q, c.T).rgb, tiled.rgb), 0.01) << name;
    }
}

// Test that skipping empty bricks moves no sample with tiling: bit for bit the
// image without skipping, with bricks the period fills (5 of 25) and a last one
// it does not (5 of 32). The box of that seventh brick along x must be cut at
// the seam: uncut, it reaches over the next period's first three voxels, and a
// ray leaving it in +x would jump over the narrow blob there (at x = 3.5 and
// y = 22.5, below the 1e-3 cut at x = 0.5 and clear of the seam blob, so the
// bricks grown by their wrapped column stay empty). The eye is inside the layer
// looking along +x, its rays crossing seven seams; fixed and adaptive steps.
TEST(MarchTiling, SkippingMovesNoSampleAcrossTheSeams) {
    TiledCopies c = MakeTiledCopies({32, 25, 10}, 1);
    const std::vector<float> narrow = test::GaussianBlobField(c.period, {{3.5, 22.5, 5, 0.8}});
    for (size_t v = 0; v < c.q.size(); ++v) c.q[v] = std::min(c.q[v] + narrow[v], 1.0f);
    for (bool adaptive : {false, true}) {
        MarchParams off = test::CameraParams(c.period, {6, 11, 5}, {40, 13, 5}, 24, 18);
        off.camera.farPlane = 200;
        off.skipping = false;
        off.setup.tiling = true;
        off.setup.invSize = {1.0f / 32, 1.0f / 25, 1.0f / 10};
        off.setup.adaptive = adaptive;
        off.setup.kappa = 0.02f;
        off.setup.adaptiveStart = 10;
        MarchParams on = off;
        on.skipping = true;
        on.brick = 5;
        const TilingImage a = RenderTilingCpu(off, c.period, c.q, c.T), b = RenderTilingCpu(on, c.period, c.q, c.T);
        ASSERT_EQ(a.rgb.size(), b.rgb.size());
        for (size_t i = 0; i < a.rgb.size(); ++i)
            ASSERT_EQ(a.rgb[i], b.rgb[i]) << "adaptive " << adaptive << " at " << i;
        EXPECT_GT(b.stats.bricksSkipped, 0u) << "adaptive " << adaptive;
        EXPECT_LT(b.stats.samples, a.stats.samples) << "adaptive " << adaptive;
        EXPECT_EQ(b.stats.lightSamples, a.stats.lightSamples) << "adaptive " << adaptive;
    }
}

// Test a homogeneous layer (q = 1, T = 1, phase none) from an eye a thousand
// periods away: looking straight down through it, the trilinear optical depth
// is sigma h (nz - 1/4) as over the box (q ramps from 1/2 to 1 in the half voxel
// at each face); looking level from inside it, sigma h D over the far plane's
// D = 50 voxel edges (six periods). C = (sun + ambient)(1 - T) + T background.
// Without tiling both rays miss the box and see the background.
TEST(MarchTiling, HomogeneousLayerFromAThousandPeriodsAway) {
    const Extent3 e{8, 8, 12};
    const std::vector<float> ones(e.Count(), 1.0f);
    struct View {
        const char* name;
        std::array<double, 3> eye, target;
        double depth;  // the optical depth per sigma h
    };
    for (const View& v : {View{"down", {-7996.5, 8003, 40}, {-7996.5, 8003, 0}, 12 - 0.25},
                          View{"level", {-7996.5, 8003, 6}, {0, 8003, 6}, 50}}) {
        MarchParams p = test::CameraParams(e, v.eye, v.target, 1, 1, 0.07f);
        p.camera.farPlane = 50;
        p.setup.light.phase.kind = PhaseKind::None;
        p.skipping = false;
        p.setup.tiling = true;
        p.setup.invSize = {1.0f / 8, 1.0f / 8, 1.0f / 12};
        const TilingImage im = RenderTilingCpu(p, e, ones, ones);
        ASSERT_EQ(im.rgb.size(), 3u) << v.name;
        const double T = std::exp(-0.07 * v.depth);
        const MarchSetup& s = p.setup;
        for (int ch = 0; ch < 3; ++ch) {
            const double expected =
                (double(s.light.sunRadiance[ch]) + s.light.ambient[ch]) * (1 - T) + T * s.background[ch];
            EXPECT_NEAR(im.rgb[ch], expected, 1e-4 * expected) << v.name << " channel " << ch;
        }
        p.setup.tiling = false;
        const TilingImage untiled = RenderTilingCpu(p, e, ones, ones);
        for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(untiled.rgb[ch], p.setup.background[ch]) << v.name;
    }
}

std::vector<float> RenderTilingReference(const MarchParams& p, const Extent3& e, const std::vector<float>& q) {
    ref::MarchReferenceOptions o;
    o.stepVoxels = 0.25f;
    o.threads = 2;
    auto r = ref::RenderMarchReference(p, e, q, q, o);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    return r ? r->image : std::vector<float>{};
}

// Test the reference's tiled exact light and view against the untiled
// reference of explicit copies: the two integrate the same field, in double,
// one piece per period crossed or over the copies' runs, so they agree to the
// float rounding of the samples' positions (the light depth is summed in
// another order).
TEST(MarchTiling, ReferenceEqualsTheUntiledReferenceOfCopies) {
    const TiledCopies c = MakeTiledCopies({12, 10, 8}, 7);
    TilingPair p = MakeTilingPair(c, MarchLightSource::Shade);
    p.tiled.camera = MakeCameraFrame(
        [] {
            CameraSettings cam;
            cam.eye = {6, 5, 14};
            cam.target = {14, 11, 0};
            cam.fovDeg = 50;
            cam.nearPlane = 0.01;
            cam.farPlane = 20;
            return cam;
        }(),
        12, 9);
    p.copies.camera = p.tiled.camera;
    const std::vector<float> tiled = RenderTilingReference(p.tiled, c.period, c.q);
    const std::vector<float> copies = RenderTilingReference(p.copies, c.big, c.qBig);
    ASSERT_EQ(tiled.size(), copies.size());
    EXPECT_LE(TilingWorstDifference(tiled, copies), 2e-5);
    p.tiled.setup.tiling = false;
    EXPECT_GT(TilingWorstDifference(RenderTilingReference(p.tiled, c.period, c.q), tiled), 0.01);
}

// Test the reference's exact light where it crosses many periods: a layer of
// constant q0 (24 voxels thick, a period of 8 x 6), seen level from its middle
// along (1, 1/2, 0) over D = 40 voxel edges, under a sun 10 degrees up toward
// (-0.6, 0.8): the light's path to the top runs 67 voxels across, through about
// 14 periods. Its depth is constant along the view: (11.5 + 3/8) q0 / s_z
// (constant q0 to the outer half voxel, then the shell's 3/8 q0), so
// C = S e^{-s c}(1 - e^{-a D}) + A (1 - e^{-a D}) + B e^{-a D}, a = sigma h q0,
// with no error from the step (MarchReferenceTest's constant-light case).
TEST(MarchTiling, ReferenceLightThroughManyPeriodsMatchesTheClosedForm) {
    const Extent3 e{8, 6, 24};
    const float q0 = 0.8f;
    const std::vector<float> q(e.Count(), q0);
    CameraSettings cam;
    cam.eye = {-3.25, 2.5, 12};
    cam.target = {-1.25, 3.5, 12};
    cam.fovDeg = 40;
    cam.nearPlane = 1e-4;
    cam.farPlane = 40;
    MarchParams p;
    p.camera = MakeCameraFrame(cam, 1, 1);
    MarchSetup& s = p.setup;
    s.size = {8, 6, 24};
    s.invSize = {1.0f / 8, 1.0f / 6, 1.0f / 24};
    s.tiling = true;
    s.voxelSize = s.light.voxelSize = 1;
    s.sigmaH = 0.1f;
    s.light.sunRadiance = {1.0f, 0.8f, 0.6f};
    s.light.ambient = {0.05f, 0.1f, 0.2f};
    s.background = {0.3f, 0.5f, 0.9f};
    s.light.phase.kind = PhaseKind::None;
    const double elevation = 10 * M_PI / 180;
    s.sun = {float(-0.6 * std::cos(elevation)), float(0.8 * std::cos(elevation)), float(std::sin(elevation))};
    p.alpha = 0.5f;
    const std::vector<float> image = RenderTilingReference(p, e, q);
    ASSERT_EQ(image.size(), 3u);
    const double a = double(s.sigmaH) * q0, D = 40;
    const double c = (11.5 + 0.375) * q0 / double(s.sun[2]);
    for (int ch = 0; ch < 3; ++ch) {
        const double expected = s.light.sunRadiance[ch] * std::exp(-double(s.sigmaH) * c) * (1 - std::exp(-a * D)) +
                                s.light.ambient[ch] * (1 - std::exp(-a * D)) + s.background[ch] * std::exp(-a * D);
        EXPECT_NEAR(image[ch], expected, 2e-5) << "channel " << ch;
    }
}

}  // namespace
}  // namespace cb
