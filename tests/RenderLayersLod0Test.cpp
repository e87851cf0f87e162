// The layered renderer's billboards near the eye (LOD0; SPEC 15, docs/pipeline.md "The billboards"): eq. 13's sizes
// as read, the grid points within r0 of the eye, the layers starting at r0, one billboard fragment by hand, a field
// of billboards against its closed form back to front on every backend, and the GPU backends against the CPU with
// billboards on. The fixtures and cases are tests/RenderLayersTestUtil.h's (the tests live in its namespace).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/math/Layers.h"
#include "core/math/Shading.h"
#include "core/stages/render_layers/RenderLayers.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/BackendTestUtil.h"
#include "tests/RenderLayersTestUtil.h"
#include "tests/TestUtil.h"

namespace cb::test {
namespace {

// ---- Billboards (LOD0) ----

// Test LOD0's constants against eq. 13 as docs/pipeline.md reads it, worked by hand: W_p = p_s, H_p = max(dz, p_s)
// (dz the layers' spacing), a fragment's path min(p_s, dz), inner2 = r0^2.
TEST(LayersLod0, SizesAreEq13AsRead) {
    LayersSetup s;
    s.spacing = 0.5f;  // two layers per voxel
    SetLayersLod0(s, 3.0, 2.0);
    EXPECT_EQ(s.inner2, 9.0f);
    EXPECT_EQ(s.billboardSpacing, 2.0f);
    EXPECT_EQ(s.halfWidth, 1.0f);        // W_p = 2
    EXPECT_EQ(s.halfHeight, 1.0f);       // H_p = max(0.5, 2) = 2
    EXPECT_EQ(s.billboardLength, 0.5f);  // min(2, 0.5)
    s.spacing = 3.0f;                    // one layer per three voxels, or N = 1 over nz = 3
    SetLayersLod0(s, 0.25, 1.0);
    EXPECT_EQ(s.inner2, 0.0625f);
    EXPECT_EQ(s.halfWidth, 0.5f);        // W_p = 1
    EXPECT_EQ(s.halfHeight, 1.5f);       // H_p = max(3, 1) = 3
    EXPECT_EQ(s.billboardLength, 1.0f);  // min(1, 3)
    SetLayersLod0(s, 0.0, 1.0);          // LOD0 off
    EXPECT_EQ(s.inner2, 0.0f);
}

// Test the grid of LOD0 by hand: p_s = 1 and the eye over (0.5, 0.5), so the grid points are the eye's column plus
// integer offsets (a, b); with r0 = 3 those with a^2 + b^2 <= 9 are in, 29 a layer (7 + 2 * 5 + 2 * 5 + 2),
// (3.5, 0.5) exactly at r0 among them; with r0 = 2.99 the four at distance 3 are out (25). Every centre lies on a
// layer's plane at ((a + 1/2), (b + 1/2)); looking up from below every billboard is in front, in decreasing depth
// (z_i - z_eye here), so the top layer's come first. Looking along +x from inside, those behind the eye are left out.
TEST(LayersLod0, GridPointsWithinR0OfTheEye) {
    LayersSetup s;
    s.eye = {0.5f, 0.5f, -2.0f};
    s.count = 3;
    s.spacing = 2.0f;  // layers at z = 1, 3, 5
    SetLayersLod0(s, 3.0, 1.0);
    const std::vector<LayersBillboard> up = MakeLayersBillboards(s, {0, 0, 1});
    ASSERT_EQ(up.size(), 3u * 29u);
    for (size_t n = 0; n < up.size(); ++n) {
        const LayersBillboard& b = up[n];
        const float z = n < 29 ? 5.0f : n < 58 ? 3.0f : 1.0f;
        EXPECT_EQ(b.centre[2], z) << n;
        EXPECT_EQ(b.depth, z + 2.0f) << n;
        const double a = b.centre[0] - 0.5, c = b.centre[1] - 0.5;
        EXPECT_EQ(a, std::round(a));
        EXPECT_EQ(c, std::round(c));
        EXPECT_LE(a * a + c * c, 9.0);
    }
    const auto has = [&](const std::vector<LayersBillboard>& v, float x, float y) {
        return std::ranges::any_of(v, [&](const LayersBillboard& b) { return b.centre[0] == x && b.centre[1] == y; });
    };
    EXPECT_TRUE(has(up, 3.5f, 0.5f));   // exactly at r0: in
    EXPECT_TRUE(has(up, 0.5f, -2.5f));  // exactly at r0: in
    EXPECT_FALSE(has(up, 3.5f, 1.5f));  // sqrt(10) > 3: out
    SetLayersLod0(s, 2.99, 1.0);
    const std::vector<LayersBillboard> smaller = MakeLayersBillboards(s, {0, 0, 1});
    EXPECT_EQ(smaller.size(), 3u * 25u);
    EXPECT_FALSE(has(smaller, 3.5f, 0.5f));
    // From inside (eye at z = 3.5), looking along +x: depth = x - 0.5, so only the columns a >= 1 are in front.
    SetLayersLod0(s, 3.0, 1.0);
    s.eye = {0.5f, 0.5f, 3.5f};
    const std::vector<LayersBillboard> ahead = MakeLayersBillboards(s, {1, 0, 0});
    EXPECT_EQ(ahead.size(), 3u * (5u + 5u + 1u));  // a = 1: |b| <= 2; a = 2: |b| <= 2; a = 3: b = 0
    for (size_t n = 1; n < ahead.size(); ++n) EXPECT_GE(ahead[n - 1].depth, ahead[n].depth);
    EXPECT_EQ(ahead.front().depth, 3.0f);
    EXPECT_EQ(ahead.back().depth, 1.0f);
    SetLayersLod0(s, 0.0, 1.0);
    EXPECT_TRUE(MakeLayersBillboards(s, {0, 0, 1}).empty());  // r0 = 0: none
    // An eye 1e20 cells from the origin (past 2^52, where no float tells the cells apart): none, and no overflow.
    SetLayersLod0(s, 3.0, 1.0);
    s.eye = {1e20f, 0.5f, -2.0f};
    EXPECT_TRUE(MakeLayersBillboards(s, {0, 0, 1}).empty());
    s.eye = {0.5f, 0.5f, -2.0f};
    EXPECT_EQ(MakeLayersBillboards(s, {0, 0, 1}).size(), 3u * 29u);  // and back at the origin, all of them
}

// Test that LOD0 cuts the layers to an annulus: a layer fragment whose crossing lies within r0 of the eye
// horizontally is not a fragment; at r0 and beyond it is, as before.
TEST(LayersLod0, LayersStartAtR0) {
    const Extent3 e{8, 8, 4};
    LayersCase c = UniformLayers(e, 1.0f);
    c.params = CameraLayers(e, {4, 4, -10}, {4, 4.1, 4}, 16, 16, 4, true);
    LayersSetup& s = c.params.setup;
    auto fetch = [](uint32_t) { return std::array<float, 2>{1.0f, 1.0f}; };
    uint32_t inside = 0, outside = 0;
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = 0; x < 16; ++x) {
            const LayersRay ray = MakeLayersRay(c.params.camera, 1.0f, x, y);
            const float t = (LayerHeight(s, 3) - s.eye[2]) / ray.dir[2];
            const double r = std::hypot(double(ray.dir[0] * t), double(ray.dir[1] * t));
            if (std::fabs(r - 2.0) < 1e-3) continue;  // the float test at r0 may fall either way
            SetLayersLod0(s, 0.0, 1.0);
            EXPECT_TRUE(LayerFragment(s, ray, SunPhases{{1.0f}}, 3, fetch).crossed);
            SetLayersLod0(s, 2.0, 1.0);
            EXPECT_EQ(LayerFragment(s, ray, SunPhases{{1.0f}}, 3, fetch).crossed, r > 2.0) << x << ", " << y;
            (r > 2.0 ? outside : inside) += 1;
        }
    EXPECT_GT(inside, 10u);
    EXPECT_GT(outside, 10u);
}

// A billboard field for the closed forms: grid 8 x 8 x 4 untiled, one layer (N = 1: dz = nz = 4, at z = 2), the
// eye on that plane (so no layer is crossed), looking along +y and a little to the side; p_s = 1 and r0 = 2.5, so
// W_p = 1, H_p = max(4, 1) = 4 (the billboards span z in [0, 4]) and the path is min(1, 4) / cos(ray, forward).
// q = 1 and T varies along y: T = 0.2 + 0.1 j on row j, so billboards at different depths differ in colour.
LayersCase BillboardField() {
    const Extent3 e{8, 8, 4};
    LayersCase c = UniformLayers(e, 1.0f);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) c.T[i + e.nx * (j + size_t(e.ny) * k)] = 0.2f + 0.1f * float(j);
    c.params = CameraLayers(e, {4.3, 1.2, 2.0}, {4.6, 9.0, 2.0}, 64, 48, 1, false);
    SetLayersLod0(c.params.setup, 2.5, 1.0);
    return c;
}

