// The twin cases of core/math/march.glsl that need no MarchGpu block (the rest
// run in GlslTwinTest.cpp): ArcCos, the Mie lookup, the ray and step formulas.
#include <cmath>
#include <limits>
#include <vector>

#include "GlslTwinHarness.h"
#include "core/math/Ground.h"
#include "core/math/March.h"
#include "core/math/Shading.h"
#include "core/math/Shafts.h"

namespace cb::test {

void AddMarchCases(std::vector<TwinCase>& c) {
    {
        // Every x of a grid of step 1/4096 over [-1, 1] (2^13 + 1 points), the ends and their neighbours.
        std::vector<Words> edges;
        for (int n = -4096; n <= 4096; ++n) edges.push_back(WF({float(n) / 4096.0f}));
        for (float x : {1.0f, -1.0f, 0.0f, 0.5f, -0.5f})
            for (float y : AndNeighbours(x))
                if (std::fabs(y) <= 1.0f) edges.push_back(WF({y}));
        edges.push_back(WF({-0.0f}));
        c.push_back({"ArcCos",
                     kTwinArcCos,
                     {Kind::F},
                     [](Pcg32& r, Words& in) { in = WF({Uniform(r, -1, 1)}); },
                     edges,
                     [](const Words& in, Words& out) { out[0] = Bits(ArcCos(Float(in[0]))); },
                     /*otherDeviceUlps=*/8});
    }
    {
        // The lookup with the real table (bound by GlslTwin::Run): cos at every node of the table and
        // one float either side, and cos slightly outside [-1, 1] (clamped).
        const float perRadian = kMieCloudTable.indexPerRadian;
        const uint32_t count = kMieCloudTable.count;
        std::vector<Words> edges;
        for (uint32_t i = 0; i < count; ++i)
            for (float x : AndNeighbours(float(std::cos(double(i) / perRadian))))
                edges.push_back(W({Bits(perRadian), count, Bits(std::clamp(x, -1.0f, 1.0f))}));
        for (float x : {1.5f, -1.5f, 1.0f, -1.0f}) edges.push_back(W({Bits(perRadian), count, Bits(x)}));
        c.push_back({"SamplePhaseTable",
                     kTwinSamplePhaseTable,
                     {Kind::F},
                     [perRadian, count](Pcg32& r, Words& in) {
                         in = W({Bits(perRadian), count, Bits(Uniform(r, -1, 1))});
                     },
                     edges,
                     [](const Words& in, Words& out) { out[0] = Bits(SamplePhaseTable(kMieCloudTable, Float(in[2]))); },
                     /*otherDeviceUlps=*/64});
        // PhaseValue of every kind through light.glsl's LightPhase of a MarchGpu's light (Mie: the table; the dual
        // lobe: its three words 5-7 of LightGpu; the others: shading.glsl).
        const uint32_t dual = uint32_t(PhaseKind::DualLobe);
        c.push_back({"LightPhase",
                     kTwinLightPhase,
                     {Kind::F},
                     [perRadian, count](Pcg32& r, Words& in) {
                         in = W({r.Below(5), Bits(Uniform(r, -0.95, 0.95)), Bits(Uniform(r, -1, 1)), Bits(perRadian),
                                 count, Bits(Uniform(r, 0, 0.95)), Bits(Uniform(r, -0.95, 0)), Bits(Uniform(r, 0, 1))});
                     },
                     {W({3, Bits(0.6f), Bits(1.0f), Bits(perRadian), count}),
                      W({3, Bits(0.6f), Bits(-1.0f), Bits(perRadian), count}),
                      W({3, Bits(0.0f), Bits(0.0f), Bits(perRadian), count}),
                      W({1, Bits(0.6f), Bits(1.0f), Bits(perRadian), count}),
                      W({dual, Bits(0.6f), Bits(1.0f), Bits(perRadian), count, Bits(0.8f), Bits(-0.5f), Bits(0.5f)}),
                      W({dual, Bits(0.6f), Bits(-1.0f), Bits(perRadian), count, Bits(0.8f), Bits(-0.5f), Bits(0.5f)})},
                     [](const Words& in, Words& out) {
                         out[0] = Bits(PhaseValue(
                             {PhaseKind(in[0]), Float(in[1]), Float(in[5]), Float(in[6]), Float(in[7])}, Float(in[2])));
                     },
                     /*otherDeviceUlps=*/64});
        // The dual lobe alone (shading.glsl DualLobePhase): g_forward in [0, 1), g_backward in (-1, 0], the blend
        // in [0, 1]; the ends of each range, cos at +-1 and 0.
        std::vector<Words> lobeEdges;
        for (float gf : {0.0f, 0.8f, 0.99f})
            for (float gb : {0.0f, -0.5f, -0.99f})
                for (float w : {0.0f, 0.5f, 1.0f})
                    for (float x : {1.0f, -1.0f, 0.0f}) lobeEdges.push_back(WF({gf, gb, w, x}));
        c.push_back({"DualLobePhase",
                     kTwinDualLobePhase,
                     {Kind::F},
                     [](Pcg32& r, Words& in) {
                         in = WF({Uniform(r, 0, 0.95), Uniform(r, -0.95, 0), Uniform(r, 0, 1), Uniform(r, -1, 1)});
                     },
                     lobeEdges,
                     [](const Words& in, Words& out) {
                         PhaseParams phase{PhaseKind::DualLobe, 0.0f, Float(in[0]), Float(in[1]), Float(in[2])};
                         out[0] = Bits(PhaseValue(phase, Float(in[3])));
                     },
                     /*otherDeviceUlps=*/4});
    }
    {
        // Boxes up to 300 voxels, origins inside and outside, directions with zero components (and
        // components below 1e-20, treated as zero), and near / far intervals.
        auto component = [](Pcg32& r) {
            const uint32_t k = r.Below(6);
            return k == 0 ? 0.0f : k == 1 ? -0.0f : k == 2 ? Uniform(r, -1e-21, 1e-21) : Uniform(r, -1, 1);
        };
        std::vector<Words> edges = {
            WF({5, 5, 5, 0, 0, 1, 10, 10, 10, 0, 1e30f}),  WF({5, 5, -1, 0, 0, 1, 10, 10, 10, 0, 1e30f}),
            WF({-1, 5, 5, 0, 0, 1, 10, 10, 10, 0, 1e30f}), WF({11, 5, 5, 0, 1, 0, 10, 10, 10, 0, 1e30f}),
            WF({0, 0, 0, 1, 1, 1, 10, 10, 10, 0, 1e30f}),  WF({10, 10, 10, -1, -1, -1, 10, 10, 10, 2, 5}),
            WF({5, 5, 5, -0.0f, 0, 1, 10, 10, 10, 0, 1e30f}), WF({5, 5, 5, 1e-20f, 0, 1, 10, 10, 10, 0, 3}),
            WF({5, 5, 5, 0, 0, 0, 10, 10, 10, 0, 1e30f})};
        // ClipRayToBox, and ClipRayToVolume with tiling (the slab in z alone).
        c.push_back({"ClipRayToBox",
                     kTwinClipRayToBox,
                     {Kind::F, Kind::F, Kind::F, Kind::F},
                     [component](Pcg32& r, Words& in) {
                         const float n[3] = {float(1 + r.Below(300)), float(1 + r.Below(300)), float(1 + r.Below(300))};
                         in = WF({Uniform(r, -50, n[0] + 50), Uniform(r, -50, n[1] + 50), Uniform(r, -50, n[2] + 50),
                                  component(r), component(r), component(r), n[0], n[1], n[2], Uniform(r, 0, 20),
                                  r.Below(2) ? 1e30f : Uniform(r, 20, 500)});
                     },
                     edges,
                     [](const Words& in, Words& out) {
                         float tMin = Float(in[9]), tMax = Float(in[10]);
                         const Vec3 o{Float(in[0]), Float(in[1]), Float(in[2])},
                             d{Float(in[3]), Float(in[4]), Float(in[5])}, n{Float(in[6]), Float(in[7]), Float(in[8])};
                         ClipRayToBox(o, d, n, tMin, tMax);
                         out[0] = Bits(tMin);
                         out[1] = Bits(tMax);
                         float zMin = Float(in[9]), zMax = Float(in[10]);
                         ClipRayToVolume(o, d, n, true, zMin, zMax);
                         out[2] = Bits(zMin);
                         out[3] = Bits(zMax);
                     },
                     /*otherDeviceUlps=*/3});
        c.push_back({"RayExitFromBox",
                     kTwinRayExitFromBox,
                     {Kind::F, Kind::F, Kind::F, Kind::F},
                     [component](Pcg32& r, Words& in) {
                         const float B = float(1 + r.Below(16));
                         const float lo[3] = {B * float(r.Below(20)), B * float(r.Below(20)), B * float(r.Below(20))};
                         in = WF({Uniform(r, lo[0], lo[0] + B), Uniform(r, lo[1], lo[1] + B), Uniform(r, lo[2], lo[2] + B),
                                  component(r), component(r), component(r), lo[0], lo[1], lo[2], lo[0] + B, lo[1] + B,
                                  lo[2] + B, Uniform(r, 0, 300)});
                     },
                     {WF({1, 1, 1, 0, 0, 1, 0, 0, 0, 8, 8, 8, 0}), WF({1, 1, 1, 0, -0.0f, -1, 0, 0, 0, 8, 8, 8, 0}),
                      WF({1, 1, 1, 1e-21f, 1, 0, 0, 0, 0, 8, 8, 8, 100}), WF({8, 8, 8, 1, 1, 1, 0, 0, 0, 8, 8, 8, 0})},
                     [](const Words& in, Words& out) {
                         const Vec3 inv = InverseDirection({Float(in[3]), Float(in[4]), Float(in[5])});
                         out[0] = Bits(RayExitFromBox({Float(in[0]), Float(in[1]), Float(in[2])}, inv,
                                                      {Float(in[6]), Float(in[7]), Float(in[8])},
                                                      {Float(in[9]), Float(in[10]), Float(in[11])}, Float(in[12])));
                         out[1] = Bits(inv[0]);
                         out[2] = Bits(inv[1]);
                         out[3] = Bits(inv[2]);
                     },
                     /*otherDeviceUlps=*/3});
    }
    {
        // Points inside and outside the grid's box and many periods away, bricks that the grid fills and a last
        // one it does not (n not a multiple of B), with tiling and without.
        auto brickInputs = [](float px, float py, float pz, float nx, float ny, float nz, float B, uint32_t tiling) {
            const auto count = [B](float n) { return uint32_t(std::ceil(n / B)); };
            return W({Bits(px), Bits(py), Bits(pz), Bits(nx), Bits(ny), Bits(nz), Bits(1.0f / nx), Bits(1.0f / ny),
                      Bits(1.0f / nz), count(nx), count(ny), count(nz), Bits(B), Bits(1.0f / B), tiling});
        };
        std::vector<Words> edges;
        for (uint32_t tiling : {0u, 1u})
            for (float x : {0.0f, 7.999f, 8.0f, 12.0f, 12.5f, -0.001f, -12.0f, 100.25f, -1e4f})
                edges.push_back(brickInputs(x, 3.5f, 2.0f, 12, 10, 8, 8, tiling));
        c.push_back(
            {"MarchBrickAt",
             kTwinMarchBrickAt,
             {Kind::U, Kind::U, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F},
             [brickInputs](Pcg32& r, Words& in) {
                 const float n[3] = {float(1 + r.Below(300)), float(1 + r.Below(300)), float(1 + r.Below(60))};
                 const float B = float(1 + r.Below(16));
                 const float reach = r.Below(2) ? 2.0f : 40.0f;  // near the box, or many periods away
                 in = brickInputs(Uniform(r, -reach * n[0], (reach + 1) * n[0]),
                                  Uniform(r, -reach * n[1], (reach + 1) * n[1]), Uniform(r, -2, n[2] + 2), n[0], n[1],
                                  n[2], B, r.Below(2));
             },
             edges,
             [](const Words& in, Words& out) {
                 MarchSetup s;
                 s.size = {Float(in[3]), Float(in[4]), Float(in[5])};
                 s.invSize = {Float(in[6]), Float(in[7]), Float(in[8])};
                 s.tiling = in[14] != 0;
                 MarchBricks b;
                 b.count[0] = in[9], b.count[1] = in[10], b.count[2] = in[11];
                 const MarchBrickCell cell =
                     MarchBrickAt(s, b, Float(in[13]), {Float(in[0]), Float(in[1]), Float(in[2])});
                 Vec3 lo{0, 0, 0}, hi{0, 0, 0};
                 if (cell.inside) MarchBrickBox(s, cell, Float(in[12]), lo, hi);
                 out[0] = cell.inside ? 1u : 0u;
                 out[1] = cell.index;
                 for (int a = 0; a < 3; ++a) out[2 + a] = Bits(lo[a]), out[5 + a] = Bits(hi[a]);
             },
             /*otherDeviceUlps=*/3});
    }
    c.push_back({"MarchStepAt",
                 kTwinMarchStepAt,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({Bits(Uniform(r, 0.01, 4)), Bits(Uniform(r, 0, 0.5)), Bits(Uniform(r, 0, 200)), r.Below(2),
                             Bits(Uniform(r, 0, 2000))});
                 },
                 {W({Bits(0.5f), Bits(0.05f), Bits(64.0f), 1, Bits(64.0f)}),
                  W({Bits(0.5f), Bits(0.05f), Bits(64.0f), 1, Bits(10.0f)}),
                  W({Bits(0.5f), Bits(0.05f), Bits(64.0f), 0, Bits(1000.0f)})},
                 [](const Words& in, Words& out) {
                     MarchSetup s;
                     s.step = Float(in[0]), s.kappa = Float(in[1]), s.adaptiveStart = Float(in[2]);
                     s.adaptive = in[3] != 0;
                     out[0] = Bits(MarchStepAt(s, Float(in[4])));
                 }});
    // Inputs: step, kappa, t_a, t, tMax, xi, tExit (the adaptive step on); the landing from t = 40 past the exit at
    // 52.3, one that the far end stops, and a step below the float spacing at t = 2^24.
    c.push_back({"MarchAdaptiveLanding",
                 kTwinMarchAdaptiveLanding,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     const float t = Uniform(r, 0, 300);
                     in = WF({Uniform(r, 0.05f, 4), Uniform(r, 0, 0.5f), Uniform(r, 0, 200), t, t + Uniform(r, 0, 400),
                              Uniform(r, 0, 1), t + Uniform(r, 0, 60)});
                 },
                 {WF({0.5f, 0.05f, 64, 40, 400, 0.5f, 52.3f}), WF({0.5f, 0.05f, 64, 40, 45, 0.5f, 52.3f}),
                  WF({1e-6f, 0, 0, 16777216.0f, 16777220.0f, 0.5f, 16777218.0f})},
                 [](const Words& in, Words& out) {
                     MarchSetup s;
                     s.step = Float(in[0]), s.kappa = Float(in[1]), s.adaptiveStart = Float(in[2]);
                     s.adaptive = true;
                     out[0] = Bits(MarchAdaptiveLanding(s, Float(in[3]), Float(in[4]), Float(in[5]), Float(in[6])));
                 }});
    c.push_back({"MarchJitter",
                 kTwinMarchJitter,
                 {Kind::F},
                 [](Pcg32& r, Words& in) { in = W({r.NextU32(), r.Below(1000), r.Below(1u << 22)}); },
                 {W({0, 0, 0}), W({1, 0, 0}), W({0xffffffffu, 0xffffffffu, 0xffffffffu})},
                 [](const Words& in, Words& out) { out[0] = Bits(MarchJitter(in[0], in[1], in[2])); }});
    // PowderTerm (kTwinPowderTerm) calls pow: GlslTwinTest.cpp compares it with an absolute bound.
    {
        std::vector<Words> edges = {WF({1, 0.5f, 2, 4, 1, 0}), WF({0, 1, 1, 0, 1, -0.0f}),
                                    WF({3.4e38f, 1, 1, 1e-30f, 1e-30f, -1}), WF({0.07f, 0, 1e6f, 2500, 2500, 1e30f}),
                                    WF({1, 1, 0, 1, 2, Float(0x7f7ffffeu)})};
        c.push_back({"MarchKernelFormulas",
                     kTwinMarchKernelFormulas,
                     {Kind::F, Kind::F, Kind::F},
                     [](Pcg32& r, Words& in) {
                         in = WF({Uniform(r, 0, 5), Uniform(r, 0, 1), Uniform(r, 0, 4), Uniform(r, 0, 1e6),
                                  Uniform(r, 1, 1e4), Uniform(r, -1e3, 1e3)});
                     },
                     edges,
                     [](const Words& in, Words& out) {
                         out[0] = Bits(SegmentTransmittance(Float(in[0]), Float(in[1]), Float(in[2])));
                         out[1] = Bits(PointLightFalloff(Float(in[3]), Float(in[4])));
                         out[2] = Bits(std::nextafter(Float(in[5]), std::numeric_limits<float>::max()));
                     },
                     /*otherDeviceUlps=*/3});
    }
}

