// Constructed boundary cases for every event comparison of the
// automaton (SPEC 1 and 3: an event fires iff rand24 < P, strictly), on every
// kernel path. A random draw lands exactly on a threshold about once in 10^10
// draws on the shipped scenes, so no differential test sees a `<=` for `<`; here
// the published inverse of lowbias32 (tests/LowBias32Inverse.h) builds a seed
// that puts the draw P - 1, P or P + 1 at a chosen step, stream and voxel, and
// the test asserts the outcome SPEC 3 fixes: only P - 1 fires.
//
// Paths: the CPU's scalar and AVX-512 event kernels (impl_cpu/CaKernels.h), the
// whole CPU CaStep and CaInitialize, and the GPU backends (vk, gl packed, gl
// RGBA8) through the Backend interface. Voxels sit at the ends of the 16-lane
// AVX chunks, of the CPU's 64-bit and the GPUs' 32-bit words, in the second
// word and in the partial last word of a row, on a 70 x 3 x 2 grid.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Random.h"
#include "impl_cpu/CaKernels.h"
#include "tests/BackendTestUtil.h"
#include "tests/CaReference.h"
#include "tests/CpuIsaTestUtil.h"
#include "tests/LowBias32Inverse.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// One threshold: region value r (as the event sees it: 255 - R for extinction),
// q = Q(p), and P = (r q + 127) / 255 worked by hand (SPEC 3, uint32 division).
struct EbThreshold {
    uint32_t r, q, p;
};

// r q + 127 = 128 * 255001 + 127 = 32640255 = 255 * 128001 exactly, so at the
// draw P - 1 the division-free form 255 (rand24 + 1) <= r q + 127 is an
// equality: `<=` against `<` there (cmple against cmplt) changes the outcome.
constexpr EbThreshold kEbExact{128, 255001, 128001};
// r = 255: P = (255 q + 127) / 255 = q (the +127 never carries).
constexpr EbThreshold kEbFull{255, 1677722, 1677722};
// r = 1, q = 2^24: (16777216 + 127) / 255 = 16777343 / 255 = 65793 rem 128 (255 * 65793 = 16777215).
constexpr EbThreshold kEbLow{1, 16777216, 65793};
// r = 254, q = 2^24: (4261412864 + 127) / 255 = 4261412991 / 255 = 16711423 rem 126
// (255 * 16711423 = 4261412865). For extinction this is R = 1.
constexpr EbThreshold kEbHigh{254, 16777216, 16711423};
static_assert(128u * 255001u + 127u == 255u * 128001u);
static_assert(255u * 65793u == 16777215u && 16777343u - 16777215u == 128u);
static_assert(255u * 16711423u == 4261412865u && 254u * 16777216u + 127u - 4261412865u == 126u);

constexpr std::array kEbThresholds = {kEbExact, kEbFull, kEbLow, kEbHigh};

// The draws one below, at and one above a threshold P (those in 0 .. 2^24 - 1):
// only P - 1 fires.
struct EbDraw {
    uint32_t draw;
    bool fires;
};
std::vector<EbDraw> EbDrawsAround(uint32_t p) {
    std::vector<EbDraw> out;
    for (const EbDraw& d : {EbDraw{p - 1, true}, EbDraw{p, false}, EbDraw{p + 1, false}})
        if (d.draw < (1u << 24)) out.push_back(d);
    return out;
}

// Test the construction itself: the seeds that the audit worked out in Python
// (notes/i17-audit.md, item 2: step 7, voxel 5, low bits 0) and that each seed
// gives the chosen draw through core's hash.
TEST(CaEventBoundary, SeedConstructionGivesTheChosenDraw) {
    EXPECT_EQ(test::SeedForDraw(128000, 7, kStreamExtinction, 5), 1872996042u);
    EXPECT_EQ(test::SeedForDraw(128001, 7, kStreamHumidity, 5), 2946680795u);
    EXPECT_EQ(test::SeedForDraw(128002, 7, kStreamActivation, 5), 3667648226u);
    Pcg32 rng(2);
    for (int n = 0; n < 1000; ++n) {
        const uint32_t draw = rng.NextU32() >> 8, step = rng.NextU32(), stream = rng.Below(4), voxel = rng.NextU32();
        const uint32_t low = rng.Below(256);
        ASSERT_EQ(Rand24(test::SeedForDraw(draw, step, stream, voxel, low), step, stream, voxel), draw);
        ASSERT_EQ(Rand24FromKey(test::KeyForDraw(draw, voxel, low), voxel), draw);
    }
}