// The closed form of BillboardField at pixel (x, y), worked in double from the geometry alone: every grid point
// ((a + 1/2), (b + 1/2), 2) within 2.5 of the eye horizontally and in front is a quad perpendicular to forward,
// 1 wide along right and 4 high along up; the ray meets it at t = depth / (d . forward). A hit counts where |u| <= 1/2,
// |v| <= 2, the point lies within 2.5 of the eye horizontally and 0 <= z <= 4; its q is min(1, z + 1/2, 4.5 - z)
// (trilinear, the box's border empty above and below) and T = 0.2 + 0.1 (y - 1/2) (linear in y between the row
// centres); alpha = 1 - exp(-sigma h q / (d . forward)). Blended farthest first over the background. `ambiguous`
// is set where a hit lies within 1e-3 of an edge (u, v, r0, the box), where float and double may disagree;
// `hits` counts them; `reversed` blends nearest first instead.
Vec3 BillboardClosedForm(const LayersCase& c, uint32_t px, uint32_t py, bool& ambiguous, int& hits,
                         bool reversed = false) {
    const LayersSetup& s = c.params.setup;
    const CameraFrame& cam = c.params.camera;
    const double u0 = (px + 0.5 - 0.5 * cam.width) / cam.focalPx, v0 = (0.5 * cam.height - (py + 0.5)) / cam.focalPx;
    double d[3], f[3], ri[3], up[3];
    for (int a = 0; a < 3; ++a) {
        f[a] = cam.forward[a], ri[a] = cam.right[a], up[a] = cam.upVector[a];
        d[a] = f[a] + u0 * ri[a] + v0 * up[a];
    }
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (double& x : d) x /= len;
    const double cosF = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    const double eye[3] = {s.eye[0], s.eye[1], s.eye[2]};
    const double phase = PhaseValue(s.light.phase, MarchDot(s.sun, Vec3{float(d[0]), float(d[1]), float(d[2])}));
    struct Hit {
        double depth, alpha, T;
    };
    std::vector<Hit> list;
    ambiguous = false;
    for (int b = -4; b <= 6; ++b)
        for (int a = 0; a <= 9; ++a) {
            const double cc[3] = {a + 0.5, b + 0.5, 2.0};
            const double hx = cc[0] - eye[0], hy = cc[1] - eye[1];
            if (hx * hx + hy * hy > 6.25) continue;
            const double depth = hx * f[0] + hy * f[1] + (cc[2] - eye[2]) * f[2];
            if (!(depth > 0)) continue;
            const double t = depth / cosF;
            double p[3], uu = 0, vv = 0;
            for (int k = 0; k < 3; ++k) p[k] = eye[k] + t * d[k];
            for (int k = 0; k < 3; ++k) uu += (p[k] - cc[k]) * ri[k], vv += (p[k] - cc[k]) * up[k];
            const double r = std::hypot(p[0] - eye[0], p[1] - eye[1]);
            const double edges[] = {
                std::fabs(uu) - 0.5, std::fabs(vv) - 2.0, r - 2.5, p[2], p[2] - 4.0, p[0], p[0] - 8.0, p[1],
                p[1] - 8.0};
            for (double g : edges) ambiguous = ambiguous || std::fabs(g) < 1e-3;
            if (!(std::fabs(uu) <= 0.5 && std::fabs(vv) <= 2.0 && r < 2.5 && p[2] >= 0 && p[2] <= 4)) continue;
            if (p[0] < 0 || p[0] > 8 || p[1] < 0 || p[1] > 8) continue;
            const double q = std::min({1.0, p[2] + 0.5, 4.5 - p[2]});
            const double T = 0.2 + 0.1 * std::clamp(p[1] - 0.5, 0.0, 7.0);
            list.push_back({depth, 1 - std::exp(-double(s.sigmaH) * q / cosF), T});
        }
    hits = int(list.size());
    std::sort(list.begin(), list.end(),
              [&](const Hit& x, const Hit& y) { return reversed ? x.depth < y.depth : x.depth > y.depth; });
    double C[3] = {s.background[0], s.background[1], s.background[2]};
    for (const Hit& h : list)
        for (int ch = 0; ch < 3; ++ch) {
            const double lit = s.light.sunRadiance[ch] * h.T * phase + s.light.ambient[ch];
            C[ch] = h.alpha * lit + (1 - h.alpha) * C[ch];
        }
    return {float(C[0]), float(C[1]), float(C[2])};
}

