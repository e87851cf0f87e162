// The 90-degree rotation about z as a metamorphic invariant,
// on every backend. A scene turned by 90 degrees about z (the grid transposed
// to ny x nx, the sun, the wind shifts, the ellipsoids and the cameras turned
// with it) must give turned outputs: bit for bit for the integer stages, within
// SPEC's tolerance for the float ones, and the same image from a camera turned
// about the grid. Unlike a differential test, this sees a bug that every
// backend shares (core/, core/math) and one that swaps or mirrors an axis.
//
// The automaton is equivariant only where nothing is random: its draws are
// keyed by the voxel index v = i + nx (j + ny k), which the rotation changes
// (docs/pipeline.md, "The automaton is not rotation-equivariant"). So it runs
// with p in {0, 1} and R in {0, 255} from an injected, turned state.
//
// The mapping and the fixtures are in tests/MetamorphicRotation.h; shade,
// shadow and the renderers in tests/MetamorphicRotationImageTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/StageGraph.h"
#include "harness/report/Report.h"
#include "tests/BackendTestUtil.h"
#include "tests/MetamorphicRotation.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test the mapping on a 3 x 2 x 1 grid by hand: the rows [0 1 2] (j = 0) and
// [3 4 5] (j = 1) become, in the 2 x 3 grid, the columns x' = 1 and x' = 0
// read upward, so its rows are [3 0], [4 1], [5 2]; the voxel centres and the
// sun agree with it; four turns are none.
TEST(RotationMapping, HandWorked) {
    const Extent3 e{3, 2, 1};
    const std::vector<int> f = {0, 1, 2, 3, 4, 5};
    EXPECT_EQ(RotExtent(e), (Extent3{2, 3, 1}));
    EXPECT_EQ(RotRotate(e, f), (std::vector<int>{3, 0, 4, 1, 5, 2}));
    EXPECT_EQ(RotUnrotate(e, RotRotate(e, f)), f);
    EXPECT_EQ(RotIndex(e, 2, 0, 0), 5u);  // (2, 0) -> (1, 2)
    EXPECT_EQ(RotIndex(e, 0, 1, 0), 0u);  // (0, 1) -> (0, 0)
    // Four turns of a 3 x 2 x 2 field are none; two are the half turn (i, j) -> (nx-1-i, ny-1-j).
    const Extent3 a{3, 2, 2}, b = RotExtent(a);
    std::vector<int> g(12);
    for (int n = 0; n < 12; ++n) g[n] = n;
    const std::vector<int> half = RotRotate(b, RotRotate(a, g));
    EXPECT_EQ(RotRotate(b, RotRotate(a, half)), g);
    EXPECT_EQ(half, (std::vector<int>{5, 4, 3, 2, 1, 0, 11, 10, 9, 8, 7, 6}));
    // The centre of voxel (i, j) goes to the centre of voxel (ny-1-j, i): (2.5, 0.5) -> (1.5, 2.5) with h = 1.
    EXPECT_EQ(RotPoint(e, 1.0, {2.5, 0.5, 0.5}), (std::array<double, 3>{1.5, 2.5, 0.5}));
    EXPECT_EQ(RotPoint(e, 2.0, {5.0, 1.0, 1.0}), (std::array<double, 3>{3.0, 5.0, 1.0}));
    // A sun toward +x is toward +y after the turn, one toward +y toward -x.
    EXPECT_EQ(RotVec({1, 0, 0.5f}), (Vec3{0, 1, 0.5f}));
    EXPECT_EQ(RotVec({0, 1, 0}), (Vec3{-1, 0, 0}));
}

// ---- The automaton -----------------------------------------------------------

