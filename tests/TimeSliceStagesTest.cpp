// Time-slicing at the stage level (SPEC 13, core/pipeline/Backend.h SliceRange): a
// stage run as a sequence of shares, ascending and each once, must leave
// exactly the outputs of the whole call, byte for byte, on every backend.
// Each output starts filled with a pattern no stage writes, so a share that
// leaves part of its slices unwritten, or writes past them, fails. Odd grids,
// and share sizes that do not divide the share count.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "core/math/Random.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/ShadePlan.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

constexpr Extent3 kGrid{37, 29, 11};
// Share sizes: one slice, sizes that leave a short last share, and more than the count.
constexpr uint32_t kShareSizes[] = {1, 3, 4, 64};

// The shares [0, s), [s, 2s), ... of `count` slices.
std::vector<SliceRange> Shares(uint32_t count, uint32_t size) {
    std::vector<SliceRange> shares;
    for (uint32_t b = 0; b < count; b += size) shares.push_back({b, std::min(count, b + size)});
    return shares;
}

class TimeSliceStages : public test::BackendTest {
  protected:
    // A buffer holding a pattern no stage writes: 0xA5 bytes for U8, 1 for bits
    // (a full field), -1 for floats.
    std::unique_ptr<Buffer> Patterned(BufferFormat format, Extent3 extent) {
        auto buffer = test::MakeBuffer(*mBackend, format, extent);
        Fill(*buffer);
        return buffer;
    }
    void Fill(Buffer& buffer) {
        std::vector<std::byte> bytes(buffer.CanonicalBytes());
        if (buffer.Format() == BufferFormat::F32) {
            const float minusOne = -1.0f;
            for (size_t n = 0; n < bytes.size(); n += 4) std::memcpy(&bytes[n], &minusOne, 4);
        } else {
            std::fill(bytes.begin(), bytes.end(), std::byte(buffer.Format() == BufferFormat::Bits ? 1 : 0xA5));
        }
        ASSERT_TRUE(mBackend->Upload(buffer, bytes));
    }
    std::vector<std::byte> Bytes(const Buffer& buffer) { return test::Read<std::byte>(*mBackend, buffer); }

    // Runs `call(whole)` into the outputs, then for each share size refills them
    // and runs `call(share)` per share; the bytes must equal the whole call's.
    // `decoy`, if given, runs the stage whole on other inputs before each sequence
    // of shares, so scratch a backend keeps between calls holds another call's
    // data: a share that relied on the whole call's scratch fails.
    void ExpectSharesEqualWhole(const std::string& what, uint32_t count, const std::vector<Buffer*>& outputs,
                                const std::function<Status(SliceRange)>& call,
                                const std::function<Status()>& decoy = {}) {
        for (Buffer* out : outputs) Fill(*out);
        Status whole = call(SliceRange{});
        ASSERT_TRUE(whole.has_value()) << what << ": " << whole.error().message;
        std::vector<std::vector<std::byte>> expected;
        for (Buffer* out : outputs) expected.push_back(Bytes(*out));
        for (uint32_t size : kShareSizes) {
            for (Buffer* out : outputs) Fill(*out);
            if (decoy) {
                ASSERT_TRUE(decoy().has_value()) << what << ": the decoy call";
            }
            for (SliceRange share : Shares(count, size)) {
                Status s = call(share);
                ASSERT_TRUE(s.has_value())
                    << what << " share [" << share.begin << ", " << share.end << "): " << s.error().message;
            }
            for (size_t n = 0; n < outputs.size(); ++n) {
                const auto got = Bytes(*outputs[n]);
                size_t differ = 0, first = got.size();
                for (size_t b = 0; b < got.size(); ++b)
                    if (got[b] != expected[n][b] && differ++ == 0) first = b;
                EXPECT_EQ(differ, 0u) << what << ", output " << n << ", shares of " << size << " of " << count << ": "
                                      << differ << " bytes differ from the whole call, first at byte " << first;
            }
        }
    }

