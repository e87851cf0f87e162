// Vulkan shade in blocks of slices (impl_vk/shaders/shade_block.comp):
// T must be byte for byte the per-slice reference path's (shade_slice.comp, one
// dispatch per slice, BackendVk::ShadeSweep::PerSlice) at every
// principal axis and sign, fractional and whole taps (45-degree ties: a tap
// offset of +1 or -1 with weight 0), nearest taps, odd grids that are not
// multiples of the 32-cell tile and sweeps longer than a 16-slice block,
// every storage, both attenuations, resolutions 1, 2 and 4, and in shares; and
// shade_sky, the same sweep with coarse grids of its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/math/Random.h"
#include "core/pipeline/ShadePlan.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"

namespace cb {
namespace {

// q with holes and a dense blob, so that T falls far below 1 (fp16 and unorm8 rounding matter).
std::vector<float> ShadeBlockQ(const Extent3& e, uint32_t seed) {
    Pcg32 rng(seed);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? 0.0f : float(1 + rng.Below(256)) / 256.0f;
    return q;
}

Vec3 Unit(float x, float y, float z) {
    const float n = std::sqrt(x * x + y * y + z * z);
    return {x / n, y / n, z / n};
}

class ShadeBlockVk : public ::testing::Test {
  protected:
    void SetUp() override {
        auto backend = test::MakeTestBackend("vk");
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
    }
    vk::BackendVk& Vk() { return static_cast<vk::BackendVk&>(*mBackend); }
    void TearDown() override {
        if (mBackend) test::ExpectNoValidationMessages(mBackend.get());
    }

    // T from `shares` calls (an empty list: one whole call) on the block path or the per-slice path.
    std::vector<float> RunShade(const ShadeParams& p, const Buffer& q, Buffer& T, bool perSlice,
                                const std::vector<SliceRange>& shares = {}) {
        Vk().SetShadeSweep(perSlice ? vk::BackendVk::ShadeSweep::PerSlice : vk::BackendVk::ShadeSweep::Blocks);
        std::vector<float> minusOne(T.Extent().Count(), -1.0f);  // a value shade never writes
        EXPECT_TRUE(mBackend->Upload(T, std::as_bytes(std::span(minusOne))));
        std::vector<SliceRange> calls = shares.empty() ? std::vector<SliceRange>{SliceRange{}} : shares;
        for (SliceRange s : calls) {
            ShadeParams share = p;
            share.slices = s;
            Status status = mBackend->Shade(share, q, T);
            EXPECT_TRUE(status.has_value()) << (status ? "" : status.error().message);
        }
        Vk().SetShadeSweep(vk::BackendVk::ShadeSweep::Auto);
        return test::Read<float>(*mBackend, T);
    }

    // Expects the block path's T byte-identical to the per-slice path's; returns false on a difference.
    bool ExpectSame(const std::string& what, const ShadeParams& p, const Buffer& q, Buffer& T,
                    const std::vector<SliceRange>& shares = {}) {
        const auto reference = RunShade(p, q, T, true);
        const auto got = RunShade(p, q, T, false, shares);
        size_t differ = 0, first = got.size();
        for (size_t n = 0; n < got.size(); ++n)
            if (std::memcmp(&got[n], &reference[n], 4) != 0) {
                if (differ++ == 0) first = n;
            }
        EXPECT_EQ(differ, 0u) << what << ": " << differ << " of " << got.size() << " differ, first at " << first << ": "
                              << (first < got.size() ? got[first] : 0) << " against "
                              << (first < got.size() ? reference[first] : 0);
        // The test must see the sweep do something: some T well below 1, none left unwritten.
        size_t dark = 0, unwritten = 0;
        for (float t : reference) {
            dark += t < 0.5f;
            unwritten += t < 0.0f;
        }
        EXPECT_GT(dark, 0u) << what;
        EXPECT_EQ(unwritten, 0u) << what;
        return differ == 0;
    }

    std::unique_ptr<Backend> mBackend;
};

// Suns: each principal axis, both signs, above and below; fractional taps; ties
// (du = +1 or -1 exactly: tap offset +1 or -1, weight 0).
const Vec3 kShadeBlockSuns[] = {
    Unit(0.3f, 0.2f, 0.93f),  Unit(-0.3f, 0.45f, -0.9f), Unit(0.9f, 0.35f, -0.25f), Unit(-0.9f, -0.6f, 0.25f),
    Unit(0.3f, 0.9f, 0.1f),   Unit(0.2f, -0.9f, -0.7f),  Unit(1.0f, 0.5f, 1.0f),    Unit(1.0f, -1.0f, 0.4f),
    Unit(-1.0f, 1.0f, -1.0f), Unit(0.0f, 0.0f, 1.0f),
};

std::string SunName(const Vec3& s) {
    return "sun (" + std::to_string(s[0]) + ", " + std::to_string(s[1]) + ", " + std::to_string(s[2]) + ")";
}

TEST_F(ShadeBlockVk, SameAsPerSliceAtEverySunStorageAndAttenuation) {
    // Two tiles by two along most planes, sweeps of 45 to 70 slices (several blocks).
    const Extent3 grid{70, 45, 37};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 3));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    for (const Vec3& sun : kShadeBlockSuns)
        for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8})
            for (bool thesis : {false, true}) {
                ShadeParams p;
                p.sun = sun, p.storage = storage;
                p.attenuation = thesis ? AttenuationKind::Thesis : AttenuationKind::Beer;
                p.scattering = thesis;
                p.sigma = 0.004f;
                const std::string what =
                    SunName(sun) + " storage " + std::to_string(int(storage)) + (thesis ? " thesis" : " beer");
                if (!ExpectSame(what, p, *q, *T)) return;
            }
}