// Test that three automaton steps from a random state with deterministic
// events (q in {0, 2^24}, R in {0, 255}) and per-slice wind shifts give, from
// the turned state with the turned shifts (sx, sy) -> (-sy, sx), the turned
// state bit for bit.
TEST_P(RotationCa, DeterministicStepsTurnWithTheGrid) {
    Need(Stage::Ca);
    Backend& b = *mBackend;
    const Extent3 e{37, 21, 6}, er = RotExtent(e);
    const size_t n = e.Count();
    Pcg32 rng(90);
    std::vector<uint8_t> hum(n), act(n), cld(n), region(n);
    for (size_t v = 0; v < n; ++v) {
        hum[v] = rng.Below(100) < 45;
        act[v] = rng.Below(100) < 8;
        cld[v] = rng.Below(100) < 40;
        region[v] = rng.Below(5) == 0 ? 0 : 255;
    }
    constexpr uint32_t kOne = 1u << 24;  // Q(1)
    struct Qs {
        uint32_t ext, hum, act;
    };
    const Qs qs[3] = {{kOne, 0, kOne}, {0, kOne, 0}, {kOne, kOne, kOne}};
    std::unique_ptr<Buffer> plain[2][3], turned[2][3];
    for (int s = 0; s < 2; ++s)
        for (int f = 0; f < 3; ++f) {
            plain[s][f] = test::MakeBuffer(b, BufferFormat::Bits, e);
            turned[s][f] = test::MakeBuffer(b, BufferFormat::Bits, er);
        }
    const std::vector<uint8_t>* start[3] = {&hum, &act, &cld};
    for (int f = 0; f < 3; ++f) {
        ASSERT_TRUE(b.Upload(*plain[0][f], std::as_bytes(std::span(*start[f]))).has_value());
        const std::vector<uint8_t> r = RotRotate(e, *start[f]);
        ASSERT_TRUE(b.Upload(*turned[0][f], std::as_bytes(std::span(r))).has_value());
    }
    auto regionPlain = test::MakeFilled(b, BufferFormat::U8, e, region);
    auto regionTurned = test::MakeFilled(b, BufferFormat::U8, er, RotRotate(e, region));
    for (int t = 0; t < 3; ++t) {
        std::vector<int32_t> sx(e.nz), sy(e.nz), sxr(e.nz), syr(e.nz);
        for (uint32_t k = 0; k < e.nz; ++k) {
            sx[k] = int32_t(rng.Below(7)) - 3;
            sy[k] = int32_t(rng.Below(5)) - 2;
            sxr[k] = -sy[k];
            syr[k] = sx[k];
        }
        CaStepParams p;
        p.seed = 777;
        p.step = 10 + t;
        p.qExt = qs[t].ext;
        p.qHum = qs[t].hum;
        p.qAct = qs[t].act;
        p.shiftX = sx;
        p.shiftY = sy;
        const int in = t % 2, out = 1 - in;
        Status s = b.CaStep(p, {plain[in][0].get(), plain[in][1].get(), plain[in][2].get()}, *regionPlain,
                            {plain[out][0].get(), plain[out][1].get(), plain[out][2].get()});
        ASSERT_TRUE(s.has_value()) << s.error().message;
        p.shiftX = sxr;
        p.shiftY = syr;
        s = b.CaStep(p, {turned[in][0].get(), turned[in][1].get(), turned[in][2].get()}, *regionTurned,
                     {turned[out][0].get(), turned[out][1].get(), turned[out][2].get()});
        ASSERT_TRUE(s.has_value()) << s.error().message;
        const char* names[3] = {"hum", "act", "cld"};
        for (int f = 0; f < 3; ++f) {
            const std::vector<uint8_t> want = test::Read<uint8_t>(b, *plain[out][f]);
            const std::vector<uint8_t> got = RotUnrotate(e, test::Read<uint8_t>(b, *turned[out][f]));
            size_t differ = 0, set = 0;
            for (size_t v = 0; v < n; ++v) {
                differ += want[v] != got[v];
                set += want[v];
            }
            EXPECT_EQ(differ, 0u) << names[f] << " after step " << t + 1;
            EXPECT_GT(set, 0u) << names[f] << " after step " << t + 1 << " is empty: the case tests nothing";
        }
    }
}

// ---- Smooth, density and region: exact ---------------------------------------

// Test that smoothing a random cld at radius 0, 1 and 2 commutes with the turn, exactly.
TEST_P(Rotation, SmoothIsExact) {
    Need(Stage::Smooth);
    Backend& b = *mBackend;
    const Extent3 e{37, 21, 9}, er = RotExtent(e);
    Pcg32 rng(91);
    std::vector<uint8_t> cld(e.Count());
    for (uint8_t& c : cld) c = rng.Below(100) < 30;
    auto c0 = test::MakeFilled(b, BufferFormat::Bits, e, cld);
    auto c1 = test::MakeFilled(b, BufferFormat::Bits, er, RotRotate(e, cld));
    auto q0 = test::MakeBuffer(b, BufferFormat::F32, e);
    auto q1 = test::MakeBuffer(b, BufferFormat::F32, er);
    for (int r = 0; r <= 2; ++r) {
        ASSERT_TRUE(b.Smooth(r, *c0, *q0).has_value());
        ASSERT_TRUE(b.Smooth(r, *c1, *q1).has_value());
        EXPECT_EQ(RotUnrotate(e, test::Read<float>(b, *q1)), test::Read<float>(b, *q0)) << "radius " << r;
    }
}