    // A share writes its own slices and nothing else (see EachShareWritesItsSlicesAndNothingElse).
    void ExpectOnly(const std::string& what, const std::vector<Buffer*>& outputs,
                    const std::function<Status(SliceRange)>& call, const std::vector<SliceRange>& run,
                    SliceRange written, const std::function<uint32_t(size_t, size_t)>& shareOf,
                    bool writtenMayWait = false) {
        for (Buffer* out : outputs) Fill(*out);
        const std::vector<std::vector<std::byte>> pattern = [&] {
            std::vector<std::vector<std::byte>> p;
            for (Buffer* out : outputs) p.push_back(Bytes(*out));
            return p;
        }();
        ASSERT_TRUE(call(SliceRange{}).has_value()) << what;
        std::vector<std::vector<std::byte>> whole;
        for (Buffer* out : outputs) whole.push_back(Bytes(*out));
        for (Buffer* out : outputs) Fill(*out);
        for (SliceRange share : run) {
            Status s = call(share);
            ASSERT_TRUE(s.has_value()) << what << ": " << s.error().message;
        }
        for (size_t n = 0; n < outputs.size(); ++n) {
            const auto got = Bytes(*outputs[n]);
            const size_t element = CanonicalElementBytes(outputs[n]->Format());
            size_t wrong = 0, first = 0;
            for (size_t e = 0; e * element < got.size(); ++e) {
                const uint32_t share = shareOf(n, e);
                const bool inside = share >= written.begin && share < written.end;
                auto equals = [&](const std::vector<std::byte>& expected) {
                    return std::equal(got.begin() + e * element, got.begin() + (e + 1) * element,
                                      expected.begin() + e * element);
                };
                const bool ok =
                    inside ? equals(whole[n]) || (writtenMayWait && equals(pattern[n])) : equals(pattern[n]);
                if (!ok && wrong++ == 0) first = e;
            }
            EXPECT_EQ(wrong, 0u) << what << ", output " << n << ": " << wrong
                                 << " elements wrong (written outside the share, or not written inside); first "
                                 << first << " (share " << shareOf(n, first) << ")";
        }
    }

};

// A sparse q with exact zeros, so occupancy has empty tiles and bands.
std::vector<float> SparseQ(const Extent3& e, uint32_t seed) {
    Pcg32 rng(seed);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(5) == 0 ? float(1 + rng.Below(64)) / 64.0f : 0.0f;
    return q;
}

TEST_P(TimeSliceStages, RegionInSlicesOfK) {
    const auto ellipsoids = test::RandomEllipsoids(kGrid, 7);
    auto region = Patterned(BufferFormat::U8, kGrid);
    ExpectSharesEqualWhole("region", kGrid.nz, {region.get()},
                           [&](SliceRange s) { return mBackend->Region(ellipsoids, *region, s); });
}

TEST_P(TimeSliceStages, CaStepInSlicesOfK) {
    const auto ellipsoids = test::RandomEllipsoids(kGrid, 7);
    auto region = Patterned(BufferFormat::U8, kGrid);
    ASSERT_TRUE(mBackend->Region(ellipsoids, *region));
    auto hum = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 1, 2));
    auto act = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 2, 3));
    auto cld = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 3, 4));
    auto hum1 = Patterned(BufferFormat::Bits, kGrid), act1 = Patterned(BufferFormat::Bits, kGrid),
         cld1 = Patterned(BufferFormat::Bits, kGrid);
    // A distinct wind shift per slice, both signs.
    std::vector<int32_t> shiftX(kGrid.nz), shiftY(kGrid.nz);
    for (uint32_t k = 0; k < kGrid.nz; ++k) shiftX[k] = int32_t(k % 3) - 1, shiftY[k] = int32_t(k % 5) - 2;
    for (bool wind : {false, true}) {
        CaStepParams p;
        p.seed = 11, p.step = 3;
        p.qExt = 0x20000000u, p.qHum = 0x30000000u, p.qAct = 0x40000000u;
        if (wind) p.shiftX = shiftX, p.shiftY = shiftY;
        ExpectSharesEqualWhole(wind ? "ca with wind" : "ca", kGrid.nz, {hum1.get(), act1.get(), cld1.get()},
                               [&](SliceRange s) {
                                   CaStepParams share = p;
                                   share.slices = s;
                                   return mBackend->CaStep(share, {hum.get(), act.get(), cld.get()}, *region,
                                                           {hum1.get(), act1.get(), cld1.get()});
                               });
    }
}

TEST_P(TimeSliceStages, SmoothInSlicesOfK) {
    auto cld = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 4, 3));
    auto q = Patterned(BufferFormat::F32, kGrid);
    auto otherCld = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 9, 2));
    auto otherQ = Patterned(BufferFormat::F32, kGrid);
    for (int radius : {0, 1, 2})
        ExpectSharesEqualWhole(
            "smooth radius " + std::to_string(radius), kGrid.nz, {q.get()},
            [&](SliceRange s) { return mBackend->Smooth(radius, *cld, *q, s); },
            [&] { return mBackend->Smooth(radius, *otherCld, *otherQ); });
}

