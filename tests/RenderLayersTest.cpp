// Stage render_layers (SPEC 15) on every backend: closed forms (an empty sky is
// the background bit for bit; a homogeneous layer is the slab's transmittance
// at several elevations, seen from below, from inside looking up and down, and
// from above), an independent front-to-back march that samples at the ray's
// crossings of the layer planes (SPEC 15's last rule) with its own wrapped
// trilinear sampler, and the GPU backends against the CPU by SPEC 8's image
// rule with the same counters, for the eye below, inside and above the layer,
// tiled and not, each phase function, other layer counts and l_max.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "core/math/Layers.h"
#include "core/math/Shading.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/stages/render_layers/RenderLayers.h"
#include "core/stages/shade/Shade.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/RenderLayersTestUtil.h"
#include "tests/TestUtil.h"

namespace cb::test {
namespace {

// Test that an empty sky leaves the background bit for bit on every backend, with every crossing counted and none
// drawn: alpha 0 blends nothing.
TEST_P(RenderLayersAll, EmptySkyIsTheBackgroundBitForBit) {
    const Extent3 e{9, 7, 5};
    for (bool tiling : {false, true})
        for (const auto& eye : Eyes(e)) {
            LayersCase c;
            c.grid = e;
            c.qPrev.assign(e.Count(), 0.0f);
            c.qCur = c.qPrev;
            c.T.assign(e.Count(), 0.5f);
            c.params = CameraLayers(e, eye, {0.5 * e.nx, 0.5 * e.ny, 0.5 * e.nz}, 33, 21, 5, tiling);
            const LayersImage im = RenderLayersOn(*mBackend, c);
            ASSERT_TRUE(im.ok);
            const Vec3& bg = c.params.setup.background;
            for (size_t p = 0; p < im.rgb.size() / 3; ++p)
                for (int ch = 0; ch < 3; ++ch)
                    ASSERT_EQ(std::bit_cast<uint32_t>(im.rgb[3 * p + ch]), std::bit_cast<uint32_t>(bg[ch])) << p;
            EXPECT_GT(im.stats.fragments, 0u);
            EXPECT_EQ(im.stats.drawn, 0u);
        }
}

// Test the closed form of a homogeneous layer (q = 1, T = 1, tiled so every crossing is inside): a layer at height z
// reads the trilinear q(z) = min(1, z + 1/2, nz + 1/2 - z) (outside the grid q = 0; below 1 only on the outer
// half-voxels, which more than nz layers reach), so a ray's transmittance is exp(-sigma h spacing sum q(z_i) / |d_z|)
// over the layers it crosses (l uncapped), and the pixel is ambient + sun P^ times (1 - that) plus the background
// times it. Seen from below, from above, and from inside
// looking up (the layers above) and down (those below), at pixels of several elevations.
TEST_P(RenderLayersAll, HomogeneousLayerIsTheSlabsClosedForm) {
    const Extent3 e{8, 8, 6};
    struct View {
        std::array<double, 3> eye, target;
    };
    const View views[] = {
        {{4, 4, -20}, {4.5, 9, 0}},   // below, looking up
        {{4, 4, 30}, {4.2, 10, 6}},   // above, looking down
        {{4, 4, 2.3}, {4, 9, 6.5}},   // inside, looking up
        {{4, 4, 4.1}, {4, 9, -0.5}},  // inside, looking down
    };
    for (uint32_t count : {6u, 3u, 12u})
        for (const View& v : views) {
            LayersCase c = UniformLayers(e, 1.0f);
            c.params = CameraLayers(e, v.eye, v.target, 40, 30, count, true);
            LayersSetup& s = c.params.setup;
            s.maxLength = 1e30f;  // uncapped: the closed form holds at every elevation
            const LayersImage im = RenderLayersOn(*mBackend, c);
            ASSERT_TRUE(im.ok);
            double worst = 0;
            for (uint32_t y = 0; y < 30; ++y)
                for (uint32_t x = 0; x < 40; ++x) {
                    const LayersRay ray = MakeLayersRay(c.params.camera, 1.0f, x, y);
                    const double dz = ray.dir[2];
                    double depth = 0;
                    for (uint32_t i = 0; i < count; ++i) {
                        const double z = (i + 0.5) * double(e.nz) / count;
                        if ((z - s.eye[2]) / dz > 0) depth += std::min({1.0, z + 0.5, e.nz + 0.5 - z});
                    }
                    const double transmittance =
                        std::exp(-double(s.sigmaH) * depth * double(s.spacing) / std::fabs(dz));
                    const double phase = PhaseValue(s.light.phase, MarchDot(s.sun, ray.dir));
                    for (int ch = 0; ch < 3; ++ch) {
                        const double lit = double(s.light.sunRadiance[ch]) * phase + s.light.ambient[ch];
                        const double want = lit * (1 - transmittance) + s.background[ch] * transmittance;
                        const double got = im.rgb[3 * (x + 40 * y) + ch];
                        worst = std::max(worst, std::fabs(got - want) / std::max(1.0, want));
                    }
                }
            // float rounding of N blends and N exps: measured below 1e-6 on every backend.
            EXPECT_LT(worst, 1e-5) << "count " << count << " eye z " << v.eye[2];
        }
}

// Test LayersFade by hand: extent 100 (outer2 10^4) and fade 0.2, so the inner radius is 80 and fadeInv2 =
// 1 / (10^4 - 6400) = 1 / 3600. w = (10^4 - r^2) / 3600, the fade w^2 (3 - 2 w): 1 at r <= 80; at r^2 = 8200,
// w = 1/2 and 1/4 * 2 = 1/2; at r = 90, w = 19/36 and (361/1296)(70/36) = 25270/46656; 0 at r = 100 and beyond.
TEST(LayersFade, SmoothFalloffFromTheInnerRadiusToTheExtent) {
    const float outer2 = 10000.0f, inv = 1.0f / 3600.0f;
    EXPECT_EQ(LayersFade(0.0f, outer2, inv), 1.0f);
    EXPECT_EQ(LayersFade(6400.0f, outer2, inv), 1.0f);  // the fade's start
    EXPECT_NEAR(LayersFade(8200.0f, outer2, inv), 0.5f, 1e-6f);
    EXPECT_NEAR(LayersFade(8100.0f, outer2, inv), 25270.0f / 46656.0f, 1e-6f);
    EXPECT_EQ(LayersFade(10000.0f, outer2, inv), 0.0f);  // the extent
    EXPECT_EQ(LayersFade(12100.0f, outer2, inv), 0.0f);  // beyond
    // Its slope vanishes at both ends (no kink): a step of 1 in r^2 changes it by O(1 / 3600^2).
    EXPECT_GT(LayersFade(6401.0f, outer2, inv), 1.0f - 1e-6f);
    EXPECT_LT(LayersFade(9999.0f, outer2, inv), 1e-6f);
    // Monotone across the band.
    float last = 1.0f;
    for (float r2 = 6400.0f; r2 <= 10000.0f; r2 += 7.0f) {
        const float f = LayersFade(r2, outer2, inv);
        EXPECT_LE(f, last) << r2;
        last = f;
    }
    // fadeInv2 0: no falloff, a hard cut left to the caller's extent test.
    EXPECT_EQ(LayersFade(9999.0f, outer2, 0.0f), 1.0f);
    EXPECT_EQ(LayersFade(20000.0f, outer2, 0.0f), 1.0f);
}

// Test the falloff in the image on every backend: one homogeneous tiled layer (q = 1, T = 1) at z = 3 seen from
// below, extent 60 and fade 0.5 (inner radius 30). A pixel whose ray meets the plane at horizontal distance r has
// alpha = (1 - exp(-sigma h 6 / |d_z|)) s(w), s(w) = w^2 (3 - 2 w), w = clamp((60^2 - r^2) / (60^2 - 30^2), 0, 1),
// worked in double; beyond 60 the pixel is the background bit for bit.
TEST_P(RenderLayersAll, OpacityFadesOutTowardTheExtent) {
    const Extent3 e{8, 8, 6};
    LayersCase c = UniformLayers(e, 1.0f);
    c.params = CameraLayers(e, {4, 4, -20}, {4, 50, 3}, 48, 36, 1, true);
    LayersSetup& s = c.params.setup;
    s.maxLength = 1e30f;
    s.outer2 = 3600.0f;
    s.fadeInv2 = float(1.0 / (3600.0 - 900.0));
    const LayersImage im = RenderLayersOn(*mBackend, c);
    ASSERT_TRUE(im.ok);
    double worst = 0;
    uint32_t inBand = 0, beyond = 0;
    for (uint32_t y = 0; y < 36; ++y)
        for (uint32_t x = 0; x < 48; ++x) {
            const LayersRay ray = MakeLayersRay(c.params.camera, 1.0f, x, y);
            const double dz = ray.dir[2], t = (3.0 - s.eye[2]) / dz;
            const double r = std::hypot(ray.dir[0] * t, ray.dir[1] * t);
            if (!(dz > 0) || r > 60.001) {
                ++beyond;
                for (int ch = 0; ch < 3; ++ch)
                    ASSERT_EQ(im.rgb[3 * (x + 48 * y) + ch], s.background[ch]) << x << ", " << y;
                continue;
            }
            if (r > 59.999) continue;  // the float test at the extent may fall either way
            const double w = std::clamp((3600.0 - r * r) / 2700.0, 0.0, 1.0);
            inBand += w > 0.05 && w < 0.95 ? 1 : 0;
            const double alpha = (1 - std::exp(-double(s.sigmaH) * 6.0 / dz)) * w * w * (3 - 2 * w);
            const double phase = PhaseValue(s.light.phase, MarchDot(s.sun, ray.dir));
            for (int ch = 0; ch < 3; ++ch) {
                const double lit = double(s.light.sunRadiance[ch]) * phase + s.light.ambient[ch];
                const double want = lit * alpha + s.background[ch] * (1 - alpha);
                worst = std::max(worst, std::fabs(im.rgb[3 * (x + 48 * y) + ch] - want) / std::max(1.0, want));
            }
        }
    EXPECT_LT(worst, 1e-5);
    EXPECT_GT(inBand, 100u);  // the band is well sampled
    EXPECT_GT(beyond, 50u);   // and so is the sky beyond it
}

// Test the wang opacity (Wang, Ji and Zhang's eq. 16) on every backend, by hand: q = 0.8 and T = 1 everywhere, untiled,
// coverage 0.7 and density 1.5, and a map that is 0 on the columns x < 6 and 1 on the others. A layer crossed over
// the first columns has alpha = min(1.5 max(0.8 - (0 + 1 - 0.7), 0), 1) = 1 - 1/4 (= 0.75 within float), over the
// others 1.5 max(0.8 - 1.3, 0) = 0; so a pixel whose crossings all lie at 0.5 < x < 5.5 and 0.5 < y < 7.5 (where the
// bilinear map is 0 and the trilinear q is 0.8 q_z, q_z = min(1, z + 1/2, nz + 1/2 - z) of the layer's height) is
// lit (1 - K) + background K, K the product of (1 - alpha(0.8 q_z)) over its crossings, and one whose crossings
// all lie at x > 6.5 is the background bit for bit (it blends alpha 0). Seen from above and below, with 6 and 12
// layers (12 puts the outer layers on the grid's half-voxel rim, where q_z < 1).
TEST_P(RenderLayersAll, WangOpacityIsEq16OfQAndTheMap) {
    const Extent3 e{12, 8, 6};
    std::vector<float> map(size_t(e.nx) * e.ny);
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) map[i + e.nx * j] = i < 6 ? 0.0f : 1.0f;
    const std::array<double, 3> eyes[] = {{6, 4, 40}, {6, 4, -34}};
    for (uint32_t count : {6u, 12u})
        for (const auto& eye : eyes) {
            LayersCase c = UniformLayers(e, 0.8f);
            c.params = CameraLayers(e, eye, {6, 4, 3}, 48, 32, count, false);
            LayersSetup& s = c.params.setup;
            s.wang = true;
            s.coverage = 0.7f;
            s.density = 1.5f;
            s.map = map.data();
            const LayersImage im = RenderLayersOn(*mBackend, c);
            ASSERT_TRUE(im.ok);
            uint32_t lit = 0, clear = 0;
            double worst = 0;
            for (uint32_t y = 0; y < 32; ++y)
                for (uint32_t x = 0; x < 48; ++x) {
                    const LayersRay ray = MakeLayersRay(c.params.camera, 1.0f, x, y);
                    double lo = 1e30, hi = -1e30, keep = 1;
                    bool rim = false;
                    int k = 0;
                    for (uint32_t i = 0; i < count; ++i) {
                        const double z = (i + 0.5) * double(e.nz) / count, t = (z - s.eye[2]) / ray.dir[2];
                        const double px = s.eye[0] + ray.dir[0] * t, py = s.eye[1] + ray.dir[1] * t;
                        if (!(t > 0) || px < 0 || px > e.nx || py < 0 || py > e.ny) continue;
                        lo = std::min(lo, px), hi = std::max(hi, px), ++k;
                        rim = rim || px < 0.5 || py < 0.5 || py > e.ny - 0.5;
                        const double q = 0.8 * std::min({1.0, z + 0.5, e.nz + 0.5 - z});
                        keep *= 1 - std::min(1.5 * std::max(q - 0.3, 0.0), 1.0);
                    }
                    const float* got = &im.rgb[3 * (x + 48 * y)];
                    if (k > 0 && lo > 6.5) {
                        ++clear;
                        for (int ch = 0; ch < 3; ++ch)
                            ASSERT_EQ(std::bit_cast<uint32_t>(got[ch]), std::bit_cast<uint32_t>(s.background[ch]));
                    } else if (k > 0 && hi < 5.5 && !rim) {
                        ++lit;
                        const double phase = PhaseValue(s.light.phase, MarchDot(s.sun, ray.dir));
                        for (int ch = 0; ch < 3; ++ch) {
                            const double want = (s.light.sunRadiance[ch] * phase + s.light.ambient[ch]) * (1 - keep) +
                                                s.background[ch] * keep;
                            worst = std::max(worst, std::fabs(got[ch] - want) / std::max(1.0, want));
                        }
                    }
                }
            EXPECT_GT(lit, 20u) << "count " << count << " eye z " << eye[2];
            EXPECT_GT(clear, 20u) << "count " << count << " eye z " << eye[2];
            EXPECT_LT(worst, 1e-5) << "count " << count << " eye z " << eye[2];  // float rounding of k blends
        }
}

// Test relighting's factor on every backend: T with lightScale 1/2 gives the image of T/2 (exact in float) with
// lightScale 1, bit for bit, for the eye below, inside and above.
TEST_P(RenderLayersAll, LightScaleScalesTBitForBit) {
    const Extent3 e{11, 9, 6};
    for (const auto& eye : Eyes(e)) {
        LayersCase scaled = BlobLayers(e);
        scaled.params = CameraLayers(e, eye, {0.5 * e.nx, 0.6 * e.ny, 0.5 * e.nz}, 31, 23, 6, true);
        LayersCase halved = scaled;
        scaled.params.setup.lightScale = 0.5f;
        for (float& t : halved.T) t *= 0.5f;
        const LayersImage a = RenderLayersOn(*mBackend, scaled), b = RenderLayersOn(*mBackend, halved);
        ASSERT_TRUE(a.ok && b.ok);
        EXPECT_GT(a.stats.drawn, 0u);
        for (size_t i = 0; i < a.rgb.size(); ++i)
            ASSERT_EQ(std::bit_cast<uint32_t>(a.rgb[i]), std::bit_cast<uint32_t>(b.rgb[i])) << "eye z " << eye[2];
    }
}

// Test what relighting asks of the host: shade lights toward the first step's sun at every step, so the loop
// shades once, and each frame scales T by max(0, s0 . s); without it shade follows the sun and the factor is 1.
TEST(RenderLayersRelight, ShadesOnceAndScalesByTheSunsCosine) {
    const std::string path = std::string(CLOUDBENCH_SCENES_DIR) + "/layers-small.json";
    const std::vector<SceneOverride> moving = {{"steps", "6"},
                                               {"sun.speed", R"({"azimuth_deg": 20, "elevation_deg": -4})"}};
    std::vector<SceneOverride> relit = moving;
    relit.push_back({"layers.relight", R"("vector")"});
    Result<Scene> plain = LoadScene(path, moving), vector = LoadScene(path, relit);
    ASSERT_TRUE(plain && vector) << (plain ? vector.error().message : plain.error().message);
    const Vec3 s0 = vector->sun.DirectionAt(0);
    for (uint32_t step : {0u, 3u, 5u}) {
        const Vec3 s = vector->sun.DirectionAt(step);
        EXPECT_EQ(ShadeSunAt(*vector, step), s0) << step;
        EXPECT_EQ(MakeShadeParams(*vector, step).sun, s0) << step;
        EXPECT_EQ(ShadeSunAt(*plain, step), s) << step;
        const float cosine = s0[0] * s[0] + s0[1] * s[1] + s0[2] * s[2];
        EXPECT_NEAR(MakeLayersParams(*vector, vector->render.cameras[0], step).setup.lightScale, cosine, 1e-6f);
        EXPECT_EQ(MakeLayersParams(*vector, vector->render.cameras[0], step).setup.sun, s) << step;
        EXPECT_EQ(MakeLayersParams(*plain, plain->render.cameras[0], step).setup.lightScale, 1.0f) << step;
    }
    EXPECT_LT(MakeLayersParams(*vector, vector->render.cameras[0], 5).setup.lightScale, 0.9f);  // the sun moved
}

// Test Wang, Ji and Zhang's wind (eq. 18) on every backend: with tiling, a drift of whole voxels (3, -2) gives the
// image of the volume rolled by those voxels without drift, to float rounding of the shifted coordinates.
TEST_P(RenderLayersAll, WindDriftIsTheVolumeRolledDownwind) {
    const Extent3 e{12, 10, 6};
    for (const auto& eye : Eyes(e)) {
        LayersCase drifted = BlobLayers(e);
        drifted.params = CameraLayers(e, eye, {0.5 * e.nx, 0.6 * e.ny, 0.5 * e.nz}, 40, 30, 6, true);
        drifted.params.setup.drift = {3.0f, -2.0f};
        LayersCase rolled = drifted;
        rolled.params.setup.drift = {0.0f, 0.0f};
        auto roll = [&](const std::vector<float>& v) {
            std::vector<float> out(v.size());
            for (uint32_t k = 0; k < e.nz; ++k)
                for (uint32_t j = 0; j < e.ny; ++j)
                    for (uint32_t i = 0; i < e.nx; ++i)
                        out[(i + 3) % e.nx + e.nx * ((j + e.ny - 2) % e.ny + size_t(e.ny) * k)] =
                            v[i + e.nx * (j + size_t(e.ny) * k)];
            return out;
        };
        rolled.qPrev = roll(drifted.qPrev), rolled.qCur = roll(drifted.qCur), rolled.T = roll(drifted.T);
        const LayersImage a = RenderLayersOn(*mBackend, drifted), b = RenderLayersOn(*mBackend, rolled);
        ASSERT_TRUE(a.ok && b.ok);
        double worst = 0;
        for (size_t i = 0; i < a.rgb.size(); ++i) worst = std::max(worst, double(std::fabs(a.rgb[i] - b.rgb[i])));
        EXPECT_LT(worst, 1e-5) << "eye z " << eye[2];
        EXPECT_EQ(a.stats.drawn, b.stats.drawn);
        EXPECT_GT(a.stats.drawn, 0u);
    }
}

// The independent path of SPEC 15's last rule: a front-to-back march over the ray's crossings of the layer
// planes, t_i = (z_i - z_eye) / d_z with segment l = min(spacing / |d_z|, l_max), L += T_view (1 - tau) c,
// T_view *= tau, sampled by TrilinearSample of core/math/March.h with the taps wrapped by the test itself.
Vec3 LayerPlaneMarch(const LayersCase& c, uint32_t x, uint32_t y) {
    const LayersSetup& s = c.params.setup;
    const Extent3 e = c.grid;
    std::vector<float> qa(e.Count());
    for (size_t v = 0; v < qa.size(); ++v) qa[v] = Lerp(c.qPrev[v], c.qCur[v], c.params.alpha);
    const LayersRay ray = MakeLayersRay(c.params.camera, s.voxelSize, x, y);
    // The wrapped sample: the periodic extension of the grid, built explicitly three tiles wide.
    const Extent3 big{3 * e.nx, 3 * e.ny, e.nz};
    std::vector<float> qBig(big.Count()), tBig(big.Count());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < big.ny; ++j)
            for (uint32_t i = 0; i < big.nx; ++i) {
                const size_t src = (i % e.nx) + e.nx * ((j % e.ny) + size_t(e.ny) * k);
                const size_t dst = i + big.nx * (j + size_t(big.ny) * k);
                const bool home = i / e.nx == 1 && j / e.ny == 1;
                qBig[dst] = s.tiling || home ? qa[src] : 0.0f;
                tBig[dst] = s.tiling || home ? c.T[src] : 1.0f;
            }
    const double phase = PhaseValue(s.light.phase, MarchDot(s.sun, ray.dir));
    std::vector<std::pair<double, uint32_t>> crossings;
    for (uint32_t i = 0; i < s.count; ++i) {
        const double z = (i + 0.5) * double(e.nz) / s.count;
        const double t = (z - s.eye[2]) / ray.dir[2];
        if (t > 0 && t >= ray.tNear && t <= ray.tFar) crossings.push_back({t, i});
    }
    std::sort(crossings.begin(), crossings.end());
    double L[3] = {0, 0, 0}, Tv = 1;
    for (const auto& [t, i] : crossings) {
        double px = s.eye[0] + ray.dir[0] * t - s.drift[0], py = s.eye[1] + ray.dir[1] * t - s.drift[1];
        if (!s.tiling && (px < 0 || px > e.nx || py < 0 || py > e.ny)) continue;
        if (s.tiling) {
            px -= e.nx * std::floor(px / e.nx);
            py -= e.ny * std::floor(py / e.ny);
        }
        const Vec3 p{float(px + e.nx), float(py + e.ny), float((i + 0.5) * double(e.nz) / s.count)};
        const double q = TrilinearSample(qBig.data(), big, 0.0f, p);
        if (!(q > 0)) continue;
        const double T = TrilinearSample(tBig.data(), big, 1.0f, p);
        const double len = std::min(double(s.spacing) / std::fabs(ray.dir[2]), double(s.maxLength));
        const double tau = std::exp(-double(s.sigmaH) * q * len);
        for (int ch = 0; ch < 3; ++ch)
            L[ch] += Tv * (1 - tau) * (s.light.sunRadiance[ch] * T * phase + s.light.ambient[ch]);
        Tv *= tau;
    }
    return {float(L[0] + Tv * s.background[0]), float(L[1] + Tv * s.background[1]), float(L[2] + Tv * s.background[2])};
}

