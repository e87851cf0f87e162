// The cases of the GLSL twin tests (GlslTwinTest.cpp): every function of
// core/math but MakeSplat, grouped by its GLSL file, with random inputs,
// hand-picked edges and the C++ twin.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "GlslTwinHarness.h"
#include "core/math/Automaton.h"
#include "core/math/Noise.h"
#include "core/math/Random.h"
#include "core/math/Rules.h"
#include "core/math/Shading.h"
#include "core/math/Splat.h"

namespace cb::test {

std::vector<TwinCase> Cases() {
    std::vector<TwinCase> c;
    const uint32_t kQ1 = 1u << 24;  // probability 1
    // The floats v where float(255 v) is exactly k + 0.5, for every k in 0..254
    // (found by search near (k + 0.5)/255), and one ulp outside the first and
    // last of each k: the ties of unorm8 and of the region's quantisation.
    std::vector<float> unormTies;
    for (int k = 0; k <= 254; ++k) {
        float v = (float(k) + 0.5f) / 255.0f;
        for (int n = 0; n < 16; ++n) v = std::nextafter(v, 0.0f);
        std::vector<float> ties;
        for (int n = 0; n < 33; ++n, v = std::nextafter(v, 1.0f))
            if (255.0f * v == float(k) + 0.5f) ties.push_back(v);
        if (ties.empty()) continue;  // SharedFormulaTest asserts there is one for every k
        unormTies.push_back(std::nextafter(ties.front(), 0.0f));
        unormTies.insert(unormTies.end(), ties.begin(), ties.end());
        unormTies.push_back(std::nextafter(ties.back(), 1.0f));
    }

    // ---- random.glsl ----
    c.push_back({"LowBias32",
                 kTwinLowBias32,
                 {Kind::U},
                 [](Pcg32& r, Words& in) { in[0] = r.NextU32(); },
                 {W({0}), W({1}), W({0xffffffffu}), W({0x80000000u})},
                 [](const Words& in, Words& out) { out[0] = LowBias32(in[0]); }});
    c.push_back({"StreamKey",
                 kTwinStreamKey,
                 {Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32(), r.Below(4)});
                 },
                 {W({0, 0, 0}), W({0, kInitialStateStep, 1}), W({0xffffffffu, kInitialStateStep, 3})},
                 [](const Words& in, Words& out) { out[0] = StreamKey(in[0], in[1], in[2]); }});
    c.push_back({"Rand24FromKey",
                 kTwinRand24FromKey,
                 {Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32()});
                 },
                 {W({0, 0}), W({0xffffffffu, 0xffffffffu})},
                 [](const Words& in, Words& out) { out[0] = Rand24FromKey(in[0], in[1]); }});
    {
        // Half the draws sit on the threshold (R q + 127) / 255 or one either side.
        auto random = [kQ1](Pcg32& r, Words& in) {
            const uint32_t region = r.Below(256), q = r.Below(3) == 0 ? kQ1 : r.Below(kQ1 + 1);
            const int64_t threshold = (int64_t(region) * q + 127) / 255;
            const int64_t rand = r.Below(2) ? threshold + int64_t(r.Below(3)) - 1 : int64_t(r.Below(kQ1));
            in = W({uint32_t(std::clamp<int64_t>(rand, 0, kQ1 - 1)), region, q});
        };
        c.push_back({"RegionEventFires",
                     kTwinRegionEventFires,
                     {Kind::U},
                     random,
                     {W({0, 0, 0}), W({0, 255, kQ1}), W({kQ1 - 1, 255, kQ1}), W({kQ1 - 1, 254, kQ1}), W({0, 1, 1}),
                      W({0, 0, kQ1})},
                     [](const Words& in, Words& out) { out[0] = RegionEventFires(in[0], in[1], in[2]); }});
    }

    // ---- rules.glsl ----
    {
        auto random = [](Pcg32& r, Words& in) {
            const float yaw = Uniform(r, 0, 2 * std::numbers::pi);
            const float cx = Uniform(r, 0, 64), cy = Uniform(r, 0, 64), cz = Uniform(r, 0, 16);
            in = WF({cx, cy, cz, Uniform(r, 0.5, 40), Uniform(r, 0.5, 40), Uniform(r, 0.5, 8), std::cos(yaw),
                     std::sin(yaw), float(int(cx) + int(r.Below(81)) - 40) + 0.5f,
                     float(int(cy) + int(r.Below(81)) - 40) + 0.5f, float(int(cz) + int(r.Below(17)) - 8) + 0.5f});
        };
        auto cpp = [](const Words& in, Words& out) {
            const RasterEllipsoid e{{Float(in[0]), Float(in[1]), Float(in[2])},
                                    {Float(in[3]), Float(in[4]), Float(in[5])},
                                    Float(in[6]),
                                    Float(in[7])};
            out[0] = Bits(EllipsoidWeight(e, Float(in[8]), Float(in[9]), Float(in[10])));
        };
        c.push_back({"EllipsoidWeight",
                     kTwinEllipsoidWeight,
                     {Kind::F},
                     random,
                     {WF({10.5f, 10.5f, 4.5f, 3, 3, 2, 1, 0, 10.5f, 10.5f, 4.5f}),   // at the centre: w = 1
                      WF({10.5f, 10.5f, 4.5f, 3, 3, 2, 1, 0, 13.5f, 10.5f, 4.5f}),   // on the surface: w = 0
                      WF({10.5f, 10.5f, 4.5f, 3, 3, 2, 0, 1, 10.5f, 13.5f, 4.5f})},  // yaw 90 degrees
                     cpp,
                     /*otherDeviceUlps=*/4});
    }
    {
        std::vector<Words> edges;
        for (float w : {0.0f, 1.0f, 1e-9f, 2.0f}) edges.push_back(WF({w}));
        for (int k : {0, 1, 127, 253, 254})  // w where 255 w + 0.5 is near an integer
            for (float w : AndNeighbours((float(k) + 0.5f) / 255.0f)) edges.push_back(WF({w}));
        for (float w : unormTies) edges.push_back(WF({w}));  // 255 w = k + 0.5 exactly
        c.push_back({"QuantizeRegion",
                     kTwinQuantizeRegion,
                     {Kind::U},
                     [](Pcg32& r, Words& in) { in = WF({Uniform(r, 0, 1)}); },
                     edges,
                     [](const Words& in, Words& out) { out[0] = uint32_t(QuantizeRegion(Float(in[0]))); }});
    }
    {
        std::vector<Words> edges;
        for (int radius = 0; radius <= 2; ++radius)
            for (int d = -3; d <= 3; ++d) edges.push_back(W({uint32_t(radius), uint32_t(d)}));
        c.push_back({"SmoothWeight",
                     kTwinSmoothWeight,
                     {Kind::I},
                     [](Pcg32& r, Words& in) {
                         in = W({r.Below(3), uint32_t(int(r.Below(7)) - 3)});
                     },
                     edges,
                     [](const Words& in, Words& out) { out[0] = uint32_t(SmoothWeight(Int(in[0]), Int(in[1]))); }});
    }

    // ---- shading.glsl ----
    {
        std::vector<Words> edges;
        for (float x : {0.0f, -0.0f, -1e-30f, -1e-45f, -88.0f, -1000.0f, -0.5f * std::numbers::ln2_v<float>})
            edges.push_back(WF({x}));
        for (float x : AndNeighbours(-87.0f)) edges.push_back(WF({x}));
        for (int k = 1; k < 126; k += 17)  // where the range reduction's k changes
            for (float x : AndNeighbours(-(float(k) + 0.5f) * std::numbers::ln2_v<float>)) edges.push_back(WF({x}));
        c.push_back({"ExpNonPositive",
                     kTwinExpNonPositive,
                     {Kind::F},
                     [](Pcg32& r, Words& in) { in = WF({Uniform(r, -90, 0)}); },
                     edges,
                     [](const Words& in, Words& out) { out[0] = Bits(ExpNonPositive(Float(in[0]))); }});
    }
    // Storage rounding: ties to even in the normal and the subnormal half range,
    // the normal/subnormal boundary, overflow, signs.
    std::vector<Words> halfEdges;
    for (float x : {0.0f, -0.0f, 1.0f, 0.5f, 65504.0f, 65520.0f, 1e-8f, -1e-8f}) halfEdges.push_back(WF({x}));
    for (float x : {1.0f + 0x1p-11f, 1.0f + 3 * 0x1p-11f, 0.75f + 0x1p-12f, 0x1p-14f, 0x1p-14f - 0x1p-25f,
                    0.5f * 0x1p-24f, 1.5f * 0x1p-24f, 2.5f * 0x1p-24f, 1023.5f * 0x1p-24f})
        for (float y : AndNeighbours(x)) {
            halfEdges.push_back(WF({y}));
            halfEdges.push_back(WF({-y}));
        }
    for (float x : AndNeighbours(Float(0x477ff000u))) halfEdges.push_back(WF({x}));
    // Every fp16 tie in [0, 1): the midpoint of codes h and h + 1 (exact in float) and
    // one ulp either side, and the negated midpoint (sparse GPU ties let a
    // wrong tie rounding survive).
    std::vector<Words> halfTies;
    for (uint32_t h = 0; h < 0x3C00u; ++h) {
        auto value = [](uint32_t code) {
            const uint32_t exponent = code >> 10, mantissa = code & 0x3ffu;
            return exponent == 0 ? std::ldexp(double(mantissa), -24)
                                 : std::ldexp(1.0 + mantissa / 1024.0, int(exponent) - 15);
        };
        const float m = float((value(h) + value(h + 1)) / 2);
        for (float x : AndNeighbours(m)) halfTies.push_back(WF({x}));
        halfTies.push_back(WF({-m}));
    }
    c.push_back({"RoundToHalf",
                 kTwinRoundToHalf,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     // Any float of magnitude < 2^18 (random sign, exponent and mantissa), or one in [0, 1].
                     const uint32_t bits = (r.NextU32() & 0x807fffffu) | (r.Below(145) << 23);
                     in = r.Below(2) ? W({bits}) : WF({Uniform(r, 0, 1)});
                 },
                 [&] {
                     std::vector<Words> edges = halfEdges;
                     edges.insert(edges.end(), halfTies.begin(), halfTies.end());
                     return edges;
                 }(),
                 [](const Words& in, Words& out) { out[0] = Bits(RoundToHalf(Float(in[0]))); }});
    std::vector<Words> unormEdges;
    for (float x : {0.0f, -0.0f, 1.0f, -0.5f, 1.5f}) unormEdges.push_back(WF({x}));
    for (int k = 0; k < 255; k += 3)  // 255 v = k + 0.5: the ties
        for (float v : AndNeighbours((float(k) + 0.5f) / 255.0f)) unormEdges.push_back(WF({v}));
    for (float v : unormTies) unormEdges.push_back(WF({v}));  // every k: 255 v = k + 0.5 exactly
    c.push_back({"RoundToUnorm8",
                 kTwinRoundToUnorm8,
                 {Kind::F},
                 [](Pcg32& r, Words& in) { in = WF({Uniform(r, -0.1, 1.1)}); },
                 unormEdges,
                 [](const Words& in, Words& out) { out[0] = Bits(RoundToUnorm8(Float(in[0]))); }});
    {
        std::vector<Words> edges;
        for (uint32_t storage = 0; storage < 3; ++storage) {
            for (const Words& e : halfEdges) edges.push_back(W({storage, e[0]}));
            for (const Words& e : unormEdges) edges.push_back(W({storage, e[0]}));
        }
        for (const Words& e : halfTies) edges.push_back(W({uint32_t(StorageFormat::Fp16), e[0]}));
        c.push_back(
            {"RoundToStorage",
             kTwinRoundToStorage,
             {Kind::F},
             [](Pcg32& r, Words& in) {
                 in = W({r.Below(3), Bits(Uniform(r, 0, 1))});
             },
             edges,
             [](const Words& in, Words& out) { out[0] = Bits(RoundToStorage(StorageFormat(in[0]), Float(in[1]))); }});
    }
    c.push_back({"Lerp",
                 kTwinLerp,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, -2, 2), Uniform(r, -2, 2), Uniform(r, 0, 1)});
                 },
                 {WF({0.25f, 0.75f, 0}), WF({0.25f, 0.75f, 1}), WF({1, 1, 0.5f})},
                 [](const Words& in, Words& out) { out[0] = Bits(Lerp(Float(in[0]), Float(in[1]), Float(in[2]))); }});
    c.push_back({"Bilinear",
                 kTwinBilinear,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1),
                              Uniform(r, 0, 1)});
                 },
                 {WF({1, 1, 1, 1, 0.5f, 0.5f}), WF({0, 1, 0, 1, 0, 0}), WF({0, 1, 0, 1, 1, 1})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(
                         Bilinear(Float(in[0]), Float(in[1]), Float(in[2]), Float(in[3]), Float(in[4]), Float(in[5])));
                 }});
    c.push_back({"PhaseValue",
                 kTwinPhaseValue,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(3), Bits(Uniform(r, -0.95, 0.95)), Bits(Uniform(r, -1, 1))});
                 },
                 {W({0, Bits(0.6f), Bits(1.0f)}), W({1, Bits(0.0f), Bits(0.3f)}), W({1, Bits(0.6f), Bits(1.0f)}),
                  W({2, Bits(0.6f), Bits(-1.0f)}), W({2, Bits(-0.9f), Bits(1.0f)})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(PhaseValue({PhaseKind(in[0]), Float(in[1])}, Float(in[2])));
                 },
                 /*otherDeviceUlps=*/4});
    c.push_back({"SplatKernel",
                 kTwinSplatKernel,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, -0.2, 1.2), Uniform(r, -0.2, 1.2)});
                 },
                 {WF({0.5f, 0.5f}), WF({0, 0}), WF({1, 0.5f}), WF({0.5f, 0})},
                 [](const Words& in, Words& out) { out[0] = Bits(SplatKernel(Float(in[0]), Float(in[1]))); }});
    c.push_back({"SliceFactor",
                 kTwinSliceFactor,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(2), Bits(Uniform(r, 0, 5)), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 0.5)),
                             Bits(Uniform(r, 0, 1))});
                 },
                 {W({1, Bits(2.0f), Bits(0.9f), 0, 0}),                     // q = 0: factor 1
                  W({1, Bits(200.0f), Bits(0.9f), 0, Bits(1.0f)}),          // exp underflows to 0
                  W({1, Bits(1.0f), Bits(0.9f), Bits(2.0f), Bits(1.0f)}),   // clamped to 1
                  W({0, Bits(1.0f), Bits(0.0f), Bits(0.0f), Bits(1.0f)})},  // thesis form at 0
                 [](const Words& in, Words& out) {
                     out[0] = Bits(SliceFactor(in[0] != 0, Float(in[1]), Float(in[2]), Float(in[3]), Float(in[4])));
                 }});
    c.push_back({"StoreTransmittance",
                 kTwinStoreTransmittance,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(3), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 1))});
                 },
                 {W({0, Bits(1e-20f), Bits(1e-20f)}), W({0, Bits(kTransmittanceFloor), Bits(1.0f)}),
                  W({0, Bits(std::nextafter(kTransmittanceFloor, 0.0f)), Bits(1.0f)}), W({1, Bits(1e-30f), Bits(1.0f)}),
                  W({1, Bits(1.0f + 0x1p-11f), Bits(1.0f)}), W({2, Bits(0.5f / 255.0f), Bits(1.0f)})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(StoreTransmittance(StorageFormat(in[0]), Float(in[1]), Float(in[2])));
                 }});
    c.push_back({"GroundShadow",
                 kTwinGroundShadow,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(2), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 0.1)), Bits(Uniform(r, 0, 100))});
                 },
                 {W({1, Bits(0.5f), 0, 0}), W({0, 0, Bits(0.05f), Bits(20.0f)}), W({0, 0, Bits(0.05f), Bits(40.0f)}),
                  W({1, Bits(10.0f), 0, Bits(100.0f)})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(GroundShadow(in[0] != 0, Float(in[1]), Float(in[2]), Float(in[3])));
                 }});
    c.push_back({"WangShadow",
                 kTwinWangShadow,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 1)),
                             Bits(Uniform(r, 0, 100))});
                 },
                 {W({Bits(0.5f), Bits(1.0f), Bits(1.0f), Bits(2.0f)}),
                  W({Bits(0.5f), Bits(0.8f), Bits(0.5f), Bits(2.0f)}),
                  W({Bits(0.5f), Bits(0.3f), Bits(1.0f), Bits(2.0f)}), W({Bits(10.0f), 0, Bits(1.0f), Bits(100.0f)}),
                  W({0, Bits(1.0f), Bits(1.0f), 0})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(WangShadow(Float(in[0]), Float(in[1]), Float(in[2]), Float(in[3])));
                 }});
    {
        std::vector<Words> edges;
        for (uint32_t f : {1u, 2u, 4u})
            for (uint32_t cells : {1u, 2u, 3u, 16u})
                for (uint32_t i : {0u, f * cells - 1, f * cells / 2}) edges.push_back(W({i, f, cells}));
        c.push_back({"UpsampleTap",
                     kTwinUpsampleTap,
                     {Kind::I, Kind::I, Kind::F},
                     [](Pcg32& r, Words& in) {
                         const uint32_t f = 1u << r.Below(3), cells = 1 + r.Below(40);
                         in = W({r.Below(f * cells), f, cells});
                     },
                     edges,
                     [](const Words& in, Words& out) {
                         const UpsampleTaps t = UpsampleTap(in[0], int(in[1]), in[2]);
                         out = W({t.i0, t.i1, Bits(t.w)});
                     }});
    }

    // ---- automaton.glsl ----
    c.push_back({"CaRowNeighbours",
                 kTwinCaRowNeighbours,
                 {Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32(), r.NextU32()});
                 },
                 {W({0, 0, 0}), W({1, 0, 0}), W({0x80000000u, 0, 0}), W({0, 0xc0000000u, 3})},
                 [](const Words& in, Words& out) { out[0] = CaRowNeighbours<uint32_t>(in[0], in[1], in[2]); }});
    c.push_back({"CaGrowth",
                 kTwinCaGrowth,
                 {Kind::U, Kind::U, Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32(), r.NextU32(), r.NextU32()});
                 },
                 {W({1, 1, 0, 1}), W({1, 0, 0, 1}), W({0, 1, 1, 0})},
                 [](const Words& in, Words& out) {
                     const CaBits<uint32_t> s = CaGrowth<uint32_t>({in[0], in[1], in[2]}, in[3]);
                     out = W({s.hum, s.act, s.cld});
                 }});
    {
        auto q = [kQ1](Pcg32& r) {
            const uint32_t kind = r.Below(4);
            return kind == 0   ? 0u
                   : kind == 1 ? kQ1
                   : kind == 2 ? QuantizeProbability(r.NextDouble() * 0.1)
                               : r.Below(kQ1);
        };
        std::vector<Words> edges;
        for (uint32_t g = 0; g < 8; ++g)
            for (uint32_t r : {0u, 1u, 255u})
                for (uint32_t qq : {0u, kQ1})
                    edges.push_back(W({g & 1, g >> 1 & 1, g >> 2, r, 12345, 1, 2, 3, qq, qq, qq}));
        c.push_back({"CaVoxelEvents",
                     kTwinCaVoxelEvents,
                     {Kind::U, Kind::U, Kind::U},
                     [q](Pcg32& r, Words& in) {
                         const uint32_t kind = r.Below(3);
                         const uint32_t region = kind == 0 ? 0 : kind == 1 ? 255 : r.Below(256);
                         in = W({r.Below(2), r.Below(2), r.Below(2), region, r.NextU32(), r.NextU32(), r.NextU32(),
                                 r.NextU32(), q(r), q(r), q(r)});
                     },
                     edges,
                     [](const Words& in, Words& out) {
                         const CaEvents e{in[5], in[6], in[7], in[8], in[9], in[10]};
                         const CaBits<uint32_t> s = CaVoxelEvents({in[0], in[1], in[2]}, in[3], in[4], e);
                         out = W({s.hum, s.act, s.cld});
                     }});
        c.push_back({"CaInitialVoxel",
                     kTwinCaInitialVoxel,
                     {Kind::U, Kind::U, Kind::U},
                     [q](Pcg32& r, Words& in) {
                         in = W({r.NextU32(), r.NextU32(), q(r), q(r), r.NextU32()});
                     },
                     {W({1, 2, 0, kQ1, 7}), W({1, 2, kQ1, 0, 7})},
                     [](const Words& in, Words& out) {
                         const CaBits<uint32_t> s = CaInitialVoxel(in[0], in[1], in[2], in[3], in[4]);
                         out = W({s.hum, s.act, s.cld});
                     }});
        c.push_back({"MakeCaEvents",
                     kTwinMakeCaEvents,
                     std::vector<Kind>(6, Kind::U),
                     [q](Pcg32& r, Words& in) {
                         in = W({r.NextU32(), r.NextU32(), q(r), q(r), q(r)});
                     },
                     {W({0, 0, 0, 0, 0}), W({5, kInitialStateStep, kQ1, kQ1, kQ1})},
                     [](const Words& in, Words& out) {
                         const CaEvents e = MakeCaEvents(in[0], in[1], in[2], in[3], in[4]);
                         out = W({e.keyExt, e.keyHum, e.keyAct, e.qExt, e.qHum, e.qAct});
                     }});
    }

    // ---- splat.glsl (MakeSplat needs a frame: see SplatFrames) ----
    c.push_back({"SplatQ",
                 kTwinSplatQ,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1)});
                 },
                 {WF({0.25f, 0.75f, 0}), WF({0.25f, 0.75f, 1}), WF({0, 0, 0.5f})},
                 [](const Words& in, Words& out) { out[0] = Bits(SplatQ(Float(in[0]), Float(in[1]), Float(in[2]))); }});
    c.push_back(
        {"SplatCoord",
         kTwinSplatCoord,
         {Kind::F},
         [](Pcg32& r, Words& in) {
             in = WF({float(r.Below(1024)) + 0.5f, Uniform(r, -100, 1100), Uniform(r, 1, 255)});
         },
         {WF({10.5f, 10.5f, 4}), WF({8.5f, 10.5f, 4}), WF({0.5f, 0.25f, 1})},
         [](const Words& in, Words& out) { out[0] = Bits(SplatCoord(Float(in[0]), Float(in[1]), Float(in[2]))); },
         /*otherDeviceUlps=*/3});
    c.push_back(
        {"SplatAlpha",
         kTwinSplatAlpha,
         {Kind::F},
         [](Pcg32& r, Words& in) {
             in = WF({Uniform(r, 0, 1.5), Uniform(r, -0.2, 1.2), Uniform(r, -0.2, 1.2)});
         },
         {WF({0.6f, 0.5f, 0.5f}), WF({2, 0.5f, 0.5f}), WF({0.6f, 0, 0})},
         [](const Words& in, Words& out) { out[0] = Bits(SplatAlpha(Float(in[0]), Float(in[1]), Float(in[2]))); }});

    // ---- noise.glsl ----
    {
        // twin.comp's NoiseWord: the permutation i -> (167 i + 13) mod 256.
        static const noise::Permutation kTwinPerm = [] {
            noise::Permutation p;
            for (uint32_t i = 0; i < 256; ++i) p[i] = uint8_t((i * 167u + 13u) & 255u);
            return p;
        }();
        // Words: x, y, z (floats), period x, y, z (ints); `multiple` makes the periods multiples of 3 (simplex).
        auto point = [](Pcg32& r, Words& in, int multiple) {
            const int px = multiple * int(1 + r.Below(8)), py = multiple * int(1 + r.Below(8)),
                      pz = multiple * int(1 + r.Below(4));
            const int periods[3] = {px, py, pz};
            for (int a = 0; a < 3; ++a) {
                float v;
                switch (r.Below(5)) {
                    case 0:  // a lattice point
                        v = float(int(r.Below(2 * periods[a] + 1)) - 1);
                        break;
                    case 1:  // a period's edge
                        v = std::nextafter(float(periods[a]), r.Below(2) ? -INFINITY : INFINITY);
                        break;
                    case 2:  // a voxel of the stage's grid
                        v = float(2 * periods[a]) * float(r.Below(1024)) / 1024.0f;
                        break;
                    default:
                        v = Uniform(r, -3, 2 * periods[a] + 3);
                        break;
                }
                in[a] = Bits(v);
            }
            for (int a = 0; a < 3; ++a) in[3 + a] = uint32_t(periods[a]);
        };
        auto edgesFor = [](int multiple) {
            std::vector<Words> e;
            const uint32_t p = uint32_t(multiple * 4);
            for (float v : {0.0f, 0.5f, 1.0f, float(p) - 0.5f, float(p), float(2 * p), -1.0f, -0.25f})
                for (float u : AndNeighbours(v)) {
                    Words w = WF({u, 0.5f, float(p) * 0.5f});
                    w[3] = w[4] = w[5] = p;
                    e.push_back(w);
                    w = WF({u, u, u});
                    w[3] = w[4] = w[5] = p;
                    e.push_back(w);
                }
            return e;
        };
        auto period = [](const Words& in) { return noise::Period{Int(in[3]), Int(in[4]), Int(in[5])}; };
        c.push_back({"NoisePerlin",
                     kTwinNoisePerlin,
                     {Kind::F},
                     [point](Pcg32& r, Words& in) { point(r, in, 1); },
                     edgesFor(1),
                     [period](const Words& in, Words& out) {
                         out[0] = Bits(
                             noise::Perlin(kTwinPerm.data(), Float(in[0]), Float(in[1]), Float(in[2]), period(in)));
                     }});
        c.push_back({"NoiseSimplex",
                     kTwinNoiseSimplex,
                     {Kind::F},
                     [point](Pcg32& r, Words& in) { point(r, in, 3); },
                     edgesFor(3),
                     [period](const Words& in, Words& out) {
                         out[0] = Bits(
                             noise::Simplex(kTwinPerm.data(), Float(in[0]), Float(in[1]), Float(in[2]), period(in)));
                     }});
        c.push_back({"NoiseWorley",
                     kTwinNoiseWorley,
                     {Kind::F},
                     [point](Pcg32& r, Words& in) {
                         point(r, in, 1);
                         in[6] = r.NextU32();
                     },
                     edgesFor(1),
                     [period](const Words& in, Words& out) {
                         out[0] = Bits(noise::Worley(in[6], Float(in[0]), Float(in[1]), Float(in[2]), period(in)));
                     },
                     /*otherDeviceUlps=*/4});
        c.push_back({"NoiseFbm",
                     kTwinNoiseFbm,
                     {Kind::F, Kind::F},
                     [point](Pcg32& r, Words& in) {
                         const uint32_t basis = r.Below(3);
                         point(r, in, basis == 1 ? 3 : 1);
                         in[6] = basis, in[7] = r.NextU32(), in[8] = 1 + r.Below(5);
                         in[9] = Bits(Uniform(r, 0.2, 0.8)), in[10] = 2 + r.Below(2), in[11] = r.Below(2);
                     },
                     {},
                     [period](const Words& in, Words& out) {
                         const NoiseBasis basis = NoiseBasis(in[6]);
                         const FbmSettings fbm{basis, in[8], double(Float(in[9])), in[10], in[11] != 0};
                         const noise::Lattice lattice{basis, kTwinPerm.data(), in[7]};
                         const float sum =
                             noise::Fbm(lattice, fbm, Float(in[0]), Float(in[1]), Float(in[2]), period(in));
                         out[0] = Bits(sum);
                         out[1] = Bits(noise::Fbm01FromSum(basis, fbm, sum));
                     },
                     /*otherDeviceUlps=*/8});
        c.push_back({"NoiseForming",
                     kTwinNoiseForming,
                     {Kind::F, Kind::F, Kind::F, Kind::I, Kind::F},
                     [](Pcg32& r, Words& in) {
                         const float half = float(int(r.Below(41)) - 20) + 0.5f;  // round's ties half the time
                         in = WF({Uniform(r, -0.2, 1.5), Uniform(r, 0, 0.99), Uniform(r, 0, 1), Uniform(r, 0, 1),
                                  Uniform(r, 0, 3), Uniform(r, 0, 1), Uniform(r, 0, 0.99), 0, 0,
                                  r.Below(2) ? half : Uniform(r, -20, 20)});
                         in[7] = uint32_t(int(r.Below(401)) - 200), in[8] = 1 + r.Below(64);
                     },
                     {[] {
                          Words w = WF({0.35f, 0.35f, 0, 0.65f, 1, 1, 0.99f, 0, 0, -0.5f});
                          w[7] = uint32_t(-64), w[8] = 32;
                          return w;
                      }(),
                      [] {
                          Words w = WF({1, 0, 1, 0, 0, 0, 0, 0, 0, std::nextafter(0.5f, 0.0f)});
                          w[7] = uint32_t(-1), w[8] = 7;
                          return w;
                      }()},
                     [](const Words& in, Words& out) {
                         out[0] = Bits(noise::Threshold(Float(in[0]), Float(in[1])));
                         out[1] = Bits(CoverageModulate(Float(in[0]), Float(in[2]), Float(in[3]), Float(in[4])));
                         out[2] = Bits(noise::Erode(Float(in[0]), Float(in[5]), Float(in[6])));
                         out[3] = uint32_t(noise::WrapIndex(Int(in[7]), Int(in[8])));
                         out[4] = Bits(std::round(Float(in[9])));
                     },
                     /*otherDeviceUlps=*/3});
        TwinCase exps{
            "NoiseHeightAndTower",
            kTwinNoiseHeightAndTower,
            {Kind::F, Kind::F},
            [](Pcg32& r, Words& in) {
                // A voxel centre within 4 sigma of the tower per axis (the result stays a normal
                // float), x and y wrapped onto the grid, so half the towers straddle an edge. HD's
                // a h >= 1: below, 1 - e^{-a h} cancels and multiplies exp's relative error by 1 / (a h)
                // (the stage reads HD from the host, so only the formula is checked here).
                const float n[3] = {float(1 + r.Below(128)), float(1 + r.Below(128)), 32};
                float centre[3], inv[3], at[3];
                for (int a = 0; a < 3; ++a) {
                    const float sigma = Uniform(r, 0.5, 12);
                    centre[a] = Uniform(r, 0, n[a]);
                    inv[a] = float(1.0 / (double(sigma) * sigma));
                    float p = centre[a] + Uniform(r, -4 * sigma, 4 * sigma);
                    if (a < 2) p = p < 0 ? p + n[a] : (p >= n[a] ? p - n[a] : p);
                    at[a] = std::floor(std::clamp(p, 0.0f, n[a] - 0.5f)) + 0.5f;
                }
                in = WF({Uniform(r, 0.05, 1), Uniform(r, 20, 60), Uniform(r, 0, 10), centre[0], centre[1], centre[2],
                         inv[0], inv[1], inv[2], Uniform(r, 0.05, 1), at[0], at[1], at[2], n[0], n[1]});
            },
            {},
            [](const Words& in, Words& out) {
                out[0] = Bits(noise::HeightDistribution(Float(in[0]), Float(in[1]), Float(in[2])));
                const noise::TowerF t{Float(in[3]), Float(in[4]), Float(in[5]), Float(in[6]),
                                      Float(in[7]), Float(in[8]), Float(in[9])};
                out[1] = Bits(
                    noise::TowerSum(&t, 1, Float(in[10]), Float(in[11]), Float(in[12]), Float(in[13]), Float(in[14])));
            },
            /*otherDeviceUlps=*/0};
        exps.expUlps = 160;  // |x| log2(e) + a few: exp2 of the rounded x log2(e), |x| < 88 before underflow
        c.push_back(exps);
    }
    AddMarchCases(c);
    AddGroundCases(c);
    AddShaftsCases(c);
    return c;
}

}  // namespace cb::test
