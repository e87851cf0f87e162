// Hand-worked cases for every rule of the automaton (SPEC section 3), each on
// a state small enough to check by eye.
#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "core/math/Random.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

using Voxel = std::tuple<uint32_t, uint32_t, uint32_t>;

struct Fields {
    std::vector<uint8_t> hum, act, cld;
};

class CaRules : public ::testing::Test {
  protected:
    const Extent3 e{9, 9, 9};
    cpu::BackendCpu backend;

    size_t Index(uint32_t i, uint32_t j, uint32_t k) const { return VoxelIndex(e, i, j, k); }
    Fields Empty() const { return {std::vector<uint8_t>(e.Count()), std::vector<uint8_t>(e.Count()), std::vector<uint8_t>(e.Count())}; }

    // One step on the CPU backend with probabilities p (not yet quantised).
    Fields Step(const Fields& in, const std::vector<uint8_t>& region, double pExt, double pHum, double pAct,
                std::vector<int32_t> sx = {}, std::vector<int32_t> sy = {}) {
        auto hum = test::MakeFilled(backend, BufferFormat::Bits, e, in.hum);
        auto act = test::MakeFilled(backend, BufferFormat::Bits, e, in.act);
        auto cld = test::MakeFilled(backend, BufferFormat::Bits, e, in.cld);
        auto r = test::MakeFilled(backend, BufferFormat::U8, e, region);
        auto hum2 = test::MakeBuffer(backend, BufferFormat::Bits, e);
        auto act2 = test::MakeBuffer(backend, BufferFormat::Bits, e);
        auto cld2 = test::MakeBuffer(backend, BufferFormat::Bits, e);
        CaStepParams p{9, 0, QuantizeProbability(pExt), QuantizeProbability(pHum), QuantizeProbability(pAct), sx, sy, {}};
        Status s = backend.CaStep(p, {hum.get(), act.get(), cld.get()}, *r, {hum2.get(), act2.get(), cld2.get()});
        EXPECT_TRUE(s.has_value());
        return {test::Read<uint8_t>(backend, *hum2), test::Read<uint8_t>(backend, *act2), test::Read<uint8_t>(backend, *cld2)};
    }

    std::set<Voxel> Ones(const std::vector<uint8_t>& field) const {
        std::set<Voxel> out;
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i)
                    if (field[Index(i, j, k)]) out.insert({i, j, k});
        return out;
    }
};

// Test that one active voxel in a humid, quiet world activates exactly its 11
// neighbours: i+-1, i+-2, j+-1, j+-2, k+-1 and k+2 (the voxel two above sees it
// as its k-2 neighbour), and that it turns into cloud and loses its humidity.
TEST_F(CaRules, OneActiveVoxelActivatesExactlyItsElevenNeighbours) {
    Fields in = Empty();
    std::fill(in.hum.begin(), in.hum.end(), 1);
    in.act[Index(4, 4, 4)] = 1;
    std::vector<uint8_t> region(e.Count(), 255);
    Fields out = Step(in, region, 0, 0, 0);
    std::set<Voxel> expected = {{3, 4, 4}, {5, 4, 4}, {2, 4, 4}, {6, 4, 4}, {4, 3, 4}, {4, 5, 4},
                                {4, 2, 4}, {4, 6, 4}, {4, 4, 3}, {4, 4, 5}, {4, 4, 6}};
    EXPECT_EQ(Ones(out.act), expected);
    EXPECT_EQ(Ones(out.cld), (std::set<Voxel>{{4, 4, 4}}));
    EXPECT_EQ(out.hum[Index(4, 4, 4)], 0);
    EXPECT_EQ(Ones(out.hum).size(), e.Count() - 1);
}

// Test that activity does not spread two slices down: SPEC's neighbour list has
// k-2 but no k+2, so the voxel at k-2 stays inactive while k+2 activates.
TEST_F(CaRules, NoGrowthTwoSlicesDown) {
    Fields in = Empty();
    std::fill(in.hum.begin(), in.hum.end(), 1);
    in.act[Index(4, 4, 4)] = 1;
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 255), 0, 0, 0);
    EXPECT_EQ(out.act[Index(4, 4, 2)], 0);
    EXPECT_EQ(out.act[Index(4, 4, 6)], 1);
    // Nor diagonally, nor three away.
    EXPECT_EQ(out.act[Index(5, 5, 4)], 0);
    EXPECT_EQ(out.act[Index(7, 4, 4)], 0);
}

// Test that activation needs humidity: without hum nothing grows.
TEST_F(CaRules, NoGrowthWithoutHumidity) {
    Fields in = Empty();
    in.act[Index(4, 4, 4)] = 1;
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 255), 0, 0, 0);
    EXPECT_TRUE(Ones(out.act).empty());
    EXPECT_EQ(Ones(out.cld), (std::set<Voxel>{{4, 4, 4}}));
}