// The dispatches of a whole sweep of nw = 40 slices (w = x; a 40 x 24 x 6 grid,
// f = 1): one per slice per slice; in blocks, the first dispatch computes slices
// 0 .. 16 from slice 0's T = 1 and each further one 16 more, so 1 + ceil((40 -
// 17) / 16) = 3. On a CPU device (lavapipe) Auto is per slice.
TEST_F(ShadeBlockVk, BlocksCutTheDispatchesAndAutoFollowsTheDevice) {
    const Extent3 grid{40, 24, 6};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 3));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    ShadeParams p;
    p.sun = Unit(0.9f, 0.35f, 0.25f);
    ASSERT_EQ(MakeShadePlan(p, grid).nw, 40u);
    auto dispatches = [&](vk::BackendVk::ShadeSweep sweep) {
        Vk().SetShadeSweep(sweep);
        const uint64_t before = Vk().Dispatches();
        EXPECT_TRUE(mBackend->Shade(p, *q, *T).has_value());
        return Vk().Dispatches() - before;
    };
    EXPECT_EQ(dispatches(vk::BackendVk::ShadeSweep::PerSlice), 40u);
    EXPECT_EQ(dispatches(vk::BackendVk::ShadeSweep::Blocks), 3u);
    const auto devices = vk::ListDevices();
    ASSERT_TRUE(devices.has_value());
    if (devices->front().type == "cpu") {
        EXPECT_EQ(dispatches(vk::BackendVk::ShadeSweep::Auto), 40u);
    }
    Vk().SetShadeSweep(vk::BackendVk::ShadeSweep::Auto);
}

TEST_F(ShadeBlockVk, SameAsPerSliceWithNearestTaps) {
    const Extent3 grid{41, 67, 23};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 4));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    for (const Vec3& sun : kShadeBlockSuns) {
        ShadeParams p;
        p.sun = sun, p.filter = SampleFilter::Nearest, p.storage = StorageFormat::Fp16, p.sigma = 0.004f;
        if (!ExpectSame(SunName(sun) + " nearest", p, *q, *T)) return;
    }
}

TEST_F(ShadeBlockVk, SameAsPerSliceAtCoarseResolutions) {
    const Extent3 grid{77, 53, 29};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 5));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    for (int f : {2, 4})
        for (const Vec3& sun : {kShadeBlockSuns[0], kShadeBlockSuns[3], kShadeBlockSuns[5], kShadeBlockSuns[7]})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = sun, p.resolution = f, p.storage = storage, p.sigma = 0.01f;
                const std::string what =
                    SunName(sun) + " f " + std::to_string(f) + " storage " + std::to_string(int(storage));
                if (!ExpectSame(what, p, *q, *T)) return;
            }
}

TEST_F(ShadeBlockVk, SharesOfTheSweepSameAsPerSlice) {
    // Shares that start inside a block, at slice 0, of one slice, and longer than a block.
    const Extent3 grid{70, 45, 37};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 6));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    for (int f : {1, 2})
        for (const Vec3& sun : {kShadeBlockSuns[2], kShadeBlockSuns[8]}) {
            ShadeParams p;
            p.sun = sun, p.resolution = f, p.storage = StorageFormat::Fp16, p.sigma = 0.004f;
            const uint32_t nw = MakeShadePlan(p, grid).nw;
            ASSERT_GT(nw, 8u);
            const uint32_t split = std::min(29u, nw - 2);
            const std::vector<SliceRange> shares = {{0, 1}, {1, 5}, {5, 6}, {6, split}, {split, nw}};
            if (!ExpectSame(SunName(sun) + " f " + std::to_string(f) + " in shares", p, *q, *T, shares)) return;
        }
}

