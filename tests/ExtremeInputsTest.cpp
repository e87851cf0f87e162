// Extreme but valid inputs: huge ellipsoids in the CPU region and
// an extreme focal length in the splat renderer. Each case crashed, wrapped an
// integer or produced NaN before the fix; none relies on a sanitizer to fail.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>

#include "core/math/Camera.h"
#include "core/math/Splat.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/ShadePlan.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/RegionReference.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// The CPU region of `list` against brute force over every voxel.
void ExpectRegionEqualsBruteForce(const Extent3& e, const std::vector<RasterEllipsoid>& list) {
    const std::vector<uint8_t> expected = test::BruteForceRegion(e, list);
    cpu::BackendCpu backend(1);
    auto region = test::MakeBuffer(backend, BufferFormat::U8, e);
    ASSERT_TRUE(backend.Region(list, *region).has_value());
    const std::vector<uint8_t> got = test::Read<uint8_t>(backend, *region);
    for (size_t v = 0; v < got.size(); ++v) ASSERT_EQ(got[v], expected[v]) << "voxel " << v;
}

// Test ellipsoids of semi-axes 1e10 voxels (the scene `size_mean` 1e10, `margin`
// 3e10) on a tiny grid: a row span beyond 2^31 voxels on either side
// used to be narrowed to int32, wrap, and index the row buffer out of bounds
// (SIGSEGV); beyond 2^63 the double-to-int64 conversion overflowed.
TEST(ExtremeInputs, HugeEllipsoidsRegionEqualsBruteForce) {
    const Extent3 e{9, 7, 5};
    const float big = 1e10f;
    const std::vector<std::vector<RasterEllipsoid>> cases = {
        {{{3e10f, 3.5f, 2.5f}, {big, big, big}, 1, 0}},             // span starts past 2^31
        {{{-3e10f, 3.5f, 2.5f}, {big, big, big}, 1, 0}},            // span ends before -2^31
        {{{4.5f, 3.5f, 2.5f}, {big, big, big}, 1, 0}},              // covers the grid
        {{{3e10f, -2e10f, 2.5f}, {big, 2 * big, big}, 0.8f, 0.6f}},  // turned
        {{{1e20f, 3.5f, 2.5f}, {1e19f, 1e19f, 1e19f}, 1, 0}},        // past int64
        {{{-1e20f, 3.5f, 2.5f}, {1e19f, 1e19f, 1e19f}, 1, 0}},
        {{{3e10f, 3.5f, 2.5f}, {big, big, big}, 1, 0}, {{4.5f, 3.5f, 2.5f}, {4, 3, 2}, 1, 0}},
    };
    for (size_t n = 0; n < cases.size(); ++n) {
        SCOPED_TRACE("case " + std::to_string(n));
        ExpectRegionEqualsBruteForce(e, cases[n]);
    }
}

// A splat frame for a 64 x 48 image of the camera at (1, 1, 11) looking down -z.
SplatFrame FrameWithFocal(float focalPx) {
    CameraSettings camera;
    camera.eye = {1, 1, 11};
    camera.target = {1, 1, 0};
    camera.up = {0, 1, 0};
    const CameraFrame f = MakeCameraFrame(camera, 64, 48);
    SplatFrame F{};
    F.grid[0] = F.grid[1] = F.grid[2] = 8;
    F.width = 64, F.height = 48;
    for (int a = 0; a < 3; ++a) {
        F.eye[a] = f.eye[a];
        F.forward[a] = f.forward[a];
        F.right[a] = f.right[a];
        F.up[a] = f.upVector[a];
    }
    F.nearPlane = f.nearPlane;
    F.focalPx = focalPx;
    F.sun[2] = 1;
    F.light.sunRadiance = {1, 1, 1};
    F.light.phaseKind = uint32_t(PhaseKind::None);
    F.qMin = 0.3f;
    F.opacity = 0.6f;
    F.voxelSize = 0.25f;
    F.splatDiameter = 0.4f;
    return F;
}

// Test MakeSplat at extreme focal lengths (fov_deg 1e-300 gives an infinite
// one): every splat made has a finite centre and size and covers only pixels
// of the image. Before, an infinite centre converted to INT_MIN (x0 = INT_MIN,
// x1 = 63: x1 - x0 + 1 overflowed), and a centre on the axis was 0 * inf = NaN,
// which covered the whole image.
TEST(ExtremeInputs, MakeSplatCoversOnlyTheImageAtExtremeFocalLengths) {
    const float inf = std::numeric_limits<float>::infinity();
    CameraSettings tiny;
    tiny.fovDeg = 1e-300;
    EXPECT_EQ(MakeCameraFrame(tiny, 64, 48).focalPx, inf);  // what fov_deg 1e-300 feeds MakeSplat
    for (float focal : {inf, 1e30f, 1e12f, 3e9f}) {
        SCOPED_TRACE("focal " + std::to_string(focal));
        const SplatFrame F = FrameWithFocal(focal);
        for (uint32_t k = 0; k < 8; ++k)
            for (uint32_t j = 0; j < 8; ++j)
                for (uint32_t i = 0; i < 8; ++i) {
                    Splat s;
                    if (!MakeSplat(F, i, j, k, 0.9f, 1.0f, 1.0f, s)) continue;
                    ASSERT_TRUE(std::isfinite(s.px) && std::isfinite(s.py) && std::isfinite(s.size)) << i << j << k;
                    if (s.x0 <= s.x1) {
                        ASSERT_TRUE(s.x0 >= 0 && s.x1 < 64) << s.x0 << " " << s.x1;
                    }
                    if (s.y0 <= s.y1) {
                        ASSERT_TRUE(s.y0 >= 0 && s.y1 < 48) << s.y0 << " " << s.y1;
                    }
                }
    }
}