// twin.comp's G of ground cell (i, j): a hash of the cell.
float TwinGroundG(uint32_t i, uint32_t j) { return float(LowBias32(i + 4096u * j) >> 8) * (1.0f / 16777216.0f); }

void AddGroundCases(std::vector<TwinCase>& c) {
    // Eyes above and below the plane, directions down, level and up, near / far intervals that cut the hit.
    c.push_back({"GroundHit",
                 kTwinGroundHit,
                 {Kind::U, Kind::F, Kind::F},
                 [](Pcg32& r, Words& in) {
                     const float near = Uniform(r, 0, 5);
                     in = WF({Uniform(r, -50, 50), Uniform(r, -50, 50), Uniform(r, -2, 60), Uniform(r, -1, 1),
                              Uniform(r, -1, 1), Uniform(r, -1, 0.2), near, r.Below(2) ? 1e30f : Uniform(r, near, 200)});
                 },
                 {WF({5, 5, 10, 0, 0, -1, 0.1f, 100}), WF({5, 5, 10, 0, 0, -1, 10, 10}),
                  WF({5, 5, 10, 0, 0, -1, 10.01f, 100}), WF({5, 5, 10, 0, 0, -1, 0.1f, 9.99f}),
                  WF({5, 5, 10, 1, 0, 0, 0.1f, 100}), WF({5, 5, 10, 0, 0, -0.0f, 0.1f, 100}),
                  WF({5, 5, -1, 0, 0, -1, 0.1f, 100}), WF({5, 5, 0, 0.6f, 0, -0.8f, 0, 100})},
                 [](const Words& in, Words& out) {
                     float x = 0, y = 0;
                     const bool hit = GroundHit({Float(in[0]), Float(in[1]), Float(in[2])},
                                                {Float(in[3]), Float(in[4]), Float(in[5])}, Float(in[6]), Float(in[7]), x, y);
                     out[0] = hit ? 1 : 0;
                     out[1] = Bits(hit ? x : 0.0f);
                     out[2] = Bits(hit ? y : 0.0f);
                 },
                 /*otherDeviceUlps=*/3});
    // Points inside, on the edges of and outside the footprint of grids from 1 x 1 up.
    std::vector<Words> edges;
    for (uint32_t n : {1u, 2u, 7u})
        for (float x : {0.0f, 0.25f, 0.5f, 1.0f, float(n) - 0.5f, float(n), float(n) + 0.01f, -0.01f})
            edges.push_back(W({Bits(x), Bits(0.75f), n, n + 1}));
    c.push_back({"GroundShadowAt",
                 kTwinGroundShadowAt,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     const uint32_t nx = 1 + r.Below(40), ny = 1 + r.Below(40);
                     in = W({Bits(Uniform(r, -2, nx + 2.0)), Bits(Uniform(r, -2, ny + 2.0)), nx, ny});
                 },
                 edges,
                 [](const Words& in, Words& out) {
                     out[0] = Bits(GroundShadowAt(Float(in[0]), Float(in[1]), in[2], in[3], TwinGroundG));
                 }});
    c.push_back({"GroundChannel",
                 kTwinGroundChannel,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, 0, 1), Uniform(r, 0, 20), Uniform(r, -1, 1), Uniform(r, 0, 2), Uniform(r, 0, 1)});
                 },
                 {WF({0.5f, 1.2f, 1, 0.2f, 1}), WF({0.3f, 2, -0.5f, 0.25f, 0.5f}), WF({1, 1, 0, 0, 1})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(GroundChannel(Float(in[0]), Float(in[1]), Float(in[2]), Float(in[3]), Float(in[4])));
                 }});
}

