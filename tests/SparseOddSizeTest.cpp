// Sparse fields on grids whose sizes are not multiples of the
// tile, band or word size, on every backend, against hand-derived outputs.
//
// The odd-size tests elsewhere fill every tile, so a read past the end of a row
// in a partial tile, band or word (which lands on the first voxels of the next
// row) changes nothing there. Here one nonzero voxel sits at (0, j+1, k), where
// a read past row j's end lands, or at its mirror (nx-1, j, k), where a read
// before row j+1's start lands; every other voxel is 0, so each output is known
// exactly: D, tiles, bands and cover of one column; the smoothing kernel around
// one voxel; the 11 growth neighbours of one act bit.
//
// Sizes: 37 x 21 x 9 with tiles of 8 and bands of 4 (partial last tile in x and
// y, partial last band); 33 x 17 x 5 (rows of one and two 32-bit words, one voxel
// in the last); 65 x 3 x 5 (rows of two 64-bit words, one voxel in the last);
// 63 x 5 x 3 (a row ends one voxel short of a word, so a read one or two
// voxels past its end in a packed layout reaches the next row's first word).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

struct SoGrid {
    Extent3 e;
    uint32_t tile, band;
};
// 63 x 5 x 3: one short of two 32-bit words and of one 64-bit word, so a read
// one or two past a row's end (smoothing, growth) lands in the next row's first word.
constexpr std::array<SoGrid, 4> kSoGrids = {
    {{{37, 21, 9}, 8, 4}, {{33, 17, 5}, 8, 4}, {{65, 3, 5}, 32, 4}, {{63, 5, 3}, 8, 2}}};

// One voxel of a sparse case.
struct SoVoxel {
    uint32_t i, j, k;
};

std::string SoWhere(const Extent3& e, const SoVoxel& v) {
    return std::to_string(e.nx) + "x" + std::to_string(e.ny) + "x" + std::to_string(e.nz) + " voxel (" +
           std::to_string(v.i) + ", " + std::to_string(v.j) + ", " + std::to_string(v.k) + ")";
}

// The voxels of a grid: (0, j+1, k) and its mirror (nx-1, j, k), for the first
// rows, a row at a tile edge and the last rows; k in the first, a middle and
// the last slice.
std::vector<SoVoxel> SoVoxels(const SoGrid& g) {
    std::vector<SoVoxel> out;
    const uint32_t nx = g.e.nx, ny = g.e.ny, nz = g.e.nz;
    std::vector<uint32_t> rows = {0, ny - 2};     // row j; j + 1 <= ny - 1
    if (g.tile < ny) rows.push_back(g.tile - 1);  // j + 1 starts the next row of tiles
    for (uint32_t j : rows)
        for (uint32_t k : {0u, nz / 2, nz - 1}) {
            out.push_back({0, j + 1, k});
            out.push_back({nx - 1, j, k});
        }
    return out;
}

class SparseOddSize : public test::BackendTest {};