// Test the CPU splat renderer with fov_deg 1e-300 on a cloud of voxels, one of
// them on the view axis: the image stays finite, and no splat covers a pixel.
// Before, the axis voxel's NaN splat turned the whole image NaN.
TEST(ExtremeInputs, RenderSplatWithTinyFovIsFinite) {
    cpu::BackendCpu backend(0);
    const Extent3 e{3, 3, 3};
    const std::vector<float> q(e.Count(), 0.9f), T(e.Count(), 1.0f);
    auto qp = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto qc = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto t = test::MakeFilled(backend, BufferFormat::F32, e, T);
    const uint32_t width = 40, height = 30;
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, width, height});
    CameraSettings camera;
    camera.eye = {3, 3, 20};  // on the axis through the centre of voxel (1, 1, 1) of size 2
    camera.target = {3, 3, 0};
    camera.up = {0, 1, 0};
    camera.fovDeg = 1e-300;
    SplatParams p;
    p.voxelSize = 2;
    p.splatDiameter = 3;
    p.background = {0.1f, 0.2f, 0.3f};
    p.tile = 4;
    p.band = 4;
    p.culling = false;
    p.skipping = false;
    p.camera = MakeCameraFrame(camera, width, height);
    const SplatOrder order = MakeSplatOrder(p.camera, e, {0, 0, 0}, p.voxelSize);
    p.order = &order;
    SplatStats stats;
    const Status status = backend.RenderSplat(p, {qp.get(), qc.get(), t.get()}, *image, &stats);
    ASSERT_TRUE(status.has_value()) << status.error().message;
    const std::vector<float> rgb = test::Read<float>(backend, *image);
    for (size_t n = 0; n < rgb.size(); ++n) ASSERT_EQ(rgb[n], p.background[n % 3]) << "value " << n;
    EXPECT_LE(stats.splats, e.Count());
    EXPECT_EQ(stats.fragments, 0u);
}

// Test that the shade plan's taps into the previous slice are -1, 0 or 1 for any sun vector, NaN and inf
// components included, and are floor(s_u / |s_w|) (bilinear) for valid ones. A sun path from -1e308 to 1e308
// degrees (now refused at load) gave s = (NaN, NaN, 0.5): int(floor(NaN)) was INT_MIN, and the CPU's
// shade sized a scratch of 2^31 rows by it (std::bad_alloc at step 2).
TEST(ExtremeInputs, ShadePlanTapsWithinOneCellForAnySun) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const Extent3 e{16, 12, 8};
    for (const Vec3& sun : std::vector<Vec3>{{nan, nan, 0.5f},
                                             {nan, nan, nan},
                                             {inf, 0, 0},
                                             {-inf, inf, 1},
                                             {0, 0, 0},
                                             {1e-45f, -1e-45f, 0},
                                             {0.3f, -0.8f, nan}}) {
        for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest}) {
            ShadeParams p;
            p.sun = sun;
            p.filter = filter;
            const ShearWarp g = MakeShadePlan(p, e).geometry;
            EXPECT_TRUE(g.u0 >= -1 && g.u0 <= 1 && g.v0 >= -1 && g.v0 <= 1)
                << "sun (" << sun[0] << ", " << sun[1] << ", " << sun[2] << "): taps " << g.u0 << ", " << g.v0;
        }
    }
    // Valid directions keep their taps: the largest component is w, so |s_u / s_w| <= 1 and nothing is clamped.
    for (int el = -85; el <= 85; el += 17)
        for (int az = 0; az < 360; az += 13) {
            ShadeParams p;
            p.sun = SunDirection(el * 3.14159265358979 / 180, az * 3.14159265358979 / 180);
            const ShearWarp g = MakeShadePlan(p, e).geometry;
            EXPECT_EQ(g.u0, int(std::floor(p.sun[g.u] / std::fabs(p.sun[g.w])))) << el << " " << az;
            EXPECT_EQ(g.v0, int(std::floor(p.sun[g.v] / std::fabs(p.sun[g.w])))) << el << " " << az;
        }
}

// Test that the CPU shade with a NaN sun allocates within the grid's scale: under a soft RLIMIT_AS of its address
// space now plus 256 MiB (restored after) it returns; before, it threw std::bad_alloc for rows of 2^31 cells.
TEST(ExtremeInputs, CpuShadeWithNanSunStaysWithinTheGrid) {
    cpu::BackendCpu backend(1);
    const Extent3 e{32, 32, 8};
    auto q = test::MakeFilled(backend, BufferFormat::F32, e, std::vector<float>(e.Count(), 0.5f));
    auto T = test::MakeBuffer(backend, BufferFormat::F32, e);
    ShadeParams p;
    p.sun = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN(), 0.5f};
    std::ifstream status("/proc/self/status");
    uint64_t vmKb = 0;
    for (std::string line; std::getline(status, line);)
        if (line.starts_with("VmSize:")) vmKb = std::stoull(line.substr(7));
    rlimit old{};
    ASSERT_TRUE(vmKb > 0 && getrlimit(RLIMIT_AS, &old) == 0);
    rlimit tight = old;
    tight.rlim_cur = std::min<rlim_t>(old.rlim_cur, vmKb * 1024 + (rlim_t(256) << 20));
    ASSERT_EQ(setrlimit(RLIMIT_AS, &tight), 0);
    bool threw = false;
    Status s;
    try {
        s = backend.Shade(p, *q, *T);
    } catch (const std::bad_alloc&) {
        threw = true;
    }
    ASSERT_EQ(setrlimit(RLIMIT_AS, &old), 0);
    EXPECT_FALSE(threw) << "shade ran out of memory";
    EXPECT_TRUE(s.has_value()) << s.error().message;
}

}  // namespace
}  // namespace cb