// ---- The CPU event kernels ----------------------------------------------------

using EbKernel = uint64_t (*)(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert);

// For every threshold, polarity, lane and draw: the constructed lane fires iff
// its draw is P - 1; every other lane follows SPEC 3 written out here.
void EbCheckKernel(EbKernel kernel) {
    Pcg32 rng(1717);
    std::vector<uint8_t> region(64 + 64);  // callers pad the region buffer
    // Lanes at both ends of each 16-lane AVX-512 chunk, and the word's ends.
    for (uint32_t lane : {0u, 1u, 15u, 16u, 31u, 32u, 47u, 48u, 62u, 63u})
        for (uint32_t v0 : {0u, 64u, 1000003u, 0xFFFFFFE0u})  // the last wraps the voxel index at lane 32
            for (const EbThreshold& t : kEbThresholds)
                for (bool invert : {false, true})
                    for (const EbDraw& d : EbDrawsAround(t.p)) {
                        for (uint8_t& r : region) r = uint8_t(rng.Below(256));
                        region[lane] = uint8_t(invert ? 255 - t.r : t.r);  // the event sees t.r
                        const uint32_t voxel = v0 + lane;
                        const uint32_t key = test::KeyForDraw(d.draw, voxel, rng.Below(256));
                        ASSERT_EQ(Rand24FromKey(key, voxel), d.draw);
                        const uint64_t bits = kernel(key, v0, region.data(), t.q, invert);
                        ASSERT_EQ((bits >> lane) & 1, uint64_t(d.fires))
                            << "lane " << lane << " v0 " << v0 << " r " << t.r << " q " << t.q << " draw " << d.draw
                            << " (P = " << t.p << ")" << (invert ? " inverted" : "");
                        uint64_t want = 0;
                        for (uint32_t b = 0; b < 64; ++b) {
                            const uint32_t r = invert ? 255u - region[b] : region[b];
                            want |= uint64_t(Rand24FromKey(key, v0 + b) < (r * t.q + 127u) / 255u) << b;
                        }
                        ASSERT_EQ(bits, want) << "other lanes, lane " << lane << " v0 " << v0;
                    }
}

TEST(CaEventBoundary, ScalarKernelAtThresholds) { EbCheckKernel(cpu::EventBitsScalar); }

class CaEventBoundaryVector : public test::OnEveryCpuIsa {};
INSTANTIATE_TEST_SUITE_P(Targets, CaEventBoundaryVector, test::EveryCpuIsa(), test::CpuIsaTestName);

TEST_P(CaEventBoundaryVector, KernelAtThresholds) { EbCheckKernel(cpu::EventBitsVector); }

// ---- Whole stages through the Backend interface --------------------------------

enum class EbEvent { Extinction, Humidity, Activation };

struct EbVoxel {
    uint32_t i, j, k;
};

// On 70 x 3 x 2: lanes 0, 15, 16 and 31 of the first 32- and 64-bit word; 32
// (the GPUs' second word); 63 (the end of the CPU's first word); 64 (the CPU's
// second word, the GPUs' third); 65 and 69 (the partial last word of a row);
// every row and both slices.
constexpr std::array<EbVoxel, 10> kEbVoxels = {{{0, 0, 0},
                                                {15, 0, 0},
                                                {16, 1, 0},
                                                {31, 0, 1},
                                                {32, 2, 0},
                                                {63, 1, 1},
                                                {64, 0, 0},
                                                {65, 2, 1},
                                                {69, 2, 1},
                                                {69, 0, 0}}};

class CaEventBoundaryBackend : public test::BackendTest {
  protected:
    const Extent3 mExtent{70, 3, 2};

    void SetUp() override {
        test::BackendTest::SetUp();
        if (mBackend && !mBackend->Supports(Stage::Ca)) GTEST_SKIP() << "no ca stage";
    }

    uint32_t Index(const EbVoxel& at) const { return VoxelIndex(mExtent, at.i, at.j, at.k); }

