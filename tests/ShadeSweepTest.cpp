// The CPU's light attenuation sweep (SPEC 6) against a plain per-voxel sweep
// written separately: on several thread counts, in shares, and its schedule
// worked by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "core/math/Shading.h"
#include "core/pipeline/ShadePlan.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/ShadeSchedule.h"
#include "tests/ShadeTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// The sweep of SPEC 6 written plainly, one voxel at a time in slice order:
// T = 1 on the first slice; after it, T = store(bilinear T, factor(bilinear q))
// of the previous slice at (u + u0, v + v0), with T = 1 and q = 0 outside.
std::vector<float> PlainShadeSweep(const Extent3& e, const std::vector<float>& q, const ShadeParams& p) {
    const ShadePlan plan = MakeShadePlan(p, e);
    const ShearWarp& g = plan.geometry;
    std::vector<float> T(e.Count(), -1.0f);
    auto index = [&](int64_t a, int64_t b, uint32_t w) {
        uint32_t c[3];
        c[g.u] = uint32_t(a);
        c[g.v] = uint32_t(b);
        c[g.w] = w;
        return VoxelIndex(e, c[0], c[1], c[2]);
    };
    auto inside = [&](int64_t a, int64_t b) { return a >= 0 && b >= 0 && a < plan.nu && b < plan.nv; };
    for (uint32_t m = 0; m < plan.nw; ++m)
        for (int64_t b = 0; b < plan.nv; ++b)
            for (int64_t a = 0; a < plan.nu; ++a) {
                if (m == 0) {
                    T[index(a, b, plan.SliceW(0))] = 1.0f;
                    continue;
                }
                const uint32_t w = plan.SliceW(m - 1);
                auto t = [&](int64_t x, int64_t y) { return inside(x, y) ? T[index(x, y, w)] : 1.0f; };
                auto d = [&](int64_t x, int64_t y) { return inside(x, y) ? q[index(x, y, w)] : 0.0f; };
                const int64_t x = a + g.u0, y = b + g.v0;
                const float tt = Bilinear(t(x, y), t(x + 1, y), t(x, y + 1), t(x + 1, y + 1), g.fu, g.fv);
                const float qq = Bilinear(d(x, y), d(x + 1, y), d(x, y + 1), d(x + 1, y + 1), g.fu, g.fv);
                T[index(a, b, plan.SliceW(m))] = StoreTransmittance(p.storage, tt, plan.attenuation.Factor(qq));
            }
    return T;
}

// Test that the CPU's shade on 2, 5 and 16 threads (the slice plane in bands
// along v on 2 and 5, along u on 16, run as a pipeline of tiles) equals a
// plain per-voxel sweep written separately, bit for bit, on odd sizes: each
// principal axis, both sun signs, the 45 degree ties, both filters and every
// storage; and that the coarse resolutions do not depend on the thread count
// either. T starts as NaN, so a tile that read a cell of another band before
// that band wrote it would show here even on one core (the tiles' order
// comes from their dependencies, not from the cores).
TEST(Shade, ParallelSweepEqualsPlainSweep) {
    const Extent3 e{67, 53, 41};
    Pcg32 rng(16);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) ? float(rng.Below(65)) / 64.0f : 0.0f;
    const float d45 = std::numbers::pi_v<float> / 4;
    const std::vector<Vec3> suns = {SunDirection(0.3, 0.2),      SunDirection(0.3, 3.3),  // x, both signs
                                    SunDirection(-0.3, -0.2),  // x, the other sign of v0 (bands wait the other way)
                                    SunDirection(0.4, 1.4),      SunDirection(0.4, -1.7),  // y
                                    SunDirection(1.1, 0.5),      SunDirection(-1.2, 2.0),  // z
                                    SunDirection(d45, 0.0),      SunDirection(0.3, d45),
                                    test::Normalized(-0.3f, 0.9f, 0.4f)};
    int compared = 0;
    for (const Vec3& sun : suns)
        for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = sun;
                p.filter = filter;
                p.storage = storage;
                p.sigma = 0.004f;
                const std::vector<float> plain = PlainShadeSweep(e, q, p);
                for (int threads : {1, 2, 5, 16}) {
                    const std::vector<float> banded = test::ShadeOnCpu(e, q, p, threads, std::nanf(""));
                    ASSERT_EQ(banded, plain) << threads << " threads, sun " << sun[0] << " " << sun[1] << " " << sun[2];
                }
                // Light must reach the far side partly: else the test is blind.
                ASSERT_GT(std::count_if(plain.begin(), plain.end(), [](float t) { return t > 0 && t < 1; }), 1000);
                ++compared;
            }
    EXPECT_EQ(compared, 60);
    // Sweeps along x cut into chunks of rows (100 cells along y: on 2 threads 2
    // chunks of 64 and 36, on 5 and 16 threads 3 of 48, 48 and 4; 2 bands of 10
    // rows along z), both signs of u0 and v0, tiles of 15, 16 and 8 slices.
    const Extent3 wide{40, 100, 20};
    std::vector<float> qw(wide.Count());
    for (float& v : qw) v = rng.Below(3) ? float(rng.Below(65)) / 64.0f : 0.0f;
    // Azimuth +-0.55 rad with the nearest filter: du = +-0.61 rounds to u0 = +-1, so the taps reach two
    // cells beyond a chunk (the second with weight 0) or one before it.
    int comparedX = 0, reachTwo = 0;
    for (const Vec3& sun : {SunDirection(0.3, 0.2), SunDirection(0.3, 3.3), SunDirection(-0.3, -0.2), SunDirection(0.3, -0.2),
                            SunDirection(0.3, 0.55), SunDirection(0.3, -0.55)})
        for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = sun;
                p.filter = filter;
                p.storage = storage;
                p.sigma = 0.004f;
                const ShadePlan plan = MakeShadePlan(p, wide);
                ASSERT_EQ(plan.geometry.w, 0);
                reachTwo += plan.geometry.u0 == 1;
                const std::vector<float> plain = PlainShadeSweep(wide, qw, p);
                for (int threads : {1, 2, 5, 16})
                    ASSERT_EQ(test::ShadeOnCpu(wide, qw, p, threads, std::nanf("")), plain)
                        << threads << " threads, sun " << sun[0] << " " << sun[1] << " " << sun[2];
                ++comparedX;
            }
    EXPECT_EQ(comparedX, 24);
    EXPECT_EQ(reachTwo, 2);
    // The cut those runs took on 16 threads, so the chunks were exercised.
    ShadeParams px;
    px.sun = SunDirection(0.3, 0.2);
    const cpu::ShadeSchedule wide16 = cpu::MakeShadeSchedule(MakeShadePlan(px, wide), 16, 0, 40);
    EXPECT_EQ(wide16.bands, 2u);
    EXPECT_EQ(wide16.chunks, 3u);
    EXPECT_EQ(wide16.chunkCells, 48u);
    for (int f : {2, 4}) {
        ShadeParams p;
        p.sun = SunDirection(0.3, 0.2);
        p.resolution = f;
        p.sigma = 0.004f;
        EXPECT_EQ(test::ShadeOnCpu(e, q, p, 16, std::nanf("")), test::ShadeOnCpu(e, q, p, 1)) << f;
    }
}

