// The GLSL twin of core/math/Layers.h (core/math/layers.glsl), run by
// tests/twin/twin.comp with blocks from MakeLayersGpu: the pixel's ray and the
// walk over its layers, the padded taps and the tiling's wrap, one layer's
// fragment and the blend, the whole pixel. Bit-exact on lavapipe (no function
// here calls the driver's exp: SegmentTransmittance is the project's own);
// within 4 ulps on other devices, as GlslTwinTest.cpp's cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math/Layers.h"
#include "core/pipeline/LayersGpu.h"
#include "tests/GlslTwinHarness.h"

namespace cb {
namespace {

using test::Bits;
using test::Compare;
using test::Float;
using test::Kind;
using test::TwinPaddedQT;
using test::Uniform;
using test::W;
using test::WF;
using test::Words;

// A random layered call: a grid up to 40 x 40 x 24, a camera below, inside or above it, tiled or not, a layer
// count from a quarter to four per voxel, an extent that cuts some rays, every phase, beer or wang opacity (the
// map TwinLayersMap, held in `map`).
LayersParams RandomLayersParams(Pcg32& r, std::vector<float>& map) {
    const Extent3 e{1 + r.Below(40), 1 + r.Below(40), 1 + r.Below(24)};
    const float h = Uniform(r, 0.5, 100);
    CameraSettings camera;
    for (int a = 0; a < 3; ++a) {
        const double extent = double(h) * (a == 0 ? e.nx : a == 1 ? e.ny : e.nz);
        camera.eye[a] = r.Uniform(-extent, 2 * extent);
        camera.target[a] = r.Uniform(-extent, 2 * extent);
    }
    camera.fovDeg = r.Uniform(20, 90);
    camera.nearPlane = r.Uniform(0.01, 2 * h);
    camera.farPlane = r.Below(2) ? 1e6 : r.Uniform(10 * h, 80 * h);
    LayersParams p;
    p.camera = MakeCameraFrame(camera, 1 + r.Below(300), 1 + r.Below(200));
    LayersSetup& s = p.setup;
    for (int a = 0; a < 3; ++a) s.eye[a] = p.camera.eye[a] / h;
    s.size = {float(e.nx), float(e.ny), float(e.nz)};
    s.invSize = {1.0f / s.size[0], 1.0f / s.size[1], 1.0f / s.size[2]};
    s.voxelSize = h;
    s.count = std::max(1u, uint32_t(e.nz * Uniform(r, 0.25, 4)));
    s.spacing = float(double(e.nz) / s.count);
    const float extent = Uniform(r, 2, 200);
    s.outer2 = extent * extent;
    s.maxLength = Uniform(r, 0.5, 30);
    s.sigmaH = Uniform(r, 0, 2);
    s.tiling = r.Below(2) == 1;
    s.drift = {Uniform(r, -2, 2) * s.size[0], Uniform(r, -2, 2) * s.size[1]};
    s.sun = SunDirection(r.Uniform(-0.2, 1.55), r.Uniform(0, 6.28));
    s.light.sunRadiance = {Uniform(r, 0, 3), Uniform(r, 0, 3), Uniform(r, 0, 3)};
    s.light.ambient = {Uniform(r, 0, 0.4), Uniform(r, 0, 0.4), Uniform(r, 0, 0.4)};
    s.background = {Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1)};
    const PhaseKind kinds[] = {PhaseKind::None, PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks, PhaseKind::Mie,
                               PhaseKind::DualLobe};
    s.light.phase = {kinds[r.Below(5)], Uniform(r, -0.9, 0.9), Uniform(r, 0, 0.9), Uniform(r, -0.9, 0),
                     Uniform(r, 0, 1)};
    s.wang = r.Below(2) == 1;
    s.coverage = Uniform(r, 0, 1);
    s.density = Uniform(r, 0.5, 8);
    map.resize(size_t(e.nx) * e.ny);
    for (uint32_t i = 0; i < map.size(); ++i) map[i] = test::TwinLayersMap(i);
    s.map = map.data();
    const float fade = Uniform(r, 0.05f, 1);  // one call in three without the falloff
    s.fadeInv2 = r.Below(3) == 0 ? 0.0f : 1.0f / (s.outer2 * fade * (2.0f - fade));
    // LOD0 in two calls of three: p_s from half a voxel to 3, r0 up to 5 p_s (and within the extent).
    if (r.Below(3) != 0) {
        const float ps = Uniform(r, 0.5, 3);
        SetLayersLod0(s, std::min(Uniform(r, 0.3f, 5) * ps, extent), ps);
    }
    // The sky light in half the calls (its T_sky TwinPaddedSkyT, read through TwinFetchSky).
    s.light.skyOn = r.Below(2) == 1;
    s.light.skyRadiance = {Uniform(r, 0, 2), Uniform(r, 0, 2), Uniform(r, 0, 2)};
    s.light.skyDirection = SunDirection(r.Uniform(0.02, 1.55), r.Uniform(0, 6.28));
    return p;
}

std::vector<Words> PixelInputs(Pcg32& r, const CameraFrame& c, uint32_t layers) {
    const uint32_t w = c.width, h = c.height;
    std::vector<Words> in = {W({0, 0, 0}), W({w - 1, 0, layers - 1}), W({0, h - 1, 0}), W({w - 1, h - 1, layers / 2})};
    for (int n = 0; n < 600; ++n) in.push_back(W({r.Below(w), r.Below(h), r.Below(layers)}));
    return in;
}

auto TwinFetch = [](uint32_t i) { return TwinPaddedQT(i); };
// With the sky light: (q, T, T_sky), as the CPU's layers read them (twin.comp's MarchFetchSkyT is the third).
auto TwinFetchSky = [](uint32_t i) {
    const std::array<float, 2> qt = TwinPaddedQT(i);
    return std::array<float, 3>{qt[0], qt[1], test::TwinPaddedSkyT(i)};
};

#if CLOUDBENCH_HAVE_VK

using test::GlslTwin;

// Test that MakeLayersRay and LayersWalkOf, the padded taps with TileWrap and LayerHeight, LayerFragment with
// LayersOver, BillboardFragment, and LayersPixel with LOD0's billboards equal their C++ twins on random calls and
// pixels, corners included; and that the cases reach both outcomes of a fragment (drawn and not).
TEST_F(GlslTwin, LayersFunctionsEqualTheirCppTwins) {
    Pcg32 rng(0x1a7e);
    const uint32_t ulps = sExact ? 0 : 4;
    uint32_t drawn = 0, fragments = 0, billboardDrawn = 0, billboardMissed = 0;
    for (int call = 0; call < 24; ++call) {
        std::vector<float> map;
        const LayersParams p = RandomLayersParams(rng, map);
        const LayersSetup& s = p.setup;
        const std::vector<LayersBillboard> list = MakeLayersBillboards(s, p.camera.forward);
        const LayersBillboards billboards{list.data(), uint32_t(list.size()), p.camera.right, p.camera.upVector};
        const LayersGpu g = MakeLayersGpu(p, billboards.count);
        const std::vector<Words> pixels = PixelInputs(rng, p.camera, s.count);
        std::vector<Kind> rayKinds(5, Kind::F);
        rayKinds.insert(rayKinds.end(), {Kind::I, Kind::I, Kind::U});
        Compare("MakeLayersRay", rayKinds, ulps, pixels, Run(test::kTwinMakeLayersRay, pixels, {}, {}, g),
                [&](const Words& in, Words& out) {
                    const LayersRay r = MakeLayersRay(p.camera, s.voxelSize, in[0], in[1]);
                    const LayersWalk w = LayersWalkOf(s, r.dir[2]);
                    out = W({Bits(r.dir[0]), Bits(r.dir[1]), Bits(r.dir[2]), Bits(r.tNear), Bits(r.tFar),
                             uint32_t(w.first), uint32_t(w.step), w.count});
                });
        std::vector<Words> points;
        for (int n = 0; n < 600; ++n) {
            const float x = Uniform(rng, -3 * s.size[0], 3 * s.size[0]);
            const float nx = s.size[0];
            points.push_back(WF({Uniform(rng, -1, s.size[0] + 1), Uniform(rng, -1, s.size[1] + 1),
                                 Uniform(rng, -1, s.size[2] + 1), x, nx, s.invSize[0]}));
            points.back()[6] = rng.Below(s.count);
        }
        std::vector<Kind> tapKinds = {Kind::U, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F};
        Compare("LayersTaps", tapKinds, ulps, points, Run(test::kTwinLayersTaps, points, {}, {}, g),
                [&](const Words& in, Words& out) {
                    const LayersTaps t = LayersTapsAt(s.size, {Float(in[0]), Float(in[1]), Float(in[2])});
                    const auto qt = LayersBlend(s.size, t, TwinFetch);
                    out = W({t.base, Bits(t.wx), Bits(t.wy), Bits(t.wz), Bits(qt[0]), Bits(qt[1]),
                             Bits(TileWrap(Float(in[3]), Float(in[4]), Float(in[5]))), Bits(LayerHeight(s, in[6]))});
                });
        std::vector<Words> fragmentsIn = pixels;
        for (Words& w : fragmentsIn) {
            w[3] = Bits(Uniform(rng, 0, 1)), w[4] = Bits(Uniform(rng, 0, 1)), w[5] = Bits(Uniform(rng, 0, 1));
        }
        std::vector<Kind> fragmentKinds = {Kind::U, Kind::U};
        fragmentKinds.insert(fragmentKinds.end(), 8, Kind::F);
        Compare("LayerFragment", fragmentKinds, ulps, fragmentsIn,
                Run(test::kTwinLayerFragment, fragmentsIn, {}, {}, g), [&](const Words& in, Words& out) {
                    const LayersRay r = MakeLayersRay(p.camera, s.voxelSize, in[0], in[1]);
                    const SunPhases sunPhases = LayersSunPhases(s, r);
                    const LayerFragmentResult f = s.light.skyOn ? LayerFragment(s, r, sunPhases, in[2], TwinFetchSky)
                                                                : LayerFragment(s, r, sunPhases, in[2], TwinFetch);
                    const Vec3 over = LayersOver({Float(in[3]), Float(in[4]), Float(in[5])}, f.alpha, f.color);
                    out = W({uint32_t(f.crossed), uint32_t(f.drawn), Bits(f.alpha), Bits(f.color[0]), Bits(f.color[1]),
                             Bits(f.color[2]), Bits(sunPhases.value[0]), Bits(over[0]), Bits(over[1]), Bits(over[2])});
                    drawn += f.drawn ? 1 : 0;
                });
        const std::vector<Kind> pixelKinds = {Kind::F, Kind::F, Kind::F, Kind::U, Kind::U};
        Compare("LayersPixel", pixelKinds, ulps, pixels, Run(test::kTwinLayersPixel, pixels, {}, {}, g, list),
                [&](const Words& in, Words& out) {
                    const LayersRay ray = MakeLayersRay(p.camera, s.voxelSize, in[0], in[1]);
                    const LayersPixelResult r = s.light.skyOn
                                                    ? LayersPixel(s, MakeLayersWalks(s), ray, TwinFetchSky, billboards)
                                                    : LayersPixel(s, MakeLayersWalks(s), ray, TwinFetch, billboards);
                    out = W({Bits(r.color[0]), Bits(r.color[1]), Bits(r.color[2]), r.fragments, r.drawn});
                    fragments += r.fragments;
                });
        // BillboardFragment on pixels near the projections of random billboards (so that both outcomes occur).
        if (!list.empty()) {
            std::vector<Words> billboardIn;
            const CameraFrame& c = p.camera;
            for (int n = 0; n < 400; ++n) {
                const uint32_t k = rng.Below(uint32_t(list.size()));
                const LayersBillboard& b = list[k];
                const Vec3 rel{b.centre[0] - s.eye[0], b.centre[1] - s.eye[1], b.centre[2] - s.eye[2]};
                const float reach = 1.5f * c.focalPx / b.depth;  // pixels per voxel edge at the billboard
                const float px = 0.5f * c.width + c.focalPx * MarchDot(rel, c.right) / b.depth +
                                 Uniform(rng, -1, 1) * reach * s.halfWidth;
                const float py = 0.5f * c.height - c.focalPx * MarchDot(rel, c.upVector) / b.depth +
                                 Uniform(rng, -1, 1) * reach * s.halfHeight;
                const auto clampTo = [](float v, uint32_t n) {
                    return uint32_t(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, float(n - 1)));
                };
                billboardIn.push_back(W({clampTo(px, c.width), clampTo(py, c.height), k}));
            }
            std::vector<Kind> billboardKinds = {Kind::U, Kind::U};
            billboardKinds.insert(billboardKinds.end(), 5, Kind::F);
            Compare("BillboardFragment", billboardKinds, ulps, billboardIn,
                    Run(test::kTwinBillboardFragment, billboardIn, {}, {}, g, list), [&](const Words& in, Words& out) {
                        const LayersRay r = MakeLayersRay(p.camera, s.voxelSize, in[0], in[1]);
                        const SunPhases sunPhases = LayersSunPhases(s, r);
                        const LayerFragmentResult f =
                            s.light.skyOn ? BillboardFragment(s, billboards, r, sunPhases, list[in[2]], TwinFetchSky)
                                          : BillboardFragment(s, billboards, r, sunPhases, list[in[2]], TwinFetch);
                        out = W({uint32_t(f.crossed), uint32_t(f.drawn), Bits(f.alpha), Bits(f.color[0]),
                                 Bits(f.color[1]), Bits(f.color[2]), Bits(r.cosForward)});
                        billboardDrawn += f.drawn ? 1 : 0;
                        billboardMissed += f.crossed ? 0 : 1;
                    });
        }
        // LayersFade across its inner radius, the band, the extent and beyond.
        std::vector<Words> fadeIn;
        for (int n = 0; n < 200; ++n) fadeIn.push_back(WF({Uniform(rng, 0, 1.5f * s.outer2), s.outer2, s.fadeInv2}));
        Compare("LayersFade", {Kind::F}, ulps, fadeIn, Run(test::kTwinLayersFade, fadeIn, {}, {}, g),
                [&](const Words& in, Words& out) {
                    out = W({Bits(LayersFade(Float(in[0]), Float(in[1]), Float(in[2])))});
                });
    }
    // Both outcomes are well represented: fragments drawn, and pixels whose rays cross layers.
    EXPECT_GT(drawn, 500u);
    EXPECT_GT(fragments, 5000u);
    EXPECT_GT(billboardDrawn, 150u);  // and billboard fragments drawn and missed
    EXPECT_GT(billboardMissed, 300u);
}

#endif  // CLOUDBENCH_HAVE_VK

}  // namespace
}  // namespace cb