    // One CaStep per threshold, voxel and draw: a random state and region
    // around the constructed voxel, whose state meets the event's
    // preconditions (extinction: cld = 1, R > 0; humidity: hum = act = 0;
    // activation: act = 0 and hum = 0, so not hum & f). Its outcome is
    // asserted from SPEC 3; every voxel is compared with tests/CaReference.h.
    void RunStepCases(EbEvent event) {
        Backend& b = *mBackend;
        const size_t n = mExtent.Count();
        auto region = test::MakeBuffer(b, BufferFormat::U8, mExtent);
        std::unique_ptr<Buffer> in[3], out[3];
        for (int f = 0; f < 3; ++f) {
            in[f] = test::MakeBuffer(b, BufferFormat::Bits, mExtent);
            out[f] = test::MakeBuffer(b, BufferFormat::Bits, mExtent);
        }
        const uint32_t stream = event == EbEvent::Extinction ? kStreamExtinction
                                : event == EbEvent::Humidity ? kStreamHumidity
                                                             : kStreamActivation;
        Pcg32 rng(100 + stream);
        uint32_t step = 7;
        for (const EbThreshold& t : kEbThresholds) {
            // Extinction sees 255 - R; R = 255 - 255 = 0 would clear cld whatever the draw.
            if (event == EbEvent::Extinction && t.r == 255) continue;
            const uint8_t r = uint8_t(event == EbEvent::Extinction ? 255 - t.r : t.r);
            for (const EbVoxel& at : kEbVoxels)
                for (const EbDraw& d : EbDrawsAround(t.p)) {
                    ++step;
                    const uint32_t v = Index(at);
                    test::ByteState state;
                    std::vector<uint8_t> regionBytes(n);
                    state.hum.resize(n);
                    state.act.resize(n);
                    state.cld.resize(n);
                    for (size_t u = 0; u < n; ++u) {
                        state.hum[u] = rng.Below(100) < 40;
                        state.act[u] = rng.Below(100) < 15;
                        state.cld[u] = rng.Below(100) < 40;
                        regionBytes[u] = rng.Below(4) == 0 ? 0 : uint8_t(rng.Below(256));
                    }
                    regionBytes[v] = r;
                    if (event == EbEvent::Extinction) {
                        state.cld[v] = 1;
                    } else {
                        state.hum[v] = 0;
                        state.act[v] = 0;
                    }
                    // All three events on, with the same q (the other two draw whatever the seed gives).
                    test::ByteStepParams p{
                        test::SeedForDraw(d.draw, step, stream, v, rng.Below(256)), step, t.q, t.q, t.q, {}, {}};
                    ASSERT_EQ(Rand24(p.seed, step, stream, v), d.draw);
                    ASSERT_TRUE(b.Upload(*region, std::as_bytes(std::span(regionBytes))).has_value());
                    const std::vector<uint8_t>* fields[3] = {&state.hum, &state.act, &state.cld};
                    for (int f = 0; f < 3; ++f)
                        ASSERT_TRUE(b.Upload(*in[f], std::as_bytes(std::span(*fields[f]))).has_value());
                    CaStepParams params;
                    params.seed = p.seed;
                    params.step = step;
                    params.qExt = params.qHum = params.qAct = t.q;
                    const Status s = b.CaStep(params, {in[0].get(), in[1].get(), in[2].get()}, *region,
                                              {out[0].get(), out[1].get(), out[2].get()});
                    ASSERT_TRUE(s.has_value()) << s.error().message;
                    const std::vector<uint8_t> got[3] = {test::Read<uint8_t>(b, *out[0]),
                                                         test::Read<uint8_t>(b, *out[1]),
                                                         test::Read<uint8_t>(b, *out[2])};
                    const std::string where = "voxel (" + std::to_string(at.i) + ", " + std::to_string(at.j) + ", " +
                                              std::to_string(at.k) + "), region " + std::to_string(r) + ", q " +
                                              std::to_string(t.q) + ", draw " + std::to_string(d.draw) +
                                              " (P = " + std::to_string(t.p) + ")";
                    // SPEC 3: extinction clears cld iff it fires; humidity and activation set their bit iff it fires.
                    if (event == EbEvent::Extinction) {
                        ASSERT_EQ(got[2][v], d.fires ? 0 : 1) << "cld at " << where;
                    } else if (event == EbEvent::Humidity) {
                        ASSERT_EQ(got[0][v], d.fires ? 1 : 0) << "hum at " << where;
                    } else {
                        ASSERT_EQ(got[1][v], d.fires ? 1 : 0) << "act at " << where;
                    }
                    const test::ByteState want = test::ReferenceStep(mExtent, state, regionBytes, p);
                    ASSERT_EQ(got[0], want.hum) << "hum elsewhere, " << where;
                    ASSERT_EQ(got[1], want.act) << "act elsewhere, " << where;
                    ASSERT_EQ(got[2], want.cld) << "cld elsewhere, " << where;
                }
        }
    }