// Test that one nonzero voxel gives D in its column only, exactly one tile and
// one band (the voxel's), and a cover of one column, with cld given and without.
TEST_P(SparseOddSize, DensityOfOneVoxel) {
    Backend& b = *mBackend;
    if (!b.Supports(Stage::Density)) GTEST_SKIP() << "unsupported here: no density stage";
    for (const SoGrid& g : kSoGrids) {
        const Extent3 e = g.e;
        const Extent3 tilesE{CeilDiv(e.nx, g.tile), CeilDiv(e.ny, g.tile), 1};
        const Extent3 bandsE{tilesE.nx, tilesE.ny, CeilDiv(e.nz, g.band)};
        auto D = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
        auto tiles = test::MakeBuffer(b, BufferFormat::U8, tilesE);
        auto bands = test::MakeBuffer(b, BufferFormat::U8, bandsE);
        for (const SoVoxel& v : SoVoxels(g))
            for (bool withCld : {true, false}) {
                const std::string where = SoWhere(e, v) + (withCld ? ", cld given" : ", no cld");
                std::vector<float> q(e.Count(), 0.0f);
                std::vector<uint8_t> cld(e.Count(), 0);
                q[VoxelIndex(e, v.i, v.j, v.k)] = 0.375f;
                cld[VoxelIndex(e, v.i, v.j, v.k)] = 1;
                auto qb = test::MakeFilled(b, BufferFormat::F32, e, q);
                auto cb = test::MakeFilled(b, BufferFormat::Bits, e, cld);
                DensityOutputs out{D.get(), tiles.get(), bands.get(), 99};
                const Status s = b.Density({g.tile, g.band, {}}, *qb, withCld ? cb.get() : nullptr, out);
                ASSERT_TRUE(s.has_value()) << s.error().message;
                std::vector<float> wantD(size_t(e.nx) * e.ny, 0.0f);
                wantD[v.i + e.nx * v.j] = 0.375f;
                std::vector<uint8_t> wantTiles(tilesE.Count(), 0), wantBands(bandsE.Count(), 0);
                const uint32_t ti = v.i / g.tile, tj = v.j / g.tile, tb = v.k / g.band;
                wantTiles[ti + tilesE.nx * tj] = 1;
                wantBands[ti + tilesE.nx * (tj + tilesE.ny * tb)] = 1;
                EXPECT_EQ(test::Read<float>(b, *D), wantD) << where;
                EXPECT_EQ(test::Read<uint8_t>(b, *tiles), wantTiles) << where;
                EXPECT_EQ(test::Read<uint8_t>(b, *bands), wantBands) << where;
                EXPECT_EQ(out.coveredColumns, 1u) << where;
            }
    }
}

// Test smoothing of one cld voxel at a row's end or start: q is the binomial
// kernel w(di) w(dj) w(dk) / W around it, cut at the grid's faces, and 0 on the
// neighbouring row's other end (where a wrapped read would put it).
TEST_P(SparseOddSize, SmoothOfOneVoxel) {
    Backend& b = *mBackend;
    if (!b.Supports(Stage::Smooth)) GTEST_SKIP() << "unsupported here: no smooth stage";
    const std::array<std::vector<float>, 3> weights = {std::vector<float>{1},  // r = 0: q = cld
                                                       std::vector<float>{1, 2, 1}, std::vector<float>{1, 4, 6, 4, 1}};
    const float W[3] = {1, 64, 4096};
    for (const SoGrid& g : kSoGrids) {
        const Extent3 e = g.e;
        auto q = test::MakeBuffer(b, BufferFormat::F32, e);
        for (const SoVoxel& v : SoVoxels(g)) {
            std::vector<uint8_t> cld(e.Count(), 0);
            cld[VoxelIndex(e, v.i, v.j, v.k)] = 1;
            auto cb = test::MakeFilled(b, BufferFormat::Bits, e, cld);
            for (int r = 0; r <= 2; ++r) {
                ASSERT_TRUE(b.Smooth(r, *cb, *q).has_value());
                std::vector<float> want(e.Count(), 0.0f);
                for (int dk = -r; dk <= r; ++dk)
                    for (int dj = -r; dj <= r; ++dj)
                        for (int di = -r; di <= r; ++di) {
                            const int64_t i = int64_t(v.i) + di, j = int64_t(v.j) + dj, k = int64_t(v.k) + dk;
                            if (i < 0 || j < 0 || k < 0 || i >= e.nx || j >= e.ny || k >= e.nz) continue;
                            want[VoxelIndex(e, uint32_t(i), uint32_t(j), uint32_t(k))] =
                                weights[r][di + r] * weights[r][dj + r] * weights[r][dk + r] / W[r];
                        }
                ASSERT_EQ(test::Read<float>(b, *q), want) << SoWhere(e, v) << ", radius " << r;
            }
        }
    }
}

// Test growth from one act bit at a row's end or start (SPEC 3, with R = 255
// and every probability 0, so nothing is random): act moves to exactly the
// in-grid growth neighbours of the bit (v with the bit at v + d, d one of
// i+-1, i+-2, j+-1, j+-2, k+-1, k-2), never to the next row's start or the previous
// row's end; hum is cleared at the bit and cld set there.
class SparseOddSizeCa : public test::BackendTest {};