// Test the billboards' closed form on every backend (BillboardField): each pixel is its billboards' blend, farthest
// first, with beer's opacity of the hand-worked path; pixels of two and of three billboards are both present, and
// the blend nearest first (T differs between them) is measurably different, so a reversed order fails.
TEST_P(RenderLayersAll, BillboardsAreTheirClosedFormBackToFront) {
    const LayersCase c = BillboardField();
    const LayersImage im = RenderLayersOn(*mBackend, c);
    ASSERT_TRUE(im.ok);
    double worst = 0, reversedWorst = 0;
    int counted[4] = {0, 0, 0, 0};
    for (uint32_t y = 0; y < 48; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            bool ambiguous = false;
            int hits = 0;
            const Vec3 want = BillboardClosedForm(c, x, y, ambiguous, hits);
            if (ambiguous) continue;
            const Vec3 backward = BillboardClosedForm(c, x, y, ambiguous, hits, true);
            ++counted[std::min(hits, 3)];
            for (int ch = 0; ch < 3; ++ch) {
                const double got = im.rgb[3 * (x + 64 * y) + ch];
                worst = std::max(worst, std::fabs(got - want[ch]) / std::max(1.0, double(want[ch])));
                reversedWorst = std::max(reversedWorst, std::fabs(got - backward[ch]));
            }
        }
    EXPECT_LT(worst, 1e-5);  // float rounding of a few blends and exps
    EXPECT_GT(reversedWorst, 1e-3);
    EXPECT_GT(counted[2], 50);
    EXPECT_GT(counted[3], 50);
    EXPECT_GT(im.stats.drawn, 0u);
}