// shade_sky (BackendVk::ShadeSky) is shade's sweep with coarse grids of its own: between two shares of the sun's
// sweep at f = 2 or 4, alone or with the three calls in one batch (one command buffer), on either path, the
// sun's T is byte for byte its whole sweep's and T_sky the sky's sweep alone, which is shade's toward the sky.
TEST_F(ShadeBlockVk, SkyShadeBetweenSharesLeavesTheSunsSweepAsItWas) {
    const Extent3 grid{70, 45, 37};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 8));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    auto skyT = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    auto expectBytes = [](const std::vector<float>& got, const std::vector<float>& want, const std::string& what) {
        ASSERT_EQ(got.size(), want.size()) << what;
        EXPECT_EQ(std::memcmp(got.data(), want.data(), got.size() * 4), 0) << what;
    };
    for (int f : {2, 4})
        for (bool perSlice : {false, true})
            for (bool batched : {false, true}) {
                Vk().SetShadeSweep(perSlice ? vk::BackendVk::ShadeSweep::PerSlice : vk::BackendVk::ShadeSweep::Blocks);
                ShadeParams sun;
                sun.sun = kShadeBlockSuns[2], sun.resolution = f, sun.storage = StorageFormat::Fp16, sun.sigma = 0.004f;
                ShadeParams sky = sun;
                sky.sun = kShadeBlockSuns[5];  // another sweep axis and direction
                const std::string what =
                    "f " + std::to_string(f) + (perSlice ? " per slice" : " blocks") + (batched ? " batched" : "");
                ASSERT_TRUE(mBackend->Shade(sun, *q, *T).has_value());
                const std::vector<float> wholeT = test::Read<float>(*mBackend, *T);
                ASSERT_TRUE(mBackend->ShadeSky(sky, *q, *skyT).has_value());
                const std::vector<float> aloneSkyT = test::Read<float>(*mBackend, *skyT);
                ASSERT_TRUE(mBackend->Shade(sky, *q, *T).has_value());
                expectBytes(test::Read<float>(*mBackend, *T), aloneSkyT, what + ": T_sky is shade's toward the sky");

                const std::vector<float> minusOne(grid.Count(), -1.0f);  // a value shade never writes
                ASSERT_TRUE(mBackend->Upload(*T, std::as_bytes(std::span(minusOne))));
                ASSERT_TRUE(mBackend->Upload(*skyT, std::as_bytes(std::span(minusOne))));
                const uint32_t nw = MakeShadePlan(sun, grid).nw, split = nw / 2;
                ASSERT_GT(split, 0u);
                if (batched) {
                    ASSERT_TRUE(mBackend->BeginBatch().has_value());
                }
                ShadeParams first = sun, second = sun;
                first.slices = {0, split};
                second.slices = {split, nw};
                ASSERT_TRUE(mBackend->Shade(first, *q, *T).has_value());
                ASSERT_TRUE(mBackend->ShadeSky(sky, *q, *skyT).has_value());
                ASSERT_TRUE(mBackend->Shade(second, *q, *T).has_value());
                if (batched) {
                    ASSERT_TRUE(mBackend->EndBatch().has_value());
                }
                expectBytes(test::Read<float>(*mBackend, *T), wholeT, what + ": the sun's T");
                expectBytes(test::Read<float>(*mBackend, *skyT), aloneSkyT, what + ": T_sky");
            }
    Vk().SetShadeSweep(vk::BackendVk::ShadeSweep::Auto);
}

// Not a test: times both paths on thesis-medium's grid and sun (256 x 256 x 32,
// 25 degrees high, azimuth 60: 256 slices of 256 x 32), interleaved, and prints
// medians and quartiles of wall and device ms. Run with
// --gtest_also_run_disabled_tests --gtest_filter=ShadeBlockVk.DISABLED_Bench
// (SHADE_BENCH_ELEVATION=degrees for another sun).
TEST_F(ShadeBlockVk, DISABLED_Bench) {
    auto made = CreateBackend("vk", BackendOptions{});  // without the validation layer, which costs per dispatch
    ASSERT_TRUE(made.has_value());
    mBackend = std::move(*made);
    const Extent3 grid{256, 256, 32};
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, grid, ShadeBlockQ(grid, 7));
    auto T = test::MakeBuffer(*mBackend, BufferFormat::F32, grid);
    ShadeParams p;
    const char* elevation = std::getenv("SHADE_BENCH_ELEVATION");  // degrees; e.g. 70: z principal, 32 slices
    p.sun = SunDirection((elevation ? std::atof(elevation) : 25) * 3.14159265358979 / 180, 60 * 3.14159265358979 / 180);
    std::vector<double> wall[2], device[2];
    for (int round = 0; round < 12; ++round)
        for (int perSlice : {0, 1}) {
            Vk().SetShadeSweep(perSlice ? vk::BackendVk::ShadeSweep::PerSlice : vk::BackendVk::ShadeSweep::Blocks);
            const auto start = std::chrono::steady_clock::now();
            ASSERT_TRUE(mBackend->Shade(p, *q, *T).has_value());
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            if (round < 2) continue;  // warm-up: pipelines, scratch
            wall[perSlice].push_back(ms);
            device[perSlice].push_back(mBackend->LastDeviceMs().value_or(-1));
        }
    auto quartiles = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const size_t n = v.size();
        return std::to_string(v[n / 2]) + " [" + std::to_string(v[n / 4]) + "-" + std::to_string(v[3 * n / 4]) + "]";
    };
    for (int perSlice : {0, 1})
        std::printf("%s: wall %s ms, device %s ms\n", perSlice ? "per slice" : "blocks",
                    quartiles(wall[perSlice]).c_str(), quartiles(device[perSlice]).c_str());
}

}  // namespace
}  // namespace cb
#endif