// Test that the CPU backend's image equals the layer-plane march within SPEC 10's 1e-4, for the eye below, inside
// and above, tiled and not, one layer per voxel and others, l_max capping grazing rays.
TEST(RenderLayersCpu, EqualsAMarchAtTheLayerPlanes) {
    const Extent3 e{12, 10, 6};
    cpu::BackendCpu cpu(2);
    for (bool tiling : {false, true})
        for (uint32_t count : {6u, 3u, 12u})
            for (const auto& eye : Eyes(e)) {
                LayersCase c = BlobLayers(e);
                c.params = CameraLayers(e, eye, {0.5 * e.nx, 0.6 * e.ny, 0.5 * e.nz}, 48, 36, count, tiling);
                c.params.setup.maxLength = 3.0f;
                if (count == 3) c.params.setup.drift = {2.3f, -1.7f};
                const LayersImage im = RenderLayersOn(cpu, c);
                ASSERT_TRUE(im.ok);
                double worst = 0;
                for (uint32_t y = 0; y < 36; ++y)
                    for (uint32_t x = 0; x < 48; ++x) {
                        const Vec3 want = LayerPlaneMarch(c, x, y);
                        for (int ch = 0; ch < 3; ++ch)
                            worst = std::max(worst, double(std::fabs(im.rgb[3 * (x + 48 * y) + ch] - want[ch])));
                    }
                EXPECT_LT(worst, 1e-4) << "tiling " << tiling << " count " << count << " eye z " << eye[2];
                EXPECT_GT(im.stats.drawn, 0u);
            }
}

