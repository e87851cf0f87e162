// Every function of core/glsl against its C++ twin in core/ (issue 10, item 7):
// tests/twin/twin.comp runs the GLSL on a Vulkan device, on random inputs and
// hand-picked edges (ties, zeros, boundaries), and each output is compared with
// the C++ bit for bit.
//
// Tolerances. On lavapipe (a device of type "cpu", what CI and `conform` use)
// every case must be bit-exact: float + - * round correctly everywhere, the
// twins are written `precise` where the C++ (built with -ffp-contract=off)
// does not fuse, and lavapipe's / and sqrt are correctly rounded. Another
// Vulkan device may compute x / y within 2.5 ulp and sqrt as 1/inversesqrt,
// so the cases that divide by something other than a power of two or take a
// square root state `otherDeviceUlps` (floats within that many ulps, integers
// derived from those floats within 1). Nothing else gets any slack.
//
// Also here, without Vulkan: the CPU's bit-parallel automaton word
// (impl_cpu/CaKernels.h CaStepWord) against the per-voxel twin.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/Automaton.h"
#include "core/Camera.h"
#include "core/Random.h"
#include "core/Rules.h"
#include "core/Shading.h"
#include "core/Splat.h"
#include "impl_cpu/CaKernels.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/VulkanContext.h"
#include "twin.spv.h"
#endif

