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
// derived from those floats within 1). The noise forming's two functions that
// call exp (HD, a Gaussian tower) state `expUlps` on every device: GLSL's exp
// is the driver's and glibc's expf is not, so they are not bit-exact even on
// lavapipe (the stage itself reads HD from the host; a tower's error is well
// inside SPEC 10a's 1e-5). Nothing else gets any slack.
//
// Also here, without Vulkan: the CPU's bit-parallel automaton word
// (impl_cpu/CaKernels.h CaStepWord) against the per-voxel twin.
//
// The harness is in GlslTwinHarness.h/.cpp, the cases in GlslTwinCases.cpp.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "GlslTwinHarness.h"
#include "core/Automaton.h"
#include "core/Camera.h"
#include "core/Random.h"
#include "core/Rules.h"
#include "core/Shading.h"
#include "core/Splat.h"
#include "impl_cpu/CaKernels.h"

namespace cb {
namespace {

using test::Bits;
using test::Cases;
using test::Compare;
using test::Float;
using test::Kind;
using test::kRandomPerCase;
using test::TwinCase;
using test::Uniform;
using test::W;
using test::Words;

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

#if CLOUDBENCH_HAVE_VK

using test::GlslTwin;

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
        Compare(c.name, c.outputs, std::max(c.expUlps, sExact ? 0u : c.otherDeviceUlps), inputs,
                Run(c.fn, inputs, SplatFrame{}), c.cpp);
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