TEST_P(TimeSliceStages, DensityInRowsOfTilesAndTheCoverCountsAddUp) {
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, kGrid, SparseQ(kGrid, 5));
    auto cld = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 6, 40));
    DensityParams p;
    p.tile = 8, p.band = 4;  // 5 x 4 tiles, 3 bands: the last row and band are partial
    const uint32_t tilesX = CeilDiv(kGrid.nx, p.tile), tilesY = CeilDiv(kGrid.ny, p.tile);
    auto D = Patterned(BufferFormat::F32, {kGrid.nx, kGrid.ny, 1});
    auto tiles = Patterned(BufferFormat::U8, {tilesX, tilesY, 1});
    auto bands = Patterned(BufferFormat::U8, {tilesX, tilesY, CeilDiv(kGrid.nz, p.band)});
    for (const Buffer* cover : {static_cast<const Buffer*>(cld.get()), static_cast<const Buffer*>(nullptr)}) {
        const std::string what = cover ? "density, cover from cld" : "density, cover from D";
        uint64_t coverSum = 0;
        std::optional<uint32_t> wholeCover;
        ExpectSharesEqualWhole(what, tilesY, {D.get(), tiles.get(), bands.get()}, [&](SliceRange s) -> Status {
            DensityParams share = p;
            share.slices = s;
            DensityOutputs out{D.get(), tiles.get(), bands.get()};
            CB_TRY(mBackend->Density(share, *q, cover, out));
            if (s == SliceRange{}) {
                wholeCover = out.coveredColumns;
            } else {
                coverSum += out.coveredColumns;
                if (s.end >= tilesY) {  // the last share: the counts of one sequence must add up to the whole's
                    EXPECT_EQ(coverSum, wholeCover.value_or(~0u)) << what;
                    coverSum = 0;
                }
            }
            return {};
        });
        EXPECT_GT(wholeCover.value_or(0), 0u) << what << ": the test field must cover some columns";
    }
}

TEST_P(TimeSliceStages, ShadeInSlicesOfTheSweep) {
    auto q = test::MakeFilled(*mBackend, BufferFormat::F32, kGrid, SparseQ(kGrid, 8));
    auto T = Patterned(BufferFormat::F32, kGrid);
    auto otherQ = test::MakeFilled(*mBackend, BufferFormat::F32, kGrid, SparseQ(kGrid, 10));
    auto otherT = Patterned(BufferFormat::F32, kGrid);
    // z principal, x principal from below the diagonal, y principal with negative components.
    const Vec3 suns[] = {SunDirection(1.2, 0.3), SunDirection(0.35, 0.2), SunDirection(0.5, 4.4)};
    for (const Vec3& sun : suns)
        for (int f : {1, 2, 4})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8})
                for (bool scattering : {false, true}) {
                    ShadeParams p;
                    p.sun = sun, p.resolution = f, p.storage = storage, p.scattering = scattering;
                    p.attenuation = scattering ? AttenuationKind::Thesis : AttenuationKind::Beer;
                    p.sigma = 0.01f;
                    const uint32_t count = MakeShadePlan(p, kGrid).nw;
                    const std::string what = "shade sun (" + std::to_string(sun[0]) + ", " + std::to_string(sun[1]) +
                                             ", " + std::to_string(sun[2]) + ") f " + std::to_string(f) + " storage " +
                                             std::to_string(int(storage)) + (scattering ? " scattering" : "");
                    ExpectSharesEqualWhole(
                        what, count, {T.get()},
                        [&](SliceRange s) {
                            ShadeParams share = p;
                            share.slices = s;
                            return mBackend->Shade(share, *q, *T);
                        },
                        [&] { return mBackend->Shade(p, *otherQ, *otherT); });
                    if (HasFailure()) return;
                }
}

// A share writes its own slices and nothing else (a share that rewrote other slices with equal values would pass the
// tests above): after the shares `run` on patterned outputs, every element whose share is in `written` equals the
// whole call's, and every other one still holds the pattern.