namespace cb {
namespace {

// One element: 16 input words, 16 output words; floats as their bits.
using Words = std::array<uint32_t, 16>;
constexpr uint32_t kRandomPerCase = 4096;

uint32_t Bits(float f) { return std::bit_cast<uint32_t>(f); }
float Float(uint32_t u) { return std::bit_cast<float>(u); }
float Uniform(Pcg32& rng, double lo, double hi) { return float(rng.Uniform(lo, hi)); }
int32_t Int(uint32_t u) { return int32_t(u); }

enum class Kind : uint8_t { U, I, F };  // how an output word compares

struct TwinCase {
    const char* name;
    uint32_t fn;  // the `fn` of twin.comp
    std::vector<Kind> outputs;
    std::function<void(Pcg32&, Words&)> random;
    std::vector<Words> edges;
    std::function<void(const Words&, Words&)> cpp;
    uint32_t otherDeviceUlps = 0;  // see the top of this file
};

Words W(std::initializer_list<uint32_t> words) {
    Words w{};
    std::copy(words.begin(), words.end(), w.begin());
    return w;
}
Words WF(std::initializer_list<float> floats) {
    Words w{};
    size_t n = 0;
    for (float f : floats) w[n++] = Bits(f);
    return w;
}

// Floats next to x: x itself and one ulp either side.
std::vector<float> AndNeighbours(float x) { return {std::nextafter(x, -INFINITY), x, std::nextafter(x, INFINITY)}; }

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

// The MakeSplat case: a frame (a random camera around a 64 x 64 x 16 grid) and
// voxels of it, some behind the eye or below q_min.
constexpr uint32_t kMakeSplatFn = 27;
const std::vector<Kind> kSplatOutputs = {Kind::U, Kind::F, Kind::F, Kind::F, Kind::F, Kind::F,
                                         Kind::F, Kind::F, Kind::I, Kind::I, Kind::I, Kind::I};

SplatFrame RandomSplatFrame(Pcg32& r) {
    CameraSettings camera;
    camera.eye = {r.Uniform(-1000, 4200), r.Uniform(-1000, 4200), r.Uniform(0, 1500)};
    camera.target = {r.Uniform(0, 3200), r.Uniform(0, 3200), r.Uniform(0, 800)};
    camera.fovDeg = r.Uniform(30, 90);
    const uint32_t width = 64 + r.Below(1024), height = 64 + r.Below(768);
    const CameraFrame f = MakeCameraFrame(camera, width, height);
    const Vec3 sun = SunDirection(r.Uniform(0.1, 1.5), r.Uniform(0, 6.28));
    SplatFrame F{};
    F.grid[0] = 64, F.grid[1] = 64, F.grid[2] = 16;
    F.image[0] = width, F.image[1] = height;
    for (int a = 0; a < 3; ++a) {
        F.eye[a] = f.eye[a];
        F.forward[a] = f.forward[a];
        F.right[a] = f.right[a];
        F.up[a] = f.upVector[a];
        F.sun[a] = sun[a];
        F.sunRadiance[a] = Uniform(r, 0, 2);
        F.ambient[a] = Uniform(r, 0, 0.3);
        F.origin[a] = 0;
    }
    F.eye[3] = f.nearPlane;
    F.forward[3] = f.focalPx;
    F.sun[3] = Uniform(r, -0.9, 0.9);
    F.sunRadiance[3] = float(r.Below(3));
    F.ambient[3] = 0.3f;
    F.background[3] = 0.6f;
    F.origin[3] = 50;
    F.misc[0] = 75, F.misc[1] = 0.5f;
    return F;
}

Words RandomVoxel(Pcg32& r) {
    return W({r.Below(64), r.Below(64), r.Below(16), Bits(r.Below(4) == 0 ? 0.3f : Uniform(r, 0, 1)),
              Bits(Uniform(r, 0, 1))});
}

void MakeSplatCpp(const SplatFrame& F, const Words& in, Words& out) {
    Splat s;
    const bool made = MakeSplat(F, in[0], in[1], in[2], Float(in[3]), Float(in[4]), s);
    out = W({uint32_t(made), Bits(s.px), Bits(s.py), Bits(s.size), Bits(s.alphaScale), Bits(s.colour[0]),
             Bits(s.colour[1]), Bits(s.colour[2]), uint32_t(s.x0), uint32_t(s.x1), uint32_t(s.y0), uint32_t(s.y1)});
}

// |a - b| in ulps (floats), or as integers.
uint64_t Distance(Kind kind, uint32_t a, uint32_t b) {
    if (kind == Kind::F) {
        if (std::isnan(Float(a)) && std::isnan(Float(b))) return 0;
        auto ordered = [](uint32_t u) { return (u >> 31) ? -int64_t(u & 0x7fffffffu) : int64_t(u); };
        return uint64_t(std::llabs(ordered(a) - ordered(b)));
    }
    if (kind == Kind::I) return uint64_t(std::llabs(int64_t(Int(a)) - int64_t(Int(b))));
    return a == b ? 0 : UINT64_MAX;
}

// Compares the GLSL's outputs with the C++ twin's, element by element; the
// failure message shows the first few mismatches with their inputs.
void Compare(const char* name, const std::vector<Kind>& kinds, uint32_t ulps, const std::vector<Words>& inputs,
             const std::vector<Words>& glsl, const std::function<void(const Words&, Words&)>& cpp) {
    int reported = 0;
    size_t failures = 0;
    for (size_t n = 0; n < inputs.size(); ++n) {
        Words expected{};
        cpp(inputs[n], expected);
        for (size_t k = 0; k < kinds.size(); ++k) {
            const uint64_t allowed = kinds[k] == Kind::F ? ulps : std::min<uint32_t>(ulps, 1);
            if (Distance(kinds[k], glsl[n][k], expected[k]) <= allowed) continue;
            ++failures;
            if (reported++ < 5) {
                std::string in;
                for (int w = 0; w < 11; ++w) in += std::to_string(inputs[n][w]) + (w < 10 ? "," : "");
                ADD_FAILURE() << name << " input #" << n << " {" << in << "} output " << k << ": glsl 0x" << std::hex
                              << glsl[n][k] << " (" << Float(glsl[n][k]) << "), c++ 0x" << expected[k] << " ("
                              << Float(expected[k]) << ")" << std::dec;
            }
        }
    }
    EXPECT_EQ(failures, 0u) << name << ": " << failures << " mismatches in " << inputs.size() << " inputs";
}

#if CLOUDBENCH_HAVE_VK

class GlslTwin : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        auto context = vk::VulkanContext::Create("", false);
        if (!context) {
            sSkipReason = "no Vulkan device: " + context.error().message;
            return;
        }
        sContext = std::move(*context);
        auto devices = vk::ListDevices();
        if (devices)
            for (const vk::DeviceInfo& d : *devices)
                if (d.name == sContext->DeviceName()) sExact = d.type == "cpu";
    }
    static void TearDownTestSuite() { sContext.reset(); }
    void SetUp() override {
        if (!sContext) GTEST_SKIP() << sSkipReason;
    }