// Test that the CPU's sweep in shares ([0, 5), [5, 17), [17, end): tiles
// that start mid-sweep read the slice an earlier share wrote) equals the plain
// sweep on every principal axis, both sun signs, on 1, 2 and 16 threads.
TEST(Shade, CpuSharesEqualPlainSweep) {
    const Extent3 e{37, 29, 23};
    Pcg32 rng(17);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) ? float(rng.Below(65)) / 64.0f : 0.0f;
    int compared = 0;
    for (const Vec3& sun : {SunDirection(0.3, 0.2), SunDirection(0.3, 3.3), SunDirection(0.4, 1.4),
                            SunDirection(0.4, -1.7), SunDirection(1.1, 0.5), SunDirection(-1.2, 2.0)})
        for (int threads : {1, 2, 16}) {
            ShadeParams p;
            p.sun = sun;
            p.sigma = 0.004f;
            cpu::BackendCpu backend(threads);
            auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
            auto T = test::MakeFilled(backend, BufferFormat::F32, e, std::vector<float>(e.Count(), std::nanf("")));
            for (SliceRange share : {SliceRange{0, 5}, SliceRange{5, 17}, SliceRange{17, UINT32_MAX}}) {
                p.slices = share;
                ASSERT_TRUE(backend.Shade(p, *qb, *T).has_value());
            }
            p.slices = {};
            ASSERT_EQ(test::Read<float>(backend, *T), PlainShadeSweep(e, q, p)) << threads << " threads, sun "
                                                                               << sun[0] << " " << sun[1];
            ++compared;
        }
    EXPECT_EQ(compared, 18);
}