// Test that each GPU backend's image matches the CPU's by SPEC 8's image rule (and lies within 1e-4 of it
// everywhere, measured), with the same counters, over the eye below, inside and above, tiling, layer counts, l_max,
// every phase function, q_prev != q_cur and the fade toward the extent.

TEST_P(RenderLayersGpu, MatchesTheCpu) {
    ASSERT_TRUE(mBackend->Supports(Stage::RenderLayers));
    cpu::BackendCpu cpu(2);
    const Extent3 e{13, 11, 7};
    const PhaseParams phases[] = {{PhaseKind::HenyeyGreenstein, 0.6f},
                                  {PhaseKind::None, 0.0f},
                                  {PhaseKind::CornetteShanks, 0.8f},
                                  {PhaseKind::Mie, 0.0f}};
    int n = 0;
    for (bool tiling : {false, true})
        for (uint32_t count : {7u, 4u, 15u})
            for (const auto& eye : Eyes(e)) {
                LayersCase c = BlobLayers(e);
                c.params = CameraLayers(e, eye, {0.5 * e.nx, 0.6 * e.ny, 0.5 * e.nz}, 37, 29, count, tiling);
                c.params.setup.light.phase = phases[n++ % 4];
                if (count == 4) c.params.setup.maxLength = 2.5f;
                if (count == 15) c.params.setup.drift = {1.37f, -0.61f};
                if (tiling) {  // an extent of 20 voxel edges, faded over its outer half: 1 / (400 - 100)
                    c.params.setup.outer2 = 400.0f;
                    c.params.setup.fadeInv2 = 1.0f / 300.0f;
                }
                // The wang opacity with a map that varies per column, in every third case.
                std::vector<float> map(size_t(e.nx) * e.ny);
                for (size_t i = 0; i < map.size(); ++i) map[i] = float((i * 2654435761u) % 997) / 2000.0f;
                if (n % 3 == 0) {
                    c.params.setup.wang = true;
                    c.params.setup.coverage = 0.9f;
                    c.params.setup.density = 3.0f;
                    c.params.setup.map = map.data();
                }
                const LayersImage want = RenderLayersOn(cpu, c);
                const LayersImage got = RenderLayersOn(*mBackend, c);
                ASSERT_TRUE(want.ok && got.ok);
                double worst = 0;
                for (size_t i = 0; i < want.rgb.size(); ++i)
                    worst = std::max(worst, double(std::fabs(want.rgb[i] - got.rgb[i])));
                EXPECT_LT(worst, 1e-4) << "tiling " << tiling << " count " << count << " eye z " << eye[2];
                EXPECT_EQ(got.stats.fragments, want.stats.fragments);
                EXPECT_EQ(got.stats.drawn, want.stats.drawn);
                EXPECT_GT(want.stats.drawn, 0u);
            }
}

INSTANTIATE_TEST_SUITE_P(Backends, RenderLayersAll, ::testing::ValuesIn(test::TestBackends()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Backends, RenderLayersGpu, ::testing::ValuesIn(test::GpuTestBackends()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cb::test