// Test one billboard fragment by hand (BillboardFragment with q = 1 and T = 1 everywhere): the pixel at the centre
// of the image, whose ray is forward, meets a billboard 3 ahead at its centre: alpha = 1 - exp(-sigma h * 1) (path
// min(p_s, dz) = 1 with cos = 1), colour sun P^ + ambient; the same billboard moved 0.6 to the side (past
// W_p / 2 = 0.5) is missed, and so is one 3 behind.
TEST(LayersLod0, OneBillboardFragmentByHand) {
    const Extent3 e{8, 8, 4};
    LayersParams p = CameraLayers(e, {4, 1, 2}, {4, 9, 2}, 33, 33, 4, true);
    LayersSetup& s = p.setup;
    SetLayersLod0(s, 3.5, 1.0);
    const LayersBillboards list{nullptr, 0, p.camera.right, p.camera.upVector};
    auto fetch = [](uint32_t) { return std::array<float, 2>{1.0f, 1.0f}; };
    const LayersRay ray = MakeLayersRay(p.camera, 1.0f, 16, 16);
    ASSERT_NEAR(ray.cosForward, 1.0f, 1e-6f);
    const float phase = PhaseValue(s.light.phase, MarchDot(s.sun, ray.dir));
    const SunPhases phases{{phase}};
    const LayerFragmentResult f = BillboardFragment(s, list, ray, phases, {{4, 4, 2.2f}, 3.0f}, fetch);
    EXPECT_TRUE(f.crossed && f.drawn);
    EXPECT_NEAR(f.alpha, 1 - std::exp(-double(s.sigmaH)), 1e-6);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(f.color[ch], s.light.sunRadiance[ch] * phase + s.light.ambient[ch], 1e-5);
    EXPECT_FALSE(BillboardFragment(s, list, ray, phases, {{4.6f, 4, 2.2f}, 3.0f}, fetch).crossed);
    EXPECT_FALSE(BillboardFragment(s, list, ray, phases, {{4, -2, 2.2f}, -3.0f}, fetch).crossed);
    // Beyond r0 horizontally (3.5): the same billboard 4 ahead is LOD1's, not LOD0's.
    EXPECT_FALSE(BillboardFragment(s, list, ray, phases, {{4, 5, 2.2f}, 4.0f}, fetch).crossed);
}

