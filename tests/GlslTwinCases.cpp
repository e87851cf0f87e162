// The cases of the GLSL twin tests (GlslTwinTest.cpp): every function of
// core/glsl but MakeSplat, grouped by its GLSL file, with random inputs,
// hand-picked edges and the C++ twin.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "GlslTwinHarness.h"
#include "core/Automaton.h"
#include "core/Random.h"
#include "core/Rules.h"
#include "core/Shading.h"
#include "core/Splat.h"

namespace cb::test {

std::vector<TwinCase> Cases() {
    std::vector<TwinCase> c;
    const uint32_t kQ1 = 1u << 24;  // probability 1

    // ---- random.glsl ----
    c.push_back({"LowBias32",
                 0,
                 {Kind::U},
                 [](Pcg32& r, Words& in) { in[0] = r.NextU32(); },
                 {W({0}), W({1}), W({0xffffffffu}), W({0x80000000u})},
                 [](const Words& in, Words& out) { out[0] = LowBias32(in[0]); }});
    c.push_back({"StreamKey",
                 1,
                 {Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32(), r.Below(4)});
                 },
                 {W({0, 0, 0}), W({0, kInitialStateStep, 1}), W({0xffffffffu, kInitialStateStep, 3})},
                 [](const Words& in, Words& out) { out[0] = StreamKey(in[0], in[1], in[2]); }});
    c.push_back({"Rand24FromKey",
                 2,
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
                     3,
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
                     4,
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
        c.push_back({"QuantizeRegion",
                     5,
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
                     6,
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
                     7,
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
    c.push_back({"RoundToHalf",
                 8,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     // Any float of magnitude < 2^18 (random sign, exponent and mantissa), or one in [0, 1].
                     const uint32_t bits = (r.NextU32() & 0x807fffffu) | (r.Below(145) << 23);
                     in = r.Below(2) ? W({bits}) : WF({Uniform(r, 0, 1)});
                 },
                 halfEdges,
                 [](const Words& in, Words& out) { out[0] = Bits(RoundToHalf(Float(in[0]))); }});
    std::vector<Words> unormEdges;
    for (float x : {0.0f, -0.0f, 1.0f, -0.5f, 1.5f}) unormEdges.push_back(WF({x}));
    for (int k = 0; k < 255; k += 3)  // 255 v = k + 0.5: the ties
        for (float v : AndNeighbours((float(k) + 0.5f) / 255.0f)) unormEdges.push_back(WF({v}));
    c.push_back({"RoundToUnorm8",
                 9,
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
        c.push_back(
            {"RoundToStorage",
             10,
             {Kind::F},
             [](Pcg32& r, Words& in) {
                 in = W({r.Below(3), Bits(Uniform(r, 0, 1))});
             },
             edges,
             [](const Words& in, Words& out) { out[0] = Bits(RoundToStorage(StorageFormat(in[0]), Float(in[1]))); }});
    }
    c.push_back({"Lerp",
                 11,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, -2, 2), Uniform(r, -2, 2), Uniform(r, 0, 1)});
                 },
                 {WF({0.25f, 0.75f, 0}), WF({0.25f, 0.75f, 1}), WF({1, 1, 0.5f})},
                 [](const Words& in, Words& out) { out[0] = Bits(Lerp(Float(in[0]), Float(in[1]), Float(in[2]))); }});
    c.push_back({"Bilinear",
                 12,
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
                 13,
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
                 14,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, -0.2, 1.2), Uniform(r, -0.2, 1.2)});
                 },
                 {WF({0.5f, 0.5f}), WF({0, 0}), WF({1, 0.5f}), WF({0.5f, 0})},
                 [](const Words& in, Words& out) { out[0] = Bits(SplatKernel(Float(in[0]), Float(in[1]))); }});
    c.push_back({"SliceFactor",
                 15,
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
                 16,
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
                 17,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = W({r.Below(2), Bits(Uniform(r, 0, 1)), Bits(Uniform(r, 0, 0.1)), Bits(Uniform(r, 0, 100))});
                 },
                 {W({1, Bits(0.5f), 0, 0}), W({0, 0, Bits(0.05f), Bits(20.0f)}), W({0, 0, Bits(0.05f), Bits(40.0f)}),
                  W({1, Bits(10.0f), 0, Bits(100.0f)})},
                 [](const Words& in, Words& out) {
                     out[0] = Bits(GroundShadow(in[0] != 0, Float(in[1]), Float(in[2]), Float(in[3])));
                 }});
    {
        std::vector<Words> edges;
        for (uint32_t f : {1u, 2u, 4u})
            for (uint32_t cells : {1u, 2u, 3u, 16u})
                for (uint32_t i : {0u, f * cells - 1, f * cells / 2}) edges.push_back(W({i, f, cells}));
        c.push_back({"UpsampleTap",
                     18,
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
                 19,
                 {Kind::U},
                 [](Pcg32& r, Words& in) {
                     in = W({r.NextU32(), r.NextU32(), r.NextU32()});
                 },
                 {W({0, 0, 0}), W({1, 0, 0}), W({0x80000000u, 0, 0}), W({0, 0xc0000000u, 3})},
                 [](const Words& in, Words& out) { out[0] = CaRowNeighbours<uint32_t>(in[0], in[1], in[2]); }});
    c.push_back({"CaGrowth",
                 20,
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
                     21,
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
                     22,
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
                     23,
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
                 24,
                 {Kind::F},
                 [](Pcg32& r, Words& in) {
                     in = WF({Uniform(r, 0, 1), Uniform(r, 0, 1), Uniform(r, 0, 1)});
                 },
                 {WF({0.25f, 0.75f, 0}), WF({0.25f, 0.75f, 1}), WF({0, 0, 0.5f})},
                 [](const Words& in, Words& out) { out[0] = Bits(SplatQ(Float(in[0]), Float(in[1]), Float(in[2]))); }});
    c.push_back(
        {"SplatCoord",
         25,
         {Kind::F},
         [](Pcg32& r, Words& in) {
             in = WF({float(r.Below(1024)) + 0.5f, Uniform(r, -100, 1100), Uniform(r, 1, 255)});
         },
         {WF({10.5f, 10.5f, 4}), WF({8.5f, 10.5f, 4}), WF({0.5f, 0.25f, 1})},
         [](const Words& in, Words& out) { out[0] = Bits(SplatCoord(Float(in[0]), Float(in[1]), Float(in[2]))); },
         /*otherDeviceUlps=*/3});
    c.push_back(
        {"SplatAlpha",
         26,
         {Kind::F},
         [](Pcg32& r, Words& in) {
             in = WF({Uniform(r, 0, 1.5), Uniform(r, -0.2, 1.2), Uniform(r, -0.2, 1.2)});
         },
         {WF({0.6f, 0.5f, 0.5f}), WF({2, 0.5f, 0.5f}), WF({0.6f, 0, 0})},
         [](const Words& in, Words& out) { out[0] = Bits(SplatAlpha(Float(in[0]), Float(in[1]), Float(in[2]))); }});
    return c;
}

}  // namespace cb::test
