// The bit-field automaton against the byte-per-voxel reference of
// tests/CaReference.h, on random states of odd sizes over many steps.
#include <gtest/gtest.h>

#include "core/math/Random.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/CaKernels.h"
#include "tests/CaReference.h"
#include "tests/CpuIsaTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

using test::ByteState;

struct CaCase {
    const char* name;
    Extent3 size;
    bool wind;
    int threads;
};

void PrintTo(const CaCase& c, std::ostream* os) { *os << c.name; }

class CaBitfield : public ::testing::TestWithParam<CaCase> {};

std::vector<uint8_t> RandomRegion(const Extent3& e, Pcg32& rng) {
    std::vector<uint8_t> region(e.Count());
    // A third zero, a third full, a third anything: every branch of the rules.
    for (uint8_t& r : region) {
        uint32_t kind = rng.Below(3);
        r = kind == 0 ? 0 : kind == 1 ? 255 : uint8_t(rng.Below(256));
    }
    return region;
}

// Test that N steps of the CPU bit-field automaton equal the byte reference
// bit for bit, every step, with and without wind.
TEST_P(CaBitfield, EqualsByteReferenceEveryStep) {
    const CaCase& c = GetParam();
    const Extent3 e = c.size;
    cpu::BackendCpu backend(c.threads);
    Pcg32 rng(1234 + e.nx);

    const uint32_t seed = 77;
    const uint32_t qHum0 = QuantizeProbability(0.4), qAct0 = QuantizeProbability(0.05);
    ByteState ref = test::ReferenceInitialState(e, seed, qHum0, qAct0);
    // Seed some cloud too, so that extinction has work from the first step.
    for (uint8_t& v : ref.cld) v = rng.Below(4) == 0;

    std::unique_ptr<Buffer> fields[2][3];
    for (auto& state : fields)
        for (auto& f : state) f = test::MakeBuffer(backend, BufferFormat::Bits, e);
    ASSERT_TRUE(backend.Upload(*fields[0][0], std::as_bytes(std::span(ref.hum))));
    ASSERT_TRUE(backend.Upload(*fields[0][1], std::as_bytes(std::span(ref.act))));
    ASSERT_TRUE(backend.Upload(*fields[0][2], std::as_bytes(std::span(ref.cld))));

    // Initial state from the backend equals the reference's.
    {
        auto init = test::MakeBuffer(backend, BufferFormat::Bits, e);
        auto act = test::MakeBuffer(backend, BufferFormat::Bits, e);
        auto cld = test::MakeBuffer(backend, BufferFormat::Bits, e);
        ASSERT_TRUE(backend.CaInitialize({seed, qHum0, qAct0}, {init.get(), act.get(), cld.get()}));
        ByteState fresh = test::ReferenceInitialState(e, seed, qHum0, qAct0);
        EXPECT_EQ(test::Read<uint8_t>(backend, *init), fresh.hum);
        EXPECT_EQ(test::Read<uint8_t>(backend, *act), fresh.act);
        EXPECT_EQ(test::Read<uint8_t>(backend, *cld), std::vector<uint8_t>(e.Count(), 0));
    }

    test::ByteStepParams p;
    p.seed = seed;
    // Large probabilities so that every rule fires often on small grids.
    p.qExt = QuantizeProbability(0.3);
    p.qHum = QuantizeProbability(0.2);
    p.qAct = QuantizeProbability(0.05);
    if (c.wind) {
        for (uint32_t k = 0; k < e.nz; ++k) {
            p.shiftX.push_back(int32_t(k % 5) - 2);    // -2 .. 2
            p.shiftY.push_back(k % 3 == 0 ? 1 : -int32_t(k % 2));
        }
        p.shiftX[0] = 70;  // more than a word: moves everything out
    }

    const int steps = 40;
    int cur = 0;
    for (int t = 0; t < steps; ++t) {
        std::vector<uint8_t> region = RandomRegion(e, rng);
        auto regionBuffer = test::MakeFilled(backend, BufferFormat::U8, e, region);
        p.step = uint32_t(t);
        CaStepParams params{p.seed, p.step, p.qExt, p.qHum, p.qAct, p.shiftX, p.shiftY, {}};
        ASSERT_TRUE(backend.CaStep(params, {fields[cur][0].get(), fields[cur][1].get(), fields[cur][2].get()},
                                   *regionBuffer, {fields[1 - cur][0].get(), fields[1 - cur][1].get(), fields[1 - cur][2].get()}));
        cur = 1 - cur;
        ref = test::ReferenceStep(e, ref, region, p);
        const char* names[3] = {"hum", "act", "cld"};
        const std::vector<uint8_t>* expected[3] = {&ref.hum, &ref.act, &ref.cld};
        for (int f = 0; f < 3; ++f) {
            std::vector<uint8_t> got = test::Read<uint8_t>(backend, *fields[cur][f]);
            for (size_t v = 0; v < got.size(); ++v) {
                ASSERT_EQ(got[v], (*expected[f])[v]) << names[f] << " differs at step " << t << ", voxel (" << v % e.nx
                                                     << ", " << (v / e.nx) % e.ny << ", " << v / (size_t(e.nx) * e.ny) << ")";
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, CaBitfield,
    ::testing::Values(CaCase{"Odd70x33x17", {70, 33, 17}, false, 0}, CaCase{"Odd70x33x17Wind", {70, 33, 17}, true, 0},
                      CaCase{"Exact64x8x4", {64, 8, 4}, false, 0}, CaCase{"Two128x5x6Wind", {128, 5, 6}, true, 0},
                      CaCase{"Just65x3x5OneThread", {65, 3, 5}, true, 1}, CaCase{"Single1x1x1", {1, 1, 1}, false, 0},
                      CaCase{"Column1x1x9", {1, 1, 9}, true, 0}, CaCase{"Row130x1x1", {130, 1, 1}, false, 2}),
    [](const ::testing::TestParamInfo<CaCase>& info) { return std::string(info.param.name); });

// Test every SIMD target's event and mask kernels against the scalar ones they
// replace, on every region value, both polarities and probabilities at the ends.
class CaKernels : public test::OnEveryCpuIsa {};
INSTANTIATE_TEST_SUITE_P(Targets, CaKernels, test::EveryCpuIsa(), test::CpuIsaTestName);

TEST_P(CaKernels, VectorEqualsScalar) {
    std::vector<uint8_t> region(64 * 4 + 64);
    for (size_t n = 0; n < region.size(); ++n) region[n] = uint8_t(n * 37 + 11);
    region[3] = 0;
    region[9] = 255;
    for (uint32_t q : {0u, 1u, 16777u, 1677722u, 1u << 24})
        for (bool invert : {false, true})
            for (uint32_t base : {0u, 64u, 4294967200u})  // the last wraps the voxel index
                for (uint32_t offset = 0; offset < 256; offset += 64) {
                    uint32_t key = StreamKey(3, base, 1);
                    ASSERT_EQ(cpu::EventBitsVector(key, base + offset, region.data() + offset, q, invert),
                              cpu::EventBitsScalar(key, base + offset, region.data() + offset, q, invert));
                    ASSERT_EQ(cpu::NonZeroMaskVector(region.data() + offset), cpu::NonZeroMaskScalar(region.data() + offset));
                }
}

// Test that the result does not depend on the thread count.
TEST(CaBitfield, SameResultForOneAndTwoThreads) {
    const Extent3 e{200, 40, 12};
    std::vector<uint8_t> results[2];
    for (int threads : {1, 2}) {
        cpu::BackendCpu backend(threads);
        std::unique_ptr<Buffer> s[2][3];
        for (auto& state : s)
            for (auto& f : state) f = test::MakeBuffer(backend, BufferFormat::Bits, e);
        ASSERT_TRUE(backend.CaInitialize({5, QuantizeProbability(0.4), QuantizeProbability(0.01)}, {s[0][0].get(), s[0][1].get(), s[0][2].get()}));
        std::vector<uint8_t> region(e.Count(), 200);
        auto r = test::MakeFilled(backend, BufferFormat::U8, e, region);
        int cur = 0;
        for (uint32_t t = 0; t < 20; ++t) {
            CaStepParams params{5, t, QuantizeProbability(0.1), QuantizeProbability(0.1), QuantizeProbability(0.01), {}, {}, {}};
            ASSERT_TRUE(backend.CaStep(params, {s[cur][0].get(), s[cur][1].get(), s[cur][2].get()}, *r,
                                       {s[1 - cur][0].get(), s[1 - cur][1].get(), s[1 - cur][2].get()}));
            cur = 1 - cur;
        }
        results[threads - 1] = test::Read<uint8_t>(backend, *s[cur][2]);
    }
    EXPECT_EQ(results[0], results[1]);
}

}  // namespace
}  // namespace cb
