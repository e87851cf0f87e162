// Time-slicing on gl (SPEC 13): what the GL backend keeps between the shares
// of a stage must not outlive its inputs. The RGBA8 automaton carries its
// state from a complete sequence of shares into the next step, and back from
// a whole step into shares; smooth reuses the xy sums a preceding share left,
// which must not survive a change of cld in place. Both are checked against
// whole calls (the RGBA8 steps against the packed layout's, which keeps no
// state between calls). TimeSliceStagesTest covers each stage's shares alone; SkyLight's, shade's shares with a
// shade_sky between them.
#include <gtest/gtest.h>

#include <span>
#include <vector>

#include "core/math/Random.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

std::unique_ptr<Backend> GlsMake(bool rgba8) {
    BackendOptions o;
    if (rgba8) o.glCaLayout = gl::CaLayout::Rgba8;
    auto b = CreateBackend("gl", o);
    return b ? std::move(*b) : nullptr;
}

// Eleven steps, each whole or in shares of 1, 3, 5 or 64 slices, with and
// without wind: the RGBA8 layout's fields after each step equal the packed
// layout's whole steps.
TEST(TimeSliceGL, Rgba8StepsInSharesAndWholeCarryTheState) {
    const Extent3 e{45, 23, 13};
    for (bool wind : {false, true}) {
        auto A = GlsMake(true), B = GlsMake(false);
        if (!A || !B) GTEST_SKIP() << "no gl backend here";
        auto region = test::MakeFilled(*A, BufferFormat::U8, e, std::vector<uint8_t>(e.Count(), 200));
        auto regionB = test::MakeFilled(*B, BufferFormat::U8, e, std::vector<uint8_t>(e.Count(), 200));
        std::unique_ptr<Buffer> a[2][3], b[2][3];
        for (int s = 0; s < 2; ++s)
            for (int n = 0; n < 3; ++n)
                a[s][n] = test::MakeBuffer(*A, BufferFormat::Bits, e),
                b[s][n] = test::MakeBuffer(*B, BufferFormat::Bits, e);
        CaInitParams ip{9, 0x60000000u, 0x10000000u};
        ASSERT_TRUE(A->CaInitialize(ip, {a[0][0].get(), a[0][1].get(), a[0][2].get()}));
        ASSERT_TRUE(B->CaInitialize(ip, {b[0][0].get(), b[0][1].get(), b[0][2].get()}));
        std::vector<int32_t> sx(e.nz), sy(e.nz);
        for (uint32_t k = 0; k < e.nz; ++k) sx[k] = int32_t(k % 3) - 1, sy[k] = int32_t(k % 4) - 2;
        const int modes[] = {1, 0, 3, 3, 0, 5, 0, 1, 1, 0, 64};  // 0 whole, else share size
        for (int t = 0; t < 11; ++t) {
            const int i = t % 2, o = 1 - i;
            CaStepParams p;
            p.seed = 4, p.step = uint32_t(t), p.qExt = 0x08000000u, p.qHum = 0x20000000u, p.qAct = 0x30000000u;
            if (wind) p.shiftX = sx, p.shiftY = sy;
            ASSERT_TRUE(B->CaStep(p, {b[i][0].get(), b[i][1].get(), b[i][2].get()}, *regionB,
                                  {b[o][0].get(), b[o][1].get(), b[o][2].get()}));
            if (modes[t] == 0) {
                ASSERT_TRUE(A->CaStep(p, {a[i][0].get(), a[i][1].get(), a[i][2].get()}, *region,
                                      {a[o][0].get(), a[o][1].get(), a[o][2].get()}));
            } else {
                for (uint32_t k = 0; k < e.nz; k += modes[t]) {
                    CaStepParams s = p;
                    s.slices = {k, k + modes[t]};
                    ASSERT_TRUE(A->CaStep(s, {a[i][0].get(), a[i][1].get(), a[i][2].get()}, *region,
                                          {a[o][0].get(), a[o][1].get(), a[o][2].get()}));
                }
            }
            for (int n = 0; n < 3; ++n)
                EXPECT_EQ(test::Read<uint8_t>(*A, *a[o][n]), test::Read<uint8_t>(*B, *b[o][n]))
                    << "wind " << wind << " step " << t << " field " << n;
        }
    }
}

// Shares, then cld uploaded anew into the same buffer, then shares again:
// the result is the whole call's on the new cld.
TEST(TimeSliceGL, SmoothSharesSeeACldChangedInPlace) {
    const Extent3 e{37, 29, 11};
    auto A = GlsMake(false);
    if (!A) GTEST_SKIP() << "no gl backend here";
    auto cld = test::MakeFilled(*A, BufferFormat::Bits, e, test::RandomBits(e, 1, 3));
    auto q = test::MakeBuffer(*A, BufferFormat::F32, e), w = test::MakeBuffer(*A, BufferFormat::F32, e);
    for (uint32_t k = 0; k < e.nz; k += 2) ASSERT_TRUE(A->Smooth(2, *cld, *q, {k, k + 2}));
    const auto zzNew = test::RandomBits(e, 2, 3);
    ASSERT_TRUE(A->Upload(*cld, std::as_bytes(std::span(zzNew))));
    for (uint32_t k = 0; k < e.nz; k += 2) ASSERT_TRUE(A->Smooth(2, *cld, *q, {k, k + 2}));
    ASSERT_TRUE(A->Smooth(2, *cld, *w));
    EXPECT_EQ(test::Read<float>(*A, *q), test::Read<float>(*A, *w));
}

}  // namespace
}  // namespace cb