TEST_P(SparseOddSizeCa, GrowthFromOneActBit) {
    Backend& b = *mBackend;
    if (!b.Supports(Stage::Ca)) GTEST_SKIP() << "unsupported here: no ca stage";
    // The voxels v that the bit at a activates: a - d for each growth offset d.
    constexpr std::array<std::array<int, 3>, 11> kActivated = {
        {{-1, 0, 0},
         {1, 0, 0},
         {-2, 0, 0},
         {2, 0, 0},
         {0, -1, 0},
         {0, 1, 0},
         {0, -2, 0},
         {0, 2, 0},
         {0, 0, -1},
         {0, 0, 1},
         {0, 0, 2}}};  // k + 2 reads the bit as its k - 2 neighbour
    for (const SoGrid& g : kSoGrids) {
        const Extent3 e = g.e;
        const size_t n = e.Count();
        auto region = test::MakeFilled(b, BufferFormat::U8, e, std::vector<uint8_t>(n, 255));
        std::unique_ptr<Buffer> out[3];
        for (auto& f : out) f = test::MakeBuffer(b, BufferFormat::Bits, e);
        for (const SoVoxel& a : SoVoxels(g)) {
            const uint32_t va = VoxelIndex(e, a.i, a.j, a.k);
            std::vector<uint8_t> hum(n, 1), act(n, 0), cld(n, 0);
            act[va] = 1;
            auto hb = test::MakeFilled(b, BufferFormat::Bits, e, hum);
            auto ab = test::MakeFilled(b, BufferFormat::Bits, e, act);
            auto cb = test::MakeFilled(b, BufferFormat::Bits, e, cld);
            CaStepParams p;  // q* = 0: P_ext = (0 + 127) / 255 = 0, P_hum = P_act = 127 / 255 = 0
            p.seed = 12345;
            p.step = 3;
            const Status s =
                b.CaStep(p, {hb.get(), ab.get(), cb.get()}, *region, {out[0].get(), out[1].get(), out[2].get()});
            ASSERT_TRUE(s.has_value()) << s.error().message;
            std::vector<uint8_t> wantHum(n, 1), wantAct(n, 0), wantCld(n, 0);
            wantHum[va] = 0;
            wantCld[va] = 1;
            for (size_t d = 0; d < kActivated.size(); ++d) {
                const int64_t i = int64_t(a.i) + kActivated[d][0], j = int64_t(a.j) + kActivated[d][1],
                              k = int64_t(a.k) + kActivated[d][2];
                if (i < 0 || j < 0 || k < 0 || i >= e.nx || j >= e.ny || k >= e.nz) continue;
                wantAct[VoxelIndex(e, uint32_t(i), uint32_t(j), uint32_t(k))] = 1;
            }
            const std::string where = SoWhere(e, a);
            const std::vector<uint8_t> gotAct = test::Read<uint8_t>(b, *out[1]);
            // The named cases first: the next row's first voxel and the previous row's last.
            if (a.i == e.nx - 1 && a.j + 1 < e.ny) {
                EXPECT_EQ(gotAct[VoxelIndex(e, 0, a.j + 1, a.k)], 0) << "(0, j+1, k) activated from " << where;
            }
            if (a.i == 0 && a.j >= 1) {
                EXPECT_EQ(gotAct[VoxelIndex(e, e.nx - 1, a.j - 1, a.k)], 0)
                    << "(nx-1, j-1, k) activated from " << where;
            }
            EXPECT_EQ(gotAct, wantAct) << "act from " << where;
            EXPECT_EQ(test::Read<uint8_t>(b, *out[0]), wantHum) << "hum from " << where;
            EXPECT_EQ(test::Read<uint8_t>(b, *out[2]), wantCld) << "cld from " << where;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, SparseOddSize, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const auto& info) { return std::string(info.param); });
INSTANTIATE_TEST_SUITE_P(Backends, SparseOddSizeCa, ::testing::ValuesIn(cb::test::TestBackendsAndCaLayouts()),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace cb