// twin.comp's D of column (i, j): a hash of the column, up to 16.
float TwinShaftsD(uint32_t i, uint32_t j) {
    return float(LowBias32(i * 7919u + 65537u * j) >> 8) * (1.0f / 1048576.0f);
}

void AddShaftsCases(std::vector<TwinCase>& c) {
    // Points inside, on the column centres and edges of, and outside grids from 1 x 1 up, tiled and not; points
    // periods away (the remainder) and far away (the clamps).
    std::vector<Words> edges;
    for (uint32_t n : {1u, 2u, 7u})
        for (uint32_t tiling : {0u, 1u})
            for (float x : {0.0f, 0.25f, 0.5f, 1.0f, float(n) - 0.5f, float(n), float(n) + 0.01f, -0.01f, -1.5f,
                            -3.0f * float(n) + 0.3f, 1e7f, -1e9f, 1e30f})
                edges.push_back(W({Bits(x), Bits(0.75f), n, n + 1, tiling}));
    c.push_back({"ShaftsColumnAt",
                 kTwinShaftsColumnAt,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     const uint32_t nx = 1 + r.Below(40), ny = 1 + r.Below(40);
                     const float reach = r.Below(4) ? 3.0f : 300.0f;
                     in = W({Bits(Uniform(r, -reach * nx, reach * nx)), Bits(Uniform(r, -reach * ny, reach * ny)), nx,
                             ny, r.Below(2)});
                 },
                 edges,
                 [](const Words& in, Words& out) {
                     out[0] = Bits(ShaftsColumnAt(Float(in[0]), Float(in[1]), in[2], in[3], in[4] != 0, TwinShaftsD));
                 }});
    c.push_back({"ShaftsLayerForm",
                 kTwinShaftsLayerForm,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(3), Bits(Uniform(r, 0, 5)), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 1)),
                             Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 20))});
                 },
                 {W({0, Bits(1e30f), 0, 0, 0, Bits(0.0f)}), W({0, Bits(1e30f), 0, 0, 0, Bits(1e-3f)}),
                  W({1, 0, Bits(0.5f), 0, 0, Bits(3.0f)}), W({2, Bits(0.5f), 0, Bits(0.7f), Bits(0.6f), Bits(2.0f)})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(
                         ShaftsLayerForm(in[0], Float(in[1]), Float(in[2]), Float(in[3]), Float(in[4]), Float(in[5])));
                 },
                 /*otherDeviceUlps=*/3});
    c.push_back(
        {"ShaftsFalloff",
         kTwinShaftsFalloff,
         {Kind::F},
         [](Pcg32& r, Words& in) {
             const float cosW = Uniform(r, -1, 0.999);
             in = WF({Uniform(r, -1, 1), cosW, r.Below(4) ? 1.0f / (1.0f - cosW) : 0.0f});
         },
         {WF({1, 0.5f, 2}), WF({0.5f, 0.5f, 2}), WF({0.2f, 0.5f, 2}), WF({0.2f, 0.5f, 0})},
         [](const Words& in, Words& out) { out[0] = Bits(ShaftsFalloff(Float(in[0]), Float(in[1]), Float(in[2]))); }});
}

}  // namespace cb::test