struct RotDensity {
    std::vector<float> D;
    std::vector<uint8_t> tiles, bands;
    uint32_t covered = 0;
};

RotDensity RotRunDensity(Backend& b, const Extent3& e, const std::vector<float>& q, const std::vector<uint8_t>& cld,
                         uint32_t T, uint32_t B) {
    auto qb = test::MakeFilled(b, BufferFormat::F32, e, q);
    auto cb = cld.empty() ? nullptr : test::MakeFilled(b, BufferFormat::Bits, e, cld);  // empty: no automaton
    auto D = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
    auto tiles = test::MakeBuffer(b, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), 1});
    auto bands = test::MakeBuffer(b, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), CeilDiv(e.nz, B)});
    DensityOutputs out{D.get(), tiles.get(), bands.get(), 0};
    const Status s = b.Density({T, B, {}}, *qb, cb.get(), out);
    EXPECT_TRUE(s.has_value()) << s.error().message;
    return {test::Read<float>(b, *D), test::Read<uint8_t>(b, *tiles), test::Read<uint8_t>(b, *bands),
            out.coveredColumns};
}

// Test that D, the cover, and (with nx and ny multiples of the tile) the tile
// and band occupancy turn with the grid, exactly; on an odd grid D and the
// cover still do (its partial edge tiles change sides, so the tiles do not).
TEST_P(Rotation, DensityIsExact) {
    Need(Stage::Density);
    Backend& b = *mBackend;
    Pcg32 rng(92);
    for (const Extent3& e : {Extent3{24, 16, 9}, Extent3{37, 21, 9}}) {
        const bool whole = e.nx % 8 == 0 && e.ny % 8 == 0;
        std::vector<float> q(e.Count(), 0.0f);
        std::vector<uint8_t> cld(e.Count(), 0);
        // Sparse: a few blobs of cells, so that some tiles and bands stay empty.
        for (int blob = 0; blob < 4; ++blob) {
            const uint32_t ci = rng.Below(e.nx), cj = rng.Below(e.ny), ck = rng.Below(e.nz);
            for (int n = 0; n < 12; ++n) {
                const uint32_t i = std::min(e.nx - 1, ci + rng.Below(3)), j = std::min(e.ny - 1, cj + rng.Below(3)),
                               k = std::min(e.nz - 1, ck + rng.Below(2));
                q[VoxelIndex(e, i, j, k)] = float(1 + rng.Below(64)) / 64.0f;
                cld[VoxelIndex(e, i, j, k)] = rng.Below(2);
            }
        }
        for (bool withCld : {true, false}) {
            const std::vector<uint8_t> c = withCld ? cld : std::vector<uint8_t>{};
            const RotDensity plain = RotRunDensity(b, e, q, c, 8, 4);
            const RotDensity turned =
                RotRunDensity(b, RotExtent(e), RotRotate(e, q), withCld ? RotRotate(e, cld) : c, 8, 4);
            const std::string where =
                std::to_string(e.nx) + "x" + std::to_string(e.ny) + (withCld ? " cld" : " no cld");
            EXPECT_EQ(RotUnrotate({e.nx, e.ny, 1}, turned.D), plain.D) << where;
            EXPECT_EQ(turned.covered, plain.covered) << where;
            EXPECT_GT(plain.covered, 0u) << where;
            if (whole) {
                const Extent3 te{e.nx / 8, e.ny / 8, 1}, be{e.nx / 8, e.ny / 8, CeilDiv(e.nz, 4)};
                EXPECT_EQ(RotUnrotate(te, turned.tiles), plain.tiles) << where;
                EXPECT_EQ(RotUnrotate(be, turned.bands), plain.bands) << where;
                EXPECT_NE(std::count(plain.bands.begin(), plain.bands.end(), 0), 0) << where << ": every band full";
            }
        }
    }
}

// Ellipsoids turned with the grid: centre (x, y) -> (ny - y, x); the yaw +90
// degrees, as cos' = -sin, sin' = cos (exact) or recomputed from the angle.
RasterEllipsoid RotEllipsoid(const Extent3& e, const RasterEllipsoid& el, double yaw, bool recompute) {
    RasterEllipsoid r = el;
    r.center[0] = float(e.ny) - el.center[1];
    r.center[1] = el.center[0];
    if (recompute) {
        r.cosYaw = float(std::cos(yaw + std::numbers::pi / 2));
        r.sinYaw = float(std::sin(yaw + std::numbers::pi / 2));
    } else {
        r.cosYaw = -el.sinYaw;
        r.sinYaw = el.cosYaw;
    }
    return r;
}