// Test the CPU sweep's schedule on thesis-medium's grid (256 x 256 x 32) by
// hand. Sun at 25 degrees, azimuth 60: w = y, u = x (256), v = z (32), 256
// slices, taps at u0 = v0 = 0 (one band toward higher indices). On 2 threads
// v has 32 >= 4 * 2 rows: 2 bands of 16 rows, 4096 cells a slice, so 16384 /
// 4096 = 4 slices a tile; the longest chain is 1 fill tile plus all 256
// slices of one band: (4 + 256) * 4096 cells of 2^21. On 16 threads 32 < 64
// rows: 16 bands along u of 16 x 32 = 512 cells; 32 slices would fill 16384,
// but the fill (15 tiles) may take at most a quarter of the sweep, 256 / 60
// -> 4 slices; the chain is (15 * 4 + 256) * 512.
TEST(Shade, CpuScheduleByHand) {
    ShadeParams p;
    p.sun = SunDirection(25.0 * std::numbers::pi / 180.0, 60.0 * std::numbers::pi / 180.0);
    const ShadePlan plan = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(plan.geometry.w, 1);
    ASSERT_EQ(plan.geometry.u0, 0);
    ASSERT_EQ(plan.geometry.v0, 0);
    const cpu::ShadeSchedule one = cpu::MakeShadeSchedule(plan, 1, 0, 256);
    EXPECT_EQ(one.bands, 1u);
    EXPECT_EQ(one.span, one.work);
    const cpu::ShadeSchedule two = cpu::MakeShadeSchedule(plan, 2, 0, 256);
    EXPECT_EQ(two.axis, 1);
    EXPECT_EQ(two.bands, 2u);
    EXPECT_EQ(two.blockSlices, 4u);
    EXPECT_EQ(two.blocks, 64u);
    EXPECT_TRUE(two.towardHigher);
    EXPECT_EQ(two.work, 2097152.0);
    EXPECT_EQ(two.span, (4.0 + 256.0) * 4096.0);
    // 8 threads: 32 >= 4 * 8 rows, so 8 bands of 4 rows (1024 cells): 16 slices
    // would fill 16384, the fill (7 tiles) allows 256 / 28 -> 9.
    const cpu::ShadeSchedule eight = cpu::MakeShadeSchedule(plan, 8, 0, 256);
    EXPECT_EQ(eight.axis, 1);
    EXPECT_EQ(eight.bands, 8u);
    EXPECT_EQ(eight.blockSlices, 9u);
    EXPECT_EQ(eight.blocks, 29u);
    EXPECT_EQ(eight.span, (7.0 * 9.0 + 256.0) * 1024.0);
    const cpu::ShadeSchedule sixteen = cpu::MakeShadeSchedule(plan, 16, 0, 256);
    EXPECT_EQ(sixteen.axis, 0);
    EXPECT_EQ(sixteen.bands, 16u);
    EXPECT_EQ(sixteen.blockSlices, 4u);
    EXPECT_EQ(sixteen.span, (15.0 * 4.0 + 256.0) * 512.0);
    // A share of the sweep: slices [100, 140) on 2 threads, 40 slices, fill 1 tile of 4.
    const cpu::ShadeSchedule share = cpu::MakeShadeSchedule(plan, 2, 100, 140);
    EXPECT_EQ(share.blocks, 10u);
    EXPECT_EQ(share.span, (4.0 + 40.0) * 4096.0);
    // The sun at -x (azimuth 180 + 11 degrees, 17 high): s = (-0.94, -0.19,
    // 0.30), w = x, u = y, v = z, dv = 0.30 / 0.94 -> v0 = 0, du = -0.19 /
    // 0.94 -> u0 = -1. Rows along y are strided: tiles of 16 slices (a cache
    // line of floats along x), 4 bands of 8 rows, and the rows cut into chunks
    // until a block has 2 tiles a thread (at least 32 cells wide, whole lines):
    // ceil(2p / 4) chunks, so 1 on 1 and 2 threads, 2 of 128 cells on 4, 4 of 64
    // on 8, 8 of 32 on 16. The chain is 3 + (chunks - 1) fill tiles of 16
    // slices plus 256 slices, of 8 x (chunk) cells.
    p.sun = SunDirection(0.3, std::numbers::pi + 0.2);
    const ShadePlan west = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(west.geometry.w, 0);
    ASSERT_EQ(west.geometry.v0, 0);
    ASSERT_EQ(west.geometry.u0, -1);
    for (auto [threads, chunks] : {std::pair{1, 1}, {2, 1}, {4, 2}, {8, 4}, {16, 8}}) {
        const cpu::ShadeSchedule x = cpu::MakeShadeSchedule(west, threads, 0, 256);
        const uint32_t cells = 256 / chunks;
        EXPECT_EQ(x.axis, 1);
        EXPECT_EQ(x.bands, 4u) << threads;
        EXPECT_EQ(x.chunks, uint32_t(chunks)) << threads;
        EXPECT_EQ(x.chunkCells, cells) << threads;
        EXPECT_EQ(x.blockSlices, 16u);
        EXPECT_TRUE(x.towardHigher);
        EXPECT_FALSE(x.chunkTowardHigher);
        EXPECT_EQ(x.span, ((3.0 + chunks - 1) * 16.0 + 256.0) * 8.0 * cells) << threads;
    }
    // 16 threads: 2.1 M cells over a chain of 416 x 256: parallelism 19.7.
    EXPECT_NEAR(cpu::MakeShadeSchedule(west, 16, 0, 256).work / cpu::MakeShadeSchedule(west, 16, 0, 256).span,
                2097152.0 / (416.0 * 256.0), 1e-9);
    // Sun at azimuth -80 degrees, 60 high: s = (0.09, -0.49, 0.87), w = z,
    // v = y, dv = -0.49 / 0.87 -> v0 = -1: each band reads the band below.
    p.sun = SunDirection(60.0 * std::numbers::pi / 180.0, -80.0 * std::numbers::pi / 180.0);
    const ShadePlan south = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(south.geometry.w, 2);
    ASSERT_EQ(south.geometry.v0, -1);
    const cpu::ShadeSchedule z2 = cpu::MakeShadeSchedule(south, 2, 0, 32);
    EXPECT_EQ(z2.axis, 1);
    EXPECT_FALSE(z2.towardHigher);
}

}  // namespace
}  // namespace cb