// Test that each GPU backend's image matches the CPU's by SPEC 8's image rule (within 1e-4 everywhere) with LOD0's
// billboards on, with the same counters: the eye below, inside and above the layer, tiled and not, billboards at the
// voxel spacing and wider and narrower, one layer per voxel and fewer (N = 1 among them), beer and wang opacity.
TEST_P(RenderLayersGpu, MatchesTheCpuWithBillboards) {
    ASSERT_TRUE(mBackend->Supports(Stage::RenderLayers));
    cpu::BackendCpu cpu(2);
    const Extent3 e{13, 11, 7};
    struct Lod0 {
        uint32_t count;
        double radius, spacing;
    };
    const Lod0 lods[] = {{7, 4.0, 1.0}, {3, 6.5, 1.7}, {1, 3.2, 0.6}};
    int n = 0;
    uint64_t drawnBillboards = 0;
    for (bool tiling : {false, true})
        for (const Lod0& lod : lods)
            for (const auto& eye : Eyes(e)) {
                LayersCase c = BlobLayers(e);
                c.params = CameraLayers(e, eye, {0.5 * e.nx, 0.6 * e.ny, 0.5 * e.nz}, 37, 29, lod.count, tiling);
                c.params.setup.drift = {0.37f, -0.21f};
                std::vector<float> map(size_t(e.nx) * e.ny);
                for (size_t i = 0; i < map.size(); ++i) map[i] = float((i * 2654435761u) % 997) / 2000.0f;
                if (n++ % 3 == 1) {
                    c.params.setup.wang = true;
                    c.params.setup.coverage = 0.9f;
                    c.params.setup.density = 3.0f;
                    c.params.setup.map = map.data();
                }
                LayersCase without = c;
                SetLayersLod0(c.params.setup, lod.radius, lod.spacing);
                const LayersImage want = RenderLayersOn(cpu, c), got = RenderLayersOn(*mBackend, c);
                const LayersImage layersOnly = RenderLayersOn(cpu, without);
                ASSERT_TRUE(want.ok && got.ok && layersOnly.ok);
                double worst = 0;
                for (size_t i = 0; i < want.rgb.size(); ++i)
                    worst = std::max(worst, double(std::fabs(want.rgb[i] - got.rgb[i])));
                const std::string what = "tiling " + std::to_string(tiling) + " count " + std::to_string(lod.count) +
                                         " eye z " + std::to_string(eye[2]);
                EXPECT_LT(worst, 1e-4) << what;
                EXPECT_EQ(got.stats.fragments, want.stats.fragments) << what;
                EXPECT_EQ(got.stats.drawn, want.stats.drawn) << what;
                size_t changed = 0;
                for (size_t i = 0; i < want.rgb.size(); ++i) changed += want.rgb[i] != layersOnly.rgb[i] ? 1 : 0;
                drawnBillboards += changed > 30 ? 1 : 0;
            }
    // Most cases show billboards (untiled, the eye below or above sees LOD0 outside the box in some).
    EXPECT_GE(drawnBillboards, 10u);
}

}  // namespace
}  // namespace cb::test