    // Runs twin.comp's function `fn` on `inputs` with `frame` bound.
    static std::vector<Words> Run(uint32_t fn, const std::vector<Words>& inputs, const SplatFrame& frame) {
        vk::VulkanContext& ctx = *sContext;
        const VkDeviceSize bytes = inputs.size() * sizeof(Words);
        auto pipeline = ctx.GetPipeline("twin", 3, kSpirv_twin);
        auto in = ctx.CreateBuffer(bytes);
        auto out = ctx.CreateBuffer(bytes);
        auto frameBuffer = ctx.CreateBuffer(sizeof frame);
        std::vector<Words> result(inputs.size());
        if (!pipeline || !in || !out || !frameBuffer) {
            ADD_FAILURE() << "could not set up the twin pipeline";
            return result;
        }
        EXPECT_TRUE(ctx.Upload(*in, std::as_bytes(std::span(inputs))));
        EXPECT_TRUE(ctx.Upload(*frameBuffer, std::as_bytes(std::span(&frame, 1))));
        const struct { uint32_t fn, count; } push{fn, uint32_t(inputs.size())};
        const vk::DeviceBuffer* buffers[] = {&*in, &*out, &*frameBuffer};
        auto ran = ctx.Run("twin", [&](vk::VulkanContext::Recorder& r) {
            r.Dispatch(**pipeline, buffers, &push, sizeof push, push.count);
        });
        EXPECT_TRUE(ran) << (ran ? "" : ran.error().message);
        EXPECT_TRUE(ctx.Download(*out, std::as_writable_bytes(std::span(result))));
        ctx.DestroyBuffer(*in);
        ctx.DestroyBuffer(*out);
        ctx.DestroyBuffer(*frameBuffer);
        return result;
    }

    static inline std::unique_ptr<vk::VulkanContext> sContext;
    static inline std::string sSkipReason;
    static inline bool sExact = false;  // lavapipe: every case bit-exact
};

// Test that every GLSL function of core/glsl equals its C++ twin on 4096
// random inputs and the hand-picked edges (bit-exact on lavapipe).
TEST_F(GlslTwin, EveryFunctionEqualsItsCppTwin) {
    for (const TwinCase& c : Cases()) {
        SCOPED_TRACE(c.name);
        Pcg32 rng(0x7717 + c.fn);
        std::vector<Words> inputs = c.edges;
        for (uint32_t n = 0; n < kRandomPerCase; ++n) {
            Words w{};
            c.random(rng, w);
            inputs.push_back(w);
        }
        Compare(c.name, c.outputs, sExact ? 0 : c.otherDeviceUlps, inputs, Run(c.fn, inputs, SplatFrame{}), c.cpp);
    }
}

// Test that MakeSplat (position, size, colour, alpha scale, covered pixels,
// and whether a splat is made at all) equals the C++ for random cameras.
TEST_F(GlslTwin, MakeSplatEqualsItsCppTwin) {
    Pcg32 rng(0x5917);
    uint32_t made = 0, total = 0;
    for (int frameIndex = 0; frameIndex < 16; ++frameIndex) {
        const SplatFrame frame = RandomSplatFrame(rng);
        std::vector<Words> inputs;
        for (uint32_t n = 0; n < 1024; ++n) inputs.push_back(RandomVoxel(rng));
        Compare("MakeSplat", kSplatOutputs, sExact ? 0 : 4, inputs, Run(kMakeSplatFn, inputs, frame),
                [&](const Words& in, Words& out) {
                    MakeSplatCpp(frame, in, out);
                    made += out[0];
                    ++total;
                });
    }
    // Both outcomes are well represented (splats made, and rejected by q_min or the near plane).
    EXPECT_GT(made, total / 5);
    EXPECT_LT(made, total - total / 10);
}