// Test that probability 0 never fires: no humidity, activation or extinction
// appears, whatever the region, so the state only follows the growth rules.
TEST_F(CaRules, ProbabilityZeroNeverFires) {
    Fields in = Empty();
    for (size_t v = 0; v < e.Count(); v += 3) in.cld[v] = 1;
    std::vector<uint8_t> region(e.Count());
    for (size_t v = 0; v < region.size(); ++v) region[v] = uint8_t(1 + v % 255);  // never 0
    Fields out = Step(in, region, 0, 0, 0);
    EXPECT_TRUE(Ones(out.hum).empty());
    EXPECT_TRUE(Ones(out.act).empty());
    EXPECT_EQ(out.cld, in.cld);  // no extinction
}

// Test that probability 1 at R = 255 always fires: every non-humid voxel gains
// humidity and every inactive voxel activates; and that p_ext = 1 at R = 255
// never fires, since extinction scales with 255 - R.
TEST_F(CaRules, ProbabilityOneAlwaysFiresAtFullRegion) {
    Fields in = Empty();
    for (size_t v = 0; v < e.Count(); v += 2) in.cld[v] = 1;
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 255), 1, 1, 1);
    EXPECT_EQ(Ones(out.hum).size(), e.Count());
    EXPECT_EQ(Ones(out.act).size(), e.Count());
    EXPECT_EQ(out.cld, in.cld);
}

// Test that p_ext = 1 at a small region value removes almost all cloud: at
// R = 1, P_ext = (254*2^24 + 127)/255, so each voxel survives with 1/255.
TEST_F(CaRules, ExtinctionAtLowRegionRemovesCloud) {
    Fields in = Empty();
    std::fill(in.cld.begin(), in.cld.end(), 1);
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 1), 1, 0, 0);
    size_t survivors = Ones(out.cld).size();
    EXPECT_LT(survivors, 15u);  // expected 729/255 = 2.9
    // Exactly the voxels whose draw misses the threshold survive.
    const uint32_t pExt = (254u * (1u << 24) + 127u) / 255u;
    for (uint32_t v = 0; v < e.Count(); ++v)
        ASSERT_EQ(out.cld[v], Rand24(9, 0, kStreamExtinction, v) >= pExt) << v;
}

// Test that extinction only removes cloud: a voxel without cloud never gains
// it except through activation (cld1 = cld | act).
TEST_F(CaRules, ExtinctionOnlyWhereThereIsCloud) {
    Fields in = Empty();
    in.cld[Index(1, 1, 1)] = 1;
    in.act[Index(7, 7, 7)] = 1;
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 100), 1, 0, 0);
    for (const Voxel& v : Ones(out.cld)) {
        const auto [i, j, k] = v;
        EXPECT_TRUE(in.cld[Index(i, j, k)] || in.act[Index(i, j, k)]) << i << "," << j << "," << k;
    }
}

// Test that no cloud survives where R = 0, even with p_ext = 0.
TEST_F(CaRules, NoCloudWhereRegionIsZero) {
    Fields in = Empty();
    std::fill(in.cld.begin(), in.cld.end(), 1);
    std::vector<uint8_t> region(e.Count(), 200);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < 4; ++i) region[Index(i, j, k)] = 0;
    Fields out = Step(in, region, 0, 0, 0);
    for (uint32_t v = 0; v < e.Count(); ++v) ASSERT_EQ(out.cld[v], region[v] > 0) << v;
}

// Test advection: a voxel moves by (sx[k], sy[k]) in its own slice, the
// vacated cells fill with 0, and what leaves the grid is gone.
TEST_F(CaRules, AdvectionShiftsWithZeroFill) {
    Fields in = Empty();
    in.cld[Index(2, 2, 0)] = 1;  // slice 0 moves by (+3, -1)
    in.cld[Index(8, 4, 1)] = 1;  // slice 1 moves by (+1, 0): leaves the grid
    in.cld[Index(0, 0, 2)] = 1;  // slice 2 moves by (0, +8)
    in.hum[Index(5, 5, 3)] = 1;  // slice 3 moves by (-5, -5)
    std::vector<int32_t> sx(e.nz, 0), sy(e.nz, 0);
    sx[0] = 3, sy[0] = -1;
    sx[1] = 1;
    sy[2] = 8;
    sx[3] = -5, sy[3] = -5;
    Fields out = Step(in, std::vector<uint8_t>(e.Count(), 255), 0, 0, 0, sx, sy);
    EXPECT_EQ(Ones(out.cld), (std::set<Voxel>{{5, 1, 0}, {0, 8, 2}}));
    EXPECT_EQ(Ones(out.hum), (std::set<Voxel>{{0, 0, 3}}));
}

}  // namespace
}  // namespace cb