std::vector<uint8_t> RotRunRegion(Backend& b, const Extent3& e, const std::vector<RasterEllipsoid>& list) {
    auto R = test::MakeBuffer(b, BufferFormat::U8, e);
    const Status s = b.Region(list, *R);
    EXPECT_TRUE(s.has_value()) << s.error().message;
    return test::Read<uint8_t>(b, *R);
}

// Test the region: round ellipsoids (a = b) at yaw 0, centres on quarter
// voxels, give the turned R exactly; any yaw and a != b within SPEC 2's rule
// (|dR| <= 1, at most 0.5 % of voxels differ), with the yaw turned exactly
// (cos' = -sin, sin' = cos) and recomputed from the angle.
TEST_P(Rotation, RegionExactForRoundEllipsoids) {
    Need(Stage::Region);
    Backend& b = *mBackend;
    const Extent3 e{37, 21, 9};
    Pcg32 rng(93);
    std::vector<RasterEllipsoid> round, roundTurned, any, anyExact, anyRecomputed;
    for (int n = 0; n < 12; ++n) {
        const float cx = float(rng.Below(4 * (e.nx + 8))) / 4 - 4, cy = float(rng.Below(4 * (e.ny + 8))) / 4 - 4,
                    cz = float(rng.Below(4 * e.nz)) / 4;
        const float a = float(4 + rng.Below(40)) / 4, c = float(4 + rng.Below(16)) / 4;
        round.push_back({{cx, cy, cz}, {a, a, c}, 1.0f, 0.0f});
        roundTurned.push_back(RotEllipsoid(e, round.back(), 0.0, false));
        const double yaw = rng.Uniform(0, 2 * std::numbers::pi);
        any.push_back({{cx, cy, cz}, {a, float(4 + rng.Below(40)) / 4, c}, float(std::cos(yaw)), float(std::sin(yaw))});
        anyExact.push_back(RotEllipsoid(e, any.back(), yaw, false));
        anyRecomputed.push_back(RotEllipsoid(e, any.back(), yaw, true));
    }
    const std::vector<uint8_t> plain = RotRunRegion(b, e, round);
    EXPECT_EQ(RotUnrotate(e, RotRunRegion(b, RotExtent(e), roundTurned)), plain);
    EXPECT_GT(std::count_if(plain.begin(), plain.end(), [](uint8_t r) { return r > 0; }), 100);
    const std::vector<uint8_t> anyPlain = RotRunRegion(b, e, any);
    for (bool recompute : {false, true}) {
        const std::vector<uint8_t> got =
            RotUnrotate(e, RotRunRegion(b, RotExtent(e), recompute ? anyRecomputed : anyExact));
        int worst = 0;
        size_t differ = 0;
        for (size_t v = 0; v < got.size(); ++v) {
            worst = std::max(worst, std::abs(int(got[v]) - int(anyPlain[v])));
            differ += got[v] != anyPlain[v];
        }
        EXPECT_LE(worst, 1) << (recompute ? "recomputed" : "exact") << " yaw";
        EXPECT_LE(double(differ), 0.005 * double(got.size())) << (recompute ? "recomputed" : "exact") << " yaw";
        std::printf("[ rotation ] %s region, yaw %s: max |dR| %d, %zu of %zu voxels differ\n", b.Name().c_str(),
                    recompute ? "recomputed" : "turned exactly", worst, differ, got.size());
    }
}

// The ellipsoid list's settings for a grid turned or not: no births, deaths or
// removals (the target is the count, lifetimes long, the bounds wide), no
// jitter, and a 3 x 2 wind grid of distinct, asymmetric vectors, turned as
// gx x gy -> gy x gx, cell (a, b) -> (gy-1-b, a), vector (wx, wy) -> (-wy, wx).
EllipsoidSettings RotListSettings(bool turned, uint32_t count) {
    EllipsoidSettings s;
    s.seed = 17;
    s.targetCount = count;
    s.lifetimeMean = 1000;
    s.lifetimeVariance = 0;
    s.shrinkSteps = 4;
    s.margin = 16;
    s.jitter = 0;
    const uint32_t gx = 3, gy = 2;
    const std::array<std::array<double, 2>, 6> grid = {
        {{0.50, 0.10}, {0.90, -0.30}, {-0.20, 0.70}, {0.30, 0.40}, {-0.60, -0.25}, {0.15, -0.80}}};
    if (!turned) {
        s.wind.gridNx = gx;
        s.wind.gridNy = gy;
        s.wind.grid.assign(grid.begin(), grid.end());
    } else {
        s.wind.gridNx = gy;
        s.wind.gridNy = gx;
        s.wind.grid.resize(6);
        for (uint32_t b = 0; b < gy; ++b)
            for (uint32_t a = 0; a < gx; ++a) {
                const auto& w = grid[a + gx * b];
                s.wind.grid[(gy - 1 - b) + gy * a] = {-w[1], w[0]};
            }
    }
    return s;
}