#endif  // CLOUDBENCH_HAVE_VK

// Test that the CPU's 64-voxel automaton word (growth and the three events at
// once, bit-parallel) equals the shared per-voxel rules applied bit by bit,
// on random words, regions (a third 0, a third 255) and probabilities.
TEST(CaTwin, CpuWordEqualsPerVoxelRules) {
    Pcg32 rng(0xca64);
    for (int n = 0; n < 20000; ++n) {
        const uint32_t validBits = n % 4 == 0 ? 1 + rng.Below(64) : 64;
        const uint64_t valid = validBits == 64 ? ~0ull : (1ull << validBits) - 1;
        auto word = [&] { return (uint64_t(rng.NextU32()) << 32 | rng.NextU32()) & valid; };
        const CaBits<uint64_t> s{word(), word(), word()};
        const uint64_t f = word();
        uint8_t region[64];
        for (uint8_t& r : region) {
            const uint32_t kind = rng.Below(3);
            r = kind == 0 ? 0 : kind == 1 ? 255 : uint8_t(rng.Below(256));
        }
        auto q = [&] { return rng.Below(4) == 0 ? (1u << 24) : QuantizeProbability(rng.NextDouble() * 0.5); };
        const CaEvents e = MakeCaEvents(rng.NextU32(), rng.NextU32(), q(), q(), q());
        const uint32_t v0 = rng.NextU32();
        const CaBits<uint64_t> word64 = cpu::CaStepWord(s, f, region, valid, v0, e);
        for (uint32_t b = 0; b < 64; ++b) {
            const auto bit = [b](uint64_t w) { return uint32_t(w >> b & 1); };
            const CaBits<uint32_t> expected =
                (valid >> b & 1) ? CaVoxelEvents(CaGrowth<uint32_t>({bit(s.hum), bit(s.act), bit(s.cld)}, bit(f)),
                                                 region[b], v0 + b, e)
                                 : CaBits<uint32_t>{0, 0, 0};
            ASSERT_EQ((CaBits<uint32_t>{bit(word64.hum), bit(word64.act), bit(word64.cld)}), expected)
                << "word " << n << " bit " << b;
        }
    }
}

// Test that the in-row growth neighbours of a word are act at i +- 1 and i +- 2
// (kGrowthNeighbours' x entries), across word edges, for both word widths.
TEST(CaTwin, RowNeighboursAreTheXNeighbours) {
    Pcg32 rng(0x0b17);
    for (int n = 0; n < 2000; ++n) {
        const uint64_t row[3] = {uint64_t(rng.NextU32()) << 32 | rng.NextU32(),
                                 uint64_t(rng.NextU32()) << 32 | rng.NextU32(),
                                 uint64_t(rng.NextU32()) << 32 | rng.NextU32()};
        auto act = [&](int i) { return i >= 0 && i < 192 && (row[i / 64] >> (i % 64) & 1); };
        const uint64_t f64 = CaRowNeighbours<uint64_t>(row[1], row[0], row[2]);
        const uint32_t f32 = CaRowNeighbours<uint32_t>(uint32_t(row[1] >> 32), uint32_t(row[1]), uint32_t(row[2]));
        for (int b = 0; b < 64; ++b) {
            bool expected = false;
            for (const GridOffset& o : kGrowthNeighbours)
                if (o.dj == 0 && o.dk == 0) expected |= act(64 + b + o.di);
            ASSERT_EQ(bool(f64 >> b & 1), expected) << b;
            if (b >= 32) {
                ASSERT_EQ(bool(f32 >> (b - 32) & 1), expected) << b;
            }
        }
    }
}

}  // namespace
}  // namespace cb