    // The initial state (SPEC 3): hum = rand24(seed, 0xFFFFFFFF, 1, v) < Q(hum0),
    // act likewise on stream 2; a constructed draw Q - 1, Q or Q + 1 at each voxel.
    void RunInitCases(uint32_t stream) {
        Backend& b = *mBackend;
        std::unique_ptr<Buffer> out[3];
        for (int f = 0; f < 3; ++f) out[f] = test::MakeBuffer(b, BufferFormat::Bits, mExtent);
        Pcg32 rng(200 + stream);
        // Q(0.35) = round(5872025.6) = 5872026; Q(0.001) = round(16777.216) = 16777.
        for (const auto& [qHum0, qAct0] :
             {std::pair{5872026u, 16777u}, std::pair{16777u, 5872026u}, std::pair{1u, 16777215u}})
            for (const EbVoxel& at : kEbVoxels) {
                const uint32_t q = stream == kStreamHumidity ? qHum0 : qAct0;
                for (const EbDraw& d : EbDrawsAround(q)) {
                    const uint32_t v = Index(at);
                    const uint32_t seed = test::SeedForDraw(d.draw, kInitialStateStep, stream, v, rng.Below(256));
                    ASSERT_EQ(Rand24(seed, 0xFFFFFFFFu, stream, v), d.draw);
                    const Status s = b.CaInitialize({seed, qHum0, qAct0}, {out[0].get(), out[1].get(), out[2].get()});
                    ASSERT_TRUE(s.has_value()) << s.error().message;
                    const std::vector<uint8_t> got[3] = {test::Read<uint8_t>(b, *out[0]),
                                                         test::Read<uint8_t>(b, *out[1]),
                                                         test::Read<uint8_t>(b, *out[2])};
                    const std::string where = "voxel (" + std::to_string(at.i) + ", " + std::to_string(at.j) + ", " +
                                              std::to_string(at.k) + "), draw " + std::to_string(d.draw) +
                                              " (Q = " + std::to_string(q) + ")";
                    const int f = stream == kStreamHumidity ? 0 : 1;
                    ASSERT_EQ(got[f][v], d.fires ? 1 : 0) << (f == 0 ? "hum" : "act") << " at " << where;
                    const test::ByteState want = test::ReferenceInitialState(mExtent, seed, qHum0, qAct0);
                    ASSERT_EQ(got[0], want.hum) << "hum elsewhere, " << where;
                    ASSERT_EQ(got[1], want.act) << "act elsewhere, " << where;
                    ASSERT_EQ(got[2], want.cld) << "cld elsewhere, " << where;
                }
            }
    }
};

TEST_P(CaEventBoundaryBackend, ExtinctionAtThreshold) { RunStepCases(EbEvent::Extinction); }
TEST_P(CaEventBoundaryBackend, HumidityAtThreshold) { RunStepCases(EbEvent::Humidity); }
TEST_P(CaEventBoundaryBackend, ActivationAtThreshold) { RunStepCases(EbEvent::Activation); }
TEST_P(CaEventBoundaryBackend, InitialHumidityAtThreshold) { RunInitCases(kStreamHumidity); }
TEST_P(CaEventBoundaryBackend, InitialActivationAtThreshold) { RunInitCases(kStreamActivation); }

INSTANTIATE_TEST_SUITE_P(Backends, CaEventBoundaryBackend, ::testing::ValuesIn(cb::test::TestBackendsAndCaLayouts()),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace cb