// Test the ellipsoid list update: an injected list and its turned copy (centre
// (x, y) -> (ny - y, x), yaw + 90 degrees) moved by the wind grid and its turned
// copy for 6 steps stay turned copies (to 1e-9 voxels, the bilinear weights f
// and 1 - f round differently), and their rasters give SPEC 2's region rule.
TEST_P(Rotation, EllipsoidListUpdateTurnsWithTheGrid) {
    Need(Stage::Region);
    Backend& b = *mBackend;
    const Extent3 e{37, 21, 9}, er = RotExtent(e);
    Pcg32 rng(94);
    std::vector<Ellipsoid> items, itemsTurned;
    for (int n = 0; n < 10; ++n) {
        Ellipsoid el{};
        el.center[0] = rng.Uniform(-4, e.nx + 4);
        el.center[1] = rng.Uniform(-4, e.ny + 4);
        el.center[2] = rng.Uniform(2, e.nz - 2);
        el.semiAxes[0] = rng.Uniform(2, 9);
        el.semiAxes[1] = rng.Uniform(2, 9);
        el.semiAxes[2] = rng.Uniform(1, 4);
        el.yaw = rng.Uniform(0, 2 * std::numbers::pi);
        el.lifetime = n < 3 ? 8 : 1000;  // three shrink over the last 4 of the 6 steps (and live)
        el.age = n < 3 ? 1 : rng.Below(100);
        items.push_back(el);
        Ellipsoid t = el;
        t.center[0] = e.ny - el.center[1];
        t.center[1] = el.center[0];
        t.yaw = el.yaw + std::numbers::pi / 2;
        itemsTurned.push_back(t);
    }
    EllipsoidList plain(RotListSettings(false, 10), e), turned(RotListSettings(true, 10), er);
    plain.Restore(items, plain.Rng());
    turned.Restore(itemsTurned, turned.Rng());
    for (int step = 1; step <= 6; ++step) {
        plain.Update();
        turned.Update();
        ASSERT_EQ(plain.Items().size(), 10u);
        ASSERT_EQ(turned.Items().size(), 10u);
        double moved = 0;
        for (size_t n = 0; n < 10; ++n) {
            const Ellipsoid &p = plain.Items()[n], &t = turned.Items()[n];
            EXPECT_NEAR(t.center[0], e.ny - p.center[1], 1e-9) << "ellipsoid " << n << " step " << step;
            EXPECT_NEAR(t.center[1], p.center[0], 1e-9) << "ellipsoid " << n << " step " << step;
            EXPECT_EQ(t.center[2], p.center[2]);
            EXPECT_EQ(t.age, p.age);
            EXPECT_EQ(t.yaw, p.yaw + std::numbers::pi / 2);
            moved += std::fabs(p.center[0] - items[n].center[0]) + std::fabs(p.center[1] - items[n].center[1]);
        }
        EXPECT_GT(moved, 0.5 * step) << "the wind moved nothing";
        const std::vector<uint8_t> R = RotRunRegion(b, e, plain.Raster());
        const std::vector<uint8_t> Rt = RotUnrotate(e, RotRunRegion(b, er, turned.Raster()));
        int worst = 0;
        size_t differ = 0;
        for (size_t v = 0; v < R.size(); ++v) {
            worst = std::max(worst, std::abs(int(R[v]) - int(Rt[v])));
            differ += R[v] != Rt[v];
        }
        EXPECT_LE(worst, 1) << "step " << step;
        EXPECT_LE(double(differ), 0.005 * double(R.size())) << "step " << step;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, Rotation, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const auto& info) { return std::string(info.param); });
INSTANTIATE_TEST_SUITE_P(Backends, RotationCa, ::testing::ValuesIn(cb::test::TestBackendsAndCaLayouts()),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace cb