TEST_P(TimeSliceStages, EachShareWritesItsSlicesAndNothingElse) {
    const size_t sliceSize = size_t(kGrid.nx) * kGrid.ny;
    auto sliceK = [&](size_t, size_t v) { return uint32_t(v / sliceSize); };
    // Bits and floats: one element per voxel; the pattern check reads canonical bytes per element.
    const auto ellipsoids = test::RandomEllipsoids(kGrid, 7);
    auto region = Patterned(BufferFormat::U8, kGrid);
    ExpectOnly(
        "region", {region.get()}, [&](SliceRange s) { return mBackend->Region(ellipsoids, *region, s); }, {{3, 5}},
        {3, 5}, sliceK);

    auto hum = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 1, 2));
    auto act = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 2, 3));
    auto cld = test::MakeFilled(*mBackend, BufferFormat::Bits, kGrid, test::RandomBits(kGrid, 3, 4));
    ASSERT_TRUE(mBackend->Region(ellipsoids, *region));
    auto hum1 = Patterned(BufferFormat::Bits, kGrid), act1 = Patterned(BufferFormat::Bits, kGrid),
         cld1 = Patterned(BufferFormat::Bits, kGrid);
    // The pattern of bits is 1: an empty state in the ca keeps most output bits 0, so untouched ones show.
    ExpectOnly(
        "ca", {hum1.get(), act1.get(), cld1.get()},
        [&](SliceRange s) {
            CaStepParams p;
            p.seed = 11, p.step = 3, p.qExt = 0x20000000u, p.qHum = 0x30000000u, p.qAct = 0x40000000u;
            p.slices = s;
            return mBackend->CaStep(p, {hum.get(), act.get(), cld.get()}, *region,
                                    {hum1.get(), act1.get(), cld1.get()});
        },
        {{3, 5}}, {3, 5}, sliceK);

    auto q = Patterned(BufferFormat::F32, kGrid);
    ExpectOnly(
        "smooth", {q.get()}, [&](SliceRange s) { return mBackend->Smooth(2, *cld, *q, s); }, {{3, 5}}, {3, 5}, sliceK);

    auto field = test::MakeFilled(*mBackend, BufferFormat::F32, kGrid, SparseQ(kGrid, 5));
    DensityParams dp;
    dp.tile = 8, dp.band = 4;
    const uint32_t tilesX = CeilDiv(kGrid.nx, dp.tile), tilesY = CeilDiv(kGrid.ny, dp.tile);
    auto D = Patterned(BufferFormat::F32, {kGrid.nx, kGrid.ny, 1});
    auto tiles = Patterned(BufferFormat::U8, {tilesX, tilesY, 1});
    auto bands = Patterned(BufferFormat::U8, {tilesX, tilesY, CeilDiv(kGrid.nz, dp.band)});
    ExpectOnly(
        "density", {D.get(), tiles.get(), bands.get()},
        [&](SliceRange s) {
            DensityParams share = dp;
            share.slices = s;
            DensityOutputs out{D.get(), tiles.get(), bands.get()};
            return mBackend->Density(share, *field, cld.get(), out);
        },
        {{1, 2}}, {1, 2}, [&](size_t output, size_t e) {  // the row of tiles of a column of D, a tile, a tile x band
            return output == 0 ? uint32_t(e / kGrid.nx / dp.tile) : uint32_t((e / tilesX) % tilesY);
        });

    auto T = Patterned(BufferFormat::F32, kGrid);
    for (const Vec3& sun : {SunDirection(1.2, 0.3), SunDirection(0.35, 0.2), SunDirection(0.5, 4.4)}) {
        ShadeParams p;
        p.sun = sun, p.sigma = 0.01f;
        const ShadePlan plan = MakeShadePlan(p, kGrid);
        const uint32_t n[3] = {kGrid.nx, kGrid.ny, kGrid.nz};
        const int w = plan.geometry.w;
        auto sweepSlice = [&](size_t, size_t v) {  // m of the voxel's slice: SliceW(m) is its w index
            const uint32_t ijk[3] = {uint32_t(v % n[0]), uint32_t(v / n[0] % n[1]), uint32_t(v / sliceSize)};
            return plan.geometry.sunAbove ? plan.nw - 1 - ijk[w] : ijk[w];
        };
        auto shade = [&](SliceRange s) {
            ShadeParams share = p;
            share.slices = s;
            return mBackend->Shade(share, *field, *T);
        };
        // A backend may keep the sweep in scratch and write T when it ends (gl does; core/pipeline/Backend.h): inside
        // the shares run, final values or the pattern; outside, the pattern only.
        ExpectOnly("shade", {T.get()}, shade, {{0, 3}, {3, 5}}, {0, 5}, sweepSlice, /*writtenMayWait=*/true);
        // At resolution 2, T is written by the last share alone.
        p.resolution = 2;
        const uint32_t coarse = MakeShadePlan(p, kGrid).nw;
        ExpectOnly("shade f 2", {T.get()}, shade, {{0, 2}, {2, coarse - 1}}, {0, 0}, sweepSlice);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, TimeSliceStages, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(GlRgba8, TimeSliceStages, ::testing::Values(std::string("gl_rgba8")),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cb
